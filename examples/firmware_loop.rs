//! How an autopilot firmware uses the library, written as it would be on a
//! Cortex-M (no allocation, static data, one planner placed by the caller),
//! and run here on the host with the plant standing in for the vehicle:
//!
//! - the map and the line are `static` arrays, validated once into views;
//! - a 10 Hz control step calls [`Autopilot::update`] on the measurements;
//! - at each waypoint the planner plans the next track from the measured
//!   state (`VehicleState::new`), and the autopilot steers to its depth.
//!
//! `cargo run --release --example firmware_loop`
#![allow(
    clippy::unwrap_used,
    clippy::arithmetic_side_effects,
    clippy::indexing_slicing
)]

use auvnav::{
    AutopilotState, Mission, Planner, PlannerConfig, ProfileView, Scenario, Vehicle, VehicleState,
    WaypointsView,
};

/// The mapped bottom under the line, m (as flashed with the mission).
static MAP_X: [f32; 7] = [0.0, 400.0, 800.0, 1200.0, 1600.0, 2000.0, 2400.0];
static MAP_B: [f32; 7] = [500.0, 480.0, 430.0, 330.0, 300.0, 310.0, 320.0];
/// The line's waypoints, m along track.
static WAYPOINTS: [f32; 4] = [0.0, 800.0, 1600.0, 2380.0];

fn main() -> Result<(), auvnav::Error> {
    let vehicle = Vehicle::c_auv4()?;
    let map = ProfileView::new(&MAP_X, &MAP_B)?;
    let line = auvnav::Waypoints::<4>::new(&WAYPOINTS)?;
    let line: WaypointsView<'_> = line.view();
    let sc = Scenario::from_views(&vehicle, map, line, Mission::default())?;
    // The planner and its workspace: a `static` in firmware.
    let mut planner = Planner::<3>::new(PlannerConfig::default())?;

    // The vehicle (here: the plant and the kinematics), and what the
    // firmware measures of it.
    let plant = vehicle.plant();
    let (u, ts) = (vehicle.speed(), vehicle.sample_time());
    let d0 = sc.default_initial_depth();
    let (mut eta, mut x, mut x_prev, mut d, mut d_prev) = ([0.0_f32; 3], 0.0_f32, 0.0_f32, d0, d0);
    let mut ap = AutopilotState::trimmed(d0);
    let mut track = None;
    let mut reference = d0;
    let mut min_altitude = f32::INFINITY;
    while x < WAYPOINTS[3] {
        // At a waypoint: plan the next track from the measured state.
        let n = WAYPOINTS.iter().rposition(|&w| x >= w).unwrap_or(0);
        if track != Some(n) {
            let state = VehicleState::new(
                eta,
                d,
                d_prev,
                x,
                x_prev,
                ap.depth_integral,
                ap.pitch_integral,
            );
            let plan = planner.plan(&sc, &state, n)?;
            println!(
                "track {}: depth {:.1} m, {}, predicted min altitude {:.1} m",
                n + 1,
                plan.depth,
                plan.status,
                plan.min_altitude
            );
            reference = plan.depth;
            track = Some(n);
        }
        // The 10 Hz control step, as the autopilot runs it.
        let theta = plant.pitch(&eta);
        let cmd = vehicle
            .autopilot()
            .update(&mut ap, reference, d, theta, plant.pitch_rate(&eta));
        eta = plant.step(&eta, cmd.elevator);
        let mean = 0.5 * (theta + plant.pitch(&eta)).to_radians();
        d_prev = d;
        d -= u * ts * mean.sin();
        x_prev = x;
        x += u * ts * mean.cos();
        if x <= WAYPOINTS[3] {
            min_altitude = min_altitude.min(map.depth_at(x)? - d);
        }
    }
    println!("flown: minimum altitude {min_altitude:.1} m (h_a 60 m)");
    Ok(())
}
