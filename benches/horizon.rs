//! Host benchmark (criterion) of the constrained horizon problem against a
//! constrained peer: `cargo bench --bench horizon -- horizon`.
//!
//! The problem is the planner's first (cold) call of `Planner::<5>` in
//! horizon mode on `us_monterey_canyon_1` (default vehicle, `h_r`/`h_a`
//! 80/60 m, trimmed start at `X_0`, `b(X_0) − h_r`): five tracks jointly,
//! `min Σ J` over the five reference depths, in the planner's search box,
//! subject to the minimum altitude on every track (expressed, as the
//! planner does, through the violation integral `V = ∫ max(0, h_p − h)² dx`
//! over the horizon, m³, zero exactly when no sample is below the penalty
//! altitude `h_p = h_a + m_p`, `m_p` = 0.25 m).
//!
//! - `ours`: `Planner::<5>::plan` with `PlannerConfig::default()`, the real
//!   call: beam scan, penalized BFGS with its penalty stages and plateau
//!   escape, verification, and the commit's certification of the
//!   continuation to the line's end;
//! - `open`: `optimization_engine` 0.12 (OpEn), its penalty method (the
//!   ALM/PM outer loop with `F2(z) = √V(z)`, so that its `ψ = Σ J + c/2 V`
//!   is the planner's `Σ J + μ V` with `μ = c/2`, first `c` = 2e4 as the
//!   planner's `μ` = 1e4) around PANOC in the same box, on the library's
//!   own simulation and exact gradient (`Scenario::evaluate`,
//!   `Scenario::simulate`: an f64 wrapper over the f32 model), from the
//!   same start point, the planner's beam scan, replicated here flight for
//!   flight through the public API and counted in `open`'s flights and
//!   time.
//!
//! Stopping: ours stops on a gradient norm of 1e-3 m² or a relative change
//! of `Φ` below 1e-5 (`Tolerances::default`); PANOC's test is the norm of
//! its fixed-point residual `‖z − Π(z − γ ∇ψ)‖` (m), which has no relative
//! counterpart. `open` gets the loosest residual of 1e-2, 3e-3, 1e-3,
//! 3e-4, 1e-4 m at which its `J` is within ours' relative tolerance of
//! ours' (or below) and its answer feasible, i.e. the most favourable
//! tolerance at equal `J`; the sweep is printed. Its outer loop stops at
//! `‖F2‖ = √V <= 0.1 m^1.5` (`V <= 0.01 m³`, which ours' answer meets),
//! `c` ×100 between outer iterations as the planner's `μ`. Feasibility:
//! the solution's least altitude over the horizon, flown again, against
//! `h_a + m_s` (`m_s` = 0.002 m).
//!
//! `open_least_j` is OpEn at the residual of the sweep where its feasible
//! `J` is least.
//!
//! Before criterion, a table printed to stderr gives each solution's time
//! (mean of a few runs), `J`, least altitude, flights and gradient
//! evaluations, and, for comparison, the best safe `J` of this horizon by
//! the independent f64 exhaustive search (`scripts/j_gap.py`, read from
//! `target/j_gap_horizon.json` when it has written it: the first call's
//! horizon is Monterey 1's whole line).

// Bench code: a failed unwrap is a failed bench.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]
#![allow(clippy::arithmetic_side_effects, missing_docs)]

mod common;

use std::cell::{Cell, RefCell};
use std::hint::black_box;
use std::time::{Duration, Instant};

use auvnav::{Planner, PlannerConfig, Scenario, TrackScore, VehicleState};
use common::line;
use criterion::{Criterion, criterion_group};
use optimization_engine::SolverError;
use optimization_engine::alm::{AlmCache, AlmOptimizer, AlmProblem, NO_MAPPING, NO_SET};
use optimization_engine::constraints::Rectangle;
use optimization_engine::core::panoc::PANOCCache;

