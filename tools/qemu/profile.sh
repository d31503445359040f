#!/usr/bin/env bash
# Where the instructions go: runs a firmware ELF under QEMU with the
# counting plugin in profile mode and prints the TOP (default 25)
# functions by instructions executed over the whole run, demangled.
#
#   tools/qemu/profile.sh target/thumbv7em-none-eabihf/release/examples/qemu_bench [TOP]
#   tools/qemu/profile.sh --hot ELF [TOP]   # the hottest blocks, by address
#
# Machine as tools/qemu/run.sh ($QEMU_MACHINE, lm3s6965evb for thumbv7m).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
mode=profile
if [ "${1:-}" = --hot ]; then
  mode=hot
  shift
fi
elf=${1:?usage: profile.sh [--hot] ELF [TOP]}
top=${2:-25}
case "$elf" in
  */thumbv7m-none-eabi/*) machine=${QEMU_MACHINE:-lm3s6965evb} ;;
  *) machine=${QEMU_MACHINE:-mps2-an386} ;;
esac
case "$machine" in
  lm3s6965evb) cpu=cortex-m3 ;; mps2-an500) cpu=cortex-m7 ;; *) cpu=cortex-m4 ;;
esac
plugin=$("$here/build_plugin.sh")
timeout --foreground "${QEMU_TIMEOUT:-600}" qemu-system-arm -machine "$machine" -cpu "$cpu" \
  -nographic -monitor none -serial none -semihosting-config enable=on,target=native \
  -kernel "$elf" -plugin "$plugin,$mode=$top" |
  grep -a -E '^QEMU-(PROFILE|HOT|TOTAL) ' |
  awk '{ s = $3; for (i = 4; i <= NF; i++) s = s " " $i; printf "%14s  %s\n", ($1 == "QEMU-TOTAL" ? $2 " total" : $2), s }' |
  c++filt
