//! Pitch dynamics: the vehicle's identified transfer function, realized and
//! discretized exactly as the autopilot's sample-and-hold sees it.
//!
//! A `θ(s)/δ(s) = N(s)/D(s)` (deg/deg) with `D(s) = s^n + a1 s^(n-1) + … +
//! an` of order `n <= N` becomes the *observability* canonical form, whose
//! states are the pitch, the pitch rate and (from the third on) higher
//! derivatives less their input terms:
//!
//! ```text
//!       |  0   1   0  …  0  |        | h1 |
//!   A = |  0   0   1  …  0  |    B = | h2 |    C = [1 0 … 0],  θ = η1,  q = C A η = η2
//!       |  …            1   |        | …  |
//!       | -an  …  -a2  -a1  |        | hn |
//! ```
//!
//! with `h1..hn` the first Markov parameters of `N/D` (`h1 = b1`,
//! `hk = bk − Σ_{i<k} ai h(k−i)`). `deg N <= n - 2` makes `h1 = C B = 0`, so
//! the pitch rate has no direct feed-through from the elevator (model
//! contract §4) and is exactly the second state. The model contract allows
//! any minimal realization; this one makes the autopilot's two
//! measurements free (no `C η`, `C A η` products in the simulation loop).
//! It is minimal when `N` and `D` have no common root. Every realization of
//! the same `N/D` has the same Markov parameters `C Ad^k Bd`, which is how
//! the tests compare it with the f64 reference's (scipy's `tf2ss`) form.
//! When `n < N` the last `N - n` states are padding: zero rows and columns,
//! they stay exactly zero. Discretization is the exact zero-order hold,
//! computed in f32 by [`super::expm::zoh`].

use core::fmt;

use nalgebra::{SMatrix, SVector};

use super::expm;

/// Why a transfer function or its discretization was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PlantError {
    /// A coefficient is NaN or infinite.
    NonFinite,
    /// The denominator is empty or all zero, or of order zero.
    NoDynamics,
    /// The denominator's order exceeds the capacity `N`.
    OrderTooHigh {
        /// The denominator's order.
        order: usize,
        /// The capacity `N`.
        capacity: usize,
    },
    /// `deg N > deg D - 2`: the pitch rate would feed through directly.
    RelativeDegree {
        /// Degree of the `θ/δ` numerator.
        num_degree: usize,
        /// Degree of the denominator.
        den_degree: usize,
    },
    /// A `q/δ` numerator whose constant term is not zero cannot be divided
    /// by `s` (the rate form must have a zero at the origin).
    RateNumeratorNotDivisible,
    /// `N(0) = 0`: the elevator has no steady effect on pitch, so the
    /// sign of the pitch loop is undefined.
    NoSteadyGain,
    /// The sample time is not positive and finite.
    SampleTime,
    /// `exp(A Ts)` could not be computed in f32 (`||A Ts||` too large).
    Discretization,
}

impl fmt::Display for PlantError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::NonFinite => f.write_str("plant coefficient is not finite"),
            Self::NoDynamics => f.write_str("plant denominator has no dynamics (order 0)"),
            Self::OrderTooHigh { order, capacity } => write!(
                f,
                "plant order {order} exceeds the model capacity {capacity}"
            ),
            Self::RelativeDegree {
                num_degree,
                den_degree,
            } => write!(
                f,
                "plant relative degree below 2 (theta/delta numerator degree {num_degree}, denominator degree {den_degree})"
            ),
            Self::RateNumeratorNotDivisible => {
                f.write_str("rate-form (q/delta) numerator must have a zero constant term")
            }
            Self::NoSteadyGain => {
                f.write_str("plant numerator N(0) is zero: the pitch loop sign is undefined")
            }
            Self::SampleTime => f.write_str("sample time must be positive and finite"),
            Self::Discretization => {
                f.write_str("plant cannot be discretized in f32 (|A Ts| too large)")
            }
        }
    }
}

impl core::error::Error for PlantError {}

/// Which quantity a transfer function's output is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TfKind {
    /// `θ(s)/δ(s)`, pitch (deg) per elevator (deg).
    Pitch,
    /// `q(s)/δ(s)`, pitch rate (deg/s) per elevator (deg): the paper's form.
    /// Its numerator's constant term must be zero; it is divided by `s`.
    Rate,
}

