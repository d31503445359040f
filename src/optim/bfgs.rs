//! Dense BFGS on the paper's metric `A` (eqs. 3.7–3.13).
//!
//! Each iteration solves `A_i s_i = −G_i` for the direction (a Cholesky
//! solve, eq. 3.7), finds a step `α_i` by the line search (Armijo, eq. 3.8
//! with `J` for the paper's `G`), moves `Δζ = α_i s_i` (3.9) and updates
//!
//! ```text
//! Y = G_{i+1} − G_i,   A_{i+1} = A_i + Y Yᵀ / (Yᵀ Δζ) + G_i G_iᵀ / (G_iᵀ s_i)   (3.10–3.13)
//! ```
//!
//! The update is computed in the equivalent general form
//! `A + Y Yᵀ/(YᵀΔζ) − (A Δζ)(A Δζ)ᵀ/(Δζᵀ A Δζ)`, which equals the paper's
//! whenever `A s = −G` holds for the step taken (then `A Δζ = −α G`) and
//! stays the correct BFGS update when the box clips the step or the metric
//! was rescaled. A unit test checks the two forms agree.
//!
//! Safeguards, each named:
//! - **curvature guard**: the update is skipped when `Yᵀ Δζ <= 0` (the
//!   paper's rule; in f32 with a relative tolerance, `Yᵀ Δζ <= 1e-6 ‖Y‖‖Δζ‖`,
//!   since rounding alone can make a vanishing `Yᵀ Δζ` positive), which
//!   keeps `A` symmetric positive definite (N&W §6.1);
//! - **first step**: `A_0 = (‖G_0‖ / first_step) I`, so the first trial
//!   step is `first_step` metres long instead of `‖G‖` metres (thousands,
//!   for `J` in m³); before the first update `A` is rescaled to
//!   `(YᵀY / YᵀΔζ) I` (N&W eq. 6.20) so its scale follows the curvature
//!   actually measured;
//! - **step cap**: a direction longer than `max_step` (∞-norm) is shortened;
//! - **box**: variables pinned or pushed against their bound are held
//!   (their rows and columns of `A` are replaced by the identity in the
//!   solve), and every trial point is projected on the box;
//! - **reset**: if the Cholesky solve fails or does not give a descent
//!   direction (only possible through rounding), `A` is reset to the
//!   scaled identity;
//! - **negative curvature**: where the curvature guard skips the update
//!   after a full step (`Yᵀ Δζ <= 0`: `J` falls at least linearly along
//!   it, and the quadratic model has no minimum that way), `A` is halved,
//!   so that the next step is twice as long for the same gradient: a metric
//!   stuck at a short first step otherwise walks down a concave stretch in
//!   steps that grow only with the gradient (17 iterations of 0.3 to 2.8 m
//!   on `check_planner.py --seed 1404 --vehicle
//!   tools/reference/vehicles/second.toml`, `unseen_1404_5` track 2);
//! - **slivers**: two steps in a row that the line search cut to a
//!   sliver of the direction, or that crawl, end the run
//!   ([`Status::LineSearchFailed`]): `J` is not smooth at the step's scale
//!   (`optim/sliver.rs`);
//! - **vee**: with one free variable, after a line search that
//!   backtracked, the step is capped where the tangent at the point meets
//!   the secant through the last two rejected trials beyond it, the
//!   estimate of a kink at the minimum that every longer first trial
//!   overshoots (`optim/vee.rs`).

use nalgebra::SMatrix;

use super::sliver::Slivers;
use super::vee::Vee;
use super::{
    Armijo, Bounds, LineSearch, Objective, OptimConfigError, OptimError, Outcome, Status,
    Tolerances, Vector, dot, norm, start,
};

/// Relative tolerance of the curvature guard (see the module docs).
const CURVATURE_TOL: f32 = 1e-6;

/// A step at least this share of the direction is the full step (the box
/// may clip it by rounding).
const FULL: f32 = 0.999;

/// BFGS settings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BfgsConfig {
    /// Iteration cap, ≥ 1. Default 200 (paper §5.3.2).
    pub max_iterations: u32,
    /// Length of the first trial step, m (> 0). Default 10.
    pub first_step: f32,
    /// Longest trial step (∞-norm), m (> 0). Default 500.
    pub max_step: f32,
    /// Line search settings.
    pub armijo: Armijo,
    /// Stopping rules.
    pub tol: Tolerances,
}

