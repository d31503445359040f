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

use crate::optim::Bounds;

use super::Planner;
use super::objective::{PlanObjective, Stop};

/// The share of `h_r − h_a` by which the moved depth must lift its
/// track's least altitude above the track's target for the restart.
const LIFT: f32 = 0.05;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The escape of the module docs from the kink of track `g` of the
    /// horizon (index in the call's horizon), feasible within `tol` (m).
    /// Returns the iterations so far (a kept restart counts one more).
    /// Not inlined: its state stays off the SQP runs' stack.
    #[inline(never)]
    pub(super) fn leave_kink(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        (g, tol): (usize, f32),
        iterations: u32,
    ) -> u32 {
        match self.kink_start(obj, bounds, g) {
            Ok(Some(z)) => self
                .sqp_restart(obj, &z, (h, bounds), (tol, 0.0), iterations)
                .unwrap_or(iterations),
            Ok(None) | Err(_) => iterations,
        }
    }

    /// The restart point: the workspace's depths with track `g`'s moved
    /// towards the depth the vehicle starts that track at, by `h_r − h_a`
    /// or half the way, within the box; `None` when the track does not
    /// dive (a saturated climb is not freed by either side).
    fn kink_start(
        &self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        g: usize,
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
        let shift = crate::num::min(band, 0.5 * dive);
        // (NaN, from a diverged head, moves nothing either.)
        if shift.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            return Ok(None);
        }
        let up = crate::num::max(zg - shift, lo);
        // Only where the shallower dive lifts the track's least altitude
        // clear of its target (the row was at it): where the dive stays
        // saturated past that sample (Monterey 2's later calls), the
        // restart would only find the same optimum again.
        let least = obj.least_of_track(&at_g, g, up)?;
        let bar = obj.target_of(g) + LIFT * band;
        if least.partial_cmp(&bar) != Some(core::cmp::Ordering::Greater) {
            return Ok(None);
        }
        if let Some(v) = z.get_mut(g) {
            *v = up;
        }
        Ok(Some(z))
    }
}
