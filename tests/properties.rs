//! Property tests on random terrains and vehicles (seed committed below):
//! - nothing panics and every output is finite;
//! - every depth the planner reports safe is safe when re-simulated by an
//!   independent f64 implementation of the contract written here (RK4
//!   sub-stepping instead of the library's matrix exponential, no
//!   compensated sums, no cursor), to 1e-2 m;
//! - every `infeasible` really has no safe depth: a grid of the whole
//!   reachable range (beyond it the pitch reference saturates over the
//!   whole track, so the flight is the same) finds none.
//!
//! `PROPTEST_CASES` sets the number of terrains (default 10,000 in release,
//! as the README's test command runs it, 500 in an unoptimized build).

// Test code: a failed unwrap or index is a failed test.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]
#![allow(
    clippy::arithmetic_side_effects,
    clippy::float_cmp,
    clippy::too_many_arguments
)]

use auvnav::{
    AutopilotConfig, Mission, Mode, PidGains, PlanStatus, Planner, PlannerConfig, Profile,
    Scenario, TrackScore, TransferFunction, Vehicle, VehicleConfig, Waypoints,
};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// The committed seed of the run.
const SEED: [u8; 32] = *b"auvnav-properties-seed-2026-11-2";

#[derive(Clone, Debug)]
struct Case {
    x: Vec<f32>,
    b: Vec<f32>,
    waypoints: Vec<f32>,
    speed: f32,
    ts: f32,
    pitch_limit: f32,
    gains: [f32; 6],
    h_r: f32,
    h_a: f32,
    start_altitude: f32,
    horizon: bool,
}

/// A bottom of `n` samples `ds` apart: a random walk of slopes up to 60°,
/// with cliffs, flats and spikes mixed in.
fn terrain() -> impl Strategy<Value = (Vec<f32>, Vec<f32>)> {
    (
        40_usize..120,
        4.0_f32..20.0,
        300.0_f32..1500.0,
        prop::collection::vec((0_u8..10, -1.0_f32..1.0), 120),
    )
        .prop_map(|(n, ds, depth0, steps)| {
            let mut x = Vec::with_capacity(n);
            let mut b = Vec::with_capacity(n);
            let mut d = depth0;
            for (i, &(kind, u)) in steps.iter().take(n).enumerate() {
                x.push(i as f32 * ds);
                b.push(d.max(5.0));
                let slope = match kind {
                    0 => 0.0,                               // flat
                    1 => u.signum() * 3.0,                  // cliff: ~72° over one sample
                    2 => u * 6.0,                           // spike-ish jump
                    _ => (u * 60.0_f32).to_radians().tan(), // up to 60°
                };
                d -= slope * ds;
            }
            (x, b)
        })
}

fn case() -> impl Strategy<Value = Case> {
    (
        terrain(),
        (0.2_f32..0.8, 0.2_f32..0.8),
        (0.8_f32..2.5, 0.05_f32..0.25, 12.0_f32..30.0),
        prop::array::uniform6(0.7_f32..1.3),
        (20.0_f32..100.0, 0.2_f32..0.9, 0.3_f32..3.0),
        any::<bool>(),
    )
        .prop_map(
            |((x, b), (w1, w2), (speed, ts, pitch_limit), g, (h_r, ha_frac, start), horizon)| {
                let end = *x.last().unwrap();
                let x1 = (end * w1 * 0.5).max(20.0);
                let x2 = (x1 + (end - x1) * w2).max(x1 + 20.0).min(end);
                Case {
                    waypoints: vec![0.0, x1, x2],
                    x,
                    b,
                    speed,
                    ts,
                    pitch_limit,
                    gains: g,
                    h_r,
                    h_a: h_r * ha_frac,
                    start_altitude: h_r * start,
                    horizon,
                }
            },
        )
}

