//! A kink ahead of a one-variable BFGS run: the **vee** safeguard.
//!
//! Where `J` has a kink at its minimum (a saturation that sets in there:
//! the slope jumps from negative to positive), the metric, built from
//! gradients on the smooth side, keeps putting the minimum past the
//! kink. Every first trial lands beyond it and is rejected, the line
//! search's interpolation falls to its floor (a tenth of the step), and
//! the run crawls towards the kink, each iteration a little nearer: on
//! `check_planner.py --seed 2559 --vehicle
//! tools/reference/vehicles/integ.toml`, `unseen_2559_2` track 2,
//! unconstrained, eleven iterations, over the checker's 10, `J` falling
//! 41, 10, 5, 3, 2 … m³ an iteration while the gradient on the smooth
//! side stayed at −50 to −140 m².
//!
//! The rejected trials lie on the kink's far side. With two of them
//! beyond the current point (from the last two line searches that
//! backtracked, on the one free variable), the far side's secant
//! through them and the near side's tangent at the current point meet
//! at an estimate of the kink; the next direction is shortened to reach
//! no further. On a vee of straight sides the estimate is exact. On a
//! convex quadratic, where a rejected trial lies at least as far past the
//! minimum as the point is short of it (it was rejected: its `J` is not
//! below the point's), the estimate lies at or past the minimum, so the
//! cap does not cut a step short of it.
//!
//! Only for one free variable (a single track), and only after a line
//! search that backtracked: a run whose first trials are accepted is
//! not touched.

use super::Vector;

/// The trials rejected beyond the current point, on one variable.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Vee {
    /// The free variable's index.
    axis: usize,
    /// The nearest rejected trial beyond the point, `(z, J)` (m, m³).
    near: Option<(f32, f32)>,
    /// The next nearest, farther on the same side.
    far: Option<(f32, f32)>,
    /// Whether the last line search backtracked.
    backtracked: bool,
}

impl Vee {
    /// After an iteration along `dir` that accepted `z` with gradient `g`
    /// (m, m²), the line search's rejected trial `rejected`, if any.
    pub(crate) fn record<const K: usize>(
        &mut self,
        (z, g): (&Vector<K>, &Vector<K>),
        dir: &Vector<K>,
        rejected: Option<&(Vector<K>, f32)>,
    ) {
        // One free variable, and `J` still falling towards the rejected
        // side; else nothing is kept.
        let along = lone_axis(dir).and_then(|a| Some((a, *z.get(a)?, *g.get(a)?, *dir.get(a)?)));
        let Some((axis, zi, _, di)) = along.filter(|&(_, _, gi, di)| gi * di < 0.0) else {
            *self = Self::default();
            return;
        };
        let ahead = |p: &(f32, f32)| (p.0 - zi) * di > 0.0 && p.1.is_finite();
        let new = rejected.and_then(|(r, jr)| r.get(axis).map(|&ri| (ri, *jr)));
        let kept = if axis == self.axis {
            [self.near, self.far, new]
        } else {
            [new, None, None]
        };
        let by_distance =
            |p: &Option<(f32, f32)>| p.map_or(f32::INFINITY, |p| libm::fabsf(p.0 - zi));
        let mut points = kept.map(|p| p.filter(ahead));
        points.sort_unstable_by(|a, b| by_distance(a).total_cmp(&by_distance(b)));
        let [near, far, _] = points;
        // Two points at one depth give no secant.
        let far = far.filter(|f| near.is_some_and(|n| libm::fabsf(n.0 - f.0) > 0.0));
        *self = Self {
            axis,
            near,
            far,
            backtracked: rejected.is_some(),
        };
    }

