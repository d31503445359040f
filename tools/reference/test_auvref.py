#!/usr/bin/env python3
"""Self-checks of the f64 reference.  Run:  python3 tools/reference/test_auvref.py
(also collectable by pytest).  Prints one line per check and the measured
step-response figures of the default vehicle."""

from __future__ import annotations

import json
import math
import os
import sys
import traceback

import numpy as np
import scipy.integrate
import scipy.linalg

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # keep the source tree clean
sys.path.insert(0, HERE)
import auvref as ar  # noqa: E402
import make_fixtures as mf  # noqa: E402

FIXTURES = os.path.join(HERE, "..", "..", "tests", "fixtures")


def _plants():
    return [mf.CAUV4, mf.CAUV4_RATE, mf.REMUS, mf.INTEGRATOR, mf.FOURTH, mf.POSITIVE,
            mf.CAUV4_UNNORMALIZED]


# ---------------------------------------------------------------- plants

def test_rate_form_equals_pitch_form():
    p = ar.realize("pitch", [-0.173], mf.CAUV4_DEN)
    r = ar.realize("rate", [-0.173, 0.0], mf.CAUV4_DEN)
    for k in ("A", "B", "C", "CA"):
        assert np.array_equal(getattr(p, k), getattr(r, k)), k
    assert p.sigma == r.sigma == -1.0
    assert p.dc_gain == r.dc_gain
    assert abs(p.dc_gain - (-3.604)) < 1e-3  # model.md: DC gain -3.604 deg/deg
    vp = ar.Vehicle.from_config({})
    vr = ar.Vehicle.from_config({"plant": mf.CAUV4_RATE})
    assert np.array_equal(vp.Ad, vr.Ad) and np.array_equal(vp.Bd, vr.Bd)
    tp = ar.simulate(vp, [0.0, 300.0], [70.0], 50.0)
    tr = ar.simulate(vr, [0.0, 300.0], [70.0], 50.0)
    assert tp.x == tr.x and tp.depth == tr.depth and tp.pitch == tr.pitch
    # non-monic / leading zeros give the same realization
    u = ar.realize("pitch", [0.0, -0.346], [0.0, 2.0, 5.362, 1.092, 0.096])
    for k in ("A", "B", "C", "CA"):
        assert np.array_equal(getattr(p, k), getattr(u, k)), k


def test_realization_structure():
    for pd in _plants():
        pl = ar.realize(pd["kind"], pd["num"], pd["den"])
        n = pl.order
        # transfer function of (A, B, C) equals N/D at a few points
        for s in (0.3j, 1.0 + 0.5j, 2.0, -0.7 + 2j):
            tf = pl.C @ np.linalg.solve(s * np.eye(n) - pl.A, pl.B)
            ref = np.polyval(pl.num, s) / np.polyval(pl.den, s)
            assert abs(tf - ref) <= 1e-12 * max(1.0, abs(ref)), (pd, s)
        assert pl.C @ pl.B == 0.0  # no feed-through into q
        assert np.array_equal(pl.CA, pl.C @ pl.A)


def test_pitch_loop_sign():
    assert ar.realize(**mf.CAUV4).sigma == -1.0
    assert ar.realize(**mf.REMUS).sigma == -1.0
    assert ar.realize(**mf.INTEGRATOR).sigma == -1.0  # D(0)=0: uses 1.1
    assert ar.realize(**mf.FOURTH).sigma == -1.0
    assert ar.realize(**mf.POSITIVE).sigma == 1.0
    assert ar.realize("pitch", [0.5], [1.0, 1.2, -0.35]).sigma == -1.0  # unstable D, sign by D(0)
    assert ar.realize(**mf.INTEGRATOR).dc_gain is None


def test_invalid_plants_rejected():
    for name, p, _ in mf.INVALID_PLANTS:
        try:
            ar.realize(p["kind"], p["num"], p["den"])
        except ar.ModelError:
            continue
        raise AssertionError(f"{name} accepted")


