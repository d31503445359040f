//! The mission's envelope: the reference and minimum altitudes, the
//! allowed reference depths, and the uncertainty the plan is certified
//! against.

use super::check::{ConfigError, finite, positive};
use super::uncertainty::Uncertainty;

/// The mission's altitude envelope, allowed reference depths and declared
/// uncertainty.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Mission {
    reference_altitude: f32,
    min_altitude: f32,
    depth_limits: [f32; 2],
    uncertainty: Uncertainty,
}

impl Default for Mission {
    /// The paper's `h_r = 80 m`, `h_a = 60 m`, depths `[0, 6000]` m.
    fn default() -> Self {
        Self {
            reference_altitude: 80.0,
            min_altitude: 60.0,
            depth_limits: [0.0, 6000.0],
            uncertainty: Uncertainty::NONE,
        }
    }
}

impl Mission {
    /// `h_r` reference altitude (m), `h_a` minimum altitude (m) with
    /// `0 < h_a <= h_r`, and the allowed reference depths `[min, max]` (m).
    ///
    /// # Errors
    /// [`ConfigError`] for non-finite values, `h_a <= 0`, `h_a > h_r`, or
    /// reversed depth limits.
    pub fn new(
        reference_altitude: f32,
        min_altitude: f32,
        depth_limits: [f32; 2],
    ) -> Result<Self, ConfigError> {
        finite(reference_altitude, "reference_altitude")?;
        positive(min_altitude, "min_altitude")?;
        if min_altitude > reference_altitude {
            return Err(ConfigError::MinAltitudeAboveReference);
        }
        let [lo, hi] = depth_limits;
        finite(lo, "depth_limits")?;
        finite(hi, "depth_limits")?;
        if lo > hi {
            return Err(ConfigError::DepthLimitsReversed);
        }
        Ok(Self {
            reference_altitude,
            min_altitude,
            depth_limits,
            uncertainty: Uncertainty::NONE,
        })
    }

    /// The same mission, certified against `uncertainty` (model contract
    /// §12; default none).
    pub fn with_uncertainty(mut self, uncertainty: Uncertainty) -> Self {
        self.uncertainty = uncertainty;
        self
    }

    /// The declared uncertainty.
    pub fn uncertainty(&self) -> &Uncertainty {
        &self.uncertainty
    }

    /// `h_r`, m: the target depth is the bottom shifted up by `h_r`.
    pub fn reference_altitude(&self) -> f32 {
        self.reference_altitude
    }

    /// `h_a`, m: the flight must stay at least this high above the bottom.
    pub fn min_altitude(&self) -> f32 {
        self.min_altitude
    }

    /// Allowed reference depths `[min, max]`, m.
    pub fn depth_limits(&self) -> [f32; 2] {
        self.depth_limits
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mission_validation() {
        assert!(Mission::new(80.0, 60.0, [0.0, 6000.0]).is_ok());
        assert_eq!(
            Mission::new(50.0, 60.0, [0.0, 6000.0]),
            Err(ConfigError::MinAltitudeAboveReference)
        );
        assert_eq!(
            Mission::new(80.0, 0.0, [0.0, 6000.0]),
            Err(ConfigError::NotPositive("min_altitude"))
        );
        assert_eq!(
            Mission::new(80.0, 60.0, [10.0, 0.0]),
            Err(ConfigError::DepthLimitsReversed)
        );
        assert_eq!(
            Mission::new(f32::NAN, 60.0, [0.0, 1.0]),
            Err(ConfigError::NonFinite("reference_altitude"))
        );
    }
}
