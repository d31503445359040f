#!/usr/bin/env python3
"""The planner's whole-line J against the best safe J an independent f64
exhaustive search finds, on the six shared profiles (issue 15, the J check).

    python3 scripts/j_gap.py [--bin target/release/examples/plan] [--quick]
    python3 scripts/j_gap.py --horizon-only      # Monterey 1 only (the bench's)

For each profile (h_r/h_a 80/60 Monterey, 5/3 Medes, 2/1 Aburatsubo) it runs
the tool (`--json`, horizon mode, the default: K = 5 = every track of these
lines; and `--horizon 5`, the same) and the reference of
tools/reference/check_planner.py (numpy, f64, its own simulator):

  1. `best_horizon_plan`: a wide beam search (B = 100 partial plans, 32
     depths per track and state), focused beam passes around its 3 best
     distinct plans, the last track searched exactly, then a cyclic
     coordinate search (`refine_plan`, up to 8 sweeps);
  2. a final f64 polish of the best plan: scipy's Nelder–Mead on the total J
     with an infinite wall where any track's least altitude is below h_a;
  3. (reported apart, "seeded") the same coordinate search and polish
     started from the tool's own plan when it is safe: a check that the
     reference is a minimum the tool's plan does not improve on.

The reference's best is the least of 1-3; a plan is safe when its least
altitude over the line, flown by the reference, is >= h_a. The table
(markdown) gives the tool's total J and safety, the reference's best, the
gap (tool / best - 1), which search found the best, the gap against the
best plan raised (by the least shift, 0.5 mm steps) to clear the tool's
certified altitude h_a + m_s (m_s = 2 mm), the gap against the reference's
own search alone, and the tool's `--horizon 5` J.  `--json-out F` writes
everything; `--reuse F` takes the reference's own search from such a file
and redoes the rest (the tool after a change: minutes instead of half an
hour).  Monterey 1's best (its five tracks are the first call's horizon)
goes to target/j_gap_horizon.json, which `cargo bench --bench horizon`
prints beside its solutions; `--horizon-only` runs Monterey 1 alone.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import numpy as np  # noqa: E402
from scipy.optimize import minimize  # noqa: E402

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
REF = os.path.join(ROOT, "tools", "reference")
sys.dont_write_bytecode = True
sys.path.insert(0, REF)
import check_planner as cp  # noqa: E402
import ref_plan  # noqa: E402
import auvref as ar  # noqa: E402

SAFETY_MARGIN = 0.002  # m_s of PlannerConfig::default, m


def fly(fm, z):
    """(total J, least altitude, per-track J, per-track least altitude)."""
    Js, hs, _ = fm.fly_plan([np.asarray(z, dtype=float)])
    return float(Js.sum()), float(hs.min()), Js[0].tolist(), hs[0].tolist()


def polish(fm, z, maxfev=600):
    """Nelder-Mead on the total J, unsafe plans walled off (f64)."""
    z = np.asarray(z, dtype=float)
    j0, h0, _, _ = fly(fm, z)
    if h0 < fm.h_a:
        return z, j0

    def f(u):
        u = np.clip(u, fm.lo, fm.hi)
        j, h, _, _ = fly(fm, u)
        return j if h >= fm.h_a else np.inf

    step = 2.0 * cp.zscale(fm)
    simplex = np.vstack([z] + [z + step * np.eye(len(z))[i] for i in range(len(z))])
    r = minimize(f, z, method="Nelder-Mead",
                 options={"initial_simplex": simplex, "maxfev": maxfev,
                          "xatol": 1e-3 * cp.zscale(fm), "fatol": 1e-9 * j0})
    u = np.clip(r.x, fm.lo, fm.hi)
    j, h, _, _ = fly(fm, u)
    return (u, j) if (h >= fm.h_a and j < j0) else (z, j0)


def reference(fm, quick, seed=0):
    """The reference's own best safe plan (1 and 2 of the module docs)."""
    if quick:
        hz = cp.best_horizon_plan(fm, seed=seed)
    else:
        hz = cp.best_horizon_plan(fm, seed=seed, starts=3, sweeps=8)
    if not hz["safe_plan"]:
        return {"safe": False, "dead_track": hz["dead_track"],
                "max_min_altitude": hz["max_min_altitude"]}
    beam_j = hz["total_J"]
    z, j = polish(fm, hz["plan"], maxfev=200 if quick else 600)
    return {"safe": True, "plan": [float(v) for v in z], "total_J": j,
            "beam_total_J": beam_j, "evaluations": hz["evaluations"]}


def seeded(fm, z, quick):
    """Coordinate search and polish from the tool's plan (if safe)."""
    j0, h0, _, _ = fly(fm, z)
    if h0 < fm.h_a:
        return None
    rr = cp.refine_plan(fm, z, max_sweeps=4 if quick else 8)
    u, j = polish(fm, rr["plan"], maxfev=200 if quick else 600)
    return {"plan": [float(v) for v in u], "total_J": j}


def at_certified(fm, plan, m_s=SAFETY_MARGIN):
    """The best plan made to clear the tool's certified altitude h_a + m_s:
    every depth raised by the least shift (in 0.5 mm steps, up to 2 cm) at
    which it does; (shift, total J) or None."""
    z = np.asarray(plan, dtype=float)
    for k in range(1, 41):
        s = 5e-4 * k
        j, h, _, _ = fly(fm, z - s)
        if h >= fm.h_a + m_s:
            return s, j
    return None


