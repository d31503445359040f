#!/usr/bin/env python3
"""End-to-end cross-check of the Rust `plan` tool against the f64 reference.

    python3 tools/reference/check_plan.py [-n 30] [--seed 1] [--bin-cmd CMD]

Generates N random, unseen cases (random-walk bottom profile, waypoints,
vehicle config, depth plan), writes PROFILE.csv / WAYPOINTS.csv / VEHICLE.toml
into a temporary directory, runs

    cargo run --release --quiet --example plan -- --profile P --waypoints W \
        --config V --depths z1,...,zM --json

from the repository root (override the part before the arguments with
--bin-cmd, e.g. --bin-cmd target/release/examples/plan), parses its JSON
(cli.md) and compares, per track, J and rms (relative 1e-4), min_altitude
(1e-2 m), and total_J and the overall min_altitude.  One line per case, then
exactly `N passed, M failed`; exit status 1 if any case failed.

The reference reads back the very files it wrote, so both sides see the same
numbers.  Self-test without Rust:
    python3 tools/reference/check_plan.py --bin-cmd "python3 tools/reference/ref_plan.py"
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.dont_write_bytecode = True  # keep the source tree clean
sys.path.insert(0, HERE)
import auvref as ar  # noqa: E402
import ref_plan  # noqa: E402

DEFAULT_CMD = "cargo run --release --quiet --example plan --"

PLANTS = {
    "cauv4": {"kind": "pitch", "num": [-0.173], "den": [1.0, 2.681, 0.546, 0.048]},
    "cauv4_rate": {"kind": "rate", "num": [-0.173, 0.0], "den": [1.0, 2.681, 0.546, 0.048]},
    "remus_class": {"kind": "pitch", "num": [-0.62], "den": [1.0, 1.45, 0.29]},
    "fourth_order": {"kind": "pitch", "num": [-0.05, -0.2], "den": [1.0, 3.2, 3.1, 0.9, 0.08]},
    "integrator": {"kind": "pitch", "num": [-0.4], "den": [1.0, 1.1, 0.0]},
    "positive_gain": {"kind": "pitch", "num": [0.5], "den": [1.0, 1.2, 0.35]},
}


def sig(v, digits=4):
    """Round to `digits` significant figures (tidy config values)."""
    return float(f"{v:.{digits}g}")


# --------------------------------------------------------------------------
# Random case generation
# --------------------------------------------------------------------------


def random_profile(rng: random.Random):
    """Random-walk bottom: slope angle random walk up to ±50 deg, depth 50..1500 m."""
    length = rng.uniform(800.0, 4000.0)
    spacing = rng.uniform(2.0, 30.0)
    jitter = rng.random() < 0.5  # non-uniform spacing half of the time
    x0 = 0.0 if rng.random() < 0.7 else round(rng.uniform(10.0, 2000.0), 2)
    xs = [x0]
    while xs[-1] < x0 + length:
        dx = spacing * (rng.uniform(0.5, 1.5) if jitter else 1.0)
        xs.append(round(xs[-1] + max(dx, 0.5), 2))
    b = rng.uniform(150.0, 1400.0)
    ang = rng.uniform(-20.0, 20.0)
    step_sigma = rng.uniform(1.0, 10.0)  # deg per sample: smooth .. rugged
    bs = [round(b, 2)]
    for i in range(1, len(xs)):
        ang = max(-50.0, min(50.0, ang + rng.gauss(0.0, step_sigma)))
        if rng.random() < 0.02:  # occasional flat stretch or a sharp break
            ang = 0.0 if rng.random() < 0.5 else rng.uniform(-50.0, 50.0)
        nb = b + math.tan(math.radians(ang)) * (xs[i] - xs[i - 1])
        if not 50.0 <= nb <= 1500.0:
            ang = -ang
            nb = b + math.tan(math.radians(ang)) * (xs[i] - xs[i - 1])
            nb = min(1500.0, max(50.0, nb))
        b = nb
        bs.append(round(b, 2))
    return xs, bs


def random_waypoints(rng: random.Random, xs, force_inside=False):
    lo, hi = xs[0], xs[-1]
    L = hi - lo
    M = rng.randint(2, 6)
    inside = force_inside or rng.random() < 0.3
    if inside:
        a = round(lo + rng.uniform(0.01, 0.15) * L, 1)
        b = round(hi - rng.uniform(0.01, 0.15) * L, 1)
        a = max(a, lo + 0.1)
        b = min(b, hi - 0.1)
    else:
        a, b = lo, hi
    min_gap = min(50.0, (b - a) / (2 * M))
    for _ in range(1000):
        mids = sorted(round(rng.uniform(a, b), 1) for _ in range(M - 1))
        X = [a] + mids + [b]
        if all(X[i + 1] - X[i] >= min_gap for i in range(M)):
            return X
    return [a + (b - a) * i / M for i in range(M + 1)]


def random_vehicle(rng: random.Random, prof: ar.Profile, X0: float):
    """A random valid config dict (TOML overrides) with a stable small-signal loop."""
    for _ in range(100):
        cfg = {}
        cfg["speed"] = sig(rng.uniform(0.8, 2.5))
        cfg["sample_time"] = sig(rng.uniform(0.05, 0.25), 3)
        cfg["pitch_limit"] = sig(rng.uniform(10.0, 30.0))
        if rng.random() < 0.3:
            cfg["elevator_limit"] = sig(rng.uniform(15.0, 30.0))
        # (h_r less than the water at X0, where the vehicle starts at
        # b(X0) - h_r; the same draw otherwise)
        h_r = sig(min(rng.uniform(20.0, 100.0), 0.9 * prof(X0)))
        cfg["reference_altitude"] = h_r
        cfg["min_altitude"] = sig(h_r * rng.uniform(0.4, 0.9))
        d = ar.DEFAULT_VEHICLE
        cfg["depth_pid"] = {k: sig(d["depth_pid"][k] * rng.uniform(0.7, 1.3))
                            for k in ("kp", "ki", "kd")}
        if rng.random() < 0.25:
            cfg["depth_pid"]["ki"] = sig(rng.uniform(0.005, 0.03))
        cfg["pitch_pid"] = {k: sig(d["pitch_pid"][k] * rng.uniform(0.7, 1.3))
                            for k in ("kp", "ki", "kd")}
        u = rng.random()
        name = ("cauv4" if u < 0.55 else "remus_class" if u < 0.7 else
                "cauv4_rate" if u < 0.85 else
                rng.choice(["fourth_order", "integrator", "positive_gain"]))
        cfg["plant"] = dict(PLANTS[name])
        if rng.random() < 0.3:
            cfg["initial_depth"] = sig(prof(X0) - h_r + rng.uniform(-40.0, 40.0), 6)
            # (above the bottom: the draw reaches 40 m below b - h_r, and
            # h_r may be as little as 20 m)
            cfg["initial_depth"] = max(min(cfg["initial_depth"], sig(prof(X0) - 0.3 * h_r, 6)), 1.0)
        if rng.random() < 0.2:
            cfg["optimizer"] = {"max_iterations": rng.choice([50, 100, 200])}
        # drop some keys now and then: the tool must fill in the defaults
        if name == "cauv4" and rng.random() < 0.4:
            del cfg["plant"]
        if rng.random() < 0.2:
            del cfg["pitch_pid"]
        if rng.random() < 0.15:
            del cfg["depth_pid"]
        v = ar.Vehicle.from_config(cfg)
        if ar.spectral_radius(v) < 0.9995:
            return cfg, name
    raise RuntimeError("could not draw a stable vehicle")


def random_depths(rng: random.Random, prof: ar.Profile, X, h_r, d0, limits):
    M = len(X) - 1
    u = rng.random()
    kind = ("target_noise" if u < 0.5 else "midpoint" if u < 0.7 else
            "constant" if u < 0.85 else "uniform")
    if kind == "target_noise":
        z = [prof(X[n]) - h_r + rng.gauss(0.0, 0.3 * h_r) for n in range(1, M + 1)]
    elif kind == "midpoint":
        z = [prof(0.5 * (X[n - 1] + X[n])) - h_r for n in range(1, M + 1)]
    elif kind == "constant":
        z = [d0] * M
    else:
        lo = min(prof.b) - h_r - 50.0
        hi = max(prof.b) - h_r + 50.0
        z = [rng.uniform(lo, hi) for _ in range(M)]
    lo, hi = limits
    return kind, [round(min(hi, max(lo + 1.0, v)), 2) for v in z]


# --------------------------------------------------------------------------
# Files
# --------------------------------------------------------------------------


def fmt(v):
    """A float for CSV/TOML: shortest repr, never exponent notation."""
    s = repr(float(v))
    if "e" in s or "E" in s:
        s = f"{float(v):.12f}".rstrip("0")
        if s.endswith("."):
            s += "0"
    return s


def write_profile(path, xs, bs):
    with open(path, "w") as f:
        f.write("x_m,bottom_depth_m\n")
        for x, b in zip(xs, bs):
            f.write(f"{x:.2f},{b:.2f}\n")


def write_waypoints(path, X):
    with open(path, "w") as f:
        f.write("wp,x_m\n")
        for i, x in enumerate(X):
            f.write(f"{i},{fmt(x)}\n")


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return fmt(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    raise TypeError(type(v))


def write_toml(path, cfg):
    lines = []
    for k, v in cfg.items():
        if not isinstance(v, dict):
            lines.append(f"{k} = {toml_value(v)}")
    for k, v in cfg.items():
        if isinstance(v, dict):
            lines.append("")
            lines.append(f"[{k}]")
            for kk, vv in v.items():
                lines.append(f"{kk} = {toml_value(vv)}")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


# --------------------------------------------------------------------------
# Comparison
# --------------------------------------------------------------------------


class Tol:
    def __init__(self, a):
        self.rel = a.rtol
        self.j_abs = a.j_atol
        self.rms_abs = a.rms_atol
        self.alt = a.alt_tol


def close_rel(a, b, rel, floor):
    return abs(a - b) <= rel * max(abs(a), abs(b)) + floor


def compare(ref: dict, got: dict, tol: Tol):
    """List of problems (empty: pass) and the worst deviations seen."""
    bad = []
    worst = {"J": 0.0, "rms": 0.0, "alt": 0.0}

    def rel(a, b):
        return abs(a - b) / max(abs(a), abs(b), 1e-300)

    try:
        tracks = got["tracks"]
        if len(tracks) != len(ref["tracks"]):
            return [f"{len(tracks)} tracks, expected {len(ref['tracks'])}"], worst
        for t_ref, t in zip(ref["tracks"], tracks):
            n = t_ref["track"]
            if t.get("track") != n:
                bad.append(f"track numbering {t.get('track')} != {n}")
            for key in ("x_start", "x_end", "depth"):
                if abs(float(t[key]) - t_ref[key]) > 1e-5 * max(1.0, abs(t_ref[key])):
                    bad.append(f"track {n} {key} {t[key]!r} != {t_ref[key]!r}")
            J, rms, alt = float(t["J"]), float(t["rms"]), float(t["min_altitude"])
            worst["J"] = max(worst["J"], rel(J, t_ref["J"]))
            worst["rms"] = max(worst["rms"], rel(rms, t_ref["rms"]))
            worst["alt"] = max(worst["alt"], abs(alt - t_ref["min_altitude"]))
            if not close_rel(J, t_ref["J"], tol.rel, tol.j_abs):
                bad.append(f"track {n} J {J!r} vs ref {t_ref['J']!r} "
                           f"(rel {rel(J, t_ref['J']):.2e})")
            if not close_rel(rms, t_ref["rms"], tol.rel, tol.rms_abs):
                bad.append(f"track {n} rms {rms!r} vs ref {t_ref['rms']!r} "
                           f"(rel {rel(rms, t_ref['rms']):.2e})")
            if not abs(alt - t_ref["min_altitude"]) <= tol.alt:
                bad.append(f"track {n} min_altitude {alt!r} vs ref "
                           f"{t_ref['min_altitude']!r}")
        tJ = float(got["total_J"])
        worst["J"] = max(worst["J"], rel(tJ, ref["total_J"]))
        if not close_rel(tJ, ref["total_J"], tol.rel, tol.j_abs):
            bad.append(f"total_J {tJ!r} vs ref {ref['total_J']!r}")
        ma = float(got["min_altitude"])
        if not abs(ma - ref["min_altitude"]) <= tol.alt:
            bad.append(f"min_altitude {ma!r} vs ref {ref['min_altitude']!r}")
        if got.get("method") != "fixed":
            bad.append(f"method {got.get('method')!r}, expected 'fixed'")
    except (KeyError, TypeError, ValueError) as e:
        bad.append(f"malformed JSON output: {e!r}")
    return bad, worst


# --------------------------------------------------------------------------
# Driver
# --------------------------------------------------------------------------


def make_case(rng: random.Random, index: int, force_inside: bool):
    for _ in range(20):
        xs, bs = random_profile(rng)
        prof = ar.Profile(xs, bs)
        X = random_waypoints(rng, xs, force_inside)
        cfg, plant_name = random_vehicle(rng, prof, X[0])
        full = ar.full_config(cfg)
        h_r = full["reference_altitude"]
        d0 = full["initial_depth"] if full["initial_depth"] is not None else prof(X[0]) - h_r
        kind, z = random_depths(rng, prof, X, h_r, d0, full["depth_limits"])
        return {"index": index, "xs": xs, "bs": bs, "X": X, "cfg": cfg,
                "plant": plant_name, "plan": kind, "depths": z}
    raise RuntimeError("case generation failed")


def describe(c):
    cfg = ar.full_config(c["cfg"])
    L = c["xs"][-1] - c["xs"][0]
    inside = c["X"][0] > c["xs"][0] or c["X"][-1] < c["xs"][-1]
    return (f"L={L:.0f}m S={len(c['xs'])} M={len(c['X']) - 1}"
            f"{' inner-wps' if inside else ''} U0={cfg['speed']} Ts={cfg['sample_time']} "
            f"thmax={cfg['pitch_limit']} plant={c['plant']} plan={c['plan']}"
            f"{' d0' if 'initial_depth' in c['cfg'] else ''}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__)
    ap.add_argument("-n", "--cases", type=int, default=30)
    ap.add_argument("--seed", type=int, default=20240601)
    ap.add_argument("--bin-cmd", default=DEFAULT_CMD,
                    help=f"command the arguments are appended to (default: {DEFAULT_CMD!r})")
    ap.add_argument("--cwd", default=ROOT, help="working directory for the command")
    ap.add_argument("--timeout", type=float, default=1800.0, help="seconds per case")
    ap.add_argument("--rtol", type=float, default=1e-4, help="relative tol. of J, rms")
    ap.add_argument("--j-atol", type=float, default=1e-2,
                    help="absolute floor added to the J tolerance, m^3 (default 1e-2)")
    ap.add_argument("--rms-atol", type=float, default=1e-4,
                    help="absolute floor added to the rms tolerance, m (default 1e-4)")
    ap.add_argument("--alt-tol", type=float, default=1e-2, help="min_altitude tol., m")
    ap.add_argument("--keep", metavar="DIR",
                    help="write the cases into DIR (kept) instead of a temp dir")
    ap.add_argument("--generate-only", action="store_true",
                    help="write the cases and the reference results, run nothing")
    ap.add_argument("--only", type=int, nargs="+", metavar="I",
                    help="run only these case indices (same cases as in a full run)")
    ap.add_argument("-v", "--verbose", action="store_true")
    a = ap.parse_args(argv)
    tol = Tol(a)

    only = set(a.only) if a.only else None
    base = a.keep or tempfile.mkdtemp(prefix="check_plan_")
    os.makedirs(base, exist_ok=True)
    cmd0 = shlex.split(a.bin_cmd)
    passed = failed = 0
    try:
        for i in range(a.cases):
            if only is not None and i not in only:
                continue
            # each case has its own generator: case i does not depend on N;
            # case 0 always has its waypoints strictly inside the profile
            rng = random.Random(f"{a.seed}/{i}")
            c = make_case(rng, i, force_inside=(i == 0))
            d = os.path.join(base, f"case_{i:03d}")
            os.makedirs(d, exist_ok=True)
            P, W, V = (os.path.join(d, n) for n in ("PROFILE.csv", "WAYPOINTS.csv", "VEHICLE.toml"))
            write_profile(P, c["xs"], c["bs"])
            write_waypoints(W, c["X"])
            write_toml(V, c["cfg"])
            zs = ",".join(fmt(z) for z in c["depths"])
            # reference from the files as written
            _, _, rtr, ref = ref_plan.run(P, W, V, [float(s) for s in zs.split(",")])
            Xw = ref_plan.load_waypoints(W)
            margin = min(min(abs(x - Xn) for x in rtr.x) for Xn in Xw[1:])
            with open(os.path.join(d, "reference.json"), "w") as f:
                json.dump(ref, f, indent=1)
            args = ["--profile", P, "--waypoints", W, "--config", V, "--depths", zs, "--json"]
            with open(os.path.join(d, "command.txt"), "w") as f:
                f.write(shlex.join(cmd0 + args) + "\n")
            label = f"case {i:3d} [{describe(c)}]"
            if margin < 1e-3:  # a sample within 1 mm of a waypoint: knife edge
                label += f" (knife-edge: a sample {margin:.1e} m from a waypoint)"
            if a.generate_only:
                print(f"{label} total_J={ref['total_J']:.6g} "
                      f"min_alt={ref['min_altitude']:.3f} (generated)")
                continue
            t0 = time.time()
            try:
                p = subprocess.run(cmd0 + args, cwd=a.cwd, capture_output=True, text=True,
                                   timeout=a.timeout)
            except (OSError, subprocess.TimeoutExpired) as e:
                failed += 1
                print(f"FAIL {label}: could not run: {e}")
                continue
            dt = time.time() - t0
            if p.returncode != 0:
                failed += 1
                err = (p.stderr.strip().splitlines() or ["(no stderr)"])[-1]
                print(f"FAIL {label}: exit status {p.returncode}: {err}")
                continue
            try:
                got = json.loads(p.stdout)
            except json.JSONDecodeError as e:
                failed += 1
                print(f"FAIL {label}: stdout is not one JSON object: {e}")
                continue
            with open(os.path.join(d, "tool.json"), "w") as f:
                json.dump(got, f, indent=1)
            bad, worst = compare(ref, got, tol)
            stats = (f"maxrel J {worst['J']:.1e} rms {worst['rms']:.1e} "
                     f"max|dalt| {worst['alt']:.1e} m ({dt:.1f}s)")
            if bad:
                failed += 1
                print(f"FAIL {label}: {stats}")
                for b in bad[: (None if a.verbose else 6)]:
                    print(f"       {b}")
            else:
                passed += 1
                print(f"ok   {label}: {stats}")
            sys.stdout.flush()
    finally:
        if not a.keep:
            shutil.rmtree(base, ignore_errors=True)
    if a.generate_only:
        print(f"{a.cases} cases generated in {base}" if a.keep else f"{a.cases} cases generated")
        return 0
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
