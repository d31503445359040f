//! The vehicle as the planner sees it: speed, sample time, plant and
//! autopilot, validated together.

use super::autopilot::{Autopilot, AutopilotConfig};
use super::check::{ConfigError, positive};
use super::plant::{Plant, TransferFunction};

/// Power-iteration steps of the stability check (4 096 to settle on the
/// dominant mode, then the window), and the window over which the growth
/// is measured (on the M4F about 4.0 M instructions, once, at
/// configuration). The window is long against the loop's slowest
/// modes: a slow, damped oscillation (a complex pair of modulus just under
/// 1, whose eigenvectors are far from orthogonal) swells a disturbance's
/// norm by a bounded factor within each period, which a short window reads
/// as growth (a stable loop with spectral radius 0.99897 and a period of
/// 5 600 steps read 1.2 over 1 024 steps; over 16 384 its decay, 5e-8,
/// dominates).
const GROWTH_STEPS: u32 = 20_480;
const GROWTH_WINDOW: u32 = 16_384;
/// A disturbance growing more than this over the window means instability
/// (a dominant eigenvalue above about 1 + 1e-4 per step: 1.1 per 1 024
/// steps, 1.1^16 per window).
const UNSTABLE_GROWTH: f32 = 4.59;
/// Size of the stability check's disturbance (m, deg, …).
const SCALE: f32 = 1e-3;

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

/// Least distance flown per step `U0 Ts` that [`Vehicle::new`] accepts, m.
pub const MIN_STEP_LENGTH: f32 = 1e-4;

impl<const N: usize> Vehicle<N> {
    /// Validates `cfg` and discretizes `tf` at `cfg.sample_time`.
    ///
    /// # Errors
    /// [`ConfigError`] naming the first invalid parameter.
    pub fn new(cfg: &VehicleConfig, tf: TransferFunction<N>) -> Result<Self, ConfigError> {
        positive(cfg.speed, "speed")?;
        positive(cfg.sample_time, "sample_time")?;
        // The distance flown per step, `U0 Ts`, bounds a simulation's step
        // count (a line of `L` metres takes about `L / (U0 Ts)` steps), so
        // it must not underflow: below a tenth of a millimetre per step
        // (say 1 mm/s sampled at 10 kHz) a 4 km line would already take
        // forty million steps.
        let step = cfg.speed * cfg.sample_time;
        if step.is_nan() || step < MIN_STEP_LENGTH {
            return Err(ConfigError::OutOfRange("speed × sample_time"));
        }
        let autopilot = Autopilot::new(&cfg.autopilot, &tf, cfg.sample_time)?;
        let plant = Plant::new(tf, cfg.sample_time)?;
        let v = Self {
            speed: cfg.speed,
            plant,
            autopilot,
        };
        if v.disturbance_growth() > UNSTABLE_GROWTH {
            return Err(ConfigError::UnstableLoop);
        }
        Ok(v)
    }

