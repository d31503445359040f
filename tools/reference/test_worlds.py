#!/usr/bin/env python3
"""Self-tests of worlds.py (model.md section 12).  Plain asserts:

    python3 tools/reference/test_worlds.py      (also works under pytest)
"""

from __future__ import annotations

import math
import os
import random
import sys

import numpy as np

sys.dont_write_bytecode = True
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import auvref as ar  # noqa: E402
import worlds as W  # noqa: E402

DATA = "/work/shared/data/bathymetry"
if not os.path.isdir(DATA):
    DATA = os.path.join(HERE, "..", "..", "data", "bathymetry")


def _monterey():
    import ref_plan
    prof = ar.Profile.from_csv(os.path.join(DATA, "us_monterey_canyon_1.csv"))
    X = ref_plan.load_waypoints(os.path.join(DATA, "us_monterey_canyon_1.waypoints.csv"))
    return prof, X


def test_zero_world_is_nominal():
    """All bounds 0: the flight and the altitudes are auvref's, bit for bit."""
    prof, X = _monterey()
    plants = [None,
              {"kind": "pitch", "num": [-0.05, -0.2], "den": [1.0, 3.2, 3.1, 0.9, 0.08]},
              {"kind": "pitch", "num": [0.5], "den": [1.0, 1.2, 0.35]}]
    for plant in plants:
        cfg = {} if plant is None else {"plant": plant, "pitch_pid": {"kp": 2.0, "ki": 0.1, "kd": 2.5}}
        v = ar.Vehicle.from_config(cfg)
        z = [prof(x) - 80.0 + 15.0 * (-1) ** i for i, x in enumerate(X[1:])]
        d0 = prof(X[0]) - 80.0
        tr, res = ar.evaluate_plan(v, prof, X, z)
        b = W.Bounds()
        ms, bs = W.sample_worlds(b, v.speed, X[0], X[-1], 8, 0)
        assert len(ms) == 1 and len(bs) == 1, (ms, bs)
        tr2 = W.fly(v, X, z, d0, ms[0])
        assert tr2.x == tr.x and tr2.depth == tr.depth and tr2.pitch == tr.pitch
        alts = W.track_min_altitudes(W.track_points(tr2, X), prof, bs[0])
        ref = [t["min_altitude"] for t in res["tracks"]]
        assert alts == ref, (alts, ref)
        worst, det = W.worst_case(v, prof, X, z, d0, b, 8, 0)
        assert [w[0] for w in worst] == ref
        assert det["nominal"] == ref


def test_vertical_current_level_flight():
    """w > 0 on a level flight (flat bottom, reference = start depth): the
    vehicle ends deeper; the closed loop fights back, so the offset grows like
    w t at first (before the loop reacts) and then levels off."""
    prof = ar.Profile([0.0, 5000.0], [500.0, 500.0])
    v = ar.Vehicle.from_config({})
    X = [0.0, 3000.0]
    d0 = 420.0
    w = 0.05
    nom = W.fly(v, X, [d0], d0)
    wet = W.fly(v, X, [d0], d0, W.Motion(v.speed, 0.0, w))
    assert all(d == d0 for d in nom.depth)  # trimmed level flight stays level
    Ts = v.sample_time
    # first 1 s: the loop has hardly reacted, depth offset ~ w t
    k = int(round(1.0 / Ts))
    dd = wet.depth[k] - nom.depth[k]
    assert abs(dd - w * k * Ts) < 0.1 * w * k * Ts, dd
    # open-loop bound: never more than w t deeper, and always deeper (> 0)
    for i in range(1, 200):
        off = wet.depth[i] - d0
        assert 0.0 < off <= w * i * Ts + 1e-12, (i, off)
    # steady state: deeper by a positive amount, altitude lower
    assert wet.depth[-1] > d0 + 1e-3
    a_nom = W.track_min_altitudes(W.track_points(nom, X), prof, None)[0]
    a_wet = W.track_min_altitudes(W.track_points(wet, X), prof, None)[0]
    assert a_wet < a_nom
    # w < 0 is the mirror image
    dry = W.fly(v, X, [d0], d0, W.Motion(v.speed, 0.0, -w))
    for a, b in zip(wet.depth, dry.depth):
        assert abs((a - d0) + (b - d0)) < 1e-9


