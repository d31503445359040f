//! From the C structs to the library's validated types, and back.

use auvnav::{
    AutopilotConfig, Method, Mission, Mode, OptimizerStop, PidGains, PlannerConfig, TfKind,
    TransferFunction, Uncertainty, VehicleConfig,
};

use crate::error::{self, AUVNAV_ERR_CAPACITY, AUVNAV_ERR_MISSION, AUVNAV_ERR_NON_FINITE};
use crate::error::{AUVNAV_ERR_PLANT, AUVNAV_ERR_SETTINGS, Code};
use crate::types::*;

/// The paper's vehicle, C-AUV #4 (model.md section 9).
pub(crate) fn vehicle_default() -> auvnav_vehicle {
    let c = VehicleConfig::default();
    let a = c.autopilot;
    let tf = TransferFunction::C_AUV4;
    let d = tf.denominator();
    let n = tf.numerator();
    auvnav_vehicle {
        speed: c.speed,
        sample_time: c.sample_time,
        pitch_limit: a.pitch_limit,
        elevator_limit: a.elevator_limit,
        depth_kp: a.depth_pid.kp,
        depth_ki: a.depth_pid.ki,
        depth_kd: a.depth_pid.kd,
        pitch_kp: a.pitch_pid.kp,
        pitch_ki: a.pitch_pid.ki,
        pitch_kd: a.pitch_pid.kd,
        plant_kind: AUVNAV_PLANT_PITCH,
        num_len: 1,
        den_len: 4,
        num: [n[2], 0.0, 0.0, 0.0, 0.0],
        den: [1.0, d[0], d[1], d[2], 0.0],
    }
}

/// `h_r` 80 m, `h_a` 60 m, depths `[0, 6000]` m, no uncertainty.
pub(crate) fn mission_default() -> auvnav_mission {
    let m = Mission::default();
    let [lo, hi] = m.depth_limits();
    auvnav_mission {
        reference_altitude: m.reference_altitude(),
        min_altitude: m.min_altitude(),
        depth_min: lo,
        depth_max: hi,
        horizontal_uncertainty: 0.0,
        nav_drift: 0.0,
        vertical_uncertainty: 0.0,
        speed_uncertainty: 0.0,
        flight_path_offset: 0.0,
        vertical_current: 0.0,
    }
}

/// The library's `PlannerConfig::default()`, its horizon capped at
/// `AUVNAV_MAX_HORIZON` (the same plans: a plan does not depend on the
/// capacity).
pub(crate) fn settings_default() -> auvnav_settings {
    let p = PlannerConfig::default();
    auvnav_settings {
        mode: AUVNAV_MODE_HORIZON,
        method: AUVNAV_METHOD_BFGS,
        horizon: AUVNAV_MAX_HORIZON,
        max_iterations: p.bfgs.max_iterations,
        max_flights: 0,
    }
}

/// The autopilot's part of the vehicle.
pub(crate) fn vehicle_config(v: &auvnav_vehicle) -> VehicleConfig {
    let pid = |kp, ki, kd| PidGains { kp, ki, kd };
    VehicleConfig {
        speed: v.speed,
        sample_time: v.sample_time,
        autopilot: AutopilotConfig {
            depth_pid: pid(v.depth_kp, v.depth_ki, v.depth_kd),
            pitch_pid: pid(v.pitch_kp, v.pitch_ki, v.pitch_kd),
            pitch_limit: v.pitch_limit,
            elevator_limit: v.elevator_limit,
        },
    }
}

/// The plant's transfer function with room for order `N`.
pub(crate) fn transfer_function<const N: usize>(
    v: &auvnav_vehicle,
) -> Result<TransferFunction<N>, Code> {
    let kind = match v.plant_kind {
        AUVNAV_PLANT_PITCH => TfKind::Pitch,
        AUVNAV_PLANT_RATE => TfKind::Rate,
        _ => return Err(AUVNAV_ERR_PLANT),
    };
    let len = |n: u32| {
        usize::try_from(n)
            .ok()
            .filter(|&n| n <= AUVNAV_MAX_COEFFICIENTS)
    };
    let (Some(nl), Some(dl)) = (len(v.num_len), len(v.den_len)) else {
        return Err(AUVNAV_ERR_CAPACITY);
    };
    let (Some(num), Some(den)) = (v.num.get(..nl), v.den.get(..dl)) else {
        return Err(AUVNAV_ERR_CAPACITY);
    };
    TransferFunction::new(kind, num, den).map_err(error::plant)
}

