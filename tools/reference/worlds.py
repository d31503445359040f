"""Declared uncertainty ("worlds", model.md section 12) in f64, open loop.

A *world* is ``(s(.), v(.), U, alpha, w)``:

* the bottom under the navigated position x is ``b_w(x) = b(x + s(x)) + v(x)``
  with ``|s(x)| <= e_h + r (x - X_0)`` and ``|v(x)| <= e_v``;
* the kinematics of model.md section 6 become
  ``d_{k+1} = d_k - U Ts sin(theta_bar - alpha) + w Ts`` and
  ``x_{k+1} = x_k + U Ts cos(theta_bar - alpha)`` with
  ``U in [U0 (1 - eps_U), U0 (1 + eps_U)]``, ``|alpha| <= alpha_max`` (deg),
  ``|w| <= w_max`` (m/s), all three constant over a flight;
* the autopilot, the plant and the waypoint switching (on the navigated x)
  are those of ``auvref`` (same Vehicle: same realization, same ZOH, same
  cascade, same anti-windup, same step order).

Because the line is flown *open loop* (fixed reference depths, the autopilot
sees only its own depth and pitch), the flight depends on ``(U, alpha, w)``
only, and the bottom ``(s, v)`` enters only when the altitude is scored.  So a
world is split into a :class:`Motion` (U, alpha, w), flown once, and a
:class:`Bottom` (s, v), evaluated on the flown samples with numpy; every
motion is scored against every bottom (any pair is a world of the set).

Scoring follows model.md section 8: per track n the least
``b_w(x) - d`` over the samples with ``X_{n-1} <= x_k <= X_n`` and at the two
clipped end points (depth interpolated linearly in x there).

Choice where the contract is silent: ``b(x + s)`` with ``x + s`` outside the
profile is *clamped* to the profile's end value (the bottom is continued flat
beyond its ends).  Nothing is extrapolated; a world never raises for a
shifted query.  Nominal ``b(x)`` itself is still only evaluated inside.

Everything is IEEE double precision.  With every bound 0 the flight is bit
for bit ``auvref.simulate`` and the altitudes are bit for bit
``auvref.evaluate``'s (the interpolation below repeats ``auvref.Profile``'s
formula operation by operation).
"""

from __future__ import annotations

import bisect
import itertools
import math
import operator
import random
from dataclasses import dataclass

import numpy as np

import auvref as ar

__all__ = [
    "Bounds", "Motion", "Bottom", "bottom_interp", "fly", "track_points",
    "track_min_altitudes", "world_min_altitudes", "corner_motions",
    "corner_bottoms", "random_motions", "random_bottoms", "sample_worlds",
    "worst_case", "UNCERTAINTY_KEYS",
]

UNCERTAINTY_KEYS = ("horizontal_uncertainty", "nav_drift", "vertical_uncertainty",
                    "speed_uncertainty", "flight_path_offset", "vertical_current")


# --------------------------------------------------------------------------
# Declared bounds
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class Bounds:
    e_h: float = 0.0  # horizontal_uncertainty, m
    r: float = 0.0  # nav_drift, m per m travelled from X_0
    e_v: float = 0.0  # vertical_uncertainty, m
    eps_U: float = 0.0  # speed_uncertainty, fraction
    alpha_max: float = 0.0  # flight_path_offset, deg
    w_max: float = 0.0  # vertical_current, m/s

    @classmethod
    def from_config(cls, cfg: dict) -> "Bounds":
        g = lambda k: float(cfg.get(k, 0.0))  # noqa: E731
        b = cls(g("horizontal_uncertainty"), g("nav_drift"), g("vertical_uncertainty"),
                g("speed_uncertainty"), g("flight_path_offset"), g("vertical_current"))
        for k, v in zip(UNCERTAINTY_KEYS, b.as_tuple()):
            if not (math.isfinite(v) and v >= 0.0):
                raise ar.ModelError(f"{k} must be finite and >= 0, got {v!r}")
        if b.eps_U >= 1.0:
            raise ar.ModelError("speed_uncertainty must be < 1")
        return b

    def as_tuple(self):
        return (self.e_h, self.r, self.e_v, self.eps_U, self.alpha_max, self.w_max)

    def as_config(self) -> dict:
        return dict(zip(UNCERTAINTY_KEYS, self.as_tuple()))

    def is_zero(self) -> bool:
        return all(v == 0.0 for v in self.as_tuple())

    def s_bound(self, x, X0):
        """e_h + r (x - X_0), the bound on |s(x)| (x >= X_0 on a flight)."""
        return self.e_h + self.r * (np.asarray(x, dtype=float) - X0)


