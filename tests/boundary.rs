//! The boundary searches on a flat safe side (`src/optim/root.rs`): a
//! track's least altitude set at its start, where the previous track's
//! boundary left it a few centimetres above `h_a + m_s`, is the same over
//! a wide range of the track's depth, inside the search's tolerance. A
//! search given a safe end there used to stop on it, and a committed
//! depth's continuation search to stop on its anchor; the boundary lies
//! where that range ends. Bounds from the independent f64 searches.
#![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::panic)]
#![allow(clippy::arithmetic_side_effects, clippy::float_cmp)]

mod tool;

use tool::{fixture, json_of, tracks_of};

/// Track-wise with a slower vehicle (`check_planner.py --seed 53
/// --vehicle`, `unseen_53_7`: 1 m/s, `Ts` 0.2 s, 30° limits, another
/// plant): track 3's least altitude is 60.021 m at its start for every
/// depth up to 909.1 m. Its constrained solve answered 866.87 m, `J`
/// 3.718e5 m³, 1.74× the f64 brute force's best safe 2.14106e5 m³
/// (909.161 m).
#[test]
fn a_flat_track_start_is_no_boundary() {
    let (p, w, c) = fixture("flat_start");
    let args = ["--profile", &p, "--waypoints", &w, "--config", &c];
    let v = json_of(&[&args[..], &["--mode", "track", "--json"]].concat());
    let tracks = v["tracks"].as_array().unwrap();
    let head = [1034.1005, 1037.8691];
    for (t, z) in tracks.iter().zip(head) {
        let d = t["depth"].as_f64().unwrap();
        assert!((d - z).abs() < 0.01, "depth {d} against the premise {z}");
    }
    let t3 = &tracks[2];
    let j3 = t3["J"].as_f64().unwrap();
    assert_eq!(t3["safe"], true, "{t3}");
    assert!(j3 <= 1.005 * 2.141_06e5, "track 3: J {j3} vs the best safe");
}

/// The same flat side above the tolerance, its corner 1.7 m from the
/// unsafe end of a 206 m bracket (`check_planner.py --seed 81` with h_r/h_a
/// 30/20, `unseen_81_4`): track 2's constrained solve answered 810.38 m,
/// `J` 2.2816e7 m³, 4.7× the f64 brute force's best safe 4.80787e6 m³
/// (1 014.85 m).
#[test]
fn a_corner_near_the_unsafe_end_is_reached() {
    let tracks = tracks_of("far_corner", &["--mode", "track"], &[(0, 1016.556)]);
    let t2 = &tracks[1];
    let j2 = t2["J"].as_f64().unwrap();
    assert_eq!(t2["safe"], true, "{t2}");
    assert!(j2 <= 1.005 * 4.807_87e6, "track 2: J {j2} vs the best safe");
}

/// The same flat side, its unsafe side sloped at 0.08 m of altitude a
/// metre of depth (`check_planner.py --seed 2101`, `unseen_2101_3`,
/// default vehicle): unit steps from the unsafe end, which assume a slope
/// of 1, crawled a quarter of a metre each and the search ran out of
/// steps at a safe end 61 m short. Track 4 answered 437.71 m, `J`
/// 3.83215e7 m³, 1.476× the f64 best safe 2.59700e7 m³ (498.641 m, from
/// the state the tool's tracks 1 to 3 leave). Now the secant of two
/// unsafe evaluations.
#[test]
fn a_shallow_unsafe_slope_is_crossed_by_its_secant() {
    let premise = [(0, 397.033), (1, 669.723), (2, 491.758)];
    let tracks = tracks_of("flat_boundary", &["--mode", "track"], &premise);
    let t4 = &tracks[3];
    let j4 = t4["J"].as_f64().unwrap();
    assert_eq!(t4["safe"], true, "{t4}");
    assert!(j4 <= 1.005 * 2.597_00e7, "track 4: J {j4} vs the best safe");
}

/// The safe mode with a one-track horizon (its continuation certified to
/// the line's end) on the shared profiles, against the best safe `J` of
/// the f64 exhaustive search (`scripts/j_gap.py`, BENCHMARKS.md "J
/// against the exhaustive search"). Before: 1.28×, 1.34×, 1.23×, 2.13×
/// (each committed depth held at a flat least altitude's first safe
/// depth, or at the anchor of its continuation search).
#[test]
fn a_one_track_horizon_reaches_the_best_safe_plan() {
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/data/bathymetry");
    let cases = [
        ("us_monterey_canyon_1", "80", "60", 1.140_489e7),
        ("es_medes_islands_1", "5", "3", 1.937_978e5),
        ("es_medes_islands_2", "5", "3", 1.610_515e5),
        ("jp_aburatsubo_sagami_1", "2", "1", 2.548_083e4),
    ];
    let dir = std::env::temp_dir().join(format!("auvnav-boundary-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, h_r, h_a, best) in cases {
        let cfg = dir.join(format!("{name}.toml"));
        std::fs::write(
            &cfg,
            format!("reference_altitude = {h_r}\nmin_altitude = {h_a}\n"),
        )
        .unwrap();
        let (p, w) = (
            format!("{data}/{name}.csv"),
            format!("{data}/{name}.waypoints.csv"),
        );
        let cfg = cfg.to_str().unwrap();
        let v = json_of(&[
            "--profile",
            &p,
            "--waypoints",
            &w,
            "--config",
            cfg,
            "--horizon",
            "1",
            "--json",
        ]);
        let total = v["total_J"].as_f64().unwrap();
        assert_eq!(v["safe"], true, "{name}");
        assert!(
            total <= 1.01 * best,
            "{name}: J {total} vs the best safe {best}"
        );
    }
}
