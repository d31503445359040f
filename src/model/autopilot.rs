//! The autopilot's depth → pitch → elevator PID cascade (model contract §5),
//! exactly as the vehicle runs it once per sample.
//!
//! Configuration ([`AutopilotConfig`], validated into [`Autopilot`]) is kept
//! apart from state ([`AutopilotState`]), so the very same code runs inside
//! the planner's simulation and in a real autopilot loop:
//!
//! ```
//! use auvnav::{Autopilot, AutopilotConfig, AutopilotState, TransferFunction};
//! let ap = Autopilot::new(&AutopilotConfig::default(), &TransferFunction::C_AUV4, 0.1)?;
//! let mut st = AutopilotState::trimmed(100.0);
//! // 20 m above the reference: pitch nose-down (negative), elevator up.
//! let cmd = ap.update(&mut st, 120.0, 100.0, 0.0, 0.0);
//! assert_eq!(cmd.pitch_ref, -25.0);
//! assert!(cmd.elevator > 0.0);
//! # Ok::<(), auvnav::ConfigError>(())
//! ```
//!
//! Why the control choices:
//! - **Derivative on measurement** (`ḋ`, `q`), not on the error: a waypoint
//!   switch steps the reference, and a derivative of the error would kick the
//!   elevator at every waypoint.
//! - **Clamping anti-windup** (conditional integration): while the output is
//!   saturated, the integrator stops only when integrating would push the
//!   output further into saturation, so it still unwinds.
//! - **The pitch loop's sign** follows the plant: the paper's plant has a
//!   negative DC gain, hence its leading minus; a positive-gain plant flips
//!   the loop and the anti-windup test with it. The depth loop's sign comes
//!   from the kinematics (nose-down goes deeper) and never changes.

use super::check::{ConfigError, non_negative, positive};
use super::plant::TransferFunction;
use crate::num::clamp;

/// Gains of one PID loop. Units depend on the loop (see
/// [`AutopilotConfig`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PidGains {
    /// Proportional gain.
    pub kp: f32,
    /// Integral gain.
    pub ki: f32,
    /// Derivative gain (on the measurement).
    pub kd: f32,
}

/// Gains and limits of the cascade, as the user configures them.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AutopilotConfig {
    /// Depth loop: `kp` deg/m, `ki` deg/(m s), `kd` deg s/m.
    /// Default 1.5, 0.0, 2.0.
    pub depth_pid: PidGains,
    /// Pitch loop: `kp` deg/deg, `ki` 1/s, `kd` s. Default 2.0, 0.1, 3.0.
    pub pitch_pid: PidGains,
    /// `θmax`, pitch reference limit, deg, in (0, 90). Default 25.
    pub pitch_limit: f32,
    /// `δmax`, elevator limit, deg, > 0. Default 25.
    pub elevator_limit: f32,
}

impl Default for AutopilotConfig {
    fn default() -> Self {
        Self {
            depth_pid: PidGains {
                kp: 1.5,
                ki: 0.0,
                kd: 2.0,
            },
            pitch_pid: PidGains {
                kp: 2.0,
                ki: 0.1,
                kd: 3.0,
            },
            pitch_limit: 25.0,
            elevator_limit: 25.0,
        }
    }
}

/// A validated cascade bound to a plant's loop sign and a sample time.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Autopilot {
    cfg: AutopilotConfig,
    sign: f32,
    /// The pitch gains times the loop sign, folded once.
    signed_pitch: PidGains,
    sample_time: f32,
}

/// The cascade's memory between samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AutopilotState {
    /// `I_d = Σ Ts e_d`, m s.
    pub depth_integral: f32,
    /// `I_θ = Σ Ts e_θ`, deg s.
    pub pitch_integral: f32,
    /// Depth measured at the previous sample, m.
    pub depth_prev: f32,
}

impl AutopilotState {
    /// Trimmed start at `depth` (m): integrators zero, no depth rate.
    pub fn trimmed(depth: f32) -> Self {
        Self {
            depth_integral: 0.0,
            pitch_integral: 0.0,
            depth_prev: depth,
        }
    }
}

/// Contributions of one loop's terms to its (unclamped) output.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PidTerms {
    /// Proportional term, deg.
    pub p: f32,
    /// Integral term, deg.
    pub i: f32,
    /// Derivative term, deg.
    pub d: f32,
}

