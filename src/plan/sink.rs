//! A cold horizon whose SQP ends with an earlier track held above the
//! depth its `J` wants by a later track's least altitude: the mirror of
//! the lift (`lift/`). Sinking the earlier depth makes the vehicle
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
//! The later track that holds it need not be the next one. On
//! `unseen_2728_3` (`--seed 2728`, `integ`) track 1 was held at 812.5 m by
//! track 5's least altitude, with tracks 2 and 4 diving or climbing at the
//! pitch limit between them: raising track 5's or track 4's depth moves
//! nothing, and the best safe plan sinks track 1 89 m with track 3 raised
//! 104 m. The line's `J` was 1.72× the f64 search's best; after, 1.0006×.
//!
//! The escape, for each earlier track `j` above its own target by more
//! than the hundredth of the band (as the lift's), with `∂J/∂z_j ≠ 0`,
//! and the first later track `g` at its target within as much (all read
//! from one plain flight of the SQP's end): depth `j` sunk by the band
//! `h_r − h_a`, doubling ([`SINKS`] times at most, within the box), while
//! track `j` still clears its own target there (one flight of tracks
//! `j..=g` tells both); the first sink that does not is bisected back
//! toward the last that did ([`NARROW`](super::raise::NARROW) flights of
//! track `j`), and its start is the last. At each sink where track `g` falls short, a depth
//! from `g` back to `j + 1` is raised from where the last sink left the
//! depths to the deepest found that clears `g`'s target
//! ([`super::raise::raised`]): the first that can, from the depth the
//! last sink raised (at first `g`) back (a depth whose track is saturated
//! moves nothing later). The start so made is flown to the end
//! of the horizon: the sink whose start has the lowest `J`, below the
//! SQP's and feasible within the band, restarts the SQP, kept where it
//! ends better ([`Planner::sqp_restart`]). The sinks stop where a start's
//! `J` is more than [`FREED_SHARE`] above the SQP's, the lift's bound on a
//! freed start (without that stop, 15 flights a line instead of 6.8, and
//! the same plans). On the 267 random
//! lines 5 move, all lower (`unseen_2534_1` 0.61×, `unseen_3104_3` 0.92×,
//! `unseen_3131_6` 0.95×), for 6.8 flights a line (1.8 % of the horizon
//! mode's); the 18 shared runs keep their plans, at 2 flights more in
//! Monterey 1's cold call, 19 in Monterey 2's and 12 in Monterey 3's
//! third call, where no start beats the SQP's end. With a later track
//! other than the next one (a round later) 6 more move, all lower
//! (`unseen_3124_6` 0.66×, `unseen_2524_7` 0.77×, `unseen_3121_5` 0.97×),
//! for 6.4 flights a line more; the 18 shared runs the same.
//!
//! The sign of `∂J/∂z_j` at the SQP's end does not tell what a sink of
//! the band does: on `unseen_2737_2` (`--seed 2737`, `slow`) it was +380
//! m² (a wrinkle: later tracks' `J` rises over the first metres), though
//! the line's `J` falls 2.0e6 m³ over the next 158 m of sink with track 3
//! at its target all the way. The sink is tried wherever the gradient is
//! not exactly 0 (a depth on a plateau, its track saturated: sinking it
//! moves nothing, and on Monterey 1 it cost the cold call 10 flights).
//! There the sink of 160 m passed track 1's own target, and the deepest
//! depth between 80 and 160 m that clears it is the best plan's: the
//! line went from 1.27× to 1.0012× the f64 best. On the 267 random lines
//! 6 move, 4 lower (`unseen_2507_4` 0.90×, `unseen_3104_4` 0.97×), 2
//! higher (`unseen_3128_1` +0.24 %; `unseen_3103_3` +2.4 %: its cold
//! call's horizon `J` is lower, 16.400e6 m³ against 16.424e6, and the
//! later calls, which had improved on the old one, keep the new), for 0.5
//! flights a line more; the 18 shared runs keep their plans and flights.
//!
//! The first depth back from `g` that clears it may clear it dearly: a
//! start more than [`FREED_SHARE`] above the SQP's `J` ends the sinks.
//! There the depth before it is raised instead, where that start's `J`
//! is lower. On `check_planner.py --seed 2924 --vehicle
//! tools/reference/vehicles/twoki.toml` (`unseen_2924_0`) track 1 flew
//! 15 m above its target, held by track 3 through track 2's saturated
//! dive; a 15 m sink left track 3 15 m short, and its own depth cleared
//! it 270 m up (2.9× the SQP's `J`). The best safe plan sinks track 1 24
//! m and raises track 2 60 m, for track 3 158 m deeper: the line went
//! from 1.35× the f64 best safe plan to 1.00006×. On the 267 random lines
//! no plan moves, at 0.16 flights a line; the 18 shared runs keep their
//! plans and flights.
//!
//! Where the track between `j` and `g` flies on a plateau (its depth's
//! gradient exactly 0: a saturated dive or climb, whose flight its
//! depth does not move), that depth is raised with each sink by as much,
//! so that the dive ends where it did; and where no single raise then
//! clears track `g`, the sink is still a start if it is feasible within
//! twice the band, and the sinks go on. On `check_planner.py --seed 3004
//! --vehicle tools/reference/vehicles/fast.toml` (`unseen_3004_0`) track
//! 1 flew 4 m above its target at 403.8 m, held by track 3 through track
//! 2's saturated dive to 644.9 m; the best safe plan sinks track 1 81 m to
//! its own boundary, raises track 2 70 m and track 3 1.5 m, two raises no
//! single one makes. The line's `J` was 4.77× the f64 search's best safe
//! plan; after, 1.0012×. On the 304 random lines 6 move, 5 lower (by up
//! to 0.012 %) and one 0.012 % higher, 4.2 flights a line more; the 18
//! shared runs keep their plans and flights.

