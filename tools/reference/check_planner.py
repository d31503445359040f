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
    the previous depth, which belongs to J_n).

    The batch step is the model's arithmetic rearranged for speed (the plant
    update, theta and q in one product, the bottom as intercept + slope x, the
    gains' signs folded): it agrees with auvref to ~1e-13 relative, which the
    self-test checks.  With Kid = 0 the depth integrator has no effect and is
    not tracked (it keeps its start value)."""

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
        self.slope = self.pdb / self.pdx
        self.icpt = self.pb0 - self.slope * self.px0
        # stacked one-step map: [eta; theta; q](k+1) = G eta(k) + H delta(k)
        self.G = np.vstack((self.Ad, self.C @ self.Ad, self.CA @ self.Ad))
        self.H = np.concatenate((self.Bd.ravel(), [self.C @ self.Bd.ravel(),
                                                  self.CA @ self.Bd.ravel()])).reshape(no + 2, 1)
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
        if N == 1:
            return self._fly1(S, float(np.ravel(z)[0]), n)
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
        esq = e * e
        out_S = np.empty((self.nrow, N))
        out_J = np.empty(N)
        out_h = np.empty(N)
        idx = np.arange(N)  # original column of each working candidate
        bXb = float(self.prof(Xb))
        # constants of the rearranged (same-model, reordered-arithmetic) step
        G, H = self.G, self.H
        kdd_ts = kdd / Ts
        skpt, skit, skdt = sigma * kpt, sigma * kit, sigma * kdt
        half_deg = 0.5 * DEG
        track_id = kid != 0.0
        px0, inv_dx, nseg1 = self.px[0], self.inv_dx, self.nseg - 1
        icpt, slope = self.icpt, self.slope
        guard = 0
        while True:
            if guard <= 0:
                guard = int((Xb - float(x.max())) / U) - 1
            # 2. depth loop (the sample is inside the track: reference z)
            e_d = z - d
            if track_id:
                vk = kdd_ts * (d - dp) - kpd * e_d - kid * Id
            else:
                vk = kdd_ts * (d - dp) - kpd * e_d
            thref = np.minimum(np.maximum(vk, -thmax), thmax)
            #    pitch loop
            e_t = thref - theta
            wk = skpt * e_t + skit * Ith - skdt * q
            delta = np.minimum(np.maximum(wk, -dmax), dmax)
            #    conditional integration
            if track_id:
                Id = Id + np.where((vk * e_d < 0.0) & (vk != thref), 0.0, Ts * e_d)
            if sigma > 0.0:
                sat = (wk * e_t > 0.0) & (wk != delta)
            else:
                sat = (wk * e_t < 0.0) & (wk != delta)
            Ith = Ith + np.where(sat, 0.0, Ts * e_t)
            # 3. plant: eta, theta and q of the next sample in one product
            Y = G @ eta + H * delta
            eta = Y[:no]
            theta1 = Y[no]
            q = Y[no + 1]
            # 4. kinematics
            tb = (theta + theta1) * half_deg
            x1 = x + U * np.cos(tb)
            d1 = d - U * np.sin(tb)
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
                    jj = idx[c]
                    out_J[jj] = J[c] + (Xb - xc) * (esq[c] + ecb * ecb) / 4.0
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
                    x1, d1, esq = x1[keep], d1[keep], esq[keep]
                    theta1, q, J, hmin = theta1[keep], q[keep], J[keep], hmin[keep]
            # sample k+1 inside the track: a full trapezoid segment
            if self.uniform:
                i = ((x1 - px0) * inv_dx).astype(np.intp)
                np.minimum(i, nseg1, out=i)
                h1 = icpt.take(i) + slope.take(i) * x1 - d1
            else:
                h1 = self.bottom(x1) - d1
            e1 = h1 - h_r
            e1sq = e1 * e1
            J = J + (x1 - x) * (esq + e1sq) * 0.25
            hmin = np.minimum(hmin, h1)
            # 5. shift
            dp = d
            d = d1
            x = x1
            esq = e1sq
            theta = theta1

    def _fly1(self, S, z, n):
        """fly() for one candidate on plain Python floats (numpy's per-call
        overhead dominates a batch of one); the same arithmetic."""
        v = self.v
        no = self.no
        rng = range(no)
        Ad = [[float(a) for a in row] for row in self.Ad]
        Bd = [float(b) for b in self.Bd.ravel()]
        C = [float(c) for c in self.C]
        CA = [float(c) for c in self.CA]
        col = [float(u) for u in S[:, 0]]
        eta = col[:no]
        Id, Ith, x, d, dp, xp = col[no:no + 6]
        Xa, Xb = self.X[n - 1], self.X[n]
        h_r = self.h_r
        Ts, U = v.sample_time, self.U
        thmax, dmax = v.pitch_limit, v.elevator_limit
        kpd, kid, kdd = v.kpd, v.kid, v.kdd
        kpt, kit, kdt = v.kpt, v.kit, v.kdt
        sigma = v.plant.sigma
        prof = self.prof
        if x > Xb:
            raise ar.ModelError("track shorter than one step")
        dc = d if x == Xa else dp + (d - dp) * (Xa - xp) / (x - xp)
        ba = prof(Xa)
        ec = ba - h_r - dc
        b = prof(x)
        e = b - h_r - d
        J = (x - Xa) * (ec * ec + e * e) / 4.0
        hmin = min(ba - dc, b - d)
        theta = sum(C[j] * eta[j] for j in rng)
        q = sum(CA[j] * eta[j] for j in rng)
        bXb = prof(Xb)
        sin, cos = math.sin, math.cos
        while True:
            e_d = z - d
            ddot = (d - dp) / Ts
            vk = -(kpd * e_d + kid * Id - kdd * ddot)
            thref = min(max(vk, -thmax), thmax)
            e_t = thref - theta
            wk = sigma * (kpt * e_t + kit * Ith - kdt * q)
            delta = min(max(wk, -dmax), dmax)
            if kid != 0.0 and not ((vk > thmax and e_d < 0.0) or (vk < -thmax and e_d > 0.0)):
                Id += Ts * e_d  # (with Kid = 0, I_d has no effect: not tracked)
            se = sigma * e_t
            if not ((wk > dmax and se > 0.0) or (wk < -dmax and se < 0.0)):
                Ith += Ts * e_t
            eta = [sum(Ad[i][j] * eta[j] for j in rng) + Bd[i] * delta for i in rng]
            theta1 = sum(C[j] * eta[j] for j in rng)
            tb = (0.5 * (theta + theta1)) * DEG
            x1 = x + U * cos(tb)
            d1 = d - U * sin(tb)
            q = sum(CA[j] * eta[j] for j in rng)
            self.steps += 1
            if x1 >= Xb:
                dcb = d1 if x1 == Xb else d + (d1 - d) * (Xb - x) / (x1 - x)
                ecb = bXb - h_r - dcb
                J += (Xb - x) * (e * e + ecb * ecb) / 4.0
                hmin = min(hmin, bXb - dcb)
                out = np.array(eta + [Id, Ith, x1, d1, d, x]).reshape(self.nrow, 1)
                return np.array([J]), np.array([hmin]), out
            b1 = prof(x1)
            e1 = b1 - h_r - d1
            J += (x1 - x) * (e * e + e1 * e1) / 4.0
            h1 = b1 - d1
            if h1 < hmin:
                hmin = h1
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

    Returns best_z/best_J (unconstrained), best_safe_z/best_safe_J (None when
    no evaluated depth is safe: feasible False), max_min_altitude, and
    fallback_z/fallback_J: the least J among the depths whose min altitude is
    within 1 mm of the highest (what a planner could fly where nothing is
    safe)."""
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
    # the best fallback where nothing is safe: the least J among the depths
    # whose min altitude is within 1 mm of the highest one
    jf = np.where(h >= h.max() - 1e-3, J, np.inf)
    k = int(np.argmin(jf))
    res.update(fallback_z=float(z[k]), fallback_J=float(J[k]),
               fallback_min_altitude=float(h[k]))
    # the distinct local minima of J (for the report)
    mins = _pick_minima(z, J, np.ones(len(z), dtype=bool), 4, min_sep=max(3, len(z) // 50))
    res["local_minima"] = [[float(z[m]), float(J[m])] for m in mins]
    return res


# --------------------------------------------------------------------------
# Whole-line search: beam search over tracks, then a local coordinate search
# --------------------------------------------------------------------------


def zscale(fm: Fast):
    """Depth scale of the local searches: max(h_r, 20 m) / 80 (1 m at the
    paper's h_r = 80 m; 0.25 m on the shallow sites, whose optimal depths
    still move by metres)."""
    return max(fm.h_r, 20.0) / 80.0


def _track_band(fm: Fast, n):
    """Bottom depth range over track n (profile samples and the ends)."""
    a, b = fm.X[n - 1], fm.X[n]
    bs = [fm.prof(a), fm.prof(b)] + [bb for xx, bb in zip(fm.prof.x, fm.prof.b) if a < xx < b]
    return min(bs), max(bs)


def beam_search(fm: Fast, B=100, nz=32, seed=0, center=None, halfwidth=None,
                n_local=6, keep=1, reserve=0.25):
    """Best safe whole-line plans by beam search.

    Track by track, every kept partial plan (a start state) is extended by nz
    depths: a third spread over the reachable range (its two ends included:
    beyond them the pitch reference saturates over the whole track), two
    thirds over the band [min b - 2 h_r, max b - h_a + h_r] of the track, each
    grid jittered per state; then n_local more depths within one grid step of
    each state's best safe one.  Extensions that are unsafe on the new track
    are dropped; the survivors are binned by their depth at the track's end
    (bins of h_r/40) and the best of each bin kept; the next beam is the
    (1 - reserve) B best bins by accumulated J plus the reserve B shallowest
    other bins (a reserve for walls further on).

    With `center` (a plan) and `halfwidth`, a focused pass: the nz depths of
    track n are spread over center_n +- halfwidth (center_n itself included)
    and the bins are halfwidth/20 wide.

    Returns a dict with the best plan (plan, per-track J and min altitude,
    total J) and `finals`, up to `keep` distinct good plans; or, when every
    partial plan died, safe_plan False and the track where it happened."""
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
        if center is None:
            R = L * tan + 50.0
            a = np.maximum(fm.lo, ds - R)
            b = np.minimum(fm.hi, ds + R)
            bmin, bmax = _track_band(fm, n)
            ba = np.maximum(a, bmin - 2.0 * h_r)
            bb = np.minimum(b, bmax - h_a + h_r)
            inband = bb > ba
            bb = np.where(inband, bb, b)
            ba = np.where(inband, ba, a)
            nu = max(nz // 3, 3)
            nbnd = nz - nu
            u1 = (np.arange(nu - 2)[None, :] + rng.random((nb, nu - 2))) / (nu - 2)
            u2 = (np.arange(nbnd)[None, :] + rng.random((nb, nbnd))) / nbnd
            Z = np.concatenate((a[:, None], b[:, None],
                                a[:, None] + (b - a)[:, None] * u1,
                                ba[:, None] + (bb - ba)[:, None] * u2), axis=1)
            step = (bb - ba) / nbnd
        else:
            c = float(center[n - 1])
            u = (np.arange(nz - 1)[None, :] + rng.random((nb, nz - 1))) / (nz - 1)
            Z = np.concatenate((np.full((nb, 1), c), c - halfwidth + 2.0 * halfwidth * u),
                               axis=1)
            Z = np.clip(Z, fm.lo, fm.hi)
            step = np.full(nb, 2.0 * halfwidth / (nz - 1))
        parent = np.repeat(np.arange(nb), Z.shape[1])
        z = Z.ravel()
        J, h, S1 = fm.fly(S[:, parent], z, n)
        n_eval += len(z)
        if n_local > 0:
            # each state's best safe depth, refined within one grid step
            key = np.where(h >= h_a, J, np.inf).reshape(nb, -1)
            jb = np.argmin(key, axis=1)
            has = np.isfinite(key[np.arange(nb), jb])
            if has.any():
                st = np.nonzero(has)[0]
                zb = Z[st, jb[st]]
                u = (np.arange(n_local)[None, :] + rng.random((len(st), n_local))) / n_local
                Z2 = np.clip(zb[:, None] + step[st, None] * (2.0 * u - 1.0), fm.lo, fm.hi)
                p2 = np.repeat(st, n_local)
                z2 = Z2.ravel()
                J2, h2, S2 = fm.fly(S[:, p2], z2, n)
                n_eval += len(z2)
                parent = np.concatenate((parent, p2))
                z = np.concatenate((z, z2))
                J = np.concatenate((J, J2))
                h = np.concatenate((h, h2))
                S1 = np.concatenate((S1, S2), axis=1)
        ok = np.nonzero(h >= h_a)[0]
        if len(ok) == 0:
            return {"safe_plan": False, "dead_track": n, "evaluations": n_eval,
                    "max_min_altitude": float(h.max()),
                    "partial_plan": plans[int(np.argmin(acc))].tolist()}
        accn = acc[parent[ok]] + J[ok]
        order = ok[np.argsort(accn, kind="stable")]
        if n == fm.M:
            take = order  # the last track: keep every safe plan, best first
        else:
            bins = np.floor(S1[fm.I_D, order] / w)
            _, first = np.unique(bins, return_index=True)
            first.sort()  # representatives in accumulated-J order
            reps = order[first]
            nbest = B - int(round(reserve * B))
            take = list(reps[:nbest])
            rest = reps[nbest:]
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
    # acc is sorted; distinct plans: a depth differs by > 10 zscale and the
    # total J by > 1e-6 (two depths beyond reach fly the same saturated path)
    finals = []
    for k in range(len(acc)):
        if all(np.max(np.abs(plans[k] - plans[j])) > 10.0 * zscale(fm)
               and abs(acc[k] - acc[j]) > 1e-6 * acc[j] for j in finals):
            finals.append(k)
        if len(finals) >= keep:
            break
    res = [{"plan": plans[k].tolist(), "J": Jt[k].tolist(), "min_altitude": ht[k].tolist(),
            "total_J": float(acc[k])} for k in finals]
    out = {"safe_plan": True, "evaluations": n_eval, "finals": res}
    out.update(res[0])
    return out


def refine_plan(fm: Fast, z, max_sweeps=4):
    """Cyclic coordinate search on a safe plan: for each track in turn try
    z_n + {+-0.03, 0.1, 0.3, 1, 3, 10, 30} x zscale m (the later tracks
    re-flown), keep the best safe improvement; repeat until a sweep finds
    nothing."""
    z = np.array(z, dtype=float)
    M = len(z)
    Js, hs, states = fm.fly_plan([z])
    h_a = fm.h_a
    assert (hs >= h_a).all()
    total = float(Js.sum())
    base = np.array([0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0]) * zscale(fm)
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


def best_horizon_plan(fm: Fast, B=100, nz=32, seed=0, focus=(20.0, 5.0, 1.25), starts=1,
                      B_focus=50, sweeps=0):
    """The reference's best safe whole-line plan: a wide beam search, then
    for each of its `starts` best distinct plans, focused beam passes around
    it (half-widths `focus` x zscale m, each centred on the best so far of
    that start), then the last track re-optimized exactly (search_track) from
    the state the best plan reaches, and optionally a coordinate search.

    When the wide beam dies on a track after the first, it is retried with a
    beam twice as wide, half of it the shallowest states, before concluding
    that no safe plan was found (on the first track the search is exhaustive:
    the start state is fixed and the full climb z = d_min is a candidate)."""
    wide = beam_search(fm, B=B, nz=nz, seed=seed, keep=starts)
    if not wide["safe_plan"] and wide["dead_track"] > 1:
        retry = beam_search(fm, B=2 * B, nz=nz, seed=seed + 1, keep=starts, reserve=0.5)
        retry["evaluations"] += wide["evaluations"]
        retry["retried"] = True
        wide = retry
    if not wide["safe_plan"]:
        return wide
    out = {"safe_plan": True, "evaluations": wide["evaluations"],
           "wide_total_J": [f["total_J"] for f in wide["finals"]], "starts": []}
    best = None
    for i, start in enumerate(wide["finals"]):
        cur = start
        passes = [cur["total_J"]]
        for k, hw in enumerate(focus):
            r = beam_search(fm, B=B_focus, nz=nz, seed=seed + 100 * (i + 1) + k,
                            center=cur["plan"], halfwidth=hw * zscale(fm))
            out["evaluations"] += r["evaluations"]
            passes.append(r["total_J"] if r["safe_plan"] else None)
            if r["safe_plan"] and r["total_J"] < cur["total_J"]:
                cur = r
        out["starts"].append(passes)
        if best is None or cur["total_J"] < best["total_J"]:
            best = cur
    plan = list(best["plan"])
    # the last track alone, exactly, from the state the plan reaches
    M = fm.M
    _, _, states = fm.fly_plan([plan])
    r = search_track(fm, states[M - 1], M)
    out["evaluations"] += r["evaluations"]
    if r["feasible"] and r["best_safe_J"] < best["J"][-1]:
        plan[-1] = r["best_safe_z"]
    if sweeps:
        rr = refine_plan(fm, plan, max_sweeps=sweeps)
        out["evaluations"] += rr["evaluations"]
        plan = rr["plan"]
    Js, hs, _ = fm.fly_plan([plan])
    out.update(plan=[float(v) for v in plan], J=Js[0].tolist(),
               min_altitude=hs[0].tolist(), total_J=float(Js.sum()))
    return out


# --------------------------------------------------------------------------
# Cases: the six shared profiles and random unseen ones
# --------------------------------------------------------------------------


def unseen_case(seed, i):
    """A random-walk bottom (slopes up to 45 deg, depth 200-1500 m, 10 m
    sampling) under 4-5 tracks of 300-900 m; h_r/h_a 80/60."""
    rng = random.Random(f"planner/{seed}/{i}")
    M = rng.randint(4, 5)
    X = [0.0]
    for _ in range(M):
        X.append(X[-1] + round(rng.uniform(300.0, 900.0), 1))
    ds = 10.0
    n = int(math.ceil(X[-1] / ds)) + 1
    xs = [k * ds for k in range(n + 1)]
    b = rng.uniform(400.0, 1300.0)
    ang = rng.uniform(-25.0, 25.0)
    sd = rng.uniform(2.0, 8.0)
    bs = [round(b, 2)]
    for _ in range(n):
        ang = max(-45.0, min(45.0, ang + rng.gauss(0.0, sd)))
        if rng.random() < 0.03:  # a flat stretch or a sharp break now and then
            ang = 0.0 if rng.random() < 0.5 else rng.uniform(-45.0, 45.0)
        nb = b + math.tan(math.radians(ang)) * ds
        if not 200.0 <= nb <= 1500.0:
            ang = -ang
            nb = min(1500.0, max(200.0, b + math.tan(math.radians(ang)) * ds))
        b = nb
        bs.append(round(b, 2))
    return {"name": f"unseen_{seed}_{i}", "xs": xs, "bs": bs, "X": X,
            "h_r": 80.0, "h_a": 60.0}


def write_case(case, base, vehicle=None):
    """Write (or point at) PROFILE.csv, WAYPOINTS.csv and VEHICLE.toml
    (the case's h_r, h_a, and every key of the `vehicle` dict, if any)."""
    d = os.path.join(base, case["name"])
    os.makedirs(d, exist_ok=True)
    if "xs" in case:
        P = os.path.join(d, "PROFILE.csv")
        W = os.path.join(d, "WAYPOINTS.csv")
        check_plan.write_profile(P, case["xs"], case["bs"])
        check_plan.write_waypoints(W, case["X"])
    else:
        P = os.path.join(DATA, case["name"] + ".csv")
        W = os.path.join(DATA, case["name"] + ".waypoints.csv")
    V = os.path.join(d, "VEHICLE.toml")
    # (A vehicle's own h_r / h_a replace the case's, for the checks too.)
    vehicle = vehicle or {}
    case["h_r"] = float(vehicle.get("reference_altitude", case["h_r"]))
    case["h_a"] = float(vehicle.get("min_altitude", case["h_a"]))
    cfg = {"reference_altitude": case["h_r"], "min_altitude": case["h_a"]}
    cfg.update(vehicle)
    check_plan.write_toml(V, cfg)
    case.update(P=P, W=W, V=V, dir=d)
    return case


# --------------------------------------------------------------------------
# The tool and its output
# --------------------------------------------------------------------------

# (key, --mode, --method, --unconstrained)
RUNS = [
    ("track_unconstrained_bfgs", "track", "bfgs", True),
    ("track_constrained_bfgs", "track", "bfgs", False),
    ("horizon_bfgs", "horizon", "bfgs", False),
    ("track_unconstrained_gd", "track", "gd", True),
]


def tool_args(case, mode, method, unconstrained):
    a = ["--profile", case["P"], "--waypoints", case["W"], "--config", case["V"],
         "--mode", mode, "--method", method]
    if unconstrained:
        a.append("--unconstrained")
    return a + ["--json"]


class ToolRunner:
    def __init__(self, cmd, cwd, timeout):
        self.cmd0 = shlex.split(cmd)
        self.cwd = cwd
        self.timeout = timeout

    def __call__(self, case, key, mode, method, unconstrained):
        """(parsed JSON or None, error message, seconds, command line)."""
        args = self.cmd0 + tool_args(case, mode, method, unconstrained)
        t0 = time.time()
        try:
            p = subprocess.run(args, cwd=self.cwd, capture_output=True, text=True,
                               timeout=self.timeout)
        except (OSError, subprocess.TimeoutExpired) as e:
            return None, f"could not run: {e}", time.time() - t0, shlex.join(args)
        dt = time.time() - t0
        if p.returncode != 0:
            err = (p.stderr.strip().splitlines() or ["(no stderr)"])[-1]
            return None, f"exit status {p.returncode}: {err}", dt, shlex.join(args)
        try:
            return json.loads(p.stdout), "", dt, shlex.join(args)
        except json.JSONDecodeError as e:
            return None, f"stdout is not one JSON object: {e}", dt, shlex.join(args)


def plan_json(fm: Fast, depths, mode, method, statuses=None, iterations=None):
    """The cli.md JSON of a plan, scored by auvref (the scalar reference)."""
    _, res = ar.evaluate_plan(fm.v, fm.prof, fm.X, depths)
    h_a = fm.h_a
    tracks = []
    for i, (t, z) in enumerate(zip(res["tracks"], depths)):
        tracks.append({
            "track": t["track"], "x_start": t["x_start"], "x_end": t["x_end"],
            "depth": float(z), "J": t["J"], "rms": t["rms"],
            "min_altitude": t["min_altitude"], "safe": t["min_altitude"] >= h_a,
            "iterations": iterations[i] if iterations else 0,
            "evaluations": 2 * (iterations[i] if iterations else 0),
            "status": statuses[i] if statuses else "converged",
            "J_history": [t["J"]],
        })
    return {"method": method, "mode": mode, "tracks": tracks, "total_J": res["total_J"],
            "min_altitude": res["min_altitude"], "safe": res["min_altitude"] >= h_a}


# --------------------------------------------------------------------------
# The checks
# --------------------------------------------------------------------------


def _g(v, p=6):
    return "None" if v is None else f"{v:.{p}g}"


class CaseChecker:
    """Everything about one profile: the model, cached searches, the checks."""

    def __init__(self, case, beam=100, nz=32, seed=0):
        self.case = case
        self.name = case["name"]
        prof = ref_plan.load_profile(case["P"])
        X = ref_plan.load_waypoints(case["W"])
        self.vehicle = ar.Vehicle.from_config(ref_plan.load_config(case["V"]))
        self.fm = Fast(self.vehicle, prof, X)
        self.h_a = self.vehicle.min_altitude
        self.beam, self.nz, self.seed = beam, nz, seed
        self._search = {}
        self._horizon = None
        self.checks = []  # (ok, line)
        self.info = []
        self.consistency = []  # (max rel J, max |h|) of auvref vs Fast
        self.data = {"name": self.name, "h_r": self.vehicle.reference_altitude,
                     "h_a": self.h_a, "waypoints": X, "runs": {}}

    # ---- cached searches ----
    def search(self, S, n):
        key = (n, tuple(np.round(np.asarray(S).ravel(), 7)))
        if key not in self._search:
            self._search[key] = search_track(self.fm, S, n)
        return self._search[key]

    def horizon(self):
        if self._horizon is None:
            hz = best_horizon_plan(self.fm, B=self.beam, nz=self.nz, seed=self.seed)
            if hz["safe_plan"]:
                # confirm the plan with the scalar reference
                _, res = ar.evaluate_plan(self.vehicle, self.fm.prof, self.fm.X, hz["plan"])
                hz["auvref_total_J"] = res["total_J"]
                hz["auvref_min_altitude"] = res["min_altitude"]
                if res["min_altitude"] < self.h_a:
                    raise RuntimeError(f"{self.name}: beam plan unsafe in auvref")
            self._horizon = hz
        return self._horizon

    def add(self, ok, what, msg):
        line = f"{'ok  ' if ok else 'FAIL'} {what} {self.name}: {msg}"
        self.checks.append((bool(ok), line))
        return ok

    # ---- helpers ----
    def parse(self, out):
        """(depths, tracks) of a tool's JSON, or raise ValueError."""
        tr = out["tracks"]
        if len(tr) != self.fm.M:
            raise ValueError(f"{len(tr)} tracks, expected {self.fm.M}")
        depths = []
        for n, t in enumerate(tr, 1):
            if t.get("track") != n:
                raise ValueError(f"track numbering {t.get('track')} != {n}")
            z = t["depth"]
            if z is None or not math.isfinite(float(z)):
                raise ValueError(f"track {n} depth {z!r}")
            depths.append(float(z))
            for k in ("J", "min_altitude", "iterations", "status", "safe"):
                if k not in t:
                    raise ValueError(f"track {n} has no {k!r}")
        return depths, tr

    def resim(self, depths):
        """auvref's scalar simulation of the tool's depths, and the track
        start states from the vectorized one."""
        _, res = ar.evaluate_plan(self.vehicle, self.fm.prof, self.fm.X, depths)
        Js, hs, states = self.fm.fly_plan([depths])
        # the two f64 implementations (scalar auvref, vectorized Fast) agree
        dj = max(abs(Js[0, i] - t["J"]) / max(abs(t["J"]), 1e-300)
                 for i, t in enumerate(res["tracks"]))
        dh = max(abs(hs[0, i] - t["min_altitude"]) for i, t in enumerate(res["tracks"]))
        self.consistency.append((dj, dh))
        return res, states

    # ---- criterion 4 (every run) ----
    def check_resim(self, key, out, depths, tracks, res):
        h_a = self.h_a
        bad = []
        worst_j = worst_h = 0.0
        n_safe = 0
        lo, hi = self.fm.lo, self.fm.hi
        for t, r, z in zip(tracks, res["tracks"], depths):
            n = r["track"]
            if not (lo - 1e-6 <= z <= hi + 1e-6):
                bad.append(f"track {n} depth {z} outside [{lo}, {hi}]")
            J = float(t["J"])
            rel = abs(J - r["J"]) / max(abs(r["J"]), 1e-300)
            worst_j = max(worst_j, rel)
            if abs(J - r["J"]) > J_RESIM_RTOL * abs(r["J"]) + J_FLOOR:
                bad.append(f"track {n} J {J:.9g} but re-simulated {r['J']:.9g} (rel {rel:.1e})")
            worst_h = max(worst_h, abs(float(t["min_altitude"]) - r["min_altitude"]))
            if t["safe"] is True:
                n_safe += 1
                if r["min_altitude"] < h_a - ALT_TOL:
                    bad.append(f"track {n} reported safe, re-simulated min altitude "
                               f"{r['min_altitude']:.4f} < h_a {h_a:g} - {ALT_TOL:g}")
        if out.get("safe") is True and res["min_altitude"] < h_a - ALT_TOL:
            bad.append(f"flight reported safe, re-simulated min altitude "
                       f"{res['min_altitude']:.4f} < h_a")
        msg = (f"{n_safe}/{len(tracks)} tracks reported safe, all confirmed; "
               if not bad else "") + \
            f"J vs re-sim max rel {worst_j:.1e}, min altitude max |diff| {worst_h:.1e} m"
        if bad:
            msg += "; " + "; ".join(bad)
        self.add(not bad, f"C4 resim [{key}]", msg)

    # ---- criteria 1 and 2 ----
    def check_track_mode(self, key, constrained, tracks, res, states):
        rows = []
        for n in range(1, self.fm.M + 1):
            t = tracks[n - 1]
            r = self.search(states[n - 1], n)
            J = float(t["J"])
            it = int(t["iterations"])
            st = t["status"]
            hmin = res["tracks"][n - 1]["min_altitude"]
            row = {"track": n, "tool_depth": float(t["depth"]), "tool_J": J,
                   "tool_iterations": it, "tool_status": st, "tool_safe": t["safe"],
                   "resim_J": res["tracks"][n - 1]["J"], "resim_min_altitude": hmin,
                   "ref": r}
            rows.append(row)
            if not constrained:
                best = r["best_J"]
                ratio = J / best if best > 0 else float("inf")
                ok = J <= J_RATIO_TRACK * best + J_FLOOR and it <= MAX_ITER_BFGS
                note = ""
                if J < best - (1e-4 * best + J_FLOOR):
                    note = " (the tool beats the reference search)"
                row["ratio"] = ratio
                self.add(ok, f"C1 track {n} [{key}]",
                         f"J {_g(J)} (z {t['depth']:.3f}) best {_g(best)} (z {r['best_z']:.3f}) "
                         f"ratio {ratio:.5f}, iterations {it}, {st}{note}")
                continue
            if not r["feasible"]:
                ok = st == "infeasible" or hmin >= self.h_a
                note = (" (the tool's depth is safe: the reference search missed it)"
                        if hmin >= self.h_a else "")
                self.add(ok, f"C2 track {n} [{key}]",
                         f"no safe depth in [{self.fm.lo:g}, {self.fm.hi:g}] (best min altitude "
                         f"{r['max_min_altitude']:.3f} m at z {r['z_max_min_altitude']:.2f} < h_a "
                         f"{self.h_a:g}; least J there {_g(r['fallback_J'])} at z "
                         f"{r['fallback_z']:.3f}); tool status {st}, depth {t['depth']:.3f}, "
                         f"min altitude {hmin:.3f}, J {_g(J)}{note}")
                continue
            best = r["best_safe_J"]
            ratio = J / best if best > 0 else float("inf")
            row["ratio"] = ratio
            safe_ok = hmin >= self.h_a - ALT_TOL
            ok = safe_ok and st != "infeasible" and J <= J_RATIO_TRACK * best + J_FLOOR
            note = ""
            if J < best - (1e-4 * best + J_FLOOR) and hmin >= self.h_a:
                note = " (the tool beats the reference search)"
            self.add(ok, f"C2 track {n} [{key}]",
                     f"J {_g(J)} (z {t['depth']:.3f}, min alt {hmin:.3f}{'' if safe_ok else ' UNSAFE'}) "
                     f"best safe {_g(best)} (z {r['best_safe_z']:.3f}) ratio {ratio:.5f}, "
                     f"iterations {it}, {st}{note}")
        return rows

    # ---- criterion 3 ----
    def check_horizon(self, key, out, tracks, res):
        hz = self.horizon()
        tot = float(out["total_J"])
        safe_tool = res["min_altitude"] >= self.h_a - ALT_TOL
        sts = [t["status"] for t in tracks]
        info = {"tool_total_J": tot, "tool_depths": [float(t["depth"]) for t in tracks],
                "tool_statuses": sts, "tool_safe": out.get("safe"),
                "resim_min_altitudes": [t["min_altitude"] for t in res["tracks"]],
                "reference": hz}
        if hz["safe_plan"]:
            self.info.append(
                f"info C3 reference plan {self.name}: z {[round(v, 3) for v in hz['plan']]}, "
                f"J {[float(_g(v)) for v in hz['J']]}, min altitude "
                f"{[round(v, 3) for v in hz['min_altitude']]}, total {_g(hz['total_J'], 7)} "
                f"(wide beam {_g(hz['wide_total_J'][0])}, focused passes "
                f"{[float(_g(p)) if p else p for p in hz['starts'][0][1:]]})")
            best = hz["total_J"]
            ratio = tot / best
            info["ratio"] = ratio
            ok = safe_tool and tot <= J_RATIO_HORIZON * best + J_FLOOR
            note = ""
            if tot < best - (1e-4 * best + J_FLOOR) and res["min_altitude"] >= self.h_a:
                note = " (the tool beats the reference search)"
            self.add(ok, f"C3 horizon [{key}]",
                     f"total J {_g(tot)} best safe {_g(best)} ratio {ratio:.4f}; tool flight "
                     f"min altitude {res['min_altitude']:.3f}{'' if safe_tool else ' UNSAFE'} "
                     f"(h_a {self.h_a:g}); statuses {','.join(sts)}{note}")
        else:
            claims_safe = out.get("safe") is True
            ok = (not claims_safe) or res["min_altitude"] >= self.h_a
            note = ""
            if res["min_altitude"] >= self.h_a:
                note = " (the tool's flight is safe: the beam search missed it)"
            self.add(ok, f"C3 horizon [{key}]",
                     f"no safe plan found (every partial plan unsafe on track "
                     f"{hz['dead_track']}, best min altitude there {hz['max_min_altitude']:.3f} "
                     f"< h_a {self.h_a:g}); tool says safe={out.get('safe')}, statuses "
                     f"{','.join(sts)}, total J {_g(tot)}, flight min altitude "
                     f"{res['min_altitude']:.3f}{note}")
        return info

    # ---- one tool run ----
    def check_run(self, key, out, err=""):
        if out is None:
            self.add(False, f"run [{key}]", err)
            return None
        try:
            depths, tracks = self.parse(out)
            float(out["total_J"])
        except (KeyError, TypeError, ValueError) as e:
            self.add(False, f"run [{key}]", f"malformed JSON output: {e!r}")
            return None
        res, states = self.resim(depths)
        self.check_resim(key, out, depths, tracks, res)
        d = {"depths": depths, "tool": out, "resim": res}
        if key == "track_unconstrained_bfgs":
            d["tracks"] = self.check_track_mode(key, False, tracks, res, states)
        elif key == "track_constrained_bfgs":
            d["tracks"] = self.check_track_mode(key, True, tracks, res, states)
        elif key == "horizon_bfgs":
            d["horizon"] = self.check_horizon(key, out, tracks, res)
        self.data["runs"][key] = d
        return d

    def gd_info(self):
        runs = self.data["runs"]
        g, b = runs.get("track_unconstrained_gd"), runs.get("track_unconstrained_bfgs")
        if not g or not b:
            return
        gi = [t["iterations"] for t in g["tool"]["tracks"]]
        bi = [t["iterations"] for t in b["tool"]["tracks"]]
        gs = [t["status"] for t in g["tool"]["tracks"]]
        line = (f"info C5 gd vs bfgs {self.name}: iterations gd {gi} vs bfgs {bi}; "
                f"gd statuses {','.join(gs)}; total J gd {_g(g['tool']['total_J'])} vs bfgs "
                f"{_g(b['tool']['total_J'])}")
        self.info.append(line)
        self.data["gd_vs_bfgs"] = {"gd_iterations": gi, "bfgs_iterations": bi,
                                   "gd_statuses": gs,
                                   "gd_total_J": g["tool"]["total_J"],
                                   "bfgs_total_J": b["tool"]["total_J"]}


# --------------------------------------------------------------------------
# Self-test: the checker fed plans from its own searches
# --------------------------------------------------------------------------


class SelfTool:
    """Stands in for the Rust tool: track mode flies the searches' best
    depths track by track (best safe, or the highest one where none is safe,
    marked infeasible); horizon mode the beam search's plan."""

    def __init__(self, cc: CaseChecker):
        self.cc = cc
        self.plans = {}

    def track_plan(self, constrained):
        cc, fm = self.cc, self.cc.fm
        S = fm.start()
        depths, sts = [], []
        for n in range(1, fm.M + 1):
            r = cc.search(S, n)
            if not constrained:
                z, st = r["best_z"], "converged"
            elif r["feasible"]:
                z, st = r["best_safe_z"], "converged"
            else:
                z, st = r["fallback_z"], "infeasible"
            depths.append(z)
            sts.append(st)
            _, _, S = fm.fly(S, [z], n)
        return depths, sts

    def plan(self, key):
        if key not in self.plans:
            fm = self.cc.fm
            if key.startswith("track"):
                depths, sts = self.track_plan("_constrained" in key)
            else:
                hz = self.cc.horizon()
                if hz["safe_plan"]:
                    depths, sts = hz["plan"], ["converged"] * fm.M
                else:
                    depths, sts = self.track_plan(True)
            self.plans[key] = (depths, sts)
        return self.plans[key]

    def __call__(self, case, key, mode, method, unconstrained):
        depths, sts = self.plan(key)
        its = [40 if method == "gd" else 3] * self.cc.fm.M
        out = plan_json(self.cc.fm, depths, mode, method, sts, its)
        return json.loads(json.dumps(out)), "", 0.0, "self-test " + " ".join(
            tool_args(case, mode, method, unconstrained)[6:])


def negative_tests(cc: CaseChecker, tool: SelfTool):
    """Spoiled outputs that the checker must reject: [(what, detected, fails)]."""
    fm, h_a, M = cc.fm, cc.h_a, cc.fm.M
    out = []

    def trial(key, what, doc, expect):
        saved = (cc.checks, cc.data, cc.consistency, cc.info)
        cc.checks, cc.data, cc.consistency, cc.info = [], {"runs": {}}, [], []
        try:
            cc.check_run(key, json.loads(json.dumps(doc)))
            got = cc.checks
        finally:
            cc.checks, cc.data, cc.consistency, cc.info = saved
        fails = [line for ok, line in got if not ok]
        detected = all(any(e in line for line in fails) for e in expect)
        out.append((f"{key}: {what}", detected, fails))

    # N1: unconstrained, last track's depth moved off the optimum (honest J)
    key = "track_unconstrained_bfgs"
    depths, sts = tool.plan(key)
    _, _, states = fm.fly_plan([depths])
    r = cc.search(states[M - 1], M)
    for k in (2, 5, 10, 20, 50, 100, 300):
        z = float(np.clip(depths[-1] + k * zscale(fm), fm.lo, fm.hi))
        J, _, _ = fm.fly(states[M - 1], [z], M)
        if J[0] > 1.02 * r["best_J"] + 1.0:
            trial(key, f"track {M} depth {depths[-1]:.2f} -> {z:.2f} (J x{J[0] / r['best_J']:.3f})",
                  plan_json(fm, depths[:-1] + [z], "track", "bfgs", sts, [3] * M),
                  [f"C1 track {M} "])
            break
    # N2: 11 iterations on track 1
    trial(key, "11 iterations on track 1",
          plan_json(fm, depths, "track", "bfgs", sts, [11] + [3] * (M - 1)), ["C1 track 1 "])
    # N6: a reported J that is not the flight's
    doc = plan_json(fm, depths, "track", "bfgs", sts, [3] * M)
    doc["tracks"][0]["J"] *= 0.9
    trial(key, "track 1 J reported x0.9", doc, ["C4 resim"])

    key = "track_constrained_bfgs"
    depths, sts = tool.plan(key)
    _, _, states = fm.fly_plan([depths])
    for k in (M, M - 1):
        r = cc.search(states[k - 1], k)
        if r["feasible"] and r["best_min_altitude"] < h_a - 0.05:
            # N3: the unconstrained optimum, unsafe, claimed safe
            dz = list(depths)
            dz[k - 1] = r["best_z"]
            doc = plan_json(fm, dz, "track", "bfgs", sts, [3] * M)
            doc["tracks"][k - 1]["safe"] = True
            trial(key, f"track {k} unsafe depth {r['best_z']:.2f} (min alt "
                  f"{r['best_min_altitude']:.2f}) claimed safe", doc,
                  [f"C2 track {k} ", "C4 resim"])
            break
    for k in range(M, 0, -1):
        if sts[k - 1] != "infeasible":
            # N4: a feasible track said infeasible
            s2 = list(sts)
            s2[k - 1] = "infeasible"
            trial(key, f"feasible track {k} reported infeasible",
                  plan_json(fm, depths, "track", "bfgs", s2, [3] * M), [f"C2 track {k} "])
            break
    for k in range(1, M + 1):
        if sts[k - 1] == "infeasible":
            # N7: an infeasible track claimed converged and safe
            s2 = list(sts)
            s2[k - 1] = "converged"
            doc = plan_json(fm, depths, "track", "bfgs", s2, [3] * M)
            doc["tracks"][k - 1]["safe"] = True
            doc["safe"] = True
            trial(key, f"infeasible track {k} claimed converged and safe", doc,
                  [f"C2 track {k} ", "C4 resim"])
            break

    key = "horizon_bfgs"
    hz = cc.horizon()
    if hz["safe_plan"]:
        plan = list(hz["plan"])
        Jbest = hz["total_J"]
        _, _, states = fm.fly_plan([plan])
        # N5: a safe but poor last depth (total J > 1.15 x best)
        cand = np.linspace(fm.lo, min(fm.hi, plan[-1] + 300.0), 61)
        J, h, _ = fm.fly(np.repeat(states[M - 1], len(cand), axis=1), cand, M)
        tot = Jbest - hz["J"][-1] + J
        ok = np.nonzero((h >= h_a + 0.05) & (tot > 1.15 * Jbest))[0]
        if len(ok):
            i = ok[int(np.argmin(tot[ok]))]
            trial(key, f"safe last depth {cand[i]:.2f}, total J x{tot[i] / Jbest:.3f}",
                  plan_json(fm, plan[:-1] + [float(cand[i])], "horizon", "bfgs"),
                  ["C3 horizon"])
        # N8: the unconstrained track plan, unsafe, as the horizon plan
        du, su = tool.plan("track_unconstrained_bfgs")
        _, res = ar.evaluate_plan(fm.v, fm.prof, fm.X, du)
        if res["min_altitude"] < h_a - 0.05:
            trial(key, f"unsafe plan (min alt {res['min_altitude']:.2f})",
                  plan_json(fm, du, "horizon", "bfgs"), ["C3 horizon"])
    return out


# --------------------------------------------------------------------------
# Driver
# --------------------------------------------------------------------------


def run_case(job):
    case, o = job
    t0 = time.time()
    cc = CaseChecker(case, beam=o["beam"], nz=o["nz"], seed=o["seed"])
    tool = SelfTool(cc) if o["self_test"] else ToolRunner(o["bin_cmd"], o["cwd"], o["timeout"])
    meta = {}
    tool_time = 0.0
    for key, mode, method, unc in RUNS:
        out, err, dt, cmdline = tool(case, key, mode, method, unc)
        tool_time += dt
        meta[key] = {"seconds": dt, "command": cmdline, "error": err}
        cc.check_run(key, out, err)
    cc.gd_info()
    cc.data["tool_runs"] = meta
    dj = max((c[0] for c in cc.consistency), default=0.0)
    dh = max((c[1] for c in cc.consistency), default=0.0)
    cc.data["auvref_vs_vectorized"] = {"max_rel_J": dj, "max_abs_min_altitude": dh}
    if o["self_test"]:
        cc.add(dj <= 1e-9 and dh <= 1e-9, "self-test simulators",
               f"auvref vs vectorized: max rel J {dj:.1e}, max |min alt| {dh:.1e} m")
        for what, detected, fails in negative_tests(cc, tool):
            cc.add(detected, "self-test negative",
                   f"{what}: {'caught' if detected else 'NOT caught'}"
                   + (f" ({fails[0].split(': ', 1)[-1][:110]})" if fails else ""))
    elif dj > 1e-9 or dh > 1e-9:
        cc.info.append(f"WARN reference {cc.name}: auvref vs vectorized differ "
                       f"(rel J {dj:.1e}, min alt {dh:.1e} m)")
    cc.data["seconds"] = time.time() - t0
    cc.data["tool_seconds"] = tool_time
    hdr = (f"== {cc.name}: h_r {cc.vehicle.reference_altitude:g} h_a {cc.h_a:g}, "
           f"{cc.fm.M} tracks, {time.time() - t0:.1f} s (tool {tool_time:.1f} s)")
    return hdr, cc.checks, cc.info, cc.data


def _jsonable(o):
    if isinstance(o, (np.floating,)):
        return float(o)
    if isinstance(o, (np.integer,)):
        return int(o)
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.bool_,)):
        return bool(o)
    raise TypeError(type(o))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__)
    ap.add_argument("--bin-cmd", default=DEFAULT_CMD,
                    help=f"command the arguments are appended to (default: {DEFAULT_CMD!r})")
    ap.add_argument("--cwd", default=ROOT, help="working directory of the tool")
    ap.add_argument("--self-test", action="store_true",
                    help="no tool: feed the checker its own plans (and spoiled ones)")
    ap.add_argument("--unseen", type=int, default=3, help="random profiles (default 3)")
    ap.add_argument("--seed", type=int, default=7, help="seed of the random profiles")
    ap.add_argument("--only", nargs="+", metavar="NAME",
                    help="only the cases whose name contains one of these")
    ap.add_argument("--no-shared", action="store_true", help="skip the six real profiles")
    ap.add_argument("--beam", type=int, default=100, help="beam width B (default 100)")
    ap.add_argument("--nz", type=int, default=32, help="depths per beam state (default 32)")
    ap.add_argument("--jobs", type=int, default=2, help="profiles checked in parallel")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per tool run")
    ap.add_argument("--json-out", metavar="FILE", help="write every number to FILE")
    ap.add_argument("--keep", metavar="DIR", help="keep the generated inputs in DIR")
    ap.add_argument("--vehicle", metavar="TOML",
                    help="a vehicle for every case: its keys (speed, [plant], "
                         "[depth_pid], ..., and reference_altitude / min_altitude, "
                         "which replace the case's) are written into each VEHICLE.toml")
    a = ap.parse_args(argv)

    cases = [] if a.no_shared else [{"name": n, "h_r": hr, "h_a": ha} for n, hr, ha in SHARED]
    cases += [unseen_case(a.seed, i) for i in range(a.unseen)]
    if a.only:
        cases = [c for c in cases if any(s in c["name"] for s in a.only)]
    base = a.keep or tempfile.mkdtemp(prefix="check_planner_")
    os.makedirs(base, exist_ok=True)
    vehicle = None
    if a.vehicle:
        import tomllib
        with open(a.vehicle, "rb") as f:
            vehicle = tomllib.load(f)
    for c in cases:
        write_case(c, base, vehicle)
    o = {"beam": a.beam, "nz": a.nz, "seed": a.seed, "self_test": a.self_test,
         "bin_cmd": a.bin_cmd, "cwd": a.cwd, "timeout": a.timeout}
    t0 = time.time()
    passed = failed = 0
    report = {"generator": "tools/reference/check_planner.py", "argv": sys.argv[1:],
              "self_test": a.self_test, "bin_cmd": None if a.self_test else a.bin_cmd,
              "thresholds": {"J_ratio_track": J_RATIO_TRACK, "J_floor": J_FLOOR,
                             "max_iterations_bfgs": MAX_ITER_BFGS,
                             "J_ratio_horizon": J_RATIO_HORIZON, "alt_tol": ALT_TOL,
                             "J_resim_rtol": J_RESIM_RTOL},
              "cases": []}
    jobs = [(c, o) for c in cases]
    try:
        if a.jobs > 1 and len(jobs) > 1:
            pool = multiprocessing.get_context("fork").Pool(min(a.jobs, len(jobs)))
            results = pool.imap(run_case, jobs)
        else:
            pool = None
            results = map(run_case, jobs)
        for hdr, checks, info, data in results:
            print(hdr)
            for ok, line in checks:
                print(line)
                passed += ok
                failed += not ok
            for line in info:
                print(line)
            sys.stdout.flush()
            report["cases"].append(data)
        if pool is not None:
            pool.close()
            pool.join()
    finally:
        if not a.keep:
            shutil.rmtree(base, ignore_errors=True)
    report["seconds"] = time.time() - t0
    report["passed"], report["failed"] = passed, failed
    if a.json_out:
        with open(a.json_out, "w") as f:
            json.dump(report, f, indent=1, default=_jsonable)
    print(f"total time {time.time() - t0:.1f} s")
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