# --------------------------------------------------------------------------
# Motion part of a world: (U, alpha, w), and the open-loop flight
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class Motion:
    U: float
    alpha: float  # deg
    w: float  # m/s, positive down (makes the vehicle deeper)
    name: str = ""


def fly(vehicle: ar.Vehicle, waypoints, depths, initial_depth: float,
        motion: Motion | None = None, max_steps: int | None = None) -> ar.Trajectory:
    """auvref.simulate with the world's kinematics (model.md section 12).

    The loop is auvref.simulate's, statement for statement; only step 4
    (kinematics) uses U, alpha and w.  motion=None is the nominal world.
    """
    X = [float(v) for v in waypoints]
    z = [float(v) for v in depths]
    M = len(X) - 1
    if M < 1 or len(z) != M:
        raise ar.ModelError("need M+1 >= 2 waypoints and M depths")
    if any(X[i + 1] <= X[i] for i in range(M)):
        raise ar.ModelError("waypoints must be strictly increasing")
    v = vehicle
    Ts = v.sample_time
    if motion is None:
        motion = Motion(v.speed, 0.0, 0.0, "nominal")
    U, alpha, wv = float(motion.U), float(motion.alpha), float(motion.w)
    thmax, dmax = v.pitch_limit, v.elevator_limit
    kpd, kid, kdd = v.kpd, v.kid, v.kdd
    kpt, kit, kdt = v.kpt, v.kit, v.kdt
    sigma = v.plant.sigma
    n = v.plant.order
    Ad = [tuple(float(a) for a in row) for row in v.Ad]
    Bd = [float(b) for b in v.Bd]
    AB = list(zip(Ad, Bd))
    C = tuple(float(c) for c in v.plant.C)
    CA = tuple(float(c) for c in v.plant.CA)
    mul = operator.mul
    if max_steps is None:
        max_steps = int(20 * (X[-1] - X[0]) / (U * Ts)) + 1000

    eta = [0.0] * n
    Id = 0.0
    Ith = 0.0
    x = X[0]
    d = float(initial_depth)
    d_prev = d
    theta = 0.0
    q = 0.0
    xs, ds, ths, qs = [x], [d], [theta], [q]
    dels, threfs, refs = [], [], []
    XM = X[-1]
    steps = 0
    while x < XM:
        if steps >= max_steps:
            raise ar.ModelError("vehicle does not progress along the track")
        r = z[bisect.bisect_right(X, x) - 1]
        e_d = r - d
        ddot = (d - d_prev) / Ts
        vk = -(kpd * e_d + kid * Id - kdd * ddot)
        thref = min(max(vk, -thmax), thmax)
        e_t = thref - theta
        wk = sigma * (kpt * e_t + kit * Ith - kdt * q)
        delta = min(max(wk, -dmax), dmax)
        if not ((vk > thmax and e_d < 0.0) or (vk < -thmax and e_d > 0.0)):
            Id += Ts * e_d
        se = sigma * e_t
        if not ((wk > dmax and se > 0.0) or (wk < -dmax and se < 0.0)):
            Ith += Ts * e_t
        # same products, same left-to-right sums as auvref (bit for bit)
        eta = [sum(map(mul, row, eta)) + bd * delta for row, bd in AB]
        theta1 = sum(map(mul, C, eta))
        # world kinematics: flight path = pitch - alpha; vertical current w
        tb = math.radians(0.5 * (theta + theta1) - alpha)
        x_new = x + U * Ts * math.cos(tb)
        d_new = d - U * Ts * math.sin(tb) + wv * Ts
        if not x_new > x:
            raise ar.ModelError("x does not increase (|flight path| >= 90 deg?)")
        d_prev = d
        d = d_new
        x = x_new
        theta = theta1
        q = sum(map(mul, CA, eta))
        steps += 1
        dels.append(delta)
        threfs.append(thref)
        refs.append(r)
        xs.append(x)
        ds.append(d)
        ths.append(theta)
        qs.append(q)
    return ar.Trajectory(xs, ds, ths, qs, dels, threfs, refs)


# --------------------------------------------------------------------------
# Scoring points (model.md section 8) and min altitude per track
# --------------------------------------------------------------------------


