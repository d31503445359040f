//! Small numerical helpers shared by the simulation and the optimizers.
//!
//! The only one with a story is [`Comp`]: along-track position and depth are
//! integrated over tens of thousands of steps of 0.15 m on values near
//! 1000-5000 m. In plain f32 each addition loses up to half an ulp (0.24 mm
//! at 4000 m), and because the increment is nearly constant the loss is
//! systematic: after a 4 km line `x` would be off by metres, moving every
//! waypoint switch. Compensated (Dekker's Fast2Sum) accumulation keeps the exact
//! rounding error of every addition in a second f32, so the f32 core tracks
//! an f64 reference to about 1e-6 m at a cost of three extra additions.

/// A value kept as an unevaluated sum `hi + lo` (Dekker's Fast2Sum).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Comp {
    hi: f32,
    lo: f32,
}

impl Comp {
    /// A compensated value equal to `v`.
    #[inline(always)]
    pub(crate) const fn new(v: f32) -> Self {
        Self { hi: v, lo: 0.0 }
    }

    /// The value rounded to one f32.
    #[inline(always)]
    pub(crate) fn value(self) -> f32 {
        self.hi + self.lo
    }

    /// `self + v`, keeping the rounding error of the addition.
    ///
    /// Dekker's Fast2Sum: `s + err == hi + v` exactly when `|hi| >= |v|`,
    /// which holds for a position or depth and its per-step increment
    /// (0.15 m by default) except within one increment of zero, where the
    /// error term itself is off by at most an ulp of the increment (about
    /// 1e-8 m): two additions fewer per step than Knuth's TwoSum.
    #[inline(always)]
    pub(crate) fn add(self, v: f32) -> Self {
        let s = self.hi + v;
        let err = v - (s - self.hi);
        Self {
            hi: s,
            lo: self.lo + err,
        }
    }

    /// `self - c`, accurate when `self` and `c` are close (the `hi - c` part
    /// is then exact by Sterbenz' lemma).
    #[inline(always)]
    pub(crate) fn minus(self, c: f32) -> f32 {
        (self.hi - c) + self.lo
    }

    /// `self - other`, accurate when both are close.
    #[inline(always)]
    pub(crate) fn diff(self, other: Self) -> f32 {
        (self.hi - other.hi) + (self.lo - other.lo)
    }
}

/// Kahan-compensated running sum, for the objective's integrals. Their
/// terms are never negative, so the running sum dominates every term and
/// plain Kahan is exact to rounding without Neumaier's branch.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Sum {
    s: f32,
    c: f32,
}

impl Sum {
    #[inline(always)]
    pub(crate) fn add(&mut self, v: f32) {
        let y = v - self.c;
        let t = self.s + y;
        self.c = (t - self.s) - y;
        self.s = t;
    }

    #[inline(always)]
    pub(crate) fn value(self) -> f32 {
        self.s + self.c
    }
}

/// `(sin x, cos x)` for `x` in radians.
///
/// The vehicle's mean pitch stays well inside ±90° (the pitch reference is
/// limited to less than 90° and the step fails beyond it), where a short
/// polynomial beats libm's `sinf`/`cosf` by a wide margin on a Cortex-M4F
/// (their kernels work in f64, which that FPU does not have). Two pairs of
/// near-minimax polynomials: on `|x| <= π/4` ([`sin_cos_short`], where a
/// cruising vehicle flies) the odd degree-7 and even degree-8 ones, on
/// `π/4 < |x| <= π/2` the odd degree-9 and even degree-10 ones; evaluated in
/// f32 their error is at most 1.8e-7 (sin) and 1.3e-7 (cos), two to three
/// times f32 rounding, checked by the unit test over the whole interval.
/// Outside it the result is NaN.
#[inline(never)]
pub(crate) fn sin_cos(x: f32) -> (f32, f32) {
    if libm::fabsf(x) <= SHORT {
        return sin_cos_short(x);
    }
    // Beyond ±90° (and for NaN) the vehicle would be flying backwards: the
    // simulation fails there anyway, so no value is needed (and libm's
    // `sinf`/`cosf`, whose argument reduction works in f64, a soft-float
    // type on a Cortex-M4F, stay out of the firmware).
    if libm::fabsf(x).partial_cmp(&core::f32::consts::FRAC_PI_2)
        == Some(core::cmp::Ordering::Greater)
        || x.is_nan()
    {
        return (f32::NAN, f32::NAN);
    }
    sin_cos_long(x)
}

/// The degree-9/10 polynomials of [`sin_cos`] (`|x| <= π/2`, radians; not
/// checked).
#[inline(always)]
pub(crate) fn sin_cos_long(x: f32) -> (f32, f32) {
    let x2 = x * x;
    let s = x * (1.0 + x2 * (SIN[0] + x2 * (SIN[1] + x2 * (SIN[2] + x2 * SIN[3]))));
    let c = 1.0 + x2 * (COS[0] + x2 * (COS[1] + x2 * (COS[2] + x2 * (COS[3] + x2 * COS[4]))));
    (s, c)
}

