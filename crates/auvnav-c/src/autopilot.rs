//! The autopilot behind `auvnav_autopilot`: the library's cascade with the
//! firmware loop around it ([`auvnav::Autopilot::step`]).

use auvnav::{Autopilot, LoopInput, LoopState, TransferFunction, Vehicle};

use crate::convert;
use crate::error::{self, Code};
use crate::types::auvnav_vehicle;

/// Everything `auvnav_autopilot` holds.
pub(crate) struct AutopilotInner {
    autopilot: Autopilot,
    state: LoopState,
    hold: bool,
}

/// What one step reports besides the elevator.
pub(crate) struct Stepped {
    /// Elevator, deg.
    pub elevator: f32,
    /// The command was held because an input was not finite.
    pub non_finite: bool,
}

impl AutopilotInner {
    /// The cascade of vehicle `v` (validated as the planner validates it,
    /// with its stability check), engaged bumplessly from a zero elevator.
    pub(crate) fn new(v: &auvnav_vehicle) -> Result<Self, Code> {
        convert::finite_vehicle(v)?;
        let tf: TransferFunction<4> = convert::transfer_function(v)?;
        let vehicle = Vehicle::new(&convert::vehicle_config(v), tf).map_err(error::vehicle)?;
        let mut inner = Self {
            autopilot: *vehicle.autopilot(),
            state: LoopState::default(),
            hold: false,
        };
        inner.engage(0.0);
        Ok(inner)
    }

    /// Bumpless take-over from an elevator at `elevator` deg: the next
    /// sample continues from it, with a zero depth rate (no depth known
    /// yet).
    pub(crate) fn engage(&mut self, elevator: f32) {
        self.state = LoopState::engage(0.0, elevator);
        self.state.stale_depth = true;
    }

    /// Holds (or releases) the command.
    pub(crate) fn set_hold(&mut self, hold: bool) {
        self.hold = hold;
    }

    /// One sample: reference depth and depth (m), pitch (deg), pitch rate
    /// (deg/s).
    pub(crate) fn step(&mut self, reference: f32, depth: f32, pitch: f32, rate: f32) -> Stepped {
        let input = LoopInput {
            reference,
            depth,
            pitch,
            pitch_rate: rate,
            hold: self.hold,
        };
        let out = self.autopilot.step(&mut self.state, &input);
        Stepped {
            elevator: out.elevator,
            non_finite: out.non_finite,
        }
    }
}
