//! Regression tests from fuzzing (`scripts/fuzz.sh`, `fuzz/`): each case a
//! fuzz target found, reduced to the library calls that show it.
//!
//! Each issue also has a switch in `fuzz/src/known.rs` under which the
//! fuzz targets would tolerate it (and only it) while it is open; all are
//! fixed (7f04130, 735d48d, f6ac315) and every switch is off.

// Test code: a failed unwrap or index is a failed test.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]
#![allow(clippy::arithmetic_side_effects)]

use std::sync::mpsc;
use std::time::Duration;

use auvnav::{
    AutopilotConfig, Mission, PidGains, PlanError, Planner, PlannerConfig, Profile, Scenario,
    SimError, TrackScore, TransferFunction, Vehicle, VehicleConfig, VehicleState, Waypoints,
};

/// Found by `planner` (a tuned vehicle with raw `speed` and `sample_time`):
/// each is positive, so `Vehicle::new` accepted them, but their product
/// `U0 Ts` underflows to 0 m. The vehicle then never advanced: a
/// simulation of a 100 m track ran its whole step budget, `u32::MAX`
/// steps when `4 L / (U0 Ts)` is infinite (about 700 s here), and a plan
/// runs dozens of those, against the README's bounded time. Either
/// `Vehicle::new` rejects such a vehicle (the fix), or the flight fails
/// fast.
#[test]
fn vehicle_step_underflowing_to_zero() {
    let cfg = VehicleConfig {
        speed: 1e-23,
        sample_time: 1e-23,
        ..VehicleConfig::default()
    };
    let Ok(vehicle) = Vehicle::new(&cfg, TransferFunction::C_AUV4) else {
        return; // rejected: fixed
    };
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let bottom = Profile::<4>::new(&[0.0, 100.0], &[300.0, 300.0]).unwrap();
        let waypoints = Waypoints::<4>::new(&[0.0, 100.0]).unwrap();
        let line = Scenario::new(&vehicle, &bottom, &waypoints, Mission::default()).unwrap();
        let start = line.start_state(220.0);
        let mut scores = [TrackScore::default()];
        let flown = line.simulate(&start, 0, &[220.0], &mut scores, |_| {});
        let planned = Planner::<1>::new(PlannerConfig::default())
            .unwrap()
            .plan(&line, &start, 0);
        let _ = tx.send((flown.is_err(), planned.is_err()));
    });
    match rx.recv_timeout(Duration::from_secs(10)) {
        Ok((flight_failed, plan_failed)) => {
            assert!(
                flight_failed && plan_failed,
                "a vehicle that never advances flew"
            );
        }
        Err(_) => panic!("a vehicle with U0 Ts = 0 m: simulate and plan still running after 10 s"),
    }
}

/// Found by `simulate` (`fuzz/regressions/simulate/score-overflow`: raw
/// bottom and reference depths): finite inputs of absurd magnitude
/// overflowed `J` (here `½ (3·10¹⁸ m)² · 100 m`) to ∞ and its compensated
/// sum to NaN, and `Scenario::simulate` and `Scenario::evaluate` returned
/// `Ok` with a NaN `J`, against "never a non-finite value" and
/// `SimError::Diverged` ("a value became non-finite").
#[test]
fn overflowing_score_is_an_error() {
    let vehicle = Vehicle::c_auv4().unwrap();
    let bottom = Profile::<4>::new(&[0.0, 100.0], &[3e18, 3e18]).unwrap();
    let waypoints = Waypoints::<4>::new(&[0.0, 100.0]).unwrap();
    let line = Scenario::new(&vehicle, &bottom, &waypoints, Mission::default()).unwrap();
    let start = line.start_state(0.0);

    let mut scores = [TrackScore::default()];
    let flown = line.simulate(&start, 0, &[0.0], &mut scores, |_| {});
    let s = scores[0];
    assert!(
        flown.is_err()
            || [s.j(), s.violation(), s.min_altitude()]
                .iter()
                .all(|v| v.is_finite()),
        "simulate returned Ok with J = {}",
        s.j()
    );
    if let Ok(e) = line.evaluate::<1>(&start, 0, &[0.0]) {
        assert!(
            [
                e.j,
                e.violation,
                e.min_altitude,
                e.grad_j[0],
                e.grad_violation[0]
            ]
            .iter()
            .all(|v| v.is_finite()),
            "evaluate returned Ok with {e:?}"
        );
    }
    if let Ok(p) = Planner::<1>::new(PlannerConfig::default())
        .unwrap()
        .plan(&line, &start, 0)
    {
        assert!(p.j.is_finite() && p.objective.is_finite(), "{p:?}");
    }
}