def run_tool(binary, case, extra):
    args = [binary, "--profile", case["P"], "--waypoints", case["W"],
            "--config", case["V"], "--json"] + extra
    p = subprocess.run(args, capture_output=True, text=True, check=True)
    return json.loads(p.stdout)


def one(name, h_r, h_a, binary, quick, base, reuse=None):
    case = cp.write_case({"name": name, "h_r": h_r, "h_a": h_a}, base)
    prof = ref_plan.load_profile(case["P"])
    X = ref_plan.load_waypoints(case["W"])
    vehicle = ar.Vehicle.from_config(ref_plan.load_config(case["V"]))
    fm = cp.Fast(vehicle, prof, X)
    row = {"profile": name, "h_r": h_r, "h_a": h_a, "tool": {}}
    for key, extra in (("default", []), ("horizon5", ["--horizon", "5"])):
        out = run_tool(binary, case, extra)
        depths = [float(t["depth"]) for t in out["tracks"]]
        j, h, _, _ = fly(fm, depths)
        row["tool"][key] = {"depths": depths, "total_J": float(out["total_J"]),
                            "safe": bool(out["safe"]), "resim_J": j,
                            "resim_min_altitude": h}
    ref = reuse["reference"] if reuse else reference(fm, quick)
    row["reference"] = ref
    tool = row["tool"]["default"]
    row["seeded"] = seeded(fm, tool["depths"], quick)
    cands = []
    if ref["safe"]:
        cands.append(("search", ref["total_J"], ref["plan"]))
    if row["seeded"]:
        cands.append(("seeded", row["seeded"]["total_J"], row["seeded"]["plan"]))
    if cands:
        how, best, plan = min(cands, key=lambda c: c[1])
        _, h, Js, hs = fly(fm, plan)
        row["best"] = {"by": how, "total_J": best, "plan": plan, "J": Js,
                       "min_altitude": hs}
        row["gap_percent"] = 100.0 * (tool["total_J"] / best - 1.0)
        cert = at_certified(fm, plan)
        row["best_certified"] = ({"shift": cert[0], "total_J": cert[1],
                                  "gap_percent": 100.0 * (tool["total_J"] / cert[1] - 1.0)}
                                 if cert else None)
    else:
        row["best"] = None
        row["gap_percent"] = None
    return row


def table(rows):
    out = ["| profile | h_r/h_a | tool J (m³) | tool safe | reference best J (m³) | "
           "found by | reference safe | gap | gap at h_a + m_s | own search alone | "
           "`--horizon 5` J |",
           "|---|---|---:|---|---:|---|---|---:|---:|---:|---:|"]
    for r in rows:
        t = r["tool"]["default"]
        b = r["best"]
        ref = r["reference"]
        own = (f"{100.0 * (t['total_J'] / ref['total_J'] - 1.0):+.3f} %"
               if ref["safe"] else "no safe plan")
        bc = r.get("best_certified")
        cert = f"{bc['gap_percent']:+.3f} %" if bc else "-"
        out.append(
            f"| {r['profile']} | {r['h_r']:g}/{r['h_a']:g} | {t['total_J']:.6e} | "
            f"{t['safe']} | {b['total_J']:.6e} | {b['by']} | True | "
            f"{r['gap_percent']:+.3f} % | {cert} | {own} | "
            f"{r['tool']['horizon5']['total_J']:.6e} |"
            if b else
            f"| {r['profile']} | {r['h_r']:g}/{r['h_a']:g} | {t['total_J']:.6e} | "
            f"{t['safe']} | none | - | False | - | - | - | "
            f"{r['tool']['horizon5']['total_J']:.6e} |")
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "examples", "plan"))
    ap.add_argument("--quick", action="store_true", help="the default beam and fewer sweeps")
    ap.add_argument("--horizon-only", action="store_true",
                    help="Monterey 1 only; writes target/j_gap_horizon.json")
    ap.add_argument("--only", help="one profile by name")
    ap.add_argument("--json-out")
    ap.add_argument("--reuse", metavar="JSON",
                    help="the reference's own search from an earlier --json-out (the tool "
                         "runs and the seeded search are redone)")
    a = ap.parse_args(argv)
    cases = cp.SHARED
    if a.horizon_only:
        cases = cases[:1]
    elif a.only:
        cases = [c for c in cases if c[0] == a.only]
    rows = []
    old = {}
    if a.reuse:
        with open(a.reuse) as f:
            old = {r["profile"]: r for r in json.load(f)}
    with tempfile.TemporaryDirectory() as base:
        for name, h_r, h_a in cases:
            rows.append(one(name, h_r, h_a, a.bin, a.quick, base, old.get(name)))
            print(f"done {name}", file=sys.stderr, flush=True)
    print(table(rows))
    for r in rows:
        if r["best"]:
            print(f"{r['profile']}: tool depths {[round(v, 3) for v in r['tool']['default']['depths']]}"
                  f", best {[round(v, 3) for v in r['best']['plan']]}"
                  f", best J per track {[float(f'{v:.5g}') for v in r['best']['J']]}"
                  f", least altitudes {[round(v, 3) for v in r['best']['min_altitude']]}")
    if a.json_out:
        with open(a.json_out, "w") as f:
            json.dump(rows, f, indent=1)
    # Monterey 1's five tracks are the bench's horizon (call 1: the whole line)
    for r in rows:
        if r["profile"] == "us_monterey_canyon_1" and r["best"]:
            path = os.path.join(ROOT, "target", "j_gap_horizon.json")
            with open(path, "w") as f:
                json.dump({"profile": r["profile"], "best_safe_J": r["best"]["total_J"],
                           "plan": r["best"]["plan"], "by": r["best"]["by"]}, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
