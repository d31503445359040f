//! Allocation-free optimizers for the reference depths: gradient descent
//! (the paper's baseline, eq. 3.6) and dense BFGS with an Armijo
//! backtracking line search (eqs. 3.7–3.13), both on a box.
//!
//! The dimension `K` is a const generic; a problem may use fewer variables
//! by pinning the others (`lo == hi` in [`Bounds`]). Non-convergence is an
//! [`Outcome`] with a [`Status`], never an error; only a failed evaluation
//! at the starting point is an error.
//!
//! Every numerical safeguard is named and documented where it acts:
//! the curvature guard and the first-step scaling in [`mod@bfgs`], the
//! backtracking cap in [`mod@armijo`], the step cap in [`BfgsConfig`].

pub mod armijo;
pub(crate) mod best;
pub mod bfgs;
pub(crate) mod constrained;
pub(crate) mod dense;
mod dual;
pub mod gd;
pub(crate) mod qp;
pub(crate) mod root;
mod sliver;
pub(crate) mod sqp;
pub(crate) mod step;
pub(crate) mod vee;

use core::fmt;

use heapless::Vec;
use nalgebra::SVector;

pub use armijo::Armijo;
pub(crate) use armijo::LineSearch;
pub use bfgs::{BfgsConfig, bfgs, bfgs_from};
pub use gd::{GdConfig, gradient_descent};

/// A function to minimize: its value and gradient at a point.
///
/// For the planner the point is a vector of reference depths (m), the
/// value `J` (m³) and the gradient `∂J/∂z` (m²).
pub trait Objective<const K: usize> {
    /// Why an evaluation failed.
    type Error;
    /// Value and gradient at `z`.
    ///
    /// # Errors
    /// When the function cannot be evaluated at `z` (for the planner: the
    /// simulation diverged).
    fn eval(&mut self, z: &[f32; K]) -> Result<(f32, [f32; K]), Self::Error>;

    /// The value alone at `z`, when the objective has a cheaper way to it
    /// than [`Objective::eval`] (for the planner: a flight without the
    /// tangent pass); `None` (the default) when it has not. It must equal
    /// `eval`'s value. The line search tries its trial points with it and
    /// evaluates the gradient only at the point it accepts.
    ///
    /// # Errors
    /// As [`Objective::eval`].
    fn value(&mut self, _z: &[f32; K]) -> Option<Result<f32, Self::Error>> {
        None
    }
}

/// The optimizers' internal vector type; plain arrays at the boundary.
pub(crate) type Vector<const K: usize> = SVector<f32, K>;

/// [`Objective::eval`] on the internal vector type.
pub(crate) fn eval<const K: usize, O: Objective<K>>(
    obj: &mut O,
    z: &Vector<K>,
) -> Result<(f32, Vector<K>), O::Error> {
    let (j, g) = obj.eval(&(*z).into())?;
    Ok((j, Vector::from(g)))
}

/// `aᵀb`, summed in index order whatever `K`: a dimension-independent
/// result (nalgebra unrolls dot products of eight or more entries into
/// partial sums, so a problem padded to a larger `K` would round
/// differently).
pub(crate) fn dot<const K: usize>(a: &Vector<K>, b: &Vector<K>) -> f32 {
    a.iter().zip(b.iter()).fold(0.0, |s, (x, y)| s + x * y)
}

/// `‖a‖₂`, as [`dot`].
pub(crate) fn norm<const K: usize>(a: &Vector<K>) -> f32 {
    libm::sqrtf(dot(a, a))
}

/// Box constraint `lo <= z <= hi`, enforced by projection (clamping) of
/// every trial point. A variable with `lo == hi` is pinned.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Bounds<const K: usize> {
    /// Lower bounds.
    pub lo: [f32; K],
    /// Upper bounds.
    pub hi: [f32; K],
}

impl<const K: usize> Bounds<K> {
    /// The same interval `[lo, hi]` for every variable.
    pub fn uniform(lo: f32, hi: f32) -> Self {
        Self {
            lo: [lo; K],
            hi: [hi; K],
        }
    }

    /// `z` clamped into the box.
    pub fn project(&self, z: &[f32; K]) -> [f32; K] {
        self.project_v(&Vector::from(*z)).into()
    }

