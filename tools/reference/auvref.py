"""Independent f64 reference implementation of the AUV closed-loop model.

This module follows /work/shared/spec/model.md (the model contract) to the
letter, with the project's choices for what the contract leaves open (see
README.md in this folder):

* plant realization: controllable canonical form as produced by
  ``scipy.signal.tf2ss`` on the monic, leading-zero-stripped transfer function
  (a ``kind = "rate"`` q/δ numerator is divided by ``s`` first);
* ZOH discretization with ``scipy.signal.cont2discrete`` (cross-checked with
  ``scipy.linalg.expm`` of the augmented matrix);
* pitch-loop sign σ = sign(N(0)) · sign(lowest-order nonzero coefficient of D);
* objective, RMS, minimum altitude and a violation measure per track, by the
  clipped trapezoidal rule of model.md section 8.

Everything is IEEE double precision.  The time loop runs on plain Python
floats (the same f64 arithmetic as a numpy loop, only faster for the tiny
2..6 state vectors involved).
"""

from __future__ import annotations

import bisect
import copy
import math
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg
import scipy.signal

__all__ = [
    "DEFAULT_VEHICLE",
    "ModelError",
    "Plant",
    "realize",
    "discretize",
    "Profile",
    "Vehicle",
    "Trajectory",
    "simulate",
    "evaluate",
    "evaluate_plan",
    "plan_objectives",
    "gradients",
    "full_config",
    "closed_loop_matrix",
    "spectral_radius",
]


class ModelError(ValueError):
    """Invalid input for the model (bad plant, bad profile, out-of-range x...)."""


# --------------------------------------------------------------------------
# Defaults (model.md section 9, cli.md VEHICLE.toml)
# --------------------------------------------------------------------------

DEFAULT_VEHICLE = {
    "speed": 1.5,
    "sample_time": 0.1,
    "pitch_limit": 25.0,
    "elevator_limit": 25.0,
    "reference_altitude": 80.0,
    "min_altitude": 60.0,
    "initial_depth": None,  # default: b(X_0) - h_r
    "depth_limits": [0.0, 6000.0],
    "depth_pid": {"kp": 1.5, "ki": 0.0, "kd": 2.0},
    "pitch_pid": {"kp": 2.0, "ki": 0.1, "kd": 3.0},
    "plant": {"kind": "pitch", "num": [-0.173], "den": [1.0, 2.681, 0.546, 0.048]},
    "optimizer": {"max_iterations": 200},
}


# --------------------------------------------------------------------------
# Plant: realization and discretization (model.md section 4)
# --------------------------------------------------------------------------


def _strip_leading_zeros(c):
    c = [float(v) for v in c]
    i = 0
    while i < len(c) and c[i] == 0.0:
        i += 1
    return c[i:]


@dataclass
class Plant:
    """A realized pitch plant θ(s)/δ(s) = N(s)/D(s), D monic of order n."""

    kind: str
    num_in: list  # coefficients as given (highest power first)
    den_in: list
    num: list  # θ/δ numerator after rate-division and monic scaling
    den: list  # monic denominator, length n+1
    A: np.ndarray  # n x n
    B: np.ndarray  # n
    C: np.ndarray  # n   θ = C η
    CA: np.ndarray  # n   q = C A η
    sigma: float  # pitch-loop sign, ±1
    dc_gain: float | None  # N(0)/D(0); None when D(0) = 0 (integrator)

    @property
    def order(self) -> int:
        return len(self.den) - 1