def test_zoh_cont2discrete_equals_expm_and_integral():
    for pd in _plants():
        pl = ar.realize(pd["kind"], pd["num"], pd["den"])
        n = pl.order
        for ts in (0.05, 0.1, 0.5, 2.0):
            Ad, Bd = ar.discretize(pl.A, pl.B, ts)  # asserts vs augmented expm
            M = np.zeros((n + 1, n + 1))
            M[:n, :n] = pl.A
            M[:n, n] = pl.B
            E = scipy.linalg.expm(M * ts)
            assert np.allclose(E[:n, :n], Ad, rtol=1e-13, atol=1e-15)
            assert np.allclose(E[:n, n], Bd, rtol=1e-13, atol=1e-15)
            # independent: Ad = expm(A Ts), Bd = ∫0^Ts expm(A τ) dτ B (quadrature)
            assert np.allclose(scipy.linalg.expm(pl.A * ts), Ad, rtol=1e-12, atol=1e-14)
            Bq, _ = scipy.integrate.quad_vec(lambda t: scipy.linalg.expm(pl.A * t) @ pl.B,
                                             0.0, ts, epsabs=1e-15, epsrel=1e-13)
            assert np.allclose(Bq, Bd, rtol=1e-10, atol=1e-14), (pd, ts, Bq, Bd)


# ---------------------------------------------------------------- simulation

def test_step_response_default_vehicle():
    v = ar.Vehicle.from_config({"initial_depth": 50.0})
    for r in (70.0, 30.0):
        tr = ar.simulate(v, [0.0, 600.0], [r], 50.0)
        m = mf.step_metrics(tr, 50.0, r)
        print(f"    default vehicle 50 -> {r:g} m: overshoot {m['overshoot_m']:.3g} m, "
              f"within 0.4 m (2 %) from x = {m['settle_x_0.4m']:.1f} m, "
              f"within 0.1 m from x = {m['settle_x_0.1m']:.1f} m, "
              f"max |pitch| {max(map(abs, tr.pitch)):.2f} deg")
        assert m["overshoot_m"] <= 0.5
        assert m["settle_x_0.4m"] < 250.0
        assert abs(m["final_error_m"]) < 1e-3
    # the small-signal loop is stable
    assert ar.spectral_radius(v) < 1.0


def test_step_is_symmetric():
    v = ar.Vehicle.from_config({})
    a = ar.simulate(v, [0.0, 400.0], [70.0], 50.0)
    b = ar.simulate(v, [0.0, 400.0], [30.0], 50.0)
    assert len(a.x) == len(b.x)
    assert all(abs(xa - xb) < 1e-9 for xa, xb in zip(a.x, b.x))
    assert all(abs((da - 50.0) + (db - 50.0)) < 1e-9 for da, db in zip(a.depth, b.depth))


def test_positive_gain_plant_goes_the_right_way():
    v = ar.Vehicle.from_config({"plant": mf.POSITIVE})
    tr = ar.simulate(v, [0.0, 600.0], [70.0], 50.0)
    assert abs(tr.depth[-1] - 70.0) < 1e-2
    # going deeper needs nose-down pitch: negative θ, and δ of the sign of θ (gain > 0)
    k = 100
    assert tr.pitch[k] < 0.0 and tr.elevator[k] < 0.0


def test_switch_and_stop_rules():
    v = ar.Vehicle.from_config({})
    X = [0.0, 100.0, 250.0, 400.0]
    z = [60.0, 45.0, 80.0]
    tr = ar.simulate(v, X, z, 50.0)
    assert tr.x[-1] >= X[-1] and tr.x[-2] < X[-1]
    assert len(tr.elevator) == len(tr.x) - 1 == len(tr.reference)
    for k, r in enumerate(tr.reference):
        n = max(i for i in range(3) if X[i] <= tr.x[k])
        assert r == z[n]
    # the first sample reaching X_1 already uses z_2
    k1 = next(k for k, x in enumerate(tr.x) if x >= 100.0)
    assert tr.reference[k1] == 45.0 and tr.reference[k1 - 1] == 60.0


