//! `Autopilot::update` is the real control loop's call: a firmware loop
//! that measures depth, pitch and pitch rate each sample, calls `update`
//! and drives the elevator flies the same flight as the planner's
//! simulation of it. Here the "vehicle" is the plant itself (`Plant::step`)
//! with the contract's kinematics written out in f64, so the only
//! differences are the simulation's compensated sums and f32 rounding.
#![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::float_cmp)]
#![allow(clippy::arithmetic_side_effects)]

use auvnav::{AutopilotState, Mission, Profile, Sample, Scenario, TrackScore, Vehicle, Waypoints};

#[test]
fn the_real_loop_flies_the_simulated_flight() {
    let vehicle = Vehicle::c_auv4().unwrap();
    let bottom = Profile::<4>::new(&[0.0, 3000.0], &[600.0, 400.0]).unwrap();
    let wps = Waypoints::<4>::new(&[0.0, 1000.0, 2000.0]).unwrap();
    let sc = Scenario::new(&vehicle, &bottom, &wps, Mission::default()).unwrap();
    let d0 = sc.default_initial_depth();
    let start = sc.start_state(d0);
    // Dive 40 m, then climb 90 m: both loops saturate on the way.
    let depths = [d0 + 40.0, d0 - 50.0];
    let mut samples: Vec<Sample> = Vec::new();
    let mut scores = [TrackScore::default(); 2];
    sc.simulate(&start, 0, &depths, &mut scores, |s| samples.push(*s))
        .unwrap();

    let ap = vehicle.autopilot();
    let plant = vehicle.plant();
    let (u, ts) = (f64::from(vehicle.speed()), f64::from(vehicle.sample_time()));
    let mut state = AutopilotState::trimmed(d0);
    let mut eta = [0.0_f32; 3];
    let (mut x, mut d) = (0.0_f64, f64::from(d0));
    let mut worst = (0.0_f32, 0.0_f64);
    for s in samples.iter().filter(|s| s.command.is_some()) {
        let (track, r) = s.reference.unwrap();
        // The same reference the simulation switched to at this sample.
        assert_eq!(track, usize::from(x >= 1000.0), "switch at x = {x}");
        let theta = plant.pitch(&eta);
        let cmd = ap.update(&mut state, r, d as f32, theta, plant.pitch_rate(&eta));
        let sim = s.command.unwrap();
        worst.0 = worst.0.max((cmd.elevator - sim.elevator).abs());
        worst.1 = worst.1.max((d - f64::from(s.depth)).abs());
        eta = plant.step(&eta, cmd.elevator);
        let mean = 0.5 * f64::from(theta + plant.pitch(&eta)).to_radians();
        d -= u * ts * mean.sin();
        x += u * ts * mean.cos();
    }
    // Saturated stretches agree exactly; elsewhere to f32 rounding of the
    // depth rate (the loop differences plain depths, the simulation its
    // compensated steps).
    assert!(worst.0 < 1e-2, "elevator differs by {} deg", worst.0);
    assert!(worst.1 < 1e-2, "depth differs by {} m", worst.1);
    assert!(samples.len() > 10_000);
}
