//! The planner: the next waypoint's reference depth, optimized by flying
//! the vehicle's closed loop over the mapped bottom, verified safe or
//! explicitly flagged (model contract §10).
//!
//! ```text
//! state at X_{n-1}, waypoints, bottom ─► search box (reachable depths)
//!   ─► start: coarse scan, track by track (or the previous call's plan)
//!   ─► BFGS or GD on  Φ(ζ) = Σ J + μ Σ V          ζ = (z_n .. z_{n+h-1})
//!   ─► verify z_n by simulation ─► safe? ─ no ─► closest safe depth (safe_fallback)
//!                                              or the safest one (infeasible)
//! ```
//!
//! **Modes.** Receding horizon (the default) optimizes the next `h <= K`
//! tracks jointly, commits the first depth, and keeps the rest to
//! warm-start the next call; track-wise (the paper's method) optimizes `z_n`
//! for track `n` alone.
//!
//! **Search box.** Over a track of length `L` the vehicle cannot change
//! depth by more than `L sin θ` (θ a little over the pitch limit: the pitch
//! overshoots its reference by a few degrees). A reference further away
//! than that, plus the depth error that saturates the pitch reference
//! (`θmax / Kpd`), keeps the pitch reference saturated over the whole track:
//! the flight, and `J`, no longer change (model contract §10's plateaus).
//! So `z_j` is searched within `d ± (Σ L sin θ + 3 θmax/Kpd + 20 m)` of the
//! current depth `d`, intersected with `depth_limits`: nothing outside
//! gives a different flight, and the optimizer is never started on the
//! plateau.
//!
//! **Starting point.** A coarse scan of `scan_points` depths over the box
//! (`track_scan_points` for a constrained single track),
//! track by track from the state the best of the previous track leaves:
//! the search starts in the best basin found, never on a plateau that is
//! not the best scanned value. In horizon mode later calls start from the
//! previous call's plan, and only the newly visible track is scanned.
//!
//! **Constraint, one track** (track-wise mode, and the last track of a
//! horizon). The scan also gives each scanned depth's minimum altitude.
//! When the scan's best depth is unsafe, or safe but with its parabola
//! pointing to an unsafe neighbour, the optimum of `J` lies beyond the safe
//! set, and the constrained optimum on its boundary next to it: a root
//! search on the minimum altitude between the nearest safe and unsafe
//! scanned depths (a unit-slope step, secants, regula falsi) finds it from
//! the safe side in one to four plain flights, and a finite difference of `J` there (the search's
//! previous safe depth, or one more flight) confirms that `J` does not
//! decrease into the safe set; if it does, BFGS optimizes from there. When
//! no scanned depth is safe the track is [`PlanStatus::Infeasible`] and the
//! safest scanned depth is returned. Otherwise BFGS (without a penalty)
//! optimizes from the scan's parabola vertex, and an unsafe optimum falls
//! back to the boundary by the same search ([`PlanStatus::SafeFallback`]).
//!
//! **Constraint, a horizon.** `h >= h_a` enters the optimization as a
//! quadratic penalty: `Φ = Σ J + μ Σ V` with `V = ½ ∫ max(0, h_a + m_p − h)² dx`
//! (the violation of [`crate::TrackScore`], taken against `h_a` plus the
//! penalty margin `m_p`), whose exact gradient comes from the same tangent
//! pass. `J` ranges from 1e2 to 1e8 m³ between a shallow bay and a canyon
//! wall, so no single `μ` fits: the sequential penalty method (N&W §17.1)
//! re-solves from the last optimum with `μ` a hundred times larger while
//! that optimum still violates, for at most `penalty_stages` stages.
//!
//! **Verification.** The committed depth is **verified by simulation**: it
//! is reported safe only when the track's minimum altitude is at least
//! `h_a + m_s` (the safety margin, covering f32 vs f64 differences in
//! altitude). If not, the planner looks for the safe depth closest to the
//! optimum (among the scanned depths, then by the boundary search) and
//! returns it flagged [`PlanStatus::SafeFallback`]; if no depth in the box
//! is safe, it returns the safest depth it found, flagged
//! [`PlanStatus::Infeasible`] with its predicted minimum altitude.
//! With `constrained = false` (the paper's bare objective) there is no
//! penalty and no fallback; safety is still verified and reported.

use core::fmt;

use heapless::Vec;
use nalgebra::SVector;

use crate::num::DEG;
use crate::optim::{
    self, BfgsConfig, Bounds, GdConfig, HISTORY, Objective, OptimError, Outcome, Status,
};

/// First step of a warm-started solve, relative to `first_step`.
const WARM_FIRST_STEP: f32 = 0.1;

/// Factor on `μ` between penalty stages.
const PENALTY_GROWTH: f32 = 100.0;
use crate::sim::{Scenario, SimError, TrackScore, VehicleState};

/// Which optimizer runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Method {
    /// Dense BFGS with Armijo backtracking (paper §3, eqs. 3.7–3.13).
    Bfgs,
    /// Constant-rate gradient descent (paper eq. 3.6), the baseline.
    GradientDescent,
}

/// What is optimized at each call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Mode {
    /// The next `horizon` tracks jointly; the first depth is committed.
    Horizon,
    /// The next track alone, as in the paper.
    TrackWise,
}

/// Planner settings, with units. `Default` gives the documented defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PlannerConfig {
    /// Optimizer. Default BFGS.
    pub method: Method,
    /// Mode. Default receding horizon.
    pub mode: Mode,
    /// Tracks optimized jointly in horizon mode, `1..=K` (fewer near the
    /// end of the line). Default `usize::MAX`: as many as `K` allows.
    pub horizon: usize,
    /// BFGS settings; their iteration cap and tolerances apply to GD too.
    pub bfgs: BfgsConfig,
    /// GD learning rate `κ`, 1/m. Default 1e-4: stable on every shared
    /// profile, and slow like the paper's baseline (see the README's
    /// experiment).
    pub gd_rate: f32,
    /// Whether `h >= h_a` enters the optimization and unsafe optima fall
    /// back to safe depths. Default true.
    pub constrained: bool,
    /// Penalty weight `μ` of the first stage, dimensionless (`J` and the
    /// violation are both m³). Default 1e4.
    pub penalty_weight: f32,
    /// Penalty stages: each re-solves with `μ` ×100 while the optimum still
    /// violates. ≥ 1. Default 2 (μ up to 1e6). A warm-started call starts
    /// at the `μ` the previous call ended with.
    pub penalty_stages: u32,
    /// Penalty margin `m_p` above `h_a` for horizons of two tracks or
    /// more, m (a single track is not penalized: its boundary search finds
    /// the safe boundary exactly). Default 0.25.
    pub penalty_margin: f32,
    /// Safety margin `m_s` above `h_a` for a depth to be reported safe, m.
    /// Default 0.002: the f32 core's altitudes agree with an f64 reference
    /// to 5.0e-4 m on the golden fixtures and 9.3e-4 m on 300 random
    /// unseen cases (`tools/reference/check_plan.py`), so 2 mm covers them
    /// twice over; a wider margin costs `J` measurably where `h_r` is a few
    /// metres.
    pub safety_margin: f32,
    /// Depths scanned per track for the starting point, ≥ 2, in horizon
    /// mode and for an unconstrained solve, where the scan alone keeps the
    /// optimizer out of a worse basin. Default 9.
    pub scan_points: u32,
    /// Depths scanned for a constrained single-track solve (track-wise
    /// mode, the last track of a horizon), ≥ 2. Default 5: there the scan
    /// is most of a solve's flights, and the boundary search, not the
    /// optimizer, places most answers; the independent brute-force check
    /// (`tools/reference/check_planner.py`) finds them within 0.5 % of the
    /// best safe `J` on every shared profile.
    pub track_scan_points: u32,
    /// Most flights of the boundary search towards the safe-set boundary
    /// (see the module docs). Default 16 (bisection alone would bring a
    /// 50 m bracket under a millimetre); it usually stops after 1 to 4.
    pub bisection_steps: u32,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        Self {
            method: Method::Bfgs,
            mode: Mode::Horizon,
            horizon: usize::MAX,
            bfgs: BfgsConfig::default(),
            gd_rate: 1e-4,
            constrained: true,
            penalty_weight: 1e4,
            penalty_stages: 2,
            penalty_margin: 0.25,
            safety_margin: 0.002,
            scan_points: 9,
            track_scan_points: 5,
            bisection_steps: 16,
        }
    }
}