    pub(crate) fn project_v(&self, z: &Vector<K>) -> Vector<K> {
        Vector::from_fn(|i, _| {
            let v = z.get(i).copied().unwrap_or(0.0);
            match (self.lo.get(i), self.hi.get(i)) {
                (Some(&lo), Some(&hi)) => v.max(lo).min(hi),
                _ => v,
            }
        })
    }

    /// Whether variable `i` can move in the direction `-g[i]`: neither
    /// pinned nor pushed against the bound it sits on.
    pub(crate) fn free(&self, z: &Vector<K>, g: &Vector<K>, i: usize) -> bool {
        let (Some(&v), Some(&lo), Some(&hi), Some(&gi)) =
            (z.get(i), self.lo.get(i), self.hi.get(i), g.get(i))
        else {
            return false;
        };
        lo < hi && !(v <= lo && gi > 0.0) && !(v >= hi && gi < 0.0)
    }

    /// The gradient with the components of non-free variables zeroed:
    /// its norm is the projected-gradient stopping measure.
    pub(crate) fn free_gradient(&self, z: &Vector<K>, g: &Vector<K>) -> Vector<K> {
        Vector::from_fn(|i, _| {
            if self.free(z, g, i) {
                g.get(i).copied().unwrap_or(0.0)
            } else {
                0.0
            }
        })
    }

    /// The norm of the free gradient, computed without overflow (scaled
    /// by its largest component): finite for any finite gradient.
    pub fn free_gradient_norm(&self, z: &[f32; K], g: &[f32; K]) -> f32 {
        self.free_gradient_norm_v(&Vector::from(*z), &Vector::from(*g))
    }

    pub(crate) fn free_gradient_norm_v(&self, z: &Vector<K>, g: &Vector<K>) -> f32 {
        let f = self.free_gradient(z, g);
        let m = f.amax();
        if m > 0.0 && m.is_finite() {
            m * norm(&(f / m))
        } else {
            norm(&f)
        }
    }

    /// `true` when every bound is finite and `lo <= hi`.
    pub fn is_valid(&self) -> bool {
        self.lo
            .iter()
            .zip(self.hi.iter())
            .all(|(l, h)| l.is_finite() && h.is_finite() && l <= h)
    }
}

/// Why an optimizer stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Status {
    /// A stopping rule held (paper 3.14a or 3.14b, see [`Tolerances`]).
    Converged,
    /// The iteration cap was reached first.
    MaxIterations,
    /// No step along the search direction decreased the objective enough
    /// within the backtracking cap, or two steps in a row were slivers of
    /// theirs (BFGS, module docs of `bfgs`), or an evaluation failed (GD).
    LineSearchFailed,
}

impl Status {
    /// The name the host tool prints.
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::Converged => "converged",
            Self::MaxIterations => "max_iterations",
            Self::LineSearchFailed => "line_search_failed",
        }
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Stopping rules, paper eq. 3.14 made scale-aware:
/// - (a) `‖G‖ <= grad` on the free variables (`GᵀG <= ε1` with
///   `ε1 = grad²`), m²;
/// - (b) `|J_{i+1} − J_i| <= rel · max(|J_i|, floor)`; BFGS also stops
///   before a step when its quadratic model predicts a decrease
///   `−½ Gᵀs` below that same threshold (the step would be wasted).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Tolerances {
    /// Gradient norm, m² (objective m³ per m of depth).
    pub grad: f32,
    /// Relative change of the objective.
    pub rel: f32,
    /// Objective floor for the relative test, m³.
    pub floor: f32,
}

impl Default for Tolerances {
    fn default() -> Self {
        Self {
            grad: 1e-3,
            rel: 1e-5,
            floor: 1.0,
        }
    }
}

impl Tolerances {
    /// The 3.14b threshold at objective value `j`.
    pub fn j_threshold(&self, j: f32) -> f32 {
        self.rel * libm::fabsf(j).max(self.floor)
    }

    fn is_valid(&self) -> bool {
        self.grad.is_finite()
            && self.grad >= 0.0
            && self.rel.is_finite()
            && self.rel >= 0.0
            && self.floor.is_finite()
            && self.floor > 0.0
    }
}

