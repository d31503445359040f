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
//! Lagrangian `∇J − Σ λᵢ ∇cᵢ`, which keeps it positive definite. A QP whose
//! linearized constraints have no common point is relaxed: each violated
//! constraint is asked for `1 − σ` of its shortfall, `σ` = ½, 0.9, then 1
//! (do not make it worse), which `d = 0` always satisfies.
//!
//! Stops (each with `v` within the feasibility tolerance): the step
//! shorter than [`STEP_TOL`] (m), or the QP's model of the decrease of
//! `J` below the relative tolerance of [`super::Tolerances`] (as BFGS's
//! 3.14b); a full step that changes `φ` by less than that; else the
//! iteration cap, or no acceptable step (`LineSearchFailed`).

use heapless::Vec;
use nalgebra::SMatrix;

use super::qp::{self, QP_ROWS, QpError, Row};
use super::{BfgsConfig, Bounds, OptimError, Outcome, Status, Vector, dot};

/// Most constraint rows an objective gives (the rest of the QP's rows are
/// the box's).
pub(crate) const CONSTRAINTS: usize = 48;

/// A step whose largest component is below this (m) is no step.
pub(crate) const STEP_TOL: f32 = 1e-3;

/// `ρ` is kept at least this many times the largest group's multipliers.
const RHO_FACTOR: f32 = 1.5;

/// Relaxations of an incompatible QP: the share of each shortfall left.
const RELAXATIONS: [f32; 4] = [0.0, 0.5, 0.9, 1.0];

/// Relative regularization of the metric's diagonal in the QP.
const REGULARIZATION: f32 = 1e-6;

/// One constraint `c >= 0` at the point (m), with its gradient (m/m) and
/// its group (for the planner: the track).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Constraint<const K: usize> {
    pub c: f32,
    pub a: [f32; K],
    pub group: u8,
}

/// An objective's linearization at a point.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Linearized<const K: usize> {
    /// `J`, m³.
    pub j: f32,
    /// `∇J`, m².
    pub grad: [f32; K],
    /// ℓ1 infeasibility `v`, m.
    pub infeasibility: f32,
    /// Every constraint, in the same order at every point.
    pub rows: Vec<Constraint<K>, CONSTRAINTS>,
    /// Rows with `c` above this (m) stay out of the QP: too far from
    /// active for their linearization to matter.
    pub band: f32,
    /// The Gauss–Newton matrix of `J` (m), when asked for.
    pub gn: SMatrix<f32, K, K>,
}

impl<const K: usize> Default for Linearized<K> {
    fn default() -> Self {
        Self {
            j: f32::INFINITY,
            grad: [0.0; K],
            infeasibility: 0.0,
            rows: Vec::new(),
            band: f32::INFINITY,
            gn: SMatrix::zeros(),
        }
    }
}

/// A constrained objective.
pub(crate) trait Constrained<const K: usize> {
    /// Why an evaluation failed.
    type Error;
    /// The linearization at `z` into `out` (with the Gauss–Newton matrix
    /// when `gn`).
    ///
    /// # Errors
    /// When the objective cannot be evaluated at `z`.
    fn linearize(
        &mut self,
        z: &[f32; K],
        gn: bool,
        out: &mut Linearized<K>,
    ) -> Result<(), Self::Error>;
    /// `(J, v)` at `z` alone (m³, m).
    ///
    /// # Errors
    /// As [`Constrained::linearize`].
    fn value(&mut self, z: &[f32; K]) -> Result<(f32, f32), Self::Error>;
}

