//! A cold horizon whose SQP ends with a later track held at its least
//! altitude's target by the depth of the track before it: the vehicle
//! arrives too deep for the later track to be given a deeper depth.
//! Lifting the earlier depth lets the later one dive, a joint move of two
//! depths that neither makes alone. On a random canyon line
//! (`check_planner.py --seed 60606`, `unseen_60606_0`) the SQP ended with
//! track 1 at 662.6 m (a saturated dive: `∂J/∂z_1` exactly 0, and no
//! single-depth scan gains) and track 2 at its target at 661.1 m; the best
//! safe plan flies track 1 at 587 m so that track 2 can dive to 922 m. The
//! line's `J` was 1.56× the f64 search's best safe plan; after, 1.001×
//! (`unseen_5151_6`: 1.33× → 1.002×). The escape, for each later track
//! `g` at its target: depth `g − 1` lifted by the band `h_r − h_a`,
//! doubling (at most [`LIFTS`] times, within the box), until track `g`'s
//! least altitude clears its target by the band (one flight of the two
//! tracks each); depth `g` then deepened by what was freed beyond the
//! band, and the SQP restarted from there where the horizon's `J` is
//! lower (one flight of the tail), kept only if it ends better.

use crate::optim::Bounds;

use super::Planner;
use super::objective::{PlanObjective, Stop};

/// Lifts tried for one track (the band, doubling).
const LIFTS: u32 = 6;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The escape of the module docs over a horizon of `h` tracks in
    /// `bounds`, feasible within `tol` (m), after `iterations`. Returns the
    /// iterations so far. Not inlined: its state stays off the SQP runs'
    /// stack.
    #[inline(never)]
    pub(super) fn lift_earlier(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
        iterations: u32,
    ) -> u32 {
        if obj.last_violation > tol || iterations >= self.cfg.bfgs.max_iterations {
            return iterations;
        }
        for g in 1..h {
            let Ok(Some(z)) = self.lift_start(obj, bounds, g, tol) else {
                continue;
            };
            if let Some(total) = self.sqp_restart(obj, &z, (h, bounds), (tol, 0.0), iterations) {
                return total;
            }
        }
        iterations
    }

    /// The restart point for later track `g`: `None` unless `g` is at its
    /// target (within the band's hundredth, or `tol`, m) and a lift of
    /// track `g − 1` frees it.
    fn lift_start(
        &self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        g: usize,
        tol: f32,
    ) -> Result<Option<[f32; K]>, Stop> {
        let m = obj.sc.mission();
        let band = m.reference_altitude() - m.min_altitude();
        let j = g.saturating_sub(1);
        let mut z = self.work.z;
        let (head, at_j) = obj.head(&z, j)?;
        let target = obj.target_of(g);
        let least = obj.least_at((&at_j, j), &z, g)?;
        if least > target + tol.max(0.01 * band) {
            return Ok(None);
        }
        let (Some(&zj), Some(&lo)) = (z.get(j), bounds.lo.get(j)) else {
            return Ok(None);
        };
        let mut lift = band;
        for _ in 0..LIFTS {
            let up = crate::num::max(zj - lift, lo);
            if let Some(v) = z.get_mut(j) {
                *v = up;
            }
            let freed = obj.least_at((&at_j, j), &z, g)? - target - band;
            if freed >= 0.0 {
                // Track `g` given the freed altitude: kept only where the
                // horizon's `J` falls (and it stays within the band).
                if let Some(v) = z.get_mut(g) {
                    *v += freed;
                }
                let (jz, v) = obj.tail_value(&head, (&at_j, j), &z)?;
                return Ok((v <= band && jz < self.work.j).then_some(z));
            }
            if up <= lo {
                break;
            }
            lift *= 2.0;
        }
        Ok(None)
    }
}