/// An outcome's first coordinate in a box ([`Outcome::first_in`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct First {
    /// The coordinate (unit of the variable: m for a depth).
    pub z: f32,
    /// The gradient's entry there (objective unit per variable unit).
    pub g: f32,
    /// The box's bounds on it (unit of the variable).
    pub lo: f32,
    pub hi: f32,
}

/// How many objective values an [`Outcome`] keeps (the first ones).
pub const HISTORY: usize = 256;

/// Result of an optimization: where it stopped, why, and what it cost.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Outcome<const K: usize> {
    /// The last accepted point.
    pub z: [f32; K],
    /// Objective there.
    pub j: f32,
    /// Gradient there.
    pub gradient: [f32; K],
    /// Norm of the gradient on the free variables.
    pub grad_norm: f32,
    /// Why it stopped.
    pub status: Status,
    /// Iterations taken (accepted steps).
    pub iterations: u32,
    /// Objective-and-gradient evaluations, the start included.
    pub evaluations: u32,
    /// BFGS updates skipped by the curvature guard.
    pub skipped_updates: u32,
    /// The objective at the start and after each iteration (the first
    /// [`HISTORY`] values).
    pub history: Vec<f32, HISTORY>,
}

impl<const K: usize> Outcome<K> {
    /// An outcome that has not run: at `z`, no history, `J = +inf`.
    pub(crate) fn at(z: &[f32; K]) -> Self {
        Self {
            z: *z,
            j: f32::INFINITY,
            gradient: [0.0; K],
            grad_norm: 0.0,
            status: Status::Converged,
            iterations: 0,
            evaluations: 0,
            skipped_updates: 0,
            history: Vec::new(),
        }
    }

    /// Where this outcome stands, for [`Outcome::restore`] to put back
    /// after a run that is not kept.
    pub(crate) fn mark(&self) -> Mark<K> {
        Mark {
            z: self.z,
            j: self.j,
            gradient: self.gradient,
            grad_norm: self.grad_norm,
            status: self.status,
            counts: (self.iterations, self.evaluations, self.skipped_updates),
            history: self.history.len(),
        }
    }

    /// Back to `mark`: every field as it was, the history truncated back
    /// to its length then (a run not kept leaves no trace).
    pub(crate) fn restore(&mut self, mark: &Mark<K>) {
        (self.z, self.j, self.gradient) = (mark.z, mark.j, mark.gradient);
        (self.grad_norm, self.status) = (mark.grad_norm, mark.status);
        (self.iterations, self.evaluations, self.skipped_updates) = mark.counts;
        self.history.truncate(mark.history);
    }

    /// How much the objective fell in the last step its history holds
    /// (0 with fewer than two values), in the objective's unit.
    pub(crate) fn last_fall(&self) -> f32 {
        match self.history.as_slice() {
            [.., a, b] => a - b,
            _ => 0.0,
        }
    }

    /// The first coordinate in `bounds` (a single track's depth, or a
    /// horizon's committed one): its value, the gradient's entry and the
    /// box's bounds on it, if `K > 0`.
    pub(crate) fn first_in(&self, bounds: &Bounds<K>) -> Option<First> {
        Some(First {
            z: *self.z.first()?,
            g: *self.gradient.first()?,
            lo: *bounds.lo.first()?,
            hi: *bounds.hi.first()?,
        })
    }

    /// This outcome made [`Outcome::at`] `z` in place (no temporary of
    /// the history's size on the stack).
    pub(crate) fn reset_at(&mut self, z: &[f32; K]) {
        self.z = *z;
        self.j = f32::INFINITY;
        self.gradient = [0.0; K];
        self.grad_norm = 0.0;
        self.status = Status::Converged;
        self.iterations = 0;
        self.evaluations = 0;
        self.skipped_updates = 0;
        self.history.clear();
    }
}

/// An [`Outcome`] as it stood ([`Outcome::mark`]), its history by length.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Mark<const K: usize> {
    z: [f32; K],
    /// The objective then.
    pub(crate) j: f32,
    gradient: [f32; K],
    grad_norm: f32,
    status: Status,
    /// Iterations, evaluations, skipped updates.
    counts: (u32, u32, u32),
    history: usize,
}