/// Minimizes `obj` over its first `n` variables from `z0` within `bounds`
/// (the others held), feasible within `feas_tol` (m of `v`), by the SQP of
/// the module docs with `cfg`'s iteration cap, tolerances and Armijo
/// constant; the result is written into `out`, `J` at the start and at
/// each iterate appended to `out.history` (not monotone: an early iterate
/// may be infeasible, and lower).
///
/// # Errors
/// [`OptimError`] when the objective fails or is not finite at the start.
pub(crate) fn sqp_into<const K: usize, O: Constrained<K>>(
    obj: &mut O,
    z0: &[f32; K],
    (bounds, n): (&Bounds<K>, usize),
    cfg: &BfgsConfig,
    feas_tol: f32,
    out: &mut Outcome<K>,
) -> Result<(), OptimError<O::Error>> {
    cfg.validate().map_err(OptimError::Config)?;
    if !bounds.is_valid() {
        return Err(OptimError::Config(super::OptimConfigError::Bounds));
    }
    let n = n.min(K);
    let mut z = bounds.project_v(&Vector::from(*z0));
    let mut lin = Linearized::default();
    obj.linearize(&z.into(), true, &mut lin)
        .map_err(OptimError::Start)?;
    if !(lin.j.is_finite() && lin.grad.iter().all(|g| g.is_finite())) {
        return Err(OptimError::NonFinite);
    }
    let mut a = initial_metric(&lin.gn, n);
    let mut rho = 0.0_f32;
    let mut evaluations = 1_u32;
    let mut iterations = 0_u32;
    let mut skipped = 0_u32;
    let _ = out.history.push(lin.j);
    let status = loop {
        if iterations >= cfg.max_iterations {
            break Status::MaxIterations;
        }
        let Some((d, lambda, sigma)) = step(&a, &lin, &z, bounds, n, cfg.max_step) else {
            break Status::LineSearchFailed;
        };
        rho = rho.max(RHO_FACTOR * largest_group(&lin, &lambda));
        let phi = lin.j + rho * lin.infeasibility;
        let g = Vector::from(lin.grad);
        let slope = dot(&g, &d) - rho * (1.0 - sigma) * lin.infeasibility;
        let feasible = lin.infeasibility <= feas_tol;
        // The QP's model of the decrease of `J` (3.14b's threshold, as
        // BFGS): below it, feasible, the step is not worth a flight.
        let model = -(dot(&g, &d) + 0.5 * dot(&d, &(a * d)));
        if feasible && (d.amax() <= STEP_TOL || model <= cfg.tol.j_threshold(lin.j)) {
            break Status::Converged;
        }
        if slope >= 0.0 {
            break if feasible {
                Status::Converged
            } else {
                Status::LineSearchFailed
            };
        }
        let Some((zt, alpha, tried)) = search(obj, (&z, &d), bounds, (phi, slope, rho), cfg) else {
            evaluations = evaluations.saturating_add(cfg.armijo.max_backtracks);
            break Status::LineSearchFailed;
        };
        evaluations = evaluations.saturating_add(tried);
        let old = lagrangian_gradient(&lin, &lambda);
        if obj.linearize(&zt.into(), false, &mut lin).is_err() {
            break Status::LineSearchFailed;
        }
        evaluations = evaluations.saturating_add(1);
        let new = lagrangian_gradient(&lin, &lambda);
        if !update(&mut a, &(zt - z), &(new - old)) {
            skipped = skipped.saturating_add(1);
        }
        z = zt;
        iterations = iterations.saturating_add(1);
        let phi_new = lin.j + rho * lin.infeasibility;
        let _ = out.history.push(lin.j);
        crate::log::debug!(
            "sqp iteration {=u32}: J {=f32} m3, v {=f32} m, rho {=f32}, alpha {=f32}",
            iterations,
            lin.j,
            lin.infeasibility,
            rho,
            alpha
        );
        let small = libm::fabsf(phi - phi_new) <= cfg.tol.j_threshold(phi_new);
        if alpha >= 1.0 && small && lin.infeasibility <= feas_tol {
            break Status::Converged;
        }
    };
    out.z = z.into();
    out.j = lin.j;
    out.gradient = lin.grad;
    out.grad_norm = bounds.free_gradient_norm_v(&z, &Vector::from(lin.grad));
    out.status = status;
    out.iterations = iterations;
    out.evaluations = evaluations;
    out.skipped_updates = skipped;
    Ok(())
}

