#!/usr/bin/env bash
# Turns the output of the benchmark firmware (examples/qemu_bench.rs) and
# the instruction-counting plugin into the benchmark table (BENCHMARKS.md),
# on stdin -> stdout. Run by tools/qemu/run.sh, which prefixes the stream
# with `machine ...` and `elf ...` lines and ends it with `exit N`.
#
# Adds the memory figures of the planner application, the panic-free
# example qemu_panic_never (the planner and a minimal runtime): it builds
# that example for the same target first (`cargo build --release`, and once
# more at opt-level "s" with fat LTO into target/qemu-size-lto), then reads
# section sizes with binutils' `size`, checks for an allocator with `nm`
# and bounds a plan call's stack over every path (stack_bound.py).
#
# Also writes the rows as tab-separated values to
# target/qemu-bench/<machine>.tsv, which scripts/qemu-bench.sh merges into
# the M4F-vs-M3 comparison.
set -uo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)

input=$(cat)
machine=$(sed -n 's/^machine \([^ ]*\).*/\1/p' <<<"$input" | head -n1)
machine_line=$(sed -n 's/^machine //p' <<<"$input" | head -n1)
elf=$(sed -n 's/^elf //p' <<<"$input" | head -n1)
status=$(sed -n 's/^exit //p' <<<"$input" | tail -n1)

if ! grep -q '^done$' <<<"$input" || [ "${status:-1}" != 0 ]; then
  echo "$input"
  echo "bench_table.sh: the benchmark firmware did not finish (exit ${status:-?})" >&2
  exit 1
fi

# Target triple and target directory from the ELF path
# (<target-dir>/<triple>/release/examples/qemu_bench).
triple=$(basename "$(dirname "$(dirname "$(dirname "$elf")")")")
target_dir=$(dirname "$(dirname "$(dirname "$(dirname "$elf")")")")

# The planner application, as configured (release) and size-optimized.
app_sizes() { # ELF -> "text rodata data bss uninit"
  size -A "$1" | awk '$1==".text"{t=$2} $1==".rodata"{r=$2} $1==".data"{d=$2}
    $1==".bss"{b=$2} $1==".uninit"{u=$2} END{print t+0, r+0, d+0, b+0, u+0}'
}
has_alloc() { nm "$1" 2>/dev/null | grep -Eq ' (__rust_alloc|__rg_alloc|__rdl_alloc)$' && echo yes || echo no; }
(cd "$root" && cargo build --quiet --release --target "$triple" --example qemu_panic_never) >&2 ||
  { echo "bench_table.sh: cannot build qemu_panic_never for $triple" >&2; exit 1; }
app=$target_dir/$triple/release/examples/qemu_panic_never
read -r a_text a_ro a_data a_bss a_un <<<"$(app_sizes "$app")"
l_text=0 l_ro=0
if [ "$triple" = thumbv7em-none-eabihf ]; then # the size-optimized build: M4F only
  (cd "$root" && CARGO_TARGET_DIR="$target_dir/qemu-size-lto" cargo build --quiet --release \
    --target "$triple" --example qemu_panic_never --config 'profile.release.opt-level="s"' \
    --config 'profile.release.lto="fat"' --config 'profile.release.codegen-units=1') >&2 ||
    { echo "bench_table.sh: cannot build the size-optimized qemu_panic_never" >&2; exit 1; }
  read -r l_text l_ro _ _ _ <<<"$(app_sizes "$target_dir/qemu-size-lto/$triple/release/examples/qemu_panic_never")"
fi
alloc="$(has_alloc "$app")/$(has_alloc "$elf")"
# The static bound of a plan call's stack, every path (tools/qemu/stack_bound.py).
bound=$(python3 "$here/stack_bound.py" "$app" | sed -n 's/^stack-bound|//p')

mkdir -p "$target_dir/qemu-bench"
tsv=$target_dir/qemu-bench/$machine.tsv