fn vehicle(c: &Case) -> Option<Vehicle<3>> {
    let g = c.gains;
    let cfg = VehicleConfig {
        speed: c.speed,
        sample_time: c.ts,
        autopilot: AutopilotConfig {
            depth_pid: PidGains {
                kp: 1.5 * g[0],
                ki: 0.0,
                kd: 2.0 * g[1],
            },
            pitch_pid: PidGains {
                kp: 2.0 * g[2],
                ki: 0.1 * g[3],
                kd: 3.0 * g[4],
            },
            pitch_limit: c.pitch_limit,
            elevator_limit: 25.0 * g[5],
        },
    };
    Vehicle::new(&cfg, TransferFunction::C_AUV4).ok()
}

/// The contract in f64, independently: C-AUV #4 in controllable canonical
/// form, the ZOH by RK4 over 8 sub-steps (h |λ| < 0.04, error ~1e-8), the cascade, the kinematics;
/// returns the minimum altitude over track 0 (samples and clipped end).
fn min_altitude_f64(c: &Case, depth0: f64, z: f64) -> f64 {
    let a = [[-2.681, -0.546, -0.048], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let cc = [0.0, 0.0, -0.173];
    let ts = f64::from(c.ts);
    let deriv = |eta: &[f64; 3], u: f64| -> [f64; 3] {
        let mut d = [0.0; 3];
        for i in 0..3 {
            d[i] = a[i][0] * eta[0] + a[i][1] * eta[1] + a[i][2] * eta[2];
        }
        d[0] += u;
        d
    };
    let bottom = |x: f64| -> f64 {
        let i =
            c.x.iter()
                .position(|&xi| f64::from(xi) > x)
                .unwrap_or(c.x.len() - 1)
                .max(1);
        let (x0, x1) = (f64::from(c.x[i - 1]), f64::from(c.x[i]));
        let (b0, b1) = (f64::from(c.b[i - 1]), f64::from(c.b[i]));
        b0 + (b1 - b0) * (x - x0) / (x1 - x0)
    };
    let g = c.gains;
    let (kpd, kdd) = (1.5 * f64::from(g[0]), 2.0 * f64::from(g[1]));
    let (kpt, kit, kdt) = (
        2.0 * f64::from(g[2]),
        0.1 * f64::from(g[3]),
        3.0 * f64::from(g[4]),
    );
    let (tmax, dmax) = (f64::from(c.pitch_limit), 25.0 * f64::from(g[5]));
    let x_end = f64::from(c.waypoints[1]);
    let (mut eta, mut d, mut dp, mut x, mut it) = ([0.0_f64; 3], depth0, depth0, 0.0_f64, 0.0_f64);
    let mut min_alt = bottom(0.0) - d;
    let u0 = f64::from(c.speed);
    for _ in 0..2_000_000 {
        let th = cc[2] * eta[2];
        let q = {
            let de = deriv(&eta, 0.0);
            cc[2] * de[2]
        };
        let e_d = z - d;
        let v = -(kpd * e_d - kdd * (d - dp) / ts);
        let th_ref = v.clamp(-tmax, tmax);
        let e_t = th_ref - th;
        let w = -(kpt * e_t + kit * it - kdt * q);
        let delta = w.clamp(-dmax, dmax);
        if !((w > dmax && -e_t > 0.0) || (w < -dmax && -e_t < 0.0)) {
            it += ts * e_t;
        }
        let h = ts / 8.0;
        for _ in 0..8 {
            let k1 = deriv(&eta, delta);
            let e2: [f64; 3] = std::array::from_fn(|i| eta[i] + 0.5 * h * k1[i]);
            let k2 = deriv(&e2, delta);
            let e3: [f64; 3] = std::array::from_fn(|i| eta[i] + 0.5 * h * k2[i]);
            let k3 = deriv(&e3, delta);
            let e4: [f64; 3] = std::array::from_fn(|i| eta[i] + h * k3[i]);
            let k4 = deriv(&e4, delta);
            for i in 0..3 {
                eta[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        let th1 = cc[2] * eta[2];
        let mean = (0.5 * (th + th1)).to_radians();
        let (x1, d1) = (x + u0 * ts * mean.cos(), d - u0 * ts * mean.sin());
        if x1 >= x_end {
            let t = (x_end - x) / (x1 - x);
            min_alt = min_alt.min(bottom(x_end) - (d + (d1 - d) * t));
            if x1 == x_end {
                min_alt = min_alt.min(bottom(x1) - d1);
            }
            return min_alt;
        }
        dp = d;
        d = d1;
        x = x1;
        min_alt = min_alt.min(bottom(x) - d);
    }
    f64::NEG_INFINITY
}

#[test]
fn random_terrains_never_produce_an_unsafe_safe_plan() {
    // 10,000 in release (the README's test command); fewer unoptimized.
    let default = if cfg!(debug_assertions) { 500 } else { 10_000 };
    let cases: u32 = std::env::var("PROPTEST_CASES")
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
    // planned, reported safe, infeasible, rejected vehicles
    let stats: [std::cell::Cell<u32>; 4] = Default::default();
    let bump = |i: usize| stats[i].set(stats[i].get() + 1);
    let result = runner.run(&case(), |c| {
        let Some(v) = vehicle(&c) else {
            bump(3);
            return Ok(());
        };
        let profile = Profile::<128>::new(&c.x, &c.b).unwrap();
        let wps = Waypoints::<4>::new(&c.waypoints).unwrap();
        let mission = Mission::new(c.h_r, c.h_a, [0.0, 6000.0]).unwrap();
        let sc = Scenario::new(&v, &profile, &wps, mission).unwrap();
        let d0 = c.b[0] - c.start_altitude;
        let st = sc.start_state(d0);
        let cfg = PlannerConfig {
            mode: if c.horizon {
                Mode::Horizon
            } else {
                Mode::TrackWise
            },
            ..PlannerConfig::default()
        };
        let mut planner = Planner::<2>::new(cfg).unwrap();
        let p = match planner.plan(&sc, &st, 0) {
            Ok(p) => p,
            // A flight that diverges from the start is an error, not a plan.
            Err(_) => return Ok(()),
        };
        bump(0);
        for v in [
            p.depth,
            p.j,
            p.rms,
            p.min_altitude,
            p.objective,
            p.grad_norm,
            p.next_state.depth(),
            p.next_state.x(),
        ] {
            prop_assert!(v.is_finite(), "non-finite output {v} in {p:?}");
        }
        prop_assert!(planner.history().iter().all(|v| v.is_finite()));
        prop_assert!(p.depth >= 0.0 && p.depth <= 6000.0);
        if p.safe {
            bump(1);
            let alt = min_altitude_f64(&c, f64::from(d0), f64::from(p.depth));
            prop_assert!(
                alt >= f64::from(c.h_a) - 1e-2,
                "reported safe at {} m (f32 min altitude {}), f64 re-simulation {alt} < h_a {}",
                p.depth,
                p.min_altitude,
                c.h_a
            );
        }
        prop_assert_eq!(p.safe, p.status != PlanStatus::Infeasible);
        // Track-wise, infeasible means no safe depth for the track; in
        // horizon mode it means no safe continuation of the line, which
        // `tests/feasibility.rs` checks against a search of whole lines.
        if p.status == PlanStatus::Infeasible && !c.horizon {
            bump(2);
            // No depth on a 2 m grid of the reachable range is safe.
            let sin = (1.3 * c.pitch_limit).min(90.0).to_radians().sin();
            let reach = c.waypoints[1] * sin + 3.0 * c.pitch_limit / (1.5 * c.gains[0]) + 20.0;
            let (lo, hi) = ((d0 - reach).max(0.0), (d0 + reach).min(6000.0));
            let mut z = lo;
            while z <= hi {
                let mut s = [TrackScore::default()];
                if sc.simulate(&st, 0, &[z], &mut s, |_| {}).is_ok() {
                    prop_assert!(
                        s[0].min_altitude() < c.h_a + 0.01 + 1e-3,
                        "infeasible reported, but {z} m flies {} >= h_a {}",
                        s[0].min_altitude(),
                        c.h_a
                    );
                }
                z += 2.0;
            }
        }
        Ok(())
    });
    println!(
        "{cases} terrains: {} planned, {} reported safe (all re-simulated safe in f64), \
         {} track-wise infeasible (no safe depth on the grid), {} random vehicles rejected as unstable",
        stats[0].get(),
        stats[1].get(),
        stats[2].get(),
        stats[3].get()
    );
    result.unwrap();
}
