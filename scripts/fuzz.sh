#!/usr/bin/env bash
# Fuzzing with cargo fuzz (fuzz/, targets in fuzz/fuzz_targets/).
#
#   bash scripts/fuzz.sh [SECONDS] [TARGET...]
#
# Runs each target (default: all of them) for SECONDS (default 20: about a
# minute for the three), starting from its corpus (fuzz/corpus/TARGET, kept
# between runs, not committed), the committed seeds (fuzz/seeds/TARGET) and
# the inputs that once failed (fuzz/regressions/TARGET), so every one of
# those is replayed first. Fails on any crash, assertion failure, timeout
# or leak; libFuzzer leaves the input in fuzz/artifacts/TARGET/ (replay it
# with `cargo fuzz run TARGET FILE`, minimize it with `cargo fuzz tmin`).
# Prints the executions per target. Set-up is automatic: cargo-fuzz is
# installed if missing; the nightly toolchain is used if installed,
# otherwise stable with RUSTC_BOOTSTRAP=1 (cargo fuzz needs -Z flags).
#
# FUZZ_JOBS=N runs N workers per target (default 1). FUZZ_SANITIZER
# overrides the sanitizer (default address; `none` is about twice as fast
# and enough for this `forbid(unsafe_code)` crate).
set -euo pipefail
cd "$(dirname "$0")/.."

secs=${1:-20}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(planner simulate tool_input)
fi

if ! command -v cargo-fuzz >/dev/null 2>&1; then
  echo "fuzz: installing cargo-fuzz"
  cargo install cargo-fuzz --locked
fi

if rustup run nightly rustc --version >/dev/null 2>&1; then
  toolchain=(+nightly)
  echo "fuzz: $(rustup run nightly rustc --version)"
else
  toolchain=()
  export RUSTC_BOOTSTRAP=1
  echo "fuzz: no nightly toolchain; $(rustc --version) with RUSTC_BOOTSTRAP=1"
fi
sanitizer=(--sanitizer "${FUZZ_SANITIZER:-address}")
jobs=${FUZZ_JOBS:-1}

echo "fuzz: clippy on the harnesses, warnings denied"
cargo clippy --quiet --manifest-path fuzz/Cargo.toml --all-targets -- -D warnings

# -O: optimized; -a: debug assertions (and overflow checks) on.
build=(-O -a "${sanitizer[@]}")
echo "fuzz: building the targets (cargo fuzz build ${build[*]})"
for t in "${targets[@]}"; do
  cargo "${toolchain[@]}" fuzz build "${build[@]}" "$t"
done
parallel=()
if [ "$jobs" -gt 1 ]; then parallel=(-jobs="$jobs" -workers="$jobs"); fi
logdir=$(mktemp -d)
trap 'rm -rf "$logdir"' EXIT
summary=()
status=0
for t in "${targets[@]}"; do
  corpus=$PWD/fuzz/corpus/$t
  mkdir -p "$corpus"
  dirs=("$corpus")
  for d in "$PWD/fuzz/seeds/$t" "$PWD/fuzz/regressions/$t"; do
    if [ -d "$d" ]; then dirs+=("$d"); fi
  done
  dict=()
  if [ -f "fuzz/$t.dict" ]; then dict=(-dict="$PWD/fuzz/$t.dict"); fi
  echo "==> fuzz $t for ${secs}s"
  log=$logdir/$t.log
  start=$(date +%s)
  # -timeout: one input taking this long is a failure (the planner's time
  # is bounded by its caps; an execution takes milliseconds).
  if cargo "${toolchain[@]}" fuzz run "${build[@]}" "$t" "${dirs[@]}" -- \
    -max_total_time="$secs" -timeout=20 -print_final_stats=1 \
    "${parallel[@]}" "${dict[@]}" >"$log" 2>&1; then
    result=ok
  else
    result=FAILED
    status=1
    grep -E -A12 "panicked|ERROR: libFuzzer|SUMMARY|Test unit written" "$log" | head -60 || true
    echo "(full log: rerun this target; artifacts in fuzz/artifacts/$t/)"
  fi
  if [ "$jobs" -gt 1 ]; then cat fuzz-*.log >>"$log" 2>/dev/null || true; rm -f fuzz-*.log; fi
  elapsed=$(($(date +%s) - start))
  execs=$(grep -h "stat::number_of_executed_units" "$log" | awk '{s += $2} END {print s + 0}')
  files=$(find "$corpus" -type f | wc -l)
  summary+=("$(printf '%-11s %-6s %10s executions in %4s s (%s exec/s), corpus %s inputs' \
    "$t" "$result" "$execs" "$elapsed" "$((execs / (elapsed > 0 ? elapsed : 1)))" "$files")")
done
echo "==> fuzz summary"
printf '%s\n' "${summary[@]}"
exit $status
