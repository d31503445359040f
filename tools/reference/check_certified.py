#!/usr/bin/env python3
"""Checker of the `plan` tool's certification promise (model.md section 12).

    python3 tools/reference/check_certified.py [--bin-cmd CMD] [--cases 12] \
        [--bounds-per-profile 2] [--random-worlds 8] [--modes horizon] [--jobs 2]

cli.md: "flying its reported depths from the start state in any world of the
declared set keeps h >= h_a on every track it reports safe".  For each case
(the shared real profiles, then random synthetic profiles with random stable
vehicles) the script writes PROFILE.csv / WAYPOINTS.csv / VEHICLE.toml with
the six uncertainty keys, runs the tool with --json, takes its per-track
`depth` and `safe`, and flies those depths open loop from the start state
(trimmed level flight at initial_depth) in f64 in the sampled worlds of
worlds.py (nominal, every corner incl. the exact shallow-envelope shift,
`--random-worlds` random motions x random smooth bottoms).  Checks per track:

  W  a track reported "safe": true keeps min true altitude >= h_a - tol in
     every sampled world (tol = --alt-tol, 0.01 m);
  N  the tool's `min_altitude` equals the f64 nominal re-flight within tol
     (otherwise the world check would test another flight);
  C  `certified_min_altitude`, when emitted: equals the nominal min altitude
     within tol when every bound is 0; with bounds, it is not above the least
     sampled altitude + tol (a certificate must be a lower bound).
Per run: the top-level "safe": true holds in every sampled world; the tool
accepts the uncertainty keys (if it rejects them with exit status 2, the
run is counted failed and, unless --no-retry, retried without the keys so
that its nominal plan is still checked against the declared worlds).

One line per run (+ details of failures), then exactly `N passed, M failed`
(checks = tracks + runs); exit status 1 on any failure.
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
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
sys.dont_write_bytecode = True
sys.path.insert(0, HERE)
import auvref as ar  # noqa: E402
import check_plan as cp  # noqa: E402  (random profiles, vehicles, file writers)
import ref_plan  # noqa: E402
import worlds as W  # noqa: E402

DEFAULT_CMD = "cargo run --release --quiet --example plan --"
SHARED = "/work/shared/data/bathymetry"
REAL = ["us_monterey_canyon_1", "us_monterey_canyon_2", "us_monterey_canyon_3",
        "es_medes_islands_1", "es_medes_islands_2", "jp_aburatsubo_sagami_1"]
RANGES = {  # realistic declared bounds, drawn uniformly in [0, max]
    "horizontal_uncertainty": 20.0,
    "nav_drift": 0.005,
    "vertical_uncertainty": 10.0,
    "speed_uncertainty": 0.1,
    "flight_path_offset": 2.0,
    "vertical_current": 0.1,
}


def hr_ha(name):
    if name.startswith("us_monterey"):
        return 80.0, 60.0
    if name.startswith("es_medes"):
        return 5.0, 3.0
    return 2.0, 1.0


def random_bounds(rng: random.Random, vertical_scale=1.0):
    """Each key uniform in [0, max] (30 % of the time 0 on its own).
    vertical_scale shrinks e_v (used on the shallow real sites, where
    h_r - h_a is 1-2 m, so that a certified plan can exist at all)."""
    b = {}
    for k, hi in RANGES.items():
        if rng.random() < 0.3:
            b[k] = 0.0
            continue
        if k == "vertical_uncertainty":
            hi *= vertical_scale
        b[k] = cp.sig(rng.uniform(0.0, hi), 3)
    return b


def zero_bounds():
    return {k: 0.0 for k in RANGES}


MAP_KEYS = ("horizontal_uncertainty", "nav_drift", "vertical_uncertainty")


def restrict(b, kind):
    """The bounds `b` with only the map's keys (kind "map") or only the
    vehicle's motion keys (kind "motion") kept; "all" keeps every key."""
    if kind == "all":
        return b
    keep = (lambda k: k in MAP_KEYS) if kind == "map" else (lambda k: k not in MAP_KEYS)
    return {k: (v if keep(k) else 0.0) for k, v in b.items()}


