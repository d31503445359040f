//! Validation of configuration values: the typed [`ConfigError`] and the
//! small checks every constructor of the model uses.

use core::fmt;

use super::plant::PlantError;

/// Why a configuration value was rejected. The `&'static str` names the
/// parameter, with the key used by the host tool's config file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
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