/// Found by `planner` (`fuzz/regressions/planner/scan-grid-rounding`):
/// the planner's scan grid `lo + (hi − lo) k / (n − 1)` was not clamped to
/// the search box, so rounding could put a scanned depth outside it, and
/// outside the mission's depth limits, and the planner returned it. Here,
/// depth limits `[-4.857232e-16, -1.917669e-37]` (the flights at all
/// scanned depths are the same, none is safe, and the last scanned one,
/// `lo + (hi − lo) = 0.0`, was returned as the safest); with ordinary
/// limits it is an ulp, e.g. `[119.0, 3319.6]` with 7 scan points scanned
/// 3319.6003.
#[test]
fn planned_depth_within_the_limits() {
    let vehicle = Vehicle::c_auv4().unwrap();
    let bottom = Profile::<4>::new(&[0.0, 53.4], &[48.64, 46.824417]).unwrap();
    let waypoints = Waypoints::<4>::new(&[0.0, 53.4]).unwrap();
    let limits = [-4.857232e-16, -1.917669e-37];
    let mission = Mission::new(80.0, 60.0, limits).unwrap();
    let line = Scenario::new(&vehicle, &bottom, &waypoints, mission).unwrap();
    let start = line.start_state(line.default_initial_depth());
    let plan = Planner::<1>::new(PlannerConfig::default())
        .unwrap()
        .plan(&line, &start, 0)
        .unwrap();
    assert!(
        plan.depth >= limits[0] && plan.depth <= limits[1],
        "planned depth {} outside the depth limits {limits:?} ({})",
        plan.depth,
        plan.status
    );
}

/// Found by `planner` (`fuzz/regressions/planner/start-off-track`: a start
/// state 6 cm before the first waypoint): `Planner::plan` documents an
/// error "for a simulation that fails at the very start (a non-finite
/// state, one off the track)", and `Scenario::simulate` names it
/// (`NonFiniteState`, `StateOffTrack`), but the planner's scan swallowed
/// every failed flight and then reported `SimError::Diverged`, which tells
/// the caller something else (an unstable flight, not a bad call).
#[test]
fn planner_names_a_bad_start_state() {
    let vehicle = Vehicle::c_auv4().unwrap();
    let bottom = Profile::<4>::new(&[0.0, 100.0], &[500.0, 500.0]).unwrap();
    let waypoints = Waypoints::<4>::new(&[0.0, 100.0]).unwrap();
    let line = Scenario::new(&vehicle, &bottom, &waypoints, Mission::default()).unwrap();
    let cases = [
        (VehicleState::trimmed(420.0, -0.06), SimError::StateOffTrack),
        (VehicleState::trimmed(420.0, 100.5), SimError::StateOffTrack),
        (
            VehicleState::trimmed(f32::NAN, 0.0),
            SimError::NonFiniteState,
        ),
    ];
    for (start, error) in cases {
        let mut scores = [TrackScore::default()];
        let flown = line.simulate(&start, 0, &[420.0], &mut scores, |_| {});
        assert_eq!(flown.unwrap_err(), error);
        let plan = Planner::<1>::new(PlannerConfig::default())
            .unwrap()
            .plan(&line, &start, 0);
        assert_eq!(plan.unwrap_err(), PlanError::Sim(error));
        let plan = Planner::<3>::new(PlannerConfig::default())
            .unwrap()
            .plan(&line, &start, 0);
        assert_eq!(plan.unwrap_err(), PlanError::Sim(error));
    }
}