def make_cases(a):
    cases = []
    if not a.no_real:
        data = a.data
        for name in REAL:
            if a.only and name not in a.only:
                continue
            P = os.path.join(data, f"{name}.csv")
            Wp = os.path.join(data, f"{name}.waypoints.csv")
            if not (os.path.exists(P) and os.path.exists(Wp)):
                continue
            h_r, h_a = hr_ha(name)
            base = {"reference_altitude": h_r, "min_altitude": h_a}
            rng = random.Random(f"{a.seed}/real/{name}")
            vs = min(1.0, (h_r - h_a) / 20.0)
            blist = [zero_bounds()] + [restrict(random_bounds(rng, vs), a.bounds_kind)
                                       for _ in range(a.bounds_per_profile)]
            for j, bd in enumerate(blist):
                cases.append({"name": f"{name}/b{j}", "profile": P, "waypoints": Wp,
                              "cfg": dict(base), "bounds": bd})
    for i in range(a.cases):
        name = f"synthetic_{i:03d}"
        if a.only and name not in a.only:
            continue
        rng = random.Random(f"{a.seed}/syn/{i}")
        xs, bs = cp.random_profile(rng)
        prof = ar.Profile(xs, bs)
        X = cp.random_waypoints(rng, xs, force_inside=(i == 0))
        cfg, plant = cp.random_vehicle(rng, prof, X[0])
        cfg.pop("optimizer", None)  # keep the tool's default effort
        bd = zero_bounds() if (i % 4 == 0 or rng.random() < 0.1) else random_bounds(rng)
        bd = restrict(bd, a.bounds_kind)
        cases.append({"name": f"{name}[{plant}]", "xs": xs, "bs": bs, "X": X,
                      "cfg": cfg, "bounds": bd})
    return cases


def write_case(c, d):
    os.makedirs(d, exist_ok=True)
    if "xs" in c:
        P, Wp = os.path.join(d, "PROFILE.csv"), os.path.join(d, "WAYPOINTS.csv")
        cp.write_profile(P, c["xs"], c["bs"])
        cp.write_waypoints(Wp, c["X"])
    else:
        P, Wp = c["profile"], c["waypoints"]
    V = os.path.join(d, "VEHICLE.toml")
    cfg = dict(c["cfg"])
    if any(c["bounds"].values()):  # all-zero bounds: keys omitted (default 0)
        cfg.update(c["bounds"])  # top-level keys, written before the tables
    cp.write_toml(V, cfg)
    V0 = os.path.join(d, "VEHICLE_nominal.toml")
    cp.write_toml(V0, c["cfg"])
    return P, Wp, V, V0


def run_tool(cmd0, args, cwd, timeout):
    try:
        p = subprocess.run(cmd0 + args, cwd=cwd, capture_output=True, text=True,
                           timeout=timeout)
    except (OSError, subprocess.TimeoutExpired) as e:
        return None, f"could not run: {e}", None
    if p.returncode != 0:
        err = (p.stderr.strip().splitlines() or ["(no stderr)"])[-1]
        return None, err, p.returncode
    try:
        return json.loads(p.stdout), None, 0
    except json.JSONDecodeError as e:
        return None, f"stdout is not one JSON object: {e}", 0


