//! A single track's optimum where `J` has small jumps.
//!
//! An autopilot whose depth loop integrates conditionally (contract §7,
//! with `ki > 0`) makes `J(z)` a sawtooth: each time the sample at which
//! the depth loop leaves saturation passes a sample, its integrator gains
//! or loses one step's increment and `J` jumps. On a random canyon line
//! (`check_planner.py --seed 51 --vehicle` with `depth_pid.ki = 0.02`) it
//! jumps +181 m³ every 6.5 cm of depth on a trend of +1 800 m³/m; between
//! jumps the exact gradient is the tooth's slope (−970 m³/m), and BFGS
//! ends inside a tooth, its `J` change below the stopping threshold while
//! the trend still falls: 7.5 m and 1.6 % short of the best `J`.
//!
//! The polish reads `J` on a scale the teeth do not matter: from the
//! optimizer's end, a step of [`STEP`] to each side (plain flights); if one
//! is lower by more than the stopping threshold, steps doubling that way
//! while `J` falls, then the vertex of the parabola through the last three
//! points. Only where the optimizer's end looks like a tooth or a step:
//! its gradient would move `J` over [`STEP`] by more than [`SHARE`] of `J`
//! (at a smooth optimum the gradient vanishes), or `J` still fell by more
//! than that share in the optimizer's last iteration (a staircase, whose
//! flat steps stop BFGS on its gradient rule: `unseen_51_1` track 2, 3.6 m
//! and 1.7 % short). A constrained track keeps only depths whose flight
//! clears the certified altitude. It is polished where the scan hands it
//! to the optimizer, and where the optimizer, having left the safe set,
//! ran again to an interior optimum (`candidate.rs`, `inward`): on
//! `check_planner.py --seed 1203 --vehicle
//! tools/reference/vehicles/integ.toml`, `unseen_1203_2` track 3 and
//! `unseen_1203_5` track 4 ended 1.3 and 2.0 m off, 1.021× the best safe
//! `J`; polished, 1.0017× and 1.00002×. Where that second run trips
//! again (a tooth's slope points out of the safe set while the trend
//! falls into it), the search runs from the boundary itself
//! ([`Planner::polish_boundary`]): on `check_planner.py --seed 1902
//! --vehicle tools/reference/vehicles/integ.toml`, `unseen_1902_0`
//! track 1 kept its boundary, 1.0087× the best safe `J`; now 1.0004×.

use crate::optim::Bounds;

use super::Planner;
use super::objective::PlanObjective;
use super::solve::horizon_flight;

/// The polish's first step, m: many teeth wide, short against a track's
/// basin (the scan's grid is tens of metres).
const STEP: f32 = 0.5;

/// The share of `J` that the gradient must predict over [`STEP`] for the
/// polish to run.
const SHARE: f32 = 1e-4;

/// Most doublings of the step.
const DOUBLINGS: u32 = 8;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The polish of the module docs on the workspace's single track, in
    /// `bounds`, every depth's least altitude at or above `h_safe` (m)
    /// when given. Plain flights, counted in `obj`'s evaluations. Not
    /// inlined: its state stays off the optimizer's stack.
    #[inline(never)]
    pub(super) fn polish_single(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        h_safe: Option<f32>,
    ) {
        let w = &self.work;
        let (Some(&z0), Some(&g0), Some(&lo), Some(&hi)) = (
            w.z.first(),
            w.gradient.first(),
            bounds.lo.first(),
            bounds.hi.first(),
        ) else {
            return;
        };
        let j0 = w.j;
        let share = SHARE * libm::fabsf(j0);
        // The last iteration's decrease of `J`.
        let fell = match w.history.as_slice() {
            [.., a, b] => a - b,
            _ => 0.0,
        };
        if !(libm::fabsf(g0) * STEP > share || fell > share) {
            return;
        }
        self.polish_from(obj, (lo, hi), h_safe, (z0, j0));
    }

    /// The polish's search from a constrained track's boundary `(z, J)`
    /// (m, m³), in `bounds`, every point's least altitude at or above the
    /// objective's guard (its trip cleared): the workspace put at the
    /// boundary, then moved to the lower `J` if one is found (whether it
    /// was).
    pub(super) fn polish_boundary(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        (z, j): (f32, f32),
    ) -> bool {
        if let Some(first) = self.work.z.first_mut() {
            *first = z;
        }
        self.work.j = j;
        let (Some(&lo), Some(&hi)) = (bounds.lo.first(), bounds.hi.first()) else {
            return false;
        };
        obj.tripped = None;
        let guard = obj.guard;
        self.polish_from(obj, (lo, hi), guard, (z, j))
    }

    /// The polish's search from `(z0, J0)` (m, m³), the workspace's single
    /// track at `z0`, in `[lo, hi]` (m): whatever the gradient says. Moves
    /// the workspace to the lowest point found below the stopping
    /// threshold; whether it moved. Out of line: one copy for both
    /// callers.
    #[inline(never)]
    pub(super) fn polish_from(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (lo, hi): (f32, f32),
        h_safe: Option<f32>,
        (z0, j0): (f32, f32),
    ) -> bool {
        let bar = j0 - self.cfg.bfgs.tol.j_threshold(j0);
        let base = self.work.z;
        let inside = |z: f32| crate::num::max(crate::num::min(z, hi), lo);
        let mut at = |z: f32| {
            let z = inside(z);
            (z.to_bits() != z0.to_bits())
                .then(|| flown_at(obj, (&base, z), h_safe))
                .flatten()
        };
        let sides = [at(z0 - STEP), at(z0 + STEP)];
        let Some(first) = sides
            .into_iter()
            .flatten()
            .filter(|p| p.1 < bar)
            .min_by(|a, b| a.1.total_cmp(&b.1))
        else {
            return false;
        };
        let dir = if first.0 < z0 { -1.0 } else { 1.0 };
        let (mut prev, mut best, mut past) = ((z0, j0), first, None);
        let mut step = STEP;
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
                None => break,
            }
        }
        if let Some(v) = past.and_then(|c| vertex(prev, best, c))
            && let Some(p) = at(v)
            && p.1 < best.1
        {
            best = p;
        }
        let w = &mut self.work;
        if let Some(z) = w.z.first_mut() {
            *z = best.0;
        }
        w.j = best.1;
        // (The polished value ends the history; full, it keeps its last.)
        let _ = w.history.push(best.1);
        true
    }
}

/// `(z, J)` of the track flown at depth `z` (m) (the horizon `base`'s
/// first), when its flight flies and its least altitude clears `h_safe`
/// (m) if given. One plain flight; out of line, so that the polish holds
/// one call of the simulation, not one per point.
#[inline(never)]
fn flown_at<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    (base, z): (&[f32; K], f32),
    h_safe: Option<f32>,
) -> Option<(f32, f32)> {
    let mut zz = *base;
    *zz.first_mut()? = z;
    let (j, least, _) = horizon_flight(obj, &zz).ok()?;
    let safe = h_safe.is_none_or(|h| least >= h);
    (safe && j.is_finite()).then_some((z, j))
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
