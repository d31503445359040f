//! Matrix exponential and zero-order-hold integral, in f32, without `std`.
//!
//! nalgebra's `exp()` needs `std`, so the ZOH discretization of the plant
//! has its own: scaling and squaring (Moler & Van Loan, "Nineteen dubious
//! ways…", method 3) with a Taylor kernel, in the `expm1` form. We never form
//! `I + E` until the end: for a slow plant sampled at 0.1 s, `exp(A Ts)` is
//! the identity plus entries of 1e-4, and squaring `I + E` in f32 would wipe
//! out the relative accuracy of those small entries. Squaring `E` as
//! `E <- (2I + E) E` keeps it.

use nalgebra::SMatrix;

/// Scale until `||X||_1 <= THETA`; the Taylor tail is then below
/// `THETA^(ORDER+2) / (ORDER+2)! ≈ 2e-13`, far below f32 resolution.
const THETA: f32 = 0.5;
/// Taylor order of the `φ1` kernel.
const ORDER: u8 = 10;
/// At most this many squarings (`||A Ts||_1 <= 0.5 · 2^40`).
const MAX_SQUARINGS: u8 = 40;

/// The exponential `exp(m)` of a square matrix.
///
/// Returns `None` when `m` is not finite or its norm is beyond
/// `0.5 · 2^40`, where f32 cannot represent the result meaningfully.
#[cfg(test)]
pub(crate) fn expm<const N: usize>(m: &SMatrix<f32, N, N>) -> Option<SMatrix<f32, N, N>> {
    let (e, _) = expm1_phi1(m, 1.0)?;
    Some(SMatrix::identity() + e)
}

/// Zero-order-hold discretization of `dη/dt = A η + B δ` over `ts` seconds:
/// returns `(Ad, Bd) = (exp(A ts), ∫_0^ts exp(A τ) dτ · B)`.
///
/// Returns `None` when the inputs are not finite or `||A ts||` is too large.
pub(crate) fn zoh<const N: usize>(
    a: &SMatrix<f32, N, N>,
    b: &SMatrix<f32, N, 1>,
    ts: f32,
) -> Option<(SMatrix<f32, N, N>, SMatrix<f32, N, 1>)> {
    let (e, f) = expm1_phi1(&(a * ts), ts)?;
    let ad = SMatrix::identity() + e;
    let bd = f * b;
    (ad.iter().chain(bd.iter()).all(|v| v.is_finite())).then_some((ad, bd))
}

/// `(exp(X) - I, h · φ1(X))` with `φ1(X) = Σ X^k/(k+1)!`, by scaling and
/// squaring. With `X = A ts`, `ts · φ1(X) = ∫_0^ts exp(A τ) dτ`.
fn expm1_phi1<const N: usize>(
    x: &SMatrix<f32, N, N>,
    ts: f32,
) -> Option<(SMatrix<f32, N, N>, SMatrix<f32, N, N>)> {
    if !ts.is_finite() || !x.iter().all(|v| v.is_finite()) {
        return None;
    }
    let mut norm = one_norm(x);
    let mut scale = 1.0_f32;
    let mut squarings = 0_u8;
    while norm > THETA {
        if squarings >= MAX_SQUARINGS {
            return None;
        }
        norm *= 0.5;
        scale *= 0.5;
        squarings = squarings.saturating_add(1);
    }
    let xs = x * scale;
    let h = ts * scale;
    let eye = SMatrix::<f32, N, N>::identity();
    // Horner: φ1 = I + X/2 (I + X/3 (I + … (I + X/(ORDER+1)))).
    let mut phi = eye;
    let mut k = ORDER.saturating_add(1);
    while k >= 2 {
        phi = eye + xs * phi * (1.0 / f32::from(k));
        k = k.saturating_sub(1);
    }
    let mut e = xs * phi;
    let mut f = phi * h;
    // Doubling: exp(2X) - I = (2I + E) E and ∫_0^{2h} = (2I + E) ∫_0^h.
    for _ in 0..squarings {
        let t = eye * 2.0 + e;
        f = t * f;
        e = t * e;
    }
    Some((e, f))
}

/// Induced 1-norm: the largest column sum of absolute values.
fn one_norm<const N: usize>(m: &SMatrix<f32, N, N>) -> f32 {
    m.column_iter()
        .map(|c| c.iter().map(|v| libm::fabsf(*v)).sum::<f32>())
        .fold(0.0, f32::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix3};

    fn close(a: f32, b: f32, rel: f32) -> bool {
        (a - b).abs() <= rel * b.abs().max(1e-30)
    }

    #[test]
    fn diagonal() {
        let m = Matrix2::new(1.0, 0.0, 0.0, -3.0);
        let e = expm(&m).unwrap();
        assert!(close(e[(0, 0)], core::f32::consts::E, 1e-6));
        assert!(close(e[(1, 1)], libm::expf(-3.0), 1e-6));
        assert_eq!(e[(0, 1)], 0.0);
    }

    #[test]
    fn rotation_needs_squaring() {
        // exp([[0, -w], [w, 0]]) is a rotation by w radians; w = 5 needs
        // four squarings.
        let w = 5.0_f32;
        let e = expm(&Matrix2::new(0.0, -w, w, 0.0)).unwrap();
        let (s, c) = (libm::sinf(w), libm::cosf(w));
        assert!((e[(0, 0)] - c).abs() < 2e-6);
        assert!((e[(1, 0)] - s).abs() < 2e-6);
        assert!((e[(0, 1)] + s).abs() < 2e-6);
    }

    #[test]
    fn nilpotent_is_exact() {
        let m = Matrix3::new(0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0);
        let e = expm(&m).unwrap();
        assert_eq!(e, Matrix3::new(1.0, 1.0, 0.5, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0));
    }

    #[test]
    fn zoh_of_a_first_order_lag() {
        // dη/dt = -a η + δ: Ad = e^{-a T}, Bd = (1 - e^{-a T}) / a.
        let a = 0.7_f32;
        let t = 3.0_f32;
        let (ad, bd) = zoh(
            &SMatrix::<f32, 1, 1>::new(-a),
            &SMatrix::<f32, 1, 1>::new(1.0),
            t,
        )
        .unwrap();
        assert!(close(ad[0], libm::expf(-a * t), 1e-6));
        assert!(close(bd[0], (1.0 - libm::expf(-a * t)) / a, 1e-6));
    }

    #[test]
    fn zoh_of_a_double_integrator_keeps_small_entries() {
        // η = [v, p]: Ad = [[1,0],[T,1]], Bd = [T, T²/2], exactly.
        let m = Matrix2::new(0.0, 0.0, 1.0, 0.0);
        let t = 1e-3_f32;
        let (ad, bd) = zoh(&m, &nalgebra::Vector2::new(1.0, 0.0), t).unwrap();
        assert!(close(ad[(1, 0)], t, 1e-7));
        assert!(close(bd[1], t * t / 2.0, 1e-6));
    }

    #[test]
    fn refuses_non_finite_and_huge() {
        assert!(expm(&Matrix2::new(f32::NAN, 0.0, 0.0, 0.0)).is_none());
        assert!(expm(&Matrix2::new(1e30, 0.0, 0.0, 0.0)).is_none());
    }
}