def check_case(c, mode, a, base):
    """Returns (lines, n_pass, n_fail, record)."""
    tag = f"{c['name']} {mode}"
    d = os.path.join(base, c["name"].replace("/", "_").replace("[", "_").replace("]", "")
                     + f"_{mode}")
    P, Wp, V, V0 = write_case(c, d)
    cmd0 = shlex.split(a.bin_cmd)
    args = ["--profile", P, "--waypoints", Wp, "--json", "--mode", mode]
    bounds = W.Bounds.from_config(c["bounds"])
    bstr = " ".join(f"{k}={v:g}" for k, v in zip(
        ("e_h", "r", "e_v", "eps_U", "alpha", "w"), bounds.as_tuple()))
    lines, npass, nfail = [], 0, 0
    rec = {"case": c["name"], "mode": mode, "bounds": c["bounds"], "cfg": c["cfg"]}
    t0 = time.time()
    got, err, rc = run_tool(cmd0, args + ["--config", V], a.cwd, a.timeout)
    rejected = False
    if got is None:
        keys_named = err is not None and any(k in err for k in W.UNCERTAINTY_KEYS)
        if rc == 2 and keys_named and not a.no_retry:
            rejected = True
            nfail += 1
            lines.append(f"       run: the tool rejects the uncertainty keys ({err}); "
                         "retrying without them, checking its nominal plan")
            got, err, rc = run_tool(cmd0, args + ["--config", V0], a.cwd, a.timeout)
        if got is None:
            nfail += 1
            lines.insert(0, f"FAIL {tag} [{bstr}]: tool: {err}")
            rec["error"] = err
            return lines, npass, nfail, rec
    elif not bounds.is_zero():
        npass += 1  # keys accepted
    t_tool = time.time() - t0
    rec["tool"] = got
    rec["rejected_uncertainty_keys"] = rejected

    prof = ar.Profile.from_csv(P)
    X = ref_plan.load_waypoints(Wp)
    veh = ar.Vehicle.from_config(c["cfg"])
    h_a = veh.min_altitude
    d0 = veh.resolved_initial_depth(prof, X[0])
    tol = a.alt_tol
    try:
        tracks = got["tracks"]
        depths = [float(t["depth"]) for t in tracks]
        if len(depths) != len(X) - 1:
            raise ValueError(f"{len(depths)} tracks, expected {len(X) - 1}")
    except (KeyError, TypeError, ValueError) as e:
        nfail += 1
        lines.insert(0, f"FAIL {tag}: malformed JSON: {e!r}")
        return lines, npass, nfail, rec
    t1 = time.time()
    worst, det = W.worst_case(veh, prof, X, depths, d0, bounds, a.random_worlds,
                              f"{a.seed}/{c['name']}/{mode}")
    t_ref = time.time() - t1
    nominal = det["nominal"]
    rec["worlds"] = {"motions": det["motions"], "bottoms": det["bottoms"]}
    rec["tracks"] = []
    n_safe = n_bad = 0
    worst_deficit = -math.inf
    missing_cma = 0
    for n, t in enumerate(tracks):
        bad = []
        safe = t.get("safe")
        w_alt, w_name = worst[n]
        if safe is True:
            n_safe += 1
            worst_deficit = max(worst_deficit, h_a - w_alt)
            if w_alt < h_a - tol:
                n_bad += 1
                bad.append(f"W reported safe, but min altitude {w_alt:.3f} < h_a {h_a:g} "
                           f"(by {h_a - w_alt:.3f} m) in world [{w_name}]")
        try:
            ma = float(t["min_altitude"])
            if abs(ma - nominal[n]) > tol:
                bad.append(f"N min_altitude {ma:.4f} vs f64 nominal re-flight {nominal[n]:.4f}")
        except (KeyError, TypeError, ValueError):
            bad.append("N no min_altitude")
        cma = t.get("certified_min_altitude")
        if cma is None:
            missing_cma += 1
        else:
            cma = float(cma)
            if bounds.is_zero() and not rejected and abs(cma - nominal[n]) > tol:
                bad.append(f"C certified_min_altitude {cma:.4f} != nominal {nominal[n]:.4f} "
                           "with every bound 0")
            if cma > w_alt + tol:
                bad.append(f"C certified_min_altitude {cma:.4f} above the sampled world "
                           f"altitude {w_alt:.4f} [{w_name}]")
        rec["tracks"].append({"track": n + 1, "depth": depths[n], "safe": safe,
                              "status": t.get("status"), "tool_min_altitude": t.get("min_altitude"),
                              "certified_min_altitude": cma, "nominal_min_altitude": nominal[n],
                              "world_min_altitude": w_alt, "worst_world": w_name,
                              "problems": bad})
        if bad:
            nfail += 1
            for b in bad:
                lines.append(f"       track {n + 1} (z={depths[n]:.2f}, "
                             f"status {t.get('status')}): {b}")
        else:
            npass += 1
    # top-level safe
    top = got.get("safe")
    least = min(w[0] for w in worst)
    if top is True:
        if least < h_a - tol:
            nfail += 1
            lines.append(f"       run: top-level safe, but a world reaches {least:.3f} < h_a {h_a:g}")
        else:
            npass += 1
    rec.update({"n_safe_tracks": n_safe, "n_unsafe_in_worlds": n_bad,
                "missing_certified_min_altitude": missing_cma,
                "least_world_altitude": least, "h_a": h_a})
    failed_here = any(l.startswith("       ") for l in lines)
    head = (f"{'FAIL' if failed_here else 'ok  '} {tag} [{bstr}] h_a={h_a:g}: "
            f"{len(tracks)} tracks, {n_safe} reported safe, {n_bad} of them below h_a-tol "
            f"in a sampled world; least world alt {least:.3f}"
            + (f", worst deficit {worst_deficit:+.3f} m" if n_safe else "")
            + f"; {det['motions']}x{det['bottoms']} worlds"
            + (f"; no certified_min_altitude" if missing_cma else "")
            + f" (tool {t_tool:.1f}s, ref {t_ref:.1f}s)")
    lines.insert(0, head)
    return lines, npass, nfail, rec