def test_profile_outside_is_error():
    p = ar.Profile([0.0, 10.0], [5.0, 7.0])
    assert p(5.0) == 6.0 and p(10.0) == 7.0 and p(0.0) == 5.0
    for xq in (-1e-9, 10.000001):
        try:
            p(xq)
        except ar.ModelError:
            continue
        raise AssertionError("extrapolated")


# ---------------------------------------------------------------- objective

def test_flat_target_plan_has_zero_J():
    xs, bs = mf.synthetic_flat()
    prof = ar.Profile(xs, bs)
    for plant in (mf.CAUV4, mf.FOURTH, mf.POSITIVE):
        v = ar.Vehicle.from_config({"plant": plant})
        _, res = ar.evaluate_plan(v, prof, mf.W3, [420.0, 420.0, 420.0])
        assert res["total_J"] == 0.0 and res["total_violation"] == 0.0
        assert res["min_altitude"] == 80.0
        assert all(t["rms"] == 0.0 for t in res["tracks"])


def _numpy_total_J(traj, prof, X, h_r, split=True):
    """Independent vectorized trapezoid of ½ e² over [X_0, X_M].

    split=True inserts every waypoint as an extra node (depth interpolated
    linearly in x): this is model.md's definition of a plan's total J.
    split=False only clips at X_M (the plain, unsplit trapezoid)."""
    x = np.array(traj.x)
    d = np.array(traj.depth)
    XM = X[-1]
    nodes = X if split else [X[0], XM]
    xi = np.union1d(x[x <= XM], np.array(nodes, dtype=float))
    di = np.interp(xi, x, d)
    exact = np.isin(xi, x)
    di[exact] = d[np.searchsorted(x, xi[exact])]
    b = np.interp(xi, prof.x, prof.b)
    e2 = (b - h_r - di) ** 2
    return 0.5 * float(np.sum(np.diff(xi) * (e2[1:] + e2[:-1]) / 2.0))


def test_clipping_sums_to_unclipped_total():
    for name in ("us_monterey_canyon_1", "es_medes_islands_1"):
        prof, X = mf.load_real(name)
        h_r, h_a = mf.REAL[name]
        v = ar.Vehicle.from_config({"reference_altitude": h_r, "min_altitude": h_a})
        z = mf.plan("offset", prof, X, h_r, prof(X[0]) - h_r)
        tr, res = ar.evaluate_plan(v, prof, X, z)
        # Σ J_n equals the trapezoid over the whole line with the waypoints
        # inserted as nodes (independent numpy code) to rounding ...
        Js = _numpy_total_J(tr, prof, X, h_r, split=True)
        assert abs(res["total_J"] - Js) <= 1e-12 * Js, (res["total_J"], Js)
        # ... and the unsplit trapezoid over [X_0, X_M] (computed both by the
        # reference with a single interval and by numpy) to O(Δx³) per split
        whole = ar.evaluate(tr, prof, [X[0], X[-1]], h_r, h_a)
        J1 = whole["total_J"]
        Ju = _numpy_total_J(tr, prof, X, h_r, split=False)
        assert abs(Ju - J1) <= 1e-12 * J1, (Ju, J1)
        rel = abs(res["total_J"] - J1) / J1
        print(f"    {name}: sum of clipped tracks {res['total_J']!r}, unsplit "
              f"{J1!r} (rel. diff {rel:.1e})")
        assert rel <= 1e-7
        assert abs(res["total_violation"] - whole["total_violation"]) <= \
            1e-7 * max(1.0, whole["total_violation"])
        assert res["min_altitude"] == whole["min_altitude"]
        # a much finer split (cuts between samples) still sums to ~ the total
        fine = [X[0]] + [X[0] + (X[-1] - X[0]) * k / 37.0 for k in range(1, 37)] + [X[-1]]
        fr = ar.evaluate(tr, prof, fine, h_r, h_a)
        assert abs(fr["total_J"] - _numpy_total_J(tr, prof, fine, h_r)) <= 1e-12 * J1
        assert abs(fr["total_J"] - J1) <= 1e-6 * J1