def realize(kind: str, num, den) -> Plant:
    """Controllable canonical realization of θ/δ (project choice 1)."""
    if kind not in ("pitch", "rate"):
        raise ModelError(f"plant kind must be 'pitch' or 'rate', got {kind!r}")
    num_in = [float(v) for v in num]
    den_in = [float(v) for v in den]
    if not all(math.isfinite(v) for v in num_in + den_in):
        raise ModelError("plant coefficients must be finite")
    n_ = _strip_leading_zeros(num_in)
    d_ = _strip_leading_zeros(den_in)
    if not d_:
        raise ModelError("plant denominator is zero")
    if not n_:
        raise ModelError("plant numerator is zero")
    if kind == "rate":
        # q/δ = s·θ/δ: the numerator's constant term must be exactly zero.
        if n_[-1] != 0.0:
            raise ModelError("rate-form numerator must have a zero constant term")
        n_ = _strip_leading_zeros(n_[:-1])
        if not n_:
            raise ModelError("rate-form numerator is zero after division by s")
    lead = d_[0]
    n_ = [v / lead for v in n_]
    d_ = [v / lead for v in d_]
    n = len(d_) - 1
    if n < 2 or len(n_) - 1 > n - 2:
        raise ModelError(
            f"need deg num <= deg den - 2 (got deg num {len(n_) - 1}, deg den {n})"
        )
    if n_[-1] == 0.0:
        raise ModelError("N(0) = 0 is not allowed (θ/δ has a zero at the origin)")

    A = np.zeros((n, n))
    A[0, :] = -np.asarray(d_[1:])
    for i in range(1, n):
        A[i, i - 1] = 1.0
    B = np.zeros(n)
    B[0] = 1.0
    C = np.zeros(n)
    C[n - len(n_):] = n_

    # Must be exactly scipy.signal.tf2ss of the monic transfer function.
    As, Bs, Cs, Ds = scipy.signal.tf2ss(n_, d_)
    assert np.array_equal(As, A), (As, A)
    assert np.array_equal(Bs.ravel(), B), (Bs, B)
    assert np.array_equal(Cs.ravel(), C), (Cs, C)
    assert np.all(Ds == 0.0)

    CA = C @ A
    # C·B = 0 because deg N <= n - 2: q has no feed-through of δ.
    assert C @ B == 0.0

    low_d = next(v for v in reversed(d_) if v != 0.0)
    sigma = math.copysign(1.0, n_[-1]) * math.copysign(1.0, low_d)
    dc_gain = n_[-1] / d_[-1] if d_[-1] != 0.0 else None
    return Plant(kind, num_in, den_in, n_, d_, A, B, C, CA, sigma, dc_gain)


def discretize(A: np.ndarray, B: np.ndarray, Ts: float):
    """Exact ZOH: (Ad, Bd) from cont2discrete, asserted equal to expm(augmented)."""
    n = A.shape[0]
    Ad, Bd, _, _, _ = scipy.signal.cont2discrete(
        (A, B.reshape(n, 1), np.zeros((1, n)), np.zeros((1, 1))), Ts, method="zoh"
    )
    Bd = Bd.ravel()
    M = np.zeros((n + 1, n + 1))
    M[:n, :n] = A
    M[:n, n] = B
    E = scipy.linalg.expm(M * Ts)
    assert np.allclose(E[:n, :n], Ad, rtol=1e-12, atol=1e-14), "Ad mismatch"
    assert np.allclose(E[:n, n], Bd, rtol=1e-12, atol=1e-14), "Bd mismatch"
    return Ad, Bd


# --------------------------------------------------------------------------
# Bottom profile (model.md section 2)
# --------------------------------------------------------------------------


class Profile:
    """Linear interpolation of (x_i, b_i); evaluation outside is an error."""

    def __init__(self, x, b):
        x = [float(v) for v in x]
        b = [float(v) for v in b]
        if len(x) != len(b) or len(x) < 2:
            raise ModelError("profile needs at least 2 samples and equal lengths")
        if not all(math.isfinite(v) for v in x + b):
            raise ModelError("profile values must be finite")
        if any(x[i + 1] <= x[i] for i in range(len(x) - 1)):
            raise ModelError("profile x must be strictly increasing")
        self.x = x
        self.b = b

    @classmethod
    def from_csv(cls, path):
        xs, bs = [], []
        with open(path) as f:
            header = f.readline().strip()
            if header != "x_m,bottom_depth_m":
                raise ModelError(f"{path}: unexpected header {header!r}")
            for line in f:
                line = line.strip()
                if not line:
                    continue
                a, c = line.split(",")
                xs.append(float(a))
                bs.append(float(c))
        return cls(xs, bs)

    def __call__(self, xq: float) -> float:
        x = self.x
        if not (x[0] <= xq <= x[-1]):
            raise ModelError(f"b(x) evaluated outside the profile: x = {xq!r}")
        i = bisect.bisect_right(x, xq) - 1
        if i >= len(x) - 1:
            return self.b[-1]
        x0, x1 = x[i], x[i + 1]
        b0, b1 = self.b[i], self.b[i + 1]
        return b0 + (b1 - b0) * (xq - x0) / (x1 - x0)


