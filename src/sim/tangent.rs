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

use nalgebra::SVector;

use crate::model::Vehicle;
use crate::num::DEG;

use super::lin::{EndAt, PieceLin, Sensitivity, StepLin};
use super::watch::{NoWatch, Watch, Watcher};
use super::{Scenario, SimError, TrackScore, VehicleState};

/// The tangent of the state with respect to one reference depth, and the
/// gradients it accumulates.
#[derive(Clone, Copy)]
struct Column<const N: usize> {
    eta: SVector<f32, N>,
    d: f32,
    d_prev: f32,
    x: f32,
    x_prev: f32,
    depth_integral: f32,
    pitch_integral: f32,
    grad_j: f32,
    grad_violation: f32,
}

impl<const N: usize> Column<N> {
    /// `∂e` at a piece end.
    #[inline(always)]
    fn de(&self, at: EndAt, slope_ratio: f32) -> f32 {
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
    fn dx(&self, at: EndAt) -> f32 {
        match at {
            EndAt::Start { .. } => self.x_prev,
            EndAt::End { .. } => self.x,
            EndAt::Clip { .. } => 0.0,
        }
    }
}

/// Tangents of the state with respect to `K` reference depths, one column
/// per depth. Depth `j`'s column is exactly zero until its track begins
/// (the start state and the earlier tracks do not depend on it), so each
/// step and piece updates only the columns of the tracks begun so far.
/// The watcher `W` sees every piece with the columns' `∂e` (`watch.rs`).
struct Tangents<'w, const N: usize, const K: usize, W: Watcher<K>> {
    cols: [Column<N>; K],
    watch: &'w mut W,
}

impl<'w, const N: usize, const K: usize, W: Watcher<K>> Tangents<'w, N, K, W> {
    /// The start state does not depend on `ζ`: every tangent is zero.
    fn zero(watch: &'w mut W) -> Self {
        Self {
            watch,
            cols: [Column {
                eta: SVector::zeros(),
                d: 0.0,
                d_prev: 0.0,
                x: 0.0,
                x_prev: 0.0,
                depth_integral: 0.0,
                pitch_integral: 0.0,
                grad_j: 0.0,
                grad_violation: 0.0,
            }; K],
        }
    }
}

impl<const N: usize, const K: usize, W: Watcher<K>> Sensitivity<N> for Tangents<'_, N, K, W> {
    #[inline(always)]
    fn step(&mut self, v: &Vehicle<N>, lin: &StepLin) {
        let plant = v.plant();
        let ap = v.autopilot();
        let cfg = ap.config();
        let ts = plant.sample_time();
        let (gd, gt) = (&cfg.depth_pid, &cfg.pitch_pid);
        let (ad, bd) = (plant.ad_m(), plant.bd_v());
        let sign = ap.loop_sign();
        let c = lin.command;
        let (dd, dx) = (lin.step * lin.cos, lin.step * lin.sin);
        for (j, col) in self
            .cols
            .iter_mut()
            .enumerate()
            .take(lin.slot.saturating_add(1))
        {
            let pitch = plant.pitch_v(&col.eta);
            let pitch_rate = plant.pitch_rate_v(&col.eta);
            let e_d = if j == lin.slot { 1.0 - col.d } else { -col.d };
            let rate = (col.d - col.d_prev) / ts;
            let v_ = -(e_d * gd.kp + col.depth_integral * gd.ki - rate * gd.kd);
            let pitch_ref = if c.pitch_ref_linear { v_ } else { 0.0 };
            let e_t = pitch_ref - pitch;
            let w = (e_t * gt.kp + col.pitch_integral * gt.ki - pitch_rate * gt.kd) * sign;
            let elevator = if c.elevator_linear { w } else { 0.0 };
            if c.depth_integrating {
                col.depth_integral += e_d * ts;
            }
            if c.pitch_integrating {
                col.pitch_integral += e_t * ts;
            }
            col.eta = ad * col.eta + bd * elevator;
            let pitch_next = plant.pitch_v(&col.eta);
            let mean = (pitch + pitch_next) * (0.5 * DEG);
            col.d_prev = col.d;
            col.x_prev = col.x;
            col.d -= mean * dd;
            col.x -= mean * dx;
        }
    }

    #[inline(always)]
    fn piece(&mut self, slot: usize, p: &PieceLin) {
        let ratio = p.dd / p.dx;
        let sq_e = 0.25 * (p.lo.e * p.lo.e + p.hi.e * p.hi.e);
        let sq_p = 0.25 * (p.lo.p * p.lo.p + p.hi.p * p.hi.p);
        let half = 0.5 * p.len;
        let mut de = [(0.0, 0.0); K];
        for (col, de) in self
            .cols
            .iter_mut()
            .zip(de.iter_mut())
            .take(slot.saturating_add(1))
        {
            let de_lo = col.de(p.lo.at, ratio);
            let de_hi = col.de(p.hi.at, ratio);
            if W::ACTIVE {
                *de = (de_lo, de_hi);
            }
            let dlen = col.dx(p.hi.at) - col.dx(p.lo.at);
            col.grad_j += dlen * sq_e + (de_lo * p.lo.e + de_hi * p.hi.e) * half;
            // p = max(0, h_a − h) and e = h − h_r, so ∂p = −∂e where p > 0.
            let dp_lo = if p.lo.p > 0.0 { -de_lo } else { 0.0 };
            let dp_hi = if p.hi.p > 0.0 { -de_hi } else { 0.0 };
            col.grad_violation += dlen * sq_p + (dp_lo * p.lo.p + dp_hi * p.hi.p) * half;
        }
        if W::ACTIVE {
            self.watch.piece(slot, p, &de);
        }
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
        self.evaluate_with(start, first_track, depths, count, &mut NoWatch)
    }

    /// As [`Scenario::evaluate_tracks`], recording the segments' least
    /// altitudes with their gradients (and the Gauss–Newton matrix if
    /// `watch` asks for it) into `watch`, laid out for this run by
    /// [`Watch::new`].
    ///
    /// # Errors
    /// As [`Scenario::evaluate_tracks`].
    pub(crate) fn evaluate_watched<const K: usize>(
        &self,
        start: &VehicleState<N>,
        first_track: usize,
        depths: &[f32; K],
        count: usize,
        watch: &mut Watch<K>,
    ) -> Result<Evaluation<N, K>, SimError> {
        self.evaluate_with(start, first_track, depths, count, watch)
    }

    /// The one tangent pass, with its watcher.
    fn evaluate_with<const K: usize, W: Watcher<K>>(
        &self,
        start: &VehicleState<N>,
        first_track: usize,
        depths: &[f32; K],
        count: usize,
        watch: &mut W,
    ) -> Result<Evaluation<N, K>, SimError> {
        let used = depths.get(..count).ok_or(SimError::TrackRange)?;
        let mut scores = [TrackScore::default(); K];
        let mut tan = Tangents::<N, K, W>::zero(watch);
        let end =
            self.run::<_, _, true>(start, first_track, used, &mut scores, &mut tan, |_| {})?;
        let grad_j: [f32; K] = core::array::from_fn(|j| tan.cols.get(j).map_or(0.0, |c| c.grad_j));
        let grad_violation: [f32; K] =
            core::array::from_fn(|j| tan.cols.get(j).map_or(0.0, |c| c.grad_violation));
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