impl PlannerConfig {
    /// `Ok` when every setting is in range, else the name of the first
    /// that is not.
    pub fn validate(&self) -> Result<(), &'static str> {
        self.bfgs.validate()?;
        if !(self.gd_rate.is_finite() && self.gd_rate > 0.0) {
            return Err("gd_rate");
        }
        if self.horizon == 0 {
            return Err("horizon");
        }
        if !(self.penalty_weight.is_finite() && self.penalty_weight >= 0.0) {
            return Err("penalty_weight");
        }
        if self.penalty_stages == 0 {
            return Err("penalty_stages");
        }
        if !(self.penalty_margin.is_finite() && self.penalty_margin >= 0.0) {
            return Err("penalty_margin");
        }
        if !(self.safety_margin.is_finite() && self.safety_margin >= 0.0) {
            return Err("safety_margin");
        }
        if self.scan_points < 2 || self.scan_points > MAX_SCAN {
            return Err("scan_points");
        }
        if self.track_scan_points < 2 || self.track_scan_points > MAX_SCAN {
            return Err("track_scan_points");
        }
        Ok(())
    }
}

/// Most scan points per track.
pub const MAX_SCAN: u32 = 64;

/// How the committed depth was obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PlanStatus {
    /// The optimizer converged and its depth is safe (or, unconstrained,
    /// simply converged).
    Converged,
    /// The optimizer hit its iteration cap; its last depth is used.
    MaxIterations,
    /// The line search failed; the last accepted depth is used.
    LineSearchFailed,
    /// The optimum was not safe; this is the closest safe depth.
    SafeFallback,
    /// No depth in the allowed range keeps this track safe; this is the
    /// safest depth found, and [`Plan::min_altitude`] says how low it goes.
    Infeasible,
}

impl PlanStatus {
    /// The name the host tool prints.
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::Converged => "converged",
            Self::MaxIterations => "max_iterations",
            Self::LineSearchFailed => "line_search_failed",
            Self::SafeFallback => "safe_fallback",
            Self::Infeasible => "infeasible",
        }
    }
}

impl From<Status> for PlanStatus {
    fn from(s: Status) -> Self {
        match s {
            Status::Converged => Self::Converged,
            Status::MaxIterations => Self::MaxIterations,
            Status::LineSearchFailed => Self::LineSearchFailed,
        }
    }
}

impl fmt::Display for PlanStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Why the planner could not plan.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PlanError {
    /// A planner setting is out of range (named).
    Config(&'static str),
    /// `track` is not a track of the line.
    TrackRange,
    /// The simulation failed where no fallback is possible (at the start).
    Sim(SimError),
}

impl fmt::Display for PlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Config(p) => write!(f, "planner setting {p} is out of range"),
            Self::TrackRange => f.write_str("no such track"),
            Self::Sim(e) => write!(f, "simulation failed: {e}"),
        }
    }
}

impl core::error::Error for PlanError {}

impl From<SimError> for PlanError {
    fn from(e: SimError) -> Self {
        Self::Sim(e)
    }
}

/// The planner's answer for one track.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan<const N: usize, const K: usize> {
    /// Reference depth to command on the track, m.
    pub depth: f32,
    /// How it was obtained.
    pub status: PlanStatus,
    /// Predicted minimum altitude on the track is at least `h_a` plus the
    /// safety margin (model contract §8).
    pub safe: bool,
    /// Predicted `J` of the track flown at [`Plan::depth`], m³.
    pub j: f32,
    /// Predicted RMS deviation from the target depth, m.
    pub rms: f32,
    /// Predicted minimum altitude on the track, m.
    pub min_altitude: f32,
    /// The optimizer's final objective (`Σ J + μ Σ V` over the horizon), m³.
    pub objective: f32,
    /// Optimizer iterations.
    pub iterations: u32,
    /// Simulations run for this answer, of every kind: scan, objective and
    /// gradient, verification, fallback.
    pub evaluations: u32,
    /// Norm of the objective's gradient at the optimizer's last point, m².
    pub grad_norm: f32,
    /// The optimizer's objective at its start and after each iteration.
    pub history: Vec<f32, HISTORY>,
    /// The whole optimized horizon (the first `horizon_len` entries), m.
    pub horizon: [f32; K],
    /// Number of tracks optimized jointly.
    pub horizon_len: usize,
    /// The state when the vehicle, flying [`Plan::depth`], first reaches
    /// the end of the track: the next call's start state.
    pub next_state: VehicleState<N>,
}

/// A receding-horizon or track-wise planner of up to `K` tracks at a time.
#[derive(Clone, Debug, PartialEq)]
pub struct Planner<const K: usize> {
    cfg: PlannerConfig,
    /// The previous call's plan for the tracks after the committed one.
    warm: Option<Warm<K>>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Warm<const K: usize> {
    track: usize,
    depths: [f32; K],
    len: usize,
    /// The penalty weight the previous call ended with.
    mu: f32,
}

impl<const K: usize> Planner<K> {
    /// A planner with validated settings.
    ///
    /// # Errors
    /// [`PlanError::Config`] naming the first setting out of range.
    pub fn new(cfg: PlannerConfig) -> Result<Self, PlanError> {
        const { assert!(K >= 1, "a planner optimizes at least one track") };
        cfg.validate().map_err(PlanError::Config)?;
        Ok(Self { cfg, warm: None })
    }

    /// The settings.
    pub fn config(&self) -> &PlannerConfig {
        &self.cfg
    }

    /// Forgets the warm start (e.g. after a re-route).
    pub fn reset(&mut self) {
        self.warm = None;
    }