/// Tracks of the horizon.
const H: usize = 5;
/// Penalty margin `m_p` and safety margin `m_s` of `PlannerConfig::default`, m.
const PENALTY_MARGIN: f32 = 0.25;
const SAFETY_MARGIN: f32 = 0.002;
/// First penalty weight of `PlannerConfig::default` (dimensionless).
const MU0: f64 = 1e4;
/// Grid points per track and paths kept of the planner's beam scan.
const SCAN_POINTS: u32 = 9;
const BEAM: usize = 4;
/// Ours' relative tolerance on `Φ`.
const REL_TOL: f64 = 1e-5;
/// OpEn's constraint tolerance on `‖F2‖ = √V`, m^1.5: `V <= 0.01 m³`,
/// which ours' answer meets (`V` = 0.0093 m³ there).
const DELTA: f64 = 0.1;
/// OpEn's factor on `c` between outer iterations: the planner's ×100.
const PENALTY_GROWTH: f64 = 100.0;
/// OpEn's L-BFGS memory (its examples' 5; 3 and 10 did no better here).
const LBFGS_MEMORY: usize = 5;
/// PANOC's fixed-point residuals tried, m, loosest first.
const EPSILONS: [f64; 5] = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4];

/// A solution: the horizon's depths, `Σ J` and least altitude flown again,
/// and what it cost.
#[derive(Clone, Copy, Debug)]
struct Solution {
    z: [f32; H],
    j: f32,
    min_altitude: f32,
    /// Flights of any kind (plain or with tangents).
    flights: u32,
    /// Of which with tangents (objective + gradient), where known (the
    /// planner reports its flights, not their kinds).
    gradients: Option<u32>,
    iterations: usize,
}

/// `Σ J` and least altitude of the horizon `z` from `st` (track 0 on).
fn fly(sc: &Scenario<'_, 3>, st: &VehicleState<3>, z: &[f32; H]) -> (f32, f32) {
    let mut s = [TrackScore::default(); H];
    sc.simulate(st, 0, z, &mut s, |_| {}).unwrap();
    let j = s.iter().map(TrackScore::j).sum();
    let alt = s
        .iter()
        .map(TrackScore::min_altitude)
        .fold(f32::INFINITY, f32::min);
    (j, alt)
}

/// Ours: the planner's cold call.
fn ours(sc: &Scenario<'_, 3>, st: &VehicleState<3>) -> Solution {
    let mut p = Planner::<H>::new(PlannerConfig::default()).unwrap();
    let plan = p.plan(sc, st, 0).unwrap();
    let z: [f32; H] = p.horizon().try_into().unwrap();
    let (j, min_altitude) = fly(sc, st, &z);
    Solution {
        z,
        j,
        min_altitude,
        flights: plan.evaluations,
        gradients: None,
        iterations: plan.iterations as usize,
    }
}

/// The planner's search box (`plan/scan.rs`, `search_box`), from public
/// data: each track's depths within the reach of the pitch limit ×1.3
/// over the tracks so far, plus the saturation band and 20 m.
fn search_box(sc: &Scenario<'_, 3>, st: &VehicleState<3>) -> ([f32; H], [f32; H]) {
    let ap = sc.vehicle().autopilot().config();
    let angle = ((1.3 * ap.pitch_limit).min(90.0) * std::f32::consts::PI / 180.0)
        .min(std::f32::consts::FRAC_PI_2);
    let saturation = 3.0 * ap.pitch_limit / ap.depth_pid.kp;
    let [dmin, dmax] = sc.mission().depth_limits();
    let wp = sc.waypoints().positions();
    let mut reach = saturation + 20.0;
    let (mut lo, mut hi) = ([0.0; H], [0.0; H]);
    for j in 0..H {
        reach += (wp[j + 1] - wp[j]) * angle.sin();
        lo[j] = (st.depth() - reach).max(dmin).min(dmax);
        hi[j] = (st.depth() + reach).max(dmin).min(dmax);
    }
    (lo, hi)
}

/// Point `k` of `n` evenly spaced over `[lo, hi]`, as the planner's grid.
fn grid(lo: f32, hi: f32, k: u32, n: u32) -> f32 {
    (lo + (hi - lo) * (k as f32) / ((n - 1) as f32)).clamp(lo, hi)
}