    /// How much a disturbance of the closed loop, linearized about level
    /// flight on depth (no clamp active, `sin θ ≈ θ`), grows over the last
    /// `GROWTH_WINDOW` of `GROWTH_STEPS` steps: the dominant eigenvalue of
    /// the loop raised to that power, by power iteration on the step map
    /// itself (no matrix is formed). Below 1 the loop is stable; a marginal
    /// mode (an unused integrator, a loop without depth feedback) gives 1.
    fn disturbance_growth(&self) -> f32 {
        let ap = self.autopilot.config();
        let (gd, gp, ts) = (ap.depth_pid, ap.pitch_pid, self.sample_time());
        let step = self.speed * ts * crate::num::DEG;
        // State: η, d, d_prev, I_d, I_θ; a disturbance in every component.
        // Kept at `SCALE` (1 mm, 1 mdeg): far inside the clamps for any
        // sane gains, so the cascade acts linearly.
        let mut eta = nalgebra::SVector::<f32, N>::repeat(0.1 * SCALE);
        let (mut d, mut dp, mut id, mut it) = (SCALE, 0.5 * SCALE, 0.1 * SCALE, 0.1 * SCALE);
        let mut window = 0.0_f32;
        for k in 0..GROWTH_STEPS {
            let theta = self.plant.pitch_v(&eta);
            let q = self.plant.pitch_rate_v(&eta);
            // The control law is the autopilot's own cascade (a unit
            // disturbance keeps it inside its limits, where it is linear).
            let w = self
                .autopilot
                .cascade(&mut id, &mut it, -d, (d - dp) / ts, theta, q)
                .elevator;
            // An integrator whose gain is zero feeds nothing back: leave it
            // out, or its harmless linear drift would read as growth.
            if gd.ki == 0.0 {
                id = 0.0;
            }
            if gp.ki == 0.0 {
                it = 0.0;
            }
            eta = self.plant.step_v(&eta, w);
            let theta_next = self.plant.pitch_v(&eta);
            dp = d;
            d -= step * 0.5 * (theta + theta_next);
            // Renormalize; accumulate the log growth over the last window.
            let norm = libm::sqrtf(eta.norm_squared() + d * d + dp * dp + id * id + it * it);
            if !(norm.is_finite() && norm > 0.0) {
                return if norm == 0.0 { 0.0 } else { f32::INFINITY };
            }
            if k >= GROWTH_STEPS - GROWTH_WINDOW {
                window += libm::logf(norm / SCALE);
            }
            let inv = SCALE / norm;
            eta *= inv;
            d *= inv;
            dp *= inv;
            id *= inv;
            it *= inv;
        }
        libm::expf(window.min(80.0))
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

#[cfg(test)]
mod tests {
    use super::*;

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
        // Each positive, their product (the step) below 0.1 mm or zero.
        for (speed, sample_time) in [(1e-23, 1e-23), (1e-3, 1e-2)] {
            cfg = VehicleConfig {
                speed,
                sample_time,
                ..Default::default()
            };
            assert_eq!(
                Vehicle::new(&cfg, TransferFunction::C_AUV4),
                Err(ConfigError::OutOfRange("speed × sample_time"))
            );
        }
        assert!(Vehicle::c_auv4().is_ok());
    }

    /// Two loops near the edge, judged as their spectral radius (from the
    /// f64 reference, `tools/reference/auvref.py` `spectral_radius`) says:
    /// a slow, damped oscillation (radius 0.998 97, a period of 5 600
    /// steps) that the 1 024-step window read as growing (1.2), and a loop
    /// growing by 7.8e-4 a step that it read as stable.
    #[test]
    fn slow_loops_are_judged_by_their_spectral_radius() {
        let vehicle = |speed, sample_time, depth: [f32; 3], pitch: [f32; 3]| {
            let mut cfg = VehicleConfig {
                speed,
                sample_time,
                ..Default::default()
            };
            let gains = |g: [f32; 3]| crate::model::PidGains {
                kp: g[0],
                ki: g[1],
                kd: g[2],
            };
            cfg.autopilot.depth_pid = gains(depth);
            cfg.autopilot.pitch_pid = gains(pitch);
            Vehicle::new(&cfg, TransferFunction::C_AUV4)
        };
        let slow = vehicle(
            1.649,
            0.0649,
            [1.114, 0.01835, 2.107],
            [1.835, 0.08415, 3.806],
        );
        assert!(slow.is_ok());
        let growing = vehicle(
            0.9772,
            0.0797,
            [3.18, 0.03806, 4.751],
            [0.2907, 0.1631, 5.909],
        );
        assert_eq!(growing, Err(ConfigError::UnstableLoop));
    }

    #[test]
    fn diverging_gains_are_rejected() {
        let unstable = |f: fn(&mut VehicleConfig)| {
            let mut cfg = VehicleConfig::default();
            f(&mut cfg);
            Vehicle::new(&cfg, TransferFunction::C_AUV4)
        };
        // No pitch damping and a stiff pitch loop: the pitch oscillation grows.
        assert_eq!(
            unstable(|c| {
                c.autopilot.pitch_pid.kd = 0.0;
                c.autopilot.pitch_pid.kp = 30.0;
            }),
            Err(ConfigError::UnstableLoop)
        );
        // A depth loop far too stiff for the pitch loop inside it.
        assert_eq!(
            unstable(|c| {
                c.autopilot.depth_pid.kp = 60.0;
                c.autopilot.depth_pid.kd = 0.0;
            }),
            Err(ConfigError::UnstableLoop)
        );
        // The default, a slow integral, and no depth feedback at all are fine.
        assert!(unstable(|_| {}).is_ok());
        assert!(unstable(|c| c.autopilot.depth_pid.ki = 0.02).is_ok());
        assert!(
            unstable(|c| c.autopilot.depth_pid = crate::model::PidGains {
                kp: 0.0,
                ki: 0.0,
                kd: 0.0
            })
            .is_ok()
        );
    }
}