# --------------------------------------------------------------------------
# Stand-in tools for --self-test (no Rust needed)
# --------------------------------------------------------------------------


def stand_in(kind, argv):
    """A toy `plan --json`: z_n = shallowest target over track n (b - h_r).

    kind "nominal": safe and certified_min_altitude from the nominal flight
    only (ignores the declared bounds: must be caught when bounds are set).
    kind "certified": certified_min_altitude = least altitude over its own
    corner worlds minus 0.5 m (exact when no bound is declared), safe = that
    >= h_a (honest, with the margin standing in for the random worlds it does
    not sample: must pass)."""
    p = argparse.ArgumentParser()
    for k in ("--profile", "--waypoints", "--config", "--mode"):
        p.add_argument(k)
    p.add_argument("--json", action="store_true")
    o = p.parse_args(argv)
    prof = ar.Profile.from_csv(o.profile)
    X = ref_plan.load_waypoints(o.waypoints)
    full = ref_plan.load_config(o.config)
    bd = {k: full.pop(k) for k in list(full) if k in W.UNCERTAINTY_KEYS}
    bounds = W.Bounds.from_config(bd)
    veh = ar.Vehicle.from_config(full)
    h_r, h_a = veh.reference_altitude, veh.min_altitude
    z = []
    for n in range(1, len(X)):
        a, b = X[n - 1], X[n]
        pts = [a, b] + [x for x in prof.x if a < x < b]
        z.append(min(prof(x) for x in pts) - h_r)
    d0 = veh.resolved_initial_depth(prof, X[0])
    _, res = ar.evaluate_plan(veh, prof, X, z)
    if kind == "certified":
        worst, _ = W.worst_case(veh, prof, X, z, d0, bounds, 0, "stand-in")
        margin = 0.0 if bounds.is_zero() else 0.5
        cert = [w[0] - margin for w in worst]
    else:
        cert = [t["min_altitude"] for t in res["tracks"]]
    tracks = []
    for t, zn, cm in zip(res["tracks"], z, cert):
        tracks.append({"track": t["track"], "x_start": t["x_start"], "x_end": t["x_end"],
                       "depth": zn, "J": t["J"], "rms": t["rms"],
                       "min_altitude": t["min_altitude"], "safe": cm >= h_a,
                       "status": "optimal" if cm >= h_a else "infeasible",
                       "certified_min_altitude": cm})
    print(json.dumps({"method": "stand-in", "mode": o.mode, "tracks": tracks,
                      "total_J": res["total_J"], "min_altitude": res["min_altitude"],
                      "safe": all(t["safe"] for t in tracks)}))
    return 0