/// The planner's starting point (`plan/scan.rs`, `beam_scan`): each
/// track's 9-point grid flown from each of the 4 best paths so far by
/// `Σ (J + μ V)`, at most one path per grid point. Returns the best
/// path's depths and the flights.
fn beam_start(
    pen: &Scenario<'_, 3>,
    st: &VehicleState<3>,
    (lo, hi): ([f32; H], [f32; H]),
) -> ([f32; H], u32) {
    let mu = MU0 as f32;
    let mut beam: Vec<([f32; H], u32, f32, VehicleState<3>)> = vec![(lo, 0, 0.0, *st)];
    let mut flights = 0;
    for j in 0..H {
        let mut next: Vec<([f32; H], u32, f32, VehicleState<3>)> = Vec::new();
        for parent in &beam {
            for k in 0..SCAN_POINTS {
                let z = grid(lo[j], hi[j], k, SCAN_POINTS);
                let mut s = [TrackScore::default()];
                flights += 1;
                let Ok(end) = pen.simulate(&parent.3, j, &[z], &mut s, |_| {}) else {
                    continue;
                };
                let mut path = *parent;
                path.0[j] = z;
                path.1 = k;
                path.2 = parent.2 + s[0].j() + mu * s[0].violation();
                path.3 = end;
                if !path.2.is_finite() {
                    continue;
                }
                // At most one path per grid point, the BEAM lowest, sorted
                // (a later path of equal objective does not displace).
                if let Some(i) = next.iter().position(|p| p.1 == k) {
                    if next[i].2 <= path.2 {
                        continue;
                    }
                    next.remove(i);
                }
                let at = next.iter().position(|p| path.2 < p.2).unwrap_or(next.len());
                next.insert(at, path);
                next.truncate(BEAM);
            }
        }
        beam = next;
    }
    (beam[0].0, flights)
}

/// One flight's record for the peer's cache: value parts, gradient parts
/// when flown with tangents.
#[derive(Clone, Copy)]
struct Flown {
    z: [f32; H],
    j: f64,
    v: f64,
    grad: Option<([f64; H], [f64; H])>,
}

/// The library's simulation behind the peer's `f64` callbacks, with the
/// last points flown kept (PANOC asks for the cost and then the gradient
/// of one point, and `F2` at points it has costed).
struct Peer<'a, 'b> {
    sc: &'a Scenario<'b, 3>,
    st: &'a VehicleState<3>,
    cache: RefCell<Vec<Flown>>,
    flights: Cell<u32>,
    gradients: Cell<u32>,
}

fn to_f32(u: &[f64]) -> [f32; H] {
    core::array::from_fn(|i| u[i] as f32)
}

impl Peer<'_, '_> {
    /// The record at `u`, flown with tangents if `grad` is asked for.
    fn at(&self, u: &[f64], grad: bool) -> Result<Flown, SolverError> {
        let z = to_f32(u);
        let same = |f: &Flown| f.z.iter().zip(&z).all(|(a, b)| a.to_bits() == b.to_bits());
        if let Some(f) = self.cache.borrow().iter().find(|f| same(f))
            && (!grad || f.grad.is_some())
        {
            return Ok(*f);
        }
        self.flights.set(self.flights.get() + 1);
        let bad = |_| SolverError::NotFiniteComputation("flight failed");
        let f = if grad {
            self.gradients.set(self.gradients.get() + 1);
            let e = self.sc.evaluate::<H>(self.st, 0, &z).map_err(bad)?;
            Flown {
                z,
                j: f64::from(e.j),
                v: f64::from(e.violation),
                grad: Some((e.grad_j.map(f64::from), e.grad_violation.map(f64::from))),
            }
        } else {
            let mut s = [TrackScore::default(); H];
            self.sc
                .simulate(self.st, 0, &z, &mut s, |_| {})
                .map_err(bad)?;
            Flown {
                z,
                j: s.iter().map(|t| f64::from(t.j())).sum(),
                v: s.iter().map(|t| f64::from(t.violation())).sum(),
                grad: None,
            }
        };
        let mut c = self.cache.borrow_mut();
        c.retain(|g| !same(g));
        c.insert(0, f);
        c.truncate(4);
        Ok(f)
    }
}