    /// Plans the reference depth of `track` (0-based) for a vehicle in
    /// `state`, the state in which it reaches the track's first waypoint.
    ///
    /// # Errors
    /// [`PlanError`] for a track outside the line, or a simulation that
    /// fails at the very start (a non-finite state, one off the track).
    pub fn plan<const N: usize, const S: usize, const W: usize>(
        &mut self,
        sc: &Scenario<'_, N, S, W>,
        state: &VehicleState<N>,
        track: usize,
    ) -> Result<Plan<N, K>, PlanError> {
        let tracks = sc.waypoints().tracks();
        let remaining = tracks
            .checked_sub(track)
            .filter(|&r| r > 0)
            .ok_or(PlanError::TrackRange)?;
        // A bad start is the caller's error, named as such (every flight
        // from it would fail the same way).
        sc.check_start(state, track)?;
        let h = match self.cfg.mode {
            Mode::TrackWise => 1,
            Mode::Horizon => self.cfg.horizon.min(K).min(remaining),
        };
        // One track: no penalty margin, since the boundary search then
        // lands on the exact safe boundary instead of `m_p` above it. A
        // horizon keeps the margin for the tracks after the first, which no
        // boundary search corrects.
        let margin = if h == 1 { 0.0 } else { self.cfg.penalty_margin };
        let penalized = sc
            .clone()
            .with_penalty_altitude(sc.mission().min_altitude() + margin);
        let warm = self.warm.filter(|w| w.track == track && w.len > 0);
        let mu = match (self.cfg.constrained, warm) {
            (false, _) => 0.0,
            (true, Some(w)) => w.mu,
            (true, None) => self.cfg.penalty_weight,
        };
        let bounds = search_box::<N, S, W, K>(sc, state, track, h);
        let mut evaluations = 0_u32;
        let mut scan = ScanLog::default();

        // Starting point.
        let mut z0 = bounds.lo;
        let mut from = 0;
        if let Some(w) = warm {
            for (i, &z) in w.depths.iter().enumerate().take(w.len.min(h)) {
                if let Some(slot) = z0.get_mut(i) {
                    *slot = z;
                }
            }
            from = w.len.min(h);
        }
        let mut curvature = SVector::<f32, K>::zeros();
        if from < h {
            self.scan_start(
                &penalized,
                state,
                track,
                from,
                h,
                mu,
                &bounds,
                &mut z0,
                &mut curvature,
                &mut evaluations,
                &mut scan,
            )?;
        }

        // One track, constrained, scanned. When the scan says the optimum of
        // `J` lies outside the safe set (its best depth is unsafe, or it is
        // safe but the parabola through it and its neighbours peaks in an
        // unsafe neighbour's direction), the constrained optimum is on the
        // safe set's boundary next to it: find that boundary directly
        // (`boundary`, a few plain flights), then check with one exact
        // gradient there that `J` does not decrease into the safe set; only
        // if it does is there an interior optimum, for the optimizer to
        // find from there. With no scanned depth safe, the track is
        // infeasible. A single track is then optimized without the
        // penalty: the verification and this boundary search enforce the
        // constraint exactly.
        let h_safe = sc.mission().min_altitude() + self.cfg.safety_margin;
        let single = h == 1 && self.cfg.constrained && from == 0 && scan.len > 0;
        let mut mu = mu;
        if single {
            mu = 0.0;
            if let Some(plan) = self.single_start(
                sc,
                state,
                track,
                &scan,
                h_safe,
                &mut z0,
                &mut curvature,
                &mut evaluations,
            )? {
                return Ok(plan);
            }
        }

        // Optimize, in penalty stages.
        let mut obj = PlanObjective {
            sc: &penalized,
            start: state,
            track,
            count: h,
            mu,
            evaluations: 0,
            last_violation: 0.0,
            last_flight: None,
            guard: single.then_some(h_safe),
            tripped: None,
            best_safe: None,
        };
        // A warm start is already close: a shorter first step.
        let first_step = if warm.is_some() {
            self.cfg.bfgs.first_step * WARM_FIRST_STEP
        } else {
            self.cfg.bfgs.first_step
        };
        let cap = self.cfg.bfgs.max_iterations;
        let mut outcome = Outcome::at(&z0);
        let first = self.optimize_onto(
            &mut obj,
            &z0,
            &bounds,
            first_step,
            cap,
            &curvature,
            &mut outcome,
            Merge::First,
        );
        if let Some(tripped) = obj.tripped {
            evaluations = evaluations.saturating_add(obj.evaluations);
            return self.single_tripped(
                sc,
                state,
                track,
                tripped,
                obj.best_safe,
                &outcome,
                &bounds,
                h_safe,
                &mut scan,
                evaluations,
            );
        }
        first?;
        let mut iterations = outcome.iterations;
        // One track: the boundary search finds the safe boundary exactly,
        // a stiffer penalty stage would only cost iterations.
        let stages = if h == 1 { 1 } else { self.cfg.penalty_stages };
        let max_mu = (1..stages).fold(self.cfg.penalty_weight, |m, _| m * PENALTY_GROWTH);
        // The iteration cap bounds the whole solve, all stages together.
        while obj.mu > 0.0 && obj.mu < max_mu && obj.last_violation > 0.0 && iterations < cap {
            obj.mu *= PENALTY_GROWTH;
            let from = outcome.z;
            let taken = self.optimize_onto(
                &mut obj,
                &from,
                &bounds,
                first_step,
                cap.saturating_sub(iterations),
                &SVector::zeros(),
                &mut outcome,
                Merge::Continue,
            )?;
            iterations = iterations.saturating_add(taken.unwrap_or(0));
        }
        // Plateau escape: a coordinate whose gradient is exactly zero has its
        // pitch reference saturated over the whole track, and no gradient
        // step will ever move it off that plateau, which need not be the
        // best (contract §10). Scan it over its box, the others held, and
        // restart from anything better.
        if h > 1 {
            for j in 0..h {
                let free = bounds
                    .lo
                    .get(j)
                    .zip(bounds.hi.get(j))
                    .is_some_and(|(l, u)| l < u);
                if !free || outcome.gradient.get(j).is_none_or(|&g| g != 0.0) {
                    continue;
                }
                let (lo, hi) = (
                    bounds.lo.get(j).copied().unwrap_or_default(),
                    bounds.hi.get(j).copied().unwrap_or_default(),
                );
                let mut best: Option<(f32, SVector<f32, K>)> = None;
                for k in 0..self.cfg.scan_points {
                    let mut z = outcome.z;
                    if let Some(zj) = z.get_mut(j) {
                        *zj = grid(lo, hi, k, self.cfg.scan_points);
                    }
                    if let Ok((phi, _)) = obj.eval(&z)
                        && phi < best.as_ref().map_or(outcome.j, |b| b.0)
                    {
                        best = Some((phi, z));
                    }
                }
                if let Some((phi, z)) = best
                    && phi < outcome.j - self.cfg.bfgs.tol.j_threshold(outcome.j)
                {
                    // The jump costs one iteration of the cap; none left, no restart.
                    let budget = cap.saturating_sub(iterations).saturating_sub(1);
                    if budget == 0 {
                        break;
                    }
                    let taken = self.optimize_onto(
                        &mut obj,
                        &z,
                        &bounds,
                        first_step,
                        budget,
                        &SVector::zeros(),
                        &mut outcome,
                        Merge::IfBetter,
                    )?;
                    if let Some(taken) = taken {
                        // The scan's jump counts as one iteration.
                        iterations = iterations.saturating_add(taken).saturating_add(1);
                    }
                }
            }
        }
        evaluations = evaluations.saturating_add(obj.evaluations);
        let obj_mu = obj.mu;

        // Verify the committed depth by simulation (the optimizer evaluated
        // this very point, so the flight cannot fail here unless the
        // scenario changed under us).
        let z_opt = outcome.z.get(0).copied().unwrap_or_default();
        let mut status = PlanStatus::from(outcome.status);
        let mut depth = z_opt;
        let (mut score, mut next) = match obj.last_flight {
            // Same start, same depth, same track: the flight is identical
            // (the penalty altitude changes only the violation, unused here).
            // Bit-identical depth, so bit-identical flight.
            Some((z, s, n)) if z.to_bits() == z_opt.to_bits() => (s, n),
            _ => self.fly(sc, state, track, z_opt, &mut evaluations)?,
        };
        let verified = score.min_altitude() >= h_safe;
        if self.cfg.constrained && !verified {
            let lo = bounds.lo.get(0).copied().unwrap_or(depth);
            let hi = bounds.hi.get(0).copied().unwrap_or(depth);
            let fb = self.fallback(
                sc,
                state,
                track,
                (z_opt, Some(score.min_altitude())),
                lo,
                hi,
                h_safe,
                &mut scan,
                &mut evaluations,
            )?;
            depth = fb.depth;
            score = fb.score;
            next = fb.next;
            status = if fb.safe {
                PlanStatus::SafeFallback
            } else {
                PlanStatus::Infeasible
            };
        }
        let safe = score.min_altitude() >= h_safe;
        crate::log::debug!(
            "plan track {=usize}: depth {=f32} m, {=str}, J {=f32} m3, min altitude {=f32} m, {=u32} iterations, {=u32} evaluations",
            track,
            depth,
            status.as_str(),
            score.j(),
            score.min_altitude(),
            iterations,
            evaluations
        );

        // Keep the rest of the horizon for the next call.
        let mut horizon = [0.0_f32; K];
        for (dst, src) in horizon.iter_mut().zip(outcome.z.iter()) {
            *dst = *src;
        }
        if let Some(first) = horizon.first_mut() {
            *first = depth;
        }
        self.warm = (self.cfg.mode == Mode::Horizon && h > 1).then(|| {
            let mut depths = [0.0; K];
            for (dst, src) in depths.iter_mut().zip(horizon.iter().skip(1)) {
                *dst = *src;
            }
            Warm {
                track: track.saturating_add(1),
                depths,
                len: h.saturating_sub(1),
                mu: obj_mu,
            }
        });
        Ok(Plan {
            depth,
            status,
            safe,
            j: score.j(),
            rms: score.rms(),
            min_altitude: score.min_altitude(),
            objective: outcome.j,
            iterations,
            evaluations,
            grad_norm: outcome.grad_norm,
            history: outcome.history,
            horizon,
            horizon_len: h,
            next_state: next,
        })
    }

