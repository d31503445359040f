//! A cold horizon whose SQP ends with an earlier track held above the
//! depth its `J` wants by a later track's least altitude: the mirror of
//! the lift (`lift.rs`). Sinking the earlier depth makes the vehicle
//! arrive deeper, so the later track must fly shallower to clear its
//! target; the SQP weighs that trade at its end, where it is dear, but a
//! larger sink can move the later track's lowest point to another dip
//! (or past it) and cost it far less.
//!
//! On `check_planner.py --seed 2676 --vehicle
//! tools/reference/vehicles/low.toml` (`unseen_2676_7`) the SQP ended with
//! track 1 at 976.9 m, its least altitude 32.5 m (`h_a` 28 m) set by the
//! start, whatever its depth, and `∂J/∂z_1` −1.8e4 m²: held by track 2,
//! at its target. Sinking track 1 by 23 m took track 2's least altitude
//! down 23 m, and raising track 2 as much gave back 1 m; the best safe
//! plan flies track 1 97 m deeper and track 2 73 m shallower. The line's
//! `J` was 1.20× the f64 search's best safe plan; after, 1.002×. The same
//! shape on `unseen_2632_1` (`--seed 2632`, `slow`: 1.33× → 1.0006×),
//! `unseen_2718_4` (`--seed 2718`, `integ`: 1.12×) and `unseen_2724_3`
//! (`--seed 2724`, `low`, tracks 2 and 3: 1.17× → 1.0008×).
//!
//! The escape, for each later track `g` at its target (within the
//! hundredth of the band, as the lift's) whose earlier track `j = g − 1`
//! is above its own by more, with `∂J/∂z_j < 0` (all read from one plain
//! flight of the SQP's end): depth `j` sunk by the band `h_r − h_a`,
//! doubling ([`SINKS`] times at most, within the box), while track `j`
//! still clears its own target there (one flight of tracks `j..=g` tells
//! both). At each sink, depth `g` is raised from where the last sink left
//! it to the deepest depth found that clears its target
//! ([`super::raise::raised`]), and the start so made is flown to the end
//! of the horizon: the sink whose start has the lowest `J`, below the
//! SQP's and feasible within the band, restarts the SQP, kept where it
//! ends better ([`Planner::sqp_restart`]). The sinks stop where a start's
//! `J` is more than [`SHARE`] above the SQP's (without that stop, 15
//! flights a line instead of 6.8, and the same plans). On the 267 random
//! lines 5 move, all lower (`unseen_2534_1` 0.61×, `unseen_3104_3` 0.92×,
//! `unseen_3131_6` 0.95×), for 6.8 flights a line (1.8 % of the horizon
//! mode's); the 18 shared runs keep their plans, at 2 flights more in
//! Monterey 1's cold call, 19 in Monterey 2's and 12 in Monterey 3's
//! third call, where no start beats the SQP's end.

use crate::optim::Bounds;
use crate::sim::TrackScore;

use super::Planner;
use super::objective::{PlanObjective, Stop};
use super::raise::raised;
use super::scan::with_depth;

/// Sinks tried for one track (the band, doubling).
const SINKS: u32 = 6;

/// The sinks stop where a start's horizon `J` is more than this share
/// above the SQP's (the lift's bound on a freed start: `lift.rs`).
const SHARE: f32 = 0.25;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The escape of the module docs over a horizon of `h` tracks in
    /// `bounds`, feasible within `tol` (m), after `iterations`. Returns the
    /// iterations so far. Not inlined: its state stays off the SQP runs'
    /// stack.
    #[inline(never)]
    pub(super) fn sink_earlier(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
        mut iterations: u32,
    ) -> u32 {
        if !self.feasible_with_room(obj, tol, iterations) {
            return iterations;
        }
        let slack = obj.held_slack(tol);
        let Ok(mut scores) = obj.flight(&self.work.z) else {
            return iterations;
        };
        for g in 1..h {
            let j = g.saturating_sub(1);
            let deeper = self.work.gradient.get(j).is_some_and(|&d| d < 0.0);
            let (Some(sj), Some(sg)) = (scores.get(j), scores.get(g)) else {
                break;
            };
            if !deeper || !held_above(obj, (j, sj), (g, sg), slack) {
                continue;
            }
            let Ok(Some(z)) = self.sink_start(obj, bounds, g) else {
                continue;
            };
            if let Some(total) =
                self.sqp_restart(obj, &z, (h, bounds), (tol, 0.0, false), iterations)
            {
                iterations = total;
                // (The later tracks' altitudes as the restart left them.)
                match obj.flight(&self.work.z) {
                    Ok(s) => scores = s,
                    Err(_) => break,
                }
            }
            if iterations >= self.cfg.bfgs.max_iterations {
                break;
            }
        }
        iterations
    }

    /// The start of the module docs for later track `g`: the sink of
    /// depth `g − 1` whose start has the lowest horizon `J`, if one is
    /// below the SQP's and feasible within the band. (Not inlined: its
    /// flights' state is not on the stack of the restart that follows.)
    #[inline(never)]
    fn sink_start(
        &self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        g: usize,
    ) -> Result<Option<[f32; K]>, Stop> {
        let j = g.saturating_sub(1);
        let z = self.work.z;
        let (Some(&zj), Some(&zg), Some(&hi), Some(&lo)) =
            (z.get(j), z.get(g), bounds.hi.get(j), bounds.lo.get(g))
        else {
            return Ok(None);
        };
        let m = obj.sc.mission();
        let band = m.reference_altitude() - m.min_altitude();
        let (own, target) = (obj.target_of(j), obj.target_of(g));
        let (head, at_j) = obj.head(&z, j)?;
        let from = (&at_j, j);
        let mut best: Option<([f32; K], f32)> = None;
        // The sink, and depth `g` as the last sink left it, m.
        let (mut sink, mut zg) = (band, zg);
        for _ in 0..SINKS {
            let down = crate::num::min(zj + sink, hi);
            let start = with_depth(&with_depth(&z, j, down), g, zg);
            let (least_j, least_g) = obj.least_pair(from, &start, g)?;
            if least_j < own {
                break;
            }
            if least_g < target {
                match raised(obj, from, (&start, g), (target, band, lo))? {
                    Some(d) => zg = d,
                    None => break,
                }
            }
            let start = with_depth(&start, g, zg);
            let (jz, v) = obj.tail_value(&head, from, &start)?;
            if v <= band && jz < best.map_or(self.work.j, |(_, b)| b) {
                best = Some((start, jz));
            }
            if down >= hi || jz > (1.0 + SHARE) * self.work.j {
                break;
            }
            sink *= 2.0;
        }
        Ok(best.map(|(start, _)| start))
    }
}

/// Whether track `g` (score `sg`) is at its target, within `slack` (m),
/// and track `j` (score `sj`) above its own by more.
fn held_above<const N: usize>(
    obj: &PlanObjective<'_, N>,
    (j, sj): (usize, &TrackScore),
    (g, sg): (usize, &TrackScore),
    slack: f32,
) -> bool {
    sg.min_altitude() <= obj.target_of(g) + slack && sj.min_altitude() > obj.target_of(j) + slack
}
