//! Gradient descent with a constant learning rate: `ζ <- P(ζ − κ G)`
//! (paper eq. 3.6, projected on the box). The paper's baseline: its
//! convergence depends entirely on `κ`, which is the point of comparing it
//! with BFGS.

use super::{
    Bounds, Objective, OptimConfigError, OptimError, Outcome, Status, Tolerances, Vector, eval,
    norm, start,
};

/// Gradient-descent settings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GdConfig {
    /// Learning rate `κ`, m per m² of gradient (1/m), > 0.
    pub rate: f32,
    /// Iteration cap, ≥ 1. Default 200 (paper §5.3.1).
    pub max_iterations: u32,
    /// Stopping rules.
    pub tol: Tolerances,
}

impl GdConfig {
    /// `Ok` when every setting is in range, else the first that is not.
    ///
    /// # Errors
    /// [`OptimConfigError`] naming it.
    pub fn validate(&self) -> Result<(), OptimConfigError> {
        if !(self.rate.is_finite() && self.rate > 0.0) {
            return Err(OptimConfigError::GdRate);
        }
        if self.max_iterations == 0 {
            return Err(OptimConfigError::MaxIterations);
        }
        if !self.tol.is_valid() {
            return Err(OptimConfigError::Tolerances);
        }
        Ok(())
    }
}

/// Minimizes `obj` from `z0` within `bounds` by constant-rate gradient
/// descent. An evaluation that fails or is not finite ends the run with
/// [`Status::LineSearchFailed`] at the last good point.
///
/// # Errors
/// [`OptimError`] for an invalid configuration or box, or a failed start.
pub fn gradient_descent<const K: usize, O: Objective<K>>(
    obj: &mut O,
    z0: &[f32; K],
    bounds: &Bounds<K>,
    cfg: &GdConfig,
) -> Result<Outcome<K>, OptimError<O::Error>> {
    let mut out = Outcome::at(z0);
    gradient_descent_into(obj, z0, bounds, cfg, &mut out, false)?;
    Ok(out)
}

/// [`gradient_descent`] writing into `out` in place (see
/// `bfgs::bfgs_into`).
pub(crate) fn gradient_descent_into<const K: usize, O: Objective<K>>(
    obj: &mut O,
    z0: &[f32; K],
    bounds: &Bounds<K>,
    cfg: &GdConfig,
    out: &mut Outcome<K>,
    continued: bool,
) -> Result<(), OptimError<O::Error>> {
    cfg.validate().map_err(OptimError::Config)?;
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
    let mut iterations = 0_u32;
    let status = loop {
        if bounds.free_gradient_norm_v(&z, &g) <= cfg.tol.grad {
            break Status::Converged;
        }
        if iterations >= cfg.max_iterations {
            break Status::MaxIterations;
        }
        let zt = bounds.project_v(&(z - g * cfg.rate));
        if zt == z {
            // Pinned against the box: no move left.
            break Status::Converged;
        }
        evaluations = evaluations.saturating_add(1);
        let (jt, gt) = match eval(obj, &zt) {
            Ok((jt, gt)) if jt.is_finite() && gt.iter().all(|v| v.is_finite()) => (jt, gt),
            _ => break Status::LineSearchFailed,
        };
        let dj = j - jt;
        z = zt;
        j = jt;
        g = gt;
        iterations = iterations.saturating_add(1);
        let _ = history.push(j);
        crate::log::debug!(
            "gd iteration {=u32}: J {=f32} m3, |G| {=f32} m2",
            iterations,
            j,
            norm(&g)
        );
        if libm::fabsf(dj) <= cfg.tol.j_threshold(j) {
            break Status::Converged;
        }
    };
    out.grad_norm = bounds.free_gradient_norm_v(&z, &g);
    out.z = z.into();
    out.j = j;
    out.gradient = g.into();
    out.status = status;
    out.iterations = iterations;
    out.evaluations = evaluations;
    out.skipped_updates = 0;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::testfns::Quadratic;
    use super::*;
    use nalgebra::{Matrix2, Vector2};

    #[test]
    fn converges_linearly_on_a_quadratic() {
        let mut q = Quadratic {
            h: Matrix2::new(2.0, 0.0, 0.0, 0.5),
            b: Vector2::zeros(),
        };
        let cfg = GdConfig {
            rate: 0.4,
            max_iterations: 500,
            tol: Tolerances {
                grad: 1e-5,
                rel: 0.0,
                floor: 1.0,
            },
        };
        // Minimum value 0 at the origin, so f32 resolves J all the way.
        let out =
            gradient_descent(&mut q, &[-1.0, -2.0], &Bounds::uniform(-9.0, 9.0), &cfg).unwrap();
        assert_eq!(out.status, Status::Converged);
        assert!(out.z.iter().all(|v| v.abs() < 1e-4), "{:?}", out.z);
        // The slow mode contracts by 1 - 0.4 * 0.5 = 0.8 per iteration.
        assert!(out.iterations > 40, "{}", out.iterations);
        assert_eq!(out.evaluations, out.iterations + 1);
        assert!(out.history.windows(2).all(|w| w[1] <= w[0]));
    }

    #[test]
    fn rejects_a_bad_rate() {
        let mut q = Quadratic {
            h: Matrix2::identity(),
            b: Vector2::zeros(),
        };
        let cfg = GdConfig {
            rate: -1.0,
            max_iterations: 5,
            tol: Tolerances::default(),
        };
        assert_eq!(
            gradient_descent(&mut q, &[0.0; 2], &Bounds::uniform(-1.0, 1.0), &cfg).unwrap_err(),
            OptimError::Config(OptimConfigError::GdRate)
        );
    }
}
