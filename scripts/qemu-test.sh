#!/usr/bin/env bash
# Every on-target check under QEMU; scripts/test-all.sh (the README's test
# command) and .ci/run call it. Fails if any test fails.
#
#   1. `cargo qemu-test`: the golden fixtures, the paper's plans bit for bit
#      and the smoke test on the Cortex-M4F (mps2-an386);
#   2. the smoke test on the Cortex-M7 (mps2-an500) and on the soft-float
#      Cortex-M3 (lm3s6965evb, thumbv7m-none-eabi);
#   3. the panic-freedom proof: examples/qemu_panic_never.rs links with
#      panic-never in release, for both targets, and runs on the M4F; its
#      plan call's stack bounded over every path, at most 8 KiB on both
#      (tools/qemu/stack_bound.py, tested by test_stack_bound.py);
#   4. the defmt log example, decoded (cargo qemu-log);
#   5. the real-time example (examples/qemu_realtime.rs): 0 deadline misses
#      of the 10 Hz control task over a whole line, under -icount;
#   6. the same under RTIC 2 (crates/auvnav-rtic, its own workspace).
# The benchmarks are scripts/qemu-bench.sh (CI runs them too).
set -euo pipefail
cd "$(dirname "$0")/.."

say() { printf '\n==> %s\n' "$*"; }
bash scripts/qemu-setup.sh

say "target: cargo qemu-test (Cortex-M4F, QEMU mps2-an386): fixtures, plans, smoke"
cargo qemu-test

say "target: smoke test on the Cortex-M7 (QEMU mps2-an500)"
QEMU_MACHINE=mps2-an500 cargo test --release --target thumbv7em-none-eabihf --test qemu_smoke

say "target: smoke test on the soft-float Cortex-M3 (QEMU lm3s6965evb)"
cargo test --release --target thumbv7m-none-eabi --test qemu_smoke

say "target: panic-freedom proof (panic-never links in release), M4F and M3; run on the M4F"
cargo build --release --target thumbv7m-none-eabi --example qemu_panic_never
cargo run --release --target thumbv7em-none-eabihf --example qemu_panic_never

say "target: a plan call's stack, static bound over every path, <= 8 KiB (M4F and M3)"
python3 tools/qemu/test_stack_bound.py
target_dir=$(cargo metadata --format-version 1 --no-deps 2>/dev/null |
  sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
for t in thumbv7em-none-eabihf thumbv7m-none-eabi; do
  python3 tools/qemu/stack_bound.py "${target_dir:-target}/$t/release/examples/qemu_panic_never" --limit 8192
done

say "target: the planner's progress as a decoded defmt log (cargo qemu-log)"
cargo qemu-log

say "target: real-time integration (timer-driven control at 10 Hz, resumable planner in the main loop, -icount)"
QEMU_ICOUNT=shift=3,sleep=off cargo run --release --target thumbv7em-none-eabihf --example qemu_realtime

say "target: real-time integration under RTIC 2 (crates/auvnav-rtic: TIMER0 task at 10 Hz, planner as a software task)"
(cd crates/auvnav-rtic && QEMU_ICOUNT=shift=3,sleep=off cargo run --release)

say "all on-target tests passed"
