//! A later track raised until it clears its target: the search the lift
//! (`lift/`) makes for the track after a deepened one, and the sink
//! (`sink.rs`) for the track after a sunk one.

use crate::sim::VehicleState;

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
/// most, not above `lo`, m), then [`NARROW`] bisections toward the last
/// depth that did not clear it; one flight of tracks `j..=g` each. The
/// deepest depth found that clears it, if any.
pub(super) fn raised<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    (at_j, j): (&VehicleState<N>, usize),
    (z, (k, g)): (&[f32; K], (usize, usize)),
    (target, band, lo): (f32, f32, f32),
) -> Result<Option<f32>, Stop> {
    let Some(&zk) = z.get(k) else {
        return Ok(None);
    };
    let (mut held, mut step) = (zk, band);
    for _ in 0..RAISES {
        let up = crate::num::max(zk - step, lo);
        if obj.least_at((at_j, j), &with_depth(z, k, up), g)? >= target {
            let d = clearing(obj, (at_j, j), (g, target), (z, (k, |d| d)), (up, held))?;
            return Ok(Some(d));
        }
        if up <= lo {
            break;
        }
        (held, step) = (up, 2.0 * step);
    }
    Ok(None)
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