/// Found by `simulate` (`fuzz/regressions/simulate/telemetry-overflow`):
/// the autopilot's telemetry terms (`Command::depth_terms`, "their sum is
/// the unclamped output") overflowed to ±∞ on absurd but finite inputs,
/// and `Scenario::simulate` handed them to the observer and returned `Ok`
/// (the clamped commands stayed finite).
#[test]
fn telemetry_terms_stay_finite() {
    let vehicle = Vehicle::c_auv4().unwrap();
    let bottom = Profile::<4>::new(&[0.0, 100.0], &[500.0, 500.0]).unwrap();
    let waypoints = Waypoints::<4>::new(&[0.0, 100.0]).unwrap();
    let line = Scenario::new(&vehicle, &bottom, &waypoints, Mission::default()).unwrap();
    let starts = [
        // A reference depth of -3e38 m: the P term.
        (line.start_state(420.0), -3e38),
        // A previous depth of -3e38 m: the D term.
        (
            VehicleState::new([0.0; 3], 420.0, -3e38, 0.0, 0.0, 0.0, 0.0),
            420.0,
        ),
    ];
    for (start, depth) in starts {
        let mut scores = [TrackScore::default()];
        let mut bad = None;
        let flown = line.simulate(&start, 0, &[depth], &mut scores, |s| {
            if let Some(c) = s.command {
                let (d, p) = (c.depth_terms, c.pitch_terms);
                if ![d.p, d.i, d.d, p.p, p.i, p.d].iter().all(|v| v.is_finite()) {
                    bad.get_or_insert(c);
                }
            }
        });
        assert!(
            flown.is_err() || bad.is_none(),
            "simulate returned Ok with the command {bad:?}"
        );
    }
}

/// Found by `planner` (`fuzz/regressions/planner/grad-norm-overflow`: a
/// window of a real profile exaggerated to a 2·10¹³ m deep bottom):
/// `Planner::plan` returned `Ok` with `grad_norm = +∞` (the objective and
/// the rest of the plan finite).
#[test]
fn plan_gradient_norm_stays_finite() {
    let vehicle = Vehicle::c_auv4().unwrap();
    let x = [
        -7187.457, -7187.0234, -7186.5894, -7186.156, -7185.7217, -7185.288, -7184.8545,
        -7184.4204, -7183.987, -7183.553, -7183.119, -7182.6855, -7182.2515, -7181.818, -7181.3843,
        -7180.95, -7180.5166, -7180.083, -7179.649, -7179.2153, -7178.7813, -7178.3477, -7177.914,
        -7177.48, -7177.0464, -7176.613, -7176.1787, -7175.745, -7175.311, -7174.8774, -7174.444,
        -7174.01, -7173.576, -7173.1426, -7172.7085, -7172.275, -7171.841, -7171.407,
    ];
    let b = [
        329.36,
        1.6788539e11,
        3.3323234e11,
        4.9602537e11,
        6.562799e11,
        8.139883e11,
        9.6661216e11,
        1.1192359e12,
        1.2667672e12,
        1.4117603e12,
        1.5567533e12,
        1.6966539e12,
        1.8340162e12,
        1.968832e12,
        2.1011019e12,
        2.230833e12,
        2.3554724e12,
        2.4801114e12,
        2.602212e12,
        2.71922e12,
        3.144022e12,
        3.8766099e12,
        4.59139e12,
        5.2909085e12,
        5.972619e12,
        6.639069e12,
        7.287718e12,
        8.6129854e12,
        1.0983719e13,
        1.2148732e13,
        1.3280683e13,
        1.438465e13,
        1.5455547e13,
        1.6498468e13,
        1.7508318e13,
        1.8563954e13,
        2.013596e13,
        2.1659644e13,
    ];
    let bottom = Profile::<64>::new(&x, &b).unwrap();
    let wp = [
        -7187.457, -7182.348, -7180.2046, -7178.0615, -7173.5503, -7171.407,
    ];
    let waypoints = Waypoints::<8>::new(&wp).unwrap();
    let line = Scenario::new(&vehicle, &bottom, &waypoints, Mission::default()).unwrap();
    let start = line.start_state(line.default_initial_depth());
    let plan = Planner::<3>::new(PlannerConfig::default())
        .unwrap()
        .plan(&line, &start, 0);
    if let Ok(p) = plan {
        assert!(p.grad_norm.is_finite(), "{p:?}");
    }
}

/// Found by `planner` (`fuzz/regressions/planner/rms-overflow`: a start
/// depth of 3·10¹⁸ m over a 38 m track): `J = 1.7·10³⁸` is finite, but the
/// RMS `√(2 J / L)` overflowed (`2 J` already did), and
/// `Scenario::simulate` and `Planner::plan` returned `Ok` with an infinite
/// RMS.
#[test]
fn rms_stays_finite() {
    let vehicle = Vehicle::c_auv4().unwrap();
    let x: Vec<f32> = (0..33).map(|i| -2631.9512 + 1.4719 * i as f32).collect();
    let b: Vec<f32> = (0..33)
        .map(|i| 33.0 + 5.0 * (0.2 * i as f32).cos())
        .collect();
    let bottom = Profile::<64>::new(&x, &b).unwrap();
    let waypoints = Waypoints::<8>::new(&[-2627.4512, -2589.351]).unwrap();
    let line = Scenario::new(&vehicle, &bottom, &waypoints, Mission::default()).unwrap();
    let start = line.start_state(2.9904567e18);
    assert_one_track_finite(&line, &start, 6000.0);
    let plan = Planner::<1>::new(PlannerConfig::default())
        .unwrap()
        .plan(&line, &start, 0);
    if let Ok(p) = plan {
        assert!(p.j.is_finite() && p.rms.is_finite(), "{p:?}");
    }
}