# --------------------------------------------------------------------------
# Vehicle configuration (cli.md VEHICLE.toml)
# --------------------------------------------------------------------------


def full_config(overrides: dict | None = None) -> dict:
    """Defaults merged with `overrides` (nested tables merged key by key)."""
    cfg = copy.deepcopy(DEFAULT_VEHICLE)
    for k, v in (overrides or {}).items():
        if k not in cfg:
            raise ModelError(f"unknown config key {k!r}")
        if isinstance(cfg[k], dict):
            if not isinstance(v, dict):
                raise ModelError(f"config key {k!r} must be a table")
            for kk, vv in v.items():
                if kk not in cfg[k]:
                    raise ModelError(f"unknown config key {k}.{kk}")
                cfg[k][kk] = copy.deepcopy(vv)
        else:
            cfg[k] = copy.deepcopy(v)
    return cfg


@dataclass
class Vehicle:
    speed: float
    sample_time: float
    pitch_limit: float
    elevator_limit: float
    reference_altitude: float
    min_altitude: float
    initial_depth: float | None
    depth_limits: tuple
    kpd: float
    kid: float
    kdd: float
    kpt: float
    kit: float
    kdt: float
    plant: Plant
    Ad: np.ndarray
    Bd: np.ndarray
    config: dict = field(repr=False)

    @classmethod
    def from_config(cls, overrides: dict | None = None) -> "Vehicle":
        c = full_config(overrides)
        f = float
        for key in ("speed", "sample_time", "pitch_limit", "elevator_limit"):
            if not (math.isfinite(f(c[key])) and f(c[key]) > 0.0):
                raise ModelError(f"{key} must be finite and > 0")
        h_r, h_a = f(c["reference_altitude"]), f(c["min_altitude"])
        if not (math.isfinite(h_r) and math.isfinite(h_a) and 0.0 < h_a <= h_r):
            raise ModelError("need 0 < min_altitude <= reference_altitude")
        lo, hi = (f(v) for v in c["depth_limits"])
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise ModelError("depth_limits must be finite with min < max")
        gains = [f(c["depth_pid"][k]) for k in ("kp", "ki", "kd")]
        gains += [f(c["pitch_pid"][k]) for k in ("kp", "ki", "kd")]
        if not all(math.isfinite(g) for g in gains):
            raise ModelError("PID gains must be finite")
        d0 = c["initial_depth"]
        if d0 is not None:
            d0 = f(d0)
            if not math.isfinite(d0):
                raise ModelError("initial_depth must be finite")
        p = c["plant"]
        plant = realize(p["kind"], p["num"], p["den"])
        Ad, Bd = discretize(plant.A, plant.B, f(c["sample_time"]))
        return cls(
            f(c["speed"]), f(c["sample_time"]), f(c["pitch_limit"]),
            f(c["elevator_limit"]), h_r, h_a, d0, (lo, hi), *gains,
            plant, Ad, Bd, c,
        )

    def resolved_initial_depth(self, profile: Profile | None, x0: float) -> float:
        if self.initial_depth is not None:
            return self.initial_depth
        if profile is None:
            raise ModelError("initial_depth needed when there is no profile")
        return profile(x0) - self.reference_altitude

    def config_dict(self, initial_depth: float | None = None) -> dict:
        """The full config dict (every cli.md key), initial_depth resolved."""
        c = copy.deepcopy(self.config)
        if initial_depth is not None:
            c["initial_depth"] = float(initial_depth)
        return c


