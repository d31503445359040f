#!/usr/bin/env bash
# Runs every test of the project, host and target, doing its own set-up.
# This is the README's test command; CI (.ci/run) calls it too. The
# on-target part (scripts/qemu-test.sh) installs qemu-system-arm and
# defmt-print when missing (scripts/qemu-setup.sh).
set -euo pipefail
cd "$(dirname "$0")/.."

say() { printf '\n==> %s\n' "$*"; }

say "set-up: Rust targets"
for t in thumbv7em-none-eabihf thumbv7m-none-eabi; do
  rustup target list --installed | grep -qx "$t" || rustup target add "$t"
done

say "host: cargo test (unit, golden fixtures, tool interface, doctests)"
# tests/cli.rs runs the real `plan` binary: build the examples as binaries
# first (`--all-targets` alone builds them only as test harnesses).
cargo build --examples
cargo test --all-targets
cargo test --doc

say "host: property tests, 10,000 random terrains (release)"
cargo test --release --test properties -- --nocapture

say "host: recursive feasibility, 1,500 random lines against a whole-line search; certificate in sampled worlds (release)"
# tests/certified.rs and tests/between.rs also run the release `plan`
# binary (the tool's line).
cargo build --release --example plan
cargo test --release --test feasibility --test certified --test between -- --nocapture

say "target: the library builds for Cortex-M4F (thumbv7em-none-eabihf), with and without defmt"
cargo build --lib --release --target thumbv7em-none-eabihf
cargo build --lib --release --target thumbv7em-none-eabihf --features defmt
cargo build --lib --release --target thumbv7m-none-eabi

say "target: on-target tests under QEMU (Cortex-M4F, M7, M3), panic-freedom proof, defmt log"
bash scripts/qemu-test.sh

say "C interface: header, host gcc and arm-none-eabi-gcc under QEMU, panic-never link (crates/auvnav-c)"
bash scripts/c-test.sh

say "all tests passed"
