//! One test per row of the README's input-error table: every invalid input
//! to the library gets its typed error (and never a panic or a non-finite
//! value). The host tool's rows are in `tests/cli.rs`.

// Test code: a failed unwrap or index is a failed test.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]
#![allow(clippy::arithmetic_side_effects)]

use auvnav::optim::{self, BfgsConfig, Bounds, OptimConfigError, OptimError};
use auvnav::{
    AutopilotConfig, ConfigError, Mission, PidGains, PlanConfigError, PlanError, Planner,
    PlannerConfig, PlantError, Profile, ProfileError, Scenario, SimError, TfKind, TrackScore,
    TransferFunction, Vehicle, VehicleConfig, VehicleState, WaypointError, Waypoints,
};

const DEN: [f32; 4] = [1.0, 2.681, 0.546, 0.048];

fn vehicle(f: impl FnOnce(&mut VehicleConfig)) -> Result<Vehicle<3>, ConfigError> {
    let mut c = VehicleConfig::default();
    f(&mut c);
    Vehicle::new(&c, TransferFunction::C_AUV4)
}

fn line() -> (Vehicle<3>, Profile<8>, Waypoints<4>) {
    (
        Vehicle::c_auv4().unwrap(),
        Profile::new(&[0.0, 500.0, 1000.0], &[300.0, 280.0, 250.0]).unwrap(),
        Waypoints::new(&[0.0, 500.0, 1000.0]).unwrap(),
    )
}

#[test]
fn empty_or_one_sample_profile() {
    assert_eq!(
        Profile::<8>::new(&[], &[]).unwrap_err(),
        ProfileError::TooFewSamples { len: 0 }
    );
    assert_eq!(
        Profile::<8>::new(&[0.0], &[1.0]).unwrap_err(),
        ProfileError::TooFewSamples { len: 1 }
    );
}

#[test]
fn profile_over_capacity() {
    let x: Vec<f32> = (0..9).map(|i| i as f32).collect();
    assert_eq!(
        Profile::<8>::new(&x, &x).unwrap_err(),
        ProfileError::OverCapacity {
            len: 9,
            capacity: 8
        }
    );
}

#[test]
fn profile_arrays_of_different_length() {
    assert_eq!(
        Profile::<8>::new(&[0.0, 1.0], &[1.0]).unwrap_err(),
        ProfileError::LengthMismatch {
            x_len: 2,
            depth_len: 1
        }
    );
}

#[test]
fn non_finite_profile_sample() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        assert_eq!(
            Profile::<8>::new(&[0.0, bad], &[1.0, 2.0]).unwrap_err(),
            ProfileError::NonFinite { index: 1 }
        );
        assert_eq!(
            Profile::<8>::new(&[0.0, 1.0], &[bad, 2.0]).unwrap_err(),
            ProfileError::NonFinite { index: 0 }
        );
    }
}

#[test]
fn unsorted_or_duplicate_profile_x() {
    assert_eq!(
        Profile::<8>::new(&[0.0, 2.0, 1.0], &[1.0; 3]).unwrap_err(),
        ProfileError::NotIncreasing { index: 2 }
    );
    assert_eq!(
        Profile::<8>::new(&[0.0, 1.0, 1.0], &[1.0; 3]).unwrap_err(),
        ProfileError::NotIncreasing { index: 2 }
    );
}

#[test]
fn bottom_query_outside_the_profile() {
    let (_, p, _) = line();
    assert_eq!(p.depth_at(-1.0), Err(ProfileError::OutOfRange));
    assert_eq!(p.depth_at(1000.5), Err(ProfileError::OutOfRange));
    assert_eq!(p.depth_at(f32::NAN), Err(ProfileError::OutOfRange));
}

#[test]
fn fewer_than_two_waypoints() {
    assert_eq!(
        Waypoints::<4>::new(&[0.0]).unwrap_err(),
        WaypointError::TooFew { len: 1 }
    );
}

#[test]
fn waypoints_over_capacity() {
    assert_eq!(
        Waypoints::<2>::new(&[0.0, 1.0, 2.0]).unwrap_err(),
        WaypointError::OverCapacity {
            len: 3,
            capacity: 2
        }
    );
}

