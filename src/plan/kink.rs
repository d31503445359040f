//! A horizon's SQP stopped at a one-sided kink of a later track's least
//! altitude (`Linearized::kinked`): the sample that sets it lies where the
//! track's pitch reference has stayed saturated in a dive since the track
//! began, so its own depth's column is exactly zero there and the row
//! blocks the earlier depths alone. A shallower dive would unsaturate
//! sooner and lift that sample (the other side of the kink), letting an
//! earlier track fly deeper. Seen on a random canyon line
//! (`check_planner.py --seed 23`, `unseen_23_1`): the SQP held track 1 at
//! 934.2 m with track 2's least altitude at 60.08 m, `J` 1.64× the best
//! safe plan's (961.7, 1 087.1 m). The escape: the later depth moved by
//! the mission's band `h_r − h_a` towards the vehicle (at most half way);
//! where that lifts the track's least altitude [`LIFT`] of the band above
//! its target (one flight of the track: a dive still saturated past the
//! sample lifts nothing), the SQP restarted from there, kept only if it
//! ends better.
//!
//! In a feasible cold call without declared uncertainty (`far`), a move
//! that lifts nothing is doubled, at most [`SHIFTS`] times and at most the
//! whole dive: on `check_planner.py --seed 2718`, `unseen_2718_2`, track 5
//! dived 425 m saturated from 515 m and held track 4 156 m above its
//! bottom; only a move of 320 m unsaturated it, and the restart found the
//! best safe plan (track 4 at 621 m, track 5 at 670 m): line `J` 1.61× →
//! 1.001×. Warm calls keep the one move: on Monterey 2 the doubled moves
//! found lifts whose restarts gained nothing and doubled the later calls'
//! flights.
//!
//! Where several rows end at such kinks, each is tried in turn until one's
//! move lifts its track (only the first was, before round 37). On
//! `check_planner.py --seed 3087 --vehicle
//! tools/reference/vehicles/stiff.toml` (`unseen_3087_6`) track 3's row
//! came first: held by track 2's arrival, its own depth moving nothing,
//! and a climb, which no move frees. Track 4 dived saturated from 349 m
//! towards 601.6 m and held track 3 there; the best safe plan flies track
//! 4 at 546 m and track 3 20 m deeper. The line's `J` was 1.272× the f64
//! best safe plan's; 1.0011×. On the 304 random lines 2 move (by under
//! 1e-5), +0.8 flights a line; the 18 shared runs keep their plans, and
//! Monterey 2's cold call flies 58 more (its second kink's restart,
//! not kept), Monterey 1's one more (a kink that does not dive).
//!
//! A restart from a kink's move that ends above the end it would
//! replace is not kept, so where that end is feasible the restart is
//! given up after its second iteration if it is still above that end and,
//! at that iteration's pace, more than ten iterations from it
//! ([`PlanObjective::ceiling`]). Monterey 2's second kink's restart went
//! 37.6, 23.3, 23.2 M m³ against the kept 17.9 M, and ended at 22.9 M
//! after 12 iterations: given up after 2, its cold call flies 248 times,
//! not 290. A restart that starts slowly goes on (`unseen_5034_2`: 16.4,
//! 13.0, 12.6, then 9.75 M against 10.25 M, its line 1.0002× the f64 best
//! safe plan; given up, 1.123×). On the 304 random lines: 17 lines fly
//! 913 times fewer (3.0 a line), one ends higher by 0.012 %
//! (`unseen_5027_3`, whose restart's pace quickened after the second
//! iteration), the rest keep their plans.

use crate::optim::Bounds;
use crate::optim::constrained::group_bit;

use super::Planner;
use super::objective::{PlanObjective, Stop};

/// The share of `h_r − h_a` by which the moved depth must lift its
/// track's least altitude above the track's target for the restart.
const LIFT: f32 = 0.05;

/// Moves tried (`h_r − h_a`, doubling, at most the whole dive).
const SHIFTS: u32 = 6;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The escape of the module docs from the kinks of the tracks in
    /// `kinks` (bit `g`: track `g` of the horizon, index in the call's
    /// horizon), the first whose move lifts its track, feasible within
    /// `tol` (m); `far`: a cold call's, whose moves may double where it
    /// ends feasible. Returns the iterations so far (a kept restart counts
    /// one more). Not inlined: its state stays off the SQP runs' stack.
    #[inline(never)]
    pub(super) fn leave_kink(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        (kinks, tol, far): (u32, f32, bool),
        iterations: u32,
    ) -> u32 {
        let feasible = obj.last_violation <= tol;
        let far = far && feasible;
        let kinked = |g: &usize| group_bit(*g).is_some_and(|b| kinks & b != 0);
        for g in (1..h).filter(kinked) {
            match self.kink_start(obj, bounds, g, far) {
                Ok(Some(z)) => {
                    obj.ceiling = feasible.then_some(self.work.j);
                    let again =
                        self.sqp_restart(obj, &z, (h, bounds), (tol, 0.0, false), iterations);
                    obj.ceiling = None;
                    return again.unwrap_or(iterations);
                }
                Ok(None) => {}
                Err(_) => return iterations,
            }
        }
        iterations
    }

    /// The restart point: the workspace's depths with track `g`'s moved
    /// towards the depth the vehicle starts that track at, by `h_r − h_a`
    /// or half the way (`far`: doubling, up to the whole way), within the
    /// box; `None` when the track does not dive (a saturated climb is not
    /// freed by either side) or no move lifts it. (Not inlined: its
    /// flights' state is not on the stack of the restart that follows.)
    #[inline(never)]
    fn kink_start(
        &self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        g: usize,
        far: bool,
    ) -> Result<Option<[f32; K]>, Stop> {
        let mut z = self.work.z;
        let (&zg, &lo) = match (z.get(g), bounds.lo.get(g)) {
            (Some(zg), Some(lo)) => (zg, lo),
            _ => return Ok(None),
        };
        let (_, at_g) = obj.head(&z, g)?;
        let dive = zg - at_g.depth();
        let m = obj.sc.mission();
        let band = m.reference_altitude() - m.min_altitude();
        let bar = obj.target_of(g) + LIFT * band;
        let (mut shift, most, tries) = if far {
            (band, dive, SHIFTS)
        } else {
            (band, 0.5 * dive, 1)
        };
        for _ in 0..tries {
            let s = crate::num::min(shift, most);
            // (NaN, from a diverged head, moves nothing either.)
            if s.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
                return Ok(None);
            }
            let up = crate::num::max(zg - s, lo);
            // Only where the shallower dive lifts the track's least
            // altitude clear of its target (the row was at it): where the
            // dive stays saturated past that sample (Monterey 2's later
            // calls), the restart would only find the same optimum again.
            let least = obj.least_of_track(&at_g, g, up)?;
            if least.partial_cmp(&bar) == Some(core::cmp::Ordering::Greater) {
                if let Some(v) = z.get_mut(g) {
                    *v = up;
                }
                return Ok(Some(z));
            }
            if s >= most || up <= lo {
                return Ok(None);
            }
            shift *= 2.0;
        }
        Ok(None)
    }
}