def track_points(traj: ar.Trajectory, waypoints):
    """Per track n: (x points, depths) = clip point X_{n-1}, the samples with
    X_{n-1} <= x_k <= X_n, clip point X_n (depth interpolated linearly)."""
    X = [float(v) for v in waypoints]
    xs, ds = traj.x, traj.depth

    def depth_at(c):
        j = bisect.bisect_left(xs, c)
        if j < len(xs) and xs[j] == c:
            return ds[j]
        if j == 0 or j >= len(xs):
            raise ar.ModelError(f"clip point {c!r} outside the simulated samples")
        x0, x1 = xs[j - 1], xs[j]
        return ds[j - 1] + (ds[j] - ds[j - 1]) * (c - x0) / (x1 - x0)

    out = []
    for n in range(1, len(X)):
        a, b = X[n - 1], X[n]
        k0 = bisect.bisect_left(xs, a)
        k1 = bisect.bisect_right(xs, b) - 1
        px = np.array([a] + xs[k0:k1 + 1] + [b], dtype=float)
        pd = np.array([depth_at(a)] + ds[k0:k1 + 1] + [depth_at(b)], dtype=float)
        out.append((px, pd))
    return out


def bottom_interp(profile: ar.Profile, xq):
    """b(xq) vectorized, auvref.Profile's formula, clamped beyond the ends."""
    px = np.asarray(profile.x, dtype=float)
    pb = np.asarray(profile.b, dtype=float)
    xq = np.asarray(xq, dtype=float)
    i = np.searchsorted(px, xq, side="right") - 1
    i = np.clip(i, 0, len(px) - 2)
    x0, x1 = px[i], px[i + 1]
    b0, b1 = pb[i], pb[i + 1]
    out = b0 + (b1 - b0) * (xq - x0) / (x1 - x0)
    out = np.where(xq >= px[-1], pb[-1], out)
    out = np.where(xq <= px[0], pb[0], out)
    # exactly at x_0 auvref interpolates (gives b_0 exactly too)
    return out


class _RangeMinMax:
    """Sparse tables for min / max of profile.b over index ranges."""

    def __init__(self, b):
        b = np.asarray(b, dtype=float)
        self.mins = [b]
        self.maxs = [b]
        k = 1
        while (1 << k) <= len(b):
            h = 1 << (k - 1)
            pm, pM = self.mins[-1], self.maxs[-1]
            self.mins.append(np.minimum(pm[:-h], pm[h:]))
            self.maxs.append(np.maximum(pM[:-h], pM[h:]))
            k += 1

    def query(self, lo, hi, use_max):
        """min/max over b[lo..hi] inclusive (arrays); +-inf where lo > hi."""
        lo = np.asarray(lo)
        hi = np.asarray(hi)
        empty = lo > hi
        lo2 = np.where(empty, 0, lo)
        hi2 = np.where(empty, 0, hi)
        length = hi2 - lo2 + 1
        k = np.floor(np.log2(length)).astype(int)
        tab = self.maxs if use_max else self.mins
        res = np.empty(lo.shape)
        for kk in np.unique(k):
            m = k == kk
            t = tab[kk]
            a = t[lo2[m]]
            c = t[hi2[m] - (1 << kk) + 1]
            res[m] = np.maximum(a, c) if use_max else np.minimum(a, c)
        return np.where(empty, -np.inf if use_max else np.inf, res)


def envelope(profile: ar.Profile, lo, hi, shallow: bool):
    """Exact min (shallow=True) or max of the clamped b over [lo, hi] per point.

    b is piecewise linear, so the extreme is at lo, hi or a profile vertex
    strictly inside."""
    px = np.asarray(profile.x, dtype=float)
    lo = np.asarray(lo, dtype=float)
    hi = np.asarray(hi, dtype=float)
    ends = np.stack([bottom_interp(profile, lo), bottom_interp(profile, hi)])
    i0 = np.searchsorted(px, lo, side="right")  # first vertex > lo
    i1 = np.searchsorted(px, hi, side="left") - 1  # last vertex < hi
    rmm = getattr(profile, "_rmm", None)
    if rmm is None:
        rmm = _RangeMinMax(profile.b)
        profile._rmm = rmm
    inner = rmm.query(i0, i1, use_max=not shallow)
    if shallow:
        return np.minimum(ends.min(axis=0), inner)
    return np.maximum(ends.max(axis=0), inner)


# --------------------------------------------------------------------------
# Bottom part of a world: (s, v)
# --------------------------------------------------------------------------