#[test]
fn non_finite_waypoint() {
    assert_eq!(
        Waypoints::<4>::new(&[0.0, f32::NAN]).unwrap_err(),
        WaypointError::NonFinite { index: 1 }
    );
}

#[test]
fn waypoints_not_increasing() {
    assert_eq!(
        Waypoints::<4>::new(&[0.0, 5.0, 5.0]).unwrap_err(),
        WaypointError::NotIncreasing { index: 2 }
    );
}

#[test]
fn waypoint_outside_the_profile() {
    let (v, p, _) = line();
    let w = Waypoints::<4>::new(&[0.0, 500.0, 1001.0]).unwrap();
    assert_eq!(
        Scenario::new(&v, &p, &w, Mission::default()).unwrap_err(),
        SimError::Waypoints(WaypointError::OutsideProfile { index: 2 })
    );
}

#[test]
fn non_positive_speed_or_sample_time() {
    assert_eq!(
        vehicle(|c| c.speed = 0.0).unwrap_err(),
        ConfigError::NotPositive("speed")
    );
    assert_eq!(
        vehicle(|c| c.speed = -1.5).unwrap_err(),
        ConfigError::NotPositive("speed")
    );
    assert_eq!(
        vehicle(|c| c.sample_time = 0.0).unwrap_err(),
        ConfigError::NotPositive("sample_time")
    );
}

#[test]
fn step_length_below_a_tenth_of_a_millimetre() {
    // Each positive, the step they make (U0 Ts) too short or underflowing.
    for (speed, sample_time) in [(1e-23_f32, 1e-23_f32), (1e-3, 1e-2)] {
        assert_eq!(
            vehicle(|c| {
                c.speed = speed;
                c.sample_time = sample_time;
            })
            .unwrap_err(),
            ConfigError::OutOfRange("speed × sample_time")
        );
    }
    assert!(vehicle(|c| c.speed = 0.01).is_ok());
}

#[test]
fn non_finite_parameter() {
    assert_eq!(
        vehicle(|c| c.speed = f32::NAN).unwrap_err(),
        ConfigError::NonFinite("speed")
    );
    assert_eq!(
        vehicle(|c| c.autopilot.pitch_pid.ki = f32::INFINITY).unwrap_err(),
        ConfigError::NonFinite("pitch_pid.ki")
    );
    assert_eq!(
        Mission::new(80.0, 60.0, [0.0, f32::NAN]).unwrap_err(),
        ConfigError::NonFinite("depth_limits")
    );
}

#[test]
fn negative_gain_or_limit() {
    assert_eq!(
        vehicle(|c| c.autopilot.depth_pid.kp = -1.0).unwrap_err(),
        ConfigError::Negative("depth_pid.kp")
    );
    assert_eq!(
        vehicle(|c| c.autopilot.pitch_limit = -25.0).unwrap_err(),
        ConfigError::NotPositive("pitch_limit")
    );
    assert_eq!(
        vehicle(|c| c.autopilot.elevator_limit = -25.0).unwrap_err(),
        ConfigError::NotPositive("elevator_limit")
    );
    assert_eq!(
        Mission::new(80.0, -60.0, [0.0, 6000.0]).unwrap_err(),
        ConfigError::NotPositive("min_altitude")
    );
}

#[test]
fn pitch_limit_of_90_degrees_or_more() {
    assert_eq!(
        vehicle(|c| c.autopilot.pitch_limit = 90.0).unwrap_err(),
        ConfigError::OutOfRange("pitch_limit")
    );
}

#[test]
fn min_altitude_above_reference_altitude() {
    assert_eq!(
        Mission::new(60.0, 80.0, [0.0, 6000.0]).unwrap_err(),
        ConfigError::MinAltitudeAboveReference
    );
}

#[test]
fn depth_limits_reversed() {
    assert_eq!(
        Mission::new(80.0, 60.0, [100.0, 0.0]).unwrap_err(),
        ConfigError::DepthLimitsReversed
    );
}

#[test]
fn plant_coefficient_not_finite() {
    assert_eq!(
        TransferFunction::<3>::pitch(&[f32::NAN], &DEN).unwrap_err(),
        PlantError::NonFinite
    );
    assert_eq!(
        TransferFunction::<3>::rate(&[-0.173, 0.0], &[1.0, f32::INFINITY, 0.5, 0.1]).unwrap_err(),
        PlantError::NonFinite
    );
}

