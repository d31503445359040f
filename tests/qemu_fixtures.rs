//! The golden fixtures, on the target: the f32 core on a Cortex-M4F (QEMU
//! mps2-an386) against the independent f64 reference, with exactly the
//! checks and tolerances of `tests/golden.rs` (see its header for the
//! reasons). The fixtures reach the target as consts generated from
//! `tests/fixtures/*.json` by `python3 tools/qemu/make_fixtures.py`
//! (`tests/qemu_support/fixtures.rs`).
//!
//! Shapes: plant order capacity `N = 4` (every fixture plant), profile
//! capacity `S = 384` (the longest profile has 352 samples), `W = 8`
//! waypoints.
//!
//! On the target: `cargo qemu-test` (defmt-test; one line per test, exit
//! status 1 on the first failure). On the host, `cargo test` runs this
//! file's `main`, which checks that the generated consts equal the JSON
//! fixtures and CSV profiles (a stale copy fails), then runs the same
//! checks against the library on the host.
#![cfg_attr(target_os = "none", no_std, no_main)]
// Test code: a failed check is a failed test.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing,
    clippy::arithmetic_side_effects,
    clippy::float_cmp,
    clippy::needless_range_loop
)]

#[macro_use]
mod qemu_support;
#[rustfmt::skip] // generated
#[path = "qemu_support/fixtures.rs"]
mod fixtures;

/// Vehicle, mission and initial depth from a fixture's `vehicle` dict, as
/// the host's `common::vehicle`.
fn vehicle<const N: usize>(v: &fixtures::VehicleCfg) -> (Vehicle<N>, Mission, f32) {
    let pid = |p: &fixtures::Pid| PidGains {
        kp: p.kp,
        ki: p.ki,
        kd: p.kd,
    };
    let cfg = VehicleConfig {
        speed: v.speed,
        sample_time: v.sample_time,
        autopilot: AutopilotConfig {
            depth_pid: pid(&v.depth_pid),
            pitch_pid: pid(&v.pitch_pid),
            pitch_limit: v.pitch_limit,
            elevator_limit: v.elevator_limit,
        },
    };
    let mission = ok!(
        Mission::new(v.reference_altitude, v.min_altitude, v.depth_limits),
        "fixture mission rejected"
    );
    let tf = ok!(
        TransferFunction::<N>::new(kind(v.rate), v.num, v.den),
        "fixture plant rejected"
    );
    let vehicle = ok!(Vehicle::new(&cfg, tf), "fixture vehicle rejected");
    (vehicle, mission, v.initial_depth)
}

/// The fixture's plant kind.
fn kind(rate: bool) -> TfKind {
    if rate { TfKind::Rate } else { TfKind::Pitch }
}

use auvnav::{
    AutopilotConfig, Mission, PidGains, TfKind, TransferFunction, Vehicle, VehicleConfig,
};

mod checks {
    use crate::fixtures::{EVALS, INVALID_PLANTS, PLANTS, STEPS};
    use crate::qemu_support::rel_err;
    use crate::{kind, vehicle};
    use auvnav::{Plant, Profile, Scenario, TrackScore, TransferFunction, VehicleState, Waypoints};

    /// Plant order capacity: every fixture plant (up to 4th order).
    pub const N: usize = 4;
    /// Profile capacity: the longest fixture profile has 352 samples.
    pub const S: usize = 384;
    /// Waypoint capacity: the fixtures have at most 6.
    pub const W: usize = 8;