impl Default for BfgsConfig {
    fn default() -> Self {
        Self {
            max_iterations: 200,
            first_step: 10.0,
            max_step: 500.0,
            armijo: Armijo::default(),
            tol: Tolerances::default(),
        }
    }
}

impl BfgsConfig {
    /// `Ok` when every setting is in range, else the first that is not.
    ///
    /// # Errors
    /// [`OptimConfigError`] naming it.
    pub fn validate(&self) -> Result<(), OptimConfigError> {
        if self.max_iterations == 0 {
            return Err(OptimConfigError::MaxIterations);
        }
        if !(self.first_step.is_finite() && self.first_step > 0.0) {
            return Err(OptimConfigError::FirstStep);
        }
        if !(self.max_step.is_finite() && self.max_step > 0.0) {
            return Err(OptimConfigError::MaxStep);
        }
        if !self.tol.is_valid() {
            return Err(OptimConfigError::Tolerances);
        }
        self.armijo.validate()
    }
}

/// Minimizes `obj` from `z0` within `bounds` by BFGS with the Armijo line
/// search of `cfg`.
///
/// # Errors
/// [`OptimError`] for an invalid configuration or box, or when the
/// objective fails or is not finite at the (projected) start.
pub fn bfgs<const K: usize, O: Objective<K>>(
    obj: &mut O,
    z0: &[f32; K],
    bounds: &Bounds<K>,
    cfg: &BfgsConfig,
) -> Result<Outcome<K>, OptimError<O::Error>> {
    bfgs_from(obj, z0, bounds, cfg, &[0.0; K])
}

/// [`bfgs`] with another line search (tests use an exact one).
#[cfg(test)]
pub(crate) fn bfgs_with<const K: usize, O: Objective<K>, L: LineSearch<K>>(
    obj: &mut O,
    z0: &[f32; K],
    bounds: &Bounds<K>,
    cfg: &BfgsConfig,
    line_search: &L,
) -> Result<Outcome<K>, OptimError<O::Error>> {
    fresh(obj, z0, bounds, cfg, line_search, &[0.0; K])
}

/// [`bfgs`] from a known diagonal curvature: `A_0 = diag(curvature)`
/// where an entry is positive (m³/m², e.g. from a parabola through scanned
/// values), the first-step scaling elsewhere. An informed metric is not
/// rescaled before the first update.
///
/// # Errors
/// As [`bfgs`].
pub fn bfgs_from<const K: usize, O: Objective<K>>(
    obj: &mut O,
    z0: &[f32; K],
    bounds: &Bounds<K>,
    cfg: &BfgsConfig,
    curvature: &[f32; K],
) -> Result<Outcome<K>, OptimError<O::Error>> {
    fresh(obj, z0, bounds, cfg, &cfg.armijo, curvature)
}

/// One run into a fresh [`Outcome`].
fn fresh<const K: usize, O: Objective<K>, L: LineSearch<K>>(
    obj: &mut O,
    z0: &[f32; K],
    bounds: &Bounds<K>,
    cfg: &BfgsConfig,
    line_search: &L,
    curvature: &[f32; K],
) -> Result<Outcome<K>, OptimError<O::Error>> {
    let mut out = Outcome::at(z0);
    bfgs_into(
        obj,
        z0,
        bounds,
        cfg,
        line_search,
        curvature,
        &mut out,
        false,
    )?;
    Ok(out)
}

