#!/usr/bin/env python3
"""The f64 reference behind the `plan` tool's interface (cli.md), fixed mode only.

    python3 tools/reference/ref_plan.py --profile P.csv --waypoints W.csv \
        [--config V.toml] --depths z1,...,zM [--json] [--trajectory OUT.csv]

Evaluates exactly the given reference depths (no optimization) and prints the
same JSON object as `cargo run --example plan -- ... --depths ... --json`.
Used to test check_plan.py without the Rust tool
(`check_plan.py --bin-cmd "python3 tools/reference/ref_plan.py"`), and handy
for looking at one case.  Input errors: one line on stderr, exit status 2.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import sys
import tomllib

sys.dont_write_bytecode = True  # keep the source tree clean
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import auvref as ar  # noqa: E402


class InputError(Exception):
    pass


def load_profile(path):
    try:
        return ar.Profile.from_csv(path)
    except (OSError, ValueError) as e:
        raise InputError(f"{path}: {e}") from e


def load_waypoints(path):
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
        if not rows or "x_m" not in rows[0] or "wp" not in rows[0]:
            raise InputError(f"{path}: expected header wp,x_m[,...]")
        xs = [float(r["x_m"]) for r in rows]
    except (OSError, ValueError) as e:
        raise InputError(f"{path}: {e}") from e
    if not all(math.isfinite(x) for x in xs):
        raise InputError(f"{path}: non-finite x_m")
    if len(xs) < 2 or any(b <= a for a, b in zip(xs, xs[1:])):
        raise InputError(f"{path}: need >= 2 strictly increasing waypoints")
    return xs


def load_config(path):
    """The TOML as an overrides dict for auvref.Vehicle.from_config."""
    if path is None:
        return {}
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise InputError(f"{path}: {e}") from e


def run(profile, waypoints, config, depths):
    """(vehicle, trajectory, JSON-able result) of a fixed plan."""
    prof = load_profile(profile)
    X = load_waypoints(waypoints)
    over = load_config(config)
    try:
        v = ar.Vehicle.from_config(over)
    except (ar.ModelError, TypeError, ValueError, KeyError) as e:
        raise InputError(f"{config}: {e}") from e
    if X[0] < prof.x[0] or X[-1] > prof.x[-1]:
        raise InputError(f"{waypoints}: a waypoint lies outside the profile")
    if len(depths) != len(X) - 1:
        raise InputError(f"--depths: need {len(X) - 1} values, got {len(depths)}")
    tr, res = ar.evaluate_plan(v, prof, X, depths)
    h_a = v.min_altitude
    tracks = []
    for t, z in zip(res["tracks"], depths):
        tracks.append({
            "track": t["track"],
            "x_start": t["x_start"],
            "x_end": t["x_end"],
            "depth": z,
            "J": t["J"],
            "rms": t["rms"],
            "min_altitude": t["min_altitude"],
            "violation": t["violation"],
            "safe": t["min_altitude"] >= h_a,
            "iterations": 0,
            "evaluations": 0,
            "status": "fixed",
            "J_history": [],
        })
    out = {
        "method": "fixed",
        "mode": "fixed",
        "tracks": tracks,
        "total_J": res["total_J"],
        "min_altitude": res["min_altitude"],
        "safe": res["min_altitude"] >= h_a,
    }
    return v, prof, tr, out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--profile", required=True)
    ap.add_argument("--waypoints", required=True)
    ap.add_argument("--config")
    ap.add_argument("--depths", required=True)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--trajectory")
    a = ap.parse_args(argv)
    try:
        try:
            depths = [float(s) for s in a.depths.split(",")]
        except ValueError as e:
            raise InputError(f"--depths: {e}") from e
        if not all(math.isfinite(z) for z in depths):
            raise InputError("--depths: non-finite value")
        v, prof, tr, out = run(a.profile, a.waypoints, a.config, depths)
    except InputError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if a.trajectory:
        with open(a.trajectory, "w") as f:
            f.write("x_m,depth_m,bottom_m,target_m,pitch_deg,elevator_deg,reference_m\n")
            for k, x in enumerate(tr.x):
                b = prof(x) if x <= prof.x[-1] else float("nan")
                el = tr.elevator[k] if k < len(tr.elevator) else float("nan")
                r = tr.reference[k] if k < len(tr.reference) else float("nan")
                f.write(f"{x!r},{tr.depth[k]!r},{b!r},{b - v.reference_altitude!r},"
                        f"{tr.pitch[k]!r},{el!r},{r!r}\n")
    if a.json:
        print(json.dumps(out))
    else:
        print(f"{'track':>5} {'x_start':>9} {'x_end':>9} {'depth':>9} {'J':>14} "
              f"{'rms':>9} {'min_alt':>9} safe")
        for t in out["tracks"]:
            print(f"{t['track']:>5} {t['x_start']:>9.1f} {t['x_end']:>9.1f} "
                  f"{t['depth']:>9.2f} {t['J']:>14.6g} {t['rms']:>9.3f} "
                  f"{t['min_altitude']:>9.3f} {t['safe']}")
        print(f"total J {out['total_J']:.9g}  min altitude {out['min_altitude']:.4f}  "
              f"safe {out['safe']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