#[test]
fn plant_relative_degree_below_two() {
    assert_eq!(
        TransferFunction::<3>::pitch(&[1.0, 0.0, -0.173], &DEN).unwrap_err(),
        PlantError::RelativeDegree {
            num_degree: 2,
            den_degree: 3
        }
    );
    // In rate form, q/δ of relative degree 1 is θ/δ of relative degree 2: fine;
    // relative degree 0 in q/δ is not.
    assert!(TransferFunction::<3>::rate(&[-0.173, 0.0], &DEN).is_ok());
    assert!(TransferFunction::<3>::rate(&[1.0, 0.0, -0.173, 0.0], &DEN).is_err());
}

#[test]
fn plant_order_above_capacity() {
    assert_eq!(
        TransferFunction::<2>::pitch(&[-0.173], &DEN).unwrap_err(),
        PlantError::OrderTooHigh {
            order: 3,
            capacity: 2
        }
    );
}

#[test]
fn plant_without_dynamics() {
    assert_eq!(
        TransferFunction::<3>::pitch(&[1.0], &[0.0, 0.0]).unwrap_err(),
        PlantError::NoDynamics
    );
    assert_eq!(
        TransferFunction::<3>::pitch(&[1.0], &[]).unwrap_err(),
        PlantError::NoDynamics
    );
}

#[test]
fn rate_numerator_with_a_constant_term() {
    assert_eq!(
        TransferFunction::<3>::new(TfKind::Rate, &[-0.173, 0.01], &DEN).unwrap_err(),
        PlantError::RateNumeratorNotDivisible
    );
}

#[test]
fn plant_with_no_steady_gain() {
    assert_eq!(
        TransferFunction::<4>::pitch(&[1.0, 0.0], &[1.0, 1.0, 1.0, 1.0]).unwrap_err(),
        PlantError::NoSteadyGain
    );
}

#[test]
fn plant_too_fast_for_f32() {
    let tf = TransferFunction::<3>::pitch(&[-0.173], &[1.0, 1e13, 1e13, 1e13]).unwrap();
    assert_eq!(
        Vehicle::new(&VehicleConfig::default(), tf).unwrap_err(),
        ConfigError::Plant(PlantError::Discretization)
    );
}

#[test]
fn gains_that_make_the_closed_loop_diverge() {
    let cfg = AutopilotConfig {
        pitch_pid: PidGains {
            kp: 30.0,
            ki: 0.1,
            kd: 0.0,
        },
        ..AutopilotConfig::default()
    };
    assert_eq!(
        vehicle(|c| c.autopilot = cfg).unwrap_err(),
        ConfigError::UnstableLoop
    );
}

#[test]
fn non_finite_reference_depth_or_state() {
    let (v, p, w) = line();
    let sc = Scenario::new(&v, &p, &w, Mission::default()).unwrap();
    let st = sc.start_state(220.0);
    let mut s = [TrackScore::default(); 2];
    assert_eq!(
        sc.simulate(&st, 0, &[200.0, f32::NAN], &mut s, |_| {})
            .unwrap_err(),
        SimError::NonFiniteDepth { index: 1 }
    );
    let bad = VehicleState::<3>::trimmed(f32::INFINITY, 0.0);
    assert_eq!(
        sc.simulate(&bad, 0, &[200.0], &mut s, |_| {}).unwrap_err(),
        SimError::NonFiniteState
    );
    assert_eq!(
        sc.evaluate::<1>(&bad, 0, &[200.0]).unwrap_err(),
        SimError::NonFiniteState
    );
}

#[test]
fn absurd_reference_depth_gives_no_infinite_state() {
    // Found by fuzzing: a finite reference of -1.7e38 m drove the depth
    // integral to -inf while the clamped flight stayed finite.
    let (v, p, w) = line();
    let sc = Scenario::new(&v, &p, &w, Mission::default()).unwrap();
    let st = sc.start_state(220.0);
    let mut s = [TrackScore::default()];
    match sc.simulate(&st, 0, &[-1.7e38], &mut s, |_| {}) {
        Ok(end) => assert!(end.depth_integral().is_finite() && s[0].j().is_finite()),
        Err(e) => assert_eq!(e, SimError::Diverged),
    }
}

