//! The f32 core against the independent f64 reference
//! (`tools/reference/`, scipy's `cont2discrete` for the ZOH and its own
//! simulation loop). Fixtures: `tests/fixtures/*.json`.
//!
//! Tolerances, and why:
//! - `Ad`, `Bd`: 1e-5 relative per entry. f32 carries 6e-8 relative per
//!   operation; the expm1 form keeps the small entries (1e-4 of the
//!   diagonal) from being swamped by the identity, so 1e-5 holds entrywise
//!   with room for the Taylor/squaring error.
//! - Step response: 1e-3 m in depth and 1e-3 deg in pitch at every sample
//!   over 600 m. Depth and position are integrated compensated, so the f32
//!   flight does not drift from the f64 one over 4000 steps.
//! - `J`: 1e-4 relative per track and in total; `rms` the same; minimum
//!   altitude 1e-2 m (the contract's figure for f32 vs f64 altitudes). A
//!   track flown almost exactly on target has `J` near zero, where relative
//!   error means nothing: there `J` may differ by 1e-3 m³ and `rms` by
//!   1e-4 m (an rms of 2 mm over 500 m).
//! - Gradients: 1e-3 relative to the f64 central difference, on the entries
//!   the reference marks smooth (where `h = 1e-3` and `h = 1e-4` central
//!   differences agree, i.e. no waypoint switch or clamp edge was crossed).
//!   Entries smaller than 1e-4 of the largest in the same case are held to
//!   1e-3 of that largest one instead: they are the differences of large
//!   terms, where f32 cannot give 3 relative digits.
//! - Knife edges: where a plan flies exactly level (`z = d0`), samples land
//!   on waypoints to within 1e-10 m (`switch_margins_m` in the fixture). The
//!   discrete simulation is not differentiable there: any change of `z`
//!   pitches the vehicle, it lags, and the switch moves one sample (worth
//!   about 1/2000 of the gradient), so both-sided differences see a branch
//!   the unperturbed run is not on. Gradient entries that depend on such a
//!   waypoint (those of tracks at or before it), and the sample count and
//!   final state when the knife edge is the line's end, are not compared.

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
    clippy::needless_range_loop
)]

mod common;

use auvnav::{Plant, Scenario, TrackScore, TransferFunction, VehicleState, Waypoints};
use common::*;
use serde_json::Value;

#[test]
fn zoh_matches_scipy_cont2discrete() {
    let fx = fixture("plants.json");
    let mut worst = 0.0_f64;
    for c in fx["cases"].as_array().unwrap() {
        let name = c["name"].as_str().unwrap();
        let tf = TransferFunction::<N>::new(kind(&c["kind"]), &fs(&c["num"]), &fs(&c["den"]))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let n = c["order"].as_u64().unwrap() as usize;
        assert_eq!(tf.order(), n, "{name}");
        let p = Plant::new(tf, f(&c["sample_time"]) as f32).unwrap();
        // The reference is in scipy's tf2ss (controllable) form, the library
        // in the observability form: compare what every realization of the
        // same discrete plant shares, its pitch and pitch-rate impulse
        // responses (Markov parameters) C Ad^k Bd and CA Ad^k Bd, over
        // 2n + 2 samples (2n determine the plant), relative to their size.
        let ad_ref: Vec<Vec<f64>> = c["Ad"].as_array().unwrap().iter().map(f64s).collect();
        let bd_ref = f64s(&c["Bd"]);
        let cc = f64s(&c["C"]);
        let ca = f64s(&c["CA"]);
        let mut x_ref = bd_ref.clone();
        let mut x: Vec<f64> = (0..n).map(|i| f64::from(p.bd()[i])).collect();
        let (mut got, mut want) = (Vec::new(), Vec::new());
        for _ in 0..2 * n + 2 {
            let dot = |r: &[f64], v: &[f64]| r.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
            let c_lib: Vec<f64> = (0..n).map(|i| f64::from(p.c()[i])).collect();
            let ca_lib: Vec<f64> = (0..n).map(|i| f64::from(p.ca()[i])).collect();
            got.push((dot(&c_lib, &x), dot(&ca_lib, &x)));
            want.push((dot(&cc, &x_ref), dot(&ca, &x_ref)));
            x_ref = (0..n).map(|i| dot(&ad_ref[i], &x_ref)).collect();
            x = (0..n)
                .map(|i| (0..n).map(|j| f64::from(p.ad()[i][j]) * x[j]).sum())
                .collect();
        }
        let scale =
            |f: fn(&(f64, f64)) -> f64| want.iter().map(f).fold(0.0_f64, |m, v| m.max(v.abs()));
        let (s_pitch, s_rate) = (scale(|v| v.0), scale(|v| v.1));
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            let e = ((g.0 - w.0).abs() / s_pitch).max((g.1 - w.1).abs() / s_rate);
            worst = worst.max(e);
            assert!(
                e <= 1e-5,
                "{name} Markov parameter {k}: {g:?} vs {w:?} ({e:e})"
            );
        }
        // θ = η1 and q = η2 exactly.
        assert_eq!(p.c()[0], 1.0, "{name} C");
        assert_eq!(p.ca()[1], 1.0, "{name} CA");
        match c["dc_gain"].as_f64() {
            Some(g) => assert!(
                rel_err(f64::from(tf.dc_gain().unwrap()), g) < 1e-5,
                "{name}"
            ),
            None => assert_eq!(tf.dc_gain(), None, "{name}"),
        }
        assert_eq!(tf.loop_sign(), f(&c["pitch_loop_sign"]) as f32, "{name}");
    }
    println!("worst Markov parameter (C Ad^k Bd, CA Ad^k Bd) relative error {worst:e}");
}