# --------------------------------------------------------------------------
# Closed-loop simulation (model.md sections 3, 5, 6, 7)
# --------------------------------------------------------------------------


@dataclass
class Trajectory:
    x: list  # sample positions x_0 .. x_K (x_K >= X_M)
    depth: list  # d_k
    pitch: list  # θ_k = C η_k
    pitch_rate: list  # q_k = C A η_k
    elevator: list  # δ_k, k = 0 .. K-1
    theta_ref: list  # θref_k, k = 0 .. K-1
    reference: list  # r_k, k = 0 .. K-1

    @property
    def n_samples(self) -> int:
        return len(self.x)


def simulate(vehicle: Vehicle, waypoints, depths, initial_depth: float,
             max_steps: int | None = None) -> Trajectory:
    """Fly the whole line X_0 .. X_M with reference depths z_1..z_M."""
    X = [float(v) for v in waypoints]
    z = [float(v) for v in depths]
    M = len(X) - 1
    if M < 1 or len(z) != M:
        raise ModelError("need M+1 >= 2 waypoints and M depths")
    if any(X[i + 1] <= X[i] for i in range(M)):
        raise ModelError("waypoints must be strictly increasing")
    if not all(math.isfinite(v) for v in X + z):
        raise ModelError("waypoints and depths must be finite")

    v = vehicle
    Ts, U0 = v.sample_time, v.speed
    thmax, dmax = v.pitch_limit, v.elevator_limit
    kpd, kid, kdd = v.kpd, v.kid, v.kdd
    kpt, kit, kdt = v.kpt, v.kit, v.kdt
    sigma = v.plant.sigma
    n = v.plant.order
    Ad = [[float(a) for a in row] for row in v.Ad]
    Bd = [float(b) for b in v.Bd]
    C = [float(c) for c in v.plant.C]
    CA = [float(c) for c in v.plant.CA]
    rng = range(n)

    if max_steps is None:
        # generous: 20x the straight-line number of steps
        max_steps = int(20 * (X[-1] - X[0]) / (U0 * Ts)) + 1000

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
            raise ModelError("vehicle does not progress along the track")
        # 1. active reference: X_{n-1} <= x < X_n
        r = z[bisect.bisect_right(X, x) - 1]
        # 2. depth loop
        e_d = r - d
        ddot = (d - d_prev) / Ts
        vk = -(kpd * e_d + kid * Id - kdd * ddot)
        thref = min(max(vk, -thmax), thmax)
        #    pitch loop (σ = -1 for a negative-DC-gain plant: model.md §5)
        e_t = thref - theta
        wk = sigma * (kpt * e_t + kit * Ith - kdt * q)
        delta = min(max(wk, -dmax), dmax)
        #    conditional integration (anti-windup)
        if not ((vk > thmax and e_d < 0.0) or (vk < -thmax and e_d > 0.0)):
            Id += Ts * e_d
        se = sigma * e_t
        if not ((wk > dmax and se > 0.0) or (wk < -dmax and se < 0.0)):
            Ith += Ts * e_t
        # 3. plant
        eta = [sum(Ad[i][j] * eta[j] for j in rng) + Bd[i] * delta for i in rng]
        theta1 = sum(C[j] * eta[j] for j in rng)
        # 4. kinematics with θ̄ = (θ_k + θ_{k+1}) / 2
        tb = math.radians(0.5 * (theta + theta1))
        x_new = x + U0 * Ts * math.cos(tb)
        d_new = d - U0 * Ts * math.sin(tb)
        if not x_new > x:
            raise ModelError("x does not increase (|pitch| >= 90 deg?)")
        # 5. derivative memory
        d_prev = d
        d = d_new
        x = x_new
        theta = theta1
        q = sum(CA[j] * eta[j] for j in rng)
        steps += 1

        dels.append(delta)
        threfs.append(thref)
        refs.append(r)
        xs.append(x)
        ds.append(d)
        ths.append(theta)
        qs.append(q)

    return Trajectory(xs, ds, ths, qs, dels, threfs, refs)