/// Where [`sin_cos_short`] applies: `|x| <= π/4` (45°).
pub(crate) const SHORT: f32 = core::f32::consts::FRAC_PI_4;

/// `SHORT²` rounded: `x * x <= SHORT_SQ` exactly where `|x| <= SHORT`
/// (and not for NaN), since f32 squaring is monotonic and the squares of
/// `SHORT` and of the next f32 round apart (tested).
pub(crate) const SHORT_SQ: f32 = SHORT * SHORT;

/// `(sin x, cos x)` for `|x| <= π/4` (radians; not checked): the degree-7
/// and degree-8 polynomials of [`sin_cos`] (their own error below 3e-9).
#[inline(always)]
pub(crate) fn sin_cos_short(x: f32) -> (f32, f32) {
    let x2 = x * x;
    let s = x + x * (x2 * (SIN_SHORT[0] + x2 * (SIN_SHORT[1] + x2 * SIN_SHORT[2])));
    let c =
        1.0 + x2 * (COS_SHORT[0] + x2 * (COS_SHORT[1] + x2 * (COS_SHORT[2] + x2 * COS_SHORT[3])));
    (s, c)
}

/// `sin x = x (1 + Σ SIN_SHORT[k] x^(2k+2))` on `[-π/4, π/4]`.
const SIN_SHORT: [f32; 3] = [-0.166_666_55, 0.008_332_18, -0.000_195_17];
/// `cos x = 1 + Σ COS_SHORT[k] x^(2k+2)` on `[-π/4, π/4]`.
const COS_SHORT: [f32; 4] = [-0.5, 0.041_666_623, -0.001_388_676_3, 2.439_045e-5];

/// `sin x = x (1 + Σ SIN[k] x^(2k+2))` on `[-π/2, π/2]`.
const SIN: [f32; 4] = [-0.166_666_48, 0.008_332_9, -0.000_198_008_97, 2.590_488e-6];
/// `cos x = 1 + Σ COS[k] x^(2k+2)` on `[-π/2, π/2]`.
const COS: [f32; 5] = [
    -0.5,
    0.041_666_638,
    -0.001_388_836_2,
    2.476_016_2e-5,
    -2.605_149_2e-7,
];

/// The lesser of `a` and `b`, inline: `f32::min` is an out-of-line
/// `fminf` call on a Cortex-M4 (no `VMINNM`). Not NaN-aware; the callers
/// compare finite values.
#[inline(always)]
pub(crate) fn min(a: f32, b: f32) -> f32 {
    if b < a { b } else { a }
}

/// The greater of `a` and `b`, inline (see [`min`]).
#[inline(always)]
pub(crate) fn max(a: f32, b: f32) -> f32 {
    if b > a { b } else { a }
}

/// The point `a + t (b − a)` of the segment from `a` to `b` (m), per
/// entry.
pub(crate) fn between<const L: usize>(a: &[f32; L], b: &[f32; L], t: f32) -> [f32; L] {
    let mut out = [0.0; L];
    between_into(a, b, t, &mut out);
    out
}

/// [`between`] into `out` (in place: a line's continuation is 256 B).
pub(crate) fn between_into<const L: usize>(a: &[f32; L], b: &[f32; L], t: f32, out: &mut [f32; L]) {
    for ((o, &ai), &bi) in out.iter_mut().zip(a).zip(b) {
        *o = ai + t * (bi - ai);
    }
}

/// Degrees to radians, as f32.
pub(crate) const DEG: f32 = core::f32::consts::PI / 180.0;

/// `v` clamped to `[-limit, limit]` (NaN stays NaN).
#[inline(always)]
pub(crate) fn clamp(v: f32, limit: f32) -> f32 {
    if v > limit {
        limit
    } else if v < -limit {
        -limit
    } else {
        v
    }
}

/// Sorts `v` ascending by `f32::total_cmp`: a heapsort written with
/// checked accesses only, so no panic path reaches the firmware
/// (`core`'s sorts keep one for inconsistent orders, which the link-time
/// proof of the C library cannot see past). Equal keys have equal bits,
/// so the result is the one any correct sort gives.
pub(crate) fn sort_total(v: &mut [f32]) {
    let n = v.len();
    let mut start = n / 2;
    while start > 0 {
        start = start.saturating_sub(1);
        sift_down(v, start, n);
    }
    let mut end = n;
    while end > 1 {
        end = end.saturating_sub(1);
        swap(v, 0, end);
        sift_down(v, 0, end);
    }
}

/// Swaps `v[i]` and `v[j]` when both exist.
fn swap(v: &mut [f32], i: usize, j: usize) {
    if let (Some(&a), Some(&b)) = (v.get(i), v.get(j)) {
        if let Some(x) = v.get_mut(i) {
            *x = b;
        }
        if let Some(y) = v.get_mut(j) {
            *y = a;
        }
    }
}