#[test]
fn planner_names_a_bad_start_state() {
    let (v, p, w) = line();
    let sc = Scenario::new(&v, &p, &w, Mission::default()).unwrap();
    for (st, e) in [
        (
            VehicleState::<3>::trimmed(f32::NAN, 0.0),
            SimError::NonFiniteState,
        ),
        (
            VehicleState::<3>::trimmed(220.0, 600.0),
            SimError::StateOffTrack,
        ),
    ] {
        let mut one = Planner::<1>::new(PlannerConfig::default()).unwrap();
        assert_eq!(one.plan(&sc, &st, 0).unwrap_err(), PlanError::Sim(e));
        let mut two = Planner::<2>::new(PlannerConfig::default()).unwrap();
        assert_eq!(two.plan(&sc, &st, 0).unwrap_err(), PlanError::Sim(e));
    }
}

#[test]
fn state_off_the_track_or_tracks_out_of_range() {
    let (v, p, w) = line();
    let sc = Scenario::new(&v, &p, &w, Mission::default()).unwrap();
    let st = sc.start_state(220.0);
    let mut s = [TrackScore::default(); 3];
    assert_eq!(
        sc.simulate(&st, 1, &[200.0], &mut s, |_| {}).unwrap_err(),
        SimError::StateOffTrack
    );
    assert_eq!(
        sc.simulate(&st, 0, &[200.0, 200.0, 200.0], &mut s, |_| {})
            .unwrap_err(),
        SimError::TrackRange
    );
    assert_eq!(
        sc.simulate(&st, 0, &[], &mut s, |_| {}).unwrap_err(),
        SimError::TrackRange
    );
    let mut short = [TrackScore::default(); 1];
    assert_eq!(
        sc.simulate(&st, 0, &[200.0, 200.0], &mut short, |_| {})
            .unwrap_err(),
        SimError::ScoreBuffer
    );
    let mut planner = Planner::<2>::new(PlannerConfig::default()).unwrap();
    assert_eq!(
        planner.plan(&sc, &st, 2).unwrap_err(),
        PlanError::TrackRange
    );
}

#[test]
fn planner_or_optimizer_setting_out_of_range() {
    let d = PlannerConfig::default();
    assert_eq!(
        Planner::<2>::new(PlannerConfig { gd_rate: -1.0, ..d }).unwrap_err(),
        PlanError::Config(PlanConfigError::Optimizer(OptimConfigError::GdRate))
    );
    assert_eq!(
        Planner::<2>::new(PlannerConfig {
            penalty_stages: 0,
            ..d
        })
        .unwrap_err(),
        PlanError::Config(PlanConfigError::PenaltyStages)
    );
    struct Q;
    impl optim::Objective<1> for Q {
        type Error = ();
        fn eval(&mut self, z: &[f32; 1]) -> Result<(f32, [f32; 1]), ()> {
            Ok((z[0] * z[0], [2.0 * z[0]]))
        }
    }
    let mut cfg = BfgsConfig::default();
    cfg.armijo.shrink = 1.5;
    let z = [1.0_f32];
    assert_eq!(
        optim::bfgs(&mut Q, &z, &Bounds::uniform(-2.0, 2.0), &cfg).unwrap_err(),
        OptimError::Config(OptimConfigError::ArmijoShrink)
    );
    assert_eq!(
        optim::bfgs(
            &mut Q,
            &z,
            &Bounds::uniform(2.0, -2.0),
            &BfgsConfig::default()
        )
        .unwrap_err(),
        OptimError::Config(OptimConfigError::Bounds)
    );
}

#[test]
fn non_finite_objective_at_the_start() {
    struct Nan;
    impl optim::Objective<1> for Nan {
        type Error = ();
        fn eval(&mut self, _: &[f32; 1]) -> Result<(f32, [f32; 1]), ()> {
            Ok((f32::NAN, [0.0]))
        }
    }
    let z = [1.0_f32];
    assert_eq!(
        optim::bfgs(
            &mut Nan,
            &z,
            &Bounds::uniform(-2.0, 2.0),
            &BfgsConfig::default()
        )
        .unwrap_err(),
        OptimError::NonFinite
    );
}