def test_track_shorter_than_a_step():
    xs, bs = mf.synthetic_slope(30.0)
    prof = ar.Profile(xs, bs)
    v = ar.Vehicle.from_config({})
    X = [0.0, 500.0, 500.01, 1500.0]  # middle track 1 cm: inside one segment
    tr, res = ar.evaluate_plan(v, prof, X, [520.0, 400.0, 300.0])
    t2 = res["tracks"][1]
    assert t2["J"] > 0.0 and math.isfinite(t2["rms"])
    Js = _numpy_total_J(tr, prof, X, 80.0, split=True)
    assert abs(res["total_J"] - Js) <= 1e-12 * Js


def test_violation_definition():
    # Altitude constant at 50 m above a flat bottom, h_a = 60: p = 10 everywhere.
    xs, bs = mf.synthetic_flat(depth=500.0)
    prof = ar.Profile(xs, bs)
    v = ar.Vehicle.from_config({"initial_depth": 450.0})
    _, res = ar.evaluate_plan(v, prof, mf.W3, [450.0] * 3)
    for t in res["tracks"]:
        # (x accumulates 0.15 m steps: the sample grid carries ~1e-10 m rounding)
        assert abs(t["violation"] - 0.5 * 100.0 * 500.0) < 1e-12 * 25000.0 * 1e3
        assert abs(t["J"] - 0.5 * 900.0 * 500.0) < 1e-12 * 225000.0 * 1e3
        assert abs(t["rms"] - 30.0) < 1e-10
        assert t["min_altitude"] == 50.0


# ---------------------------------------------------------------- fixtures

def test_fixtures_reproduce():
    path = os.path.join(FIXTURES, "plants.json")
    if not os.path.exists(path):
        print("    (fixtures not generated yet; skipped)")
        return
    assert json.load(open(path)) == json.loads(json.dumps(mf.make_plants()))
    steps = json.load(open(os.path.join(FIXTURES, "step_response.json")))
    for c in steps:
        v = ar.Vehicle.from_config(c["vehicle"])
        tr = ar.simulate(v, c["waypoints"], [c["reference_depth"]], c["initial_depth"])
        assert tr.x == c["samples"]["x"] and tr.depth == c["samples"]["depth"], c["name"]
        assert tr.elevator == c["samples"]["elevator"], c["name"]
    ev = json.load(open(os.path.join(FIXTURES, "evaluations.json")))
    for c in ev["cases"]:
        if isinstance(c["profile"], str):
            prof, X = mf.load_real(c["profile"])
            assert X == c["waypoints"]
        else:
            prof = ar.Profile(c["profile"]["x"], c["profile"]["b"])
        v = ar.Vehicle.from_config(c["vehicle"])
        _, res = ar.evaluate_plan(v, prof, c["waypoints"], c["depths"])
        for key in ("total_J", "total_violation", "min_altitude", "n_samples",
                    "final_x", "final_depth"):
            assert res[key] == c[key], (c["name"], key)
        assert res["tracks"] == c["tracks"], c["name"]


def main():
    tests = [(k, f) for k, f in globals().items() if k.startswith("test_") and callable(f)]
    failed = 0
    for name, f in tests:
        try:
            f()
            print(f"ok   {name}")
        except Exception:  # noqa: BLE001
            failed += 1
            print(f"FAIL {name}")
            traceback.print_exc()
    print(f"{len(tests) - failed} passed, {failed} failed")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