    /// `golden.rs::zoh_matches_scipy_cont2discrete`.
    pub fn zoh_matches_scipy_cont2discrete() {
        let mut worst = 0.0_f64;
        for c in PLANTS {
            let name = c.name;
            let tf = ok!(
                TransferFunction::<N>::new(kind(c.rate), c.num, c.den),
                "{}: plant rejected",
                name
            );
            let n = c.order;
            check!(tf.order() == n, "{}: order", name);
            let p = ok!(Plant::new(tf, c.sample_time), "{}: plant", name);
            // The reference is scipy's tf2ss form, the library the
            // observability form: compare the pitch and pitch-rate impulse
            // responses C Ad^k Bd, CA Ad^k Bd (Markov parameters) over
            // 2n + 2 samples, relative to their size (as golden.rs does).
            let steps = 2 * n + 2;
            let mut got = [(0.0_f64, 0.0_f64); 2 * N + 2];
            let mut want = [(0.0_f64, 0.0_f64); 2 * N + 2];
            let mut x = [0.0_f64; N];
            let mut x_ref = [0.0_f64; N];
            for i in 0..n {
                x[i] = f64::from(p.bd()[i]);
                x_ref[i] = c.bd[i];
            }
            for k in 0..steps {
                let (mut g0, mut g1, mut w0, mut w1) = (0.0, 0.0, 0.0, 0.0);
                for i in 0..n {
                    g0 += f64::from(p.c()[i]) * x[i];
                    g1 += f64::from(p.ca()[i]) * x[i];
                    w0 += c.c[i] * x_ref[i];
                    w1 += c.ca[i] * x_ref[i];
                }
                got[k] = (g0, g1);
                want[k] = (w0, w1);
                let mut nx = [0.0_f64; N];
                let mut nx_ref = [0.0_f64; N];
                for i in 0..n {
                    for j in 0..n {
                        nx[i] += f64::from(p.ad()[i][j]) * x[j];
                        nx_ref[i] += c.ad[i * n + j] * x_ref[j];
                    }
                }
                x = nx;
                x_ref = nx_ref;
            }
            let (mut s0, mut s1) = (0.0_f64, 0.0_f64);
            for w in &want[..steps] {
                s0 = s0.max(w.0.abs());
                s1 = s1.max(w.1.abs());
            }
            for k in 0..steps {
                let e = ((got[k].0 - want[k].0).abs() / s0).max((got[k].1 - want[k].1).abs() / s1);
                worst = worst.max(e);
                check!(e <= 1e-5, "{} Markov parameter {} ({})", name, k, e);
            }
            check!(p.c()[0] == 1.0 && p.ca()[1] == 1.0, "{} C, CA", name);
            match c.dc_gain {
                Some(g) => {
                    let got = tf.dc_gain();
                    check!(
                        got.is_some_and(|d| rel_err(f64::from(d), g) < 1e-5),
                        "{}: dc gain",
                        name
                    );
                }
                None => check!(tf.dc_gain().is_none(), "{}: dc gain", name),
            }
            check!(tf.loop_sign() == c.loop_sign as f32, "{}: loop sign", name);
        }
        say!(
            "{} plants: worst Ad/Bd relative error {}",
            PLANTS.len(),
            worst
        );
    }

    /// `golden.rs::invalid_plants_are_rejected`.
    pub fn invalid_plants_are_rejected() {
        check!(!INVALID_PLANTS.is_empty(), "no invalid plants");
        for c in INVALID_PLANTS {
            let r = TransferFunction::<N>::new(kind(c.rate), c.num, c.den);
            check!(r.is_err(), "{} accepted: {}", c.name, c.reason);
        }
        say!("{} invalid plants rejected", INVALID_PLANTS.len());
    }

    /// `golden.rs::step_responses_match_sample_by_sample`.
    pub fn step_responses_match_sample_by_sample() {
        for c in STEPS {
            let name = c.name;
            let (vehicle, mission, _) = vehicle::<N>(&c.vehicle);
            let wp = ok!(Waypoints::<W>::new(c.waypoints), "{}: waypoints", name);
            let end = wp.positions()[1];
            // The bottom plays no part in the dynamics; a flat one to score over.
            let prof = ok!(
                Profile::<S>::new(&[0.0, end + 1.0], &[5000.0, 5000.0]),
                "{}: profile",
                name
            );
            let sc = ok!(
                Scenario::new(&vehicle, &prof, &wp, mission),
                "{}: scenario",
                name
            );
            let start = sc.start_state(c.initial_depth);
            let mut scores = [TrackScore::default(); 1];
            let (mut k, mut wd, mut wt) = (0_usize, 0.0_f64, 0.0_f64);
            ok!(
                sc.simulate(&start, 0, &[c.reference_depth], &mut scores, |g| {
                    check!(k < c.x.len(), "{}: more samples than the reference", name);
                    let ed = (f64::from(g.depth) - c.depth[k]).abs();
                    let et = (f64::from(g.pitch) - c.pitch[k]).abs();
                    wd = wd.max(ed);
                    wt = wt.max(et);
                    check!(
                        ed <= 1e-3,
                        "{} sample {}: depth {} vs {}",
                        name,
                        k,
                        g.depth,
                        c.depth[k]
                    );
                    check!(
                        et <= 1e-3,
                        "{} sample {}: pitch {} vs {}",
                        name,
                        k,
                        g.pitch,
                        c.pitch[k]
                    );
                    check!(
                        (f64::from(g.x) - c.x[k]).abs() <= 1e-3,
                        "{} sample {}: x",
                        name,
                        k
                    );
                    check!(
                        (f64::from(g.pitch_rate) - c.pitch_rate[k]).abs() <= 1e-3,
                        "{} sample {}: q",
                        name,
                        k
                    );
                    if let Some(cmd) = g.command {
                        check!(
                            (f64::from(cmd.elevator) - c.elevator[k]).abs() <= 1e-3,
                            "{} {}: elevator",
                            name,
                            k
                        );
                    }
                    k += 1;
                }),
                "{}: simulation failed",
                name
            );
            check!(
                k == c.x.len(),
                "{}: sample count {} vs {}",
                name,
                k,
                c.x.len()
            );
            say!(
                "{}: worst depth error {} m, pitch {} deg over {} samples",
                name,
                wd,
                wt,
                k
            );
        }
    }

