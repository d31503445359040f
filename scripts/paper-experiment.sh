#!/usr/bin/env bash
# Reproduces the paper's experiment on real terrain (us_monterey_canyon_1,
# h_r = 80 m, h_a = 60 m, at most 200 iterations) with the host tool, writes
# the figures to docs/figures/ and rewrites the README section between the
# "experiment" markers. Needs only cargo and python3 (standard library).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet --example plan
out=$(mktemp -d)
cfg="$out/vehicle.toml"
printf 'reference_altitude = 80.0\nmin_altitude = 60.0\n[optimizer]\nmax_iterations = 200\n' > "$cfg"
prof=data/bathymetry/us_monterey_canyon_1.csv
wps=data/bathymetry/us_monterey_canyon_1.waypoints.csv
run() { # name, then plan arguments
  local name=$1; shift
  target/release/examples/plan --profile "$prof" --waypoints "$wps" --config "$cfg" --json \
    --plot "docs/figures/monterey1_$name.svg" "$@" > "$out/$name.json"
}
run track_bare_gd      --mode track --method gd   --unconstrained
run track_bare_bfgs    --mode track --method bfgs --unconstrained
run track_gd           --mode track --method gd
run track_bfgs         --mode track --method bfgs
run horizon_gd         --mode horizon --method gd
run horizon_bfgs       --mode horizon --method bfgs
python3 scripts/experiment_table.py "$out" README.md
echo "README.md and docs/figures/ updated"