# --------------------------------------------------------------------------
# Performance index, RMS, altitude, violation (model.md section 8)
# --------------------------------------------------------------------------


def _clipped_trapezoid(xs, vals, k0, k1, a, b, val_at):
    """½∫_a^b f² dx by the trapezoid over samples, clipped at a and b.

    Samples k0..k1 are those with a <= x_k <= b (k0 > k1 when none).
    `val_at(c)` gives f at a clip point c (interpolated depth).
    Each (sub)segment [u, w] contributes (w - u)(f_u² + f_w²)/4.
    """
    if k0 > k1:  # the interval lies inside one segment
        fa, fb = val_at(a), val_at(b)
        return (b - a) * (fa * fa + fb * fb) / 4.0
    total = 0.0
    if xs[k0] > a:
        fa = val_at(a)
        total += (xs[k0] - a) * (fa * fa + vals[k0] * vals[k0]) / 4.0
    for k in range(k0, k1):
        total += (xs[k + 1] - xs[k]) * (vals[k] * vals[k] + vals[k + 1] * vals[k + 1]) / 4.0
    if xs[k1] < b:
        fb = val_at(b)
        total += (b - xs[k1]) * (vals[k1] * vals[k1] + fb * fb) / 4.0
    return total


def evaluate(traj: Trajectory, profile: Profile, waypoints, h_r: float, h_a: float):
    """Per-track J, rms, min_altitude and violation V (project choice 5)."""
    X = [float(v) for v in waypoints]
    xs, ds = traj.x, traj.depth
    XM = X[-1]
    # Samples used pointwise: those with x_k <= X_M (later ones only via a clip).
    K = bisect.bisect_right(xs, XM)  # samples 0..K-1 have x <= X_M
    bs = [profile(xs[k]) for k in range(K)]
    e = [bs[k] - h_r - ds[k] for k in range(K)]
    h = [bs[k] - ds[k] for k in range(K)]
    p = [max(0.0, h_a - hk) for hk in h]

    def depth_at(c):
        j = bisect.bisect_left(xs, c)  # first sample with x >= c
        if j < len(xs) and xs[j] == c:
            return ds[j]
        if j == 0 or j >= len(xs):
            raise ModelError(f"clip point {c!r} outside the simulated samples")
        x0, x1 = xs[j - 1], xs[j]
        return ds[j - 1] + (ds[j] - ds[j - 1]) * (c - x0) / (x1 - x0)

    def e_at(c):
        return profile(c) - h_r - depth_at(c)

    def h_at(c):
        return profile(c) - depth_at(c)

    def p_at(c):
        return max(0.0, h_a - h_at(c))

    tracks = []
    for n in range(1, len(X)):
        a, b = X[n - 1], X[n]
        k0 = bisect.bisect_left(xs, a)
        k1 = bisect.bisect_right(xs, b) - 1
        assert k1 < K
        J = _clipped_trapezoid(xs, e, k0, k1, a, b, e_at)
        V = _clipped_trapezoid(xs, p, k0, k1, a, b, p_at)
        hmin = min([h_at(a), h_at(b)] + h[k0:k1 + 1])
        tracks.append({
            "track": n,
            "x_start": a,
            "x_end": b,
            "J": J,
            "rms": math.sqrt(2.0 * J / (b - a)),
            "min_altitude": hmin,
            "violation": V,
        })
    return {
        "tracks": tracks,
        "total_J": sum(t["J"] for t in tracks),
        "total_violation": sum(t["violation"] for t in tracks),
        "min_altitude": min(t["min_altitude"] for t in tracks),
        "n_samples": traj.n_samples,
        "final_x": xs[-1],
        "final_depth": ds[-1],
    }