/// The first metric: the Gauss–Newton matrix over the first `n`
/// variables, the identity on the held ones.
fn initial_metric<const K: usize>(gn: &SMatrix<f32, K, K>, n: usize) -> SMatrix<f32, K, K> {
    SMatrix::from_fn(|i, j| match (i < n, j < n) {
        (true, true) => gn.get((i, j)).copied().unwrap_or(0.0),
        _ if i == j => 1.0,
        _ => 0.0,
    })
}

/// The QP step at `z`: `(d, λ per constraint row, σ)` with the least
/// relaxation `σ` that makes the QP compatible; `None` when none does
/// (the metric not definite).
fn step<const K: usize>(
    a: &SMatrix<f32, K, K>,
    lin: &Linearized<K>,
    z: &Vector<K>,
    bounds: &Bounds<K>,
    n: usize,
    max_step: f32,
) -> Option<(Vector<K>, Vec<f32, CONSTRAINTS>, f32)> {
    let mean = (0..n)
        .map(|i| a.get((i, i)).copied().unwrap_or(0.0))
        .fold(0.0, |s, v| s + v)
        / (n.max(1) as f32);
    let delta = REGULARIZATION * mean.max(0.0) + REGULARIZATION;
    let a_reg = SMatrix::<f32, K, K>::from_fn(|i, j| {
        let v = a.get((i, j)).copied().unwrap_or(0.0);
        if i == j && i < n { v + delta } else { v }
    });
    let g = Vector::<K>::from(lin.grad);
    for &sigma in &RELAXATIONS {
        let (rows, index) = qp_rows(lin, z, bounds, n, sigma);
        match qp::solve(&a_reg, &g, n, &rows) {
            Ok(sol) => {
                let mut lambda: Vec<f32, CONSTRAINTS> = Vec::new();
                for _ in 0..lin.rows.len() {
                    let _ = lambda.push(0.0);
                }
                for (&l, &i) in sol.lambda.iter().zip(index.iter()) {
                    if let Some(slot) = lambda.get_mut(usize::from(i)) {
                        *slot = l;
                    }
                }
                let longest = sol.d.amax();
                let d = if longest > max_step {
                    sol.d * (max_step / longest)
                } else {
                    sol.d
                };
                return Some((d, lambda, sigma));
            }
            Err(QpError::Incompatible | QpError::Iterations) => {}
            Err(QpError::NotDefinite) => return None,
        }
    }
    None
}

/// The QP's rows at relaxation `σ`: the near-active constraints with a
/// gradient (each with its index among the objective's rows), then the
/// box around `z` (index `u8::MAX`).
fn qp_rows<const K: usize>(
    lin: &Linearized<K>,
    z: &Vector<K>,
    bounds: &Bounds<K>,
    n: usize,
    sigma: f32,
) -> (Vec<Row<K>, QP_ROWS>, Vec<u8, QP_ROWS>) {
    let mut rows: Vec<Row<K>, QP_ROWS> = Vec::new();
    let mut index: Vec<u8, QP_ROWS> = Vec::new();
    for (i, r) in lin.rows.iter().enumerate() {
        let moves = r.a.iter().take(n).any(|&v| v != 0.0);
        if !(moves && r.c < lin.band && r.c.is_finite()) {
            continue;
        }
        let c = if r.c < 0.0 { (1.0 - sigma) * r.c } else { r.c };
        if rows.push(Row { a: r.a, c }).is_ok() {
            let _ = index.push(u8::try_from(i).unwrap_or(u8::MAX));
        }
    }
    for i in 0..n {
        let (Some(&zi), Some(&lo), Some(&hi)) = (z.get(i), bounds.lo.get(i), bounds.hi.get(i))
        else {
            continue;
        };
        let mut up = [0.0; K];
        let mut down = [0.0; K];
        if let (Some(u), Some(d)) = (up.get_mut(i), down.get_mut(i)) {
            *u = 1.0;
            *d = -1.0;
        }
        for row in [
            Row { a: up, c: zi - lo },
            Row {
                a: down,
                c: hi - zi,
            },
        ] {
            if rows.push(row).is_ok() {
                let _ = index.push(u8::MAX);
            }
        }
    }
    (rows, index)
}