    /// `dir` shortened to end at the kink's estimate (module docs), from
    /// `z` with value `j` and gradient `g`; `dir` itself where there is
    /// no estimate or it lies further.
    pub(crate) fn cap<const K: usize>(
        &self,
        (z, j, g): (&Vector<K>, f32, &Vector<K>),
        dir: Vector<K>,
    ) -> Vector<K> {
        let (true, Some(near), Some(far)) = (self.backtracked, self.near, self.far) else {
            return dir;
        };
        let i = self.axis;
        let (Some(&zi), Some(&gi), Some(&di)) = (z.get(i), g.get(i), dir.get(i)) else {
            return dir;
        };
        if lone_axis(&dir) != Some(i) {
            return dir;
        }
        // Distances along the direction: the near side's slope `a` < 0,
        // the far side's secant slope `s` > 0 through `near` and `far`.
        let u = if di > 0.0 { 1.0 } else { -1.0 };
        let (pn, pf) = ((near.0 - zi) * u, (far.0 - zi) * u);
        let (a, s) = (gi * u, (far.1 - near.1) / (pf - pn));
        // J + a p = J_n + s (p - p_n).
        let p = (near.1 - s * pn - j) / (a - s);
        let ok = a < 0.0 && s > 0.0 && p.is_finite() && p > 0.0 && p < pn;
        if ok && p < libm::fabsf(di) {
            dir * (p / libm::fabsf(di))
        } else {
            dir
        }
    }
}

/// The one nonzero component of `v`, if it has exactly one.
fn lone_axis<const K: usize>(v: &Vector<K>) -> Option<usize> {
    let mut found = None;
    for (i, x) in v.iter().enumerate() {
        if *x != 0.0 {
            if found.is_some() {
                return None;
            }
            found = Some(i);
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vee of straight sides, `J = max(−2 (z − 1), 6 (z − 1))`: from
    /// z = 0, two trials rejected at 1.5 and 2.0 put the kink at 1.
    #[test]
    fn a_vee_of_straight_sides_is_found_exactly() {
        let f = |z: f32| (-2.0 * (z - 1.0)).max(6.0 * (z - 1.0));
        let v = |z: f32| Vector::<1>::new(z);
        let mut vee = Vee::default();
        let g = v(-2.0);
        vee.record((&v(-1.0), &g), &v(3.0), Some(&(v(2.0), f(2.0))));
        vee.record((&v(0.0), &g), &v(2.0), Some(&(v(1.5), f(1.5))));
        let d = vee.cap((&v(0.0), f(0.0), &g), v(4.0));
        assert!((d[0] - 1.0).abs() < 1e-6, "{d}");
        // Rising towards the rejected side: no estimate.
        vee.record((&v(0.0), &v(1.0)), &v(2.0), Some(&(v(1.5), f(1.5))));
        assert_eq!(vee.cap((&v(0.0), f(0.0), &v(-2.0)), v(4.0))[0], 4.0);
    }

    /// On a smooth minimum (`J = z²` from −1, trials rejected at 1.5 and
    /// 2) the estimate lies past the minimum: the cap does not cut the
    /// step short of it.
    #[test]
    fn a_smooth_minimum_is_not_cut_short() {
        let v = |z: f32| Vector::<1>::new(z);
        let mut vee = Vee::default();
        let g = v(-2.0);
        vee.record((&v(-1.0), &g), &v(3.0), Some(&(v(2.0), 4.0)));
        vee.record((&v(-1.0), &g), &v(2.5), Some(&(v(1.5), 2.25)));
        let d = vee.cap((&v(-1.0), 1.0, &g), v(3.0));
        assert!(d[0] >= 1.0 && d[0] < 3.0, "{d}");
    }

    /// Two free variables: nothing recorded, nothing capped.
    #[test]
    fn more_than_one_free_variable_is_left_alone() {
        let v = |a: f32, b: f32| Vector::<2>::new(a, b);
        let mut vee = Vee::default();
        let g = v(-2.0, -1.0);
        for r in [2.0, 1.5] {
            vee.record((&v(0.0, 0.0), &g), &v(3.0, 1.0), Some(&(v(r, 0.5), 9.0)));
        }
        assert_eq!(vee.cap((&v(0.0, 0.0), 0.0, &g), v(3.0, 1.0)), v(3.0, 1.0));
    }
}
