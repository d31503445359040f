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
//! rounding (and the residue below `NEGLIGIBLE` = 1e-7 that a sleeping
//! column drops: see `column.rs`; within 1e-5 of the largest entry
//! against columns kept awake, by the test below), wherever the
//! simulation is differentiable: it is not defined
//! at the isolated depths where a sample lands exactly on a waypoint or a
//! clamp's edge, and it is exactly zero on the plateaus where the pitch
//! reference stays saturated over a whole track (contract §10).

use crate::model::Vehicle;

use super::column::{Column, Factors, Gains};
use super::lin::{EndAt, FastPiece, PieceLin, Sensitivity, StepLin};
use super::watch::Watch;
use super::{Scenario, SimError, TrackScore, VehicleState};

/// Columns look for sleep every this many steps (a power of two).
const SETTLE_EVERY: u32 = 8;

/// Tangents of the state with respect to `K` reference depths, one column
/// per depth. Depth `j`'s column is exactly zero until its track begins
/// (the start state and the earlier tracks do not depend on it), so each
/// step and piece updates only the columns of the tracks begun so far.
/// The watch sees every piece with the columns' `∂e` (`watch.rs`) when it
/// records anything.
struct Tangents<'w, 'a, const N: usize, const K: usize> {
    cols: [Column<N>; K],
    gains: Gains<N>,
    /// Steps taken (for [`SETTLE_EVERY`]).
    tick: u32,
    /// Whether columns may sleep (always, but for the test that compares).
    settling: bool,
    /// Whether the watch records anything (read once).
    watching: bool,
    watch: &'w mut Watch<'a, K>,
}

impl<'w, 'a, const N: usize, const K: usize> Tangents<'w, 'a, N, K> {
    /// The start state does not depend on `ζ`: every tangent is zero.
    fn zero(vehicle: &Vehicle<N>, watch: &'w mut Watch<'a, K>) -> Self {
        Self {
            tick: 0,
            settling: true,
            watching: watch.on(),
            watch,
            gains: Gains::of(vehicle),
            cols: [Column::zero(); K],
        }
    }
}

impl<const N: usize, const K: usize> Tangents<'_, '_, N, K> {
    /// This step's factors, counting it.
    #[inline(always)]
    fn factors(&mut self, lin: &StepLin) -> Factors {
        self.tick = self.tick.wrapping_add(1);
        let check = self.settling && self.tick.is_multiple_of(SETTLE_EVERY);
        Factors::of(&self.gains, lin, check)
    }
}

impl<const N: usize, const K: usize> Sensitivity<N> for Tangents<'_, '_, N, K> {
    #[inline(always)]
    fn step(&mut self, _: &Vehicle<N>, lin: &StepLin) {
        let f = self.factors(lin);
        for (j, col) in self
            .cols
            .iter_mut()
            .enumerate()
            .take(lin.slot.saturating_add(1))
        {
            col.step(&self.gains, &f, j == lin.slot);
        }
    }

