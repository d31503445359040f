#!/usr/bin/env python3
"""Brute-force f64 checker of the Rust planner's acceptance criteria.

    python3 tools/reference/check_planner.py [--bin-cmd CMD] [--unseen 3] [--seed 7]
    python3 tools/reference/check_planner.py --self-test
    python3 tools/reference/check_planner.py --json-out planner_check.json

For each of the six real profiles in data/bathymetry (h_r/h_a 80/60 on Monterey,
5/3 on Medes, 2/1 on Aburatsubo, written to a generated VEHICLE.toml) and
--unseen N random profiles (h_r/h_a 80/60), it runs the `plan` tool in four
configurations and checks:

  1. track  --unconstrained --method bfgs: per track n, from the state reached
     by flying the tool's own depths of tracks 1..n-1, J_n(tool) <= 1.005 x
     the brute-force min_z J_n(z) + 1e-2 m^3, and iterations <= 10;
  2. track (constrained, bfgs): the best safe J_n by the same search; if no
     depth in [0, 6000] is safe, status must be "infeasible"; else the tool's
     depth must be safe when re-simulated (>= h_a - 1e-2 m) and J_n(tool) <=
     1.005 x best safe + 1e-2 m^3;
  3. horizon (bfgs): a beam search for the best safe whole-line plan; the
     tool's flight must be safe (re-simulated, >= h_a - 1e-2 m) and its total
     J <= 1.10 x the beam's best.  Where no safe plan is found, the tool's
     statuses are reported;
  4. every mode: every track reported "safe": true is safe in the f64
     re-simulation, and the reported J matches it (1e-3 relative);
  5. (informational) track --unconstrained --method gd: iterations next to
     BFGS's.

One line per check, then exactly `N passed, M failed`; exit status 1 on any
failure.  `--self-test` needs no Rust: it feeds the checker plans found by its
own searches (which must pass) and deliberately spoiled ones (which must be
caught), and cross-checks the vectorized simulator against auvref.py.
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import copy  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import multiprocessing  # noqa: E402
import random  # noqa: E402
import shlex  # noqa: E402
import shutil  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.dont_write_bytecode = True  # keep the source tree clean
sys.path.insert(0, HERE)
import auvref as ar  # noqa: E402
import check_plan  # noqa: E402  (file writers)
import ref_plan  # noqa: E402  (file readers)

DEFAULT_CMD = "cargo run --release --quiet --example plan --"
DATA = os.path.join(ROOT, "data", "bathymetry")
SHARED = [
    ("us_monterey_canyon_1", 80.0, 60.0),
    ("us_monterey_canyon_2", 80.0, 60.0),
    ("us_monterey_canyon_3", 80.0, 60.0),
    ("es_medes_islands_1", 5.0, 3.0),
    ("es_medes_islands_2", 5.0, 3.0),
    ("jp_aburatsubo_sagami_1", 2.0, 1.0),
]
DEG = math.pi / 180.0  # as math.radians

# acceptance thresholds (the issue's)
J_RATIO_TRACK = 1.005
J_FLOOR = 1e-2  # m^3
MAX_ITER_BFGS = 10
J_RATIO_HORIZON = 1.10
ALT_TOL = 1e-2  # m, f32 vs f64 altitude agreement
J_RESIM_RTOL = 1e-3


# --------------------------------------------------------------------------
# Vectorized f64 simulator: many candidates flown in lock-step
# --------------------------------------------------------------------------


class Fast:
    """The model of auvref.simulate/evaluate, one track at a time, vectorized
    over a batch of candidates (each with its own start state and depth).

    A state is a column of S (shape (n+6, N)): eta_0..eta_{n-1}, I_d, I_theta,
    x, d, d_prev, x_prev -- the sample at which the vehicle has just reached
    the track's first waypoint (the first sample with x >= X_{n-1}) and the x
    of the sample before it (for the clipped piece [X_{n-1}, x_k], flown under
    the previous depth, which belongs to J_n)."""

    def __init__(self, vehicle: ar.Vehicle, profile: ar.Profile, waypoints):
        v = vehicle
        self.v = v
        self.prof = profile
        self.X = [float(x) for x in waypoints]
        self.M = len(self.X) - 1
        self.no = v.plant.order
        no = self.no
        self.I_ID, self.I_IT, self.I_X, self.I_D, self.I_DP, self.I_XP = range(no, no + 6)
        self.nrow = no + 6
        self.Ad = np.array(v.Ad, dtype=float)
        self.Bd = np.array(v.Bd, dtype=float).reshape(no, 1)
        self.C = np.array(v.plant.C, dtype=float)
        self.CA = np.array(v.plant.CA, dtype=float)
        self.h_r = v.reference_altitude
        self.h_a = v.min_altitude
        self.U = v.speed * v.sample_time
        self.lo, self.hi = v.depth_limits
        px = np.array(profile.x, dtype=float)
        pb = np.array(profile.b, dtype=float)
        self.px0 = px[:-1]
        self.pb0 = pb[:-1]
        self.pdb = pb[1:] - pb[:-1]
        self.pdx = px[1:] - px[:-1]
        self.px = px
        self.nseg = len(px) - 1
        # uniform sampling (all shipped profiles): index by arithmetic, much
        # faster than searchsorted; a sample on a breakpoint may pick the
        # neighbouring segment, which gives the same b to rounding
        dx0 = float(self.pdx[0])
        self.uniform = bool(np.all(np.abs(self.pdx - dx0) <= 1e-9 * dx0))
        self.inv_dx = 1.0 / dx0
        self.steps = 0  # candidate-steps simulated (statistics)

    # bottom depth, exactly auvref.Profile.__call__'s formula
    def bottom(self, x):
        if self.uniform:
            i = ((x - self.px[0]) * self.inv_dx).astype(np.intp)
            np.minimum(i, self.nseg - 1, out=i)
        else:
            i = np.searchsorted(self.px, x, side="right") - 1
            np.clip(i, 0, self.nseg - 1, out=i)
        return self.pb0.take(i) + self.pdb.take(i) * (x - self.px0.take(i)) / self.pdx.take(i)

    def start(self, d0=None, N=1):
        """The default start: trimmed level flight at X_0, depth d0."""
        if d0 is None:
            d0 = self.v.resolved_initial_depth(self.prof, self.X[0])
        S = np.zeros((self.nrow, N))
        S[self.I_X] = self.X[0]
        S[self.I_D] = d0
        S[self.I_DP] = d0
        S[self.I_XP] = self.X[0] - 1.0  # dummy: the clipped piece has length 0
        return S

    def fly(self, S, z, n):
        """Fly track n (1-based) from states S with depths z.

        Returns (J_n, min altitude over [X_{n-1}, X_n], end states), with the
        end state at the first sample with x >= X_n."""
        v = self.v
        no = self.no
        S = np.array(S, dtype=float, copy=True)
        z = np.asarray(z, dtype=float)
        N = S.shape[1]
        if z.shape != (N,):
            z = np.broadcast_to(z, (N,)).copy()
        Xa, Xb = self.X[n - 1], self.X[n]
        h_r = self.h_r
        Ts, U = v.sample_time, self.U
        thmax, dmax = v.pitch_limit, v.elevator_limit
        kpd, kid, kdd = v.kpd, v.kid, v.kdd
        kpt, kit, kdt = v.kpt, v.kit, v.kdt
        sigma = v.plant.sigma
        Ad, Bd, C, CA = self.Ad, self.Bd, self.C, self.CA

        eta = S[:no]
        Id = S[self.I_ID]
        Ith = S[self.I_IT]
        x = S[self.I_X]
        d = S[self.I_D]
        dp = S[self.I_DP]
        xp = S[self.I_XP]
        if np.any(x > Xb):
            raise ar.ModelError("track shorter than one step")

        # clipped piece [X_{n-1}, x_k] (flown under the previous depth)
        dc = dp + (d - dp) * (Xa - xp) / (x - xp)
        dc = np.where(x == Xa, d, dc)
        ba = self.bottom(np.full(N, Xa))
        ec = ba - h_r - dc
        b = self.bottom(x)
        e = b - h_r - d
        J = (x - Xa) * (ec * ec + e * e) / 4.0
        hmin = np.minimum(ba - dc, b - d)

        theta = C @ eta
        q = CA @ eta
        out_S = np.empty((self.nrow, N))
        out_J = np.empty(N)
        out_h = np.empty(N)
        idx = np.arange(N)  # original column of each working candidate
        bXb = float(self.prof(Xb))
        guard = 0
        while True:
            if guard <= 0:
                guard = int((Xb - float(x.max())) / U) - 1
            # 1. reference is z (the sample is inside the track)
            # 2. depth loop
            e_d = z - d
            ddot = (d - dp) / Ts
            if kid != 0.0:
                vk = -(kpd * e_d + kid * Id - kdd * ddot)
            else:
                vk = -(kpd * e_d + 0.0 - kdd * ddot)
            thref = np.minimum(np.maximum(vk, -thmax), thmax)
            e_t = thref - theta
            wk = sigma * (kpt * e_t + kit * Ith - kdt * q)
            delta = np.minimum(np.maximum(wk, -dmax), dmax)
            if kid != 0.0:
                skip = ((vk > thmax) & (e_d < 0.0)) | ((vk < -thmax) & (e_d > 0.0))
                Id = Id + np.where(skip, 0.0, Ts * e_d)
            else:
                Id = Id + Ts * e_d  # unused by the loop (kid = 0); kept as state
            se = sigma * e_t
            skip = (wk * se > 0.0) & (np.abs(wk) > dmax)
            Ith = Ith + np.where(skip, 0.0, Ts * e_t)
            # 3. plant
            eta = Ad @ eta + Bd * delta
            theta1 = C @ eta
            # 4. kinematics
            tb = (0.5 * (theta + theta1)) * DEG
            x1 = x + U * np.cos(tb)
            d1 = d - U * np.sin(tb)
            q = CA @ eta
            self.steps += x.shape[0]
            guard -= 1
            if guard <= 0:
                cross = x1 >= Xb
                if cross.any():
                    c = np.nonzero(cross)[0]
                    # clipped end piece [x_k, X_b]
                    xc, dcur, d1c = x[c], d[c], d1[c]
                    dcb = np.where(x1[c] == Xb, d1c,
                                   dcur + (d1c - dcur) * (Xb - xc) / (x1[c] - xc))
                    ecb = bXb - h_r - dcb
                    ec0 = e[c]
                    jj = idx[c]
                    out_J[jj] = J[c] + (Xb - xc) * (ec0 * ec0 + ecb * ecb) / 4.0
                    out_h[jj] = np.minimum(hmin[c], bXb - dcb)
                    out_S[:no, jj] = eta[:, c]
                    out_S[self.I_ID, jj] = Id[c]
                    out_S[self.I_IT, jj] = Ith[c]
                    out_S[self.I_X, jj] = x1[c]
                    out_S[self.I_D, jj] = d1c
                    out_S[self.I_DP, jj] = dcur
                    out_S[self.I_XP, jj] = xc
                    keep = ~cross
                    if not keep.any():
                        return out_J, out_h, out_S
                    idx = idx[keep]
                    eta = eta[:, keep]
                    Id, Ith, x, d, z = Id[keep], Ith[keep], x[keep], d[keep], z[keep]
                    x1, d1, e = x1[keep], d1[keep], e[keep]
                    theta1, q, J, hmin = theta1[keep], q[keep], J[keep], hmin[keep]
            # sample k+1 inside the track: full trapezoid segment
            b1 = self.bottom(x1)
            e1 = b1 - h_r - d1
            J = J + (x1 - x) * (e * e + e1 * e1) / 4.0
            hmin = np.minimum(hmin, b1 - d1)
            # 5. shift
            dp = d
            d = d1
            x = x1
            e = e1
            theta = theta1

    # ---- whole plans -------------------------------------------------------

    def fly_plan(self, zs, S0=None, first=1):
        """Fly tracks first..first+len(zs[0])-1 for a batch of plans.

        zs: array (N, K) of depths; S0: start states (nrow, N) or None for the
        default start (first must then be 1).  Returns (J (N, K), hmin (N, K),
        states (K+1 arrays (nrow, N): the start of each track and the end))."""
        zs = np.atleast_2d(np.asarray(zs, dtype=float))
        N, K = zs.shape
        S = self.start(N=N) if S0 is None else S0
        Js = np.empty((N, K))
        hs = np.empty((N, K))
        states = [S]
        for k in range(K):
            J, h, S = self.fly(S, zs[:, k], first + k)
            Js[:, k] = J
            hs[:, k] = h
            states.append(S)
        return Js, hs, states


# --------------------------------------------------------------------------
# Track search: brute force over z for one track from a given state
# --------------------------------------------------------------------------


def _pick_minima(z, f, adm, k, min_sep=2):
    """Indices of the k best local minima of f among admissible points
    (non-admissible neighbours count as +inf), at least min_sep apart."""
    n = len(z)
    if n == 0:
        return []
    g = np.where(adm, f, np.inf)
    left = np.concatenate(([np.inf], g[:-1]))
    right = np.concatenate((g[1:], [np.inf]))
    cand = np.nonzero(adm & (g <= left) & (g <= right))[0]
    # points strictly inside a flat stretch need no refinement; keep its ends
    flat = (g == left) & (g == right)
    cand = [i for i in cand if not flat[i]] or list(cand[:1])
    cand.sort(key=lambda i: g[i])
    out = []
    for i in cand:
        if all(abs(i - j) >= min_sep for j in out):
            out.append(i)
        if len(out) >= k:
            break
    return out


class Pool:
    """All (z, J, hmin) evaluated for one track from one state, kept sorted."""

    def __init__(self):
        self.z = np.empty(0)
        self.J = np.empty(0)
        self.h = np.empty(0)

    def add(self, z, J, h):
        z = np.concatenate((self.z, z))
        J = np.concatenate((self.J, J))
        h = np.concatenate((self.h, h))
        z, i = np.unique(z, return_index=True)
        self.z, self.J, self.h = z, J[i], h[i]


def search_track(fm: Fast, S, n, k_best=6, n_coarse=201, n_fine=600, tol_z=0.005):
    """Brute-force min over z in the depth limits of J_n(z) from state S
    (one column), unconstrained and subject to min altitude >= h_a.

    1. coarse grid (n_coarse points) over the reachable range (start depth
       +- L tan(theta_max + 10 deg) + 4 h_r + 50 m, clipped to the limits;
       the limits themselves are added: beyond reach the pitch reference
       saturates over the whole track and J is constant);
    2. fine grid (n_fine points) over the part of that range where J varies;
    3. successive refinement: around the k_best local minima (of J, of J over
       the safe points, and of -hmin when nothing is safe yet), 10 new points
       in each neighbouring interval, until the neighbours are tol_z apart.
    """
    S = np.asarray(S, dtype=float).reshape(fm.nrow, 1)
    h_a = fm.h_a
    L = fm.X[n] - fm.X[n - 1]
    d_s = float(S[fm.I_D, 0])
    R = L * math.tan(math.radians(min(fm.v.pitch_limit + 10.0, 80.0))) + 4 * fm.h_r + 50.0
    zlo, zhi = max(fm.lo, d_s - R), min(fm.hi, d_s + R)
    pool = Pool()
    n_eval = 0

    def ev(z):
        nonlocal n_eval
        z = np.unique(np.clip(np.asarray(z, dtype=float), fm.lo, fm.hi))
        z = z[~np.isin(z, pool.z)]
        if len(z) == 0:
            return
        J, h, _ = fm.fly(np.repeat(S, len(z), axis=1), z, n)
        n_eval += len(z)
        pool.add(z, J, h)

    zA = np.linspace(zlo, zhi, n_coarse) if zhi > zlo else np.array([zlo])
    ev(np.concatenate((zA, [fm.lo, fm.hi])))
    # where does J (or hmin) vary?  the saturated plateaus at both ends don't
    J, h, z = pool.J, pool.h, pool.z
    var = (J != J[0]) | (h != h[0])
    var2 = (J != J[-1]) | (h != h[-1])
    if var.any() and var2.any():
        i0 = max(int(np.argmax(var)) - 1, 0)
        i1 = min(len(z) - 1 - int(np.argmax(var2[::-1])) + 1, len(z) - 1)
        if i1 > i0:
            ev(np.linspace(z[i0], z[i1], n_fine))
    vlo, vhi = float(pool.z[0]), float(pool.z[-1])

    for _level in range(12):
        z, J, h = pool.z, pool.J, pool.h
        safe = h >= h_a
        allp = np.ones(len(z), dtype=bool)
        picks = set(_pick_minima(z, J, allp, k_best))
        picks |= set(_pick_minima(z, J, safe, k_best))
        if not safe.any():
            picks |= set(_pick_minima(z, -h, allp, k_best))
        new = []
        for i in picks:
            for j in (i - 1, i + 1):
                if 0 <= j < len(z) and abs(z[j] - z[i]) > tol_z:
                    new.append(np.linspace(z[i], z[j], 12)[1:-1])
        if not new:
            break
        ev(np.concatenate(new))

    z, J, h = pool.z, pool.J, pool.h
    safe = h >= h_a
    i = int(np.argmin(J))
    res = {
        "track": n,
        "start_depth": d_s,
        "z_range": [zlo, zhi],
        "varying_range": [vlo, vhi],
        "evaluations": n_eval,
        "best_z": float(z[i]),
        "best_J": float(J[i]),
        "best_min_altitude": float(h[i]),
        "max_min_altitude": float(h.max()),
        "z_max_min_altitude": float(z[int(np.argmax(h))]),
        "feasible": bool(safe.any()),
    }
    if safe.any():
        js = np.where(safe, J, np.inf)
        k = int(np.argmin(js))
        res.update(best_safe_z=float(z[k]), best_safe_J=float(J[k]),
                   best_safe_min_altitude=float(h[k]))
    else:
        res.update(best_safe_z=None, best_safe_J=None, best_safe_min_altitude=None)
    # the distinct local minima of J (for the report)
    mins = _pick_minima(z, J, np.ones(len(z), dtype=bool), 4, min_sep=max(3, len(z) // 50))
    res["local_minima"] = [[float(z[m]), float(J[m])] for m in mins]
    return res


# --------------------------------------------------------------------------
# Whole-line search: beam search over tracks, then a local coordinate search
# --------------------------------------------------------------------------


def _track_band(fm: Fast, n):
    """Bottom depth range over track n (profile samples and the ends)."""
    a, b = fm.X[n - 1], fm.X[n]
    bs = [fm.prof(a), fm.prof(b)] + [bb for xx, bb in zip(fm.prof.x, fm.prof.b) if a < xx < b]
    return min(bs), max(bs)


def beam_search(fm: Fast, B=100, nz=32, seed=0, center=None, halfwidth=None):
    """Best safe whole-line plan by beam search.

    Track by track, every kept partial plan (a start state) is extended by nz
    depths: a third spread over the reachable range (its two ends included:
    beyond them the pitch reference saturates over the whole track), two
    thirds over the band [min b - 2 h_r, max b - h_a + h_r] of the track, each
    grid jittered per state.  Extensions that are unsafe on the new track are
    dropped; the survivors are binned by their depth at the track's end (bins
    of h_r/40) and the best of each bin kept; the next beam is the 3B/4 best
    bins by accumulated J plus the B/4 shallowest other bins (a reserve for
    walls further on).  Returns a dict (plan, per-track J and min altitude,
    total J), or None with the track where every partial plan died.

    With `center` (a plan) and `halfwidth`, a focused pass: the nz depths of
    track n are spread over center_n +- halfwidth (center_n itself included)
    and the bins are halfwidth/20 wide."""
    rng = np.random.default_rng(seed)
    h_r, h_a = fm.h_r, fm.h_a
    S = fm.start()
    acc = np.zeros(1)
    plans = np.zeros((1, 0))
    Jt = np.zeros((1, 0))
    ht = np.zeros((1, 0))
    tan = math.tan(math.radians(min(fm.v.pitch_limit + 10.0, 80.0)))
    w = h_r / 40.0 if center is None else halfwidth / 20.0
    n_eval = 0
    for n in range(1, fm.M + 1):
        L = fm.X[n] - fm.X[n - 1]
        nb = S.shape[1]
        ds = S[fm.I_D]
        R = L * tan + 50.0
        a = np.maximum(fm.lo, ds - R)
        b = np.minimum(fm.hi, ds + R)
        bmin, bmax = _track_band(fm, n)
        ba = np.maximum(a, bmin - 2.0 * h_r)
        bb = np.minimum(b, bmax - h_a + h_r)
        bb = np.where(bb > ba, bb, b)
        ba = np.where(bb > ba, ba, a)
        if center is None:
            nu = max(nz // 3, 3)
            nbnd = nz - nu
            u1 = (np.arange(nu - 2)[None, :] + rng.random((nb, nu - 2))) / (nu - 2)
            u2 = (np.arange(nbnd)[None, :] + rng.random((nb, nbnd))) / nbnd
            Z = np.concatenate((a[:, None], b[:, None],
                                a[:, None] + (b - a)[:, None] * u1,
                                ba[:, None] + (bb - ba)[:, None] * u2), axis=1)
        else:
            c = float(center[n - 1])
            u = (np.arange(nz - 1)[None, :] + rng.random((nb, nz - 1))) / (nz - 1)
            Z = np.concatenate((np.full((nb, 1), c), c - halfwidth + 2.0 * halfwidth * u),
                               axis=1)
            Z = np.clip(Z, fm.lo, fm.hi)
        parent = np.repeat(np.arange(nb), Z.shape[1])
        z = Z.ravel()
        J, h, S1 = fm.fly(S[:, parent], z, n)
        n_eval += len(z)
        ok = np.nonzero(h >= h_a)[0]
        if len(ok) == 0:
            return {"safe_plan": False, "dead_track": n, "evaluations": n_eval,
                    "max_min_altitude": float(h.max()),
                    "partial_plan": plans[int(np.argmin(acc))].tolist()}
        accn = acc[parent[ok]] + J[ok]
        order = ok[np.argsort(accn, kind="stable")]
        accs = acc[parent[order]] + J[order]
        bins = np.floor(S1[fm.I_D, order] / w)
        _, first = np.unique(bins, return_index=True)
        first.sort()  # representatives in accumulated-J order
        reps = order[first]
        take = list(reps[: (3 * B) // 4])
        rest = reps[(3 * B) // 4:]
        if len(rest):
            rest = rest[np.argsort(S1[fm.I_D, rest], kind="stable")]
            take += list(rest[: B - len(take)])
        take = np.array(take)
        par = parent[take]
        acc = acc[par] + J[take]
        plans = np.concatenate((plans[par], z[take][:, None]), axis=1)
        Jt = np.concatenate((Jt[par], J[take][:, None]), axis=1)
        ht = np.concatenate((ht[par], h[take][:, None]), axis=1)
        S = S1[:, take]
        del accs
    k = int(np.argmin(acc))
    return {"safe_plan": True, "plan": plans[k].tolist(), "J": Jt[k].tolist(),
            "min_altitude": ht[k].tolist(), "total_J": float(acc[k]),
            "evaluations": n_eval}


def refine_plan(fm: Fast, z, max_sweeps=4):
    """Cyclic coordinate search on a safe plan: for each track in turn try
    z_n + {+-0.03, 0.1, 0.3, 1, 3, 10, 30} x h_r/80 m (the later tracks
    re-flown), keep the best safe improvement; repeat until a sweep finds
    nothing."""
    z = np.array(z, dtype=float)
    M = len(z)
    Js, hs, states = fm.fly_plan([z])
    h_a = fm.h_a
    assert (hs >= h_a).all()
    total = float(Js.sum())
    base = np.array([0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0]) * fm.h_r / 80.0
    deltas = np.concatenate((-base[::-1], base))
    n_eval = 0
    for _sweep in range(max_sweeps):
        improved = False
        for n in range(1, M + 1):
            cand = np.clip(z[n - 1] + deltas, fm.lo, fm.hi)
            Nc = len(cand)
            Z = np.tile(z[n - 1:], (Nc, 1))
            Z[:, 0] = cand
            J2, h2, _ = fm.fly_plan(Z, S0=np.repeat(states[n - 1], Nc, axis=1), first=n)
            n_eval += Nc
            tot = float(Js[0, :n - 1].sum()) + J2.sum(axis=1)
            tot = np.where((h2 >= h_a).all(axis=1), tot, np.inf)
            k = int(np.argmin(tot))
            if tot[k] < total * (1.0 - 1e-12):
                z[n - 1] = cand[k]
                Js, hs, states = fm.fly_plan([z])
                total = float(Js.sum())
                improved = True
        if not improved:
            break
    return {"plan": z.tolist(), "J": Js[0].tolist(), "min_altitude": hs[0].tolist(),
            "total_J": total, "evaluations": n_eval, "safe": bool((hs >= h_a).all())}


def best_horizon_plan(fm: Fast, B=100, nz=32, seed=0, focus=(20.0, 5.0, 1.25, 0.3),
                      sweeps=1):
    """Wide beam search, then focused beam passes around the best plan so far
    (half-widths `focus` x h_r/80 m), then a coordinate-search polish."""
    res = beam_search(fm, B=B, nz=nz, seed=seed)
    if not res["safe_plan"]:
        return res
    res["passes"] = [res["total_J"]]
    best = res
    for k, hw in enumerate(focus):
        r = beam_search(fm, B=B, nz=nz, seed=seed + 1 + k, center=best["plan"],
                        halfwidth=hw * fm.h_r / 80.0)
        res["evaluations"] += r["evaluations"]
        res["passes"].append(r["total_J"] if r["safe_plan"] else None)
        if r["safe_plan"] and r["total_J"] < best["total_J"]:
            best = r
    out = dict(res)
    out.update(plan=best["plan"], J=best["J"], min_altitude=best["min_altitude"],
               total_J=best["total_J"])
    if sweeps:
        r = refine_plan(fm, best["plan"], max_sweeps=sweeps)
        out["evaluations"] += r["evaluations"]
        if r["total_J"] < out["total_J"]:
            out.update(plan=r["plan"], J=r["J"], min_altitude=r["min_altitude"],
                       total_J=r["total_J"])
        out["passes"].append(out["total_J"])
    return out
