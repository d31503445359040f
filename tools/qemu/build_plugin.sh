#!/usr/bin/env bash
# Builds the instruction-counting QEMU plugin (tools/qemu/insn_count.c)
# into target/qemu-plugin/ when missing or older than its sources, with
# the host's C compiler, and prints its path.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
out=${CARGO_TARGET_DIR:-$here/../../target}/qemu-plugin
so=$out/libinsn_count.so
if [ ! -f "$so" ] || [ "$here/insn_count.c" -nt "$so" ] || [ "$here/qemu-plugin-api.h" -nt "$so" ]; then
  mkdir -p "$out"
  ${CC:-cc} -O2 -Wall -Wextra -Werror -shared -fPIC -o "$so.tmp" "$here/insn_count.c" >&2
  mv "$so.tmp" "$so"
fi
echo "$so"