class Bottom:
    """b_w(x) = b(x + s(x)) + v(x), or an envelope world (see corner_bottoms).

    kind: "shift" (s, v callables of an x array) or "envelope" (at each x
    the s in [-S(x), S(x)] that minimizes (shallow) / maximizes b(x + s)).
    """

    def __init__(self, name, s=None, v=None, kind="shift", shallow=True, bounds=None,
                 X0=0.0, v_const=0.0):
        self.name = name
        self.s = s
        self.v = v
        self.kind = kind
        self.shallow = shallow
        self.bounds = bounds
        self.X0 = X0
        self.v_const = v_const

    def __call__(self, profile: ar.Profile, x):
        x = np.asarray(x, dtype=float)
        if self.kind == "envelope":
            S = self.bounds.s_bound(x, self.X0)
            base = envelope(profile, x - S, x + S, self.shallow)
            return base + self.v_const
        sx = self.s(x) if self.s is not None else 0.0
        vx = self.v(x) if self.v is not None else 0.0
        return bottom_interp(profile, x + sx) + vx

    def __repr__(self):
        return f"Bottom({self.name})"


def _const(c):
    return lambda x: np.full(np.shape(x), float(c))


# --------------------------------------------------------------------------
# World sampling
# --------------------------------------------------------------------------


def _ends(lo, hi):
    return [lo] if lo == hi else [lo, hi]


def corner_motions(bounds: Bounds, U0: float):
    """Every corner of (U, alpha, w); a zero bound gives one value (deduped)."""
    Us = _ends(U0 * (1.0 - bounds.eps_U), U0 * (1.0 + bounds.eps_U))
    As = _ends(-bounds.alpha_max, bounds.alpha_max)
    Ws = _ends(-bounds.w_max, bounds.w_max)
    out = []
    for U, a, w in itertools.product(Us, As, Ws):
        out.append(Motion(U, a, w, f"corner U={U:.6g} alpha={a:+.6g} w={w:+.6g}"))
    return out


def corner_bottoms(bounds: Bounds, X0: float):
    """v = +-e_v times s in {+S(x), -S(x), shallow envelope, deep envelope}.

    S(x) = e_h + r (x - X0).  Since s enters only through b(x + s), the
    adversarial s at each x is the one that makes the bottom *shallowest*
    (least depth, positive down: least altitude); that "shallow envelope"
    world is exact for piecewise-linear b.  The deep envelope is kept as the
    opposite corner.  Zero bounds collapse (deduped)."""
    Vs = _ends(-bounds.e_v, bounds.e_v)
    zero_s = bounds.e_h == 0.0 and bounds.r == 0.0
    out = []
    for vc in Vs:
        vn = f"v={vc:+.6g}"
        if zero_s:
            out.append(Bottom(f"s=0 {vn}", None, _const(vc)))
            continue
        for sign in (+1.0, -1.0):
            S = (lambda sg: (lambda x: sg * bounds.s_bound(x, X0)))(sign)
            out.append(Bottom(f"s={'+' if sign > 0 else '-'}S {vn}", S, _const(vc)))
        out.append(Bottom(f"s=shallow-envelope {vn}", kind="envelope", shallow=True,
                          bounds=bounds, X0=X0, v_const=vc))
        out.append(Bottom(f"s=deep-envelope {vn}", kind="envelope", shallow=False,
                          bounds=bounds, X0=X0, v_const=vc))
    return out


def random_motions(bounds: Bounds, U0: float, n: int, rng: random.Random):
    out = []
    for i in range(n):
        U = rng.uniform(U0 * (1.0 - bounds.eps_U), U0 * (1.0 + bounds.eps_U))
        a = rng.uniform(-bounds.alpha_max, bounds.alpha_max)
        w = rng.uniform(-bounds.w_max, bounds.w_max)
        out.append(Motion(U, a, w, f"random#{i} U={U:.6g} alpha={a:+.4g} w={w:+.4g}"))
    return out


def _random_unit_function(rng: random.Random, x_lo: float, x_hi: float, terms=4):
    """g(x) = c0 + sum a_j sin(2 pi x / lambda_j + phi_j) with |g| <= 1.

    sum |coefficients| = amp <= 1 (amp drawn in [0.3, 1]) so g stays inside
    [-1, 1] everywhere; wavelengths log-uniform in [20 m, 2 L]."""
    L = max(x_hi - x_lo, 1.0)
    raw = [rng.gauss(0.0, 1.0) for _ in range(terms + 1)]
    norm = sum(abs(c) for c in raw) or 1.0
    amp = rng.uniform(0.3, 1.0)
    coef = [amp * c / norm for c in raw]
    lam = [math.exp(rng.uniform(math.log(20.0), math.log(2.0 * L))) for _ in range(terms)]
    phi = [rng.uniform(0.0, 2.0 * math.pi) for _ in range(terms)]
    c0 = coef[0]

    def g(x):
        x = np.asarray(x, dtype=float)
        out = np.full(x.shape, c0)
        for a, l, p in zip(coef[1:], lam, phi):
            out = out + a * np.sin(2.0 * math.pi * x / l + p)
        return out

    return g


