//! The C-visible types of spec/capi.md (`#[repr(C)]`, in the header), the
//! capacities and the named constants. All `f32` values carry the units of
//! model.md: m, m/s, s, deg.

/// Bottom samples of a line, at most.
pub const AUVNAV_MAX_SAMPLES: u32 = 1024;
/// Waypoints of a line, at most.
pub const AUVNAV_MAX_WAYPOINTS: u32 = 64;
/// Plant order (denominator degree), at most.
pub const AUVNAV_MAX_ORDER: u32 = 4;
/// Tracks optimized jointly, at most.
pub const AUVNAV_MAX_HORIZON: u32 = 5;
/// Room for a plant's coefficients: `AUVNAV_MAX_ORDER + 1`.
pub const AUVNAV_MAX_COEFFICIENTS: usize = 5;

/// `plant_kind`: `θ(s)/δ(s)`, pitch per elevator (deg/deg).
pub const AUVNAV_PLANT_PITCH: u32 = 0;
/// `plant_kind`: `q(s)/δ(s)`, pitch rate per elevator (deg/s per deg); the
/// numerator's constant term must be zero.
pub const AUVNAV_PLANT_RATE: u32 = 1;

/// `mode`: the receding horizon over the next `horizon` tracks.
pub const AUVNAV_MODE_HORIZON: u32 = 0;
/// `mode`: each track alone.
pub const AUVNAV_MODE_TRACK: u32 = 1;

/// `method`: BFGS with Armijo line search.
pub const AUVNAV_METHOD_BFGS: u32 = 0;
/// `method`: gradient descent.
pub const AUVNAV_METHOD_GD: u32 = 1;

/// `status`: the optimum, above the minimum altitude.
pub const AUVNAV_STATUS_OPTIMAL: u32 = 0;
/// `status`: the minimum-altitude constraint decided the depth.
pub const AUVNAV_STATUS_CONSTRAINED: u32 = 1;
/// `status`: no depth keeps the minimum altitude (the safest one is given).
pub const AUVNAV_STATUS_INFEASIBLE: u32 = 2;

/// `optimizer`: a stopping rule held.
pub const AUVNAV_OPTIMIZER_CONVERGED: u32 = 0;
/// `optimizer`: the iteration cap came first.
pub const AUVNAV_OPTIMIZER_MAX_ITERATIONS: u32 = 1;
/// `optimizer`: the flight budget (`max_flights`) came first.
pub const AUVNAV_OPTIMIZER_BUDGET: u32 = 2;
/// `optimizer`: the line search made no progress.
pub const AUVNAV_OPTIMIZER_STALLED: u32 = 3;
/// `optimizer`: no optimizer ran (the scan or the boundary search decided).
pub const AUVNAV_OPTIMIZER_NONE: u32 = 4;

/// The vehicle (model.md sections 4, 5, 9).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(non_camel_case_types)]
pub struct auvnav_vehicle {
    /// `U0`, cruising speed, m/s.
    pub speed: f32,
    /// `Ts`, autopilot sample time, s.
    pub sample_time: f32,
    /// `θmax`, pitch reference limit, deg.
    pub pitch_limit: f32,
    /// `δmax`, elevator limit, deg.
    pub elevator_limit: f32,
    /// Depth loop `kp`, deg/m.
    pub depth_kp: f32,
    /// Depth loop `ki`, deg/(m s).
    pub depth_ki: f32,
    /// Depth loop `kd`, deg s/m.
    pub depth_kd: f32,
    /// Pitch loop `kp`, deg/deg.
    pub pitch_kp: f32,
    /// Pitch loop `ki`, 1/s.
    pub pitch_ki: f32,
    /// Pitch loop `kd`, s.
    pub pitch_kd: f32,
    /// `AUVNAV_PLANT_PITCH` (θ/δ) or `AUVNAV_PLANT_RATE` (q/δ).
    pub plant_kind: u32,
    /// Numerator coefficients used, highest power first.
    pub num_len: u32,
    /// Denominator coefficients used, highest power first.
    pub den_len: u32,
    /// Numerator, highest power first (the first `num_len`).
    pub num: [f32; AUVNAV_MAX_COEFFICIENTS],
    /// Denominator, highest power first (the first `den_len`).
    pub den: [f32; AUVNAV_MAX_COEFFICIENTS],
}

/// The mission (model.md sections 8, 10, 12).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(non_camel_case_types)]
pub struct auvnav_mission {
    /// `h_r`, reference altitude, m.
    pub reference_altitude: f32,
    /// `h_a`, minimum altitude, m.
    pub min_altitude: f32,
    /// Shallowest allowed reference depth, m.
    pub depth_min: f32,
    /// Deepest allowed reference depth, m.
    pub depth_max: f32,
    /// `e_h`, along-track map/navigation offset at waypoint 0, m.
    pub horizontal_uncertainty: f32,
    /// `r`, growth of that offset, m per m travelled.
    pub nav_drift: f32,
    /// `e_v`, vertical map error, m.
    pub vertical_uncertainty: f32,
    /// `ε_U`, relative speed error (fraction of `U0`).
    pub speed_uncertainty: f32,
    /// `α_max`, pitch to flight-path angle bound, deg.
    pub flight_path_offset: f32,
    /// `w_max`, vertical water velocity bound, m/s.
    pub vertical_current: f32,
}

/// The planner's settings.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub struct auvnav_settings {
    /// `AUVNAV_MODE_HORIZON` or `AUVNAV_MODE_TRACK`.
    pub mode: u32,
    /// `AUVNAV_METHOD_BFGS` or `AUVNAV_METHOD_GD`.
    pub method: u32,
    /// Tracks optimized jointly, `1..=AUVNAV_MAX_HORIZON`.
    pub horizon: u32,
    /// Optimizer iterations per call, at least 1.
    pub max_iterations: u32,
    /// Flights (simulations) per call; 0: no budget.
    pub max_flights: u32,
}

/// One track's plan.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(non_camel_case_types)]
pub struct auvnav_plan {
    /// The next track's reference depth, m.
    pub depth: f32,
    /// Predicted minimum altitude on the track (nominal model and map), m.
    pub min_altitude: f32,
    /// Least altitude over the declared worlds, m.
    pub certified_min_altitude: f32,
    /// `J` of the track, m³.
    pub j: f32,
    /// `AUVNAV_STATUS_OPTIMAL`, `_CONSTRAINED` or `_INFEASIBLE`.
    pub status: u32,
    /// `AUVNAV_OPTIMIZER_CONVERGED`, `_MAX_ITERATIONS`, `_BUDGET`,
    /// `_STALLED` or `_NONE`.
    pub optimizer: u32,
    /// Certified safe over the declared worlds.
    pub safe: bool,
    /// Optimizer iterations.
    pub iterations: u32,
    /// Flights (simulations) this call ran.
    pub flights: u32,
}

/// What the vehicle measured at the start of a track.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(non_camel_case_types)]
pub struct auvnav_measurement {
    /// Depth, m, positive down.
    pub depth: f32,
    /// Pitch, deg, nose up positive.
    pub pitch: f32,
    /// Pitch rate, deg/s.
    pub pitch_rate: f32,
    /// Along-track position, m.
    pub x: f32,
}
