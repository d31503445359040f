#!/usr/bin/env bash
# Installs what the on-target (QEMU) tests and benchmarks need, skipping
# whatever is present: the Cortex-M Rust targets, qemu-system-arm (apt,
# QEMU 7.2 on Debian bookworm), the ARM binutils (apt) and defmt-print
# (cargo install). Called by scripts/test-all.sh and .ci/run; safe to run
# again.
set -euo pipefail

for t in thumbv7em-none-eabihf thumbv7m-none-eabi; do
  rustup target list --installed | grep -qx "$t" || rustup target add "$t"
done

# (arm-none-eabi-objdump: the static stack bound, tools/qemu/stack_bound.py.)
missing=
command -v qemu-system-arm >/dev/null || missing="$missing qemu-system-arm"
command -v arm-none-eabi-objdump >/dev/null || missing="$missing binutils-arm-none-eabi"
if [ -n "$missing" ]; then
  sudo=
  [ "$(id -u)" = 0 ] || sudo=sudo
  $sudo apt-get update
  # shellcheck disable=SC2086 # (a list of packages)
  $sudo apt-get install -y --no-install-recommends $missing
fi

if ! command -v defmt-print >/dev/null; then
  cargo install defmt-print --locked
fi

# The benchmark plugin and the stack/size tools use the host's C compiler
# and binutils (nm, size), which the Rust toolchain needs anyway.
for tool in cc nm size; do
  command -v "$tool" >/dev/null || { echo "qemu-setup: $tool not found (install gcc and binutils)" >&2; exit 1; }
done