#[test]
fn invalid_plants_are_rejected() {
    let fx = fixture("plants.json");
    let invalid = fx["invalid"].as_array().unwrap();
    assert!(!invalid.is_empty());
    for c in invalid {
        let nums = |v: &Value| -> Vec<f32> {
            v.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().map_or(f32::NAN, |x| x as f32))
                .collect()
        };
        let r = TransferFunction::<N>::new(kind(&c["kind"]), &nums(&c["num"]), &nums(&c["den"]));
        assert!(r.is_err(), "{} accepted: {}", c["name"], c["reason"]);
    }
}

#[test]
fn step_responses_match_sample_by_sample() {
    let fx = fixture("step_response.json");
    for c in fx.as_array().unwrap() {
        let name = c["name"].as_str().unwrap();
        let (vehicle, mission, _) = vehicle(&c["vehicle"]);
        let wp = Waypoints::<W>::new(&fs(&c["waypoints"])).unwrap();
        let end = wp.positions()[1];
        // The bottom plays no part in the dynamics; a flat one to score over.
        let prof = auvnav::Profile::<S>::new(&[0.0, end + 1.0], &[5000.0, 5000.0]).unwrap();
        let sc = Scenario::new(&vehicle, &prof, &wp, mission).unwrap();
        let start = sc.start_state(f(&c["initial_depth"]) as f32);
        let mut got = Vec::new();
        let mut scores = [TrackScore::default(); 1];
        sc.simulate(
            &start,
            0,
            &[f(&c["reference_depth"]) as f32],
            &mut scores,
            |s| got.push(*s),
        )
        .unwrap();
        let s = &c["samples"];
        let (x, d, th, q) = (
            f64s(&s["x"]),
            f64s(&s["depth"]),
            f64s(&s["pitch"]),
            f64s(&s["pitch_rate"]),
        );
        let el = f64s(&s["elevator"]);
        assert_eq!(got.len(), x.len(), "{name}: sample count");
        let (mut wd, mut wt) = (0.0_f64, 0.0_f64);
        for (k, g) in got.iter().enumerate() {
            let ed = (f64::from(g.depth) - d[k]).abs();
            let et = (f64::from(g.pitch) - th[k]).abs();
            wd = wd.max(ed);
            wt = wt.max(et);
            assert!(
                ed <= 1e-3,
                "{name} sample {k}: depth {} vs {}",
                g.depth,
                d[k]
            );
            assert!(
                et <= 1e-3,
                "{name} sample {k}: pitch {} vs {}",
                g.pitch,
                th[k]
            );
            assert!(
                (f64::from(g.x) - x[k]).abs() <= 1e-3,
                "{name} sample {k}: x"
            );
            assert!(
                (f64::from(g.pitch_rate) - q[k]).abs() <= 1e-3,
                "{name} sample {k}: q"
            );
            if let Some(cmd) = g.command {
                assert!(
                    (f64::from(cmd.elevator) - el[k]).abs() <= 1e-3,
                    "{name} {k}: elevator"
                );
            }
        }
        println!(
            "{name}: worst depth error {wd:.2e} m, pitch {wt:.2e} deg over {} samples",
            got.len()
        );
    }
}

