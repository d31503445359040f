#!/usr/bin/env python3
"""Generate the golden fixtures in tests/fixtures/ from the f64 reference.

    python3 tools/reference/make_fixtures.py [--out DIR] [--only NAME ...]

Writes plants.json, step_response.json and evaluations.json (see README.md).
Deterministic: the same inputs give byte-identical files.
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import sys
import time

import numpy as np
import scipy

sys.dont_write_bytecode = True  # keep the source tree clean
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import auvref as ar  # noqa: E402
from jsonfmt import dumps  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
BATHY = os.path.join(ROOT, "data", "bathymetry")
GENERATOR = (
    f"tools/reference/make_fixtures.py (f64 reference auvref.py; "
    f"numpy {np.__version__}, scipy {scipy.__version__})"
)

# --------------------------------------------------------------------------
# Plants
# --------------------------------------------------------------------------

CAUV4_DEN = [1.0, 2.681, 0.546, 0.048]
CAUV4 = {"kind": "pitch", "num": [-0.173], "den": CAUV4_DEN}
CAUV4_RATE = {"kind": "rate", "num": [-0.173, 0.0], "den": CAUV4_DEN}
REMUS = {"kind": "pitch", "num": [-0.62], "den": [1.0, 1.45, 0.29]}
INTEGRATOR = {"kind": "pitch", "num": [-0.4], "den": [1.0, 1.1, 0.0]}
FOURTH = {"kind": "pitch", "num": [-0.05, -0.2], "den": [1.0, 3.2, 3.1, 0.9, 0.08]}
POSITIVE = {"kind": "pitch", "num": [0.5], "den": [1.0, 1.2, 0.35]}
# C-AUV #4 with leading zeros and a non-monic denominator (exactly 2x: the
# realization must be identical to CAUV4).
CAUV4_UNNORMALIZED = {"kind": "pitch", "num": [0.0, -0.346],
                      "den": [0.0, 2.0, 5.362, 1.092, 0.096]}

PLANT_CASES = [
    ("cauv4_ts0.1", CAUV4, 0.1),
    ("cauv4_ts0.5", CAUV4, 0.5),
    ("cauv4_ts2.0", CAUV4, 2.0),
    ("cauv4_rate_ts0.1", CAUV4_RATE, 0.1),
    ("cauv4_unnormalized_ts0.1", CAUV4_UNNORMALIZED, 0.1),
    ("remus_class_ts0.1", REMUS, 0.1),
    ("integrator_ts0.1", INTEGRATOR, 0.1),
    ("integrator_ts2.0", INTEGRATOR, 2.0),
    ("fourth_order_ts0.1", FOURTH, 0.1),
    ("fourth_order_ts0.25", FOURTH, 0.25),
    ("positive_gain_ts0.1", POSITIVE, 0.1),
]

INVALID_PLANTS = [
    ("rate_nonzero_constant", {"kind": "rate", "num": [-0.173, 0.01], "den": CAUV4_DEN},
     "rate-form numerator must have a zero constant term"),
    ("numerator_degree_too_high", {"kind": "pitch", "num": [-0.1, 0.2, -0.173], "den": CAUV4_DEN},
     "deg num > deg den - 2 (q would have feed-through)"),
    ("first_order", {"kind": "pitch", "num": [-1.0], "den": [1.0, 0.5]},
     "deg num > deg den - 2"),
    ("zero_at_origin", {"kind": "pitch", "num": [-0.173, 0.0], "den": CAUV4_DEN},
     "N(0) = 0 (θ/δ with a zero at s = 0)"),
    ("rate_zero_at_origin", {"kind": "rate", "num": [-0.173, 0.0, 0.0], "den": CAUV4_DEN},
     "N(0) = 0 after division by s"),
    ("zero_numerator", {"kind": "pitch", "num": [0.0], "den": CAUV4_DEN},
     "numerator is zero"),
    ("zero_denominator", {"kind": "pitch", "num": [-0.173], "den": [0.0, 0.0]},
     "denominator is zero"),
    ("non_finite", {"kind": "pitch", "num": [-0.173], "den": [1.0, float("nan"), 0.5]},
     "non-finite coefficient"),
]


def plant_dict(p):
    return {"kind": p["kind"], "num": list(p["num"]), "den": list(p["den"])}


def make_plants():
    cases = []
    for name, p, ts in PLANT_CASES:
        pl = ar.realize(p["kind"], p["num"], p["den"])
        Ad, Bd = ar.discretize(pl.A, pl.B, ts)
        cases.append({
            "name": name,
            "kind": p["kind"],
            "num": list(p["num"]),
            "den": list(p["den"]),
            "sample_time": ts,
            "order": pl.order,
            "num_monic": pl.num,
            "den_monic": pl.den,
            "A": pl.A.tolist(),
            "B": pl.B.tolist(),
            "C": pl.C.tolist(),
            "CA": pl.CA.tolist(),
            "Ad": Ad.tolist(),
            "Bd": Bd.tolist(),
            "dc_gain": pl.dc_gain,
            "pitch_loop_sign": int(pl.sigma),
        })
    # the rate form and the unnormalized form equal the plain C-AUV #4 form
    by = {c["name"]: c for c in cases}
    for other in ("cauv4_rate_ts0.1", "cauv4_unnormalized_ts0.1"):
        for key in ("A", "B", "C", "CA", "Ad", "Bd", "dc_gain", "pitch_loop_sign"):
            assert by[other][key] == by["cauv4_ts0.1"][key], (other, key)
    invalid = []
    for name, p, why in INVALID_PLANTS:
        try:
            ar.realize(p["kind"], p["num"], p["den"])
        except ar.ModelError:
            pass
        else:
            raise AssertionError(f"invalid plant {name} was accepted")
        num = [None if not math.isfinite(v) else v for v in p["num"]]
        den = [None if not math.isfinite(v) else v for v in p["den"]]
        invalid.append({"name": name, "kind": p["kind"], "num": num, "den": den,
                        "reason": why})
    return {
        "generator": GENERATOR,
        "notes": ("Controllable canonical form as scipy.signal.tf2ss of the monic, "
                  "leading-zero-stripped theta/delta (rate form divided by s): "
                  "A first row -den_monic[1:], ones on the sub-diagonal, B = e1, "
                  "C = num_monic left-padded to n, CA = C A. Ad, Bd: exact ZOH "
                  "(scipy.signal.cont2discrete, = expm([[A,B],[0,0]] Ts)). "
                  "dc_gain = N(0)/D(0), null when D(0) = 0. pitch_loop_sign = "
                  "sign(N(0)) * sign(lowest-order nonzero coefficient of D). "
                  "In 'invalid', null stands for NaN."),
        "cases": cases,
        "invalid": invalid,
    }


# --------------------------------------------------------------------------
# Vehicles
# --------------------------------------------------------------------------


def check_vehicle(v: ar.Vehicle, label: str):
    rho = ar.spectral_radius(v)
    assert rho < 0.9999, f"{label}: small-signal loop not stable (rho = {rho})"
    return rho


def vehicle_with(**over):
    return ar.Vehicle.from_config(over)


# --------------------------------------------------------------------------
# Step responses
# --------------------------------------------------------------------------

STEP_CASES = [
    ("default_down_20m", {}, 50.0, 70.0),
    ("default_up_20m", {}, 50.0, 30.0),
    ("remus_class_down_20m",
     {"plant": REMUS, "pitch_pid": {"kp": 1.5, "ki": 0.1, "kd": 2.5}}, 50.0, 70.0),
    ("positive_gain_down_20m",
     {"plant": POSITIVE, "pitch_pid": {"kp": 2.0, "ki": 0.1, "kd": 2.5}}, 50.0, 70.0),
]


def step_metrics(tr, d0, r):
    x = np.array(tr.x)
    d = np.array(tr.depth)
    sgn = math.copysign(1.0, r - d0)
    overshoot = max(0.0, float(np.max(sgn * (d - r))))
    err = np.abs(d - r)
    out = {"overshoot_m": overshoot}
    for tol in (0.4, 0.1):
        idx = np.where(err > tol)[0]
        out[f"settle_x_{tol}m"] = float(x[idx[-1] + 1]) if len(idx) else 0.0
    out["final_error_m"] = float(d[-1] - r)
    return out


def make_step_responses(log):
    cases = []
    for name, over, d0, r in STEP_CASES:
        v = ar.Vehicle.from_config(dict(over, initial_depth=d0))
        rho = check_vehicle(v, name)
        tr = ar.simulate(v, [0.0, 600.0], [r], d0)
        m = step_metrics(tr, d0, r)
        log(f"step {name}: rho={rho:.6f} overshoot={m['overshoot_m']:.4g} m, "
            f"settles within 0.4 m at x={m['settle_x_0.4m']:.1f} m, "
            f"within 0.1 m at x={m['settle_x_0.1m']:.1f} m, samples={tr.n_samples}")
        assert m["overshoot_m"] < 0.5, name
        assert abs(m["final_error_m"]) < 0.01, name
        cases.append({
            "name": name,
            "vehicle": v.config_dict(d0),
            "initial_depth": d0,
            "reference_depth": r,
            "waypoints": [0.0, 600.0],
            "metrics": m,
            "end_margin_m": switch_margins(tr, [0.0, 600.0])[0],
            "samples": {
                "x": tr.x,
                "depth": tr.depth,
                "pitch": tr.pitch,
                "pitch_rate": tr.pitch_rate,
                "elevator": tr.elevator,
                "theta_ref": tr.theta_ref,
            },
        })
    # A top-level list, as specified.  Each case: every simulated sample from
    # x = 0 to the first x >= 600 (no profile needed); elevator and theta_ref
    # are the commands computed at samples 0..K-1 (none at the last sample);
    # metrics are informative only (settle_x: first x after which
    # |depth - reference| stays within the tolerance).
    return cases


# --------------------------------------------------------------------------
# Evaluations
# --------------------------------------------------------------------------

REAL = {
    "jp_aburatsubo_sagami_1": (2.0, 1.0),
    "es_medes_islands_1": (5.0, 3.0),
    "es_medes_islands_2": (5.0, 3.0),
    "us_monterey_canyon_1": (80.0, 60.0),
    "us_monterey_canyon_2": (80.0, 60.0),
    "us_monterey_canyon_3": (80.0, 60.0),
}


def load_real(name):
    prof = ar.Profile.from_csv(os.path.join(BATHY, name + ".csv"))
    with open(os.path.join(BATHY, name + ".waypoints.csv")) as f:
        wps = [float(row["x_m"]) for row in csv.DictReader(f)]
    return prof, wps


def plan(kind, prof, X, h_r, d0):
    M = len(X) - 1
    if kind == "target":
        return [prof(X[n]) - h_r for n in range(1, M + 1)]
    if kind == "constant":
        return [d0] * M
    if kind == "offset":
        return [prof(X[n]) - h_r + (-1) ** n * 0.3 * h_r for n in range(1, M + 1)]
    if kind == "midpoint":
        return [prof(0.5 * (X[n - 1] + X[n])) - h_r for n in range(1, M + 1)]
    raise ValueError(kind)


def synthetic_slope(angle_deg, ascending=True, top=600.0, rise=300.0,
                    start=300.0, end_max=1200.0, length=1500.0, ds=5.0):
    """Flat at `top`, a linear slope from x = start, flat again after."""
    t = math.tan(math.radians(angle_deg))
    x_end = min(start + rise / t, end_max)
    xs = [i * ds for i in range(int(round(length / ds)) + 1)]
    bs = []
    for x in xs:
        s = min(max(x, start), x_end) - start
        bs.append(top - t * s if ascending else top + t * s)
    return xs, bs


def synthetic_flat(depth=500.0, length=1500.0, ds=5.0):
    xs = [i * ds for i in range(int(round(length / ds)) + 1)]
    return xs, [depth] * len(xs)


def synthetic_cliff(deep=600.0, shallow=500.0, at=700.0, width=0.5,
                    length=1500.0, ds=5.0):
    """Bottom rises 100 m over 0.5 m at x = 700 (89.7 deg)."""
    xs = [i * ds for i in range(int(round(length / ds)) + 1)]
    xs.append(at + width)
    xs.sort()
    bs = [deep if x <= at else shallow for x in xs]
    return xs, bs


def synthetic_sawtooth(mean=600.0, amp=40.0, period=230.0, length=1500.0, ds=5.0):
    """Triangle wave: slopes of atan(4 amp / period) = 34.8 deg."""
    xs = [i * ds for i in range(int(round(length / ds)) + 1)]
    bs = []
    for x in xs:
        ph = (x % period) / period
        tri = 4.0 * ph - 1.0 if ph < 0.5 else 3.0 - 4.0 * ph
        bs.append(mean + amp * tri)
    return xs, bs


W3 = [0.0, 500.0, 1000.0, 1500.0]

# (name, profile maker, waypoints, vehicle overrides, plans, explicit initial depth)
SYNTHETIC = [
    ("slope_10_up", lambda: synthetic_slope(10.0), W3, {},
     ["target", "constant"], None),
    ("slope_10_up_initial_depth", lambda: synthetic_slope(10.0), W3, {},
     ["target"], 500.0),
    ("slope_30_up_slow_fine", lambda: synthetic_slope(30.0), W3,
     {"speed": 1.0, "sample_time": 0.05}, ["target", "offset"], None),
    ("slope_45_up_fast_coarse_pitch15", lambda: synthetic_slope(45.0), W3,
     {"speed": 2.5, "sample_time": 0.2, "pitch_limit": 15.0}, ["target", "midpoint"], None),
    ("slope_60_up_remus", lambda: synthetic_slope(60.0), W3,
     {"plant": REMUS, "depth_pid": {"kp": 1.2, "ki": 0.0, "kd": 2.5},
      "pitch_pid": {"kp": 1.5, "ki": 0.1, "kd": 2.5}}, ["target", "constant"], None),
    ("slope_45_down_rate_form", lambda: synthetic_slope(45.0, ascending=False), W3,
     {"plant": CAUV4_RATE, "pitch_pid": {"kp": 2.5, "ki": 0.2, "kd": 3.5},
      "elevator_limit": 20.0, "reference_altitude": 50.0, "min_altitude": 30.0},
     ["target", "offset"], None),
    ("flat_fourth_order", lambda: synthetic_flat(), W3,
     {"plant": FOURTH}, ["target", "steps"], None),
    ("cliff_integrator_depth_ki", lambda: synthetic_cliff(), W3,
     {"plant": INTEGRATOR, "depth_pid": {"kp": 1.5, "ki": 0.02, "kd": 2.0}},
     ["target", "constant"], None),
    ("sawtooth_positive_gain_inner_wps", lambda: synthetic_sawtooth(),
     [100.0, 600.0, 1100.0, 1400.0],
     {"plant": POSITIVE, "pitch_pid": {"kp": 2.0, "ki": 0.1, "kd": 2.5},
      "depth_limits": [100.0, 1000.0]}, ["target", "midpoint"], None),
]


def switch_margins(tr, X):
    """min_k |x_k - X_n| for n = 1..M: how close a sample comes to a waypoint.

    A tiny margin is a knife edge: an implementation with other rounding may
    switch the reference (or stop) one sample earlier or later there."""
    x = np.array(tr.x)
    return [float(np.min(np.abs(x - Xn))) for Xn in X[1:]]


def gradient_block(v, prof, X, z, d0):
    g3 = ar.gradients(v, prof, X, z, d0, h=1e-3)
    g4 = ar.gradients(v, prof, X, z, d0, h=1e-4)

    def agree(a, b):
        return abs(a - b) <= 1e-6 * max(abs(a), abs(b)) or abs(a - b) <= 1e-9

    smooth = [all(agree(g3[i][n], g4[i][n]) for i in range(3)) for n in range(len(z))]
    return g3, smooth


def eval_case(name, profile_field, prof, X, over, z, plan_name, d0_explicit, log):
    v = ar.Vehicle.from_config(dict(over, initial_depth=d0_explicit))
    check_vehicle(v, name)
    d0 = v.resolved_initial_depth(prof, X[0])
    t0 = time.time()
    tr, res = ar.evaluate_plan(v, prof, X, z, d0)
    sat_t = sum(abs(t) == v.pitch_limit for t in tr.theta_ref) / len(tr.theta_ref)
    sat_e = sum(abs(e) == v.elevator_limit for e in tr.elevator) / len(tr.elevator)
    (gJ, gJn, gV), smooth = gradient_block(v, prof, X, z, d0)
    case = {
        "name": f"{name}/{plan_name}",
        "profile": profile_field,
        "plan": plan_name,
        "waypoints": X,
        "vehicle": v.config_dict(d0),
        "initial_depth_default": d0_explicit is None,
        "depths": z,
    }
    case.update(res)
    case["switch_margins_m"] = switch_margins(tr, X)
    case.update({
        "grad_total_J": gJ,
        "grad_track_J": gJn,
        "grad_total_violation": gV,
        "grad_smooth": smooth,
    })
    log(f"eval {case['name']}: total_J={res['total_J']:.6g} V={res['total_violation']:.6g} "
        f"min_alt={res['min_altitude']:.3f} n={res['n_samples']} "
        f"sat(theta_ref)={sat_t:.0%} sat(elevator)={sat_e:.0%} "
        f"smooth={''.join('y' if s else 'N' for s in smooth)} ({time.time() - t0:.1f}s)")
    return case


def make_evaluations(log):
    cases = []
    for name, (h_r, h_a) in REAL.items():
        prof, X = load_real(name)
        over = {"reference_altitude": h_r, "min_altitude": h_a}
        d0 = prof(X[0]) - h_r
        for pk in ("target", "constant", "offset", "midpoint"):
            z = plan(pk, prof, X, h_r, d0)
            cases.append(eval_case(name, name, prof, X, over, z, pk, None, log))
    for name, mk, X, over, plans, d0x in SYNTHETIC:
        xs, bs = mk()
        prof = ar.Profile(xs, bs)
        h_r = ar.full_config(over)["reference_altitude"]
        d0 = d0x if d0x is not None else prof(X[0]) - h_r
        for pk in plans:
            if pk == "steps":
                t = prof(X[1]) - h_r
                z = [t - 30.0, t + 15.0, t]
            else:
                z = plan(pk, prof, X, h_r, d0)
            cases.append(eval_case(name, {"x": xs, "b": bs}, prof, X,
                                   over, z, pk, d0x, log))
    return {
        "generator": GENERATOR,
        "notes": ("profile: a real profile name (data/bathymetry/<name>.csv) or an "
                  "inline {x, b}. vehicle: the full config, initial_depth "
                  "resolved (initial_depth_default tells whether it is the default "
                  "b(X_0) - h_r). tracks per model.md section 8; violation = "
                  "clipped trapezoid of p = max(0, h_a - h). Gradients: f64 central "
                  "differences of the whole-line simulation, h = 1e-3 m; "
                  "grad_smooth[n] is true when h = 1e-4 m agrees to 1e-6 relative "
                  "or 1e-9 absolute for all three entries of n. switch_margins_m[n-1] = "
                  "min over samples of |x_k - X_n|: where it is tiny (level flight "
                  "on a grid of U0 Ts steps lands on a waypoint) an implementation "
                  "with other rounding may switch/stop one sample apart: "
                  "n_samples, final_x, final_depth (and, if z changes there, J) "
                  "are knife-edge; 0.0 is an exact tie (tests the >= rule)."),
        "cases": cases,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "tests", "fixtures"))
    ap.add_argument("--only", nargs="*", choices=["plants", "step_response", "evaluations"])
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args()
    log = (lambda s: None) if args.quiet else (lambda s: print(s, flush=True))
    os.makedirs(args.out, exist_ok=True)
    jobs = {
        "plants": make_plants,
        "step_response": lambda: make_step_responses(log),
        "evaluations": lambda: make_evaluations(log),
    }
    for key in args.only or list(jobs):
        t0 = time.time()
        data = jobs[key]()
        path = os.path.join(args.out, key + ".json")
        with open(path, "w") as f:
            f.write(dumps(data))
        log(f"wrote {path} ({os.path.getsize(path)} bytes, {time.time() - t0:.1f}s)")


if __name__ == "__main__":
    main()