/// The largest sum of multipliers over one group (groups `0..K`; a row
/// of another group counts alone).
fn largest_group<const K: usize>(lin: &Linearized<K>, lambda: &[f32]) -> f32 {
    let mut sums = [0.0_f32; K];
    let mut best = 0.0_f32;
    for (r, &l) in lin.rows.iter().zip(lambda.iter()) {
        match sums.get_mut(usize::from(r.group)) {
            Some(s) => *s += l,
            None => best = best.max(l),
        }
    }
    sums.iter().fold(best, |b, &s| b.max(s))
}

/// `∇J − Σ λᵢ ∇cᵢ` (the box's rows are linear: they cancel in BFGS's `y`).
fn lagrangian_gradient<const K: usize>(lin: &Linearized<K>, lambda: &[f32]) -> Vector<K> {
    let mut g = Vector::from(lin.grad);
    for (r, &l) in lin.rows.iter().zip(lambda.iter()) {
        if l > 0.0 {
            g -= Vector::from(r.a) * l;
        }
    }
    g
}

/// Backtracking from the full step on the merit `φ = J + ρ v`: the first
/// point with `φ <= φ₀ + c₁ α slope`, with its `α` and the flights tried;
/// `None` when none within the cap.
fn search<const K: usize, O: Constrained<K>>(
    obj: &mut O,
    (z, d): (&Vector<K>, &Vector<K>),
    bounds: &Bounds<K>,
    (phi, slope, rho): (f32, f32, f32),
    cfg: &BfgsConfig,
) -> Option<(Vector<K>, f32, u32)> {
    let mut alpha = 1.0_f32;
    let mut tried = 0_u32;
    for _ in 0..=cfg.armijo.max_backtracks {
        let zt = bounds.project_v(&(z + d * alpha));
        if zt == *z {
            return None;
        }
        tried = tried.saturating_add(1);
        let merit = match obj.value(&zt.into()) {
            Ok((j, v)) => j + rho * v,
            Err(_) => return None,
        };
        if merit.is_finite() && merit <= phi + cfg.armijo.c1 * alpha * slope {
            return Some((zt, alpha, tried));
        }
        // A safeguarded quadratic through φ₀, the slope and the trial.
        let curvature = merit - phi - alpha * slope;
        let next = if merit.is_finite() && curvature > 0.0 {
            -slope * alpha * alpha / (2.0 * curvature)
        } else {
            0.1 * alpha
        };
        alpha = next.clamp(0.1 * alpha, 0.5 * alpha);
    }
    None
}

/// Powell's damped BFGS update of `a` for step `s` and Lagrangian gradient
/// change `y`; returns whether it was made.
fn update<const K: usize>(a: &mut SMatrix<f32, K, K>, s: &Vector<K>, y: &Vector<K>) -> bool {
    let bs = *a * s;
    let sbs = dot(s, &bs);
    let sy = dot(s, y);
    if !(sbs > 0.0 && sbs.is_finite() && sy.is_finite()) {
        return false;
    }
    let theta = if sy >= 0.2 * sbs {
        1.0
    } else {
        0.8 * sbs / (sbs - sy)
    };
    let r = y * theta + bs * (1.0 - theta);
    let sr = dot(s, &r);
    if sr.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
        return false;
    }
    let next = *a + r * (r.transpose() / sr) - bs * (bs.transpose() / sbs);
    if !next.iter().all(|v| v.is_finite()) {
        return false;
    }
    *a = (next + next.transpose()) * 0.5;
    true
}
