//! Sequential quadratic programming (SQP) with a dense BFGS metric and an
//! Armijo line search: the horizon's optimizer under the minimum-altitude
//! constraint (Nocedal & Wright, *Numerical Optimization*, §18.3 and
//! Procedure 18.2; the method of SLSQP).
//!
//! Each iteration linearizes the constraints `cᵢ(z) >= 0` at `z` (for the
//! planner: each segment's least altitude above its target, with its
//! gradient from the tangent pass) and solves the quadratic program
//!
//! ```text
//! min ½ dᵀ A d + ∇J ᵀ d   s.t.   cᵢ + ∇cᵢ ᵀ d >= 0,   lo <= z + d <= hi
//! ```
//!
//! for the step `d` and the multipliers `λ` ([`super::qp`]). The step is
//! accepted by backtracking on the ℓ1 merit function
//! `φ = J + ρ v`, where `v` is the objective's own ℓ1 infeasibility (for
//! the planner: the sum over tracks of the shortfall of the track's least
//! altitude below its target) and `ρ` the exact-penalty weight, kept above
//! the largest sum of multipliers of one group (track) times
//! [`RHO_FACTOR`]. The trial points are valued by [`Constrained::value`]
//! (a plain flight); only the accepted one is linearized.
//!
//! The metric `A` starts as the Gauss–Newton matrix of `J` (the objective
//! is a least-squares integral) and is then updated by the damped BFGS
//! formula of Powell (N&W eq. 18.13–18.16) on the gradient of the
//! Lagrangian `∇J − Σ λᵢ ∇cᵢ`, which keeps it positive definite in exact
//! arithmetic; where the QP finds it not so in f32, it is reset to its
//! diagonal (see [`diagonal`]). A QP whose
//! linearized constraints have no common point is relaxed: each violated
//! constraint is asked for `1 − σ` of its shortfall, `σ` = ½, 0.9, then 1
//! (do not make it worse), which `d = 0` always satisfies.
//!
//! The QP takes only the rows within the objective's band
//! ([`Linearized::band`]). A careful run (the planner's restart from the
//! best feasible iterate of a run that had to go back there) also takes
//! the rows beyond it that the step would cross by their linearization,
//! and solves again: a row 26 m clear but falling 0.96 m a metre is
//! crossed by a 190 m step. On a random line with an integrating depth
//! loop (`check_planner.py --seed 1103 --vehicle
//! tools/reference/vehicles/integ.toml`, `unseen_1103_3`) the first run
//! stepped 320 m past such a row into a 70 m shortfall that the merit's
//! weight, still 0, did not count, stalled there and went back to its
//! start: the line's `J` was 1.49× the best safe; careful, 1.0000×.
//!
//! Stops (each with `v` within the feasibility tolerance): the step
//! shorter than [`STEP_TOL`] (m), or the QP's model of the decrease of
//! `J` below the relative tolerance of [`super::Tolerances`] (as BFGS's
//! 3.14b); a full step that changes `φ` by less than that; else the
//! iteration cap, or no acceptable step (`LineSearchFailed`). A run that
//! finds no acceptable step while infeasible first tries a feasibility
//! restoration (`Run::restore`, at most [`RESTORATIONS`] a run), as does
//! one whose merit stayed unmoved [`STALLS`] iterations in a row: on a
//! random line (`unseen_11_1` of `check_planner.py --seed 11`) the runs
//! stopped infeasible and the line's `J` was 1.32× the best safe; with the
//! restoration, 1.002×. A run never ends worse than the best feasible
//! point it linearized (`best.rs`).

use heapless::Vec;

use super::best::BestFeasible;
use super::constrained::CONSTRAINTS;
pub(crate) use super::constrained::{Constrained, Linearized};
use super::dense::{Mat, at, damped_update, dot, mul, put};
use super::qp::{self, QpSolution};
use super::step::{REGULARIZATION, StepRows, step};
use super::{BfgsConfig, Bounds, OptimError, Outcome, Status, Vector};

/// A step whose largest component is below this (m) is no step.
pub(crate) const STEP_TOL: f32 = 1e-3;

/// `ρ` is kept at least this many times the largest group's multipliers.
const RHO_FACTOR: f32 = 1.5;

/// Most feasibility restorations of one run (each: one least-norm step
/// onto the linearized constraints, from where the run goes on).
const RESTORATIONS: u32 = 3;