def test_flight_path_offset_climb():
    """alpha > 0 (flight path below the pitch): deeper when climbing."""
    prof = ar.Profile([0.0, 5000.0], [800.0, 800.0])
    v = ar.Vehicle.from_config({})
    X = [0.0, 2000.0]
    d0 = 700.0
    z = [600.0]  # climb 100 m
    nom = W.fly(v, X, z, d0)
    up = W.fly(v, X, z, d0, W.Motion(v.speed, 1.0, 0.0))
    # compare at equal x (depths interpolated), over the climb
    xq = np.linspace(50.0, 400.0, 50)
    dn = np.interp(xq, nom.x, nom.depth)
    du = np.interp(xq, up.x, up.depth)
    assert np.all(dn < 699.0)  # it is climbing there
    assert np.all(du > dn), (du - dn)
    # alpha < 0 makes it shallower
    dw = np.interp(xq, *(lambda t: (t.x, t.depth))(W.fly(v, X, z, d0, W.Motion(v.speed, -1.0, 0.0))))
    assert np.all(dw < dn)


def test_speed_scales_time_not_path_at_first():
    """U only changes the time scale of the kinematics; with a different U
    the vehicle still starts level and x advances by U Ts per step."""
    prof = ar.Profile([0.0, 5000.0], [800.0, 800.0])
    v = ar.Vehicle.from_config({})
    tr = W.fly(v, [0.0, 100.0], [720.0], 720.0, W.Motion(1.2, 0.0, 0.0))
    assert abs(tr.x[1] - 1.2 * v.sample_time) < 1e-12


def test_shift_equals_shifted_profile():
    """A constant s shifts the bottom: b_w(x) = b(x + s) = shifted profile's b."""
    rng = random.Random(3)
    xs = [0.0]
    while xs[-1] < 3000.0:
        xs.append(xs[-1] + rng.uniform(3.0, 30.0))
    bs = [400.0]
    for _ in xs[1:]:
        bs.append(bs[-1] + rng.uniform(-15.0, 15.0))
    prof = ar.Profile(xs, bs)
    s = 17.25
    shifted = ar.Profile([x - s for x in xs], bs)  # b'(x) = b(x + s)
    v = ar.Vehicle.from_config({})
    X = [100.0, 900.0, 1800.0, 2700.0]
    z = [prof(x) - 80.0 for x in X[1:]]
    d0 = prof(X[0]) - 80.0
    pts = W.track_points(W.fly(v, X, z, d0), X)
    bot = W.Bottom("const", lambda x: np.full(np.shape(x), s), None)
    a = W.track_min_altitudes(pts, prof, bot)
    b = W.track_min_altitudes(pts, shifted, None)
    assert all(abs(p - q) < 1e-9 for p, q in zip(a, b)), (a, b)
    # pointwise against auvref.Profile on the shifted grid
    xq = np.linspace(100.0, 2700.0, 777)
    got = bot(prof, xq)
    ref = np.array([shifted(x) for x in xq])
    assert np.max(np.abs(got - ref)) < 1e-9
    # v adds to the bottom
    botv = W.Bottom("cv", None, lambda x: np.full(np.shape(x), -3.0))
    av = W.track_min_altitudes(pts, prof, botv)
    a0 = W.track_min_altitudes(pts, prof, None)
    assert all(abs(p - (q - 3.0)) < 1e-12 for p, q in zip(av, a0))
    # clamping beyond the ends
    assert W.bottom_interp(prof, [-50.0])[0] == bs[0]
    assert W.bottom_interp(prof, [xs[-1] + 50.0])[0] == bs[-1]