/// A validated `θ(s)/δ(s)` of order `n <= N`, denominator made monic.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TransferFunction<const N: usize> {
    order: usize,
    /// `a1..an` of `D(s) = s^n + a1 s^(n-1) + … + an`, padded with zeros.
    den: [f32; N],
    /// `b1..bn` of `N(s) = b1 s^(n-1) + … + bn` (`b1 = 0`), padded.
    num: [f32; N],
}

impl TransferFunction<3> {
    /// NMRI C-AUV #4, identified in the paper:
    /// `θ/δ = -0.173 / (s³ + 2.681 s² + 0.546 s + 0.048)`, DC gain −3.604.
    pub const C_AUV4: Self = Self {
        order: 3,
        den: [2.681, 0.546, 0.048],
        num: [0.0, 0.0, -0.173],
    };
}

impl<const N: usize> TransferFunction<N> {
    /// `θ(s)/δ(s)` from coefficients, highest power first (deg/deg).
    ///
    /// Leading zeros are ignored and the denominator is made monic.
    ///
    /// # Errors
    /// [`PlantError`] for non-finite coefficients, an order of 0 or above
    /// `N`, a relative degree below 2, or `N(0) = 0`.
    pub fn pitch(num: &[f32], den: &[f32]) -> Result<Self, PlantError> {
        const { assert!(N >= 1, "the model order capacity must be at least 1") };
        if !num.iter().chain(den).all(|v| v.is_finite()) {
            return Err(PlantError::NonFinite);
        }
        let num = strip_leading_zeros(num);
        let den = strip_leading_zeros(den);
        let (&lead, rest) = den.split_first().ok_or(PlantError::NoDynamics)?;
        let order = rest.len();
        if order == 0 {
            return Err(PlantError::NoDynamics);
        }
        if order > N {
            return Err(PlantError::OrderTooHigh { order, capacity: N });
        }
        let num_degree = num.len().saturating_sub(1);
        if num.len() > order.saturating_sub(1) {
            return Err(PlantError::RelativeDegree {
                num_degree,
                den_degree: order,
            });
        }
        let mut tf = Self {
            order,
            den: [0.0; N],
            num: [0.0; N],
        };
        for (slot, &a) in tf.den.iter_mut().zip(rest) {
            *slot = a / lead;
        }
        // num right-aligned in b1..bn.
        let pad = order.saturating_sub(num.len());
        for (slot, &b) in tf.num.iter_mut().skip(pad).zip(num) {
            *slot = b / lead;
        }
        if !tf.den.iter().chain(&tf.num).all(|v| v.is_finite()) {
            return Err(PlantError::NonFinite);
        }
        if tf.steady_num() == 0.0 {
            return Err(PlantError::NoSteadyGain);
        }
        Ok(tf)
    }

    /// `q(s)/δ(s)` (deg/s per deg), highest power first; the numerator's
    /// constant term must be zero and is divided out (`θ = q / s`).
    ///
    /// # Errors
    /// [`PlantError::RateNumeratorNotDivisible`] when the constant term is
    /// not zero, otherwise as [`TransferFunction::pitch`].
    pub fn rate(num: &[f32], den: &[f32]) -> Result<Self, PlantError> {
        if !num.iter().all(|v| v.is_finite()) {
            return Err(PlantError::NonFinite);
        }
        match num.split_last() {
            Some((0.0, rest)) => Self::pitch(rest, den),
            Some(_) => Err(PlantError::RateNumeratorNotDivisible),
            None => Err(PlantError::NoSteadyGain),
        }
    }

    /// Either form, chosen explicitly (the forms are never guessed).
    ///
    /// # Errors
    /// As [`TransferFunction::pitch`] or [`TransferFunction::rate`].
    pub fn new(kind: TfKind, num: &[f32], den: &[f32]) -> Result<Self, PlantError> {
        match kind {
            TfKind::Pitch => Self::pitch(num, den),
            TfKind::Rate => Self::rate(num, den),
        }
    }

    /// Order `n` of the denominator.
    pub fn order(&self) -> usize {
        self.order
    }

    /// `a1..an` of the monic denominator (the first `n` entries matter).
    pub fn denominator(&self) -> &[f32; N] {
        &self.den
    }

    /// `b1..bn` of the numerator over the monic denominator.
    pub fn numerator(&self) -> &[f32; N] {
        &self.num
    }

    /// DC gain `N(0)/D(0)`, deg/deg; `None` for a plant with an integrator
    /// (`D(0) = 0`).
    pub fn dc_gain(&self) -> Option<f32> {
        let d0 = self.coef(&self.den, self.order);
        (d0 != 0.0).then(|| self.steady_num() / d0)
    }