/// A restoration step is taken when it brings `v` down to this share or
/// less (a problem with no feasible point near, Monterey 3's, would
/// otherwise buy shavings of `v` with gradient evaluations).
const RESTORED: f32 = 0.5;

/// A restoration step that cut `v` by less than [`RESTORED`] is extended
/// along the secant of `v` to zero, by at most this factor.
const SECANT_REACH: f32 = 4.0;

/// An accepted step below this share of the QP's is a sliver
/// ([`SqpEnd::sliver`]).
const SLIVER: f32 = 1e-3;

/// Infeasible iterations in a row that leave the merit `φ` unmoved (within
/// the relative tolerance) before the run counts as stalled: on an
/// infeasible random line (`check_planner.py --seed 43`, `unseen_43_6`)
/// Armijo's 2⁻¹⁰ steps moved `φ` by a few parts in 10⁸ for 200 iterations,
/// 2 400 flights a call.
const STALLS: u32 = 5;

/// Minimizes `obj` over its first `n` variables from `z0` within `bounds`
/// (the others held), feasible within `feas_tol` (m of `v`), by the SQP of
/// the module docs with `cfg`'s iteration cap, tolerances and Armijo
/// constant; the result is written into `out`, `J` at the start and at
/// each iterate appended to `out.history` (not monotone: an early iterate
/// may be infeasible, and lower). The first metric is the Gauss–Newton
/// matrix at `z0` (a restart's too: the plateau's row of a finished run's
/// metric is empty, its step there would be unbounded). `rho0`: the
/// merit weight to start from (m³/m; 0 learns it from the multipliers).
/// `careful`: the QP also takes the rows beyond the band its step would
/// cross (module docs). A run that ends infeasible or worse than its best
/// feasible iterate goes back to that iterate (`best.rs`); one its
/// objective gives up ([`Constrained::abandon`]) stops there, as at the
/// iteration cap, with no `left` to follow up from. Returns the
/// ℓ1 merit's final penalty weight and any row active at a one-sided kink
/// at the end ([`SqpEnd`]).
///
/// # Errors
/// [`OptimError`] when the objective fails or is not finite at the start.
pub(crate) fn sqp_into<const K: usize, O: Constrained<K>>(
    obj: &mut O,
    (z0, rho0, careful): (&[f32; K], f32, bool),
    (bounds, n): (&Bounds<K>, usize),
    cfg: &BfgsConfig,
    feas_tol: f32,
    out: &mut Outcome<K>,
) -> Result<SqpEnd<K>, OptimError<O::Error>> {
    cfg.validate().map_err(OptimError::Config)?;
    if !bounds.is_valid() {
        return Err(OptimError::Config(super::OptimConfigError::Bounds));
    }
    let n = n.min(K);
    let mut run = Run {
        z: bounds.project(z0),
        lin: Linearized::default(),
        a: [[0.0; K]; K],
        rho: rho0.max(0.0),
        evaluations: 1,
        iterations: 0,
        skipped: 0,
        stalls: 0,
        restorations: 0,
        careful,
        sliver: false,
    };
    obj.linearize(&run.z, true, &mut run.lin)
        .map_err(OptimError::Start)?;
    if !(run.lin.j.is_finite() && run.lin.grad.iter().all(|g| g.is_finite())) {
        return Err(OptimError::NonFinite);
    }
    run.a = initial_metric(&run.lin.gn, n);
    let _ = out.history.push(run.lin.j);
    let mut best = BestFeasible::default();
    best.see(&run.z, &run.lin, feas_tol);
    let mut abandoned = false;
    let status = loop {
        if run.iterations >= cfg.max_iterations {
            break Status::MaxIterations;
        }
        let (before, j_before) = (run.iterations, run.lin.j);
        let stop = run.iterate(obj, (bounds, n), cfg, feas_tol);
        let stop = run.unstuck(obj, (bounds, n), stop, (feas_tol, cfg.max_iterations));
        // One value per completed iteration, the last included.
        if run.iterations != before {
            let _ = out.history.push(run.lin.j);
            best.see(&run.z, &run.lin, feas_tol);
        }
        if let Some(stop) = stop {
            break stop;
        }
        if obj.abandon(run.iterations, (j_before, run.lin.j)) {
            abandoned = true;
            break Status::MaxIterations;
        }
    };
    let (left, left_j, left_grad) = (run.z, run.lin.j, run.lin.grad);
    let returned = best.return_to(obj, (&mut run.z, &mut run.lin), (feas_tol, &cfg.tol));
    run.evaluations = run.evaluations.saturating_add(u32::from(returned));
    run.report(out, bounds, status);
    Ok(SqpEnd {
        rho: run.rho,
        kink: run.lin.kinked(kink_band(&run.lin, feas_tol), n),
        blended: run.lin.blended(kink_band(&run.lin, feas_tol), n),
        returned,
        // (Given up: no follow-up from where it left.)
        left: (returned && !abandoned).then_some(left),
        lower: left_j < run.lin.j,
        plateaus: plateaus(returned, z0, (&left, &left_grad), n),
        sliver: status == Status::Converged && run.sliver && !returned,
    })
}