def test_envelope_is_the_worst_shift():
    """The shallow envelope is <= b(x + s) for every |s| <= S(x), and attained."""
    rng = random.Random(5)
    xs = [0.0]
    while xs[-1] < 2000.0:
        xs.append(xs[-1] + rng.uniform(2.0, 40.0))
    bs = [300.0]
    for _ in xs[1:]:
        bs.append(bs[-1] + rng.uniform(-25.0, 25.0))
    prof = ar.Profile(xs, bs)
    b = W.Bounds(e_h=12.0, r=0.004)
    X0 = 50.0
    xq = np.linspace(X0, 1990.0, 1500)
    S = b.s_bound(xq, X0)
    env = W.Bottom("e", kind="envelope", shallow=True, bounds=b, X0=X0)(prof, xq)
    deep = W.Bottom("e", kind="envelope", shallow=False, bounds=b, X0=X0)(prof, xq)
    brute_min = np.full(xq.shape, np.inf)
    brute_max = np.full(xq.shape, -np.inf)
    for t in np.linspace(-1.0, 1.0, 401):
        bb = W.bottom_interp(prof, xq + t * S)
        brute_min = np.minimum(brute_min, bb)
        brute_max = np.maximum(brute_max, bb)
    # also the vertices inside each window
    px = np.array(xs)
    for i, x in enumerate(xq):
        m = (px > x - S[i]) & (px < x + S[i])
        if m.any():
            brute_min[i] = min(brute_min[i], np.min(np.array(bs)[m]))
            brute_max[i] = max(brute_max[i], np.max(np.array(bs)[m]))
    assert np.max(np.abs(env - brute_min)) < 1e-9
    assert np.max(np.abs(deep - brute_max)) < 1e-9
    for sg in (1.0, -1.0):
        assert np.all(env <= W.bottom_interp(prof, xq + sg * S) + 1e-12)


def test_random_worlds_within_bounds():
    b = W.Bounds(7.0, 0.003, 4.0, 0.08, 1.5, 0.07)
    U0 = 1.5
    ms, bs = W.sample_worlds(b, U0, 0.0, 3000.0, 20, "t")
    xq = np.linspace(0.0, 3000.0, 3001)
    S = b.s_bound(xq, 0.0)
    for m in ms:
        assert U0 * (1 - b.eps_U) - 1e-12 <= m.U <= U0 * (1 + b.eps_U) + 1e-12
        assert abs(m.alpha) <= b.alpha_max and abs(m.w) <= b.w_max
    n_shift = 0
    for bt in bs:
        if bt.kind != "shift":
            continue
        n_shift += 1
        s = bt.s(xq) if bt.s is not None else np.zeros_like(xq)
        v = bt.v(xq) if bt.v is not None else np.zeros_like(xq)
        assert np.all(np.abs(s) <= S + 1e-9), bt.name
        assert np.all(np.abs(v) <= b.e_v + 1e-9), bt.name
    assert n_shift == 1 + 4 + 20
    # seeded: the same seed gives the same worlds
    ms2, bs2 = W.sample_worlds(b, U0, 0.0, 3000.0, 20, "t")
    assert [m.name for m in ms] == [m.name for m in ms2]
    assert np.array_equal(bs[-1].s(xq), bs2[-1].s(xq))


def test_corner_count():
    U0 = 1.5
    full = W.Bounds(5.0, 0.001, 2.0, 0.05, 1.0, 0.05)
    assert len(W.corner_motions(full, U0)) == 8  # U x alpha x w
    assert len(W.corner_bottoms(full, 0.0)) == 8  # v(2) x s(+S, -S, 2 envelopes)
    ms, bs = W.sample_worlds(full, U0, 0.0, 1000.0, 0, 0)
    assert len(ms) == 1 + 8 and len(bs) == 1 + 8
    only_w = W.Bounds(w_max=0.1)
    assert len(W.corner_motions(only_w, U0)) == 2
    assert len(W.corner_bottoms(only_w, 0.0)) == 1
    only_drift = W.Bounds(r=0.002)
    assert len(W.corner_bottoms(only_drift, 0.0)) == 4
    assert len(W.corner_motions(only_drift, U0)) == 1
    ms, bs = W.sample_worlds(only_w, U0, 0.0, 1000.0, 5, 0)
    assert len(ms) == 1 + 2 + 5 and len(bs) == 1  # only the nominal bottom


def test_bounds_from_config():
    b = W.Bounds.from_config({"horizontal_uncertainty": 3, "vertical_current": 0.02})
    assert b == W.Bounds(e_h=3.0, w_max=0.02)
    assert W.Bounds.from_config({}).is_zero()
    try:
        W.Bounds.from_config({"nav_drift": -1.0})
    except ar.ModelError:
        pass
    else:
        raise AssertionError("negative bound accepted")


def main():
    tests = [(k, v) for k, v in sorted(globals().items())
             if k.startswith("test_") and callable(v)]
    for name, fn in tests:
        fn()
        print(f"ok {name}")
    print(f"{len(tests)} tests passed")


if __name__ == "__main__":
    main()