/// An optimizer setting out of range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum OptimConfigError {
    /// `max_iterations` is 0.
    MaxIterations,
    /// `first_step` is not finite and positive (m).
    FirstStep,
    /// `max_step` is not finite and positive (m).
    MaxStep,
    /// A stopping tolerance is not finite and non-negative (the floor
    /// positive).
    Tolerances,
    /// `armijo.c1` is not in (0, 1).
    ArmijoC1,
    /// `armijo.shrink` is not in (0, 1).
    ArmijoShrink,
    /// `armijo.max_backtracks` is 0.
    ArmijoBacktracks,
    /// The GD learning rate is not finite and positive (1/m).
    GdRate,
    /// A bound is not finite, or `lo > hi`.
    Bounds,
}

impl OptimConfigError {
    /// The setting's name, as the host tool's config file spells it.
    pub fn name(&self) -> &'static str {
        match self {
            Self::MaxIterations => "max_iterations",
            Self::FirstStep => "first_step",
            Self::MaxStep => "max_step",
            Self::Tolerances => "tolerances",
            Self::ArmijoC1 => "armijo.c1",
            Self::ArmijoShrink => "armijo.shrink",
            Self::ArmijoBacktracks => "armijo.max_backtracks",
            Self::GdRate => "gd_rate",
            Self::Bounds => "bounds",
        }
    }
}

impl fmt::Display for OptimConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "optimizer setting {} is out of range", self.name())
    }
}

impl core::error::Error for OptimConfigError {}

/// Why an optimizer could not start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum OptimError<E> {
    /// A configuration value is out of range.
    Config(OptimConfigError),
    /// The objective could not be evaluated at the starting point.
    Start(E),
    /// The objective or gradient at the starting point is not finite.
    NonFinite,
}

impl<E: fmt::Display> fmt::Display for OptimError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Config(p) => p.fmt(f),
            Self::Start(e) => write!(f, "objective failed at the start: {e}"),
            Self::NonFinite => f.write_str("objective not finite at the start"),
        }
    }
}

impl<E: fmt::Debug + fmt::Display> core::error::Error for OptimError<E> {}

/// Evaluates at the start point, checking finiteness.
fn start<const K: usize, O: Objective<K>>(
    obj: &mut O,
    z: &Vector<K>,
) -> Result<(f32, Vector<K>), OptimError<O::Error>> {
    let (j, g) = eval(obj, z).map_err(OptimError::Start)?;
    if j.is_finite() && g.iter().all(|v| v.is_finite()) {
        Ok((j, g))
    } else {
        Err(OptimError::NonFinite)
    }
}

#[cfg(test)]
pub(crate) mod testfns {
    //! Test functions shared by the optimizer tests.
    use super::Objective;
    use nalgebra::{SMatrix, SVector};

    /// Rosenbrock's function, minimum 0 at (1, 1).
    pub struct Rosenbrock {
        pub evals: u32,
    }
    impl Objective<2> for Rosenbrock {
        type Error = ();
        fn eval(&mut self, z: &[f32; 2]) -> Result<(f32, [f32; 2]), ()> {
            self.evals += 1;
            let (x, y) = (z[0], z[1]);
            let j = (1.0 - x) * (1.0 - x) + 100.0 * (y - x * x) * (y - x * x);
            let g = [
                -2.0 * (1.0 - x) - 400.0 * x * (y - x * x),
                200.0 * (y - x * x),
            ];
            Ok((j, g))
        }
    }

    /// `½ zᵀ H z − bᵀ z`.
    pub struct Quadratic<const K: usize> {
        pub h: SMatrix<f32, K, K>,
        pub b: SVector<f32, K>,
    }
    impl<const K: usize> Objective<K> for Quadratic<K> {
        type Error = ();
        fn eval(&mut self, z: &[f32; K]) -> Result<(f32, [f32; K]), ()> {
            let z = SVector::from(*z);
            let hz = self.h * z;
            Ok((0.5 * z.dot(&hz) - self.b.dot(&z), (hz - self.b).into()))
        }
    }
}
