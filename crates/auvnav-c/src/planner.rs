//! The planner behind `auvnav_planner`: owns the vehicle, the mission,
//! the line's data and the library's `Planner`, in safe Rust. The plant's
//! order picks the planner's order `N` (1 to `AUVNAV_MAX_ORDER`), so every
//! computation runs at the plant's own order.

use auvnav::{
    Measurement, Mission, Planner, PlannerConfig, Profile, Scenario, Vehicle, VehicleState,
    Waypoints, lower_envelope,
};

use crate::convert;
use crate::error::{self, AUVNAV_ERR_LINE_DONE, AUVNAV_ERR_NO_LINE, AUVNAV_ERR_NON_FINITE};
use crate::error::{AUVNAV_ERR_START, Code};
use crate::types::*;

/// Bottom samples of a line.
const SAMPLES: usize = AUVNAV_MAX_SAMPLES as usize;
/// Waypoints of a line.
const WAYPOINTS: usize = AUVNAV_MAX_WAYPOINTS as usize;
/// Tracks jointly.
const HORIZON: usize = AUVNAV_MAX_HORIZON as usize;
/// The certification bottom: the map's samples and two window crossings
/// per sample (as the `plan` tool sizes it).
const ENVELOPE: usize = 3 * SAMPLES + 1;

/// A line's data, copied in.
pub(crate) struct Line {
    profile: Profile<SAMPLES>,
    envelope: Profile<ENVELOPE>,
    waypoints: Waypoints<WAYPOINTS>,
}

/// The vehicle, planner and held state at one plant order.
pub(crate) struct Core<const N: usize> {
    vehicle: Vehicle<N>,
    planner: Planner<HORIZON, N>,
    state: VehicleState<N>,
}

/// [`Core`] at the plant's order. (Its size is the largest order's: no
/// allocator to box the rest, and the object has a fixed size anyway.)
#[allow(clippy::large_enum_variant)]
pub(crate) enum Engine {
    /// First order.
    O1(Core<1>),
    /// Second order.
    O2(Core<2>),
    /// Third order (the paper's vehicle).
    O3(Core<3>),
    /// Fourth order.
    O4(Core<4>),
}

/// Everything `auvnav_planner` holds.
pub(crate) struct PlannerInner {
    mission: Mission,
    engine: Engine,
    line: Option<Line>,
    /// Next track to plan, 0-based.
    track: usize,
}

/// Calls `$body` with the engine's [`Core`] bound to `$c`, whatever its
/// order.
macro_rules! with_core {
    ($engine:expr, $c:ident => $body:expr) => {
        match $engine {
            Engine::O1($c) => $body,
            Engine::O2($c) => $body,
            Engine::O3($c) => $body,
            Engine::O4($c) => $body,
        }
    };
}

/// The scenario of `line`, certified over its envelope (as the `plan`
/// tool builds it).
fn scenario<'a, const N: usize>(
    vehicle: &'a Vehicle<N>,
    line: &'a Line,
    mission: Mission,
) -> Result<Scenario<'a, N>, Code> {
    Scenario::new(vehicle, &line.profile, &line.waypoints, mission)
        .and_then(|sc| sc.with_certification_bottom(line.envelope.view()))
        .map_err(error::sim)
}

impl<const N: usize> Core<N> {
    fn new(v: &auvnav_vehicle, pc: PlannerConfig) -> Result<Self, Code> {
        let tf = convert::transfer_function::<N>(v)?;
        let vehicle = Vehicle::new(&convert::vehicle_config(v), tf).map_err(error::vehicle)?;
        let planner = Planner::new(pc).map_err(error::plan)?;
        Ok(Self {
            vehicle,
            planner,
            state: VehicleState::trimmed(0.0, 0.0),
        })
    }

    /// The start state at `initial_depth` (NaN: `b(X_0) - h_r`), checked
    /// as the `plan` tool checks it; resets the planner.
    fn start(&mut self, line: &Line, mission: Mission, initial_depth: f32) -> Result<(), Code> {
        let sc = scenario(&self.vehicle, line, mission)?;
        let x0 = line.waypoints.positions().first().copied().unwrap_or(0.0);
        let b0 = line.profile.depth_at(x0).map_err(error::profile)?;
        if mission.reference_altitude() > b0 {
            return Err(AUVNAV_ERR_START);
        }
        let depth = if initial_depth.is_nan() {
            sc.default_initial_depth()
        } else if !initial_depth.is_finite() {
            return Err(AUVNAV_ERR_NON_FINITE);
        } else if initial_depth < 0.0 || initial_depth >= b0 {
            return Err(AUVNAV_ERR_START);
        } else {
            initial_depth
        };
        let state = sc.start_state(depth);
        self.planner.reset();
        self.state = state;
        Ok(())
    }

