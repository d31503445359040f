//! The integer error codes of the C interface and their names, and the
//! mapping from the library's typed errors.

use auvnav::{ConfigError, PlanConfigError, PlanError, PlantError, ProfileError, SimError};
use auvnav::{PlanStatus, WaypointError};

/// Success.
pub const AUVNAV_OK: i32 = 0;
/// A pointer argument is null.
pub const AUVNAV_ERR_NULL: i32 = -1;
/// An input value is NaN or infinite.
pub const AUVNAV_ERR_NON_FINITE: i32 = -2;
/// A length is over a capacity (`AUVNAV_MAX_*`).
pub const AUVNAV_ERR_CAPACITY: i32 = -3;
/// The planner or autopilot was not initialized (`*_init` not called, or
/// it failed).
pub const AUVNAV_ERR_NOT_INITIALIZED: i32 = -4;
/// A vehicle setting is out of range (speed, sample time, gains, limits),
/// or the closed loop is unstable.
pub const AUVNAV_ERR_VEHICLE: i32 = -5;
/// The plant is invalid: unknown kind, lengths, order 0 or over
/// `AUVNAV_MAX_ORDER`, relative degree below 2, no steady gain.
pub const AUVNAV_ERR_PLANT: i32 = -6;
/// A mission setting is out of range (altitudes, depth limits,
/// uncertainty bounds).
pub const AUVNAV_ERR_MISSION: i32 = -7;
/// A planner setting is out of range (mode, method, horizon, iterations).
pub const AUVNAV_ERR_SETTINGS: i32 = -8;
/// The bottom samples are invalid (fewer than 2, x not strictly
/// increasing).
pub const AUVNAV_ERR_PROFILE: i32 = -9;
/// The waypoints are invalid (fewer than 2, not increasing, outside the
/// bottom samples).
pub const AUVNAV_ERR_WAYPOINTS: i32 = -10;
/// The start depth is above the surface or at or below the bottom, or
/// the reference altitude is larger than the water depth at waypoint 0.
pub const AUVNAV_ERR_START: i32 = -11;
/// No line set (`auvnav_planner_set_line` not called, or it failed).
pub const AUVNAV_ERR_NO_LINE: i32 = -12;
/// Every track of the line is planned.
pub const AUVNAV_ERR_LINE_DONE: i32 = -13;
/// The held state is at or below the bottom: the previous track's plan
/// predicts a collision (an infeasible line), there is nothing to plan
/// from until `auvnav_planner_measured` gives a real state.
pub const AUVNAV_ERR_BELOW_BOTTOM: i32 = -14;
/// The held or measured state is not on the track to plan.
pub const AUVNAV_ERR_OFF_TRACK: i32 = -15;
/// The simulation failed (diverged, step limit, left the bottom samples).
pub const AUVNAV_ERR_SIMULATION: i32 = -16;

/// Every code and its name, in order.
const NAMES: [(i32, &str); 17] = [
    (AUVNAV_OK, "AUVNAV_OK\0"),
    (AUVNAV_ERR_NULL, "AUVNAV_ERR_NULL\0"),
    (AUVNAV_ERR_NON_FINITE, "AUVNAV_ERR_NON_FINITE\0"),
    (AUVNAV_ERR_CAPACITY, "AUVNAV_ERR_CAPACITY\0"),
    (AUVNAV_ERR_NOT_INITIALIZED, "AUVNAV_ERR_NOT_INITIALIZED\0"),
    (AUVNAV_ERR_VEHICLE, "AUVNAV_ERR_VEHICLE\0"),
    (AUVNAV_ERR_PLANT, "AUVNAV_ERR_PLANT\0"),
    (AUVNAV_ERR_MISSION, "AUVNAV_ERR_MISSION\0"),
    (AUVNAV_ERR_SETTINGS, "AUVNAV_ERR_SETTINGS\0"),
    (AUVNAV_ERR_PROFILE, "AUVNAV_ERR_PROFILE\0"),
    (AUVNAV_ERR_WAYPOINTS, "AUVNAV_ERR_WAYPOINTS\0"),
    (AUVNAV_ERR_START, "AUVNAV_ERR_START\0"),
    (AUVNAV_ERR_NO_LINE, "AUVNAV_ERR_NO_LINE\0"),
    (AUVNAV_ERR_LINE_DONE, "AUVNAV_ERR_LINE_DONE\0"),
    (AUVNAV_ERR_BELOW_BOTTOM, "AUVNAV_ERR_BELOW_BOTTOM\0"),
    (AUVNAV_ERR_OFF_TRACK, "AUVNAV_ERR_OFF_TRACK\0"),
    (AUVNAV_ERR_SIMULATION, "AUVNAV_ERR_SIMULATION\0"),
];

