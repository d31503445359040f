//! The control loop as firmware runs it: [`Autopilot::step`] wraps the
//! cascade's [`Autopilot::update`] with what a real loop needs around it.
//!
//! - **Hold** ([`LoopInput::hold`]): the last elevator command is held and
//!   both integrators frozen; the depth measurement is still tracked, so
//!   the derivative does not kick when the loop comes back.
//! - **A measurement that is not finite** (NaN or infinite reference,
//!   depth, pitch or pitch rate): the same hold, and
//!   [`LoopOutput::non_finite`] says so; nothing of the state changes, so
//!   nothing non-finite enters it.
//! - **Bumpless re-engage**: the first normal sample after a hold or a
//!   non-finite sample (or after [`LoopState::engage`]) sets the
//!   integrators so that the command continues from the held one: the
//!   depth integral so that `θref` equals the measured pitch (when the
//!   depth loop has an integral gain), then the pitch integral so that the
//!   unclamped `w` equals the held elevator (when the pitch loop has one).
//!   With a zero integral gain that loop's jump is not removable and stays.
//!   After a non-finite sample the depth rate of the re-engaging sample is
//!   taken as zero (the previous depth is stale).

use super::autopilot::{Autopilot, AutopilotState, Command};

/// The firmware loop's memory: the cascade's state, the last command and
/// whether the next normal sample re-engages.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoopState {
    /// The cascade's integrators and previous depth.
    pub cascade: AutopilotState,
    /// The last elevator command, deg.
    pub elevator: f32,
    /// The next normal sample re-engages bumplessly.
    pub reengage: bool,
    /// The depth kept in `cascade` is stale (a non-finite sample since).
    pub stale_depth: bool,
}

impl LoopState {
    /// Trimmed and engaged at `depth` (m): integrators zero, elevator 0.
    pub fn trimmed(depth: f32) -> Self {
        Self {
            cascade: AutopilotState::trimmed(depth),
            ..Self::default()
        }
    }

    /// Taking over a vehicle whose elevator stands at `elevator` (deg):
    /// the first sample continues from it (bumpless). `depth` (m) is the
    /// depth measured now.
    pub fn engage(depth: f32, elevator: f32) -> Self {
        Self {
            cascade: AutopilotState::trimmed(depth),
            elevator: if elevator.is_finite() { elevator } else { 0.0 },
            reengage: true,
            stale_depth: false,
        }
    }
}

/// One sample's inputs: reference depth and depth (m), pitch (deg), pitch
/// rate (deg/s), and the hold request.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoopInput {
    /// Reference depth, m.
    pub reference: f32,
    /// Measured depth, m.
    pub depth: f32,
    /// Measured pitch, deg.
    pub pitch: f32,
    /// Measured pitch rate, deg/s.
    pub pitch_rate: f32,
    /// Hold the last command and freeze the integrators.
    pub hold: bool,
}

/// One sample's output.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoopOutput {
    /// The elevator to drive, deg (always finite).
    pub elevator: f32,
    /// The command was held (hold requested or a non-finite input).
    pub held: bool,
    /// An input was not finite (the command was held).
    pub non_finite: bool,
    /// This sample re-engaged bumplessly.
    pub reengaged: bool,
    /// The cascade's command with its terms (`None` when held).
    pub command: Option<Command>,
}

impl Autopilot {
    /// One sample of the firmware loop (module docs of `engage`): hold,
    /// non-finite hold, bumpless re-engage, else [`Autopilot::update`].
    pub fn step(&self, st: &mut LoopState, input: &LoopInput) -> LoopOutput {
        let held = LoopOutput {
            elevator: st.elevator,
            held: true,
            ..LoopOutput::default()
        };
        let inputs = [input.reference, input.depth, input.pitch, input.pitch_rate];
        if !inputs.iter().all(|v| v.is_finite()) {
            st.reengage = true;
            st.stale_depth = true;
            return LoopOutput {
                non_finite: true,
                ..held
            };
        }
        if input.hold {
            st.cascade.depth_prev = input.depth;
            st.stale_depth = false;
            st.reengage = true;
            return held;
        }
        if st.stale_depth {
            st.cascade.depth_prev = input.depth;
            st.stale_depth = false;
        }
        let reengaged = st.reengage;
        if reengaged {
            self.bumpless(st, input);
            st.reengage = false;
        }
        let cmd = self.update(
            &mut st.cascade,
            input.reference,
            input.depth,
            input.pitch,
            input.pitch_rate,
        );
        st.elevator = cmd.elevator;
        LoopOutput {
            elevator: cmd.elevator,
            reengaged,
            command: Some(cmd),
            ..LoopOutput::default()
        }
    }