    /// One optimizer run (BFGS or GD, as configured, writing in place; see
    /// `optim::bfgs::bfgs_into`) on `obj` from `z0` with start `curvature`,
    /// merged onto `acc` in place: the first run, a continuation (the next penalty stage:
    /// its history after its start, whose value `acc` ends with) or, with
    /// [`Merge::IfBetter`], a restart kept only if it ends lower (its whole
    /// history). Returns the run's iterations, `None` when not kept. Out of
    /// line, so that the run's own outcome is not a second history-sized
    /// local of [`Planner::plan`].
    #[allow(clippy::too_many_arguments)]
    #[inline(never)]
    fn optimize_onto<const N: usize, const S: usize, const W: usize>(
        &self,
        obj: &mut PlanObjective<'_, '_, N, S, W>,
        z0: &SVector<f32, K>,
        bounds: &Bounds<K>,
        first_step: f32,
        max_iterations: u32,
        curvature: &SVector<f32, K>,
        acc: &mut Outcome<K>,
        merge: Merge,
    ) -> Result<Option<u32>, PlanError> {
        // What a rejected restart restores.
        let kept = (
            acc.z,
            acc.j,
            acc.gradient,
            acc.grad_norm,
            acc.status,
            acc.iterations,
            acc.evaluations,
            acc.skipped_updates,
            acc.history.len(),
        );
        if let Merge::First = merge {
            acc.history.clear();
        }
        let continued = matches!(merge, Merge::Continue);
        let bfgs = BfgsConfig {
            first_step,
            max_iterations,
            ..self.cfg.bfgs
        };
        let run = match self.cfg.method {
            Method::Bfgs => optim::bfgs::bfgs_into(
                obj,
                z0,
                bounds,
                &bfgs,
                &bfgs.armijo,
                curvature,
                acc,
                continued,
            ),
            Method::GradientDescent => {
                let gd = GdConfig {
                    rate: self.cfg.gd_rate,
                    max_iterations,
                    tol: self.cfg.bfgs.tol,
                };
                optim::gd::gradient_descent_into(obj, z0, bounds, &gd, acc, continued)
            }
        };
        run.map_err(|e| match e {
            OptimError::Config(p) => PlanError::Config(p),
            OptimError::Start(e) => PlanError::Sim(e),
            OptimError::NonFinite => PlanError::Sim(SimError::Diverged),
        })?;
        // (A NaN objective is not better either.)
        if let Merge::IfBetter = merge
            && acc.j.partial_cmp(&kept.1) != Some(core::cmp::Ordering::Less)
        {
            acc.z = kept.0;
            acc.j = kept.1;
            acc.gradient = kept.2;
            acc.grad_norm = kept.3;
            acc.status = kept.4;
            acc.iterations = kept.5;
            acc.evaluations = kept.6;
            acc.skipped_updates = kept.7;
            acc.history.truncate(kept.8);
            return Ok(None);
        }
        Ok(Some(acc.iterations))
    }

    /// Flies `track` alone at depth `z` from `state`.
    fn fly<const N: usize, const S: usize, const W: usize>(
        &self,
        sc: &Scenario<'_, N, S, W>,
        state: &VehicleState<N>,
        track: usize,
        z: f32,
        evaluations: &mut u32,
    ) -> Result<(TrackScore, VehicleState<N>), SimError> {
        *evaluations = evaluations.saturating_add(1);
        let mut score = [TrackScore::default()];
        let next = sc.simulate(state, track, &[z], &mut score, |_| {})?;
        Ok((score[0], next))
    }

