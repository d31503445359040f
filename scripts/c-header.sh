#!/usr/bin/env bash
# The C interface's header, crates/auvnav-c/include/auvnav.h, generated
# from the crate's source by cbindgen at a pinned version (installed here
# when missing: a debug build, enough for a code generator and faster to
# compile).
#   scripts/c-header.sh           regenerate the header
#   scripts/c-header.sh --check   fail if the checked-in header differs (CI)
set -euo pipefail
cd "$(dirname "$0")/.."

CBINDGEN_VERSION=0.29.4
if ! cbindgen --version 2>/dev/null | grep -qx "cbindgen $CBINDGEN_VERSION"; then
  cargo install --debug --locked cbindgen --version "$CBINDGEN_VERSION"
fi

header=crates/auvnav-c/include/auvnav.h
gen() { (cd crates/auvnav-c && cbindgen --quiet --config cbindgen.toml --crate auvnav-c --output "$1" .); }
if [ "${1:-}" = --check ]; then
  tmp=$(mktemp)
  trap 'rm -f "$tmp"' EXIT
  gen "$tmp"
  if ! diff -u "$header" "$tmp"; then
    echo "c-header: $header does not match the source: run scripts/c-header.sh" >&2
    exit 1
  fi
  echo "c-header: $header matches the source (cbindgen $CBINDGEN_VERSION)"
else
  gen "$PWD/$header"
fi