    /// Sets the integrators so that this sample's command continues from
    /// `st.elevator` (module docs). Computes the cascade once on a copy of
    /// the state to read the terms, then solves each loop's integral.
    fn bumpless(&self, st: &mut LoopState, input: &LoopInput) {
        let cfg = self.config();
        let (kid, kit) = (cfg.depth_pid.ki, self.loop_sign() * cfg.pitch_pid.ki);
        let probe = |cascade: AutopilotState| {
            let mut scratch = cascade;
            let (r, d) = (input.reference, input.depth);
            self.update(&mut scratch, r, d, input.pitch, input.pitch_rate)
        };
        // θref = pitch: −ki I_d = pitch − (p + d).
        let first = probe(st.cascade);
        if kid != 0.0 && libm::fabsf(input.pitch) <= cfg.pitch_limit {
            let pd = first.depth_terms.p + first.depth_terms.d;
            let i_d = (pd - input.pitch) / kid;
            if i_d.is_finite() {
                st.cascade.depth_integral = i_d;
            }
        }
        // The pitch loop on the θref this sample will really command:
        // σ ki I_θ = δ_held − (p + d).
        let second = probe(st.cascade);
        if kit != 0.0 && libm::fabsf(st.elevator) <= cfg.elevator_limit {
            let pd = second.pitch_terms.p + second.pitch_terms.d;
            let i_t = (st.elevator - pd) / kit;
            if i_t.is_finite() {
                st.cascade.pitch_integral = i_t;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{AutopilotConfig, TransferFunction};

    fn ap(depth_ki: f32) -> Autopilot {
        let mut cfg = AutopilotConfig::default();
        cfg.depth_pid.ki = depth_ki;
        Autopilot::new(&cfg, &TransferFunction::C_AUV4, 0.1).unwrap()
    }

    fn input(reference: f32, depth: f32, pitch: f32, hold: bool) -> LoopInput {
        LoopInput {
            reference,
            depth,
            pitch,
            pitch_rate: 0.3,
            hold,
        }
    }

    #[test]
    fn engaged_step_is_update() {
        let a = ap(0.0);
        let mut st = LoopState::trimmed(50.0);
        let mut plain = AutopilotState::trimmed(50.0);
        for k in 0..50 {
            let d = 50.0 + 0.05 * k as f32;
            let out = a.step(&mut st, &input(60.0, d, -2.0, false));
            let cmd = a.update(&mut plain, 60.0, d, -2.0, 0.3);
            assert_eq!(out.command, Some(cmd));
            assert_eq!(out.elevator.to_bits(), cmd.elevator.to_bits());
            assert!(!out.held && !out.non_finite && !out.reengaged);
        }
        assert_eq!(st.cascade, plain);
    }

    #[test]
    fn hold_keeps_the_command_and_freezes_the_integrators() {
        let a = ap(0.05);
        let mut st = LoopState::trimmed(50.0);
        let last = a.step(&mut st, &input(52.0, 50.0, 0.0, false)).elevator;
        let frozen = (st.cascade.depth_integral, st.cascade.pitch_integral);
        for k in 0..30 {
            let out = a.step(&mut st, &input(80.0, 50.0 + k as f32, 5.0, true));
            assert!(out.held && !out.non_finite && out.command.is_none());
            assert_eq!(out.elevator, last);
            assert_eq!(st.cascade.depth_integral, frozen.0);
            assert_eq!(st.cascade.pitch_integral, frozen.1);
            assert_eq!(st.cascade.depth_prev, 50.0 + k as f32);
        }
    }

    #[test]
    fn non_finite_input_holds_and_flags() {
        let a = ap(0.0);
        let mut st = LoopState::trimmed(50.0);
        let last = a.step(&mut st, &input(52.0, 50.0, 0.0, false)).elevator;
        let cascade = st.cascade;
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            for which in 0..4 {
                let mut i = input(52.0, 50.0, 0.0, false);
                match which {
                    0 => i.reference = bad,
                    1 => i.depth = bad,
                    2 => i.pitch = bad,
                    _ => i.pitch_rate = bad,
                }
                let out = a.step(&mut st, &i);
                assert!(out.held && out.non_finite, "{bad} at {which}");
                assert_eq!(out.elevator, last);
                assert_eq!(st.cascade, cascade);
            }
        }
        // The next finite sample: a zero depth rate (the stale depth is
        // replaced), bumpless, and finite.
        let out = a.step(&mut st, &input(52.0, 53.0, 0.0, false));
        assert!(out.reengaged && out.elevator.is_finite());
        assert_eq!(out.command.map(|c| c.depth_terms.d), Some(0.0));
        assert!(
            (out.elevator - last).abs() < 1e-4,
            "{} {last}",
            out.elevator
        );
    }

    #[test]
    fn reengage_is_bumpless() {
        // Without a depth integral only the pitch loop's integral can
        // absorb the jump; with one, θref also starts at the measured pitch.
        for depth_ki in [0.0, 0.05] {
            let a = ap(depth_ki);
            let mut st = LoopState::trimmed(50.0);
            for _ in 0..20 {
                a.step(&mut st, &input(55.0, 50.0, 0.0, false));
            }
            let held = st.elevator;
            for _ in 0..20 {
                a.step(&mut st, &input(70.0, 51.0, 3.0, true));
            }
            let out = a.step(&mut st, &input(70.0, 51.0, 3.0, false));
            assert!(out.reengaged);
            assert!(
                (out.elevator - held).abs() < 1e-4,
                "{} {held}",
                out.elevator
            );
            if depth_ki > 0.0 {
                let r = out.command.map_or(f32::NAN, |c| c.pitch_ref);
                assert!((r - 3.0).abs() < 1e-4, "{r}");
            }
            // Without the bumpless step the command would jump.
            let mut cold = AutopilotState::trimmed(51.0);
            let jump = a.update(&mut cold, 70.0, 51.0, 3.0, 0.3).elevator;
            assert!((jump - held).abs() > 1.0, "{jump} {held}");
        }
    }

    #[test]
    fn engage_continues_from_the_given_elevator() {
        let a = ap(0.0);
        let mut st = LoopState::engage(50.0, -7.0);
        let out = a.step(&mut st, &input(50.0, 50.0, 0.0, false));
        assert!(out.reengaged);
        assert!((out.elevator + 7.0).abs() < 1e-4, "{}", out.elevator);
        assert_eq!(LoopState::engage(50.0, f32::NAN).elevator, 0.0);
    }
}