/// What a run leaves beside its [`Outcome`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SqpEnd<const K: usize> {
    /// The ℓ1 merit's final penalty weight `ρ` (m³ of `J` per m of `v`;
    /// 0 when no constraint was ever active).
    pub rho: f32,
    /// The groups (bits) of rows active at a one-sided kink at the end
    /// ([`Linearized::kinked`]).
    pub kink: u32,
    /// The groups (bits) of rows active in transition at the end
    /// ([`Linearized::blended`]).
    pub blended: u32,
    /// Whether the run went back to its best feasible iterate
    /// (`best.rs`).
    pub returned: bool,
    /// Where it ended before it went back (not where its objective gave
    /// it up).
    pub left: Option<[f32; K]>,
    /// Whether its `J` was lower there than where it went back to.
    pub lower: bool,
    /// The depths after the first (bits) that it moved from its start and
    /// left on a plateau there (`∂J/∂z_j` exactly zero: a saturated dive
    /// or climb the whole track, whose `J` it no longer sees;
    /// [`plateaus`]).
    pub plateaus: u32,
    /// Whether it converged on a step that the line search cut below
    /// [`SLIVER`] of the QP's: the metric that chose the step may be out
    /// of scale, and the end not an optimum.
    pub sliver: bool,
}

/// The first `n` depths but the first (bits) at which `end` differs
/// from `start` and the gradient `grad` is exactly zero, if the run
/// `returned` (else none).
fn plateaus<const K: usize>(
    returned: bool,
    start: &[f32; K],
    (end, grad): (&[f32; K], &[f32; K]),
    n: usize,
) -> u32 {
    let mut bits = 0_u32;
    let depths = end.iter().zip(start).zip(grad).zip(0_u32..).take(n.min(32));
    for (((e, s), &g), j) in depths.skip(1) {
        if returned && g == 0.0 && e.to_bits() != s.to_bits() {
            bits |= 1_u32.checked_shl(j).unwrap_or(0);
        }
    }
    bits
}

/// How close to zero (m) a row's `c` counts as active at the end: the
/// feasibility tolerance, or a hundredth of the band of rows the QP takes.
fn kink_band<const K: usize>(lin: &Linearized<K>, feas_tol: f32) -> f32 {
    let band = if lin.band.is_finite() {
        0.01 * lin.band
    } else {
        0.0
    };
    feas_tol.max(band)
}

/// The state of one SQP run.
struct Run<const K: usize> {
    z: [f32; K],
    lin: Linearized<K>,
    /// The BFGS metric.
    a: Mat<K>,
    /// The merit's penalty weight.
    rho: f32,
    evaluations: u32,
    iterations: u32,
    skipped: u32,
    /// Infeasible iterations in a row that left the merit unmoved.
    stalls: u32,
    /// Restorations made (at most [`RESTORATIONS`]).
    restorations: u32,
    /// Whether the QP also takes the rows beyond the band its step would
    /// cross.
    careful: bool,
    /// Whether the last accepted step was a sliver of the QP's.
    sliver: bool,
}

impl<const K: usize> Run<K> {
    /// The run's end into `out`: point, `J`, gradient (and its norm on
    /// the free variables of `bounds`), `status` and counts.
    fn report(&self, out: &mut Outcome<K>, bounds: &Bounds<K>, status: Status) {
        let z = Vector::from(self.z);
        (out.z, out.j, out.gradient) = (self.z, self.lin.j, self.lin.grad);
        out.grad_norm = bounds.free_gradient_norm_v(&z, &Vector::from(self.lin.grad));
        (out.status, out.iterations) = (status, self.iterations);
        (out.evaluations, out.skipped_updates) = (self.evaluations, self.skipped);
    }

