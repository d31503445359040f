#!/usr/bin/env bash
# Cargo runner for the Cortex-M targets (.cargo/config.toml): runs an ELF
# under QEMU and exits with the firmware's semihosting exit status.
#
#   tools/qemu/run.sh ELF [ARGS...]
#
# Machine: lm3s6965evb (Cortex-M3) for thumbv7m-none-eabi builds, else
# $QEMU_MACHINE, default mps2-an386 (Cortex-M4F); mps2-an500 is the
# Cortex-M7. Firmware that logs with defmt is decoded by defmt-print
# (`cargo install defmt-print --locked`). Firmware with the benchmark
# markers (auvnav_bench_start/stop) runs with the instruction-counting
# plugin tools/qemu/insn_count.c, built on first use with the host's cc,
# and its output is turned into a table by tools/qemu/bench_table.sh.
# Symbols are read with the host's binutils `nm` (installed with cc).
# A run that does not end within $QEMU_TIMEOUT seconds (default 600) fails.
# $QEMU_ICOUNT, if set, is passed as `-icount` (e.g. shift=3,sleep=off: a
# fixed virtual instruction rate, idle time skipped; the real-time example).
set -uo pipefail

elf=${1:?usage: run.sh ELF}
shift
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

case "$elf" in
  */thumbv7m-none-eabi/*) machine=${QEMU_MACHINE:-lm3s6965evb} ;;
  *) machine=${QEMU_MACHINE:-mps2-an386} ;;
esac
case "$machine" in
  lm3s6965evb) cpu=cortex-m3 ;;
  mps2-an500) cpu=cortex-m7 ;;
  mps2-an386) cpu=cortex-m4 ;;
  *) echo "run.sh: unknown machine $machine" >&2; exit 2 ;;
esac

qemu=(timeout --foreground "${QEMU_TIMEOUT:-600}" qemu-system-arm
  -machine "$machine" -cpu "$cpu" -nographic -monitor none -serial none
  -semihosting-config enable=on,target=native -kernel "$elf"
  ${QEMU_ICOUNT:+-icount "$QEMU_ICOUNT"})

syms=$(nm -- "$elf" 2>/dev/null) || syms=
if grep -q ' auvnav_bench_start$' <<<"$syms"; then
  plugin=$("$here/build_plugin.sh") || exit 2
  {
    echo "machine $machine ($cpu), $(qemu-system-arm --version | head -n1)"
    echo "elf $elf"
    "${qemu[@]}" -plugin "$plugin"
    echo "exit $?"
  } | "$here/bench_table.sh"
  exit "${PIPESTATUS[0]}"
elif grep -q ' _defmt_acquire$' <<<"$syms"; then
  command -v defmt-print >/dev/null ||
    { echo "run.sh: defmt-print not found (cargo install defmt-print --locked)" >&2; exit 2; }
  "${qemu[@]}" | defmt-print -e "$elf"
  status=${PIPESTATUS[0]}
else
  "${qemu[@]}"
  status=$?
fi
if [ "$status" = 124 ]; then
  echo "run.sh: $elf did not finish within ${QEMU_TIMEOUT:-600} s on $machine" >&2
fi
exit "$status"