    /// State at the first sample of track `n` when flying `depths` from the
    /// start, via the library itself.
    fn state_at_track(
        sc: &Scenario<'_, N>,
        start: &VehicleState<N>,
        depths: &[f32],
        n: usize,
    ) -> VehicleState<N> {
        if n == 0 {
            return *start;
        }
        let mut scores = [TrackScore::default(); W];
        ok!(
            sc.simulate(start, 0, &depths[..n], &mut scores[..n], |_| {}),
            "state at track {}",
            n
        )
    }

    /// Gradient of the total J and violation over all `K` tracks.
    fn horizon_gradient<const K: usize>(
        sc: &Scenario<'_, N>,
        start: &VehicleState<N>,
        depths: &[f32],
        gj: &mut [f32; W],
        gv: &mut [f32; W],
    ) -> f32 {
        let z: &[f32; K] = ok!(depths.try_into(), "{} depths", K);
        let e = ok!(sc.evaluate::<K>(start, 0, z), "evaluate");
        gj[..K].copy_from_slice(&e.grad_j);
        gv[..K].copy_from_slice(&e.grad_violation);
        e.j
    }

    /// Relative error, or 0 when within the absolute floor `abs`.
    fn close(got: f64, want: f64, abs: f64) -> f64 {
        if (got - want).abs() <= abs {
            0.0
        } else {
            rel_err(got, want)
        }
    }