/// State at the first sample of track `n` when flying `depths` from the
/// start, via the library itself (the tracks before `n` are golden-checked
/// by `line_scores_match`).
fn state_at_track(
    sc: &Scenario<'_, N>,
    start: &VehicleState<N>,
    depths: &[f32],
    n: usize,
) -> VehicleState<N> {
    if n == 0 {
        return *start;
    }
    let mut scores = vec![TrackScore::default(); n];
    sc.simulate(start, 0, &depths[..n], &mut scores, |_| {})
        .unwrap()
}

/// Gradient of the total J and violation over all `K` tracks.
fn horizon_gradient<const K: usize>(
    sc: &Scenario<'_, N>,
    start: &VehicleState<N>,
    depths: &[f32],
) -> (Vec<f32>, Vec<f32>, f32) {
    let z: [f32; K] = depths.try_into().unwrap();
    let e = sc.evaluate::<K>(start, 0, &z).unwrap();
    (e.grad_j.to_vec(), e.grad_violation.to_vec(), e.j)
}

/// Relative error, or 0 when within the absolute floor `abs`.
fn close(got: f64, want: f64, abs: f64) -> f64 {
    if (got - want).abs() <= abs {
        0.0
    } else {
        rel_err(got, want)
    }
}

/// Closer than this to a waypoint, a sample is a knife edge (see above).
const KNIFE_EDGE_M: f64 = 1e-6;

fn check_grad(name: &str, what: &str, got: &[f32], want: &[f64], smooth: &[bool]) -> f64 {
    let scale = want.iter().fold(0.0_f64, |m, g| m.max(g.abs()));
    let mut worst = 0.0_f64;
    for (i, (&g, &w)) in got.iter().zip(want).enumerate() {
        if !smooth[i] {
            continue;
        }
        let denom = w.abs().max(1e-4 * scale).max(1e-9);
        let e = (f64::from(g) - w).abs() / denom;
        worst = worst.max(e);
        assert!(
            e <= 1e-3,
            "{name} {what}[{i}]: {g} vs f64 central difference {w} ({e:.2e})"
        );
    }
    worst
}

