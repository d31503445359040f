//! The vehicle as the planner sees it: speed, sample time, plant and
//! autopilot, validated together; and the mission's altitudes and depth
//! limits.

use crate::autopilot::{Autopilot, AutopilotConfig};
use crate::error::{ConfigError, finite, positive};
use crate::plant::{Plant, TransferFunction};

/// Everything about the vehicle that the user configures, with units.
/// `Default` gives the paper's vehicle (model contract §9).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct VehicleConfig {
    /// `U0`, cruising speed, m/s, > 0. Default 1.5.
    pub speed: f32,
    /// `Ts`, autopilot sample time = simulation step, s, > 0. Default 0.1.
    pub sample_time: f32,
    /// Gains and limits of the depth → pitch → elevator cascade.
    pub autopilot: AutopilotConfig,
}

impl Default for VehicleConfig {
    fn default() -> Self {
        Self {
            speed: 1.5,
            sample_time: 0.1,
            autopilot: AutopilotConfig::default(),
        }
    }
}

/// A validated vehicle with its plant of order at most `N`, discretized at
/// the autopilot's sample time.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Vehicle<const N: usize> {
    speed: f32,
    plant: Plant<N>,
    autopilot: Autopilot,
}

impl Vehicle<3> {
    /// The paper's vehicle: C-AUV #4 with the default configuration.
    ///
    /// # Errors
    /// Never in practice; the constructor validates like any other.
    pub fn c_auv4() -> Result<Self, ConfigError> {
        Self::new(&VehicleConfig::default(), TransferFunction::C_AUV4)
    }
}

impl<const N: usize> Vehicle<N> {
    /// Validates `cfg` and discretizes `tf` at `cfg.sample_time`.
    ///
    /// # Errors
    /// [`ConfigError`] naming the first invalid parameter.
    pub fn new(cfg: &VehicleConfig, tf: TransferFunction<N>) -> Result<Self, ConfigError> {
        positive(cfg.speed, "speed")?;
        positive(cfg.sample_time, "sample_time")?;
        let autopilot = Autopilot::new(&cfg.autopilot, &tf, cfg.sample_time)?;
        let plant = Plant::new(tf, cfg.sample_time)?;
        Ok(Self {
            speed: cfg.speed,
            plant,
            autopilot,
        })
    }

    /// `U0`, m/s.
    pub fn speed(&self) -> f32 {
        self.speed
    }

    /// `Ts`, s.
    pub fn sample_time(&self) -> f32 {
        self.plant.sample_time()
    }

    /// The discretized pitch dynamics.
    pub fn plant(&self) -> &Plant<N> {
        &self.plant
    }

    /// The validated autopilot cascade.
    pub fn autopilot(&self) -> &Autopilot {
        &self.autopilot
    }
}

/// The mission's altitude envelope and allowed reference depths.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Mission {
    reference_altitude: f32,
    min_altitude: f32,
    depth_limits: [f32; 2],
}

impl Default for Mission {
    /// The paper's `h_r = 80 m`, `h_a = 60 m`, depths `[0, 6000]` m.
    fn default() -> Self {
        Self {
            reference_altitude: 80.0,
            min_altitude: 60.0,
            depth_limits: [0.0, 6000.0],
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
        })
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

    #[test]
    fn vehicle_validation() {
        let mut cfg = VehicleConfig {
            speed: 0.0,
            ..Default::default()
        };
        assert_eq!(
            Vehicle::new(&cfg, TransferFunction::C_AUV4),
            Err(ConfigError::NotPositive("speed"))
        );
        cfg = VehicleConfig::default();
        cfg.sample_time = -0.1;
        assert_eq!(
            Vehicle::new(&cfg, TransferFunction::C_AUV4),
            Err(ConfigError::NotPositive("sample_time"))
        );
        assert!(Vehicle::c_auv4().is_ok());
    }
}
