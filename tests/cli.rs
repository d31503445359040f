//! The `plan` tool's interface (spec/cli.md): every bad input is one line
//! on stderr and exit status 2, never a panic; good input gives the JSON
//! object and trajectory CSV the spec fixes.
//!
//! `cargo test` builds the examples before it runs the tests, so the tool
//! is found beside this test binary. (A filtered `cargo test --test cli`
//! does not rebuild it: run `cargo build --example plan` first.)

// Test code: a failed unwrap or index is a failed test.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]
#![allow(clippy::arithmetic_side_effects, clippy::float_cmp)]

mod tool;

use tool::{fixture, horizon_within, json_of, run, tool};

use std::path::{Path, PathBuf};
use std::process::Command;

fn tmp(name: &str, text: &str) -> PathBuf {
    static COUNT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!("auvnav-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    // Written aside and renamed: tests running in parallel may write the
    // same file, and a reader must never see it half written.
    let n = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let part = dir.join(format!("{name}.{n}.part"));
    std::fs::write(&part, text).unwrap();
    std::fs::rename(&part, &p).unwrap();
    p
}

const PROFILE: &str = "x_m,bottom_depth_m\n0,100\n100,110\n200,90\n300,100\n";
const WAYPOINTS: &str = "wp,x_m\n0,0\n1,150\n2,300\n";

/// Runs the tool and checks the one-line, exit-2 contract; returns stderr.
fn bad(args: &[&str], must_mention: &str) -> String {
    let out = run(args);
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(2), "args {args:?}: stderr {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err:?}");
    assert!(
        err.to_lowercase().contains(&must_mention.to_lowercase()),
        "{args:?}: {err:?} should mention {must_mention:?}"
    );
    assert!(out.stdout.is_empty());
    err
}

fn with(profile: &str, waypoints: &str, extra: &[&str]) -> Vec<String> {
    let p = tmp(&format!("p{}.csv", fxhash(profile)), profile);
    let w = tmp(&format!("w{}.csv", fxhash(waypoints)), waypoints);
    let mut v = vec![
        "--profile".to_string(),
        p.display().to_string(),
        "--waypoints".into(),
        w.display().to_string(),
    ];
    v.extend(extra.iter().map(|s| s.to_string()));
    v
}

fn fxhash(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
    })
}

fn refs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

#[test]
fn missing_and_unreadable_files() {
    bad(
        &[
            "--profile",
            "/nonexistent/p.csv",
            "--waypoints",
            "/nonexistent/w.csv",
        ],
        "/nonexistent/p.csv",
    );
    let dir = std::env::temp_dir();
    let d = dir.display().to_string();
    bad(&["--profile", &d, "--waypoints", &d], "cannot read");
    let a = with(
        PROFILE,
        WAYPOINTS,
        &["--config", "/nonexistent/v.toml", "--depths", "20,20"],
    );
    bad(&refs(&a), "v.toml");
}

#[test]
fn malformed_csv() {
    let a = with(
        "x_m,bottom_depth_m\n0,100\n100\n",
        WAYPOINTS,
        &["--depths", "20,20"],
    );
    bad(&refs(&a), ":3: expected 2 fields");
    let a = with(
        "x,depth\n0,100\n100,100\n",
        WAYPOINTS,
        &["--depths", "20,20"],
    );
    bad(&refs(&a), "x_m");
    let a = with(
        "x_m,bottom_depth_m\n0,100\n100,abc\n",
        WAYPOINTS,
        &["--depths", "20,20"],
    );
    bad(&refs(&a), "not a number");
    let a = with(PROFILE, "wp\n0\n1\n", &["--depths", "20,20"]);
    bad(&refs(&a), "x_m");
    let a = with("", WAYPOINTS, &["--depths", "20,20"]);
    bad(&refs(&a), "empty");
    let a = with(
        "x_m,bottom_depth_m\n0,100\n",
        WAYPOINTS,
        &["--depths", "20,20"],
    );
    bad(&refs(&a), "at least 2");
}

#[test]
fn non_finite_numbers() {
    for v in ["nan", "inf", "-inf", "NaN"] {
        let p = format!("x_m,bottom_depth_m\n0,100\n100,{v}\n300,100\n");
        let a = with(&p, WAYPOINTS, &["--depths", "20,20"]);
        bad(&refs(&a), "not finite");
    }
    let a = with(PROFILE, "wp,x_m\n0,0\n1,nan\n", &["--depths", "20"]);
    bad(&refs(&a), "not finite");
    let a = with(PROFILE, WAYPOINTS, &["--depths", "20,inf"]);
    bad(&refs(&a), "not finite");
    let c = tmp("nan.toml", "speed = nan\n");
    let a = with(
        PROFILE,
        WAYPOINTS,
        &["--config", c.to_str().unwrap(), "--depths", "20,20"],
    );
    bad(&refs(&a), "speed");
}

#[test]
fn non_increasing_x() {
    let a = with(
        "x_m,bottom_depth_m\n0,100\n100,100\n100,90\n",
        WAYPOINTS,
        &["--depths", "20,20"],
    );
    bad(&refs(&a), "does not increase");
    let a = with(
        "x_m,bottom_depth_m\n0,100\n200,100\n100,90\n",
        WAYPOINTS,
        &["--depths", "20,20"],
    );
    bad(&refs(&a), "does not increase");
    let a = with(
        PROFILE,
        "wp,x_m\n0,0\n1,200\n2,150\n",
        &["--depths", "20,20"],
    );
    bad(&refs(&a), "does not increase");
}

#[test]
fn waypoint_outside_profile() {
    let a = with(
        PROFILE,
        "wp,x_m\n0,0\n1,150\n2,301\n",
        &["--depths", "20,20"],
    );
    bad(&refs(&a), "outside the bottom profile");
    let a = with(PROFILE, "wp,x_m\n0,-5\n1,150\n", &["--depths", "20"]);
    bad(&refs(&a), "waypoint 0");
}

#[test]
fn wrong_number_of_depths() {
    let a = with(PROFILE, WAYPOINTS, &["--depths", "20"]);
    bad(&refs(&a), "1 depths for 2 tracks");
    let a = with(PROFILE, WAYPOINTS, &["--depths", "20,20,20"]);
    bad(&refs(&a), "3 depths for 2 tracks");
    let a = with(PROFILE, WAYPOINTS, &["--depths", "20,x"]);
    bad(&refs(&a), "not a number");
}

