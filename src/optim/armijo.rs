//! Armijo backtracking line search (Nocedal & Wright, Algorithm 3.1).
//!
//! From a point `z` with objective `J` and gradient `G`, along a descent
//! direction `s`, try `α = 1` and then smaller steps (at most
//! `max_backtracks` reductions), and accept the first trial
//! `z_t = P(z + α s)` (projected on the box) that satisfies the
//! sufficient-decrease condition (N&W 3.4)
//!
//! ```text
//! J(z_t) <= J + c1 · Gᵀ (z_t − z)
//! ```
//!
//! Each reduction is by the factor `ρ` (`shrink`), or, with `interpolate`,
//! to the minimizer of the quadratic through `J`, the slope and the failed
//! trial's value, safeguarded to `[0.1 α, ρ α]` (N&W §3.5, eq. 3.57): a
//! first step that lands deep in a stiff penalty then costs two or three
//! evaluations instead of a dozen halvings.
//!
//! An objective with a cheaper value ([`Objective::value`]) has its trials
//! tried by value alone, and the gradient evaluated at the accepted one.
//!
//! With projection the actual step `z_t − z` replaces `α s`, so the test
//! stays a true sufficient-decrease test at the bound. A trial whose
//! evaluation fails (a diverging simulation) or is not finite counts as
//! not decreasing, and the step shrinks.

use super::{Bounds, Objective, OptimConfigError, Vector, dot, eval};

/// An accepted trial point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Trial<const K: usize> {
    /// The point `z_t`.
    pub z: Vector<K>,
    /// Objective there.
    pub j: f32,
    /// Gradient there.
    pub g: Vector<K>,
    /// The last trial rejected before this one (the shortest rejected
    /// step) and its objective, `J` at least as high as the test allowed
    /// (∞ where its flight failed); `None` where the first trial was
    /// accepted.
    pub rejected: Option<(Vector<K>, f32)>,
}

/// A line search: finds an acceptable point along a direction.
pub(crate) trait LineSearch<const K: usize> {
    /// Searches from `z` (objective `j`, gradient `g`) along `dir`, counting
    /// evaluations into `evals`. `None` when no acceptable point was found.
    #[allow(clippy::too_many_arguments)]
    fn search<O: Objective<K>>(
        &self,
        obj: &mut O,
        bounds: &Bounds<K>,
        z: &Vector<K>,
        j: f32,
        g: &Vector<K>,
        dir: &Vector<K>,
        evals: &mut u32,
    ) -> Option<Trial<K>>;
}

/// Armijo backtracking settings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Armijo {
    /// Sufficient-decrease constant `c1`, in (0, 1). Default 1e-4.
    pub c1: f32,
    /// Step reduction factor `ρ`, in (0, 1). Default 0.5.
    pub shrink: f32,
    /// Backtracking cap: at most this many reductions of `α` (so at most
    /// `max_backtracks + 1` evaluations per search), ≥ 1. Default 20.
    pub max_backtracks: u32,
    /// Reduce by safeguarded quadratic interpolation instead of the plain
    /// factor. Default true.
    pub interpolate: bool,
}

/// Smallest reduction factor of an interpolated backtrack.
const MIN_SHRINK: f32 = 0.1;

impl Default for Armijo {
    fn default() -> Self {
        Self {
            c1: 1e-4,
            shrink: 0.5,
            max_backtracks: 20,
            interpolate: true,
        }
    }
}

impl Armijo {
    /// `Ok` when every setting is in range, else the first that is not.
    ///
    /// # Errors
    /// [`OptimConfigError`] naming it.
    pub fn validate(&self) -> Result<(), OptimConfigError> {
        if !(self.c1 > 0.0 && self.c1 < 1.0) {
            return Err(OptimConfigError::ArmijoC1);
        }
        if !(self.shrink > 0.0 && self.shrink < 1.0) {
            return Err(OptimConfigError::ArmijoShrink);
        }
        if self.max_backtracks == 0 {
            return Err(OptimConfigError::ArmijoBacktracks);
        }
        Ok(())
    }

    /// The factor by which `α` shrinks after a trial of value `j_t` failed
    /// (slope `Gᵀ(z_t − z)` of that trial's step).
    fn reduction(&self, j: f32, j_t: f32, slope: f32) -> f32 {
        if !self.interpolate {
            return self.shrink;
        }
        // Quadratic q(t) = j + slope t + c t², t = α'/α, through q(1) = j_t.
        let curv = j_t - j - slope;
        let t = -slope / (2.0 * curv);
        if t.is_finite() && curv > 0.0 {
            t.max(MIN_SHRINK).min(self.shrink)
        } else {
            self.shrink
        }
    }

    /// The sufficient-decrease test: `j_t <= j + c1 · slope`, where
    /// `slope = Gᵀ(z_t − z)` is negative for a descent step.
    #[inline]
    pub fn accepts(&self, j: f32, j_t: f32, slope: f32) -> bool {
        j_t <= j + self.c1 * slope
    }
}