    /// The QP step (`step.rs`); where the QP finds the metric not definite
    /// in f32, the metric is reset to its diagonal and the step solved
    /// again.
    fn qp_step(
        &mut self,
        (bounds, n): (&Bounds<K>, usize),
        max_step: f32,
    ) -> Option<([f32; K], Vec<f32, CONSTRAINTS>, f32)> {
        let (lin, z) = (&self.lin, &self.z);
        let first = step(&self.a, lin, z, (bounds, n), (max_step, self.careful));
        if first.is_some() {
            return first;
        }
        self.a = diagonal(&self.a, n);
        step(&self.a, lin, z, (bounds, n), (max_step, self.careful))
    }

    /// One iteration: the QP step, the line search, the new linearization
    /// and the metric's update; `Some` with the status when the run ends.
    fn iterate<O: Constrained<K>>(
        &mut self,
        obj: &mut O,
        (bounds, n): (&Bounds<K>, usize),
        cfg: &BfgsConfig,
        feas_tol: f32,
    ) -> Option<Status> {
        let stepped = self.qp_step((bounds, n), cfg.max_step);
        let lin = &self.lin;
        let Some((d, lambda, sigma)) = stepped else {
            return Some(Status::LineSearchFailed);
        };
        self.rho = self.rho.max(RHO_FACTOR * largest_group(lin, &lambda));
        let phi = lin.j + self.rho * lin.infeasibility;
        let gd = dot(&lin.grad, &d, n);
        let slope = gd - self.rho * (1.0 - sigma) * lin.infeasibility;
        let feasible = lin.infeasibility <= feas_tol;
        // The QP's model of the decrease of `J` (3.14b's threshold, as
        // BFGS): below it, feasible, the step is not worth a flight.
        let model = -(gd + 0.5 * dot(&d, &mul(&self.a, &d, n), n));
        let longest = d.iter().fold(0.0_f32, |m, v| m.max(libm::fabsf(*v)));
        if feasible && (longest <= STEP_TOL || model <= cfg.tol.j_threshold(lin.j)) {
            return Some(Status::Converged);
        }
        if slope >= 0.0 {
            return Some(if feasible {
                Status::Converged
            } else {
                Status::LineSearchFailed
            });
        }
        let merit = (phi, slope, self.rho);
        let (found, tried) = search(obj, (&self.z, &d), bounds, merit, cfg);
        self.evaluations = self.evaluations.saturating_add(tried);
        let Some((zt, alpha)) = found else {
            // No acceptable step longer than `STEP_TOL`: a feasible point
            // is as good as it gets here.
            return Some(if feasible {
                Status::Converged
            } else {
                Status::LineSearchFailed
            });
        };
        let old = lagrangian_gradient(&self.lin, &lambda);
        if obj.linearize(&zt, false, &mut self.lin).is_err() {
            return Some(Status::LineSearchFailed);
        }
        self.evaluations = self.evaluations.saturating_add(1);
        let new = lagrangian_gradient(&self.lin, &lambda);
        let s: [f32; K] = core::array::from_fn(|i| {
            zt.get(i).copied().unwrap_or(0.0) - self.z.get(i).copied().unwrap_or(0.0)
        });
        let y: [f32; K] = core::array::from_fn(|i| {
            new.get(i).copied().unwrap_or(0.0) - old.get(i).copied().unwrap_or(0.0)
        });
        if !damped_update(&mut self.a, &s, &y, n) {
            self.skipped = self.skipped.saturating_add(1);
        }
        self.z = zt;
        self.iterations = self.iterations.saturating_add(1);
        let lin = &self.lin;
        let phi_new = lin.j + self.rho * lin.infeasibility;
        crate::log::debug!(
            "sqp iteration {=u32}: J {=f32} m3, v {=f32} m, rho {=f32}, alpha {=f32}",
            self.iterations,
            lin.j,
            lin.infeasibility,
            self.rho,
            alpha
        );
        let small = libm::fabsf(phi - phi_new) <= cfg.tol.j_threshold(phi_new);
        self.sliver = alpha < SLIVER;
        self.stop_after(small, feas_tol)
    }

    /// Whether the run ends after a step that changed the merit by less
    /// than the relative tolerance (`small`) or not. Feasible within
    /// `feas_tol` (m): converged (as BFGS's 3.14b), full step or damped (a
    /// damped one near a kink of the constraints' minima would only crawl
    /// on). Infeasible, the merit unmoved [`STALLS`] iterations in a row:
    /// no acceptable step, as far as the run can tell.
    fn stop_after(&mut self, small: bool, feas_tol: f32) -> Option<Status> {
        if small && self.lin.infeasibility <= feas_tol {
            return Some(Status::Converged);
        }
        self.stalls = if small {
            self.stalls.saturating_add(1)
        } else {
            0
        };
        (self.stalls >= STALLS).then_some(Status::LineSearchFailed)
    }
}

