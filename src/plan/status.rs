//! What a plan is ([`PlanStatus`]) and why the planner could not plan
//! ([`PlanError`]).

use core::fmt;

use crate::optim::Status;
use crate::sim::SimError;

use super::PlanConfigError;

/// What a plan is, for the person or the autopilot that reads it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum PlanStatus {
    /// Safe, and the minimum-altitude constraint is not active: the best
    /// `J` found.
    Optimal,
    /// Safe, on the constraint's boundary: the vehicle flies as close to
    /// `h_r` as `h_a` (and the declared uncertainty) allows.
    Constrained,
    /// No safe depth (with a safe continuation, in horizon mode) was
    /// found: this is the safest one, and
    /// [`crate::Plan::certified_min_altitude`] says how low it goes.
    Infeasible,
}

impl PlanStatus {
    /// The name the host tool prints.
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::Optimal => "optimal",
            Self::Constrained => "constrained",
            Self::Infeasible => "infeasible",
        }
    }
}

impl fmt::Display for PlanStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Why the optimizer stopped: a diagnostic, apart from what the plan is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum OptimizerStop {
    /// A stopping rule held.
    Converged,
    /// The iteration cap came first.
    MaxIterations,
    /// The evaluation budget came first.
    Budget,
    /// The line search made no progress at a point otherwise acceptable.
    Stalled,
    /// No optimizer ran (the scan or the boundary search decided).
    None,
}

impl OptimizerStop {
    /// The name the host tool prints.
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::Converged => "converged",
            Self::MaxIterations => "max_iterations",
            Self::Budget => "budget",
            Self::Stalled => "stalled",
            Self::None => "none",
        }
    }
}

impl fmt::Display for OptimizerStop {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl From<Status> for OptimizerStop {
    fn from(s: Status) -> Self {
        match s {
            Status::Converged => Self::Converged,
            Status::MaxIterations => Self::MaxIterations,
            Status::LineSearchFailed => Self::Stalled,
        }
    }
}

/// How a track's candidate depth was found (internal).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Found {
    /// By the optimizer, which stopped so.
    Optimized(OptimizerStop),
    /// On the safe-set boundary next to the optimum (scan or boundary
    /// search), after the optimizer stopped so.
    Boundary(OptimizerStop),
    /// Nothing scanned or searched was safe for the track.
    Infeasible(OptimizerStop),
}

impl Found {
    /// Why the optimizer stopped.
    pub fn stop(&self) -> OptimizerStop {
        match *self {
            Self::Optimized(s) | Self::Boundary(s) | Self::Infeasible(s) => s,
        }
    }
}

/// Why the planner could not plan.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum PlanError {
    /// A planner setting is out of range.
    Config(PlanConfigError),
    /// `track` is not a track of the line.
    TrackRange,
    /// The start state is below the bottom (constrained planning).
    StartBelowBottom,
    /// The line has more than [`crate::plan::MAX_TRACKS`] tracks from the
    /// call's track (horizon mode certifies to the end of the line).
    LineTooLong,
    /// The mission declares map uncertainty but the scenario has no
    /// certification bottom ([`crate::Scenario::with_certification_bottom`]).
    NoCertificationBottom,
    /// The flight budget ([`crate::PlannerConfig::max_evaluations`]) is
    /// below the flights that committing the call's fallback needs (see
    /// [`crate::Planner::plan`]); nothing was flown.
    BudgetTooSmall {
        /// The least budget this call needs, flights.
        needed: u32,
    },
    /// The simulation failed where no fallback is possible (at the start).
    Sim(SimError),
}

impl fmt::Display for PlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Config(p) => p.fmt(f),
            Self::TrackRange => f.write_str("no such track"),
            Self::StartBelowBottom => f.write_str("the start state is below the bottom"),
            Self::LineTooLong => f.write_str("the line has more tracks than the planner certifies"),
            Self::NoCertificationBottom => f.write_str(
                "map uncertainty declared but no certification bottom given (see lower_envelope)",
            ),
            Self::BudgetTooSmall { needed } => {
                write!(
                    f,
                    "the flight budget is below the {needed} flights a call needs"
                )
            }
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