use crate::optim::Bounds;
use crate::sim::{TrackScore, VehicleState};

use super::Planner;
use super::lift::FREED_SHARE;
use super::objective::{PlanObjective, Stop};
use super::raise::{clearing, raised};
use super::scan::with_depth;

/// Sinks tried for one track (the band, doubling).
const SINKS: u32 = 6;

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
        for j in 0..h.saturating_sub(1) {
            // (Not a depth on a plateau: its track saturated, it moves
            // nothing.)
            let moves = self.work.gradient.get(j).is_some_and(|&d| d != 0.0);
            let Some(g) = held_above(obj, &scores, (j, h), slack) else {
                continue;
            };
            if !moves {
                continue;
            }
            let Ok(Some(z)) = self.sink_start(obj, bounds, (j, g)) else {
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

    /// The start of the module docs for earlier track `j` held by later
    /// track `g`: the sink of depth `j` whose start has the lowest horizon
    /// `J`, if one is below the SQP's and feasible within the band (within
    /// twice the band where it is carried through a plateau and no raise
    /// clears track `g`). (Not inlined: its flights' state is not on the
    /// stack of the restart that follows.)
    #[inline(never)]
    fn sink_start(
        &self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        (j, g): (usize, usize),
    ) -> Result<Option<[f32; K]>, Stop> {
        let z = self.work.z;
        let (Some(&zj), Some(&hi)) = (z.get(j), bounds.hi.get(j)) else {
            return Ok(None);
        };
        let m = obj.sc.mission();
        let band = m.reference_altitude() - m.min_altitude();
        let (own, target) = (obj.target_of(j), obj.target_of(g));
        let (head, at_j) = obj.head(&z, j)?;
        let from = (&at_j, j);
        let mut best: Option<([f32; K], f32)> = None;
        // The sink, the depths as the last sink left them, and the depth
        // the last raise moved.
        let (mut sink, mut left, mut k) = (band, z, g);
        // A depth between on a plateau (its track saturated) is raised
        // with the sink (module docs).
        let shifted = j.saturating_add(1);
        let carried = shifted < g && self.work.gradient.get(shifted).is_some_and(|&d| d == 0.0);
        let sunk = |from: &[f32; K], down: f32| {
            let start = with_depth(from, j, down);
            match (carried, z.get(shifted), bounds.lo.get(shifted)) {
                (true, Some(&zs), Some(&lo)) => {
                    with_depth(&start, shifted, crate::num::max(zs - (down - zj), lo))
                }
                _ => start,
            }
        };
        for n in 0..SINKS {
            let mut down = crate::num::min(zj + sink, hi);
            let mut start = sunk(&left, down);
            let (sj, sg) = obj.ends(from, &start, g)?;
            let (least_j, mut least_g) = (sj.min_altitude(), sg.min_altitude());
            // Past track `j`'s own target: the deepest depth found since
            // the last sink, which cleared it, and the last start.
            let last = least_j < own;
            if last {
                if n == 0 {
                    break;
                }
                let cleared = crate::num::min(zj + 0.5 * sink, hi);
                down = clearing(obj, from, (j, own), (&start, (j, |d| d)), (cleared, down))?;
                start = sunk(&left, down);
                least_g = obj.least_at(from, &start, g)?;
            }
            let (mut value, mut most) = (None, band);
            if least_g < target {
                let raise = ((from, &head), (target, band));
                match self.raised_start(obj, raise, (&start, (k, g)), bounds)? {
                    Some((raised, moved, jz)) => (start, k, value) = (raised, moved, Some(jz)),
                    // Carried through a plateau, a sink that no single
                    // raise clears is still a start within twice the
                    // band, and the sinks go on (module docs).
                    None if carried && !last => most = 2.0 * band,
                    None => break,
                }
            }
            left = start;
            let (jz, v) = match value {
                Some(value) => value,
                None => obj.tail_value(&head, from, &start)?,
            };
            if v <= most && jz < best.map_or(self.work.j, |(_, b)| b) {
                best = Some((start, jz));
            }
            if last || down >= hi || jz > (1.0 + FREED_SHARE) * self.work.j {
                break;
            }
            sink *= 2.0;
        }
        Ok(best.map(|(start, _)| start))
    }

    /// `start` with the latest depth from `k` back to `j + 1` raised
    /// until track `g` clears `target` ([`raised_before`]), or, where that
    /// start's horizon `J` is more than [`FREED_SHARE`] above the SQP's,
    /// the depth before it instead if that costs less (module docs): the
    /// start, the depth raised and the start's `(J, v)` (m³, m; its tail
    /// flown from `from` after `head`). None where no depth clears it.
    fn raised_start(
        &self,
        obj: &mut PlanObjective<'_, N>,
        ((from, head), (target, band)): (Tail<'_, N, K>, (f32, f32)),
        (start, (k, g)): (&[f32; K], (usize, usize)),
        bounds: &Bounds<K>,
    ) -> Result<Option<Raised<K>>, Stop> {
        let raise = (from, (target, band));
        let Some((moved, d)) = raised_before(obj, raise, (start, (k, g)), bounds)? else {
            return Ok(None);
        };
        let raised = with_depth(start, moved, d);
        let jz = obj.tail_value(head, from, &raised)?;
        let dear = jz.0 > (1.0 + FREED_SHARE) * self.work.j;
        let before = match moved.checked_sub(1).filter(|&b| dear && b > from.1) {
            Some(b) => raised_before(obj, raise, (start, (b, g)), bounds)?,
            None => None,
        };
        if let Some((b, d)) = before {
            let cheaper = with_depth(start, b, d);
            let jb = obj.tail_value(head, from, &cheaper)?;
            if jb.0 < jz.0 {
                return Ok(Some((cheaper, b, jb)));
            }
        }
        Ok(Some((raised, moved, jz)))
    }
}

/// A raised start, the depth raised and the start's `(J, v)` (m³, m).
type Raised<const K: usize> = ([f32; K], usize, (f32, f32));

/// Where a sink's tail is flown from: the state track `j` starts in and
/// `j`, and the scores of the tracks before it.
type Tail<'s, const N: usize, const K: usize> = ((&'s VehicleState<N>, usize), &'s [TrackScore; K]);

/// The latest depth `k` of `z`, from `last` back to `j + 1`, that
/// [`raised`] lifts until track `g` clears `target` (m), flown from `at_j`
/// (the state track `j` starts in), raising by the `band` (m) doubling,
/// not above `bounds`: that depth and where it goes, if any. A depth whose
/// track only dives or climbs at the pitch limit (a saturated track) moves
/// nothing below it, and the one before it is tried.
fn raised_before<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    ((at_j, j), (target, band)): ((&VehicleState<N>, usize), (f32, f32)),
    (z, (last, g)): (&[f32; K], (usize, usize)),
    bounds: &Bounds<K>,
) -> Result<Option<(usize, f32)>, Stop> {
    for k in (j.saturating_add(1)..=last).rev() {
        let Some(&lo) = bounds.lo.get(k) else {
            continue;
        };
        if let Some(d) = raised(obj, (at_j, j), (z, (k, g)), (target, band, lo))? {
            return Ok(Some((k, d)));
        }
    }
    Ok(None)
}

/// The first track `g` after `j` (of the `h` of the horizon) at its target
/// within `slack` (m), if track `j` is above its own by more (`scores`:
/// one flight of the horizon).
fn held_above<const N: usize>(
    obj: &PlanObjective<'_, N>,
    scores: &[TrackScore],
    (j, h): (usize, usize),
    slack: f32,
) -> Option<usize> {
    let above = |t: usize, s: &TrackScore| s.min_altitude() > obj.target_of(t) + slack;
    if !scores.get(j).is_some_and(|s| above(j, s)) {
        return None;
    }
    (j.saturating_add(1)..h).find(|&g| scores.get(g).is_some_and(|s| !above(g, s)))
}