#[test]
fn config_errors() {
    let cases = [
        ("sped = 1.5\n", "unknown field"),
        ("[depth_pid]\nkpp = 1\n", "unknown field"),
        ("[nonsense]\n", "unknown field"),
        (
            "min_altitude = 90.0\nreference_altitude = 80.0\n",
            "min_altitude",
        ),
        ("speed = 0.0\n", "speed must be positive"),
        ("speed = -1.5\n", "speed must be positive"),
        ("sample_time = 0\n", "sample_time must be positive"),
        ("pitch_limit = 95\n", "pitch_limit"),
        ("min_altitude = -1\n", "min_altitude"),
        ("depth_limits = [100.0, 0.0]\n", "depth_limits"),
        ("[depth_pid]\nkp = -1\n", "depth_pid.kp"),
        ("speed = \"fast\"\n", "invalid type"),
        ("speed = 1.5\nspeed = 2\n", "duplicate"),
        ("[plant]\nkind = \"gain\"\n", "plant.kind"),
        ("[plant]\nnum = [1.0, 0.0, 0.1]\n", "relative degree"),
        (
            "[plant]\nkind = \"rate\"\nnum = [-0.173, 0.5]\n",
            "zero constant term",
        ),
        (
            "[plant]\nden = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0]\n",
            "order",
        ),
        ("[optimizer]\nmax_iterations = 0\n", "max_iterations"),
        ("[pitch_pid]\nkp = 30.0\nkd = 0.0\n", "unstable"),
        ("[plant]\nden = [1.0, 1e13, 1e13, 1e13]\n", "discretized"),
        ("speed = 1.5\n[[", "v.toml:2"),
    ];
    for (text, mention) in cases {
        let c = tmp("v.toml", text);
        let a = with(
            PROFILE,
            WAYPOINTS,
            &["--config", c.to_str().unwrap(), "--depths", "20,20"],
        );
        bad(&refs(&a), mention);
    }
}

#[test]
fn bad_command_lines() {
    bad(&["--method", "newton"], "--method");
    bad(&["--mode", "sideways"], "--mode");
    bad(&["--horizon", "0"], "--horizon");
    bad(&["--horizon", "9"], "from 1 to 8");
    bad(&["--frobnicate"], "unknown argument");
    bad(&["--profile", "p.csv"], "--waypoints");
    bad(&["--depths"], "needs a value");
}

/// An argument that is not UTF-8 is a usage error, not a panic in
/// `std::env::args` (found while writing the fuzz target of its parsers).
#[cfg(unix)]
#[test]
fn non_utf8_argument() {
    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt;
    let out = Command::new(tool())
        .args([OsStr::new("--config"), OsStr::from_bytes(b"v\xff.toml")])
        .output()
        .unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(2), "stderr {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err:?}");
    assert!(
        err.contains("argument 2") && err.contains("UTF-8"),
        "{err:?}"
    );
}

#[test]
fn evaluate_json_has_every_field() {
    let v = json_of(&["--depths", "990,900,700,400,250", "--json"]);
    assert_eq!(v["method"], "fixed");
    let tracks = v["tracks"].as_array().unwrap();
    assert_eq!(tracks.len(), 5);
    let keys = [
        "track",
        "x_start",
        "x_end",
        "depth",
        "J",
        "rms",
        "min_altitude",
        "safe",
        "iterations",
        "evaluations",
        "status",
        "J_history",
    ];
    for (i, t) in tracks.iter().enumerate() {
        for k in keys {
            assert!(t.get(k).is_some(), "track {i} lacks {k}");
        }
        assert_eq!(t["track"], i + 1);
        assert_eq!(t["status"], "fixed");
        assert_eq!(t["iterations"], 0);
        assert_eq!(t["J_history"].as_array().unwrap().len(), 0);
        let j = t["J"].as_f64().unwrap();
        let rms = t["rms"].as_f64().unwrap();
        let len = t["x_end"].as_f64().unwrap() - t["x_start"].as_f64().unwrap();
        assert!((rms - (2.0 * j / len).sqrt()).abs() < 1e-3 * rms);
    }
    let total: f64 = tracks.iter().map(|t| t["J"].as_f64().unwrap()).sum();
    assert!((v["total_J"].as_f64().unwrap() - total).abs() <= 1e-5 * total);
    let min = tracks
        .iter()
        .map(|t| t["min_altitude"].as_f64().unwrap())
        .fold(f64::INFINITY, f64::min);
    assert_eq!(v["min_altitude"].as_f64().unwrap(), min);
    assert_eq!(v["safe"], tracks.iter().all(|t| t["safe"] == true));
}

