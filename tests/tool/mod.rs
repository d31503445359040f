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