    /// Coarse scan of tracks `from..h` of the horizon, each from the state
    /// the best scanned depth of the previous one leaves; fills `z0`.
    #[allow(clippy::too_many_arguments)]
    fn scan_start<const N: usize, const S: usize, const W: usize>(
        &self,
        sc: &Scenario<'_, N, S, W>,
        state: &VehicleState<N>,
        track: usize,
        from: usize,
        h: usize,
        mu: f32,
        bounds: &Bounds<K>,
        z0: &mut SVector<f32, K>,
        curvature: &mut SVector<f32, K>,
        evaluations: &mut u32,
        log: &mut ScanLog,
    ) -> Result<(), PlanError> {
        // The state at the start of track `from`, along the plan so far.
        let mut st = *state;
        for j in 0..from {
            let z = z0.get(j).copied().unwrap_or(0.0);
            match self.fly(sc, &st, track.saturating_add(j), z, evaluations) {
                Ok((_, n)) => st = n,
                Err(e) if j == 0 => return Err(e.into()),
                Err(_) => break,
            }
        }
        for j in from..h {
            let t = track.saturating_add(j);
            let (lo, hi) = (
                bounds.lo.get(j).copied().unwrap_or(0.0),
                bounds.hi.get(j).copied().unwrap_or(0.0),
            );
            let n = if h == 1 && self.cfg.constrained {
                self.cfg.track_scan_points
            } else {
                self.cfg.scan_points
            };
            let mut phis = [f32::INFINITY; MAX_SCAN as usize];
            // Whether the penalty acts at a scanned depth: there the
            // objective has a kink and a parabola says nothing.
            let mut kinked = [true; MAX_SCAN as usize];
            let mut best: Option<(usize, VehicleState<N>)> = None;
            for k in 0..n {
                let z = grid(lo, hi, k, n);
                let Ok((s, next)) = self.fly(sc, &st, t, z, evaluations) else {
                    continue;
                };
                if j == 0 {
                    log.push(z, &s);
                }
                let phi = s.j() + mu * s.violation();
                let i = k as usize;
                if let Some(p) = phis.get_mut(i) {
                    *p = phi;
                }
                if let Some(kk) = kinked.get_mut(i) {
                    *kk = mu > 0.0 && s.violation() > 0.0;
                }
                if best.is_none_or(|(b, _)| phis.get(b).is_none_or(|&pb| phi < pb)) {
                    best = Some((i, next));
                }
            }
            let Some((i, next)) = best else {
                return Err(PlanError::Sim(SimError::Diverged));
            };
            // A parabola through the best scanned value and its neighbours:
            // its vertex is a Newton step for free, its curvature BFGS's
            // first metric (successive parabolic interpolation).
            let h_grid = (hi - lo) / (n.saturating_sub(1).max(1) as f32);
            let z_best = grid(lo, hi, i as u32, n);
            let (mut z, mut c) = (z_best, 0.0);
            let smooth = i.checked_sub(1).is_some_and(|m| {
                kinked
                    .get(m..=i.saturating_add(1))
                    .is_some_and(|w| w.iter().all(|k| !k))
            });
            if !smooth {
                // Keep the scanned depth; the first-step scaling sets A_0.
            } else if let (Some(&pm), Some(&p0), Some(&pp)) = (
                i.checked_sub(1).and_then(|m| phis.get(m)),
                phis.get(i),
                phis.get(i.saturating_add(1))
                    .filter(|_| i.saturating_add(1) < n as usize),
            ) {
                let second = pp - 2.0 * p0 + pm;
                if second.is_finite() && second > 0.0 && h_grid > 0.0 {
                    z = z_best - 0.5 * h_grid * (pp - pm) / second;
                    // Per-track curvatures ignore the coupling of a horizon:
                    // there the measured BFGS scaling does better.
                    if h == 1 {
                        c = second / (h_grid * h_grid);
                    }
                }
            }
            if let Some(slot) = z0.get_mut(j) {
                *slot = z;
            }
            if let Some(slot) = curvature.get_mut(j) {
                *slot = c;
            }
            st = next;
        }
        Ok(())
    }

    /// The safe depth closest to `z_opt` in `[lo, hi]`, or the safest depth
    /// when none is safe.
    #[allow(clippy::too_many_arguments)]
    fn fallback<const N: usize, const S: usize, const W: usize>(
        &self,
        sc: &Scenario<'_, N, S, W>,
        state: &VehicleState<N>,
        track: usize,
        (z_opt, alt_opt): (f32, Option<f32>),
        lo: f32,
        hi: f32,
        h_safe: f32,
        log: &mut ScanLog,
        evaluations: &mut u32,
    ) -> Result<Fallback<N>, PlanError> {
        if log.len == 0 {
            let n = self.cfg.scan_points;
            for k in 0..n {
                let z = grid(lo, hi, k, n);
                if let Ok((s, _)) = self.fly(sc, state, track, z, evaluations) {
                    log.push(z, &s);
                }
            }
        }
        let nearest_safe = log.nearest_safe(z_opt, h_safe).map(|e| (e.0, e.2));
        match nearest_safe {
            Some((z_safe, alt_safe)) => {
                let b = self.boundary(
                    sc,
                    state,
                    track,
                    (z_safe, Some(alt_safe)),
                    (z_opt, alt_opt),
                    h_safe,
                    evaluations,
                )?;
                Ok(Fallback {
                    depth: b.depth,
                    score: b.score,
                    next: b.next,
                    safe: b.score.min_altitude() >= h_safe,
                })
            }
            None => {
                let (z, _) = log
                    .iter()
                    .max_by(|a, b| a.1.total_cmp(&b.1))
                    .ok_or(PlanError::Sim(SimError::Diverged))?;
                let (score, next) = self.fly(sc, state, track, z, evaluations)?;
                Ok(Fallback {
                    depth: z,
                    score,
                    next,
                    safe: false,
                })
            }
        }
    }
}

impl<const K: usize> Planner<K> {
    /// A constrained single track after its scan: decides from the scanned
    /// minimum altitudes whether the optimum lies beyond the safe set (and
    /// answers with the boundary search), whether nothing is safe
    /// (infeasible), or whether the optimizer should run, possibly from a
    /// better start (module docs). Kept out of line: its locals need not
    /// sit on the stack while the optimizer runs.
    #[allow(clippy::too_many_arguments)]
    #[inline(never)]
    fn single_start<const N: usize, const S: usize, const W: usize>(
        &mut self,
        sc: &Scenario<'_, N, S, W>,
        state: &VehicleState<N>,
        track: usize,
        scan: &ScanLog,
        h_safe: f32,
        z0: &mut SVector<f32, K>,
        curvature: &mut SVector<f32, K>,
        evaluations: &mut u32,
    ) -> Result<Option<Plan<N, K>>, PlanError> {
        let best = scan
            .entries()
            .filter(|e| e.1.is_finite())
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let vertex = z0.get(0).copied().unwrap_or(0.0);
        // The scanned neighbour of `from` in the direction of `to`.
        let neighbour = |from: f32, to: f32| {
            scan.entries()
                .filter(|e| (e.0 - from) * (to - from) > 0.0)
                .min_by(|a, b| libm::fabsf(a.0 - from).total_cmp(&libm::fabsf(b.0 - from)))
        };
        // A bracket (safe end, unsafe end) of the boundary when the scan
        // puts the optimum beyond it; `infeasible` when nothing scanned
        // is safe.
        let mut bracket: Option<(End, End)> = None;
        let mut infeasible = false;
        if let Some((z_best, _, alt_best)) = best {
            if alt_best < h_safe {
                let safe = scan.nearest_safe(z_best, h_safe);
                match safe {
                    Some(sf) => {
                        let unsafe_end = neighbour(sf.0, z_best)
                            .map_or((z_best, Some(alt_best)), |e| (e.0, Some(e.2)));
                        bracket = Some(((sf.0, Some(sf.2)), unsafe_end));
                    }
                    None => infeasible = true,
                }
            } else if let Some(n) = neighbour(z_best, vertex)
                && n.2 < h_safe
                && libm::fabsf(vertex - z_best) > 0.0
            {
                bracket = Some(((z_best, Some(alt_best)), (n.0, Some(n.2))));
            }
        }
        let mut found: Option<(f32, TrackScore, VehicleState<N>, PlanStatus)> = None;
        if infeasible {
            // The safest scanned depth.
            let z = scan
                .iter()
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .map_or(vertex, |e| e.0);
            let (score, next) = self.fly(sc, state, track, z, evaluations)?;
            found = Some((z, score, next, PlanStatus::Infeasible));
        } else if let Some((good, bad)) = bracket {
            let b = self.boundary(sc, state, track, good, bad, h_safe, evaluations)?;
            let (z_b, score, next) = (b.depth, b.score, b.next);
            // Does `J` decrease from the boundary into the safe set? A
            // finite difference towards the safe side: the boundary
            // search's previous safe depth when it is within
            // `CHECK_STEP` (no extra flight), else one flight there.
            let inward = good.0 - z_b;
            let step = CHECK_STEP.min(libm::fabsf(inward)).copysign(inward);
            let near = b.inner.filter(|p| libm::fabsf(p.0 - z_b) <= CHECK_STEP);
            let (z_in, j_in) = match near {
                Some(p) => p,
                None => {
                    let z = z_b + step;
                    let j = self
                        .fly(sc, state, track, z, evaluations)
                        .map_or(f32::INFINITY, |(s, _)| s.j());
                    (z, j)
                }
            };
            let slope = (j_in - score.j()) / (z_in - z_b);
            if slope * inward < 0.0 {
                // An interior optimum: optimize from the boundary.
                if let Some(slot) = z0.get_mut(0) {
                    *slot = z_b;
                }
                *curvature = SVector::zeros();
            } else {
                found = Some((z_b, score, next, PlanStatus::SafeFallback));
            }
        }
        if let Some((depth, score, next, status)) = found {
            let mut history = Vec::new();
            let _ = history.push(score.j());
            return Ok(Some(self.single_plan(
                depth,
                status,
                score,
                next,
                h_safe,
                0,
                *evaluations,
                history,
            )));
        }
        Ok(None)
    }