    /// Closer than this to a waypoint, a sample is a knife edge.
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
            check!(
                e <= 1e-3,
                "{} {}[{}]: {} vs f64 central difference {} ({})",
                name,
                what,
                i,
                g,
                w,
                e
            );
        }
        worst
    }

    /// `golden.rs::line_scores_match`.
    pub fn line_scores_match() {
        let (mut wj, mut wa, mut wg) = (0.0_f64, 0.0_f64, 0.0_f64);
        let mut skipped = 0;
        for c in EVALS {
            let name = c.name;
            let (vehicle, mission, d0) = vehicle::<N>(&c.vehicle);
            let prof = ok!(
                Profile::<S>::new(c.profile.x, c.profile.b),
                "{}: profile",
                name
            );
            let wp = ok!(Waypoints::<W>::new(c.waypoints), "{}: waypoints", name);
            let sc = ok!(
                Scenario::new(&vehicle, &prof, &wp, mission),
                "{}: scenario",
                name
            );
            if c.initial_depth_default {
                check!(
                    (f64::from(sc.default_initial_depth()) - f64::from(d0)).abs() < 1e-3,
                    "{} d0",
                    name
                );
            }
            let start = sc.start_state(d0);
            let depths = c.depths;
            let m = depths.len();
            let mut scores = [TrackScore::default(); W];
            let mut n_samples = 0_usize;
            let end = ok!(
                sc.simulate(&start, 0, depths, &mut scores[..m], |_| n_samples += 1),
                "{}: simulation failed",
                name
            );
            let margins = c.switch_margins;
            // margins[i]: how close the nearest sample came to waypoint i + 1.
            let knife = |i: usize| margins[i] < KNIFE_EDGE_M;
            if !knife(m - 1) {
                check!(
                    n_samples == c.n_samples,
                    "{}: samples {} vs {}",
                    name,
                    n_samples,
                    c.n_samples
                );
                check!(
                    (f64::from(end.x()) - c.final_x).abs() < 1e-3,
                    "{}: final x",
                    name
                );
                check!(
                    (f64::from(end.depth()) - c.final_depth).abs() < 1e-3,
                    "{}: final depth",
                    name
                );
            }
            for (t, (s, r)) in scores[..m].iter().zip(c.tracks).enumerate() {
                let ej = close(f64::from(s.j()), r.j, 1e-3);
                let er = close(f64::from(s.rms()), r.rms, 1e-4);
                let ea = (f64::from(s.min_altitude()) - r.min_altitude).abs();
                wj = wj.max(ej);
                wa = wa.max(ea);
                check!(
                    ej <= 1e-4,
                    "{} track {}: J {} vs {} ({})",
                    name,
                    t,
                    s.j(),
                    r.j,
                    ej
                );
                check!(
                    er <= 1e-4,
                    "{} track {}: rms {} vs {}",
                    name,
                    t,
                    s.rms(),
                    r.rms
                );
                check!(
                    ea <= 1e-2,
                    "{} track {}: min altitude {} vs {}",
                    name,
                    t,
                    s.min_altitude(),
                    r.min_altitude
                );
                let v = r.violation;
                check!(
                    (f64::from(s.violation()) - v).abs() <= 1e-3 * v.abs().max(1.0),
                    "{} track {}: violation {} vs {}",
                    name,
                    t,
                    s.violation(),
                    v
                );
            }
            let total: f64 = scores[..m].iter().map(|s| f64::from(s.j())).sum();
            check!(rel_err(total, c.total_j) <= 1e-4, "{}: total J", name);

            let smooth = c.grad_smooth;
            let mut smooth_total = [false; W];
            let mut smooth_track = [false; W];
            for n in 0..m {
                // ∂ΣJ/∂z_n depends on every switch from waypoint n on.
                smooth_total[n] = smooth[n] && !(n..m).any(knife);
                // ∂J_n/∂z_n depends on the switch at the end of track n only.
                smooth_track[n] = smooth[n] && !knife(n);
            }
            skipped += smooth.iter().filter(|&&s| s).count()
                - smooth_total[..m].iter().filter(|&&s| s).count();
            let (mut gj, mut gv) = ([0.0_f32; W], [0.0_f32; W]);
            let j = match m {
                3 => horizon_gradient::<3>(&sc, &start, depths, &mut gj, &mut gv),
                5 => horizon_gradient::<5>(&sc, &start, depths, &mut gj, &mut gv),
                _ => {
                    check!(false, "{}: {} tracks", name, m);
                    0.0
                }
            };
            check!(
                close(f64::from(j), c.total_j, 1e-3) <= 1e-4,
                "{}: J from evaluate",
                name
            );
            wg = wg.max(check_grad(
                name,
                "grad_total_J",
                &gj[..m],
                c.grad_total_j,
                &smooth_total[..m],
            ));
            wg = wg.max(check_grad(
                name,
                "grad_total_violation",
                &gv[..m],
                c.grad_total_violation,
                &smooth_total[..m],
            ));
            // Track-wise: dJ_n/dz_n from the state in which track n starts.
            let mut got = [0.0_f32; W];
            for n in 0..m {
                let st = state_at_track(&sc, &start, depths, n);
                let e = ok!(
                    sc.evaluate::<1>(&st, n, &[depths[n]]),
                    "{}: track {}",
                    name,
                    n
                );
                check!(
                    close(f64::from(e.j), c.tracks[n].j, 1e-3) <= 1e-4,
                    "{}: track {} J alone",
                    name,
                    n
                );
                got[n] = e.grad_j[0];
            }
            wg = wg.max(check_grad(
                name,
                "grad_track_J",
                &got[..m],
                c.grad_track_j,
                &smooth_track[..m],
            ));
        }
        say!(
            "{} cases: worst J relative error {}, min altitude {} m, gradient {} ({} total-gradient entries skipped at knife edges)",
            EVALS.len(),
            wj,
            wa,
            wg,
            skipped
        );
    }
}

#[cfg(target_os = "none")]
#[defmt_test::tests]
mod tests {
    #[test]
    fn zoh_matches_scipy_cont2discrete() {
        super::checks::zoh_matches_scipy_cont2discrete();
    }

    #[test]
    fn invalid_plants_are_rejected() {
        super::checks::invalid_plants_are_rejected();
    }

    #[test]
    fn step_responses_match_sample_by_sample() {
        super::checks::step_responses_match_sample_by_sample();
    }

    #[test]
    fn line_scores_match() {
        super::checks::line_scores_match();
    }
}

/// The generated consts against the JSON fixtures and CSV profiles they
/// were generated from.
/// The host tests' fixture loaders.
#[cfg(not(target_os = "none"))]
mod common;

