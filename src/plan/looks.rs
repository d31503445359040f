//! The polish's searches along one depth (`polish.rs`): the looks either
//! side of a point, the descent in doubling steps with its parabola, the
//! settling to a tooth's bottom backed off its jump, and the boundary
//! toward a step that left the safe set; each point one plain flight of
//! the horizon with that depth moved.

use crate::optim::root;

use super::fallback::boundary_rule;
use super::objective::PlanObjective;
use super::solve::horizon_flight;

/// The settling's first step, m: a fraction of a tooth's width
/// (centimetres).
const TOOTH: f32 = 0.01;

/// How far a tooth's bottom is backed off its jump, m: past where an
/// f64 flight of the same depth may see the jump (a fraction of a
/// millimetre on the cases measured, `polish.rs`), a thirtieth of a
/// tooth's width.
const BACK: f32 = 0.002;

/// Most doublings of the step.
const DOUBLINGS: u32 = 8;

/// The lower of the points a `step` (m) either side of `z` (m) whose `J`
/// is below `bar` (m³), as `(z, J)`, by `at` (one plain flight each).
pub(super) fn lower_side(
    at: &mut impl FnMut(f32) -> Option<(f32, f32)>,
    (z, step): (f32, f32),
    bar: f32,
) -> Option<(f32, f32)> {
    let sides = [at(z - step), at(z + step)];
    let lower = sides.into_iter().flatten().filter(|p| p.1 < bar);
    lower.min_by(|a, b| a.1.total_cmp(&b.1))
}

/// From `from` (`(z, J)`, m and m³) and its lower side `first` found at
/// `step` (m): steps doubling that way while `J` falls, then the vertex of
/// the parabola through the last three points (flown by `at`, inside the
/// box by `inside`). The lowest point, and the depth where a step left the
/// safe set, if one did.
pub(super) fn descend(
    at: &mut impl FnMut(f32) -> Option<(f32, f32)>,
    inside: impl Fn(f32) -> f32,
    from: (f32, f32),
    (first, mut step): ((f32, f32), f32),
) -> ((f32, f32), Option<f32>) {
    let dir = if first.0 < from.0 { -1.0 } else { 1.0 };
    let (mut prev, mut best, mut past, mut out) = (from, first, None, None);
    for _ in 0..DOUBLINGS {
        step *= 2.0;
        let z = inside(best.0 + dir * step);
        if z.to_bits() == best.0.to_bits() {
            break;
        }
        match at(z) {
            Some(p) if p.1 < best.1 => (prev, best) = (best, p),
            Some(p) => {
                past = Some(p);
                break;
            }
            None => {
                out = Some(z);
                break;
            }
        }
    }
    if let Some(v) = past.and_then(|c| vertex(prev, best, c))
        && let Some(p) = at(v)
        && p.1 < best.1
    {
        best = p;
    }
    (best, out)
}

/// The settling of a look's end `best` (`(z, J)`, m and m³) to a tooth's
/// bottom: a step of [`TOOTH`] either side lower than `bar` (m³), and the
/// descent from it; then backed off by [`BACK`] against the descent's
/// direction where `J` there is within `slack` (m³) of the bottom's
/// (module docs of `polish.rs`). By `at` (one plain flight each), inside
/// the box by `inside`.
pub(super) fn settle(
    at: &mut impl FnMut(f32) -> Option<(f32, f32)>,
    inside: impl Fn(f32) -> f32,
    best: (f32, f32),
    (bar, slack): (f32, f32),
) -> (f32, f32) {
    let Some(p) = lower_side(at, (best.0, TOOTH), bar) else {
        return best;
    };
    let dir = if p.0 < best.0 { -1.0 } else { 1.0 };
    let bottom = descend(at, &inside, best, (p, TOOTH)).0;
    match at(inside(bottom.0 - dir * BACK)) {
        Some(q) if q.1 <= bottom.1 + slack => q,
        _ => bottom,
    }
}

/// What a polished point must clear.
#[derive(Clone, Copy)]
pub(super) enum Clear<const K: usize> {
    /// The first track's least altitude at or above this, if given (m).
    First(Option<f32>),
    /// Each track's least altitude at or above its floor (m).
    Floors([f32; K]),
}