    /// The optimizer of a constrained single track left the safe set at
    /// `(z_bad, alt_bad)` (m, m): the optimum lies beyond the boundary it
    /// was descending towards. Searches that boundary between the best safe
    /// depth it evaluated (or else scanned) and the unsafe one.
    #[allow(clippy::too_many_arguments)]
    #[inline(never)]
    fn single_tripped<const N: usize, const S: usize, const W: usize>(
        &mut self,
        sc: &Scenario<'_, N, S, W>,
        state: &VehicleState<N>,
        track: usize,
        (z_bad, alt_bad): (f32, f32),
        best_safe: Option<(f32, f32, f32)>,
        first: &Outcome<K>,
        bounds: &Bounds<K>,
        h_safe: f32,
        scan: &mut ScanLog,
        mut evaluations: u32,
    ) -> Result<Plan<N, K>, PlanError> {
        // The optimizer left the safe set: the optimum lies beyond the
        // boundary it was descending towards. Search that boundary
        // between the best safe depth evaluated (or scanned) and the
        // unsafe one.
        let mut iterations = first.iterations;
        let mut history = first.history.clone();
        let good = match best_safe {
            Some((z, _, alt)) => Some((z, alt)),
            None => scan.nearest_safe(z_bad, h_safe).map(|e| (e.0, e.2)),
        };
        let (depth, score, next, status) = match good {
            Some((z_good, alt_good)) => {
                let b = self.boundary(
                    sc,
                    state,
                    track,
                    (z_good, Some(alt_good)),
                    (z_bad, Some(alt_bad)),
                    h_safe,
                    &mut evaluations,
                )?;
                (b.depth, b.score, b.next, PlanStatus::SafeFallback)
            }
            None => {
                let lo = bounds.lo.get(0).copied().unwrap_or(z_bad);
                let hi = bounds.hi.get(0).copied().unwrap_or(z_bad);
                let fb = self.fallback(
                    sc,
                    state,
                    track,
                    (z_bad, Some(alt_bad)),
                    lo,
                    hi,
                    h_safe,
                    scan,
                    &mut evaluations,
                )?;
                let status = if fb.safe {
                    PlanStatus::SafeFallback
                } else {
                    PlanStatus::Infeasible
                };
                (fb.depth, fb.score, fb.next, status)
            }
        };
        // The boundary search counts as one iteration, after the optimizer's
        // (history: the start, then one value per iteration).
        if !history.is_empty() {
            iterations = iterations.saturating_add(1);
        }
        let _ = history.push(score.j());
        Ok(self.single_plan(
            depth,
            status,
            score,
            next,
            h_safe,
            iterations,
            evaluations,
            history,
        ))
    }

    /// The answer of a single-track solve decided without the general
    /// path's verification (the depth's flight is at hand).
    #[allow(clippy::too_many_arguments)]
    fn single_plan<const N: usize>(
        &mut self,
        depth: f32,
        status: PlanStatus,
        score: TrackScore,
        next: VehicleState<N>,
        h_safe: f32,
        iterations: u32,
        evaluations: u32,
        history: Vec<f32, HISTORY>,
    ) -> Plan<N, K> {
        let mut horizon = [0.0_f32; K];
        if let Some(first) = horizon.first_mut() {
            *first = depth;
        }
        self.warm = None;
        crate::log::debug!(
            "plan: depth {=f32} m, {=str}, J {=f32} m3, min altitude {=f32} m, {=u32} iterations, {=u32} evaluations",
            depth,
            status.as_str(),
            score.j(),
            score.min_altitude(),
            iterations,
            evaluations
        );
        Plan {
            depth,
            status,
            safe: score.min_altitude() >= h_safe,
            j: score.j(),
            rms: score.rms(),
            min_altitude: score.min_altitude(),
            objective: score.j(),
            iterations,
            evaluations,
            grad_norm: 0.0,
            history,
            horizon,
            horizon_len: 1,
            next_state: next,
        }
    }