/// Restores the max-heap below `root` within `v[..end]`.
fn sift_down(v: &mut [f32], mut root: usize, end: usize) {
    let key = |v: &[f32], i: usize| v.get(i).copied().unwrap_or(f32::NAN);
    loop {
        let Some(child) = root.checked_mul(2).and_then(|c| c.checked_add(1)) else {
            return;
        };
        if child >= end {
            return;
        }
        let right = child.saturating_add(1);
        let big = if right < end && key(v, child).total_cmp(&key(v, right)).is_lt() {
            right
        } else {
            child
        };
        if key(v, root).total_cmp(&key(v, big)).is_ge() {
            return;
        }
        swap(v, root, big);
        root = big;
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
        // Across zero (a depth at the surface), where Fast2Sum's magnitude
        // condition fails for a step or two: still within 1e-6 m.
        let mut comp = Comp::new(-3.0);
        let mut exact = -3.0_f64;
        for k in 0..400 {
            let v = if k < 300 { 0.1499 } else { -0.1501 };
            comp = comp.add(v);
            exact += f64::from(v);
            let held = f64::from(comp.hi) + f64::from(comp.lo);
            assert!((held - exact).abs() < 1e-6, "at {k}: {held} vs {exact}");
        }
    }

    #[test]
    fn kahan_sum() {
        // 1e8 then a million ones: plain f32 would stay at 1e8.
        let mut s = Sum::default();
        s.add(1.0e8);
        for _ in 0..1_000_000 {
            s.add(1.0);
        }
        assert!(
            (f64::from(s.value()) - 1.01e8).abs() <= 8.0,
            "{}",
            s.value()
        );
    }

    #[test]
    fn sin_cos_polynomial_error_bound() {
        let n = 200_000;
        let (mut es, mut ec) = (0.0_f64, 0.0_f64);
        for i in 0..=n {
            let x = -core::f32::consts::FRAC_PI_2 + core::f32::consts::PI * (i as f32) / (n as f32);
            let (s, c) = sin_cos(x);
            let xd = f64::from(x);
            es = es.max((f64::from(s) - libm::sin(xd)).abs());
            ec = ec.max((f64::from(c) - libm::cos(xd)).abs());
        }
        assert!(es <= 1.8e-7, "sin error {es:e}");
        assert!(ec <= 1.3e-7, "cos error {ec:e}");
        // The short pair, on the range the simulation's fast path uses.
        let (mut es, mut ec) = (0.0_f64, 0.0_f64);
        for i in 0..=n {
            let x = -SHORT + 2.0 * SHORT * (i as f32) / (n as f32);
            let (s, c) = sin_cos_short(x);
            let xd = f64::from(x);
            es = es.max((f64::from(s) - libm::sin(xd)).abs());
            ec = ec.max((f64::from(c) - libm::cos(xd)).abs());
        }
        assert!(es <= 1.0e-7, "short sin error {es:e}");
        assert!(ec <= 1.0e-7, "short cos error {ec:e}");
        // Exact where it matters most, and NaN outside the range.
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        let (s, c) = sin_cos(2.0);
        assert!(s.is_nan() && c.is_nan());
        let (s, c) = sin_cos(f32::NAN);
        assert!(s.is_nan() && c.is_nan());
    }

    #[test]
    fn the_square_decides_short_exactly() {
        // Both sides of the limit, a few ulps out, both signs.
        let mut x = SHORT;
        for _ in 0..8 {
            x = f32::from_bits(x.to_bits() - 1);
        }
        for _ in 0..17 {
            for v in [x, -x] {
                assert_eq!(v * v <= SHORT_SQ, v.abs() <= SHORT, "{v}");
            }
            x = f32::from_bits(x.to_bits() + 1);
        }
        let nan = core::hint::black_box(f32::NAN);
        assert_eq!((nan * nan).partial_cmp(&SHORT_SQ), None);
    }

    #[test]
    fn clamp_is_symmetric() {
        assert_eq!(clamp(3.0, 2.0), 2.0);
        assert_eq!(clamp(-3.0, 2.0), -2.0);
        assert_eq!(clamp(1.0, 2.0), 1.0);
        assert!(clamp(f32::NAN, 2.0).is_nan());
    }

    #[test]
    fn sort_total_sorts_as_core_does() {
        // Random lengths and values (a small LCG), with duplicates, signed
        // zeros and infinities: the same order as `sort_unstable_by`.
        let mut seed = 12345_u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            seed
        };
        for len in 0..70 {
            let mut buf = [0.0_f32; 70];
            for x in buf.iter_mut().take(len) {
                *x = match next() % 9 {
                    0 => 0.0,
                    1 => -0.0,
                    2 => f32::INFINITY,
                    3 => f32::NEG_INFINITY,
                    4 => 7.0,
                    _ => (next() % 2000) as f32 * 0.37 - 300.0,
                };
            }
            let mut want = buf;
            want[..len].sort_unstable_by(f32::total_cmp);
            sort_total(&mut buf[..len]);
            for (a, b) in buf.iter().zip(&want) {
                assert_eq!(a.to_bits(), b.to_bits(), "len {len}");
            }
        }
    }
}
