//! Shared by the tests that run the `plan` tool as a user does
//! (`tests/cli.rs`, `tests/cli_map.rs`, `tests/fly.rs`): where the binary
//! is, and one run of it.
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