def evaluate_plan(vehicle: Vehicle, profile: Profile, waypoints, depths,
                  initial_depth: float | None = None):
    """Simulate the whole line and score it; returns (trajectory, result)."""
    X = [float(v) for v in waypoints]
    if X[0] < profile.x[0] or X[-1] > profile.x[-1]:
        raise ModelError("waypoints must lie within the profile")
    d0 = initial_depth if initial_depth is not None else \
        vehicle.resolved_initial_depth(profile, X[0])
    traj = simulate(vehicle, X, depths, d0)
    res = evaluate(traj, profile, X, vehicle.reference_altitude, vehicle.min_altitude)
    return traj, res


def plan_objectives(vehicle, profile, waypoints, depths, initial_depth=None):
    """(Σ J_n, [J_n], Σ V_n) of a plan."""
    _, r = evaluate_plan(vehicle, profile, waypoints, depths, initial_depth)
    return r["total_J"], [t["J"] for t in r["tracks"]], r["total_violation"]


def gradients(vehicle, profile, waypoints, depths, initial_depth=None, h=1e-3):
    """Central differences: (dΣJ/dz_n, dJ_n/dz_n, dΣV/dz_n) for n = 1..M."""
    z = [float(v) for v in depths]
    gJ, gJn, gV = [], [], []
    for n in range(len(z)):
        zp = list(z)
        zm = list(z)
        zp[n] += h
        zm[n] -= h
        Jp, Jnp, Vp = plan_objectives(vehicle, profile, waypoints, zp, initial_depth)
        Jm, Jnm, Vm = plan_objectives(vehicle, profile, waypoints, zm, initial_depth)
        dz = zp[n] - zm[n]
        gJ.append((Jp - Jm) / dz)
        gJn.append((Jnp[n] - Jnm[n]) / dz)
        gV.append((Vp - Vm) / dz)
    return gJ, gJn, gV


# --------------------------------------------------------------------------
# Small-signal closed loop (for sanity checks of gains, not part of the model)
# --------------------------------------------------------------------------


def closed_loop_matrix(vehicle: Vehicle) -> np.ndarray:
    """The one-step map of the unsaturated loop, linearized (sin θ ≈ θ).

    State (η_1..η_n, I_θ, I_d, d, d_prev) with a constant reference r = 0.
    Its spectral radius < 1 means the small-signal closed loop is stable.
    """
    v = vehicle
    n = v.plant.order
    N = n + 4
    Ts, k = v.sample_time, v.speed * v.sample_time * math.pi / 180.0
    Mx = np.zeros((N, N))
    for col in range(N):
        s = np.zeros(N)
        s[col] = 1.0
        eta, It, Id, d, dp = s[:n], s[n], s[n + 1], s[n + 2], s[n + 3]
        e_d = -d
        vk = -(v.kpd * e_d + v.kid * Id - v.kdd * (d - dp) / Ts)
        theta = v.plant.C @ eta
        q = v.plant.CA @ eta
        e_t = vk - theta
        w = v.plant.sigma * (v.kpt * e_t + v.kit * It - v.kdt * q)
        eta1 = v.Ad @ eta + v.Bd * w
        theta1 = v.plant.C @ eta1
        out = np.concatenate([eta1, [It + Ts * e_t, Id + Ts * e_d,
                                     d - k * 0.5 * (theta + theta1), d]])
        Mx[:, col] = out
    return Mx


def spectral_radius(vehicle: Vehicle) -> float:
    """Largest |eigenvalue| of the small-signal loop.  With Kid = 0 the depth
    integrator is a pure bookkeeping state (eigenvalue 1, no effect) and is
    left out."""
    Mx = closed_loop_matrix(vehicle)
    if vehicle.kid == 0.0:
        i = vehicle.plant.order + 1
        keep = [j for j in range(Mx.shape[0]) if j != i]
        Mx = Mx[np.ix_(keep, keep)]
    return float(max(abs(np.linalg.eigvals(Mx))))
