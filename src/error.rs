//! Configuration errors, and one umbrella error for callers that prefer a
//! single type. Each operation also has its own small error enum beside it
//! ([`ProfileError`], [`PlantError`], [`SimError`]).

use core::fmt;

use crate::plant::PlantError;
use crate::profile::ProfileError;
use crate::sim::SimError;

/// Why a configuration value was rejected. The `&'static str` names the
/// parameter, with the key used by the host tool's config file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConfigError {
    /// The parameter is NaN or infinite.
    NonFinite(&'static str),
    /// The parameter must be strictly positive.
    NotPositive(&'static str),
    /// The parameter must not be negative.
    Negative(&'static str),
    /// The parameter is outside its physical range (e.g. a pitch limit of
    /// 90° or more, where the vehicle would stop advancing).
    OutOfRange(&'static str),
    /// `min_altitude > reference_altitude`.
    MinAltitudeAboveReference,
    /// `depth_limits` has its minimum above its maximum.
    DepthLimitsReversed,
    /// The gains make the closed loop (plant, cascade, kinematics,
    /// linearized about level flight) unstable: a depth or pitch
    /// disturbance grows instead of dying out.
    UnstableLoop,
    /// The plant was rejected.
    Plant(PlantError),
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::NonFinite(p) => write!(f, "{p} is not finite"),
            Self::NotPositive(p) => write!(f, "{p} must be positive"),
            Self::Negative(p) => write!(f, "{p} must not be negative"),
            Self::OutOfRange(p) => write!(f, "{p} is out of range"),
            Self::MinAltitudeAboveReference => {
                f.write_str("min_altitude must not exceed reference_altitude")
            }
            Self::DepthLimitsReversed => f.write_str("depth_limits minimum exceeds maximum"),
            Self::UnstableLoop => f.write_str(
                "the gains make the closed loop unstable (a disturbance grows instead of dying out)",
            ),
            Self::Plant(e) => write!(f, "plant: {e}"),
        }
    }
}

impl core::error::Error for ConfigError {}

impl From<PlantError> for ConfigError {
    fn from(e: PlantError) -> Self {
        Self::Plant(e)
    }
}

/// Any error of the library.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error {
    /// A bottom profile was rejected or queried outside its samples.
    Profile(ProfileError),
    /// A transfer function was rejected.
    Plant(PlantError),
    /// A configuration value was rejected.
    Config(ConfigError),
    /// A simulation could not be run or did not finish.
    Sim(SimError),
    /// The planner could not plan.
    Plan(crate::planner::PlanError),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Profile(e) => e.fmt(f),
            Self::Plant(e) => e.fmt(f),
            Self::Config(e) => e.fmt(f),
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
impl From<crate::sim::WaypointError> for Error {
    fn from(e: crate::sim::WaypointError) -> Self {
        Self::Sim(SimError::Waypoints(e))
    }
}
impl From<crate::planner::PlanError> for Error {
    fn from(e: crate::planner::PlanError) -> Self {
        Self::Plan(e)
    }
}
impl From<SimError> for Error {
    fn from(e: SimError) -> Self {
        Self::Sim(e)
    }
}

/// `Ok(v)` when `v` is finite, else [`ConfigError::NonFinite`].
pub(crate) fn finite(v: f32, name: &'static str) -> Result<f32, ConfigError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ConfigError::NonFinite(name))
    }
}

/// `Ok(v)` when `v` is finite and `> 0`.
pub(crate) fn positive(v: f32, name: &'static str) -> Result<f32, ConfigError> {
    if finite(v, name)? > 0.0 {
        Ok(v)
    } else {
        Err(ConfigError::NotPositive(name))
    }
}

/// `Ok(v)` when `v` is finite and `>= 0`.
pub(crate) fn non_negative(v: f32, name: &'static str) -> Result<f32, ConfigError> {
    if finite(v, name)? >= 0.0 {
        Ok(v)
    } else {
        Err(ConfigError::Negative(name))
    }
}
