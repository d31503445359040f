//! Shared by the tests that run the `plan` tool as a user does
//! (`tests/cli.rs`, `tests/cli_map.rs`, `tests/fly.rs`, `tests/boundary.rs`,
//! `tests/vehicles.rs`): where the binary is, one run of it, its JSON, and
//! the paths of a fixture.
//!
//! `cargo test` builds the examples before it runs the tests, so the tool
//! is found beside the test binary. (A filtered `cargo test --test NAME`
//! does not rebuild it: run `cargo build --example plan` first.)
#![allow(dead_code)]
#![allow(clippy::unwrap_used, clippy::panic)]

use std::path::PathBuf;
use std::process::{Command, Output};

/// The `plan` example's binary, beside this test binary.
pub fn tool() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let dir = exe.parent().unwrap().parent().unwrap();
    let p = dir
        .join("examples")
        .join(format!("plan{}", std::env::consts::EXE_SUFFIX));
    assert!(
        p.exists(),
        "{} not built: run `cargo build --examples` first (scripts/test-all.sh does)",
        p.display()
    );
    p
}

/// `plan ARGS...`, its status and output.
pub fn run(args: &[&str]) -> Output {
    Command::new(tool()).args(args).output().unwrap()
}

/// `plan ARGS...` that must succeed: its JSON output.
pub fn json_of(args: &[&str]) -> serde_json::Value {
    let out = run(args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The paths of fixture `name` in `tests/fixtures/horizon`: its profile,
/// waypoints and vehicle (`NAME.csv`, `NAME.waypoints.csv`, `NAME.toml`;
/// the last need not exist).
pub fn fixture(name: &str) -> (String, String, String) {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/horizon");
    (
        format!("{dir}/{name}.csv"),
        format!("{dir}/{name}.waypoints.csv"),
        format!("{dir}/{name}.toml"),
    )
}

/// `plan ARGS... --json` on fixture `name`, with its vehicle where
/// `NAME.toml` exists (else the default vehicle): the JSON output.
pub fn json_of_fixture(name: &str, args: &[&str]) -> serde_json::Value {
    let (p, w, c) = fixture(name);
    let mut all = vec!["--profile", &p, "--waypoints", &w];
    if std::path::Path::new(&c).exists() {
        all.extend(["--config", &c]);
    }
    all.extend(args);
    all.push("--json");
    json_of(&all)
}

/// The horizon plan of fixture `name` is safe and its line `J` within
/// `ratio` of `best` (m³), the f64 beam search's best safe plan.
pub fn horizon_within(name: &str, ratio: f64, best: f64) {
    let v = json_of_fixture(name, &[]);
    let total = v["total_J"].as_f64().unwrap();
    assert_eq!(v["safe"], true);
    assert!(total <= ratio * best, "J {total} vs the best safe {best}");
}

/// Track `i` (from 0) of `plan ARGS... --json` on fixture `name`, after
/// the premise (as [`tracks_of`]), its `J` within 0.5 % of `best` (m³):
/// the f64 search's best from the same start, the checker's bound for a
/// track.
pub fn track_within(
    name: &str,
    args: &[&str],
    premise: &[(usize, f64)],
    i: usize,
    best: f64,
) -> serde_json::Value {
    let t = tracks_of(name, args, premise)[i].clone();
    let j = t["J"].as_f64().unwrap();
    assert!(
        j <= 1.005 * best,
        "track {}: J {j} vs the best {best}",
        i + 1
    );
    t
}

/// The tracks of `plan ARGS... --json` on fixture `name`, after checking
/// the premise: track `i`'s depth within 1 cm of `depth` (m) for each
/// `(i, depth)` of `premise`.
pub fn tracks_of(name: &str, args: &[&str], premise: &[(usize, f64)]) -> Vec<serde_json::Value> {
    let v = json_of_fixture(name, args);
    let tracks = v["tracks"].as_array().unwrap().clone();
    for &(i, z) in premise {
        let d = tracks[i]["depth"].as_f64().unwrap();
        assert!(
            (d - z).abs() < 0.01,
            "track {} at {d}: not the premise",
            i + 1
        );
    }
    tracks
}
