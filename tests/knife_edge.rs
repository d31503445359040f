//! A committed depth kept off a waypoint's knife edge (`src/plan/knife.rs`).
//!
//! On a random canyon line (`tools/reference/check_planner.py --seed 1602`,
//! `unseen_1602_2`, fixture `knife`), track-wise and unconstrained, the
//! committed depth of track 3 put its last sample 0.1 mm short of
//! waypoint 3 (1 968.6 m) after 13 574 steps; the f64 re-simulation of the
//! same depths was one step past it, switched to track 4's reference one
//! sample earlier, and track 4's `J` differed by 2.2e-3 relative (the
//! checker allows 1e-3). The f32 and f64 flights of the same depths put a
//! waypoint's nearest sample 0.8 mm apart at most over 888 crossings of
//! 256 random lines: a sample 2 mm off a waypoint switches there in
//! either arithmetic.
#![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::panic)]
#![allow(clippy::arithmetic_side_effects, clippy::float_cmp)]

mod tool;

use std::path::Path;

use tool::{fixture, json_of, json_of_fixture, run};

/// Every interior waypoint's nearest sample of the flight, m, in each of
/// the tool's modes on fixture `knife`.
fn nearest_samples(mode: &[&str]) -> Vec<f64> {
    let (p, w, c) = fixture("knife");
    nearest_samples_of((&p, &w, &c), mode)
}

/// Every interior waypoint's nearest sample of the flight, m, planned on
/// `(profile, waypoints, config)` with the options `mode`.
fn nearest_samples_of((p, w, c): (&str, &str, &str), mode: &[&str]) -> Vec<f64> {
    let dir = std::env::temp_dir().join(format!("auvnav-knife-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let name = Path::new(c).file_stem().unwrap().to_str().unwrap();
    let out = dir.join(format!("{name}_{}.csv", mode.join("_")));
    let path = out.to_str().unwrap();
    let mut args = vec!["--profile", p, "--waypoints", w, "--config", c];
    args.extend(mode);
    args.extend(["--trajectory", path]);
    let o = run(&args);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let xs: Vec<f64> = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    let wps: Vec<f64> = std::fs::read_to_string(w)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    wps[1..wps.len() - 1]
        .iter()
        .map(|&x| {
            xs.iter()
                .map(|s| (s - x).abs())
                .fold(f64::INFINITY, f64::min)
        })
        .collect()
}

#[test]
fn no_committed_track_ends_on_its_waypoints_knife_edge() {
    // (The trajectory's positions are f32 printed: 0.1 mm allowed.)
    for mode in [
        &["--mode", "track", "--unconstrained"][..],
        &["--mode", "track"][..],
        &[][..],
    ] {
        let near = nearest_samples(mode);
        assert_eq!(near.len(), 3);
        for (i, d) in near.iter().enumerate() {
            assert!(
                *d >= 1.9e-3,
                "{mode:?}: waypoint {}: a sample {d} m from it",
                i + 1
            );
        }
    }
}

/// Under declared motion, a kept continuation whose first track ends
/// within a millimetre of its waypoint is left for the candidate where
/// that certifies (`src/plan/knife.rs`). On `check_certified.py --seed
/// 2537 --bounds-kind motion` (Monterey 1, horizon, `ε_U` 0.00506,
/// fixture `edge_motion.toml`) call 2 kept a continuation whose sample lay
/// 0.1 mm past waypoint 2, 7.6 µm short of it in the f64 re-flight: the
/// next tracks' reported altitudes were 7 cm off the f64 flight's.
#[test]
fn under_declared_motion_a_kept_continuation_leaves_the_inner_edge() {
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/data/bathymetry/");
    let p = format!("{data}us_monterey_canyon_1.csv");
    let w = format!("{data}us_monterey_canyon_1.waypoints.csv");
    let (_, _, c) = fixture("edge_motion");
    let near = nearest_samples_of((&p, &w, &c), &[]);
    assert_eq!(near.len(), 4);
    // (The trajectory's positions are f32 printed: 0.1 mm allowed.)
    for (i, d) in near.iter().enumerate() {
        assert!(*d >= 0.9e-3, "waypoint {}: a sample {d} m from it", i + 1);
    }
}

/// A waypoints file like `w`'s with waypoint `i` moved by `dx` (m), in
/// `dir`: its path.
fn moved_waypoint(w: &str, (i, dx): (usize, f64), dir: &std::path::Path) -> String {
    let text = std::fs::read_to_string(w).unwrap();
    let mut out = String::from("wp,x_m\n");
    for (k, line) in text.lines().skip(1).enumerate() {
        let x: f64 = line.split(',').nth(1).unwrap().parse().unwrap();
        let x = if k == i { x + dx } else { x };
        out.push_str(&format!("{k},{x}\n"));
    }
    let path = dir.join(format!(
        "wp_{i}_{}.csv",
        if dx > 0.0 { "later" } else { "earlier" }
    ));
    std::fs::write(&path, out).unwrap();
    path.to_str().unwrap().to_owned()
}

/// Whichever way a knife edge's switch falls, the line is as safe as
/// reported (`src/sim/switch.rs`, `src/plan/certify/mod.rs`). On a random
/// canyon line with a slow vehicle (`check_planner.py --seed 2585
/// --vehicle tools/reference/vehicles/slow.toml`, `unseen_2585_5`, fixture
/// `switch_later`), the horizon plan's track 2 ended 1.28 mm past
/// waypoint 2 in f32 and 0.08 mm short of it in the checker's f64
/// re-simulation, which switched one sample later: the plan was reported
/// safe (track 3 at 60.09 m) and the f64 flight went to 59.974 m, below
/// `h_a` = 60 m. Every interior waypoint is moved 1.9 mm each way (a
/// sample within that of it then switches the other way; the planner
/// branches within 2 mm) and the committed depths are flown again
/// (`--depths`): the whole flight stays at or above `h_a` wherever the
/// plan said it was safe. The `knife` fixture's line too.
#[test]
fn a_safe_plan_stays_safe_whichever_way_a_knife_edge_switches() {
    let dir = std::env::temp_dir().join(format!("auvnav-switch-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for name in ["switch_later", "knife"] {
        let plan = json_of_fixture(name, &[]);
        let h_a = plan["min_altitude_limit"].as_f64().unwrap();
        assert_eq!(plan["safe"], true, "{name}: {plan}");
        let depths: Vec<String> = plan["tracks"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t["depth"].as_f64().unwrap().to_string())
            .collect();
        let depths = depths.join(",");
        let (p, w, c) = fixture(name);
        let n = std::fs::read_to_string(&w).unwrap().lines().count() - 1;
        for i in 1..n - 1 {
            for dx in [-1.9e-3, 1.9e-3] {
                let moved = moved_waypoint(&w, (i, dx), &dir);
                let mut args = vec!["--profile", &p, "--waypoints", &moved];
                if std::path::Path::new(&c).exists() {
                    args.extend(["--config", &c]);
                }
                args.extend(["--depths", &depths, "--json"]);
                let flown = json_of(&args)["min_altitude"].as_f64().unwrap();
                assert!(
                    flown >= h_a,
                    "{name}: waypoint {i} moved {dx} m: least altitude {flown} m < h_a {h_a} m"
                );
            }
        }
    }
}