impl<const K: usize> Run<K> {
    /// After an iteration that ended the run with `stop`: stuck infeasible
    /// (the line search failed beyond `feas_tol`, m), a restoration step
    /// ([`Run::restore`], an iteration of the cap where one is left), and
    /// the run goes on (`None`); else `stop`.
    fn unstuck<O: Constrained<K>>(
        &mut self,
        obj: &mut O,
        (bounds, n): (&Bounds<K>, usize),
        stop: Option<Status>,
        (feas_tol, cap): (f32, u32),
    ) -> Option<Status> {
        let stuck = stop == Some(Status::LineSearchFailed)
            && self.lin.infeasibility > feas_tol
            && self.restorations < RESTORATIONS
            && self.iterations < cap;
        if !(stuck && self.restore(obj, (bounds, n))) {
            return stop;
        }
        self.restorations = self.restorations.saturating_add(1);
        self.stalls = 0;
        None
    }

    /// Feasibility restoration (N&W §18.4's spirit, without `J`): the
    /// least step in the Euclidean norm onto the linearized constraints,
    /// halved where it makes `v` no smaller and extended along the secant
    /// of `v` to zero where it cuts `v` by less (at most 3 times), until
    /// the infeasibility `v` is at most [`RESTORED`] of what it was (where
    /// the row's gradient overstates its slope, as a depth loop's
    /// conditional integration makes it, the full step falls short); at the
    /// point reached, a new linearization and the Gauss–Newton metric (the
    /// one that failed was built on the other side of a kink). True when
    /// it moved.
    fn restore<O: Constrained<K>>(
        &mut self,
        obj: &mut O,
        (bounds, n): (&Bounds<K>, usize),
    ) -> bool {
        let Some(d) = least_step(&self.lin, &self.z, (bounds, n)) else {
            return false;
        };
        let v0 = self.lin.infeasibility;
        let mut alpha = 1.0_f32;
        for _ in 0..4 {
            let trial: [f32; K] = core::array::from_fn(|i| {
                let (z, d) = (self.z.get(i), d.get(i));
                z.copied().unwrap_or(0.0) + alpha * d.copied().unwrap_or(0.0)
            });
            let zt = bounds.project(&trial);
            self.evaluations = self.evaluations.saturating_add(1);
            match obj.value(&zt) {
                Ok((_, v)) if v <= RESTORED * v0 => {
                    if obj.linearize(&zt, true, &mut self.lin).is_err() {
                        // (Back to where the run stood.)
                        let _ = obj.linearize(&self.z, false, &mut self.lin);
                        return false;
                    }
                    self.evaluations = self.evaluations.saturating_add(1);
                    self.z = zt;
                    self.a = initial_metric(&self.lin.gn, n);
                    self.iterations = self.iterations.saturating_add(1);
                    return true;
                }
                // Progress short of the share: on along the secant of `v`
                // to zero (the linearization underestimated the step).
                Ok((_, v)) if v < v0 => alpha *= (v0 / (v0 - v)).min(SECANT_REACH),
                Ok(_) => alpha *= 0.5,
                Err(_) => return false,
            }
        }
        false
    }
}

/// The restoration's step from `z` (module docs of [`Run::restore`]): the
/// least step in the Euclidean norm onto `lin`'s rows, unrelaxed, in the
/// box. Not inlined: its QP stays off the stack of the flights that follow.
#[inline(never)]
fn least_step<const K: usize>(
    lin: &Linearized<K>,
    z: &[f32; K],
    (bounds, n): (&Bounds<K>, usize),
) -> Option<[f32; K]> {
    let mut unit: Mat<K> = [[0.0; K]; K];
    for i in 0..n {
        put(&mut unit, i, i, 1.0);
    }
    let rows = StepRows::new(lin, (z, bounds, n), (0.0, lin.band));
    let mut sol = QpSolution::default();
    qp::solve(&unit, &[0.0; K], n, &rows, &mut sol).ok()?;
    Some(sol.d)
}

