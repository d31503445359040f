//! A line track's bottom as the escapes read it (`lift/`, `raise.rs`):
//! the depths its flight would settle at over the mean, the deepest and
//! the shallowest of its bottom samples, each less an altitude.

use crate::sim::Scenario;

/// The bottom depths (m) of the profile's samples on line track `t`;
/// `None` for a track the line does not have.
fn track_bottom<'s, const N: usize>(
    sc: &'s Scenario<'_, N>,
    t: usize,
) -> Option<impl Iterator<Item = f32> + 's> {
    let wp = sc.waypoints().positions();
    let (&a, &b) = (wp.get(t)?, wp.get(t.saturating_add(1))?);
    let p = sc.profile();
    Some(
        p.positions()
            .iter()
            .zip(p.depths())
            .filter(move |&(&x, _)| x >= a && x <= b)
            .map(|(_, &d)| d),
    )
}

/// The deepest useful depth of line track `t`: its deepest bottom sample
/// less `h_r` (m); `None` without samples.
pub(super) fn deepest<const N: usize>(sc: &Scenario<'_, N>, t: usize, h_r: f32) -> Option<f32> {
    track_bottom(sc, t)?
        .map(|d| d - h_r)
        .reduce(crate::num::max)
}

/// The shallowest useful depth of line track `t`: its shallowest bottom
/// sample less `h_r` (m), a depth that clears the whole track once the
/// vehicle has settled on it; `None` without samples.
pub(super) fn shallowest<const N: usize>(sc: &Scenario<'_, N>, t: usize, h_r: f32) -> Option<f32> {
    track_bottom(sc, t)?
        .map(|d| d - h_r)
        .reduce(crate::num::min)
}

/// The preferred depth of line track `t`: the mean of its bottom samples
/// less the reference altitude `h_r` (m); `None` without samples.
pub(super) fn preferred<const N: usize>(sc: &Scenario<'_, N>, t: usize, h_r: f32) -> Option<f32> {
    let (sum, n) =
        track_bottom(sc, t)?.fold((0.0_f32, 0_u32), |(s, n), d| (s + d, n.saturating_add(1)));
    (n > 0).then(|| sum / n as f32 - h_r)
}
