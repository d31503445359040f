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

use tool::{fixture, run};

/// Every interior waypoint's nearest sample of the flight, m, in each of
/// the tool's modes on fixture `knife`.
fn nearest_samples(mode: &[&str]) -> Vec<f64> {
    let (p, w, c) = fixture("knife");
    let dir = std::env::temp_dir().join(format!("auvnav-knife-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join(format!("{}.csv", mode.join("_")));
    let path = out.to_str().unwrap();
    let mut args = vec!["--profile", &p, "--waypoints", &w, "--config", &c];
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
    let wps: Vec<f64> = std::fs::read_to_string(&w)
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
