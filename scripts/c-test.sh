#!/usr/bin/env bash
# The C interface's tests (crates/auvnav-c, README "From C"); called by
# scripts/test-all.sh. Installs arm-none-eabi-gcc and newlib (apt) when
# missing, then:
#   1. the static library for the host (release) and for the Cortex-M4F
#      (thumbv7em-none-eabihf, profile `capi`: fat LTO);
#   2. `plan --json --horizon 5` on every shared profile, and lines.h, the
#      C test's data (the profiles and the tool's values) from them;
#   3. the C test program (tests/c/test_auvnav.c, C99, -Wall -Wextra
#      -Werror -pedantic) built with the host's gcc and run;
#   4. the same program built with arm-none-eabi-gcc against the M4F
#      library, linked WITHOUT the panic hook `auvnav_panic` (the link
#      succeeds only if no panic path is left: the panic-never proof of
#      the C library), and run under QEMU mps2-an386 (semihosting), which
#      also measures each call's worst stack.
set -euo pipefail
cd "$(dirname "$0")/.."
say() { printf '\n==> %s\n' "$*"; }

bash scripts/qemu-setup.sh
if ! command -v arm-none-eabi-gcc >/dev/null || [ ! -d /usr/lib/arm-none-eabi/newlib ]; then
  sudo=
  [ "$(id -u)" = 0 ] || sudo=sudo
  $sudo apt-get update
  $sudo apt-get install -y --no-install-recommends gcc-arm-none-eabi libnewlib-arm-none-eabi
fi

out=target/c-test
src=crates/auvnav-c/tests/c
inc=crates/auvnav-c/include
mkdir -p "$out/json"

say "C: the interface crate's unit tests"
cargo test -p auvnav-c

say "C: the static library, host (release) and Cortex-M4F (profile capi: fat LTO)"
cargo build --release -p auvnav-c
cargo build --profile capi -p auvnav-c --target thumbv7em-none-eabihf
cargo build --release --example plan

say "C: plan --json --horizon 5 on every shared profile, and the C test's data"
for wp in data/bathymetry/*.waypoints.csv; do
  name=$(basename "$wp" .waypoints.csv)
  case "$name" in
    us_monterey_canyon_*) alt="reference_altitude = 80\nmin_altitude = 60" ;;
    es_medes_islands_*) alt="reference_altitude = 5\nmin_altitude = 3" ;;
    jp_aburatsubo_sagami_*) alt="reference_altitude = 2\nmin_altitude = 1" ;;
    *) echo "c-test: no altitudes for $name" >&2; exit 1 ;;
  esac
  printf "$alt\n" > "$out/json/$name.toml"
  target/release/examples/plan --profile "data/bathymetry/$name.csv" --waypoints "$wp" \
    --config "$out/json/$name.toml" --json --horizon 5 > "$out/json/$name.json"
done
python3 "$src/gen_lines.py" data/bathymetry "$out/json" "$out/lines.h"

say "C: host gcc, C99 pedantic, run"
strict=(-std=c99 -Wall -Wextra -Werror -pedantic -O2 -I"$inc" -I"$out")
native=$(cargo rustc --release -p auvnav-c --lib --crate-type staticlib -- --print native-static-libs 2>&1 \
  | sed -n 's/.*native-static-libs: //p' | tail -1)
# shellcheck disable=SC2086 # the native libraries are separate words
gcc "${strict[@]}" "$src/test_auvnav.c" "$src/io_host.c" target/release/libauvnav_c.a $native -o "$out/test_host"
"$out/test_host"

say "C: arm-none-eabi-gcc (Cortex-M4F), linked without the panic hook (panic-never proof), QEMU mps2-an386"
m4f=(-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 -O2 -ffunction-sections -fdata-sections)
arm-none-eabi-gcc "${m4f[@]}" "${strict[@]}" -c "$src/test_auvnav.c" -o "$out/test_auvnav.o"
arm-none-eabi-gcc "${m4f[@]}" -std=gnu99 -Wall -Wextra -Werror -c "$src/io_semihost.c" -o "$out/io_semihost.o"
arm-none-eabi-gcc "${m4f[@]}" "$out/test_auvnav.o" "$out/io_semihost.o" \
  target/thumbv7em-none-eabihf/capi/libauvnav_c.a -nostdlib -T "$src/mps2.ld" \
  -Wl,--gc-sections -Wl,-z,noexecstack -lgcc -o "$out/test_m4f.elf"
arm-none-eabi-size "$out/test_m4f.elf"
timeout 600 qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic -monitor none -serial none \
  -semihosting-config enable=on,target=native -kernel "$out/test_m4f.elf"

say "C interface: all tests passed"