#[cfg(not(target_os = "none"))]
mod sync {
    use crate::common::{self, f, f64s, fixture, fs};
    use crate::fixtures::{self, EVALS, INVALID_PLANTS, PLANTS, STEPS};
    use serde_json::Value;

    const STALE: &str =
        "tests/qemu_support/fixtures.rs is stale: run python3 tools/qemu/make_fixtures.py";

    /// f64 reference values: equal up to serde_json's last-bit rounding.
    fn same64(got: &[f64], want: &[f64], what: &str) {
        assert_eq!(got.len(), want.len(), "{what}: length; {STALE}");
        for (g, w) in got.iter().zip(want) {
            assert!(
                (g - w).abs() <= 4.0 * f64::EPSILON * w.abs(),
                "{what}: {g} vs {w}; {STALE}"
            );
        }
    }

    /// f32 inputs: exactly as the host tests convert them.
    fn same32(got: &[f32], want: &[f32], what: &str) {
        assert_eq!(got.len(), want.len(), "{what}: length; {STALE}");
        for (g, w) in got.iter().zip(want) {
            assert!(
                g.to_bits() == w.to_bits() || (g.is_nan() && w.is_nan()),
                "{what}: {g} vs {w}; {STALE}"
            );
        }
    }

    fn vehicle(got: &fixtures::VehicleCfg, v: &Value, what: &str) {
        let p = &v["plant"];
        let x = |k: &str| f(&v[k]) as f32;
        let pid = |g: &fixtures::Pid, k: &str| {
            same32(
                &[g.kp, g.ki, g.kd],
                &fs(&Value::Array(vec![
                    v[k]["kp"].clone(),
                    v[k]["ki"].clone(),
                    v[k]["kd"].clone(),
                ])),
                what,
            )
        };
        same32(
            &[
                got.speed,
                got.sample_time,
                got.pitch_limit,
                got.elevator_limit,
                got.reference_altitude,
                got.min_altitude,
                got.initial_depth,
            ],
            &[
                x("speed"),
                x("sample_time"),
                x("pitch_limit"),
                x("elevator_limit"),
                x("reference_altitude"),
                x("min_altitude"),
                x("initial_depth"),
            ],
            what,
        );
        same32(&got.depth_limits, &fs(&v["depth_limits"]), what);
        pid(&got.depth_pid, "depth_pid");
        pid(&got.pitch_pid, "pitch_pid");
        assert_eq!(got.rate, p["kind"] == "rate", "{what}: kind; {STALE}");
        same32(got.num, &fs(&p["num"]), what);
        same32(got.den, &fs(&p["den"]), what);
    }