/// Found by `simulate` (`fuzz/regressions/simulate/rms-subnormal-track`: a
/// track 3·10⁻³⁹ m long, a subnormal length): `2 / L` overflowed to
/// infinity, and the RMS of a finite, tiny `J` with it.
#[test]
fn rms_of_a_subnormal_track_stays_finite() {
    let vehicle = Vehicle::c_auv4().unwrap();
    let bottom = Profile::<4>::new(&[-1.704475e38, 2.3552217e-38], &[1.7014118e38, 0.0]).unwrap();
    let waypoints = Waypoints::<4>::new(&[0.0, 3.030571e-39]).unwrap();
    let line = Scenario::new(&vehicle, &bottom, &waypoints, Mission::default()).unwrap();
    let start = line.start_state(line.default_initial_depth());
    assert_one_track_finite(&line, &start, line.default_initial_depth());
}

/// Track 1 of `line` flown from `start` at depth `z` (m): a typed error, or
/// a finite `J` and RMS.
fn assert_one_track_finite(line: &Scenario<'_, 3>, start: &VehicleState<3>, z: f32) {
    let mut scores = [TrackScore::default()];
    let flown = line.simulate(start, 0, &[z], &mut scores, |_| {});
    let s = scores[0];
    assert!(
        flown.is_err() || (s.j().is_finite() && s.rms().is_finite()),
        "simulate returned Ok with J {} and RMS {}",
        s.j(),
        s.rms()
    );
}

/// Found by `planner` (`fuzz/regressions/planner/integrator-overflow`): a
/// depth gain `Kpd` of 3.6·10⁻⁴³ and a depth limit of −1.7·10³⁸ m let a
/// reference of −1.7·10³⁸ m integrate into `I_d` unclamped: the depth
/// integral overflowed to −∞ on the track's last step, and the plan came
/// back `converged` and `safe` with that non-finite `next_state` (and
/// `simulate` returned `Ok` with it).
#[test]
fn end_state_stays_finite() {
    let d = VehicleConfig::default();
    let cfg = VehicleConfig {
        sample_time: 0.997_635_1,
        autopilot: AutopilotConfig {
            depth_pid: PidGains {
                kp: 3.57e-43,
                ki: 0.0,
                kd: 0.0,
            },
            ..d.autopilot
        },
        ..d
    };
    let vehicle = Vehicle::<3>::new(&cfg, TransferFunction::C_AUV4).unwrap();
    let bottom = Profile::<4>::new(&[0.0, 110.73842], &[505.88757, 500.89206]).unwrap();
    let waypoints = Waypoints::<8>::new(&[0.0, 4.309819, 8.260487, 58.362137]).unwrap();
    let start_depth = 425.88757;
    for limits in [[-1.7014118e38, 4.9113844e-25], [0.0, 6000.0]] {
        let mission = Mission::new(80.0, 60.0, limits).unwrap();
        let line = Scenario::new(&vehicle, &bottom, &waypoints, mission).unwrap();
        let start = line.start_state(start_depth);
        for depth in [-1.7014118e38, -1.6e38, 4.9113844e-25] {
            let mut scores = [TrackScore::default()];
            if let Ok(end) = line.simulate(&start, 0, &[depth], &mut scores, |_| {}) {
                assert!(end.depth_integral().is_finite(), "{end:?}");
            }
        }
        for k in [1, 3] {
            let config = PlannerConfig::default();
            let plan = if k == 1 {
                Planner::<1>::new(config)
                    .unwrap()
                    .plan(&line, &start, 0)
                    .map(|p| p.next_state)
            } else {
                Planner::<3>::new(config)
                    .unwrap()
                    .plan(&line, &start, 0)
                    .map(|p| p.next_state)
            };
            if let Ok(next) = plan {
                let values = [
                    next.depth(),
                    next.x(),
                    next.depth_integral(),
                    next.pitch_integral(),
                ];
                assert!(values.iter().all(|v| v.is_finite()), "{next:?}");
            }
        }
    }
}
