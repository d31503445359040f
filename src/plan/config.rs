//! The planner's settings ([`PlannerConfig`], validated into a typed
//! [`PlanConfigError`]) and its choices ([`Method`], [`Mode`]).

use core::fmt;

use crate::model::Mission;
use crate::optim::{BfgsConfig, OptimConfigError};

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
    /// violation are both m³). Default 1e4. Used by gradient descent, a
    /// single track and the scan's `J + μ V`; a horizon under BFGS is an
    /// SQP, without a penalty in its objective.
    pub penalty_weight: f32,
    /// Penalty stages (gradient descent, a single track): each re-solves
    /// with `μ` ×100 while the optimum still violates. ≥ 1. Default 2 (μ
    /// up to 1e6). A warm-started call starts at the `μ` the previous call
    /// ended with.
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
    /// Most flights (simulations) of one call, every kind counted: scan,
    /// optimizer evaluations, verification and fallback, certification
    /// (one line flight per declared world), the committed depth's flight
    /// and the worlds' advance; ≥ 1, a hard bound ([`crate::Plan::evaluations`]
    /// never exceeds it). The call sets aside the flights of its fallback
    /// (the previous certified continuation, else a terrain rule or the
    /// climb) and commits
    /// the best certified plan it finds within the rest (the optimizer's
    /// stop is then `OptimizerStop::Budget`): a budget costs `J`, never
    /// safety. Below the fallback's flights (1 when nothing is declared,
    /// `1 + 2 W` for `W` declared worlds on a fresh start) the call returns
    /// [`crate::PlanError::BudgetTooSmall`]. Default `u32::MAX`: no budget
    /// (the iteration cap decides).
    pub max_evaluations: u32,
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
            max_evaluations: u32::MAX,
        }
    }
}

impl PlannerConfig {
    /// The certified altitude `h_a + m_s` of mission `m`, m: what a safe
    /// plan's least altitude clears (`safety_margin`).
    pub(super) fn certified_altitude(&self, m: &Mission) -> f32 {
        m.min_altitude() + self.safety_margin
    }

    /// `Ok` when every setting is in range, else the first that is not.
    ///
    /// # Errors
    /// [`PlanConfigError`] naming it.
    pub fn validate(&self) -> Result<(), PlanConfigError> {
        self.bfgs.validate()?;
        if !(self.gd_rate.is_finite() && self.gd_rate > 0.0) {
            return Err(OptimConfigError::GdRate.into());
        }
        if self.horizon == 0 {
            return Err(PlanConfigError::Horizon);
        }
        if !(self.penalty_weight.is_finite() && self.penalty_weight >= 0.0) {
            return Err(PlanConfigError::PenaltyWeight);
        }
        if self.penalty_stages == 0 {
            return Err(PlanConfigError::PenaltyStages);
        }
        if !(self.penalty_margin.is_finite() && self.penalty_margin >= 0.0) {
            return Err(PlanConfigError::PenaltyMargin);
        }
        if !(self.safety_margin.is_finite() && self.safety_margin >= 0.0) {
            return Err(PlanConfigError::SafetyMargin);
        }
        if self.scan_points < 2 || self.scan_points > MAX_SCAN {
            return Err(PlanConfigError::ScanPoints);
        }
        if self.track_scan_points < 2 || self.track_scan_points > MAX_SCAN {
            return Err(PlanConfigError::TrackScanPoints);
        }
        if self.max_evaluations == 0 {
            return Err(PlanConfigError::MaxEvaluations);
        }
        Ok(())
    }
}

/// Most scan points per track.
pub const MAX_SCAN: u32 = 64;

/// A planner setting out of range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum PlanConfigError {
    /// An optimizer setting (BFGS, Armijo, GD, tolerances).
    Optimizer(OptimConfigError),
    /// `horizon` is 0.
    Horizon,
    /// `penalty_weight` is not finite and non-negative.
    PenaltyWeight,
    /// `penalty_stages` is 0.
    PenaltyStages,
    /// `penalty_margin` is not finite and non-negative (m).
    PenaltyMargin,
    /// `safety_margin` is not finite and non-negative (m).
    SafetyMargin,
    /// `scan_points` is not in `2..=MAX_SCAN`.
    ScanPoints,
    /// `track_scan_points` is not in `2..=MAX_SCAN`.
    TrackScanPoints,
    /// `max_evaluations` is 0.
    MaxEvaluations,
}

impl PlanConfigError {
    /// The setting's name, as the host tool's config file spells it.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Optimizer(e) => e.name(),
            Self::Horizon => "horizon",
            Self::PenaltyWeight => "penalty_weight",
            Self::PenaltyStages => "penalty_stages",
            Self::PenaltyMargin => "penalty_margin",
            Self::SafetyMargin => "safety_margin",
            Self::ScanPoints => "scan_points",
            Self::TrackScanPoints => "track_scan_points",
            Self::MaxEvaluations => "max_evaluations",
        }
    }
}

impl fmt::Display for PlanConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "planner setting {} is out of range", self.name())
    }
}

impl core::error::Error for PlanConfigError {}

impl From<OptimConfigError> for PlanConfigError {
    fn from(e: OptimConfigError) -> Self {
        Self::Optimizer(e)
    }
}