    /// The fast path's step and its piece (both ends samples on one bottom
    /// segment, inside the track) in one pass over the columns: each
    /// column's state is loaded once, and the piece's ends are the states
    /// before and after the step.
    #[inline(always)]
    fn step_piece(&mut self, v: &Vehicle<N>, lin: &StepLin, slot: usize, q: FastPiece) {
        let (lo, hi) = (q.lo, q.hi);
        let (EndAt::Start { slope: s0 }, EndAt::End { slope: s1 }) = (lo.at, hi.at) else {
            self.step(v, lin);
            self.piece(slot, &q.whole());
            return;
        };
        if lo.p > 0.0 || hi.p > 0.0 {
            self.step(v, lin);
            self.piece(slot, &q.whole());
            return;
        }
        let f = self.factors(lin);
        let sq_e = 0.25 * (lo.e * lo.e + hi.e * hi.e);
        let half = 0.5 * q.dx;
        let (he_lo, he_hi) = (half * lo.e, half * hi.e);
        let ends = ((s0, s1), (sq_e, he_lo, he_hi));
        let n = lin.slot.saturating_add(1);
        if self.watching && !self.watch.lower_recorded(lo.x) {
            let mut de = [(0.0, 0.0); K];
            for ((j, col), de) in self.cols.iter_mut().enumerate().zip(de.iter_mut()).take(n) {
                *de = col.step_piece(&self.gains, &f, j == lin.slot, ends.0, ends.1);
            }
            self.watch.piece(slot, &q.whole(), &de);
            return;
        }
        // Watched, the lower end is recorded already: the upper end's
        // `∂e` is written only when it sets its segment's minimum.
        let row = if self.watching {
            self.watch.upper(slot, (hi.x, hi.e))
        } else {
            None
        };
        match row {
            Some(g) => {
                for ((j, col), gj) in self.cols.iter_mut().enumerate().zip(g.iter_mut()).take(n) {
                    *gj = col
                        .step_piece(&self.gains, &f, j == lin.slot, ends.0, ends.1)
                        .1;
                }
            }
            None => {
                for (j, col) in self.cols.iter_mut().enumerate().take(n) {
                    col.step_piece(&self.gains, &f, j == lin.slot, ends.0, ends.1);
                }
            }
        }
    }

    #[inline(always)]
    fn piece(&mut self, slot: usize, p: &PieceLin) {
        let ratio = p.dd / p.dx;
        let sq_e = 0.25 * (p.lo.e * p.lo.e + p.hi.e * p.hi.e);
        let sq_p = 0.25 * (p.lo.p * p.lo.p + p.hi.p * p.hi.p);
        let half = 0.5 * p.len;
        let (he_lo, he_hi) = (half * p.lo.e, half * p.hi.e);
        let violating = p.lo.p > 0.0 || p.hi.p > 0.0;
        let mut de = [(0.0, 0.0); K];
        for (col, de) in self
            .cols
            .iter_mut()
            .zip(de.iter_mut())
            .take(slot.saturating_add(1))
        {
            let de_lo = col.de(p.lo.at, ratio);
            let de_hi = col.de(p.hi.at, ratio);
            *de = (de_lo, de_hi);
            let dlen = col.dx(p.hi.at) - col.dx(p.lo.at);
            col.grad_j += dlen * sq_e + de_lo * he_lo + de_hi * he_hi;
            // p = max(0, h_a − h) and e = h − h_r, so ∂p = −∂e where p > 0
            // (nothing to add on the pieces clear of the penalty altitude).
            if violating {
                let dp_lo = if p.lo.p > 0.0 { -de_lo } else { 0.0 };
                let dp_hi = if p.hi.p > 0.0 { -de_hi } else { 0.0 };
                col.grad_violation += dlen * sq_p + (dp_lo * p.lo.p + dp_hi * p.hi.p) * half;
            }
        }
        if self.watching {
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
        self.evaluate_watched(start, first_track, depths, count, &mut Watch::off())
    }

    /// As [`Scenario::evaluate_tracks`], recording the segments' least
    /// altitudes with their gradients (and the Gauss–Newton matrix if
    /// `watch` asks for it) into `watch`, laid out for this run by
    /// [`Watch::new`].
    ///
    /// # Errors
    /// As [`Scenario::evaluate_tracks`].
    ///
    /// The one tangent pass of the library: the plain gradient is this
    /// pass with [`Watch::off`] (one copy of the loop in the firmware: out
    /// of line, so that no caller's inlining copies it).
    #[inline(never)]
    pub(crate) fn evaluate_watched<const K: usize>(
        &self,
        start: &VehicleState<N>,
        first_track: usize,
        depths: &[f32; K],
        count: usize,
        watch: &mut Watch<'_, K>,
    ) -> Result<Evaluation<N, K>, SimError> {
        self.evaluate_settling::<K, true>(start, (first_track, depths, count), watch)
            .map(|(e, _)| e)
    }

    /// [`Scenario::evaluate_watched`], with the columns' sleep allowed
    /// (`SETTLE`) or not (for the test that compares); also returns how
    /// many columns end the pass asleep.
    #[inline(always)]
    fn evaluate_settling<const K: usize, const SETTLE: bool>(
        &self,
        start: &VehicleState<N>,
        (first_track, depths, count): (usize, &[f32; K], usize),
        watch: &mut Watch<'_, K>,
    ) -> Result<(Evaluation<N, K>, usize), SimError> {
        let used = depths.get(..count).ok_or(SimError::TrackRange)?;
        let mut scores = [TrackScore::default(); K];
        let mut tan = Tangents::zero(self.vehicle, watch);
        tan.settling = SETTLE;
        let end =
            self.run::<_, _, true>(start, first_track, used, &mut scores, &mut tan, |_| {})?;
        let asleep = tan.cols.iter().filter(|c| c.asleep).count();
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
        let e = Evaluation {
            scores,
            j,
            violation,
            min_altitude,
            grad_j,
            grad_violation,
            end,
        };
        Ok((e, asleep))
    }
}

#[cfg(test)]
mod tests {
    //! Sleeping columns against columns kept awake, on random canyon
    //! lines with saturated dives: the same flight, and every gradient
    //! entry within f32 resolution of the largest of its pass.
    use super::*;
    use crate::model::{Mission, Profile, Waypoints};
    use crate::sim::rng::Lcg;