#[test]
fn line_scores_match() {
    let fx = fixture("evaluations.json");
    let (mut wj, mut wa, mut wg) = (0.0_f64, 0.0_f64, 0.0_f64);
    let mut skipped = 0;
    let cases = fx["cases"].as_array().unwrap();
    for c in cases {
        let name = c["name"].as_str().unwrap();
        let (vehicle, mission, d0) = vehicle(&c["vehicle"]);
        let prof = profile(&c["profile"]);
        let wp = Waypoints::<W>::new(&fs(&c["waypoints"])).unwrap();
        let sc = Scenario::new(&vehicle, &prof, &wp, mission).unwrap();
        if c["initial_depth_default"].as_bool() == Some(true) {
            assert!(
                (f64::from(sc.default_initial_depth()) - f64::from(d0)).abs() < 1e-3,
                "{name} d0"
            );
        }
        let start = sc.start_state(d0);
        let depths = fs(&c["depths"]);
        let m = depths.len();
        let mut scores = vec![TrackScore::default(); m];
        let mut n_samples = 0;
        let end = sc
            .simulate(&start, 0, &depths, &mut scores, |_| n_samples += 1)
            .unwrap();
        let margins = f64s(&c["switch_margins_m"]);
        // margins[i]: how close the nearest sample came to waypoint i + 1.
        let knife = |i: usize| margins[i] < KNIFE_EDGE_M;
        if !knife(m - 1) {
            assert_eq!(
                n_samples,
                c["n_samples"].as_u64().unwrap() as usize,
                "{name}: samples"
            );
            assert!(
                (f64::from(end.x()) - f(&c["final_x"])).abs() < 1e-3,
                "{name}: final x"
            );
            assert!(
                (f64::from(end.depth()) - f(&c["final_depth"])).abs() < 1e-3,
                "{name}: final depth"
            );
        }
        for (t, (s, r)) in scores
            .iter()
            .zip(c["tracks"].as_array().unwrap())
            .enumerate()
        {
            let ej = close(f64::from(s.j()), f(&r["J"]), 1e-3);
            let er = close(f64::from(s.rms()), f(&r["rms"]), 1e-4);
            let ea = (f64::from(s.min_altitude()) - f(&r["min_altitude"])).abs();
            wj = wj.max(ej);
            wa = wa.max(ea);
            assert!(
                ej <= 1e-4,
                "{name} track {t}: J {} vs {} ({ej:.2e})",
                s.j(),
                f(&r["J"])
            );
            assert!(
                er <= 1e-4,
                "{name} track {t}: rms {} vs {}",
                s.rms(),
                f(&r["rms"])
            );
            assert!(
                ea <= 1e-2,
                "{name} track {t}: min altitude {} vs {}",
                s.min_altitude(),
                f(&r["min_altitude"])
            );
            let v = f(&r["violation"]);
            assert!(
                (f64::from(s.violation()) - v).abs() <= 1e-3 * v.abs().max(1.0),
                "{name} track {t}: violation {} vs {v}",
                s.violation()
            );
        }
        let total: f64 = scores.iter().map(|s| f64::from(s.j())).sum();
        assert!(rel_err(total, f(&c["total_J"])) <= 1e-4, "{name}: total J");

        let smooth: Vec<bool> = c["grad_smooth"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b.as_bool().unwrap())
            .collect();
        // ∂ΣJ/∂z_n depends on every switch from waypoint n on.
        let smooth_total: Vec<bool> = (0..m).map(|n| smooth[n] && !(n..m).any(knife)).collect();
        // ∂J_n/∂z_n depends on the switch at the end of track n only.
        let smooth_track: Vec<bool> = (0..m).map(|n| smooth[n] && !knife(n)).collect();
        skipped +=
            smooth.iter().filter(|&&s| s).count() - smooth_total.iter().filter(|&&s| s).count();
        let (gj, gv, j) = match m {
            3 => horizon_gradient::<3>(&sc, &start, &depths),
            5 => horizon_gradient::<5>(&sc, &start, &depths),
            _ => panic!("{name}: {m} tracks"),
        };
        assert!(
            close(f64::from(j), f(&c["total_J"]), 1e-3) <= 1e-4,
            "{name}: J from evaluate"
        );
        wg = wg.max(check_grad(
            name,
            "grad_total_J",
            &gj,
            &f64s(&c["grad_total_J"]),
            &smooth_total,
        ));
        wg = wg.max(check_grad(
            name,
            "grad_total_violation",
            &gv,
            &f64s(&c["grad_total_violation"]),
            &smooth_total,
        ));
        // Track-wise: dJ_n/dz_n from the state in which track n starts.
        let want = f64s(&c["grad_track_J"]);
        let mut got = Vec::new();
        for n in 0..m {
            let st = state_at_track(&sc, &start, &depths, n);
            let e = sc.evaluate::<1>(&st, n, &[depths[n]]).unwrap();
            assert!(
                close(f64::from(e.j), f(&c["tracks"][n]["J"]), 1e-3) <= 1e-4,
                "{name}: track {n} J alone"
            );
            got.push(e.grad_j[0]);
        }
        wg = wg.max(check_grad(name, "grad_track_J", &got, &want, &smooth_track));
    }
    println!(
        "{} cases: worst J relative error {wj:.2e}, min altitude {wa:.2e} m, gradient {wg:.2e} \
         ({skipped} total-gradient entries skipped at knife edges)",
        cases.len()
    );
}