    fn plan(&mut self, line: &Line, mission: Mission, track: usize) -> Result<auvnav_plan, Code> {
        let sc = scenario(&self.vehicle, line, mission)?;
        let p = self
            .planner
            .plan(&sc, &self.state, track)
            .map_err(error::plan)?;
        self.state = p.next_state;
        Ok(auvnav_plan {
            depth: p.depth,
            min_altitude: p.min_altitude,
            certified_min_altitude: p.certified_min_altitude,
            j: p.j,
            status: error::status(p.status),
            optimizer: convert::optimizer(p.optimizer),
            safe: p.safe,
            iterations: p.iterations,
            flights: p.evaluations,
        })
    }

    fn carry(
        &mut self,
        line: &Line,
        mission: Mission,
        track: usize,
        depth: f32,
    ) -> Result<(), Code> {
        let sc = scenario(&self.vehicle, line, mission)?;
        let next = self
            .planner
            .carry(&sc, &self.state, track, depth)
            .map_err(error::plan)?;
        self.state = next;
        Ok(())
    }

    fn measured(&mut self, m: &auvnav_measurement) -> Result<(), Code> {
        let m = Measurement {
            x: m.x,
            depth: m.depth,
            pitch: m.pitch,
            pitch_rate: m.pitch_rate,
        };
        self.state = VehicleState::measured(&self.state, &m).map_err(error::sim)?;
        Ok(())
    }
}

/// The line, when it has a track `track` (0-based) left to fly.
fn track_left(line: Option<&Line>, track: usize) -> Result<&Line, Code> {
    let line = line.ok_or(AUVNAV_ERR_NO_LINE)?;
    if track >= line.waypoints.tracks() {
        return Err(AUVNAV_ERR_LINE_DONE);
    }
    Ok(line)
}

impl PlannerInner {
    /// A planner for vehicle `v`, mission `m` and settings `s`, no line.
    pub(crate) fn new(
        v: &auvnav_vehicle,
        m: &auvnav_mission,
        s: &auvnav_settings,
    ) -> Result<Self, Code> {
        convert::finite_vehicle(v)?;
        let mission = convert::mission(m, v.pitch_limit)?;
        let pc = convert::planner_config(s)?;
        // The plant's order, validated at the largest capacity.
        let order = convert::transfer_function::<4>(v)?.order();
        let engine = match order {
            1 => Engine::O1(Core::new(v, pc)?),
            2 => Engine::O2(Core::new(v, pc)?),
            3 => Engine::O3(Core::new(v, pc)?),
            _ => Engine::O4(Core::new(v, pc)?),
        };
        Ok(Self {
            mission,
            engine,
            line: None,
            track: 0,
        })
    }

    /// Copies the line in and puts the vehicle at waypoint 0; on an error
    /// the planner has no line.
    pub(crate) fn set_line(
        &mut self,
        (x, bottom): (&[f32], &[f32]),
        waypoints: &[f32],
        initial_depth: f32,
    ) -> Result<(), Code> {
        self.line = None;
        self.track = 0;
        let profile = Profile::new(x, bottom).map_err(error::profile)?;
        let waypoints = Waypoints::new(waypoints).map_err(error::waypoints)?;
        let x0 = waypoints.positions().first().copied().unwrap_or(0.0);
        let envelope = lower_envelope(profile.view(), self.mission.uncertainty(), x0)
            .map_err(error::profile)?;
        let line = self.line.insert(Line {
            profile,
            envelope,
            waypoints,
        });
        let mission = self.mission;
        let started = with_core!(&mut self.engine, c => c.start(line, mission, initial_depth));
        if started.is_err() {
            self.line = None;
        }
        started
    }

    /// Plans the next track and advances.
    pub(crate) fn plan_next(&mut self) -> Result<auvnav_plan, Code> {
        let line = track_left(self.line.as_ref(), self.track)?;
        let (mission, track) = (self.mission, self.track);
        let plan = with_core!(&mut self.engine, c => c.plan(line, mission, track))?;
        self.track = self.track.saturating_add(1);
        Ok(plan)
    }

    /// Flies the next track at `depth` (m), which the planner did not
    /// plan, its worlds carried through (`Planner::carry`), and advances.
    pub(crate) fn carry(&mut self, depth: f32) -> Result<(), Code> {
        let line = track_left(self.line.as_ref(), self.track)?;
        let (mission, track) = (self.mission, self.track);
        with_core!(&mut self.engine, c => c.carry(line, mission, track, depth))?;
        self.track = self.track.saturating_add(1);
        Ok(())
    }

    /// Replaces the held state by the measured one.
    pub(crate) fn measured(&mut self, m: &auvnav_measurement) -> Result<(), Code> {
        if self.line.is_none() {
            return Err(AUVNAV_ERR_NO_LINE);
        }
        with_core!(&mut self.engine, c => c.measured(m))
    }

    /// The next track to plan, 1-based.
    pub(crate) fn track(&self) -> u32 {
        u32::try_from(self.track.saturating_add(1)).unwrap_or(u32::MAX)
    }
}