    /// The safe-set boundary between a safe depth `good` and an unsafe one
    /// `bad` (each with its minimum altitude when known), from the safe
    /// side, by root finding on `g(z) = min altitude − h_safe` inside the
    /// bracket. `g` is typically a hinge: flat where the track's lowest
    /// point is passed before the vehicle reaches its reference, falling
    /// about a metre per metre of reference depth beyond. So the first
    /// step (and any step after an unsafe flight that gave no usable
    /// secant) moves from the unsafe end by its altitude deficit, which
    /// lands on the boundary on the sloped side; then the secant through
    /// the two latest flights, and the Illinois variant of regula falsi on
    /// the bracket when the secant falls outside it. Each aims at half the
    /// tolerance above `h_safe`. Stops when the safe end is within
    /// a tolerance of `h_safe` (0.2 % of `h_r − h_a`, within 1 mm and
    /// `BOUNDARY_ALTITUDE`), the bracket is under
    /// `BOUNDARY_DEPTH`, or after `bisection_steps` flights (bisection
    /// would need sixteen for a millimetre). Returns the safe end with its
    /// flight, and the safe end before it.
    #[allow(clippy::too_many_arguments)]
    fn boundary<const N: usize, const S: usize, const W: usize>(
        &self,
        sc: &Scenario<'_, N, S, W>,
        state: &VehicleState<N>,
        track: usize,
        (good, good_alt): (f32, Option<f32>),
        (bad, bad_alt): (f32, Option<f32>),
        h_safe: f32,
        evaluations: &mut u32,
    ) -> Result<Boundary<N>, PlanError> {
        // Each end's minimum altitude, flown unless the caller knows it.
        let (mut good, mut flight) = (good, None);
        let mut g_good = match good_alt {
            Some(a) => a - h_safe,
            None => {
                let f = self.fly(sc, state, track, good, evaluations)?;
                flight = Some(f);
                f.0.min_altitude() - h_safe
            }
        };
        // The altitude tolerance: `J` changes by about `2 δz / (h_r − h_a)`
        // relatively when the boundary moves by `δz`, so 0.2 % of the
        // envelope keeps that under 0.4 %; at most `BOUNDARY_ALTITUDE`, at
        // least a millimetre.
        let m = sc.mission();
        let tol = (BOUNDARY_SHARE * (m.reference_altitude() - m.min_altitude()))
            .clamp(BOUNDARY_DEPTH, BOUNDARY_ALTITUDE);
        let mut bad = bad;
        let mut inner = None;
        // The two latest flights `(z, g)`, newest first.
        let mut latest: Option<((f32, f32), (f32, f32))> = None;
        let mut g_bad = match bad_alt {
            Some(a) => a - h_safe,
            None => match self.fly(sc, state, track, bad, evaluations) {
                Ok((s, _)) => s.min_altitude() - h_safe,
                Err(_) => -1.0,
            },
        };
        // Which end the last two steps kept (Illinois halves its value).
        let mut kept_good = false;
        let mut kept_bad = false;
        for step in 0..self.cfg.bisection_steps {
            if g_good <= tol || libm::fabsf(good - bad) <= BOUNDARY_DEPTH {
                break;
            }
            // Regula falsi, kept inside the middle 98 % of the bracket.
            let t = if g_good > 0.0 && g_bad < 0.0 && (g_good - g_bad).is_finite() {
                (g_good / (g_good - g_bad)).clamp(0.01, 0.99)
            } else {
                0.5
            };
            // The first step from the unsafe end instead: where the vehicle
            // holds its reference depth, the minimum altitude falls metre
            // for metre as the reference deepens, and is flat where the
            // minimum is set before the vehicle gets there (a hinge, on
            // which a secant through a flat end is slow). So move from the
            // unsafe end by its altitude deficit (plus half the tolerance):
            // on the hinge's sloped side that lands on the boundary.
            // Later steps take the secant through the two latest flights
            // (superlinear on the sloped side) when it falls inside the
            // bracket, aiming at half the tolerance above the boundary.
            let width = libm::fabsf(good - bad);
            let unit = -g_bad + 0.5 * tol;
            let aim = |z: f32| (z - good) / (bad - good);
            // The secant, when it has two distinct altitudes and lands
            // inside the bracket.
            let secant = latest.and_then(|((z1, g1), (z2, g2))| {
                let ts = aim(z1 + (0.5 * tol - g1) * (z1 - z2) / (g1 - g2));
                (libm::fabsf(g1 - g2) > 0.0 && ts > 0.01 && ts < 0.99).then_some(ts)
            });
            // The unit step from the unsafe end: first, and whenever the
            // newest flight was unsafe and gave no usable secant (both on
            // a flat stretch).
            let newest_bad = latest.is_none_or(|((_, g1), _)| g1 < 0.0);
            let t = match secant {
                _ if step == 0 && g_bad < 0.0 && unit < width => 1.0 - unit / width,
                Some(ts) => ts,
                None if newest_bad && g_bad < 0.0 && unit < width => 1.0 - unit / width,
                None => t,
            };
            let mid = good + t * (bad - good);
            let flown = self.fly(sc, state, track, mid, evaluations);
            let g_mid = flown
                .as_ref()
                .map_or(f32::NEG_INFINITY, |(s, _)| s.min_altitude() - h_safe);
            latest = g_mid
                .is_finite()
                .then(|| ((mid, g_mid), latest.map_or((bad, g_bad), |l| l.0)));
            match flown {
                Ok((s, n)) if s.min_altitude() >= h_safe => {
                    if let Some((f, _)) = flight {
                        inner = Some((good, f.j()));
                    }
                    good = mid;
                    g_good = s.min_altitude() - h_safe;
                    flight = Some((s, n));
                    if kept_bad {
                        g_bad *= 0.5;
                    }
                    kept_bad = true;
                    kept_good = false;
                }
                r => {
                    bad = mid;
                    g_bad = r.map_or(-1.0, |(s, _)| s.min_altitude() - h_safe);
                    if kept_good {
                        g_good *= 0.5;
                    }
                    kept_good = true;
                    kept_bad = false;
                }
            }
        }
        let (score, next) = match flight {
            Some(f) => f,
            None => self.fly(sc, state, track, good, evaluations)?,
        };
        Ok(Boundary {
            depth: good,
            score,
            next,
            inner,
        })
    }
}

/// How [`Planner::optimize_onto`] merges a run.
#[derive(Clone, Copy)]
enum Merge {
    /// The first run: replaces.
    First,
    /// A continuation of the last run.
    Continue,
    /// A restart, kept only if better.
    IfBetter,
}

/// One end of a boundary bracket: a depth (m) and its minimum altitude
/// (m) when known.
type End = (f32, Option<f32>);

/// What [`Planner::boundary`] found.
struct Boundary<const N: usize> {
    /// The safe end, m, its score and end state.
    depth: f32,
    score: TrackScore,
    next: VehicleState<N>,
    /// The safe end before it, with its `J` (m, m³), if it moved.
    inner: Option<(f32, f32)>,
}

/// The boundary search stops when the safe end is within this much of the
/// certified altitude `h_a + m_s` at most, m (where `h_r − h_a` is 10 m or
/// more).
const BOUNDARY_ALTITUDE: f32 = 0.02;

/// ... or within this share of `h_r − h_a`, if less.
const BOUNDARY_SHARE: f32 = 0.002;

/// The finite-difference step, m, that checks a boundary optimum (`J` must
/// not decrease into the safe set).
const CHECK_STEP: f32 = 2.0;

/// ... or when the bracket is this narrow, m (see `BOUNDARY_ALTITUDE`).
const BOUNDARY_DEPTH: f32 = 1e-3;

/// Point `k` of `n >= 2` evenly spaced over `[lo, hi]`.
fn grid(lo: f32, hi: f32, k: u32, n: u32) -> f32 {
    let z = lo + (hi - lo) * (k as f32) / (n.saturating_sub(1).max(1) as f32);
    // Rounding must not put a point outside the box (hence, possibly,
    // outside the depth limits).
    if z > hi {
        hi
    } else if z < lo {
        lo
    } else {
        z
    }
}

struct Fallback<const N: usize> {
    depth: f32,
    score: TrackScore,
    next: VehicleState<N>,
    safe: bool,
}

/// Depths tried on the committed track, with their `J` and minimum
/// altitudes.
struct ScanLog {
    z: [f32; MAX_SCAN as usize],
    j: [f32; MAX_SCAN as usize],
    alt: [f32; MAX_SCAN as usize],
    len: usize,
}

impl Default for ScanLog {
    fn default() -> Self {
        Self {
            z: [0.0; MAX_SCAN as usize],
            j: [0.0; MAX_SCAN as usize],
            alt: [0.0; MAX_SCAN as usize],
            len: 0,
        }
    }
}

impl ScanLog {
    fn push(&mut self, z: f32, s: &TrackScore) {
        if let (Some(zs), Some(js), Some(a)) = (
            self.z.get_mut(self.len),
            self.j.get_mut(self.len),
            self.alt.get_mut(self.len),
        ) {
            *zs = z;
            *js = s.j();
            *a = s.min_altitude();
            self.len = self.len.saturating_add(1);
        }
    }