#[test]
fn trajectory_csv_has_every_sample() {
    let dir = std::env::temp_dir().join(format!("auvnav-traj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("t.csv");
    let a = with(
        PROFILE,
        WAYPOINTS,
        &["--depths", "20,15", "--trajectory", out.to_str().unwrap()],
    );
    let o = run(&refs(&a));
    assert_eq!(o.status.code(), Some(0));
    let text = std::fs::read_to_string(Path::new(&out)).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "x_m,depth_m,bottom_m,target_m,pitch_deg,elevator_deg,reference_m"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    // 300 m at 0.15 m per step: about 2000 samples, the first at x = 0.
    assert!(rows.len() > 1900 && rows.len() < 2100, "{}", rows.len());
    assert_eq!(rows[0][0], "0");
    assert_eq!(rows[0][6], "20");
    let last = rows.last().unwrap();
    assert!(last[0].parse::<f32>().unwrap() >= 300.0);
    assert_eq!(last[5], "", "no command at the final sample");
    // The reference switches at the first sample past the waypoint.
    let switch = rows.iter().position(|r| r[6] == "15").unwrap();
    assert!(rows[switch][0].parse::<f32>().unwrap() >= 150.0);
    assert!(rows[switch - 1][0].parse::<f32>().unwrap() < 150.0);
}

#[test]
fn planning_modes_report_the_optimizer() {
    for mode in ["track", "horizon"] {
        for method in ["bfgs", "gd"] {
            let v = json_of(&["--mode", mode, "--method", method, "--json"]);
            assert_eq!(v["method"], method);
            assert_eq!(v["mode"], mode);
            for t in v["tracks"].as_array().unwrap() {
                let status = t["status"].as_str().unwrap();
                assert!(
                    ["optimal", "constrained", "infeasible"].contains(&status),
                    "{status}"
                );
                let stop = t["optimizer"].as_str().unwrap();
                assert!(
                    ["converged", "max_iterations", "budget", "stalled", "none"].contains(&stop),
                    "{stop}"
                );
                // Safe exactly when not infeasible; the certificate is the
                // nominal flight when nothing is declared.
                assert_eq!(t["safe"] == true, status != "infeasible");
                assert_eq!(t["certified_min_altitude"], t["min_altitude"]);
                assert_eq!(t.get("continuation").is_some(), mode == "horizon");
                let it = t["iterations"].as_u64().unwrap();
                let ev = t["evaluations"].as_u64().unwrap();
                let hist = t["J_history"].as_array().unwrap();
                // The start, then one value per iteration (the first 256).
                assert_eq!(hist.len() as u64, (it + 1).min(256));
                assert!(it <= 200, "the iteration cap bounds the whole solve");
                assert!(
                    ev > it,
                    "{mode} {method}: {ev} evaluations for {it} iterations"
                );
                // infeasible is reported unsafe; a safe track is never infeasible.
                if status == "infeasible" {
                    assert!(t["min_altitude"].as_f64().unwrap() < 60.0 + 0.01 + 1e-6);
                }
                if t["safe"] == true {
                    assert!(t["min_altitude"].as_f64().unwrap() >= 60.0);
                }
            }
        }
    }
}

#[test]
fn unconstrained_ignores_the_minimum_altitude() {
    let bare = json_of(&["--mode", "track", "--unconstrained", "--json"]);
    let safe = json_of(&["--mode", "track", "--json"]);
    // From the same start, the bare objective tracks the target more
    // closely on track 1 and flies lower (later tracks start elsewhere).
    let (b1, s1) = (&bare["tracks"][0], &safe["tracks"][0]);
    assert!(b1["J"].as_f64().unwrap() < s1["J"].as_f64().unwrap());
    assert!(b1["min_altitude"].as_f64().unwrap() < 60.0);
    assert!(s1["min_altitude"].as_f64().unwrap() >= 60.0);
    // Unconstrained, nothing is done about safety: a track that is not
    // safe says so (infeasible), never optimal or constrained.
    for t in bare["tracks"].as_array().unwrap() {
        assert_eq!(t["safe"] == false, t["status"] == "infeasible", "{t}");
    }
}

#[test]
fn plot_writes_an_svg_figure() {
    let dir = std::env::temp_dir().join(format!("auvnav-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("f.svg");
    let o = run(&["--mode", "track", "--plot", out.to_str().unwrap()]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.starts_with("<svg"));
    for label in [
        "bottom b(x)",
        "minimum-altitude envelope",
        "AUV flight",
        "J against iteration, per track",
        "the line (lon, lat)",
    ] {
        assert!(svg.contains(label), "figure lacks {label}");
    }
    assert!(svg.len() < 200_000, "{} bytes", svg.len());
}

#[test]
fn main_job_prints_a_table() {
    let out = run(&[]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.starts_with("method bfgs, mode horizon"), "{text}");
    assert_eq!(
        text.lines()
            .filter(|l| l.trim_start().starts_with(char::is_numeric))
            .count(),
        5
    );
    assert!(text.contains("total J"));
}

/// Runs the tool, expects exit status 0 and one `warning:` line on stderr
/// that mentions `must_mention`; returns stdout.
fn warns(args: &[&str], must_mention: &str) -> String {
    let out = run(args);
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(0), "args {args:?}: stderr {err}");
    let lines: Vec<&str> = err.trim_end().lines().collect();
    assert_eq!(lines.len(), 1, "not one line: {err:?}");
    assert!(lines[0].starts_with("warning: "), "{err:?}");
    assert!(
        err.to_lowercase().contains(&must_mention.to_lowercase()),
        "{args:?}: {err:?} should mention {must_mention:?}"
    );
    String::from_utf8(out.stdout).unwrap()
}

fn with_config(profile: &str, toml: &str, extra: &[&str]) -> Vec<String> {
    let c = tmp(&format!("c{}.toml", fxhash(toml)), toml);
    let mut e = vec!["--config", c.to_str().unwrap()];
    e.extend(extra);
    with(profile, WAYPOINTS, &e)
}

#[test]
fn uncertainty_keys_are_parsed_and_validated() {
    let all = "horizontal_uncertainty = 5.0\nnav_drift = 0.002\nvertical_uncertainty = 2.0\n\
               speed_uncertainty = 0.1\nflight_path_offset = 3.0\nvertical_current = 0.05\n";
    // Accepted, and certified against: the worst world is lower than the
    // nominal flight.
    let mut a = with_config(PROFILE, all, &["--depths", "20,20"]);
    a.push("--json".into());
    let v = json_of(&refs(&a));
    for t in v["tracks"].as_array().unwrap() {
        let (c, m) = (
            t["certified_min_altitude"].as_f64().unwrap(),
            t["min_altitude"].as_f64().unwrap(),
        );
        assert!(c < m - 1.0, "certified {c} vs nominal {m}");
    }
    // All zero is the nominal model: no warning.
    let zero = "horizontal_uncertainty = 0.0\nnav_drift = 0\nvertical_uncertainty = 0\n\
                speed_uncertainty = 0\nflight_path_offset = 0\nvertical_current = 0\n";
    let a = with_config(PROFILE, zero, &["--depths", "20,20"]);
    let out = run(&refs(&a));
    assert_eq!(out.status.code(), Some(0));
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for key in [
        "horizontal_uncertainty",
        "nav_drift",
        "vertical_uncertainty",
        "speed_uncertainty",
        "flight_path_offset",
        "vertical_current",
    ] {
        let a = with_config(PROFILE, &format!("{key} = -0.5\n"), &["--depths", "20,20"]);
        bad(&refs(&a), &format!("{key} = -0.5 must be >= 0"));
        let a = with_config(PROFILE, &format!("{key} = nan\n"), &["--depths", "20,20"]);
        bad(&refs(&a), &format!("{key} = NaN is not finite"));
    }
    let a = with_config(PROFILE, "speed_uncertainty = 1.0\n", &["--depths", "20,20"]);
    bad(&refs(&a), "speed_uncertainty = 1 must be below 1");
    let a = with_config(
        PROFILE,
        "flight_path_offset = 25.0\n",
        &["--depths", "20,20"],
    );
    bad(&refs(&a), "below pitch_limit = 25");
    let a = with_config(
        PROFILE,
        "pitch_limit = 10.0\nflight_path_offset = 12.0\n",
        &["--depths", "20,20"],
    );
    bad(&refs(&a), "below pitch_limit = 10");
    // Unknown keys stay errors, and the message lists the new keys.
    let a = with_config(PROFILE, "nav_drfit = 0.1\n", &["--depths", "20,20"]);
    let err = bad(&refs(&a), "unknown field `nav_drfit`");
    assert!(err.contains("nav_drift"), "{err}");
}

#[test]
fn depth_limits_must_be_a_pair() {
    for (text, n) in [
        ("depth_limits = [0.0, 100.0, 200.0]\n", 3),
        ("depth_limits = [0.0]\n", 1),
        ("depth_limits = []\n", 0),
    ] {
        let a = with_config(PROFILE, text, &["--depths", "20,20"]);
        let err = bad(
            &refs(&a),
            &format!("depth_limits must be a pair [min, max] of depths in m, got {n} values"),
        );
        assert!(err.contains(".toml"), "names the file: {err}");
    }
}

#[test]
fn config_line_numbers_are_one_based() {
    for (text, line) in [
        ("sped = 1.5\n", 1),
        ("speed = 1.5\nsped = 1\n", 2),
        ("speed = 1.5\n\nsped = 1\n", 3),
        ("# vehicle\n\n\n[depth_pid]\nkp = 1\n\nkpp = 2\n", 7),
        ("speed = 1.5\n\n\nspeed = 2\n", 4),
    ] {
        let c = tmp("lines.toml", text);
        let a = with(
            PROFILE,
            WAYPOINTS,
            &["--config", c.to_str().unwrap(), "--depths", "20,20"],
        );
        bad(&refs(&a), &format!("lines.toml:{line}:"));
    }
}

#[test]
fn csv_line_numbers_count_blank_lines() {
    // Lines as an editor shows them: blank lines are skipped but counted.
    let a = with(
        "x_m,bottom_depth_m\n\n0,100\n100,110\n100,90\n300,100\n",
        WAYPOINTS,
        &["--depths", "20,20"],
    );
    bad(&refs(&a), ":5: x_m 100 does not increase");
    let a = with(
        "x_m,bottom_depth_m\n0,100\n\n100,110\n\n300,abc\n",
        WAYPOINTS,
        &["--depths", "20,20"],
    );
    bad(&refs(&a), ":6: bottom_depth_m 'abc'");
    let a = with(
        "\n\nx,depth\n0,100\n100,100\n",
        WAYPOINTS,
        &["--depths", "20,20"],
    );
    bad(&refs(&a), ":3: header must name column 'x_m'");
    let a = with(
        PROFILE,
        "wp,x_m\n0,0\n\n1,200\n2,150\n",
        &["--depths", "20,20"],
    );
    bad(&refs(&a), ":5: x_m 150 does not increase");
}

#[test]
fn elevations_are_not_depths() {
    let gebco = "x_m,bottom_depth_m\n0,-100\n100,-110\n200,-90\n300,-100\n";
    let a = with(gebco, WAYPOINTS, &["--depths", "20,20"]);
    let err = bad(&refs(&a), "look like elevations");
    assert!(err.contains("negate"), "{err}");
    assert!(err.contains("4 of 4"), "{err}");
    // Mostly negative is elevations too.
    let a = with(
        "x_m,bottom_depth_m\n0,-100\n100,-110\n200,-90\n300,100\n",
        WAYPOINTS,
        &["--depths", "20,20"],
    );
    bad(&refs(&a), "3 of 4 bottom_depth_m values are negative");
}

#[test]
fn impossible_start() {
    // h_r larger than the water depth at the start: the default start
    // depth b(X0) - h_r would be above the surface.
    let shallow = "x_m,bottom_depth_m\n0,50\n100,110\n200,90\n300,100\n";
    let a = with(shallow, WAYPOINTS, &["--depths", "20,20"]);
    let err = bad(
        &refs(&a),
        "reference_altitude = 80 m is larger than the water depth 50 m",
    );
    assert!(err.contains("above the surface"), "{err}");
    let a = with_config(
        PROFILE,
        "reference_altitude = 120.0\n",
        &["--depths", "20,20"],
    );
    bad(&refs(&a), "reference_altitude = 120 m");
    // initial_depth above the surface or below the bottom at X0 (b = 100).
    let a = with_config(PROFILE, "initial_depth = -1.0\n", &["--depths", "20,20"]);
    bad(&refs(&a), "initial_depth = -1 m is above the surface");
    let a = with_config(PROFILE, "initial_depth = 100.0\n", &["--depths", "20,20"]);
    bad(&refs(&a), "initial_depth = 100 m is at or below the bottom");
    let a = with_config(PROFILE, "initial_depth = 150.0\n", &["--depths", "20,20"]);
    bad(&refs(&a), "initial_depth = 150 m is at or below the bottom");
    // Inside the water but under h_a: a warning, and the plan is made.
    let a = with_config(PROFILE, "initial_depth = 50.0\n", &["--depths", "20,20"]);
    warns(&refs(&a), "below min_altitude = 60 m");
    // The surface itself and the default are fine.
    let a = with_config(PROFILE, "initial_depth = 0.0\n", &["--depths", "20,20"]);
    let out = run(&refs(&a));
    assert_eq!(out.status.code(), Some(0));
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn water_shallower_than_min_altitude_warns() {
    let shoal = "x_m,bottom_depth_m\n0,100\n100,110\n200,40\n250,30\n300,100\n";
    let a = with(shoal, WAYPOINTS, &["--depths", "20,20", "--json"]);
    let out = warns(
        &refs(&a),
        "shallower than min_altitude = 60 m between x = 200 and 250 m",
    );
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["safe"], false);
}

#[test]
fn depths_outside_depth_limits() {
    let a = with(PROFILE, WAYPOINTS, &["--depths", "20,-1"]);
    bad(
        &refs(&a),
        "value 2 (-1 m) is outside depth_limits [0, 6000] m",
    );
    let a = with_config(
        PROFILE,
        "depth_limits = [10.0, 30.0]\n",
        &["--depths", "20,35"],
    );
    let err = bad(
        &refs(&a),
        "value 2 (35 m) is outside depth_limits [10, 30] m",
    );
    assert!(err.contains(".toml"), "{err}");
    let a = with_config(
        PROFILE,
        "depth_limits = [10.0, 30.0]\n",
        &["--depths", "10,30"],
    );
    assert_eq!(run(&refs(&a)).status.code(), Some(0));
}

#[test]
fn conflicting_and_repeated_options() {
    for opt in [
        &["--mode", "track"][..],
        &["--method", "gd"],
        &["--horizon", "2"],
        &["--unconstrained"],
    ] {
        let mut a = vec!["--depths", "990,900,700,400,250"];
        a.extend(opt);
        bad(&a, &format!("cannot be combined with {}", opt[0]));
    }
    bad(
        &["--mode", "track", "--horizon", "2"],
        "--horizon applies to --mode horizon only",
    );
    bad(
        &["--horizon=2", "--mode=track"],
        "--horizon applies to --mode horizon only",
    );
    for twice in [
        &[
            "--profile",
            "p.csv",
            "--profile",
            "q.csv",
            "--waypoints",
            "w.csv",
        ][..],
        &["--waypoints", "w.csv", "--waypoints=w.csv"],
        &["--json", "--json"],
        &["--mode", "track", "--mode", "track"],
        &["--config", "a.toml", "--config", "b.toml"],
    ] {
        bad(
            twice,
            &format!(
                "{} given more than once",
                twice[0].split('=').next().unwrap()
            ),
        );
    }
    bad(
        &["--waypoints", "w.csv"],
        "--profile and --waypoints go together",
    );
    bad(
        &["--profile", "p.csv"],
        "--profile and --waypoints go together",
    );
}

#[test]
fn help_lists_the_whole_interface() {
    for flag in ["--help", "-h"] {
        let out = run(&[flag]);
        assert_eq!(out.status.code(), Some(0));
        let text = String::from_utf8(out.stdout).unwrap();
        for item in [
            "--profile",
            "--waypoints",
            "--config",
            "--depths",
            "--method",
            "--mode",
            "--horizon",
            "--unconstrained",
            "--json",
            "--trajectory",
            "--plot",
            "--grid",
            "--line",
            "--spacing",
            "--geojson",
            "plan profile",
            "a quarter",
            "uncertainty (the six",
            "PLAN_PROGRESS",
            "horizon (default)",
            "bfgs (default",
            "us_monterey_canyon_1",
            "speed = 1.5",
            "sample_time = 0.1",
            "pitch_limit = 25.0",
            "elevator_limit = 25.0",
            "reference_altitude = 80.0",
            "min_altitude = 60.0",
            "b(X0) - h_r",
            "depth_limits = [0.0, 6000.0]",
            "horizontal_uncertainty = 0.0",
            "nav_drift = 0.0",
            "vertical_uncertainty = 0.0",
            "speed_uncertainty = 0.0",
            "flight_path_offset = 0.0",
            "vertical_current = 0.0",
            "[depth_pid]",
            "kp = 1.5",
            "[pitch_pid]",
            "ki = 0.1",
            "[plant]",
            "den = [1.0, 2.681, 0.546, 0.048]",
            "[optimizer]",
            "max_iterations = 200",
            "m/s",
            "deg",
        ] {
            assert!(text.contains(item), "--help lacks {item:?}");
        }
    }
}

#[test]
fn outputs_name_profile_vehicle_and_altitudes() {
    let v = json_of(&["--depths", "990,900,700,400,250", "--json"]);
    assert_eq!(v["profile"], "us_monterey_canyon_1 (bundled)");
    assert_eq!(v["vehicle"], "C-AUV #4 (default)");
    assert_eq!(v["reference_altitude"], 80.0);
    assert_eq!(v["min_altitude_limit"], 60.0);
    // The existing keys are unchanged: min_altitude is the least flown.
    assert!(v["min_altitude"].as_f64().unwrap() != 60.0);
    let a = with_config(
        PROFILE,
        "reference_altitude = 50.0\nmin_altitude = 30.0\n",
        &["--depths", "50,50", "--json"],
    );
    let v = json_of(&refs(&a));
    assert!(
        v["profile"].as_str().unwrap().ends_with(".csv"),
        "{}",
        v["profile"]
    );
    assert!(
        v["vehicle"].as_str().unwrap().ends_with(".toml"),
        "{}",
        v["vehicle"]
    );
    assert_eq!(v["reference_altitude"], 50.0);
    assert_eq!(v["min_altitude_limit"], 30.0);
    let out = run(&["--depths", "990,900,700,400,250"]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(
        text.lines().nth(1).unwrap(),
        "profile us_monterey_canyon_1 (bundled), vehicle C-AUV #4 (default), h_r 80 m, h_a 60 m"
    );
}

#[test]
fn outputs_name_the_declared_uncertainty() {
    let v = json_of(&["--depths", "990,900,700,400,250", "--json"]);
    let u = v["uncertainty"].as_object().unwrap();
    for k in [
        "horizontal_uncertainty",
        "nav_drift",
        "vertical_uncertainty",
        "speed_uncertainty",
        "flight_path_offset",
        "vertical_current",
    ] {
        assert_eq!(u[k], 0.0, "{k}");
    }
    let text = String::from_utf8(run(&["--depths", "990,900,700,400,250"]).stdout).unwrap();
    assert!(
        text.lines()
            .nth(2)
            .unwrap()
            .starts_with("declared uncertainty: none"),
        "{text}"
    );
    let a = with_config(
        PROFILE,
        "reference_altitude = 50.0\nmin_altitude = 30.0\nvertical_uncertainty = 2.5\nnav_drift = 0.002\n",
        &["--depths", "50,50", "--json"],
    );
    let v = json_of(&refs(&a));
    assert_eq!(v["uncertainty"]["vertical_uncertainty"], 2.5);
    assert_eq!(v["uncertainty"]["nav_drift"], 0.002);
    let a = with_config(
        PROFILE,
        "reference_altitude = 50.0\nmin_altitude = 30.0\nvertical_uncertainty = 2.5\n",
        &["--depths", "50,50"],
    );
    let out = run(&refs(&a));
    let text = String::from_utf8(out.stdout).unwrap();
    let line = text.lines().nth(2).unwrap();
    assert!(line.contains("vertical_uncertainty 2.5 m"), "{line}");
}

/// The plot's title names the profile by its file stem, not the whole
/// path; the stretches below h_a are shaded and labelled; no map inset
/// when the waypoints have no lat/lon; the reference-depth legend is
/// dashed as the lines are (drawn as several short segments).
#[test]
fn plot_title_below_h_a_and_legend() {
    let dir = std::env::temp_dir().join(format!("auvnav-plot2-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("g.svg");
    // 100 m deep over a bottom at 90-110 m with h_a = 60: below h_a.
    let a = with(
        PROFILE,
        WAYPOINTS,
        &["--depths", "40,40", "--plot", out.to_str().unwrap()],
    );
    let o = run(&refs(&a));
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let svg = std::fs::read_to_string(&out).unwrap();
    let stem = Path::new(&a[1]).file_stem().unwrap().to_str().unwrap();
    let tmpdir = Path::new(&a[1]).parent().unwrap().to_str().unwrap();
    assert!(
        svg.contains(&format!("{stem} — fixed")),
        "title lacks the stem {stem}"
    );
    assert!(!svg.contains(tmpdir), "title holds the whole path");
    assert!(
        svg.contains("below h_a (1 stretch"),
        "below-h_a stretches not marked"
    );
    assert!(
        !svg.contains("the line (lon, lat)"),
        "inset without lat/lon"
    );
    // A run above h_a everywhere marks nothing.
    let a = with(
        PROFILE,
        WAYPOINTS,
        &["--depths", "20,20", "--plot", out.to_str().unwrap()],
    );
    assert_eq!(run(&refs(&a)).status.code(), Some(0));
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(
        !svg.contains("below h_a ("),
        "marked though never below h_a"
    );
    // The legend's sample of the reference depth (grey, left of its
    // label): dashed as the lines are, so several short segments.
    let at = svg.find("reference depth z_n").unwrap();
    let open = svg[..at].rfind("<text").unwrap();
    let attr = |tag: &str, key: &str| -> f64 {
        let i = tag.find(&format!(" {key}=\"")).unwrap() + key.len() + 3;
        tag[i..i + tag[i..].find('"').unwrap()].parse().unwrap()
    };
    let (label_x, label_y) = (attr(&svg[open..at], "x"), attr(&svg[open..at], "y"));
    let segments = svg
        .split("<polyline")
        .filter(|p| p.contains("stroke=\"#5A5A5A\""))
        .filter(|p| {
            let pts = &p[p.find("points=\"").unwrap() + 8..];
            let pts = &pts[..pts.find('"').unwrap()];
            pts.split_whitespace().all(|xy| {
                let (x, y) = xy.split_once(',').unwrap();
                let (x, y): (f64, f64) = (x.parse().unwrap(), y.parse().unwrap());
                x < label_x && (y - label_y).abs() < 12.0
            })
        })
        .count();
    assert!(
        segments >= 2,
        "reference depth legend is not dashed ({segments} segment)"
    );
}

/// Progress on stderr for runs longer than a second: with
/// `PLAN_PROGRESS=1` (stderr here is a pipe, where it is off by default).
#[test]
fn progress_on_stderr_for_long_runs() {
    let t = std::time::Instant::now();
    let out = Command::new(tool())
        .env("PLAN_PROGRESS", "1")
        .output()
        .unwrap();
    let long = t.elapsed().as_secs_f64() > 2.0;
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(0));
    if long {
        assert!(err.contains("plan: planning track 5 of 5,"), "{err:?}");
    }
    assert!(
        err.lines().all(|l| l.starts_with("plan: planning track")),
        "{err:?}"
    );
    let quiet = Command::new(tool())
        .env("PLAN_PROGRESS", "0")
        .args(["--depths", "990,900,700,400,250"])
        .output()
        .unwrap();
    assert!(quiet.stderr.is_empty());
}

/// A line that flies into the rock does not give up on the tracks after
/// it: the track that starts below the bottom is flown at the shallowest
/// depth (reported infeasible, after the crash), and the next track is
/// planned from where that climb leaves the vehicle. A random line of
/// `tools/reference/check_planner.py --seed 23` (`unseen_23_0`): tracks 1
/// and 2 cannot be made safe, and the f64 checker's best safe depth of
/// track 3 from the state the climb reaches is 140.21 m (1.796e6 m³).
#[test]
fn a_crash_does_not_end_the_planning() {
    let (p, w, _) = fixture("crash_recover");
    let v = json_of(&[
        "--profile",
        &p,
        "--waypoints",
        &w,
        "--mode",
        "track",
        "--json",
    ]);
    let tracks = v["tracks"].as_array().unwrap();
    assert_eq!(tracks[1]["status"], "infeasible");
    assert_eq!(
        tracks[1]["evaluations"], 0,
        "track 2 starts below the bottom"
    );
    let t3 = &tracks[2];
    assert_eq!(t3["safe"], true, "{t3}");
    assert!(t3["evaluations"].as_u64().unwrap() > 0);
    let j3 = t3["J"].as_f64().unwrap();
    assert!(
        j3 <= 1.005 * 1.796_27e6,
        "track 3: J {j3} vs the best safe 1.79627e6"
    );
    assert!(v["safe"] == false, "the line as a whole is not safe");
}

/// The last call of a horizon (one track, warm-started from the
/// continuation) whose penalized optimum dives below the floor answers
/// with the boundary next to its safe warm start: on a random canyon line
/// (`tools/reference/check_planner.py --unseen 8 --seed 41`, `unseen_41_5`)
/// the general fallback took the scanned safe depth nearest that optimum
/// (223.3 m, least altitude −1.5 m), 68.8 m, with `J_5` 5.71e6 m³. With the
/// first four tracks at the tool's depths (asserted: the premise), the f64
/// reference (`auvref.evaluate_plan`, `z_5` scanned every 5 cm) finds the
/// best safe `J_5` 2.222 16e6 m³ at 139.60 m (least altitude 60.016 m).
/// (Since the escapes owed by a cold call that ends infeasible, its
/// second call runs them: tracks 2–4 moved (147.12, 141.34, 169.79 m
/// before, where the best safe `J_5` was 2.319 15e6 m³ at 137.15 m), the
/// line's `J` 1.4901e7 → 1.4792e7 m³.)
#[test]
fn a_warm_last_track_stays_by_its_boundary() {
    let (p, w, _) = fixture("warm_last");
    let v = json_of(&["--profile", &p, "--waypoints", &w, "--json"]);
    let tracks = v["tracks"].as_array().unwrap();
    let head = [110.2067, 147.15475, 148.12071, 167.92351];
    for (t, z) in tracks.iter().zip(head) {
        let d = t["depth"].as_f64().unwrap();
        // (Within 15 cm: where an optimizer stops moves by centimetres
        // with the gradient's last digits.)
        assert!((d - z).abs() < 0.15, "depth {d} against the premise {z}");
    }
    let t5 = &tracks[4];
    let j5 = t5["J"].as_f64().unwrap();
    assert_eq!(t5["safe"], true, "{t5}");
    assert!(
        j5 <= 1.01 * 2.222_16e6,
        "track 5: J {j5} vs the best safe 2.222 16e6 at 139.60 m"
    );
}

/// The horizon's plateau escape rescans, in its second round, what its
/// first round scanned but did not jump: on a random canyon line
/// (`tools/reference/check_planner.py --unseen 8 --seed 13`, `unseen_13_7`)
/// the cold call ended with tracks 1 and 3 on plateaus; track 1 jumped,
/// and track 3 stayed on its saturated climb (364.1 m) because it had been
/// scanned before the jump: the line's `J` 3.7006e6 m³, 1.1015× the f64
/// beam search's best safe plan (3.3596e6 m³, track 3 at 520.3 m). The
/// checker's bound is 1.10×.
#[test]
fn a_plateau_left_after_another_jump() {
    horizon_within("plateau_second", 1.10, 3.3596e6);
}

/// The SQP ends no worse than the best feasible point it passed: on a
/// random canyon line (`tools/reference/check_planner.py --unseen 8 --seed
/// 90317`, `unseen_90317_1`) the cold horizon started feasible at `J`
/// 1.07e8 m³ (the beam's plan), stepped out of the feasible set to 4.5e7
/// under a still small merit weight and came back at 3.78e8 m³, track 3
/// held on a climb 356 m above a deep bottom: the line's `J` 3.779e8 m³,
/// 4.56× the f64 beam search's best safe plan (8.27996e7 m³: 361.2,
/// 937.8, 1 344.8, 752.5, 1 032.7 m). Back at its best feasible iterate
/// and restarted there with the merit weight it had learnt, 8.37e7. The
/// checker's bound is 1.10×.
#[test]
fn the_sqp_ends_no_worse_than_its_best_feasible_point() {
    horizon_within("best_feasible", 1.10, 8.27996e7);
}

/// A feasibility restoration that falls short is carried on along the
/// secant of `v` (`optim/sqp.rs`, `Run::restore`): on the same line the
/// restoration's least step cut the shortfall only from 92.5 to 85.3 m
/// (the rows' gradients overstate their slopes there); halved, it did no
/// better, the restoration gave up and the line ended on a worse optimum:
/// `J` 8.36830e7 m³, 1.0107× the best safe. Carried on along the secant
/// (4 steps' length), the shortfall is 0, and `J` 8.2810e7 (1.0001×).
#[test]
fn a_short_restoration_is_carried_on_along_its_secant() {
    horizon_within("best_feasible", 1.005, 8.27996e7);
}

/// A run that went back to its start from a lower `J` restarts at the
/// edge of the feasible set between the two (`src/plan/edge.rs`): on a
/// random canyon line (`tools/reference/check_planner.py --unseen 8
/// --seed 1302`, `unseen_1302_7`) track 1's least altitude falls from
/// 80 m at 501.7 m to 60 m at 556.3 m and then stays at 59.75 m (a dive
/// held at the pitch limit); a plateau restart went from 501.7 to 674 m,
/// 0.27 m short with no gradient to return by, and back: the line's `J`
/// 3.6577e7 m³, 1.81× the f64 beam search's best safe plan (2.02082e7 m³,
/// track 1 at 556.3 m). From the edge, 1.0028×. The checker's bound is
/// 1.10×.
#[test]
fn a_run_gone_back_restarts_at_the_edge_it_crossed() {
    horizon_within("edge_saturated", 1.01, 2.02082e7);
}

/// A later track held at its target by the depth before it: on a random
/// canyon line (`tools/reference/check_planner.py --unseen 8 --seed 60606`,
/// `unseen_60606_0`) the cold SQP ended with track 1 at 662.6 m (a
/// saturated dive, zero gradient) and track 2 at its least altitude's
/// target at 661.1 m: the line's `J` 2.394e7 m³, 1.56× the f64 beam
/// search's best safe plan (1.534436e7 m³: 587.0, 922.1, 575.0, 504.9,
/// 801.5 m), which flies track 1 shallower so that track 2 can dive.
/// With `lift/`, 1.001×. The checker's bound is 1.10×.
#[test]
fn a_later_track_dives_once_the_one_before_is_lifted() {
    horizon_within("lift_earlier", 1.10, 1.534436e7);
}

/// A lift that frees the later track's whole dive, not only the altitude
/// it gains at the later track's own depth: on a random canyon line
/// (`tools/reference/check_planner.py --unseen 8 --seed 1302`,
/// `unseen_1302_5`) the cold SQP held track 5 at its target at 1 056.7 m
/// by track 4's depth (942.7 m). Lifted 80 m, track 5's least altitude is
/// 93.4 m at every depth below 1 070 m (a saturated dive's plateau, set
/// by track 4 alone); the lift took the 13 m freed beyond the band
/// (1 070 m, a start worse than the SQP's end) and the line's `J` was
/// 7.551e6 m³, 1.40× the f64 beam search's best safe plan (5.410706e6 m³:
/// 1028.4, 1048.1, 965.9, 896.0, 1474.0 m). Now the lift also tries track
/// 5 at its preferred depth and narrows the least lift that clears it:
/// 1.001×. The checker's bound is 1.10×.
#[test]
fn a_lift_that_clears_a_plateau_frees_the_whole_dive() {
    horizon_within("lift_plateau", 1.01, 5.410706e6);
}

/// A climb bought for a dive: on a random canyon line
/// (`tools/reference/check_planner.py --unseen 8 --seed 90317`,
/// `unseen_90317_0`) track 4 crosses a rise 130 m above its deep end. The
/// cold SQP held track 4 at the rise's target (975 m, `J` 7.58e6 m³); a
/// lift of track 3 alone could not free it, because the climb saturates.
/// The best safe plan (the f64 beam search: 1069.8, 1063.7, 766.4,
/// 1225.5 m, line `J` 3.282938e6 m³) climbs on track 3, so that track 4
/// can dive from higher and pass the rise 60 m above it. Before
/// `lift/` sought track 4's preferred depth, 2.77×; now 1.001×. The
/// checker's bound is 1.10×.
#[test]
fn a_track_climbs_so_that_the_next_can_dive_past_a_rise() {
    horizon_within("lift_to_dive", 1.10, 3.282938e6);
}

/// A metric no longer definite in f32: on a random canyon line
/// (`tools/reference/check_planner.py --unseen 8 --seed 60606`,
/// `unseen_60606_2`) tracks 2–4 are saturated dives. One BFGS update left
/// the cold call's metric with eigenvalues −4e−4 and 1e−4 beside 1.6e3,
/// the QP refused it, and the run stopped with track 1 at 554.6 m, 12 m
/// short of its boundary: line `J` 1.893e7 m³, 1.16× the f64 beam
/// search's best safe plan (1.626596e7 m³: 566.6, 906.1, 1077.5, 1428.2,
/// 1359.2 m). With the metric reset to its diagonal, 1.0002×
/// (`unseen_5151_3`: 1.15× → 0.9997×). The checker's bound is 1.10×.
#[test]
fn an_indefinite_metric_is_reset_not_the_end_of_the_run() {
    horizon_within("indefinite_metric", 1.10, 1.626596e7);
}

/// A kink far from its way out: on a random line
/// (`tools/reference/check_planner.py --unseen 8 --seed 2718`,
/// `unseen_2718_2`) the cold SQP ended with track 5 diving 425 m
/// saturated from 515 m (its own column zero) and track 4 held 156 m above
/// its bottom by track 5's least altitude: line `J` 3.222e6 m³, 1.61× the
/// f64 beam search's best safe plan (1.99653e6 m³: 465.7, 485.6, 585.4,
/// 621.4, 670.3 m). Moving track 5 up by `h_r − h_a` lifted nothing; the
/// cold call's doubled moves unsaturate it at 320 m, and the restart
/// finds 1.001×. The checker's bound is 1.10×.
#[test]
fn a_cold_kink_escape_moves_as_far_as_the_dive_needs() {
    horizon_within("kink_far", 1.10, 1.99653e6);
}

/// A narrow feasible window at a plateau's edge: on a random canyon line
/// (`tools/reference/check_planner.py --unseen 8 --seed 5151`,
/// `unseen_5151_1`) track 1's saturated climb is flat in `z_1` up to about
/// 130 m; deeper, the line's `J` falls until a cliff near 200 m where
/// track 1's least altitude drops from 61 m to 27 m. The plateau scan's 9
/// points (97 m apart) read 126.9 m flat and 223.5 m infeasible, and the
/// cold call committed 30.2 m: line `J` 1.4135e7 m³, 1.074× the f64 beam
/// search's best safe plan (1.316275e7 m³, track 1 at 180.8 m). With the
/// scan's step into the cliff bisected (`plan/jump/`), 0.995×. Bound 1.02×:
/// the checker's 1.10× passed this line before.
#[test]
fn a_plateau_scan_finds_the_window_before_a_cliff() {
    horizon_within("plateau_edge", 1.02, 1.316275e7);
}

/// Track 1's `J` of a track-wise constrained plan of `name`.
fn track_one_j(name: &str) -> f64 {
    let (p, w, _) = fixture(name);
    let v = json_of(&[
        "--profile",
        &p,
        "--waypoints",
        &w,
        "--mode",
        "track",
        "--json",
    ]);
    assert_eq!(v["tracks"][0]["safe"], true);
    v["tracks"][0]["J"].as_f64().unwrap()
}

/// A boundary where the least altitude hardly moves with the depth: on a
/// random line (`tools/reference/check_planner.py --unseen 8 --seed 8080`,
/// `unseen_8080_6`, track-wise, constrained) track 1's least altitude
/// falls 0.024 m per m of depth at its boundary while `J` falls 0.46 % per
/// m. The boundary search stopped on its altitude tolerance 3.3 mm above
/// `h_a`, 0.13 m short in depth: `J` 51 822.6 m³, 1.0062× the f64 search's
/// best safe 51 503.8 m³ (622.770 m), over the checker's 1.005×. Near in
/// depth as well (`optim/root.rs`): 1.0041×.
#[test]
fn a_flat_boundary_is_found_near_in_depth_too() {
    let j = track_one_j("track_flat_boundary");
    assert!(j <= 1.005 * 51503.8, "J {j} vs the best safe 51503.8");
}

/// An interior optimum within `CHECK_STEP` of the boundary: on a random
/// line (`check_planner.py --unseen 8 --seed 1234`, `unseen_1234_2`,
/// track-wise, constrained) `J` is least at 1 089.24 m (least altitude
/// 60.89 m), 0.88 m inside the boundary. The optimizer overshot; the check
/// 2 m into the safe set read `J` higher than at the boundary, so the
/// boundary was kept: 34 349.2 m³, 1.0054× the f64 search's best safe
/// 34 164.4 m³. A second look a quarter of the step in (`candidate.rs`,
/// `single.rs`) finds `J` falling and the optimizer runs: 1.0000×.
#[test]
fn an_optimum_just_inside_the_boundary_is_not_lost_to_it() {
    let j = track_one_j("track_near_interior");
    assert!(j <= 1.005 * 34164.4, "J {j} vs the best safe 34164.4");
}

/// A horizon with no safe plan whose SQP stalls infeasible: on a random
/// canyon line (`tools/reference/check_planner.py --unseen 8 --seed 43`,
/// `unseen_43_6`) calls 2 and 3 took Armijo's 2⁻¹⁰ steps for all 200
/// iterations, the merit moving a few parts in 10⁸, 2 410 and 2 390
/// flights. The run now stops once its merit has stayed put five
/// iterations in a row (after its restorations): 88 and 86 flights, the
/// same depths.
#[test]
fn a_stalled_infeasible_horizon_stops() {
    let (p, w, _) = fixture("stuck_infeasible");
    let v = json_of(&["--profile", &p, "--waypoints", &w, "--json"]);
    assert_eq!(v["safe"], false);
    for t in v["tracks"].as_array().unwrap() {
        let n = t["evaluations"].as_u64().unwrap();
        assert!(n <= 300, "track {}: {n} flights", t["track"]);
    }
}

/// A later track held through a plateau, freed only further off its edge
/// (`tools/reference/check_planner.py --unseen 8 --seed 1801`,
/// `unseen_1801_2`): track 2's depth on a saturated dive's plateau, track
/// 3's least altitude at its target, held by track 1's depth. Just off
/// the plateau's edge track 3 was freed by 4.5 cm, under the slack, so
/// the cold call kept its local optimum: the line's `J` 5.6588e6 m³,
/// 1.51× the f64 beam search's best safe plan (3.73824e6 m³: 682.9,
/// 925.4, 758.1, 1 144.9, 1 100.1 m). The edge steps further off now
/// (`plan/jump/`): 1.0027×.
#[test]
fn a_later_track_held_through_a_plateau_is_freed_further_off() {
    horizon_within("freed_far", 1.01, 3.738_24e6);
}
