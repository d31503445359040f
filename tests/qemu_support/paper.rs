//! The paper's scenario, as the on-target tests, the examples and the host
//! plan it: the line `us_monterey_canyon_1` (`monterey.rs`), the default
//! vehicle C-AUV #4 (`Vehicle::c_auv4()`, plant order `N = 3`), the
//! default mission (`h_r = 80 m`, `h_a = 60 m`), started at the default
//! initial depth, planned track after track with the committed depth
//! flown to the next waypoint (`Plan::next_state`).

use auvnav::{Mission, Mode, Plan, Planner, PlannerConfig, Profile, Scenario, Vehicle, Waypoints};

use super::monterey;

/// Profile capacity (the line has 142 samples).
pub const S: usize = 256;
/// Waypoint capacity (the line has 6 waypoints).
pub const W: usize = 8;
/// Tracks of the line.
pub const TRACKS: usize = monterey::WAYPOINTS.len() - 1;

/// One track's plan, reduced to what is compared bit for bit.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrackPlan {
    /// Committed reference depth, m.
    pub depth: f32,
    /// `PlanStatus::as_str()`.
    pub status: &'static str,
    /// Verified safe.
    pub safe: bool,
    /// Predicted J of the track, m³.
    pub j: f32,
    /// Predicted minimum altitude, m.
    pub min_altitude: f32,
    /// The optimizer's final objective, m³.
    pub objective: f32,
    /// Optimizer iterations.
    pub iterations: u32,
    /// Simulations run.
    pub evaluations: u32,
    /// Entries of `Planner::history`.
    pub history_len: u32,
    /// FNV-1a over the bits of every `Planner::history` entry.
    pub history_hash: u32,
    /// `x` and depth of `Plan::next_state`, m.
    pub next_x: f32,
    /// Depth of `Plan::next_state`, m.
    pub next_depth: f32,
}

/// FNV-1a (32 bit) over the bit patterns of `values`.
pub fn fnv1a(values: &[f32]) -> u32 {
    let mut h: u32 = 0x811c_9dc5;
    for v in values {
        for b in v.to_bits().to_le_bytes() {
            h = (h ^ u32::from(b)).wrapping_mul(0x0100_0193);
        }
    }
    h
}

impl TrackPlan {
    /// The comparable part of `p`.
    pub fn of<const N: usize, const K: usize>(p: &Plan<N>, planner: &Planner<K>) -> Self {
        Self {
            depth: p.depth,
            status: p.status.as_str(),
            safe: p.safe,
            j: p.j,
            min_altitude: p.min_altitude,
            objective: p.objective,
            iterations: p.iterations,
            evaluations: p.evaluations,
            history_len: planner.history().len() as u32,
            history_hash: fnv1a(planner.history()),
            next_x: p.next_state.x(),
            next_depth: p.next_state.depth(),
        }
    }
}

/// Receding horizon, the library's default (`Planner::<5>`).
pub fn horizon_config() -> PlannerConfig {
    PlannerConfig::default()
}

/// Track-wise, the paper's method (`Planner::<1>`).
pub fn trackwise_config() -> PlannerConfig {
    PlannerConfig {
        mode: Mode::TrackWise,
        ..PlannerConfig::default()
    }
}

/// Plans the whole line with a `Planner::<K>` set up by `cfg`; `each` sees
/// every track's full plan.
pub fn plan_line<const K: usize>(
    cfg: PlannerConfig,
    mut each: impl FnMut(usize, &Plan<3>, &Planner<K>),
) -> Result<[TrackPlan; TRACKS], auvnav::Error> {
    let vehicle = Vehicle::c_auv4()?;
    let bottom = Profile::<S>::new(&monterey::X, &monterey::B)?;
    let waypoints = Waypoints::<W>::new(&monterey::WAYPOINTS)?;
    let line = Scenario::new(&vehicle, &bottom, &waypoints, Mission::default())?;
    let mut planner = Planner::<K>::new(cfg)?;
    let mut state = line.start_state(line.default_initial_depth());
    let mut out = [TrackPlan::default(); TRACKS];
    for (track, slot) in out.iter_mut().enumerate() {
        let plan = planner.plan(&line, &state, track)?;
        each(track, &plan, &planner);
        *slot = TrackPlan::of(&plan, &planner);
        state = plan.next_state;
    }
    Ok(out)
}

/// What the smoke test (`tests/qemu_smoke.rs`) compares bit for bit: a
/// cheap cross-section of the library, small enough for the soft-float
/// Cortex-M3 under QEMU.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Smoke {
    /// `Ad` of the C-AUV #4 plant at 0.1 s (row-major), from the f32 ZOH.
    pub ad: [f32; 9],
    /// `Bd` of the same.
    pub bd: [f32; 3],
    /// One objective+gradient evaluation of the whole line
    /// (`Scenario::evaluate::<5>` at [`SMOKE_DEPTHS`]): `Σ J`, m³.
    pub j: f32,
    /// Its violation, m³.
    pub violation: f32,
    /// Its minimum altitude, m.
    pub min_altitude: f32,
    /// `∂ΣJ/∂z`, m².
    pub grad_j: [f32; TRACKS],
    /// `∂ΣV/∂z`, m².
    pub grad_violation: [f32; TRACKS],
    /// End of the flight, `x` m.
    pub end_x: f32,
    /// End of the flight, depth m.
    pub end_depth: f32,
    /// Track-wise plan (`Planner::<1>`) of the last track, from the state
    /// in which flying the other tracks at [`SMOKE_DEPTHS`] leaves the
    /// vehicle.
    pub last_track: TrackPlan,
}

/// Reference depths of the smoke test's evaluation, m: about the horizon
/// plan's, with track 4 a little deep so that the violation and its
/// gradient are not zero.
pub const SMOKE_DEPTHS: [f32; TRACKS] = [845.6, 628.4, 115.1, 120.0, 60.4];

/// Computes [`Smoke`].
pub fn smoke() -> Result<Smoke, auvnav::Error> {
    let vehicle = Vehicle::c_auv4()?;
    let bottom = Profile::<S>::new(&monterey::X, &monterey::B)?;
    let waypoints = Waypoints::<W>::new(&monterey::WAYPOINTS)?;
    let line = Scenario::new(&vehicle, &bottom, &waypoints, Mission::default())?;
    let mut out = Smoke::default();
    let p = vehicle.plant();
    // Row-major, as `expected.rs` lists it.
    for (slot, v) in out.ad.iter_mut().zip(p.ad().iter().flatten()) {
        *slot = *v;
    }
    for (slot, v) in out.bd.iter_mut().zip(p.bd().iter()) {
        *slot = *v;
    }
    let start = line.start_state(line.default_initial_depth());
    let e = line.evaluate::<TRACKS>(&start, 0, &SMOKE_DEPTHS)?;
    out.j = e.j;
    out.violation = e.violation;
    out.min_altitude = e.min_altitude;
    out.grad_j = e.grad_j;
    out.grad_violation = e.grad_violation;
    out.end_x = e.end.x();
    out.end_depth = e.end.depth();
    let last = TRACKS.saturating_sub(1);
    let (first_tracks, _) = SMOKE_DEPTHS.split_at(last);
    let mut scores = [auvnav::TrackScore::default(); TRACKS];
    let (first_scores, _) = scores.split_at_mut(last);
    let state = line.simulate(&start, 0, first_tracks, first_scores, |_| {})?;
    let mut planner = Planner::<1>::new(trackwise_config())?;
    let plan = planner.plan(&line, &state, last)?;
    out.last_track = TrackPlan::of(&plan, &planner);
    Ok(out)
}