    fn nums(v: &Value) -> Vec<f32> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().map_or(f32::NAN, |x| x as f32))
            .collect()
    }

    pub fn check() {
        let fx = fixture("plants.json");
        let cases = fx["cases"].as_array().unwrap();
        assert_eq!(PLANTS.len(), cases.len(), "plants; {STALE}");
        for (g, c) in PLANTS.iter().zip(cases) {
            assert_eq!(g.name, c["name"].as_str().unwrap(), "{STALE}");
            assert_eq!(g.rate, c["kind"] == "rate", "{STALE}");
            same32(g.num, &fs(&c["num"]), g.name);
            same32(g.den, &fs(&c["den"]), g.name);
            same32(&[g.sample_time], &[f(&c["sample_time"]) as f32], g.name);
            assert_eq!(g.order as u64, c["order"].as_u64().unwrap(), "{STALE}");
            let ad: Vec<f64> = c["Ad"].as_array().unwrap().iter().flat_map(f64s).collect();
            same64(g.ad, &ad, g.name);
            same64(g.bd, &f64s(&c["Bd"]), g.name);
            same64(g.c, &f64s(&c["C"]), g.name);
            same64(g.ca, &f64s(&c["CA"]), g.name);
            same64(
                g.dc_gain.as_slice(),
                c["dc_gain"].as_f64().as_slice(),
                g.name,
            );
            same64(&[g.loop_sign], &[f(&c["pitch_loop_sign"])], g.name);
        }
        let invalid = fx["invalid"].as_array().unwrap();
        assert_eq!(
            INVALID_PLANTS.len(),
            invalid.len(),
            "invalid plants; {STALE}"
        );
        for (g, c) in INVALID_PLANTS.iter().zip(invalid) {
            assert_eq!(g.name, c["name"].as_str().unwrap(), "{STALE}");
            assert_eq!(g.rate, c["kind"] == "rate", "{STALE}");
            same32(g.num, &nums(&c["num"]), g.name);
            same32(g.den, &nums(&c["den"]), g.name);
        }

        let fx = fixture("step_response.json");
        let cases = fx.as_array().unwrap();
        assert_eq!(STEPS.len(), cases.len(), "step responses; {STALE}");
        for (g, c) in STEPS.iter().zip(cases) {
            assert_eq!(g.name, c["name"].as_str().unwrap(), "{STALE}");
            vehicle(&g.vehicle, &c["vehicle"], g.name);
            same32(
                &[g.initial_depth, g.reference_depth],
                &[
                    f(&c["initial_depth"]) as f32,
                    f(&c["reference_depth"]) as f32,
                ],
                g.name,
            );
            same32(g.waypoints, &fs(&c["waypoints"]), g.name);
            let s = &c["samples"];
            same64(g.x, &f64s(&s["x"]), g.name);
            same64(g.depth, &f64s(&s["depth"]), g.name);
            same64(g.pitch, &f64s(&s["pitch"]), g.name);
            same64(g.pitch_rate, &f64s(&s["pitch_rate"]), g.name);
            same64(g.elevator, &f64s(&s["elevator"]), g.name);
        }

        let fx = fixture("evaluations.json");
        let cases = fx["cases"].as_array().unwrap();
        assert_eq!(EVALS.len(), cases.len(), "evaluations; {STALE}");
        for (g, c) in EVALS.iter().zip(cases) {
            let name = g.name;
            assert_eq!(name, c["name"].as_str().unwrap(), "{STALE}");
            // The host tests build the profile with `common::profile`.
            let (x, b) = match &c["profile"] {
                Value::String(p) => {
                    assert_eq!(g.profile.name, p, "{STALE}");
                    common::real_profile(p)
                }
                Value::Object(o) => (fs(&o["x"]), fs(&o["b"])),
                _ => panic!("{name}: profile"),
            };
            same32(g.profile.x, &x, name);
            same32(g.profile.b, &b, name);
            same32(g.waypoints, &fs(&c["waypoints"]), name);
            vehicle(&g.vehicle, &c["vehicle"], name);
            assert_eq!(
                g.initial_depth_default,
                c["initial_depth_default"].as_bool() == Some(true),
                "{STALE}"
            );
            same32(g.depths, &fs(&c["depths"]), name);
            let tracks = c["tracks"].as_array().unwrap();
            assert_eq!(g.tracks.len(), tracks.len(), "{STALE}");
            for (t, r) in g.tracks.iter().zip(tracks) {
                same64(
                    &[t.j, t.rms, t.min_altitude, t.violation],
                    &[
                        f(&r["J"]),
                        f(&r["rms"]),
                        f(&r["min_altitude"]),
                        f(&r["violation"]),
                    ],
                    name,
                );
            }
            same64(
                &[g.total_j, g.final_x, g.final_depth],
                &[f(&c["total_J"]), f(&c["final_x"]), f(&c["final_depth"])],
                name,
            );
            assert_eq!(
                g.n_samples as u64,
                c["n_samples"].as_u64().unwrap(),
                "{STALE}"
            );
            same64(g.switch_margins, &f64s(&c["switch_margins_m"]), name);
            same64(g.grad_total_j, &f64s(&c["grad_total_J"]), name);
            same64(g.grad_track_j, &f64s(&c["grad_track_J"]), name);
            same64(
                g.grad_total_violation,
                &f64s(&c["grad_total_violation"]),
                name,
            );
            let smooth: Vec<bool> = c["grad_smooth"]
                .as_array()
                .unwrap()
                .iter()
                .map(|b| b.as_bool().unwrap())
                .collect();
            assert_eq!(g.grad_smooth, smooth.as_slice(), "{STALE}");
        }
        println!(
            "qemu fixtures in sync with tests/fixtures: {} plants, {} invalid, {} step responses, {} evaluations",
            PLANTS.len(),
            INVALID_PLANTS.len(),
            STEPS.len(),
            EVALS.len()
        );
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    sync::check();
    // The same checks as on the target, on the host (golden.rs runs them
    // with the host's own shapes; this runs the on-target code itself).
    checks::zoh_matches_scipy_cont2discrete();
    checks::invalid_plants_are_rejected();
    checks::step_responses_match_sample_by_sample();
    checks::line_scores_match();
}