/// The NUL-terminated name of `code`, or `"AUVNAV_ERR_UNKNOWN"`.
pub(crate) fn name(code: i32) -> &'static str {
    NAMES
        .iter()
        .find(|(c, _)| *c == code)
        .map_or("AUVNAV_ERR_UNKNOWN\0", |(_, n)| n)
}

/// A failed call's code.
pub(crate) type Code = i32;

/// The code of a vehicle error.
pub(crate) fn vehicle(e: ConfigError) -> Code {
    match e {
        ConfigError::NonFinite(_) => AUVNAV_ERR_NON_FINITE,
        ConfigError::Plant(p) => plant(p),
        _ => AUVNAV_ERR_VEHICLE,
    }
}

/// The code of a plant error.
pub(crate) fn plant(e: PlantError) -> Code {
    match e {
        PlantError::NonFinite => AUVNAV_ERR_NON_FINITE,
        _ => AUVNAV_ERR_PLANT,
    }
}

/// The code of a mission error.
pub(crate) fn mission(e: ConfigError) -> Code {
    match e {
        ConfigError::NonFinite(_) => AUVNAV_ERR_NON_FINITE,
        _ => AUVNAV_ERR_MISSION,
    }
}

/// The code of a planner-settings error.
pub(crate) fn settings(_: PlanConfigError) -> Code {
    AUVNAV_ERR_SETTINGS
}

/// The code of a bottom-profile error.
pub(crate) fn profile(e: ProfileError) -> Code {
    match e {
        ProfileError::OverCapacity { .. } => AUVNAV_ERR_CAPACITY,
        ProfileError::NonFinite { .. } => AUVNAV_ERR_NON_FINITE,
        _ => AUVNAV_ERR_PROFILE,
    }
}

/// The code of a waypoint error.
pub(crate) fn waypoints(e: WaypointError) -> Code {
    match e {
        WaypointError::OverCapacity { .. } => AUVNAV_ERR_CAPACITY,
        WaypointError::NonFinite { .. } => AUVNAV_ERR_NON_FINITE,
        _ => AUVNAV_ERR_WAYPOINTS,
    }
}

/// The code of a simulation error.
pub(crate) fn sim(e: SimError) -> Code {
    match e {
        SimError::Waypoints(w) => waypoints(w),
        SimError::NonFiniteState | SimError::NonFiniteDepth { .. } => AUVNAV_ERR_NON_FINITE,
        SimError::StateOffTrack | SimError::TrackRange => AUVNAV_ERR_OFF_TRACK,
        _ => AUVNAV_ERR_SIMULATION,
    }
}

/// The code of a planning error.
pub(crate) fn plan(e: PlanError) -> Code {
    match e {
        PlanError::Config(c) => settings(c),
        PlanError::StartBelowBottom => AUVNAV_ERR_BELOW_BOTTOM,
        PlanError::TrackRange => AUVNAV_ERR_LINE_DONE,
        PlanError::LineTooLong => AUVNAV_ERR_CAPACITY,
        PlanError::NoCertificationBottom => AUVNAV_ERR_MISSION,
        PlanError::Sim(s) => sim(s),
        _ => AUVNAV_ERR_SIMULATION,
    }
}

/// `AUVNAV_STATUS_*` of a plan status.
pub(crate) fn status(s: PlanStatus) -> u32 {
    match s {
        PlanStatus::Optimal => crate::types::AUVNAV_STATUS_OPTIMAL,
        PlanStatus::Constrained => crate::types::AUVNAV_STATUS_CONSTRAINED,
        _ => crate::types::AUVNAV_STATUS_INFEASIBLE,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_code_has_one_nul_terminated_name() {
        for (i, (code, n)) in NAMES.iter().enumerate() {
            assert_eq!(
                *code,
                -i32::try_from(i).unwrap(),
                "codes are 0, -1, -2, ..."
            );
            assert_eq!(name(*code), *n);
            assert!(n.ends_with('\0') && n.starts_with("AUVNAV_"));
            assert_eq!(n.matches('\0').count(), 1);
        }
        assert_eq!(name(1), "AUVNAV_ERR_UNKNOWN\0");
        assert_eq!(name(i32::MIN), "AUVNAV_ERR_UNKNOWN\0");
    }
}
