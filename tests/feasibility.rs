//! Recursive feasibility (model contract §11), as a property over random
//! terrains: for every horizon `1..=K`, iteration cap and evaluation
//! budget, the line the planner flies call after call is safe wherever a
//! safe line exists, and `infeasible` comes only where none does.
//!
//! The referee is a search of whole lines of its own (a grid over both
//! tracks' reference depths, the climb included), independent of the
//! planner's code path; it flies with the library's simulation, whose
//! agreement with the independent f64 reference is `tests/golden.rs`'s.
//! Seed committed: the run is reproducible.
#![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::float_cmp)]
#![allow(clippy::arithmetic_side_effects, clippy::cast_precision_loss)]

use auvnav::{
    Mission, Mode, PlanStatus, Planner, PlannerConfig, Profile, Scenario, TrackScore, Vehicle,
    VehicleState, Waypoints,
};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

const SEED: [u8; 32] = *b"auvnav recursive feasibility 001";

#[derive(Clone, Debug)]
struct Case {
    x: Vec<f32>,
    b: Vec<f32>,
    waypoints: [f32; 3],
    h_r: f32,
    h_a: f32,
    start_altitude: f32,
    horizon: usize,
    max_iterations: u32,
    max_evaluations: u32,
}

/// Walls, ridges and flats under a 2-track line: about one case in three
/// has no safe line at all.
fn case() -> impl Strategy<Value = Case> {
    (
        (30_usize..70, 10.0_f32..25.0, 300.0_f32..900.0),
        prop::collection::vec((0_u8..6, -1.0_f32..1.0), 70),
        (0.3_f32..0.6, 0.4_f32..0.7),
        (20.0_f32..90.0, 0.3_f32..0.9, 0.6_f32..1.6),
        (
            1_usize..=2,
            1_u32..=200,
            prop_oneof![Just(u32::MAX), 1_u32..40],
        ),
    )
        .prop_map(
            |((n, ds, d0), steps, (w1, w2), (h_r, frac, start), (horizon, it, ev))| {
                let mut x = Vec::with_capacity(n);
                let mut b = Vec::with_capacity(n);
                let mut d = d0;
                for (i, &(kind, u)) in steps.iter().take(n).enumerate() {
                    x.push(i as f32 * ds);
                    b.push(d.max(10.0));
                    let slope = match kind {
                        0 => 0.0,
                        1 => u.signum() * 2.0, // a wall of about 63°
                        _ => (u * 40.0_f32).to_radians().tan(),
                    };
                    d -= slope * ds;
                }
                let end = *x.last().unwrap();
                let x1 = end * w1 * 0.9;
                let x2 = x1 + (end * 0.98 - x1) * w2 + 10.0;
                Case {
                    waypoints: [0.0, x1, x2.min(end * 0.99)],
                    x,
                    b,
                    h_r,
                    h_a: h_r * frac,
                    start_altitude: h_r * start,
                    horizon,
                    max_iterations: it,
                    max_evaluations: ev,
                }
            },
        )
}

/// The least altitude of the whole line flown at `z` (one depth per
/// track) from `st`, or `-inf` when the flight fails.
fn line_min(sc: &Scenario<'_, 3>, st: &VehicleState<3>, z: &[f32]) -> f32 {
    let mut s = [TrackScore::default(); 2];
    match sc.simulate(st, 0, z, &mut s, |_| {}) {
        Ok(_) => s
            .iter()
            .map(TrackScore::min_altitude)
            .fold(f32::INFINITY, f32::min),
        Err(_) => f32::NEG_INFINITY,
    }
}

/// The referee: the best least altitude over a grid of both tracks'
/// depths (from the surface to 150 m below the start, 17 values each).
fn best_line(sc: &Scenario<'_, 3>, st: &VehicleState<3>) -> f32 {
    let grid: Vec<f32> = (0..17)
        .map(|k| (st.depth() + 150.0) * k as f32 / 16.0)
        .collect();
    let mut best = f32::NEG_INFINITY;
    for &z1 in &grid {
        for &z2 in &grid {
            best = best.max(line_min(sc, st, &[z1, z2]));
        }
    }
    best
}

#[test]
fn the_flown_line_is_safe_wherever_a_safe_line_exists() {
    let default = if cfg!(debug_assertions) { 60 } else { 1_500 };
    let cases: u32 = std::env::var("FEASIBILITY_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default);
    let mut runner = TestRunner::new_with_rng(
        Config {
            cases,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::from_seed(RngAlgorithm::ChaCha, &SEED),
    );
    let vehicle = Vehicle::c_auv4().unwrap();
    // flown safe, reported infeasible (referee agrees), later-call recoveries refused
    let stats: [std::cell::Cell<u32>; 2] = Default::default();
    let result = runner.run(&case(), |c| {
        let profile = Profile::<80>::new(&c.x, &c.b).unwrap();
        let wps = Waypoints::<3>::new(&c.waypoints).unwrap();
        let mission = Mission::new(c.h_r, c.h_a, [0.0, 6000.0]).unwrap();
        let sc = Scenario::new(&vehicle, &profile, &wps, mission).unwrap();
        let start = sc.start_state(c.b[0] - c.start_altitude);
        let cfg = PlannerConfig {
            mode: Mode::Horizon,
            horizon: c.horizon,
            max_evaluations: c.max_evaluations,
            ..PlannerConfig::default()
        };
        let mut cfg = cfg;
        cfg.bfgs.max_iterations = c.max_iterations;
        let mut planner = Planner::<2>::new(cfg).unwrap();
        let (mut st, mut depths, mut safe) = (start, Vec::new(), Vec::new());
        for n in 0..2 {
            let Ok(p) = planner.plan(&sc, &st, n) else {
                // Only after an infeasible call can a prediction end in rock.
                prop_assert!(safe.iter().any(|s| !s), "plan failed after safe calls");
                break;
            };
            prop_assert_eq!(p.safe, p.status != PlanStatus::Infeasible);
            depths.push(p.depth);
            safe.push(p.safe);
            st = p.next_state;
        }
        // Once a call has committed a certified continuation, every later
        // call has one.
        if let Some(first_safe) = safe.iter().position(|&s| s) {
            prop_assert!(
                safe[first_safe..].iter().all(|&s| s),
                "a safe call followed by an infeasible one: {safe:?}"
            );
        }
        if safe.len() == 2 && safe.iter().all(|&s| s) {
            stats[0].set(stats[0].get() + 1);
            let m = line_min(&sc, &start, &depths);
            prop_assert!(
                m >= c.h_a,
                "flown line {depths:?} goes to {m} < h_a {}",
                c.h_a
            );
        }
        if safe.first() == Some(&false) {
            stats[1].set(stats[1].get() + 1);
            let best = best_line(&sc, &start);
            prop_assert!(
                best < c.h_a + 0.05,
                "infeasible reported at the first call, but a line flies {best} >= h_a {}",
                c.h_a
            );
        }
        Ok(())
    });
    println!(
        "{cases} terrains: {} lines flown safe, {} infeasible from the first call \
         (the referee found no safe line either)",
        stats[0].get(),
        stats[1].get()
    );
    result.unwrap();
}