/// [`bfgs_from`] writing its result into `out` in place, its objective
/// values appended to `out.history` (all of them, or all but the start's
/// with `continued`): a caller that chains runs keeps one history, not a
/// copy per run on the stack.
#[allow(clippy::too_many_arguments)]
pub(crate) fn bfgs_into<const K: usize, O: Objective<K>, L: LineSearch<K>>(
    obj: &mut O,
    z0: &[f32; K],
    bounds: &Bounds<K>,
    cfg: &BfgsConfig,
    line_search: &L,
    curvature: &[f32; K],
    out: &mut Outcome<K>,
    continued: bool,
) -> Result<(), OptimError<O::Error>> {
    cfg.validate().map_err(OptimError::Config)?;
    let curvature = Vector::from(*curvature);
    let informed = curvature.iter().any(|&c| c.is_finite() && c > 0.0);
    if !bounds.is_valid() {
        return Err(OptimError::Config(OptimConfigError::Bounds));
    }
    let mut z = bounds.project_v(&Vector::from(*z0));
    let (mut j, mut g) = start(obj, &z)?;
    let mut evaluations = 1_u32;
    let history = &mut out.history;
    if !continued {
        let _ = history.push(j);
    }
    let mut metric: Option<SMatrix<f32, K, K>> = None;
    let mut rescaled = informed;
    let mut skipped_updates = 0_u32;
    let mut iterations = 0_u32;
    let mut slivers = Slivers::default();
    let mut vee = Vee::default();

    let status = loop {
        let grad_norm = bounds.free_gradient_norm_v(&z, &g);
        // Stopping rule 3.14a.
        if grad_norm <= cfg.tol.grad {
            break Status::Converged;
        }
        if iterations >= cfg.max_iterations {
            break Status::MaxIterations;
        }
        let identity = SMatrix::<f32, K, K>::identity() * (grad_norm / cfg.first_step);
        let scaled = grad_norm / cfg.first_step;
        let initial = SMatrix::<f32, K, K>::from_diagonal(
            &curvature.map(|c| if c.is_finite() && c > 0.0 { c } else { scaled }),
        );
        let a = metric.get_or_insert(initial);
        let dir = match direction(a, bounds, &z, &g) {
            Some(d) => d,
            None => {
                // Reset: rounding broke the metric.
                *a = identity;
                rescaled = false;
                match direction(a, bounds, &z, &g) {
                    Some(d) => d,
                    None => break Status::LineSearchFailed,
                }
            }
        };
        let longest = dir.amax();
        let dir = if longest > cfg.max_step {
            dir * (cfg.max_step / longest)
        } else {
            dir
        };
        let dir = vee.cap((&z, j, &g), dir);
        // Model-predicted decrease below the 3.14b threshold: converged
        // without spending an evaluation on a step that cannot matter.
        if -0.5 * dot(&g, &dir) <= cfg.tol.j_threshold(j) {
            break Status::Converged;
        }
        let Some(t) = line_search.search(obj, bounds, &z, j, &g, &dir, &mut evaluations) else {
            break Status::LineSearchFailed;
        };
        vee.record((&t.z, &t.g), &dir, t.rejected.as_ref());
        let dz = t.z - z;
        let y = t.g - g;
        let yd = dot(&y, &dz);
        // The step's length and the direction's, m.
        let (step, along) = (norm(&dz), norm(&dir));
        // Curvature guard: only a positive Yᵀ Δζ keeps A positive definite.
        if yd > CURVATURE_TOL * norm(&y) * step {
            if !rescaled {
                *a = SMatrix::identity() * (dot(&y, &y) / yd);
                rescaled = true;
            }
            update(a, &dz, &y, yd);
        } else {
            skipped_updates = skipped_updates.saturating_add(1);
            // Negative curvature along a full step: the next one twice as
            // long (module docs).
            if step >= FULL * along {
                *a *= 0.5;
            }
        }
        let dj = j - t.j;
        slivers.record((step, along), (dj, cfg.tol.j_threshold(t.j)));
        z = t.z;
        j = t.j;
        g = t.g;
        iterations = iterations.saturating_add(1);
        let _ = history.push(j);
        crate::log::debug!(
            "bfgs iteration {=u32}: J {=f32} m3, |G| {=f32} m2, step {=f32} m, evaluations {=u32}",
            iterations,
            j,
            norm(&g),
            step,
            evaluations
        );
        // Stopping rule 3.14b.
        if libm::fabsf(dj) <= cfg.tol.j_threshold(j) {
            break Status::Converged;
        }
        if slivers.end() {
            break Status::LineSearchFailed;
        }
    };
    out.grad_norm = bounds.free_gradient_norm_v(&z, &g);
    out.z = z.into();
    out.j = j;
    out.gradient = g.into();
    out.status = status;
    out.iterations = iterations;
    out.evaluations = evaluations;
    out.skipped_updates = skipped_updates;
    Ok(())
}

/// The BFGS update of `a` for step `dz` and gradient change `y`
/// (`yd = yᵀ dz > 0`), in the general form (see the module docs).
fn update<const K: usize>(a: &mut SMatrix<f32, K, K>, dz: &Vector<K>, y: &Vector<K>, yd: f32) {
    let ad = *a * dz;
    let dad = dot(dz, &ad);
    if dad > 0.0 {
        *a += y * (y.transpose() / yd) - ad * (ad.transpose() / dad);
        // Keep it exactly symmetric against rounding.
        *a = (*a + a.transpose()) * 0.5;
    }
}