impl PidTerms {
    /// The terms saturated to ±`f32::MAX`: a term that overflowed (absurd
    /// but finite inputs or gains) reads as the largest finite value, so
    /// that telemetry is never infinite. (The command itself is clamped
    /// to its limit either way.)
    #[inline(always)]
    fn saturated(self) -> Self {
        let s = |v: f32| clamp(v, f32::MAX);
        Self {
            p: s(self.p),
            i: s(self.i),
            d: s(self.d),
        }
    }
}

/// What the cascade commands at one sample, with every term for telemetry.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Command {
    /// Pitch reference `θref`, deg (clamped to ±θmax).
    pub pitch_ref: f32,
    /// Elevator `δ`, deg (clamped to ±δmax).
    pub elevator: f32,
    /// Depth-loop terms (their sum is the unclamped `v`, deg; each
    /// saturated to ±`f32::MAX`).
    pub depth_terms: PidTerms,
    /// Pitch-loop terms (their sum is the unclamped `w`, deg; saturated
    /// likewise).
    pub pitch_terms: PidTerms,
    /// `θref` lies inside its limits (the clamp is not active).
    pub pitch_ref_linear: bool,
    /// `δ` lies inside its limits.
    pub elevator_linear: bool,
    /// `I_d` integrated at this sample (anti-windup did not hold it).
    pub depth_integrating: bool,
    /// `I_θ` integrated at this sample.
    pub pitch_integrating: bool,
}

