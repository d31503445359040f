//! Small numerical helpers shared by the simulation and the optimizers.
//!
//! The only one with a story is [`Comp`]: along-track position and depth are
//! integrated over tens of thousands of steps of 0.15 m on values near
//! 1000-5000 m. In plain f32 each addition loses up to half an ulp (0.24 mm
//! at 4000 m), and because the increment is nearly constant the loss is
//! systematic: after a 4 km line `x` would be off by metres, moving every
//! waypoint switch. Compensated (Knuth two-sum) accumulation keeps the exact
//! rounding error of every addition in a second f32, so the f32 core tracks
//! an f64 reference to about 1e-6 m at a cost of five extra additions.

/// A value kept as an unevaluated sum `hi + lo` (Knuth's two-sum).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Comp {
    hi: f32,
    lo: f32,
}

impl Comp {
    /// A compensated value equal to `v`.
    #[inline]
    pub(crate) const fn new(v: f32) -> Self {
        Self { hi: v, lo: 0.0 }
    }

    /// The value rounded to one f32.
    #[inline]
    pub(crate) fn value(self) -> f32 {
        self.hi + self.lo
    }

    /// `self + v`, keeping the rounding error of the addition.
    #[inline]
    pub(crate) fn add(self, v: f32) -> Self {
        // Knuth's TwoSum: s + err == hi + v exactly.
        let s = self.hi + v;
        let bv = s - self.hi;
        let err = (self.hi - (s - bv)) + (v - bv);
        Self {
            hi: s,
            lo: self.lo + err,
        }
    }

    /// `self - c`, accurate when `self` and `c` are close (the `hi - c` part
    /// is then exact by Sterbenz' lemma).
    #[inline]
    pub(crate) fn minus(self, c: f32) -> f32 {
        (self.hi - c) + self.lo
    }

    /// `self - other`, accurate when both are close.
    #[inline]
    pub(crate) fn diff(self, other: Self) -> f32 {
        (self.hi - other.hi) + (self.lo - other.lo)
    }
}

/// Neumaier-compensated running sum, for the objective's integrals.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Sum {
    s: f32,
    c: f32,
}

impl Sum {
    #[inline]
    pub(crate) fn add(&mut self, v: f32) {
        let t = self.s + v;
        if libm::fabsf(self.s) >= libm::fabsf(v) {
            self.c += (self.s - t) + v;
        } else {
            self.c += (v - t) + self.s;
        }
        self.s = t;
    }

    #[inline]
    pub(crate) fn value(self) -> f32 {
        self.s + self.c
    }
}

/// Degrees to radians, as f32.
pub(crate) const DEG: f32 = core::f32::consts::PI / 180.0;

/// `v` clamped to `[-limit, limit]`, and whether it lay inside (the
/// derivative of the clamp is 1 inside and 0 outside).
#[inline]
pub(crate) fn clamp_sym(v: f32, limit: f32) -> (f32, bool) {
    if v > limit {
        (limit, false)
    } else if v < -limit {
        (-limit, false)
    } else {
        (v, true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compensated_sum_keeps_what_f32_loses() {
        // 0.15 m steps from 3000 m: plain f32 drifts, Comp does not.
        let mut plain = 3000.0_f32;
        let mut comp = Comp::new(3000.0);
        let mut exact = 3000.0_f64;
        for _ in 0..10_000 {
            plain += 0.15;
            comp = comp.add(0.15);
            exact += f64::from(0.15_f32);
        }
        let err_plain = (f64::from(plain) - exact).abs();
        let err_comp = (f64::from(comp.value()) - exact).abs();
        assert!(err_plain > 0.1, "plain f32 drift {err_plain}");
        assert!(err_comp < 1e-3, "compensated drift {err_comp}");
        assert!(f64::from(comp.minus(4500.0)) - (exact - 4500.0) < 1e-4);
    }

    #[test]
    fn neumaier_sum() {
        let mut s = Sum::default();
        s.add(1.0e8);
        for _ in 0..1000 {
            s.add(1.0);
        }
        s.add(-1.0e8);
        assert!((s.value() - 1000.0).abs() < 1e-3);
    }

    #[test]
    fn clamp_reports_linearity() {
        assert_eq!(clamp_sym(3.0, 2.0), (2.0, false));
        assert_eq!(clamp_sym(-3.0, 2.0), (-2.0, false));
        assert_eq!(clamp_sym(1.0, 2.0), (1.0, true));
    }
}
