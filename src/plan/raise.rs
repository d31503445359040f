//! A later track raised until it clears its target: the search the lift
//! (`lift/`) makes for the track after a deepened one, and the sink
//! (`sink.rs`) for the track after a sunk one.
//!
//! The raises double from the band `h_r − h_a`, so their reach is the
//! band's: 32 bands. Where none clears the target, one more raise goes to
//! the settled depth, the shallowest bottom of the raised track and the
//! held one less `h_r`, which clears both once the vehicle has settled
//! on it. On `check_planner.py --seed 2943 --vehicle
//! tools/reference/vehicles/tight.toml` (`unseen_2943_2`, band 4 m) the
//! cold SQP ended with track 2 at 432 m, 337 m above its bottom, held by
//! track 3, whose dive at the pitch limit passed a rise at its target.
//! The sink of track 2 left track 3 short, and no raise of track 3 up to
//! 128 m cleared it (the dive still passed the rise): the sinks ended.
//! The best safe plan flies track 3 162 m higher over the rise so that
//! track 2 can dive the whole track. With the settled depth, the line
//! went from 1.21× the f64 search's best safe plan to 1.0003×.

use crate::sim::VehicleState;

use super::bottom::shallowest;
use super::objective::{PlanObjective, Stop};
use super::scan::with_depth;

/// Raises tried (the band, doubling).
const RAISES: u32 = 6;

/// Bisections of the deepest depth that clears (and of the least lift
/// that frees a track's preferred depth: `lift/`).
pub(super) const NARROW: u32 = 3;

/// Depth `k` of `z` raised until track `g` (`k ≤ g`), flown with the
/// tracks from `j` on from `at_j` (the state track `j` starts in), clears
/// `target` (m): shallower by `band` (m), doubling ([`RAISES`] times at
/// most, not above `lo`, m); where none clears it, once more at the
/// settled depth (module docs); then [`NARROW`] bisections toward the
/// last depth that did not clear it; one flight of tracks `j..=g` each.
/// The deepest depth found that clears it, if any.
pub(super) fn raised<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    (at_j, j): (&VehicleState<N>, usize),
    (z, (k, g)): (&[f32; K], (usize, usize)),
    (target, band, lo): (f32, f32, f32),
) -> Result<Option<f32>, Stop> {
    let Some(&zk) = z.get(k) else {
        return Ok(None);
    };
    // Depth `k` at `up` clears the target: the deepest point toward
    // `held` that does.
    let cleared = |obj: &mut PlanObjective<'_, N>, (up, held): (f32, f32)| {
        if obj.least_at((at_j, j), &with_depth(z, k, up), g)? < target {
            return Ok(None);
        }
        clearing(obj, (at_j, j), (g, target), (z, (k, |d| d)), (up, held)).map(Some)
    };
    let (mut held, mut step) = (zk, band);
    for _ in 0..RAISES {
        let up = crate::num::max(zk - step, lo);
        if let Some(d) = cleared(obj, (up, held))? {
            return Ok(Some(d));
        }
        if up <= lo {
            return Ok(None);
        }
        (held, step) = (up, 2.0 * step);
    }
    // (The doubling's reach is the band's: 32 bands.)
    match settled(obj, (k, g)).map(|d| crate::num::max(d, lo)) {
        Some(up) if up < held => cleared(obj, (up, held)),
        _ => Ok(None),
    }
}

/// The settled depth of horizon tracks `k..=g` (module docs): their
/// shallowest bottom sample less `h_r`, m.
fn settled<const N: usize>(obj: &PlanObjective<'_, N>, (k, g): (usize, usize)) -> Option<f32> {
    let h_r = obj.sc.mission().reference_altitude();
    (k..=g)
        .filter_map(|t| shallowest(&obj.sc, obj.track.saturating_add(t), h_r))
        .reduce(crate::num::min)
}

/// The point of `(clear, held)` nearest `held` at which track `g`, flown
/// with the tracks from `j` on from `at_j`, clears `target` (m), found by
/// [`NARROW`] bisections (one flight of tracks `j..=g` each), with depth
/// `k` of `z` at `depth(t)` (m) for each point `t` tried.
pub(super) fn clearing<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    (at_j, j): (&VehicleState<N>, usize),
    (g, target): (usize, f32),
    (z, (k, depth)): (&[f32; K], (usize, impl Fn(f32) -> f32)),
    (mut clear, mut held): (f32, f32),
) -> Result<f32, Stop> {
    for _ in 0..NARROW {
        let mid = 0.5 * (clear + held);
        let at = with_depth(z, k, depth(mid));
        if obj.least_at((at_j, j), &at, g)? >= target {
            clear = mid;
        } else {
            held = mid;
        }
    }
    Ok(clear)
}