    /// Sign of the low-frequency gain: `sign(N(0))` times the sign of the
    /// lowest-order non-zero coefficient of `D`. It is −1 for the paper's
    /// plant, where the pitch loop carries a leading minus sign; +1 flips
    /// the loop and its anti-windup test (model contract §5).
    pub fn loop_sign(&self) -> f32 {
        let low_den = (1..=self.order)
            .rev()
            .map(|i| self.coef(&self.den, i))
            .find(|&a| a != 0.0)
            .unwrap_or(1.0);
        if (self.steady_num() < 0.0) == (low_den < 0.0) {
            1.0
        } else {
            -1.0
        }
    }

    /// `bn = N(0)`.
    fn steady_num(&self) -> f32 {
        self.coef(&self.num, self.order)
    }

    /// Coefficient `i` (1-based) of a padded array, 0 when absent.
    fn coef(&self, arr: &[f32; N], i: usize) -> f32 {
        i.checked_sub(1)
            .and_then(|j| arr.get(j))
            .copied()
            .unwrap_or(0.0)
    }

    /// The continuous state-space matrices `(A, B, C)` of the observability
    /// canonical form (module docs): `A` (row-major) in 1/s, `B` in state
    /// per deg of elevator per second, `C` the pitch row `e1`.
    pub fn realization(&self) -> ([[f32; N]; N], [f32; N], [f32; N]) {
        let (a, b, c) = self.realization_m();
        (rows(&a), b.into(), c.into())
    }

    /// [`TransferFunction::realization`] in nalgebra's types.
    pub(crate) fn realization_m(&self) -> (SMatrix<f32, N, N>, SVector<f32, N>, SVector<f32, N>) {
        let n = self.order;
        let mut a = SMatrix::<f32, N, N>::zeros();
        for i in 1..n {
            if let Some(v) = a.get_mut((i.saturating_sub(1), i)) {
                *v = 1.0;
            }
        }
        // Last row: -an … -a1.
        let last = n.saturating_sub(1);
        for (j, &aj) in self.den.iter().enumerate().take(n) {
            if let Some(v) = a.get_mut((last, last.saturating_sub(j))) {
                *v = -aj;
            }
        }
        // Markov parameters: h_k = b_k − Σ_{i=1}^{k−1} a_i h_{k−i}.
        let mut b = SVector::<f32, N>::zeros();
        for k in 0..n {
            let mut h = self.num.get(k).copied().unwrap_or(0.0);
            for i in 0..k {
                let ai = self.den.get(i).copied().unwrap_or(0.0);
                let hk = b
                    .get(k.saturating_sub(i).saturating_sub(1))
                    .copied()
                    .unwrap_or(0.0);
                h -= ai * hk;
            }
            if let Some(v) = b.get_mut(k) {
                *v = h;
            }
        }
        let mut c = SVector::<f32, N>::zeros();
        if let Some(v) = c.get_mut(0) {
            *v = 1.0;
        }
        (a, b, c)
    }
}

fn strip_leading_zeros(c: &[f32]) -> &[f32] {
    let first = c.iter().position(|&v| v != 0.0).unwrap_or(c.len());
    c.get(first..).unwrap_or(&[])
}

/// The discretized plant: `η_{k+1} = Ad η_k + Bd δ_k`, `θ = C η`,
/// `q = C A η`, with `Ts` the autopilot's sample time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plant<const N: usize> {
    tf: TransferFunction<N>,
    sample_time: f32,
    a: SMatrix<f32, N, N>,
    ad: SMatrix<f32, N, N>,
    bd: SVector<f32, N>,
    c: SVector<f32, N>,
    ca: SVector<f32, N>,
}

#[cfg(feature = "defmt")]
impl<const N: usize> defmt::Format for Plant<N> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "Plant {{ tf: {}, sample_time: {} s }}",
            self.tf,
            self.sample_time
        );
    }
}

impl<const N: usize> Plant<N> {
    /// Realizes `tf` and discretizes it by exact zero-order hold with sample
    /// time `sample_time` (s).
    ///
    /// # Errors
    /// [`PlantError::SampleTime`] for a non-positive or non-finite sample
    /// time, [`PlantError::Discretization`] when `exp(A Ts)` is not
    /// representable.
    pub fn new(tf: TransferFunction<N>, sample_time: f32) -> Result<Self, PlantError> {
        if !(sample_time.is_finite() && sample_time > 0.0) {
            return Err(PlantError::SampleTime);
        }
        let (a, b, c) = tf.realization_m();
        let (ad, bd) = expm::zoh(&a, &b, sample_time).ok_or(PlantError::Discretization)?;
        let ca = a.transpose() * c;
        Ok(Self {
            tf,
            sample_time,
            a,
            ad,
            bd,
            c,
            ca,
        })
    }