/// Solves `A s = −G` over the free variables (Cholesky); `None` when no
/// variable is free, the factorization fails, or `s` is not a descent
/// direction.
fn direction<const K: usize>(
    a: &SMatrix<f32, K, K>,
    bounds: &Bounds<K>,
    z: &Vector<K>,
    g: &Vector<K>,
) -> Option<Vector<K>> {
    let mut m = *a;
    let mut rhs = -g;
    let mut any_free = false;
    for i in 0..K {
        if bounds.free(z, g, i) {
            any_free = true;
        } else {
            m.set_row(i, &nalgebra::RowSVector::zeros());
            m.set_column(i, &Vector::zeros());
            if let Some(v) = m.get_mut((i, i)) {
                *v = 1.0;
            }
            if let Some(v) = rhs.get_mut(i) {
                *v = 0.0;
            }
        }
    }
    if !any_free {
        return None;
    }
    let s = m.cholesky()?.solve(&rhs);
    (s.iter().all(|v| v.is_finite()) && dot(g, &s) < 0.0).then_some(s)
}

#[cfg(test)]
mod tests {
    use super::super::armijo::{LineSearch, Trial};
    use super::super::testfns::{Quadratic, Rosenbrock};
    use super::*;
    use nalgebra::{Matrix3, SVector, Vector3};

    #[test]
    fn rosenbrock_from_the_classic_start() {
        let mut f = Rosenbrock { evals: 0 };
        let cfg = BfgsConfig {
            first_step: 0.1,
            tol: Tolerances {
                grad: 1e-5,
                rel: 0.0,
                floor: 1.0,
            },
            ..BfgsConfig::default()
        };
        let out = bfgs(&mut f, &[-1.2, 1.0], &Bounds::uniform(-5.0, 5.0), &cfg).unwrap();
        assert!((out.z[0] - 1.0).abs() < 1e-4, "{out:?}");
        assert!((out.z[1] - 1.0).abs() < 1e-4, "{out:?}");
        assert!(out.iterations < 100, "{}", out.iterations);
        assert_eq!(out.evaluations, f.evals);
    }

    /// Exact line search for a quadratic: `α = −Gᵀs / sᵀHs`.
    struct Exact(Matrix3<f32>);
    impl LineSearch<3> for Exact {
        fn search<O: Objective<3>>(
            &self,
            obj: &mut O,
            _: &Bounds<3>,
            z: &Vector<3>,
            _: f32,
            g: &Vector<3>,
            dir: &Vector<3>,
            evals: &mut u32,
        ) -> Option<Trial<3>> {
            let alpha = -g.dot(dir) / dir.dot(&(self.0 * dir));
            let zt = z + dir * alpha;
            *evals += 1;
            let (j, g) = obj.eval(&zt.into()).ok()?;
            Some(Trial {
                z: zt,
                j,
                g: SVector::from(g),
                rejected: None,
            })
        }
    }

    #[test]
    fn convex_quadratic_in_at_most_n_plus_1_iterations() {
        let h = Matrix3::new(4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0);
        let b = Vector3::new(1.0, -2.0, 3.0);
        let want = h.cholesky().unwrap().solve(&b);
        let mut q = Quadratic { h, b };
        let cfg = BfgsConfig {
            first_step: 1.0,
            tol: Tolerances {
                grad: 1e-4,
                rel: 0.0,
                floor: 1.0,
            },
            ..BfgsConfig::default()
        };
        let out = bfgs_with(
            &mut q,
            &[0.0; 3],
            &Bounds::uniform(-100.0, 100.0),
            &cfg,
            &Exact(h),
        )
        .unwrap();
        assert_eq!(out.status, Status::Converged);
        assert!(out.iterations <= 4, "{} iterations", out.iterations);
        let z = SVector::from(out.z);
        assert!((z - want).amax() < 1e-4, "{z} vs {want}");
    }

    #[test]
    fn paper_update_equals_general_form() {
        // With A s = -G and Δζ = α s, the paper's 3.13 and the general form agree.
        let a = Matrix3::new(3.0, 0.4, 0.1, 0.4, 2.0, 0.3, 0.1, 0.3, 1.5);
        let g = Vector3::new(1.0, -2.0, 0.5);
        let s = a.cholesky().unwrap().solve(&(-g));
        let alpha = 0.7;
        let dz = s * alpha;
        let h = Matrix3::new(2.0, 0.3, 0.0, 0.3, 1.0, 0.1, 0.0, 0.1, 4.0);
        let y = h * dz;
        let yd = y.dot(&dz);
        assert!(yd > 0.0);
        let paper = a + y * y.transpose() / yd + g * g.transpose() / g.dot(&s);
        let mut general = a;
        update(&mut general, &dz, &y, yd);
        assert!((paper - general).amax() < 1e-5, "{paper} vs {general}");
    }