/// The first metric: the Gauss–Newton matrix over the first `n`
/// variables (zero past them).
fn initial_metric<const K: usize>(gn: &Mat<K>, n: usize) -> Mat<K> {
    core::array::from_fn(|i| {
        core::array::from_fn(|j| if i < n && j < n { at(gn, i, j) } else { 0.0 })
    })
}

/// The diagonal of the metric `a` over the first `n` variables, each
/// entry at least a thousandth of their mean: the metric the QP falls back
/// to where `a` is not positive definite in f32. On a random canyon line
/// (`check_planner.py --seed 60606`, `unseen_60606_2`) three saturated
/// dives left the cold call's metric, after one update along nearly
/// dependent depths, with eigenvalues −4e−4 and 1e−4 beside 1.6e3; the run
/// stopped 12 m short of track 1's boundary, the line's `J` 1.16× the
/// best safe plan's.
fn diagonal<const K: usize>(a: &Mat<K>, n: usize) -> Mat<K> {
    let mean = (0..n).fold(0.0, |s, i| s + at(a, i, i).max(0.0)) / (n.max(1) as f32);
    let floor = (1e-3 * mean).max(REGULARIZATION);
    core::array::from_fn(|i| {
        core::array::from_fn(|j| {
            if i == j && i < n {
                at(a, i, i).max(floor)
            } else {
                0.0
            }
        })
    })
}

/// The largest sum of multipliers over one group (groups `0..K`; a row
/// of another group counts alone).
fn largest_group<const K: usize>(lin: &Linearized<K>, lambda: &[f32]) -> f32 {
    let mut sums = [0.0_f32; K];
    let mut best = 0.0_f32;
    for ((_, _, group), &l) in lin.iter().zip(lambda.iter()) {
        match sums.get_mut(usize::from(group)) {
            Some(s) => *s += l,
            None => best = best.max(l),
        }
    }
    sums.iter().fold(best, |b, &s| b.max(s))
}

/// `∇J − Σ λᵢ ∇cᵢ` (the box's rows are linear: they cancel in BFGS's `y`).
fn lagrangian_gradient<const K: usize>(lin: &Linearized<K>, lambda: &[f32]) -> [f32; K] {
    let mut g = lin.grad;
    for ((_, a, _), &l) in lin.iter().zip(lambda.iter()) {
        if l > 0.0 {
            for (gi, ai) in g.iter_mut().zip(a.iter()) {
                *gi -= l * ai;
            }
        }
    }
    g
}

/// Backtracking from the full step on the merit `φ = J + ρ v`: the first
/// point with `φ <= φ₀ + c₁ α slope` and its `α` (`None` when none within
/// the cap, or before the step is shorter than [`STEP_TOL`]), with the
/// flights tried.
fn search<const K: usize, O: Constrained<K>>(
    obj: &mut O,
    (z, d): (&[f32; K], &[f32; K]),
    bounds: &Bounds<K>,
    (phi, slope, rho): (f32, f32, f32),
    cfg: &BfgsConfig,
) -> (Option<([f32; K], f32)>, u32) {
    let mut alpha = 1.0_f32;
    let mut tried = 0_u32;
    for _ in 0..=cfg.armijo.max_backtracks {
        let trial: [f32; K] = core::array::from_fn(|i| {
            z.get(i).copied().unwrap_or(0.0) + alpha * d.get(i).copied().unwrap_or(0.0)
        });
        let zt = bounds.project(&trial);
        // A step this short is no step (nor one pinned by the box).
        let moved = zt
            .iter()
            .zip(z.iter())
            .fold(0.0_f32, |m, (a, b)| m.max(libm::fabsf(a - b)));
        if moved.partial_cmp(&STEP_TOL) != Some(core::cmp::Ordering::Greater) {
            return (None, tried);
        }
        tried = tried.saturating_add(1);
        let merit = match obj.value(&zt) {
            Ok((j, v)) => j + rho * v,
            Err(_) => return (None, tried),
        };
        if merit.is_finite() && merit <= phi + cfg.armijo.c1 * alpha * slope {
            return (Some((zt, alpha)), tried);
        }
        // A safeguarded quadratic through φ₀, the slope and the trial.
        let curvature = merit - phi - alpha * slope;
        let next = if merit.is_finite() && curvature > 0.0 {
            -slope * alpha * alpha / (2.0 * curvature)
        } else {
            0.1 * alpha
        };
        // (Not `clamp`, which asserts its bounds.)
        alpha = next.min(0.5 * alpha).max(0.1 * alpha);
    }
    (None, tried)
}
