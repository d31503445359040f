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
//! **Starting point.** A coarse scan of `scan_points` depths over the box,
//! track by track from the state the best of the previous track leaves:
//! the search starts in the best basin found, never on a plateau that is
//! not the best scanned value. In horizon mode later calls start from the
//! previous call's plan, and only the newly visible track is scanned.
//!
//! **Constraint.** `h >= h_a` enters the optimization as a quadratic
//! penalty: `Φ = Σ J + μ Σ V` with `V = ½ ∫ max(0, h_a + m_p − h)² dx`
//! (the violation of [`crate::TrackScore`], taken against `h_a` plus the
//! penalty margin `m_p`), whose exact gradient comes from the same tangent
//! pass. `J` ranges from 1e2 to 1e8 m³ between a shallow bay and a canyon
//! wall, so no single `μ` fits: the sequential penalty method (N&W §17.1)
//! re-solves from the last optimum with `μ` a hundred times larger while
//! that optimum still violates, for at most `penalty_stages` stages (one
//! when a single track is optimized: the bisection below then finds the
//! safe boundary exactly). Then the committed depth is **verified by simulation**: it is
//! reported safe only when the track's minimum altitude is at least
//! `h_a + m_s` (the safety margin, covering f32 vs f64 differences in
//! altitude). If not, the planner looks for the safe depth closest to the
//! optimum (among the scanned depths, then by bisection to the safe-set
//! boundary) and returns it flagged [`PlanStatus::SafeFallback`]; if no
//! depth in the box is safe, it returns the safest depth it found, flagged
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
    /// more, m (a single track is penalized at `h_a` itself and its
    /// boundary found exactly by the verification). Default 0.25.
    pub penalty_margin: f32,
    /// Safety margin `m_s` above `h_a` for a depth to be reported safe, m.
    /// Default 0.002: the f32 core's altitudes agree with an f64 reference
    /// to 2.4e-4 m on the golden fixtures and 4e-4 m on random unseen
    /// cases, so 2 mm covers them five times over; a wider margin costs `J`
    /// measurably where `h_r` is a few metres.
    pub safety_margin: f32,
    /// Depths scanned per track for the starting point, ≥ 2. Default 9.
    pub scan_points: u32,
    /// Bisection steps towards the safe-set boundary in a fallback.
    /// Default 16 (a 50 m bracket to under a millimetre).
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
        let h = match self.cfg.mode {
            Mode::TrackWise => 1,
            Mode::Horizon => self.cfg.horizon.min(K).min(remaining),
        };
        // One track: no penalty margin, since the verification's bisection
        // then lands on the exact safe boundary instead of `m_p` above it.
        // A horizon keeps the margin for the tracks after the first, which
        // no bisection corrects.
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
        };
        // A warm start is already close: a shorter first step.
        let first_step = if warm.is_some() {
            self.cfg.bfgs.first_step * WARM_FIRST_STEP
        } else {
            self.cfg.bfgs.first_step
        };
        let cap = self.cfg.bfgs.max_iterations;
        let mut outcome = self.optimize(&mut obj, &z0, &bounds, first_step, cap, &curvature)?;
        let mut iterations = outcome.iterations;
        // One track: the verification's bisection finds the safe boundary
        // exactly, a stiffer penalty stage would only cost iterations.
        let stages = if h == 1 { 1 } else { self.cfg.penalty_stages };
        let max_mu =
            self.cfg.penalty_weight * libm::powf(PENALTY_GROWTH, stages.saturating_sub(1) as f32);
        // The iteration cap bounds the whole solve, all stages together.
        while obj.mu > 0.0 && obj.mu < max_mu && obj.last_violation > 0.0 && iterations < cap {
            obj.mu *= PENALTY_GROWTH;
            let next = self.optimize(
                &mut obj,
                &outcome.z,
                &bounds,
                first_step,
                cap.saturating_sub(iterations),
                &SVector::zeros(),
            )?;
            iterations = iterations.saturating_add(next.iterations);
            let mut history = outcome.history;
            for &v in next.history.iter().skip(1) {
                let _ = history.push(v);
            }
            outcome = Outcome { history, ..next };
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
                    let next = self.optimize(
                        &mut obj,
                        &z,
                        &bounds,
                        first_step,
                        budget,
                        &SVector::zeros(),
                    )?;
                    if next.j < outcome.j {
                        // The scan's jump counts as one iteration.
                        iterations = iterations.saturating_add(next.iterations).saturating_add(1);
                        let mut history = outcome.history;
                        for &v in next.history.iter() {
                            let _ = history.push(v);
                        }
                        outcome = Outcome { history, ..next };
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
        let h_safe = sc.mission().min_altitude() + self.cfg.safety_margin;
        let verified = score.min_altitude() >= h_safe;
        if self.cfg.constrained && !verified {
            let lo = bounds.lo.get(0).copied().unwrap_or(depth);
            let hi = bounds.hi.get(0).copied().unwrap_or(depth);
            let fb = self.fallback(
                sc,
                state,
                track,
                z_opt,
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

    /// One optimizer run on `obj` from `z0`.
    fn optimize<const N: usize, const S: usize, const W: usize>(
        &self,
        obj: &mut PlanObjective<'_, '_, N, S, W>,
        z0: &SVector<f32, K>,
        bounds: &Bounds<K>,
        first_step: f32,
        max_iterations: u32,
        curvature: &SVector<f32, K>,
    ) -> Result<Outcome<K>, PlanError> {
        let bfgs = BfgsConfig {
            first_step,
            max_iterations,
            ..self.cfg.bfgs
        };
        let out = match self.cfg.method {
            Method::Bfgs => optim::bfgs_from(obj, z0, bounds, &bfgs, &bfgs.armijo, curvature),
            Method::GradientDescent => {
                let gd = GdConfig {
                    rate: self.cfg.gd_rate,
                    max_iterations,
                    tol: self.cfg.bfgs.tol,
                };
                optim::gradient_descent(obj, z0, bounds, &gd)
            }
        };
        out.map_err(|e| match e {
            OptimError::Config(p) => PlanError::Config(p),
            OptimError::Start(e) => PlanError::Sim(e),
            OptimError::NonFinite => PlanError::Sim(SimError::Diverged),
        })
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
            let n = self.cfg.scan_points;
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
                    log.push(z, s.min_altitude());
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
        z_opt: f32,
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
                    log.push(z, s.min_altitude());
                }
            }
        }
        let nearest_safe = log
            .iter()
            .filter(|&(_, alt)| alt >= h_safe)
            .min_by(|a, b| libm::fabsf(a.0 - z_opt).total_cmp(&libm::fabsf(b.0 - z_opt)));
        match nearest_safe {
            Some((z_safe, _)) => {
                // Bisection on [unsafe z_opt, safe z_safe] to the boundary.
                let (mut bad, mut good) = (z_opt, z_safe);
                for _ in 0..self.cfg.bisection_steps {
                    let mid = 0.5 * (bad + good);
                    let safe = self
                        .fly(sc, state, track, mid, evaluations)
                        .is_ok_and(|(s, _)| s.min_altitude() >= h_safe);
                    if safe {
                        good = mid;
                    } else {
                        bad = mid;
                    }
                }
                let (score, next) = self.fly(sc, state, track, good, evaluations)?;
                Ok(Fallback {
                    depth: good,
                    score,
                    next,
                    safe: score.min_altitude() >= h_safe,
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

/// Point `k` of `n >= 2` evenly spaced over `[lo, hi]`.
fn grid(lo: f32, hi: f32, k: u32, n: u32) -> f32 {
    lo + (hi - lo) * (k as f32) / (n.saturating_sub(1).max(1) as f32)
}

struct Fallback<const N: usize> {
    depth: f32,
    score: TrackScore,
    next: VehicleState<N>,
    safe: bool,
}

/// Depths tried on the committed track and their minimum altitudes.
struct ScanLog {
    z: [f32; MAX_SCAN as usize],
    alt: [f32; MAX_SCAN as usize],
    len: usize,
}

impl Default for ScanLog {
    fn default() -> Self {
        Self {
            z: [0.0; MAX_SCAN as usize],
            alt: [0.0; MAX_SCAN as usize],
            len: 0,
        }
    }
}

impl ScanLog {
    fn push(&mut self, z: f32, alt: f32) {
        if let (Some(zs), Some(a)) = (self.z.get_mut(self.len), self.alt.get_mut(self.len)) {
            *zs = z;
            *a = alt;
            self.len = self.len.saturating_add(1);
        }
    }

    fn iter(&self) -> impl Iterator<Item = (f32, f32)> + '_ {
        self.z
            .iter()
            .copied()
            .zip(self.alt.iter().copied())
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
    let sin = libm::sinf((1.3 * ap.pitch_limit).min(90.0) * DEG);
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
}

impl<const N: usize, const S: usize, const W: usize, const K: usize> Objective<K>
    for PlanObjective<'_, '_, N, S, W>
{
    type Error = SimError;

    fn eval(&mut self, z: &SVector<f32, K>) -> Result<(f32, SVector<f32, K>), SimError> {
        self.evaluations = self.evaluations.saturating_add(1);
        let depths: [f32; K] = (*z).into();
        let e = self
            .sc
            .evaluate_tracks(self.start, self.track, &depths, self.count)?;
        let g = SVector::from(e.grad_j) + SVector::from(e.grad_violation) * self.mu;
        self.last_violation = e.violation;
        self.last_flight = match (self.count, e.scores.first(), z.get(0)) {
            (1, Some(s), Some(&z0)) => Some((z0, *s, e.end)),
            _ => None,
        };
        Ok((e.j + self.mu * e.violation, g))
    }
}
