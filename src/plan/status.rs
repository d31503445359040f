//! What a plan is ([`PlanStatus`]) and why the planner could not plan
//! ([`PlanError`]).

use core::fmt;

use crate::optim::Status;
use crate::sim::SimError;

use super::PlanConfigError;

/// How the committed depth was obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
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
    /// safest depth found, and [`crate::Plan::min_altitude`] says how low it goes.
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
#[non_exhaustive]
pub enum PlanError {
    /// A planner setting is out of range.
    Config(PlanConfigError),
    /// `track` is not a track of the line.
    TrackRange,
    /// The simulation failed where no fallback is possible (at the start).
    Sim(SimError),
}

impl fmt::Display for PlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Config(p) => p.fmt(f),
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