    #[test]
    fn metric_stays_symmetric_positive_definite() {
        // Secant pairs of an SPD Hessian with 5 % noise, plus pairs of
        // negative curvature that the guard must skip.
        let h = Matrix3::new(50.0, 3.0, -1.0, 3.0, 8.0, 0.5, -1.0, 0.5, 0.7);
        let mut a = Matrix3::identity();
        let mut seed = 12345_u32;
        let mut rnd = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1 << 24) as f32 - 0.5
        };
        let mut skipped = 0;
        for k in 0..300 {
            let dz = Vector3::new(rnd(), rnd(), rnd());
            let noise = Vector3::new(rnd(), rnd(), rnd()) * (0.05 * (h * dz).norm());
            let y = if k % 7 == 0 {
                -(h * dz)
            } else {
                h * dz + noise
            };
            let yd = y.dot(&dz);
            if yd > CURVATURE_TOL * y.norm() * dz.norm() {
                update(&mut a, &dz, &y, yd);
            } else {
                skipped += 1;
            }
            assert_eq!(a, a.transpose());
            assert!(
                a.cholesky().is_some(),
                "lost positive definiteness at {k}: {a}"
            );
        }
        assert!(skipped >= 40);
        // And the metric learned the curvature.
        assert!((a - h).amax() / h.amax() < 0.2, "{a}");
    }

    #[test]
    fn respects_the_box() {
        // Minimum of the quadratic at z = (1, -2/3...); box keeps z0 <= 0.
        let h = Matrix3::identity();
        let b = Vector3::new(1.0, -2.0, 3.0);
        let mut q = Quadratic { h, b };
        let bounds = Bounds {
            lo: [-10.0, -1.0, 3.0],
            hi: [0.0, 10.0, 3.0],
        };
        let out = bfgs(&mut q, &[-5.0, 5.0, 3.0], &bounds, &BfgsConfig::default()).unwrap();
        assert_eq!(out.status, Status::Converged);
        assert!(
            (SVector::from(out.z) - Vector3::new(0.0, -1.0, 3.0)).amax() < 1e-3,
            "{:?}",
            out.z
        );
    }

    #[test]
    fn first_step_is_not_thousands_of_metres() {
        // A steep objective: ‖G‖ = 2e4 at the start.
        let h = Matrix3::identity() * 100.0;
        let b = Vector3::zeros();
        struct Spy(Quadratic<3>, heapless::Vec<f32, 64>);
        impl Objective<3> for Spy {
            type Error = ();
            fn eval(&mut self, z: &[f32; 3]) -> Result<(f32, [f32; 3]), ()> {
                let _ = self.1.push(SVector::from(*z).norm());
                self.0.eval(z)
            }
        }
        let mut spy = Spy(Quadratic { h, b }, heapless::Vec::new());
        let z0 = [200.0, 0.0, 0.0];
        let cfg = BfgsConfig::default();
        bfgs(&mut spy, &z0, &Bounds::uniform(-1e4, 1e4), &cfg).unwrap();
        // The first trial moved exactly first_step = 10 m.
        assert!((spy.1[1] - 190.0).abs() < 1e-3, "{:?}", spy.1);
    }

    #[test]
    fn rejects_bad_config() {
        let mut q = Quadratic {
            h: Matrix3::identity(),
            b: Vector3::zeros(),
        };
        let z = [0.0; 3];
        let b = Bounds::uniform(-1.0, 1.0);
        let cfg = BfgsConfig {
            max_iterations: 0,
            ..BfgsConfig::default()
        };
        assert_eq!(
            bfgs(&mut q, &z, &b, &cfg).unwrap_err(),
            OptimError::Config(OptimConfigError::MaxIterations)
        );
        let cfg = BfgsConfig {
            first_step: f32::NAN,
            ..BfgsConfig::default()
        };
        assert_eq!(
            bfgs(&mut q, &z, &b, &cfg).unwrap_err(),
            OptimError::Config(OptimConfigError::FirstStep)
        );
        let bad = Bounds::uniform(1.0, -1.0);
        assert_eq!(
            bfgs(&mut q, &z, &bad, &BfgsConfig::default()).unwrap_err(),
            OptimError::Config(OptimConfigError::Bounds)
        );
    }
}