/// `(z, J)` of the horizon `base` flown with its depth `i` at `z` (m),
/// when its flight flies and clears `clear`. One plain flight.
pub(super) fn flown_at<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    (base, i, z): (&[f32; K], usize, f32),
    clear: Clear<K>,
) -> Option<(f32, f32)> {
    let (j, margin) = margin_at(obj, (base, i, z), clear)?;
    (margin >= 0.0).then_some((z, j))
}

/// `(J, margin)` (m³, m) of the horizon `base` flown with its depth `i`
/// at `z` (m), when its flight flies to a finite `J`: the margin is the
/// least of its clearances of `clear` (infinite where nothing is to be
/// cleared). One plain flight; out of line, so that the polish holds one
/// call of the simulation, not one per point.
#[inline(never)]
fn margin_at<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    (base, i, z): (&[f32; K], usize, f32),
    clear: Clear<K>,
) -> Option<(f32, f32)> {
    let mut zz = *base;
    *zz.get_mut(i)? = z;
    let (j, margin) = match clear {
        Clear::First(h_safe) => {
            let (j, least, _) = horizon_flight(obj, &zz).ok()?;
            (j, h_safe.map_or(f32::INFINITY, |h| least - h))
        }
        Clear::Floors(floors) => {
            let scores = obj.flight(&zz).ok()?;
            let (j, _) = obj.value_of(&scores).ok()?;
            let clear = scores.iter().zip(&floors).take(obj.count);
            let least = clear.map(|(s, f)| s.min_altitude() - f);
            (j, least.fold(f32::INFINITY, f32::min))
        }
    };
    (j.is_finite() && !margin.is_nan()).then_some((j, margin))
}

/// The safe end of the boundary, in depth `i` of `base`, between the
/// polish's lowest point `at` (m), which clears `clear`, and the next
/// step's `out` (m), which did not, with its `J` (m³):
/// [`crate::optim::root`] on the margin of [`margin_at`] (a point that
/// does not fly counts as outside), stopped by the boundary searches'
/// rule in at most `steps` flights. None where nothing is to be cleared
/// or the search did not move.
pub(super) fn boundary_toward<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    (base, i, at, out): (&[f32; K], usize, f32, f32),
    clear: Clear<K>,
    steps: u32,
) -> Option<(f32, f32)> {
    if matches!(clear, Clear::First(None)) {
        return None;
    }
    let rule = boundary_rule(obj.sc.mission(), steps);
    let r = root::safe_boundary((at, None), (out, None), rule, |z| {
        margin_at(obj, (base, i, z), clear)
            .map(|(j, margin)| (margin, j))
            .ok_or(())
    })
    .ok()?;
    r.at.filter(|_| r.z.to_bits() != at.to_bits())
        .map(|j| (r.z, j))
}

/// The vertex of the parabola through three points `(z, J)` with `b`
/// the lowest, when it lies strictly between the outer two.
fn vertex(a: (f32, f32), b: (f32, f32), c: (f32, f32)) -> Option<f32> {
    let (p, q) = ((b.0 - a.0) * (b.1 - c.1), (b.0 - c.0) * (b.1 - a.1));
    let den = 2.0 * (p - q);
    let v = b.0 - ((b.0 - a.0) * p - (b.0 - c.0) * q) / den;
    let (lo, hi) = if a.0 < c.0 { (a.0, c.0) } else { (c.0, a.0) };
    (v.is_finite() && v > lo && v < hi).then_some(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_vertex_of_a_parabola_through_three_points() {
        let f = |z: f32| 3.0 * (z - 2.5) * (z - 2.5) + 1.0;
        let v = vertex((0.0, f(0.0)), (2.0, f(2.0)), (6.0, f(6.0))).unwrap();
        assert!((v - 2.5).abs() < 1e-5, "{v}");
        // Outside the outer two, or collinear: none.
        assert_eq!(vertex((0.0, 0.0), (1.0, 1.0), (2.0, 2.0)), None);
    }
}