/// OpEn's penalty method from `z0` in the box to fixed-point residual
/// `eps` (m). The start's flights are added by the caller.
fn open_from(
    sc: &Scenario<'_, 3>,
    st: &VehicleState<3>,
    z0: &[f32; H],
    (lo, hi): ([f32; H], [f32; H]),
    eps: f64,
) -> (Solution, f64) {
    let pen = sc.with_penalty_altitude(sc.mission().min_altitude() + PENALTY_MARGIN);
    let peer = Peer {
        sc: &pen,
        st,
        cache: RefCell::new(Vec::new()),
        flights: Cell::new(0),
        gradients: Cell::new(0),
    };
    let (lo64, hi64) = (lo.map(f64::from), hi.map(f64::from));
    let bounds = Rectangle::new(Some(&lo64[..]), Some(&hi64[..]));
    // ψ(z; c) = Σ J + c/2 ‖F2‖² with F2 = √V, written out (the factory's
    // ∇ψ would divide by √V, undefined at V = 0).
    let psi = |u: &[f64], xi: &[f64], cost: &mut f64| {
        let f = peer.at(u, false)?;
        *cost = f.j + 0.5 * xi[0] * f.v;
        Ok(())
    };
    let d_psi = |u: &[f64], xi: &[f64], g: &mut [f64]| {
        let (gj, gv) = peer.at(u, true)?.grad.unwrap();
        for i in 0..H {
            g[i] = gj[i] + 0.5 * xi[0] * gv[i];
        }
        Ok(())
    };
    let f2 = |u: &[f64], out: &mut [f64]| {
        out[0] = peer.at(u, false)?.v.max(0.0).sqrt();
        Ok(())
    };
    let problem = AlmProblem::new(
        bounds,
        NO_SET,
        NO_SET,
        psi,
        d_psi,
        NO_MAPPING,
        Some(f2),
        0,
        1,
    );
    let mut cache = AlmCache::new(PANOCCache::new(H, eps, LBFGS_MEMORY), 0, 1);
    let mut opt = AlmOptimizer::new(&mut cache, problem)
        .with_delta_tolerance(DELTA)
        .with_epsilon_tolerance(eps)
        .with_initial_inner_tolerance(eps.max(0.1))
        .with_max_outer_iterations(10)
        .with_max_inner_iterations(200)
        .with_initial_penalty(2.0 * MU0)
        .with_penalty_update_factor(PENALTY_GROWTH);
    let mut u = z0.map(f64::from);
    let status = opt.solve(&mut u[..]);
    let z = to_f32(&u);
    let (j, min_altitude) = fly(sc, st, &z);
    let iterations = status.as_ref().map_or(0, |s| s.num_inner_iterations());
    let f2 = status.as_ref().map_or(f64::NAN, |s| s.f2_norm());
    let sol = Solution {
        z,
        j,
        min_altitude,
        flights: peer.flights.get(),
        gradients: Some(peer.gradients.get()),
        iterations,
    };
    (sol, f2)
}

/// The peer: the planner's start, then OpEn.
fn open(sc: &Scenario<'_, 3>, st: &VehicleState<3>, eps: f64) -> Solution {
    let pen = sc.with_penalty_altitude(sc.mission().min_altitude() + PENALTY_MARGIN);
    let bx = search_box(sc, st);
    let (z0, scan) = beam_start(&pen, st, bx);
    let (mut s, _) = open_from(sc, st, &z0, bx, eps);
    s.flights += scan;
    s
}

/// Mean time of `f` over about `budget` (at least 3 runs).
fn time<T>(budget: Duration, mut f: impl FnMut() -> T) -> Duration {
    let t0 = Instant::now();
    let mut n = 0_u32;
    while t0.elapsed() < budget || n < 3 {
        black_box(f());
        n += 1;
    }
    t0.elapsed() / n
}

/// The independent search's best safe `J` of this horizon, if
/// `scripts/j_gap.py --horizon-only` has written it.
fn reference_best() -> Option<f64> {
    let p = concat!(env!("CARGO_MANIFEST_DIR"), "/target/j_gap_horizon.json");
    let text = std::fs::read_to_string(p).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    v.get("best_safe_J")?.as_f64()
}