def self_test(a):
    """The honest stand-in passes; the nominal-only one is caught."""
    me = shlex.join([sys.executable, os.path.abspath(__file__)])
    common = ["--cases", "4", "--bounds-per-profile", "1", "--random-worlds", "4",
              "--only", "us_monterey_canyon_1", "es_medes_islands_1",
              "synthetic_000", "synthetic_001", "synthetic_002", "synthetic_003",
              "--jobs", str(a.jobs), "--seed", str(a.seed)]
    print("== self-test: honest stand-in (must pass)", flush=True)
    rc1 = main(["--bin-cmd", f"{me} --stand-in certified"] + common)
    print("== self-test: nominal-only stand-in (must be caught)", flush=True)
    rc2 = main(["--bin-cmd", f"{me} --stand-in nominal"] + common)
    ok = rc1 == 0 and rc2 == 1
    print(f"self-test {'passed' if ok else 'FAILED'} (honest rc {rc1}, nominal-only rc {rc2})")
    return 0 if ok else 1


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["--stand-in"]:
        return stand_in(argv[1], argv[2:])
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__)
    ap.add_argument("--bin-cmd", default=DEFAULT_CMD,
                    help=f"command the arguments are appended to (default {DEFAULT_CMD!r})")
    ap.add_argument("--cwd", default=ROOT)
    ap.add_argument("--data", default=SHARED if os.path.isdir(SHARED)
                    else os.path.join(ROOT, "data", "bathymetry"))
    ap.add_argument("-n", "--cases", type=int, default=12, help="synthetic cases")
    ap.add_argument("--bounds-per-profile", type=int, default=2,
                    help="random bound sets per real profile (plus one all-zero)")
    ap.add_argument("--no-real", action="store_true", help="skip the real profiles")
    ap.add_argument("--random-worlds", type=int, default=8,
                    help="random motions and random bottoms each (default 8)")
    ap.add_argument("--modes", default="horizon", help="comma list of horizon,track")
    ap.add_argument("--bounds-kind", choices=("all", "map", "motion"), default="all",
                    help="keep only the map's bounds (e_h, r, e_v) or only the motion's "
                         "(eps_U, alpha, w) of each random draw (default all)")
    ap.add_argument("--seed", type=int, default=20240612)
    ap.add_argument("--alt-tol", type=float, default=0.01)
    ap.add_argument("--timeout", type=float, default=1800.0)
    ap.add_argument("--no-retry", action="store_true",
                    help="if the tool rejects the uncertainty keys, do not retry without them")
    ap.add_argument("--only", nargs="+", metavar="NAME",
                    help="real profile names / synthetic_NNN to run")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--keep", metavar="DIR")
    ap.add_argument("--json-out", metavar="FILE")
    ap.add_argument("--self-test", action="store_true",
                    help="check this checker with two stand-in tools (no Rust)")
    a = ap.parse_args(argv)
    if a.self_test:
        return self_test(a)

    cases = make_cases(a)
    modes = [m.strip() for m in a.modes.split(",") if m.strip()]
    base = a.keep or tempfile.mkdtemp(prefix="check_certified_")
    os.makedirs(base, exist_ok=True)
    jobs = [(c, m) for c in cases for m in modes]
    passed = failed = 0
    records = []
    t0 = time.time()
    try:
        if a.jobs > 1:
            with cf.ProcessPoolExecutor(a.jobs) as ex:
                futs = [ex.submit(check_case, c, m, a, base) for c, m in jobs]
                results = (f.result() for f in futs)
                for lines, p_, f_, rec in results:
                    print("\n".join(lines), flush=True)
                    passed += p_
                    failed += f_
                    records.append(rec)
        else:
            for c, m in jobs:
                lines, p_, f_, rec = check_case(c, m, a, base)
                print("\n".join(lines), flush=True)
                passed += p_
                failed += f_
                records.append(rec)
    finally:
        if not a.keep:
            shutil.rmtree(base, ignore_errors=True)
    n_safe = sum(r.get("n_safe_tracks", 0) for r in records)
    n_bad = sum(r.get("n_unsafe_in_worlds", 0) for r in records)
    n_rej = sum(1 for r in records if r.get("rejected_uncertainty_keys"))
    nz = [r for r in records if any(v for v in r["bounds"].values())]
    print(f"info: {len(records)} runs ({len(nz)} with nonzero bounds, {n_rej} rejected the "
          f"uncertainty keys); {n_safe} tracks reported safe, {n_bad} of them below "
          f"h_a - {a.alt_tol:g} m in a sampled world; {time.time() - t0:.0f}s")
    if a.json_out:
        with open(a.json_out, "w") as f:
            json.dump(records, f, indent=1, default=str)
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