    /// `(z, alt)` of each entry.
    fn iter(&self) -> impl Iterator<Item = (f32, f32)> + '_ {
        self.z
            .iter()
            .copied()
            .zip(self.alt.iter().copied())
            .take(self.len)
    }

    /// The entry `(z, J, alt)` nearest to `z` (m) whose minimum altitude is
    /// at least `h_safe` (m), if any.
    fn nearest_safe(&self, z: f32, h_safe: f32) -> Option<(f32, f32, f32)> {
        self.entries()
            .filter(|e| e.2 >= h_safe)
            .min_by(|a, b| libm::fabsf(a.0 - z).total_cmp(&libm::fabsf(b.0 - z)))
    }

    /// `(z, J, alt)` of each entry.
    fn entries(&self) -> impl Iterator<Item = (f32, f32, f32)> + '_ {
        self.z
            .iter()
            .copied()
            .zip(self.j.iter().copied())
            .zip(self.alt.iter().copied())
            .map(|((z, j), a)| (z, j, a))
            .take(self.len)
    }
}

/// The box of depths worth searching for each track of the horizon (see
/// the module docs); variables past `h` are pinned.
fn search_box<const N: usize, const S: usize, const W: usize, const K: usize>(
    sc: &Scenario<'_, N, S, W>,
    state: &VehicleState<N>,
    track: usize,
    h: usize,
) -> Bounds<K> {
    let ap = sc.vehicle().autopilot().config();
    let angle = ((1.3 * ap.pitch_limit).min(90.0) * DEG).min(core::f32::consts::FRAC_PI_2);
    let (sin, _) = crate::num::sin_cos(angle);
    let saturation = if ap.depth_pid.kp > 0.0 {
        3.0 * ap.pitch_limit / ap.depth_pid.kp
    } else {
        f32::INFINITY
    };
    let [dmin, dmax] = sc.mission().depth_limits();
    let wp = sc.waypoints().positions();
    let d = state.depth();
    let mut reach = saturation + 20.0;
    let mut b = Bounds::<K>::uniform(dmin, dmin);
    for j in 0..h.min(K) {
        let t = track.saturating_add(j);
        let len = match (wp.get(t), wp.get(t.saturating_add(1))) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        };
        reach += len * sin;
        let lo = (d - reach).max(dmin).min(dmax);
        let hi = (d + reach).max(dmin).min(dmax);
        if let (Some(l), Some(u)) = (b.lo.get_mut(j), b.hi.get_mut(j)) {
            *l = lo;
            *u = hi;
        }
    }
    b
}

/// `Φ(ζ) = Σ J + μ Σ V` over the horizon, with its exact gradient.
struct PlanObjective<'a, 'b, const N: usize, const S: usize, const W: usize> {
    sc: &'a Scenario<'b, N, S, W>,
    start: &'a VehicleState<N>,
    track: usize,
    count: usize,
    mu: f32,
    evaluations: u32,
    /// `Σ V` at the last point evaluated: the optimizers' last evaluation
    /// is always the point they return.
    last_violation: f32,
    /// With one track: the last depth evaluated, its score and end state,
    /// which the verification then need not fly again.
    last_flight: Option<(f32, TrackScore, VehicleState<N>)>,
    /// With one track, constrained: the certified altitude `h_a + m_s`. The
    /// first depth evaluated below it stops the optimizer (every later
    /// evaluation fails without a flight), so that the boundary search
    /// takes over from the best safe depth it had reached.
    guard: Option<f32>,
    /// That first unsafe depth and its minimum altitude (m, m).
    tripped: Option<(f32, f32)>,
    /// The safe depth of least `J` evaluated, with `J` and its minimum
    /// altitude (m, m³, m).
    best_safe: Option<(f32, f32, f32)>,
}

impl<const N: usize, const S: usize, const W: usize, const K: usize> Objective<K>
    for PlanObjective<'_, '_, N, S, W>
{
    type Error = SimError;

    fn eval(&mut self, z: &SVector<f32, K>) -> Result<(f32, SVector<f32, K>), SimError> {
        if self.tripped.is_some() {
            return Err(SimError::Diverged);
        }
        self.evaluations = self.evaluations.saturating_add(1);
        let depths: [f32; K] = (*z).into();
        let e = self
            .sc
            .evaluate_tracks(self.start, self.track, &depths, self.count)?;
        if let (Some(h_safe), 1, Some(&z0)) = (self.guard, self.count, z.get(0)) {
            if e.min_altitude < h_safe {
                self.tripped = Some((z0, e.min_altitude));
                return Err(SimError::Diverged);
            }
            if self.best_safe.is_none_or(|b| e.j < b.1) {
                self.best_safe = Some((z0, e.j, e.min_altitude));
            }
        }
        let g = SVector::from(e.grad_j) + SVector::from(e.grad_violation) * self.mu;
        self.last_violation = e.violation;
        self.last_flight = match (self.count, e.scores.first(), z.get(0)) {
            (1, Some(s), Some(&z0)) => Some((z0, *s, e.end)),
            _ => None,
        };
        Ok((e.j + self.mu * e.violation, g))
    }
}