def random_bottoms(bounds: Bounds, X0: float, XM: float, n: int, rng: random.Random):
    """n random smooth (s, v) inside the bounds; s = S(x) g1(x), v = e_v g2(x)."""
    out = []
    if bounds.e_h == 0.0 and bounds.r == 0.0 and bounds.e_v == 0.0:
        return out
    for i in range(n):
        g1 = _random_unit_function(rng, X0, XM)
        g2 = _random_unit_function(rng, X0, XM)
        s = (lambda g: (lambda x: bounds.s_bound(x, X0) * g(x)))(g1)
        v = (lambda g: (lambda x: bounds.e_v * g(x)))(g2)
        out.append(Bottom(f"random#{i}", s, v))
    return out


def sample_worlds(bounds: Bounds, U0: float, X0: float, XM: float, n_random: int,
                  seed):
    """(motions, bottoms): nominal + corners + n_random random of each.

    Every (motion, bottom) pair is a world of the declared set.  Seeded
    (`seed` may be any str/int)."""
    rng = random.Random(f"worlds/{seed}")
    motions = [Motion(U0, 0.0, 0.0, "nominal")]
    bottoms = [Bottom("nominal", None, None)]
    if bounds.is_zero():
        return motions, bottoms
    motions += corner_motions(bounds, U0)
    if bounds.eps_U or bounds.alpha_max or bounds.w_max:
        motions += random_motions(bounds, U0, n_random, rng)
    if bounds.e_h or bounds.r or bounds.e_v:
        bottoms += corner_bottoms(bounds, X0)
        bottoms += random_bottoms(bounds, X0, XM, n_random, rng)
    # drop duplicates of the nominal (zero-bound corners)
    seen, ms = set(), []
    for m in motions:
        key = (m.U, m.alpha, m.w)
        if key not in seen:
            seen.add(key)
            ms.append(m)
    return ms, bottoms


# --------------------------------------------------------------------------
# Putting it together
# --------------------------------------------------------------------------


def track_min_altitudes(points, profile, bottom: Bottom | None):
    """Least b_w - d per track over the scoring points."""
    if isinstance(points, list):
        points = _concat(points)
    px, pd, starts = points
    bw = bottom_interp(profile, px) if bottom is None else bottom(profile, px)
    return [float(v) for v in np.minimum.reduceat(bw - pd, starts)]


def _concat(points):
    """track_points' list as (x, depth, start index of each track)."""
    starts = np.cumsum([0] + [len(p[0]) for p in points[:-1]])
    return (np.concatenate([p[0] for p in points]),
            np.concatenate([p[1] for p in points]), starts)


def world_min_altitudes(vehicle, profile, waypoints, depths, initial_depth,
                        motion: Motion | None = None, bottom: Bottom | None = None):
    """Per-track min true altitude in one world (open loop)."""
    tr = fly(vehicle, waypoints, depths, initial_depth, motion)
    return track_min_altitudes(track_points(tr, waypoints), profile, bottom)


def worst_case(vehicle, profile, waypoints, depths, initial_depth, bounds: Bounds,
               n_random=16, seed=0):
    """Per track: (least min altitude over the sampled worlds, its world name).

    Returns (worst list, details) with details = {"motions", "bottoms",
    "nominal": per-track nominal min altitude}."""
    X = [float(v) for v in waypoints]
    motions, bottoms = sample_worlds(bounds, vehicle.speed, X[0], X[-1], n_random, seed)
    M = len(X) - 1
    worst = [(math.inf, "")] * M
    nominal = None
    for m in motions:
        pts = _concat(track_points(fly(vehicle, X, depths, initial_depth, m), X))
        for b in bottoms:
            alts = track_min_altitudes(pts, profile, None if b.name == "nominal" else b)
            if m.name == "nominal" and b.name == "nominal":
                nominal = alts
            for n in range(M):
                if alts[n] < worst[n][0]:
                    worst[n] = (alts[n], f"{m.name} | {b.name}")
    return worst, {"motions": len(motions), "bottoms": len(bottoms), "nominal": nominal}
