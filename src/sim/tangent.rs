//! Exact gradient of the objective by forward sensitivity.
//!
//! The simulation is a deterministic map from the reference depths
//! `ζ = (z_first .. z_first+K-1)` to the samples, and `J` a smooth function
//! of the samples. Differentiating every step of the discrete loop
//! (the chain rule, forward) propagates `K` tangent states
//! `∂(η, d, d_prev, x, x_prev, I_d, I_θ)/∂ζ` alongside the simulation, in
//! the same pass:
//!
//! ```text
//! ∂r_k/∂z_j   = 1 on track j, else 0
//! ∂e_d        = ∂r − ∂d,                ∂ḋ = (∂d − ∂d_prev) / Ts
//! ∂v          = −(Kpd ∂e_d + Kid ∂I_d − Kdd ∂ḋ),   ∂θref = ∂v if unclamped, else 0
//! ∂e_θ        = ∂θref − C ∂η
//! ∂w          = σ (Kpθ ∂e_θ + Kiθ ∂I_θ − Kdθ CA ∂η), ∂δ = ∂w if unclamped, else 0
//! ∂I          += Ts ∂e   where the integrator integrated
//! ∂η'         = Ad ∂η + Bd ∂δ
//! ∂θ̄          = (C ∂η + C ∂η') / 2 · π/180
//! ∂d'         = ∂d − U0 Ts cos θ̄ ∂θ̄,     ∂x' = ∂x − U0 Ts sin θ̄ ∂θ̄
//! ```
//!
//! and each scored piece `L (e_lo² + e_hi²) / 4` contributes
//! `∂L (e_lo² + e_hi²) / 4 + L (e_lo ∂e_lo + e_hi ∂e_hi) / 2`, where
//! `∂e = b'(x) ∂x − ∂d` at a sample and, at a waypoint clip a fraction `t`
//! along the segment, `∂e = −[(1−t)(∂d0 − Δd/Δx ∂x0) + t (∂d1 − Δd/Δx ∂x1)]`.
//!
//! This is the gradient of the discrete simulation itself, exact up to f32
//! rounding, wherever the simulation is differentiable: it is not defined
//! at the isolated depths where a sample lands exactly on a waypoint or a
//! clamp's edge, and it is exactly zero on the plateaus where the pitch
//! reference stays saturated over a whole track (contract §10).

use nalgebra::{SMatrix, SVector};

use crate::model::Vehicle;
use crate::num::DEG;

use super::lin::{EndAt, PieceLin, Sensitivity, StepLin};
use super::{Scenario, SimError, TrackScore, VehicleState};

/// Tangents of the state with respect to `K` reference depths, and the
/// accumulated gradients.
struct Tangents<const N: usize, const K: usize> {
    eta: SMatrix<f32, N, K>,
    d: SVector<f32, K>,
    d_prev: SVector<f32, K>,
    x: SVector<f32, K>,
    x_prev: SVector<f32, K>,
    depth_integral: SVector<f32, K>,
    pitch_integral: SVector<f32, K>,
    grad_j: SVector<f32, K>,
    grad_violation: SVector<f32, K>,
}

impl<const N: usize, const K: usize> Tangents<N, K> {
    /// The start state does not depend on `ζ`: every tangent is zero.
    fn zero() -> Self {
        Self {
            eta: SMatrix::zeros(),
            d: SVector::zeros(),
            d_prev: SVector::zeros(),
            x: SVector::zeros(),
            x_prev: SVector::zeros(),
            depth_integral: SVector::zeros(),
            pitch_integral: SVector::zeros(),
            grad_j: SVector::zeros(),
            grad_violation: SVector::zeros(),
        }
    }

    /// `∂e` at a piece end.
    #[inline(always)]
    fn de(&self, at: EndAt, slope_ratio: f32) -> SVector<f32, K> {
        match at {
            EndAt::Start { slope } => self.x_prev * slope - self.d_prev,
            EndAt::End { slope } => self.x * slope - self.d,
            EndAt::Clip { t } => {
                -((self.d_prev - self.x_prev * slope_ratio) * (1.0 - t)
                    + (self.d - self.x * slope_ratio) * t)
            }
        }
    }

    /// `∂x` at a piece end (zero at a fixed waypoint).
    #[inline(always)]
    fn dx(&self, at: EndAt) -> SVector<f32, K> {
        match at {
            EndAt::Start { .. } => self.x_prev,
            EndAt::End { .. } => self.x,
            EndAt::Clip { .. } => SVector::zeros(),
        }
    }
}