awk -v machine_line="$machine_line" -v tsv="$tsv" \
  -v a_text="$a_text" -v a_ro="$a_ro" -v a_ram="$((a_data + a_bss + a_un))" \
  -v l_text="$l_text" -v l_ro="$l_ro" -v alloc="$alloc" -v bound="${bound:-0}" -F'|' '
function group(n,   s, neg) {   # 1234567 -> 1 234 567
  n = sprintf("%.0f", n); neg = (n ~ /^-/); if (neg) n = substr(n, 2)
  s = ""
  while (length(n) > 3) { s = " " substr(n, length(n) - 2) s; n = substr(n, 1, length(n) - 3) }
  return (neg ? "-" : "") n s
}
function kib(b) { return sprintf("%s B (%.1f KiB)", group(b), b / 1024) }
/^bench\|/ { id = $2; label[id] = $3; units[id] = $4; unit[id] = $5; order[++n] = id; next }
/^QEMU-BENCH / { split($0, w, " "); count[id] = w[2]; next }
/^note\|/ { note[$2] = (note[$2] == "" ? "" : note[$2] "; ") $3; next }
/^stack\|/ { stack[$2] = $3; next }
/^skip\|/ { skipped = skipped "\n" $2; next }
/^image\|/ { img_vec = $2; img_text = $3; img_ro = $4; img_ram = $5 + $6 + $7; next }
END {
  over = count["overhead"]
  print "Benchmark: " machine_line
  print ""
  print "Instruction counts (not cycles), counted by the QEMU TCG plugin tools/qemu/insn_count.c"
  print "between two marker calls, net of the markers'"'"' own " over " instructions. Exactly repeatable."
  print ""
  print "| measurement | instructions | per unit | notes |"
  print "|---|---:|---:|---|"
  printf "" > tsv
  steep = ""; steep_deg = -1
  for (i = 1; i <= n; i++) {
    id = order[i]; if (id == "overhead") continue
    net = count[id] - over
    if (id ~ /^tw_/) { split(note[id], p, "slope "); split(p[2], q, " "); if (q[1] + 0 > steep_deg) { steep_deg = q[1] + 0; steep = id } }
  }
  for (i = 1; i <= n; i++) {
    id = order[i]; if (id == "overhead") continue
    net = count[id] - over
    lab = label[id]; per = ""
    if (unit[id] == "step" || unit[id] == "km") per = group(net / units[id]) " / " unit[id]
    if (unit[id] == "step") lab = lab " (" group(units[id]) " steps)"
    if (unit[id] == "km") lab = lab " (" units[id] " km)"
    if (id ~ /^eval1_/) lab = lab ", track " substr(id, 7)
    if (id ~ /^(tw|hz|hc)_/) lab = lab ", track " substr(id, 4)
    if (id ~ /^m[0-9][hc]_/) lab = lab ", us_monterey_canyon_" substr(id, 2, 1) ", track " substr(id, 5)
    if (id ~ /^hz_/) { hz_sum += net; if (id == "hz_1") hz_cold = net; else if (net > hz_later) hz_later = net }
    if (id ~ /^hc_/) hc_sum += net
    nt = note[id]
    if (id == steep) nt = nt " **(steepest track)**"
    if (id in stack) nt = nt "; stack " group(stack[id]) " B"
    printf "| %s | %s | %s | %s |\n", lab, group(net), per, nt
    printf "%s\t%s\t%.0f\t%s\n", id, lab, net, per >> tsv
  }
  # The other lines benchmark (examples/qemu_lines.rs): per line, the
  # cold call, the worst later call and the whole line, nominal and
  # certified, against the targets of the paper line; nothing else.
  if (!("step" in count)) {
    print ""
    print "| line, planner | cold call | worst later call | whole line | targets (cold / later / line) |"
    print "|---|---:|---:|---:|---|"
    for (i = 1; i <= n; i++) {
      id = order[i]; if (id !~ /^m[0-9][hc]_/) continue
      key = substr(id, 1, 3); net = count[id] - over
      if (!(key in lsum)) { lkeys[++nl] = key; lcold[key] = net } else if (net > llater[key]) llater[key] = net
      lsum[key] += net
    }
    for (i = 1; i <= nl; i++) {
      key = lkeys[i]; c = (substr(key, 3, 1) == "c")
      printf "| us_monterey_canyon_%s, %s | %s | %s | %s | %s |\n", substr(key, 2, 1), c ? "certified" : "nominal", group(lcold[key]), group(llater[key]), group(lsum[key]), c ? "– / – / <= 800 000 000" : "<= 250 000 000 / <= 40 000 000 / <= 400 000 000"
    }
    exit
  }
  # Summary against the targets (reported, not asserted).
  tw_stack = 0; hz_stack = 0
  for (id in stack) { if (id ~ /^tw_/ && stack[id] > tw_stack) tw_stack = stack[id]; if (id ~ /^hz_/ && stack[id] > hz_stack) hz_stack = stack[id] }
  step = (count["step"] - over) / units["step"]
  print ""
  print "| against the targets | measured | target |"
  print "|---|---:|---|"
  printf "| instructions per simulated step | %s | <= 120 |\n", group(step)
  printf "| track-wise solve of the steepest track (%s, %.1f deg) | %s | <= 10 000 000 |\n", "track " substr(steep, 4), steep_deg, group(count[steep] - over)
  printf "| stack high-water mark of one solve, track-wise (Planner::<1>), worst track | %s | <= 8 KiB |\n", kib(tw_stack)
  printf "| stack high-water mark of one solve, horizon (Planner::<5>), worst call | %s | <= 8 KiB |\n", hz_stack ? kib(hz_stack) : "not run"
  printf "| stack of any plan call (Planner::<5>), static bound over every path (tools/qemu/stack_bound.py) | %s | <= 8 KiB |\n", (bound > 0 ? kib(bound) : "not a bound")
  if (hz_sum > 0) {
    printf "| horizon (Planner::<5>), cold call (track 1) | %s | <= 250 000 000 |\n", group(hz_cold)
    printf "| horizon (Planner::<5>), worst later call | %s | <= 40 000 000 |\n", group(hz_later)
    printf "| horizon (Planner::<5>), whole line, nominal | %s | <= 400 000 000 |\n", group(hz_sum)
  }
  if (hc_sum > 0) printf "| horizon (Planner::<5>), whole line, certified (declared uncertainty) | %s | <= 800 000 000 |\n", group(hc_sum)
  if (("eval5" in count) && ("step" in count)) printf "| objective+gradient K = 5 / plain flight of the line | %.2f | <= 2.5 |\n", (count["eval5"] - over) / (count["step"] - over)
  printf "| planner flash: .text + .rodata of the planner application, release (opt-level 3) | %s | <= 64 KiB |\n", kib(a_text + a_ro)
  if (l_text > 0) printf "| the same at opt-level \"s\", fat LTO, 1 codegen unit | %s | <= 64 KiB |\n", kib(l_text + l_ro)
  printf "| static RAM (.data + .bss + .uninit) of the planner application | %s | |\n", kib(a_ram)
  split(alloc, al, "/")
  printf "| heap | %s | zero |\n", (al[1] == "no" && al[2] == "no") ? "0 B: no allocator linked (planner application and benchmark image)" : "ALLOCATOR LINKED"
  if (skipped != "") { sub(/^\n/, "", skipped); print ""; print "Not run: " skipped }
  print ""
  printf "Planner application: examples/qemu_panic_never.rs (Planner::<5>, the line'"'"'s data, cortex-m-rt, semihosting exit; vector table apart), .text %s B + .rodata %s B.\n", group(a_text), group(a_ro)
  printf "Benchmark image: .text %s B, .rodata %s B, vector table %s B, .data + .bss %s B.\n", group(img_text), group(img_ro), group(img_vec), group(img_ram)
  printf "step\t%.1f\nsteep\t%s\ntw_stack\t%d\nhz_stack\t%d\nstack_bound\t%d\nflash\t%d\nflash_lto\t%d\nram\t%d\n", step, steep, tw_stack, hz_stack, bound, a_text + a_ro, l_text + l_ro, a_ram >> tsv
}' <<<"$input"
