#!/usr/bin/env bash
# Finds the panic sites that keep examples/qemu_panic_never.rs from linking
# with panic-never: builds the same example with an ordinary panic handler
# (`--cfg auvnav_panic_probe`, into target/panic-probe/), disassembles it
# with line records and prints, for every call into `core::panicking` (or
# `core::option::expect_failed`, `core::result::unwrap_failed`, slice index
# failures), the nearest source line in this crate's src/ and the function.
#
#   tools/qemu/panic_sites.sh [TARGET]     # default thumbv7em-none-eabihf
#
# Needs llvm-objdump: `rustup component add llvm-tools`.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
target=${1:-thumbv7em-none-eabihf}
objdump=$(rustc --print sysroot)/lib/rustlib/$(rustc -vV | sed -n 's/^host: //p')/bin/llvm-objdump
[ -x "$objdump" ] || { echo "panic_sites.sh: run rustup component add llvm-tools" >&2; exit 2; }
cd "$root"
RUSTFLAGS="--cfg auvnav_panic_probe" CARGO_TARGET_DIR=target/panic-probe \
  cargo build --release --target "$target" --example qemu_panic_never >&2
elf=target/panic-probe/$target/release/examples/qemu_panic_never
"$objdump" -d -C -l --no-show-raw-insn "$elf" | awk -v src="$root/src/" '
  /^[0-9a-f]+ <.*>:$/ { fn = $0; sub(/^[0-9a-f]+ </, "", fn); sub(/>:$/, "", fn); loc = ""; srcloc = ""; next }
  /^; \// { loc = substr($0, 3); if (index(loc, src) == 1) srcloc = substr(loc, length(src) - 3); next }
  fn !~ /^core::/ && /\tbl?\t/ && /(core::panicking::|expect_failed|unwrap_failed|slice_.*_fail|panic_bounds_check)/ {
    callee = $0; sub(/.*</, "", callee); sub(/>.*/, "", callee)
    key = (srcloc != "" ? srcloc : "(no src/ line; nearest " loc ")") "  in " fn "  calls " callee
    if (!(key in seen)) { seen[key] = 1; print key }
  }' | sort