impl<const N: usize, const K: usize> Sensitivity<N> for Tangents<N, K> {
    #[inline(always)]
    fn step(&mut self, v: &Vehicle<N>, lin: &StepLin) {
        let plant = v.plant();
        let ap = v.autopilot();
        let cfg = ap.config();
        let ts = plant.sample_time();
        let (gd, gt) = (&cfg.depth_pid, &cfg.pitch_pid);

        let pitch = plant.pitch_of(&self.eta);
        let pitch_rate = plant.pitch_rate_of(&self.eta);
        let mut e_d = -self.d;
        if let Some(r) = e_d.get_mut(lin.slot) {
            *r += 1.0;
        }
        let rate = (self.d - self.d_prev) / ts;
        let v_ = -(e_d * gd.kp + self.depth_integral * gd.ki - rate * gd.kd);
        let pitch_ref = if lin.command.pitch_ref_linear {
            v_
        } else {
            SVector::zeros()
        };
        let e_t = pitch_ref - pitch;
        let w = (e_t * gt.kp + self.pitch_integral * gt.ki - pitch_rate * gt.kd) * ap.loop_sign();
        let elevator = if lin.command.elevator_linear {
            w
        } else {
            SVector::zeros()
        };
        if lin.command.depth_integrating {
            self.depth_integral += e_d * ts;
        }
        if lin.command.pitch_integrating {
            self.pitch_integral += e_t * ts;
        }
        self.eta = plant.ad_m() * self.eta + plant.bd_v() * elevator.transpose();
        let pitch_next = plant.pitch_of(&self.eta);
        let mean = (pitch + pitch_next) * (0.5 * DEG);
        let step = lin.step;
        self.d_prev = self.d;
        self.x_prev = self.x;
        self.d -= mean * (step * lin.cos);
        self.x -= mean * (step * lin.sin);
    }

    #[inline(always)]
    fn piece(&mut self, _slot: usize, p: &PieceLin) {
        let ratio = p.dd / p.dx;
        let de_lo = self.de(p.lo.at, ratio);
        let de_hi = self.de(p.hi.at, ratio);
        let dlen = self.dx(p.hi.at) - self.dx(p.lo.at);
        self.grad_j += dlen * (0.25 * (p.lo.e * p.lo.e + p.hi.e * p.hi.e))
            + (de_lo * p.lo.e + de_hi * p.hi.e) * (0.5 * p.len);
        // p = max(0, h_a − h) and e = h − h_r, so ∂p = −∂e where p > 0.
        let dp_lo = if p.lo.p > 0.0 {
            -de_lo
        } else {
            SVector::zeros()
        };
        let dp_hi = if p.hi.p > 0.0 {
            -de_hi
        } else {
            SVector::zeros()
        };
        self.grad_violation += dlen * (0.25 * (p.lo.p * p.lo.p + p.hi.p * p.hi.p))
            + (dp_lo * p.lo.p + dp_hi * p.hi.p) * (0.5 * p.len);
    }
}

/// Value and exact gradient of a run over `K` consecutive tracks.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Evaluation<const N: usize, const K: usize> {
    /// Score of each track.
    pub scores: [TrackScore; K],
    /// `Σ J` over the `K` tracks, m³.
    pub j: f32,
    /// `Σ` violation over the `K` tracks, m³ (see [`TrackScore::violation`]).
    pub violation: f32,
    /// Least altitude over the `K` tracks, m.
    pub min_altitude: f32,
    /// `∂(Σ J)/∂z_j`, m³/m = m².
    pub grad_j: [f32; K],
    /// `∂(Σ violation)/∂z_j`, m².
    pub grad_violation: [f32; K],
    /// The state at the first sample past the last track.
    pub end: VehicleState<N>,
}

impl<const N: usize> Scenario<'_, N> {
    /// Flies tracks `first_track..first_track + K` with reference depths
    /// `depths` (m) from `start`, and returns the scores with the exact
    /// gradient of `Σ J` and of the violation with respect to the depths.
    ///
    /// # Errors
    /// As [`Scenario::simulate`]; also [`SimError::Diverged`] if a
    /// gradient entry is not finite.
    pub fn evaluate<const K: usize>(
        &self,
        start: &VehicleState<N>,
        first_track: usize,
        depths: &[f32; K],
    ) -> Result<Evaluation<N, K>, SimError> {
        self.evaluate_tracks(start, first_track, depths, K)
    }

    /// As [`Scenario::evaluate`], over the first `count <= K` of the depths
    /// only (a horizon cut short by the end of the line): the remaining
    /// entries are ignored, their gradients are zero and their scores
    /// default.
    ///
    /// # Errors
    /// As [`Scenario::evaluate`]; [`SimError::TrackRange`] when `count` is 0
    /// or above `K`.
    pub fn evaluate_tracks<const K: usize>(
        &self,
        start: &VehicleState<N>,
        first_track: usize,
        depths: &[f32; K],
        count: usize,
    ) -> Result<Evaluation<N, K>, SimError> {
        let used = depths.get(..count).ok_or(SimError::TrackRange)?;
        let mut scores = [TrackScore::default(); K];
        let mut tan = Tangents::<N, K>::zero();
        let end =
            self.run::<_, _, true>(start, first_track, used, &mut scores, &mut tan, |_| {})?;
        let grad_j: [f32; K] = tan.grad_j.into();
        let grad_violation: [f32; K] = tan.grad_violation.into();
        if !grad_j.iter().chain(&grad_violation).all(|g| g.is_finite()) {
            return Err(SimError::Diverged);
        }
        let used_scores = scores.get(..count).unwrap_or(&[]);
        let j: f32 = used_scores.iter().map(TrackScore::j).sum();
        let violation: f32 = used_scores.iter().map(TrackScore::violation).sum();
        let min_altitude = used_scores
            .iter()
            .map(TrackScore::min_altitude)
            .fold(f32::INFINITY, f32::min);
        if !(j.is_finite() && violation.is_finite() && min_altitude.is_finite()) {
            return Err(SimError::Diverged);
        }
        Ok(Evaluation {
            scores,
            j,
            violation,
            min_altitude,
            grad_j,
            grad_violation,
            end,
        })
    }
}