impl Autopilot {
    /// Validates `cfg` for a plant `tf` sampled every `sample_time` s.
    ///
    /// # Errors
    /// [`ConfigError`] for non-finite or negative gains, a pitch limit not in
    /// (0°, 90°), a non-positive elevator limit or sample time.
    pub fn new<const N: usize>(
        cfg: &AutopilotConfig,
        tf: &TransferFunction<N>,
        sample_time: f32,
    ) -> Result<Self, ConfigError> {
        non_negative(cfg.depth_pid.kp, "depth_pid.kp")?;
        non_negative(cfg.depth_pid.ki, "depth_pid.ki")?;
        non_negative(cfg.depth_pid.kd, "depth_pid.kd")?;
        non_negative(cfg.pitch_pid.kp, "pitch_pid.kp")?;
        non_negative(cfg.pitch_pid.ki, "pitch_pid.ki")?;
        non_negative(cfg.pitch_pid.kd, "pitch_pid.kd")?;
        if positive(cfg.pitch_limit, "pitch_limit")? >= 90.0 {
            return Err(ConfigError::OutOfRange("pitch_limit"));
        }
        positive(cfg.elevator_limit, "elevator_limit")?;
        positive(sample_time, "sample_time")?;
        let sign = tf.loop_sign();
        let g = cfg.pitch_pid;
        Ok(Self {
            cfg: *cfg,
            sign,
            signed_pitch: PidGains {
                kp: sign * g.kp,
                ki: sign * g.ki,
                kd: sign * g.kd,
            },
            sample_time,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &AutopilotConfig {
        &self.cfg
    }

    /// Sign of the pitch loop (−1 for a plant of negative DC gain).
    pub fn loop_sign(&self) -> f32 {
        self.sign
    }

    /// Sample time `Ts`, s.
    pub fn sample_time(&self) -> f32 {
        self.sample_time
    }

    /// One autopilot sample from measurements: reference depth and depth
    /// (m), pitch (deg) and pitch rate (deg/s). Updates `state`.
    pub fn update(
        &self,
        state: &mut AutopilotState,
        reference: f32,
        depth: f32,
        pitch: f32,
        pitch_rate: f32,
    ) -> Command {
        let depth_rate = (depth - state.depth_prev) / self.sample_time;
        state.depth_prev = depth;
        self.cascade(
            &mut state.depth_integral,
            &mut state.pitch_integral,
            reference - depth,
            depth_rate,
            pitch,
            pitch_rate,
        )
    }

    /// The cascade proper, on the depth error `e_d = r - d` (m) and the
    /// depth rate `ḋ` (m/s), which the simulation computes from compensated
    /// depths. Updates both integrators after computing `δ` (contract §7).
    #[inline(always)]
    pub(crate) fn cascade(
        &self,
        depth_integral: &mut f32,
        pitch_integral: &mut f32,
        e_d: f32,
        depth_rate: f32,
        pitch: f32,
        pitch_rate: f32,
    ) -> Command {
        let g = &self.cfg.depth_pid;
        let depth_terms = PidTerms {
            p: -g.kp * e_d,
            i: -g.ki * *depth_integral,
            d: g.kd * depth_rate,
        };
        let v = depth_terms.p + depth_terms.i + depth_terms.d;
        // The depth loop's output is `−(…)`: the error pushing it up is `−e_d`.
        let depth_out = saturate(v, self.cfg.pitch_limit, -e_d);
        let pitch_ref = depth_out.value;
        // (The pitch loop does not read `I_d`: updating it here, where the
        // depth loop decides it, is the contract's order to the bit.)
        if depth_out.integrating {
            *depth_integral += self.sample_time * e_d;
        }

        let e_t = pitch_ref - pitch;
        let g = &self.signed_pitch;
        let pitch_terms = PidTerms {
            p: g.kp * e_t,
            i: g.ki * *pitch_integral,
            d: -g.kd * pitch_rate,
        };
        let w = pitch_terms.p + pitch_terms.i + pitch_terms.d;
        // The pitch loop's output is `σ (…)`: the error pushing it up is
        // `σ e_θ`.
        let pitch_out = saturate(w, self.cfg.elevator_limit, self.sign * e_t);
        let elevator = pitch_out.value;
        if pitch_out.integrating {
            *pitch_integral += self.sample_time * e_t;
        }
        Command {
            pitch_ref,
            elevator,
            depth_terms: depth_terms.saturated(),
            pitch_terms: pitch_terms.saturated(),
            pitch_ref_linear: depth_out.linear,
            elevator_linear: pitch_out.linear,
            depth_integrating: depth_out.integrating,
            pitch_integrating: pitch_out.integrating,
        }
    }
}

/// What [`saturate`] gives: the clamped output and the two flags.
#[derive(Clone, Copy)]
struct Saturated {
    /// `clamp(u)`, in the unit of `u`.
    value: f32,
    /// `|u| <= limit` (the clamp is not active; false for NaN).
    linear: bool,
    /// The integrator integrates at this sample.
    integrating: bool,
}

/// A loop's output `u` clamped to `±limit`, whether the clamp is inactive,
/// and whether its integrator
/// integrates (conditional integration, contract §7): it holds only while
/// the output is saturated and integrating would drive it further out,
/// that is on `u > limit` with `push > 0` or on `u < −limit` with
/// `push < 0`, where `push` is the loop's error signed as it pushes the
/// output up.
///
/// Inside the limits, the common case, the clamp is the identity and the
/// integrator integrates: the one compare of `|u|` decides it. Outside,
/// the side of the limit the output is on gives the clamp, and the sign
/// of `push` the integrator (no product, which could underflow to zero).
/// NaN: NaN out, no integration.
#[inline(always)]
fn saturate(u: f32, limit: f32, push: f32) -> Saturated {
    if libm::fabsf(u) <= limit {
        Saturated {
            value: u,
            linear: true,
            integrating: true,
        }
    } else if u > limit {
        Saturated {
            value: limit,
            linear: false,
            integrating: push <= 0.0,
        }
    } else if u < -limit {
        Saturated {
            value: -limit,
            linear: false,
            integrating: push >= 0.0,
        }
    } else {
        // NaN: NaN out, no integration.
        Saturated {
            value: u,
            linear: false,
            integrating: false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ap() -> Autopilot {
        Autopilot::new(&AutopilotConfig::default(), &TransferFunction::C_AUV4, 0.1).unwrap()
    }

    #[test]
    fn saturate_is_the_clamp_and_the_contracts_integration_rule() {
        // The branches must agree with the contract's form, `clamp(u)` and
        // "integrate unless u > limit with push > 0 or u < −limit with
        // push < 0" (no integration for NaN), for every `u` (zeros, the
        // limit itself, infinities and NaN) and every finite `push`.
        let vals = [
            0.0,
            -0.0,
            1e-30,
            -1e-30,
            0.5,
            -0.5,
            14.999_999,
            15.0,
            -15.0,
            15.000_001,
            -15.000_001,
            1e30,
            -1e30,
            f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        for &u in &vals {
            for &push in vals.iter().filter(|p| p.is_finite()) {
                for limit in [15.0, 1e-3, f32::MAX] {
                    let c = clamp(u, limit);
                    let held = (u > limit && push > 0.0) || (u < -limit && push < 0.0);
                    let general = (c, !u.is_nan() && !held);
                    let fast = saturate(u, limit, push);
                    assert_eq!(
                        fast.value.to_bits(),
                        general.0.to_bits(),
                        "{u} {limit} {push}"
                    );
                    assert_eq!(fast.integrating, general.1, "{u} {limit} {push}");
                }
            }
        }
    }

    #[test]
    fn level_and_on_depth_commands_nothing() {
        let mut st = AutopilotState::trimmed(50.0);
        let c = ap().update(&mut st, 50.0, 50.0, 0.0, 0.0);
        assert_eq!(c.pitch_ref, 0.0);
        assert_eq!(c.elevator, 0.0);
    }

    #[test]
    fn signs_follow_the_contract() {
        // Must go deeper by 2 m: v = -(1.5 * 2) = -3 deg (nose down).
        let mut st = AutopilotState::trimmed(50.0);
        let c = ap().update(&mut st, 52.0, 50.0, 0.0, 0.0);
        assert!((c.pitch_ref + 3.0).abs() < 1e-6);
        // e_θ = -3: w = -(2 * -3) = +6 deg.
        assert!((c.elevator - 6.0).abs() < 1e-5);
        assert!((st.depth_integral - 0.2).abs() < 1e-7);
        assert!((st.pitch_integral + 0.3).abs() < 1e-7);
    }

    #[test]
    fn derivative_is_on_measurement() {
        // Sinking at 1 m/s with no error: v = Kdd ḋ = 2 deg (nose up).
        let mut st = AutopilotState::trimmed(49.9);
        let c = ap().update(&mut st, 50.0, 50.0, 0.0, 0.0);
        assert!((c.pitch_ref - 2.0).abs() < 1e-3);
        assert_eq!(st.depth_prev, 50.0);
    }

    #[test]
    fn anti_windup_holds_only_when_pushing_out() {
        let a = ap();
        // 100 m too shallow: v = -150, saturated low, e_d > 0: hold I_d.
        let mut st = AutopilotState::trimmed(0.0);
        let c = a.update(&mut st, 100.0, 0.0, 0.0, 0.0);
        assert!(!c.pitch_ref_linear && !c.depth_integrating);
        assert_eq!(st.depth_integral, 0.0);
        // Elevator saturated high (w = 50) with e_θ = -25 < 0: hold I_θ.
        assert!(!c.elevator_linear && !c.pitch_integrating);
        // The mirror case: pitch 30° nose-down under a zero reference gives
        // e_θ = 30 > 0 and w = -60 < -δmax: hold I_θ.
        let mut st = AutopilotState::trimmed(50.0);
        let c = a.update(&mut st, 50.0, 50.0, -30.0, 0.0);
        assert!(!c.elevator_linear && !c.pitch_integrating);
    }

    #[test]
    fn positive_gain_plant_flips_the_pitch_loop() {
        let tf = TransferFunction::<2>::pitch(&[0.5], &[1.0, 1.2, 0.35]).unwrap();
        let a = Autopilot::new(&AutopilotConfig::default(), &tf, 0.1).unwrap();
        let mut st = AutopilotState::trimmed(50.0);
        let c = a.update(&mut st, 52.0, 50.0, 0.0, 0.0);
        assert!((c.elevator + 6.0).abs() < 1e-5);
    }

    #[test]
    fn rejects_bad_config() {
        let tf = TransferFunction::C_AUV4;
        let mut c = AutopilotConfig {
            pitch_limit: 90.0,
            ..Default::default()
        };
        assert_eq!(
            Autopilot::new(&c, &tf, 0.1),
            Err(ConfigError::OutOfRange("pitch_limit"))
        );
        c = AutopilotConfig::default();
        c.depth_pid.kd = -1.0;
        assert_eq!(
            Autopilot::new(&c, &tf, 0.1),
            Err(ConfigError::Negative("depth_pid.kd"))
        );
        c = AutopilotConfig::default();
        c.elevator_limit = f32::NAN;
        assert_eq!(
            Autopilot::new(&c, &tf, 0.1),
            Err(ConfigError::NonFinite("elevator_limit"))
        );
        assert_eq!(
            Autopilot::new(&AutopilotConfig::default(), &tf, 0.0),
            Err(ConfigError::NotPositive("sample_time"))
        );
    }
}