    #[test]
    fn sleeping_columns_change_no_gradient_beyond_rounding() {
        let vehicle = Vehicle::c_auv4().unwrap();
        let mut rng = Lcg(20261203);
        let (mut compared, mut asleep) = (0, 0);
        for case in 0..60 {
            // Five tracks over a bottom with walls up to 300 m high.
            let mut x = [0.0_f32; 40];
            let mut b = [0.0_f32; 40];
            let mut depth = 600.0 + 400.0 * rng.next();
            for i in 0..40 {
                x[i] = 100.0 * i as f32;
                let wall = if rng.next() < 0.2 { 600.0 } else { 60.0 };
                depth = (depth + (rng.next() - 0.5) * wall).max(150.0);
                b[i] = depth;
            }
            let bottom = Profile::<40>::new(&x, &b).unwrap();
            let wps = Waypoints::<6>::new(&[0.0, 700.0, 1500.0, 2300.0, 3000.0, 3800.0]).unwrap();
            let mission = Mission::new(80.0, 60.0, [0.0, 6000.0]).unwrap();
            let sc = Scenario::new(&vehicle, &bottom, &wps, mission).unwrap();
            let start = sc.start_state(sc.default_initial_depth());
            let z: [f32; 5] = core::array::from_fn(|n| {
                let at = ((n * 8 + 4) as f32 * 100.0).min(3900.0);
                bottom.depth_at(at).unwrap() - 60.0 - 80.0 * rng.next()
            });
            let (mut off, mut off2) = (Watch::off(), Watch::off());
            let slept = sc.evaluate_settling::<5, true>(&start, (0, &z, 5), &mut off);
            let awake = sc.evaluate_settling::<5, false>(&start, (0, &z, 5), &mut off2);
            let (Ok((slept, n)), Ok((awake, m))) = (slept, awake) else {
                continue;
            };
            assert_eq!(m, 0, "case {case}");
            assert_eq!(
                slept.scores, awake.scores,
                "case {case}: the flight differs"
            );
            for (g, h) in [
                (slept.grad_j, awake.grad_j),
                (slept.grad_violation, awake.grad_violation),
            ] {
                let scale = h.iter().fold(0.0_f32, |m, v| m.max(v.abs()));
                for (a, w) in g.iter().zip(&h) {
                    assert!(
                        (a - w).abs() <= 1e-5 * scale + 1e-6,
                        "case {case}: {g:?} against {h:?} awake"
                    );
                }
            }
            compared += 1;
            asleep += n;
        }
        assert!(compared >= 40, "{compared} lines flown");
        // Not vacuous: columns do sleep on these lines.
        assert!(
            asleep >= 2 * compared,
            "{asleep} columns asleep at the ends"
        );
    }
}