    /// The continuous transfer function.
    pub fn transfer_function(&self) -> &TransferFunction<N> {
        &self.tf
    }

    /// Sample time `Ts`, s.
    pub fn sample_time(&self) -> f32 {
        self.sample_time
    }

    /// Continuous state matrix `A`, 1/s, row-major.
    pub fn a(&self) -> [[f32; N]; N] {
        rows(&self.a)
    }

    /// `Ad = exp(A Ts)`, row-major.
    pub fn ad(&self) -> [[f32; N]; N] {
        rows(&self.ad)
    }

    /// `Bd = ∫_0^Ts exp(A τ) dτ B`, state per deg of elevator.
    pub fn bd(&self) -> [f32; N] {
        self.bd.into()
    }

    /// Output row `C` (pitch, deg, per state): `e1`.
    pub fn c(&self) -> [f32; N] {
        self.c.into()
    }

    /// `C A`: pitch rate, deg/s, per state: `e2`.
    pub fn ca(&self) -> [f32; N] {
        self.ca.into()
    }

    /// Pitch `θ = C η = η1`, deg, of a plant state `η`.
    pub fn pitch(&self, eta: &[f32; N]) -> f32 {
        eta.first().copied().unwrap_or(0.0)
    }

    /// Pitch rate `q = C A η = η2`, deg/s, of a plant state `η`.
    pub fn pitch_rate(&self, eta: &[f32; N]) -> f32 {
        eta.get(1).copied().unwrap_or(0.0)
    }

    /// One sample from plant state `η`: `Ad η + Bd δ` with the elevator
    /// `δ` (deg) held.
    pub fn step(&self, eta: &[f32; N], elevator: f32) -> [f32; N] {
        self.step_v(&SVector::from(*eta), elevator).into()
    }

    /// `Ad` as the simulation multiplies it.
    #[inline(always)]
    pub(crate) fn ad_m(&self) -> &SMatrix<f32, N, N> {
        &self.ad
    }

    /// `Bd` as the simulation multiplies it.
    #[inline(always)]
    pub(crate) fn bd_v(&self) -> &SVector<f32, N> {
        &self.bd
    }

    /// [`Plant::pitch`] on the simulation's vector type.
    #[inline(always)]
    pub(crate) fn pitch_v(&self, eta: &SVector<f32, N>) -> f32 {
        eta.get(0).copied().unwrap_or(0.0)
    }

    /// [`Plant::pitch_rate`] on the simulation's vector type.
    #[inline(always)]
    pub(crate) fn pitch_rate_v(&self, eta: &SVector<f32, N>) -> f32 {
        eta.get(1).copied().unwrap_or(0.0)
    }

    /// [`Plant::step`] on the simulation's vector type.
    #[inline(always)]
    // (`&self.ad`: by value, nalgebra copies `Ad` each step, a `memcpy`
    // call where the caller's inlining does not remove it.)
    #[allow(clippy::op_ref)]
    pub(crate) fn step_v(&self, eta: &SVector<f32, N>, elevator: f32) -> SVector<f32, N> {
        &self.ad * eta + self.bd.scale(elevator)
    }
}