/// The replicated start against the planner's: `Φ = Σ J + μ V` at the
/// beam scan's point, and the first entry of the planner's history (its
/// objective at its start point).
fn start_check(sc: &Scenario<'_, 3>, st: &VehicleState<3>) {
    let pen = sc.with_penalty_altitude(sc.mission().min_altitude() + PENALTY_MARGIN);
    let (z0, flights) = beam_start(&pen, st, search_box(sc, st));
    let e = pen.evaluate::<H>(st, 0, &z0).unwrap();
    let phi = f64::from(e.j) + MU0 * f64::from(e.violation);
    let mut p = Planner::<H>::new(PlannerConfig::default()).unwrap();
    p.plan(sc, st, 0).unwrap();
    let first = p.history().first().copied().unwrap_or(f32::NAN);
    eprintln!(
        "start (replicated beam scan, {flights} flights): {z0:.2?}, Φ = {phi:.7e} m³; \
         the planner's first Φ: {first:.7e} m³"
    );
}

/// The tolerance sweep and the table (stderr); returns `open`'s residuals:
/// the loosest at ours' `J` or better, and the one of least `J` (both
/// feasible).
fn report(sc: &Scenario<'_, 3>, st: &VehicleState<3>) -> (f64, f64) {
    let h_safe = sc.mission().min_altitude() + SAFETY_MARGIN;
    let o = ours(sc, st);
    let row = |name: &str, s: &Solution, t: Duration, t_ours: Duration| {
        let grads = s.gradients.map_or("n/a".to_string(), |g| g.to_string());
        eprintln!(
            "| {name} | {:.1} | {:.2} | {:.6e} | {:.3} | {} | {} | {grads} | {} | {:.2?} |",
            t.as_secs_f64() * 1e3,
            t.as_secs_f64() / t_ours.as_secs_f64(),
            s.j,
            s.min_altitude,
            s.min_altitude >= h_safe,
            s.flights,
            s.iterations,
            s.z
        );
    };
    eprintln!(
        "\nhorizon: Monterey 1, call 1 (cold), 5 tracks; feasible = least altitude >= {h_safe} m"
    );
    eprintln!(
        "| solver | ms | × ours | J (m³) | least alt. (m) | feasible | flights | with gradient | iterations | depths (m) |"
    );
    eprintln!("|---|---:|---:|---:|---:|---|---:|---:|---:|---|");
    let b = Duration::from_millis(1000);
    let t_ours = time(b, || ours(sc, st));
    row("ours", &o, t_ours, t_ours);
    let mut chosen = None;
    let mut least: Option<(f32, f64)> = None;
    for eps in EPSILONS {
        let s = open(sc, st, eps);
        let t = time(b, || open(sc, st, eps));
        row(&format!("open, ε = {eps} m"), &s, t, t_ours);
        let equal = f64::from(s.j) <= f64::from(o.j) * (1.0 + REL_TOL);
        if chosen.is_none() && equal && s.min_altitude >= h_safe {
            chosen = Some(eps);
        }
        if s.min_altitude >= h_safe && least.is_none_or(|l| s.j < l.0) {
            least = Some((s.j, eps));
        }
    }
    match reference_best() {
        Some(best) => eprintln!(
            "independent exhaustive search, best safe J of this horizon: {best:.6e} m³ \
             (ours {:+.3} %)",
            (f64::from(o.j) / best - 1.0) * 100.0
        ),
        None => eprintln!("(no target/j_gap_horizon.json: run scripts/j_gap.py --horizon-only)"),
    }
    let eps = chosen.unwrap_or(1e-4);
    let best = least.map_or(1e-4, |l| l.1);
    eprintln!(
        "criterion: `open` at ε = {eps} m (the loosest at ours' J or better, feasible), \
         `open_least_j` at ε = {best} m (its least feasible J)\n"
    );
    (eps, best)
}

fn benches(c: &mut Criterion) {
    let l = line();
    let sc = l.scenario();
    let st = sc.start_state(sc.default_initial_depth());
    start_check(&sc, &st);
    let (eps, best) = report(&sc, &st);
    let mut g = c.benchmark_group("horizon");
    g.sample_size(10);
    g.bench_function("ours", |b| b.iter(|| black_box(ours(&sc, &st))));
    g.bench_function("open", |b| b.iter(|| black_box(open(&sc, &st, eps))));
    g.bench_function("open_least_j", |b| {
        b.iter(|| black_box(open(&sc, &st, best)))
    });
    g.finish();
}

criterion_group!(group, benches);

fn main() {
    group();
    Criterion::default().configure_from_args().final_summary();
}