impl<const K: usize> LineSearch<K> for Armijo {
    fn search<O: Objective<K>>(
        &self,
        obj: &mut O,
        bounds: &Bounds<K>,
        z: &Vector<K>,
        j: f32,
        g: &Vector<K>,
        dir: &Vector<K>,
        evals: &mut u32,
    ) -> Option<Trial<K>> {
        let mut alpha = 1.0_f32;
        let mut rejected = None;
        for _ in 0..=self.max_backtracks {
            let zt = bounds.project_v(&(z + dir * alpha));
            let step = zt - z;
            let slope = dot(g, &step);
            // A vanished step (pinned by the box, or α underflowed) or a
            // projected step that no longer descends: nothing to gain.
            if step.iter().all(|&v| v == 0.0) || slope >= 0.0 {
                return None;
            }
            *evals = evals.saturating_add(1);
            // A cheap value first, where the objective has one: a rejected
            // trial then costs no gradient.
            let cheap = match obj.value(&zt.into()) {
                None => None,
                Some(Ok(jt)) if jt.is_finite() && self.accepts(j, jt, slope) => {
                    *evals = evals.saturating_add(1);
                    None
                }
                Some(Ok(jt)) if jt.is_finite() => Some(jt),
                Some(_) => Some(f32::INFINITY),
            };
            if let Some(jt) = cheap {
                alpha *= self.reduction(j, jt, slope);
                rejected = Some((zt, jt));
                continue;
            }
            let jt = match eval(obj, &zt) {
                Ok((jt, gt)) if jt.is_finite() && gt.iter().all(|v| v.is_finite()) => {
                    if self.accepts(j, jt, slope) {
                        return Some(Trial {
                            z: zt,
                            j: jt,
                            g: gt,
                            rejected,
                        });
                    }
                    jt
                }
                _ => f32::INFINITY,
            };
            alpha *= self.reduction(j, jt, slope);
            rejected = Some((zt, jt));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SVector;

    #[test]
    fn accepts_and_rejects_exactly_at_the_boundary() {
        let a = Armijo {
            c1: 0.25,
            shrink: 0.5,
            max_backtracks: 4,
            interpolate: false,
        };
        // j + c1 * slope = 10 - 0.25 * 8 = 8, exactly representable.
        assert!(a.accepts(10.0, 8.0, -8.0));
        assert!(!a.accepts(10.0, f32::from_bits(8.0_f32.to_bits() + 1), -8.0));
        assert!(a.accepts(10.0, f32::from_bits(8.0_f32.to_bits() - 1), -8.0));
        assert!(!a.accepts(10.0, f32::NAN, -8.0));
    }

    /// J(z) = z² from z = 1 along s = -2 (the gradient): α = 1 lands on
    /// z = -1, J = 1, no decrease: rejected; α = ½ lands on 0: accepted.
    #[test]
    fn backtracks_until_sufficient_decrease() {
        struct Sq;
        impl Objective<1> for Sq {
            type Error = ();
            fn eval(&mut self, z: &[f32; 1]) -> Result<(f32, [f32; 1]), ()> {
                Ok((z[0] * z[0], [2.0 * z[0]]))
            }
        }
        let b = Bounds::<1>::uniform(-10.0, 10.0);
        let z = SVector::<f32, 1>::new(1.0);
        let g = SVector::<f32, 1>::new(2.0);
        let mut evals = 0;
        let t = Armijo::default()
            .search(&mut Sq, &b, &z, 1.0, &g, &(-g), &mut evals)
            .unwrap();
        assert_eq!(t.z[0], 0.0);
        assert_eq!(evals, 2);
    }

    #[test]
    fn interpolation_cuts_a_huge_overshoot_fast() {
        // J = z⁴ from z = 1 along s = -40: α = 1 lands on z = -39.
        struct Quartic;
        impl Objective<1> for Quartic {
            type Error = ();
            fn eval(&mut self, z: &[f32; 1]) -> Result<(f32, [f32; 1]), ()> {
                let v = z[0];
                Ok((v * v * v * v, [4.0 * v * v * v]))
            }
        }
        let b = Bounds::<1>::uniform(-100.0, 100.0);
        let z = SVector::<f32, 1>::new(1.0);
        let g = SVector::<f32, 1>::new(4.0);
        let dir = SVector::<f32, 1>::new(-40.0);
        let (mut plain, mut interp) = (0, 0);
        let halving = Armijo {
            interpolate: false,
            ..Armijo::default()
        };
        let t1 = halving
            .search(&mut Quartic, &b, &z, 1.0, &g, &dir, &mut plain)
            .unwrap();
        let t2 = Armijo::default()
            .search(&mut Quartic, &b, &z, 1.0, &g, &dir, &mut interp)
            .unwrap();
        assert!(t1.j < 1.0 && t2.j < 1.0);
        assert!(interp < plain, "{interp} vs {plain}");
    }

    #[test]
    fn gives_up_after_the_cap() {
        struct Up;
        impl Objective<1> for Up {
            type Error = ();
            fn eval(&mut self, _: &[f32; 1]) -> Result<(f32, [f32; 1]), ()> {
                Ok((5.0, [1.0]))
            }
        }
        let a = Armijo {
            max_backtracks: 3,
            ..Armijo::default()
        };
        let b = Bounds::<1>::uniform(-10.0, 10.0);
        let z = SVector::<f32, 1>::new(0.0);
        let g = SVector::<f32, 1>::new(1.0);
        let mut evals = 0;
        assert!(
            a.search(&mut Up, &b, &z, 1.0, &g, &(-g), &mut evals)
                .is_none()
        );
        assert_eq!(evals, 4);
    }

    #[test]
    fn validates() {
        assert!(Armijo::default().validate().is_ok());
        let bad = |c1, shrink, max_backtracks| {
            Armijo {
                c1,
                shrink,
                max_backtracks,
                interpolate: true,
            }
            .validate()
        };
        assert_eq!(bad(0.0, 0.5, 3), Err(OptimConfigError::ArmijoC1));
        assert_eq!(bad(1.0, 0.5, 3), Err(OptimConfigError::ArmijoC1));
        assert_eq!(bad(f32::NAN, 0.5, 3), Err(OptimConfigError::ArmijoC1));
        assert_eq!(bad(0.1, 1.0, 3), Err(OptimConfigError::ArmijoShrink));
        assert_eq!(bad(0.1, 0.5, 0), Err(OptimConfigError::ArmijoBacktracks));
    }
}