/// The mission with its declared uncertainty; the flight-path offset must
/// stay below the pitch limit (as the `plan` tool requires).
pub(crate) fn mission(m: &auvnav_mission, pitch_limit: f32) -> Result<Mission, Code> {
    let u = Uncertainty::new(
        m.horizontal_uncertainty,
        m.nav_drift,
        m.vertical_uncertainty,
        m.speed_uncertainty,
        m.flight_path_offset,
        m.vertical_current,
    )
    .map_err(error::mission)?;
    if m.flight_path_offset >= pitch_limit {
        return Err(AUVNAV_ERR_MISSION);
    }
    let mission = Mission::new(
        m.reference_altitude,
        m.min_altitude,
        [m.depth_min, m.depth_max],
    )
    .map_err(error::mission)?;
    Ok(mission.with_uncertainty(u))
}

/// The planner's configuration: the library's defaults with the C
/// settings.
pub(crate) fn planner_config(s: &auvnav_settings) -> Result<PlannerConfig, Code> {
    let mode = match s.mode {
        AUVNAV_MODE_HORIZON => Mode::Horizon,
        AUVNAV_MODE_TRACK => Mode::TrackWise,
        _ => return Err(AUVNAV_ERR_SETTINGS),
    };
    let method = match s.method {
        AUVNAV_METHOD_BFGS => Method::Bfgs,
        AUVNAV_METHOD_GD => Method::GradientDescent,
        _ => return Err(AUVNAV_ERR_SETTINGS),
    };
    if s.horizon == 0 || s.horizon > AUVNAV_MAX_HORIZON || s.max_iterations == 0 {
        return Err(AUVNAV_ERR_SETTINGS);
    }
    let mut pc = PlannerConfig {
        mode,
        method,
        horizon: usize::try_from(s.horizon).map_err(|_| AUVNAV_ERR_SETTINGS)?,
        max_evaluations: if s.max_flights == 0 {
            u32::MAX
        } else {
            s.max_flights
        },
        ..PlannerConfig::default()
    };
    pc.bfgs.max_iterations = s.max_iterations;
    pc.validate().map_err(error::settings)?;
    Ok(pc)
}

/// `AUVNAV_OPTIMIZER_*` of an optimizer stop.
pub(crate) fn optimizer(o: OptimizerStop) -> u32 {
    match o {
        OptimizerStop::Converged => AUVNAV_OPTIMIZER_CONVERGED,
        OptimizerStop::MaxIterations => AUVNAV_OPTIMIZER_MAX_ITERATIONS,
        OptimizerStop::Budget => AUVNAV_OPTIMIZER_BUDGET,
        OptimizerStop::Stalled => AUVNAV_OPTIMIZER_STALLED,
        _ => AUVNAV_OPTIMIZER_NONE,
    }
}

/// Whether every `f32` of the vehicle is finite (the coefficients in use
/// are checked by the plant).
pub(crate) fn finite_vehicle(v: &auvnav_vehicle) -> Result<(), Code> {
    let vals = [
        v.speed,
        v.sample_time,
        v.pitch_limit,
        v.elevator_limit,
        v.depth_kp,
        v.depth_ki,
        v.depth_kd,
        v.pitch_kp,
        v.pitch_ki,
        v.pitch_kd,
    ];
    if vals.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(AUVNAV_ERR_NON_FINITE)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_map_to_the_planner_config() {
        let mut s = settings_default();
        let pc = planner_config(&s).unwrap();
        assert_eq!(pc.max_evaluations, u32::MAX, "0 flights: no budget");
        assert_eq!((pc.horizon, pc.bfgs.max_iterations), (5, 200));
        s.max_flights = 40;
        s.mode = AUVNAV_MODE_TRACK;
        s.method = AUVNAV_METHOD_GD;
        let pc = planner_config(&s).unwrap();
        assert_eq!(pc.max_evaluations, 40);
        assert_eq!(
            (pc.mode, pc.method),
            (Mode::TrackWise, Method::GradientDescent)
        );
    }

    #[test]
    fn the_default_vehicle_is_the_papers_plant() {
        let tf: TransferFunction<3> = transfer_function(&vehicle_default()).unwrap();
        assert_eq!(tf, TransferFunction::C_AUV4);
    }
}