/// A matrix as row-major arrays.
fn rows<const N: usize>(m: &SMatrix<f32, N, N>) -> [[f32; N]; N] {
    core::array::from_fn(|i| core::array::from_fn(|j| m.get((i, j)).copied().unwrap_or(0.0)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn c_auv4_constants_match_the_paper() {
        let tf = TransferFunction::<3>::pitch(&[-0.173], &[1.0, 2.681, 0.546, 0.048]).unwrap();
        assert_eq!(tf, TransferFunction::C_AUV4);
        let g = tf.dc_gain().unwrap();
        assert!((g + 3.604).abs() < 1e-3, "{g}");
        assert_eq!(tf.loop_sign(), -1.0);
    }

    #[test]
    fn rate_form_is_divided_by_s() {
        let r = TransferFunction::<3>::rate(&[-0.173, 0.0], &[1.0, 2.681, 0.546, 0.048]).unwrap();
        assert_eq!(r, TransferFunction::C_AUV4);
        assert_eq!(
            TransferFunction::<3>::rate(&[-0.173, 0.1], &[1.0, 2.681, 0.546, 0.048]),
            Err(PlantError::RateNumeratorNotDivisible)
        );
    }

    #[test]
    fn rejects_bad_transfer_functions() {
        let den = [1.0, 2.681, 0.546, 0.048];
        assert_eq!(
            TransferFunction::<3>::pitch(&[1.0, 0.0, -0.173], &den),
            Err(PlantError::RelativeDegree {
                num_degree: 2,
                den_degree: 3
            })
        );
        // deg N = 1 = n - 2 is allowed: C B = 0 still.
        let tf = TransferFunction::<3>::pitch(&[1.0, -0.173], &den).unwrap();
        let (_, b, c) = tf.realization_m();
        assert_eq!(c.dot(&b), 0.0);
        assert_eq!(
            TransferFunction::<2>::pitch(&[-0.173], &den),
            Err(PlantError::OrderTooHigh {
                order: 3,
                capacity: 2
            })
        );
        assert_eq!(
            TransferFunction::<3>::pitch(&[f32::NAN], &den),
            Err(PlantError::NonFinite)
        );
        assert_eq!(
            TransferFunction::<3>::pitch(&[1.0], &[0.0, 2.0]),
            Err(PlantError::NoDynamics)
        );
        assert_eq!(
            TransferFunction::<3>::pitch(&[1.0, 0.0], &[1.0, 1.0, 1.0]).unwrap_err(),
            PlantError::RelativeDegree {
                num_degree: 1,
                den_degree: 2
            }
        );
        assert_eq!(
            TransferFunction::<4>::pitch(&[1.0, 0.0], &[1.0, 1.0, 1.0, 1.0]),
            Err(PlantError::NoSteadyGain)
        );
    }

    #[test]
    fn lower_order_is_padded() {
        let tf = TransferFunction::<4>::pitch(&[-0.62], &[1.0, 1.45, 0.29]).unwrap();
        assert_eq!(tf.order(), 2);
        let p = Plant::new(tf, 0.1).unwrap();
        // Padding states neither move nor are driven.
        assert_eq!(p.ad()[2][2], 1.0);
        assert_eq!(p.ad()[3][3], 1.0);
        assert_eq!(p.bd()[2], 0.0);
        assert_eq!(p.ad()[0][2], 0.0);
    }

    #[test]
    fn realization_is_the_transfer_function() {
        // C (sI − A)⁻¹ B = N(s)/D(s) at a few real s, for a plant with a
        // numerator zero, padded into a larger capacity.
        let num = [0.3_f32, -0.5];
        let den = [1.0_f32, 2.0, 1.5, 0.4];
        let tf = TransferFunction::<4>::pitch(&num, &den).unwrap();
        let (a, b, c) = tf.realization_m();
        for s in [0.25_f32, 1.0, 3.0] {
            let m = SMatrix::<f32, 4, 4>::identity() * s - a;
            let x = m.try_inverse().unwrap() * b;
            let got = c.dot(&x);
            let n = num[0] * s + num[1];
            let d = ((den[0] * s + den[1]) * s + den[2]) * s + den[3];
            assert!(
                (got - n / d).abs() < 1e-5 * (n / d).abs(),
                "{s}: {got} vs {}",
                n / d
            );
        }
        // θ = η1, q = η2, and no feed-through (C B = 0).
        assert_eq!(c[0], 1.0);
        assert_eq!((a.transpose() * c)[1], 1.0);
        assert_eq!(c.dot(&b), 0.0);
    }

    #[test]
    fn steady_state_pitch_is_dc_gain() {
        let p = Plant::new(TransferFunction::C_AUV4, 0.1).unwrap();
        let mut eta = [0.0_f32; 3];
        for _ in 0..5000 {
            eta = p.step(&eta, 1.0);
        }
        assert!((p.pitch(&eta) + 3.604).abs() < 2e-3);
        assert!(p.pitch_rate(&eta).abs() < 1e-4);
    }

    #[test]
    fn integrator_plant_sign() {
        // θ/δ = -0.4 / (s (s + 1.1)): no DC gain, sign from 1.1 and -0.4.
        let tf = TransferFunction::<2>::pitch(&[-0.4], &[1.0, 1.1, 0.0]).unwrap();
        assert_eq!(tf.dc_gain(), None);
        assert_eq!(tf.loop_sign(), -1.0);
        let pos = TransferFunction::<2>::pitch(&[0.5], &[1.0, 1.2, 0.35]).unwrap();
        assert_eq!(pos.loop_sign(), 1.0);
    }
}
