//! One umbrella error for callers that prefer a single type. Each layer
//! owns the errors it raises ([`ProfileError`], [`PlantError`],
//! [`ConfigError`], [`WaypointError`] in [`crate::model`]; [`SimError`] in
//! [`crate::sim`]; [`PlanError`] in [`crate::plan`]); this module only
//! imports them, so the dependency graph points down.

use core::fmt;

use crate::model::{ConfigError, PlantError, ProfileError, WaypointError};
use crate::plan::PlanError;
use crate::sim::SimError;

/// Any error of the library.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Error {
    /// A bottom profile was rejected or queried outside its samples.
    Profile(ProfileError),
    /// A transfer function was rejected.
    Plant(PlantError),
    /// A configuration value was rejected.
    Config(ConfigError),
    /// Waypoints were rejected.
    Waypoints(WaypointError),
    /// A simulation could not be run or did not finish.
    Sim(SimError),
    /// The planner could not plan.
    Plan(PlanError),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Profile(e) => e.fmt(f),
            Self::Plant(e) => e.fmt(f),
            Self::Config(e) => e.fmt(f),
            Self::Waypoints(e) => e.fmt(f),
            Self::Sim(e) => e.fmt(f),
            Self::Plan(e) => e.fmt(f),
        }
    }
}

impl core::error::Error for Error {}

impl From<ProfileError> for Error {
    fn from(e: ProfileError) -> Self {
        Self::Profile(e)
    }
}
impl From<PlantError> for Error {
    fn from(e: PlantError) -> Self {
        Self::Plant(e)
    }
}
impl From<ConfigError> for Error {
    fn from(e: ConfigError) -> Self {
        Self::Config(e)
    }
}
impl From<WaypointError> for Error {
    fn from(e: WaypointError) -> Self {
        Self::Waypoints(e)
    }
}
impl From<PlanError> for Error {
    fn from(e: PlanError) -> Self {
        Self::Plan(e)
    }
}
impl From<SimError> for Error {
    fn from(e: SimError) -> Self {
        Self::Sim(e)
    }
}
