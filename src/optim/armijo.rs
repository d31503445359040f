//! Armijo backtracking line search (Nocedal & Wright, Algorithm 3.1).
//!
//! From a point `z` with objective `J` and gradient `G`, along a descent
//! direction `s`, try `α = 1, ρ, ρ², …` (at most `max_backtracks`
//! reductions) and accept the first trial `z_t = P(z + α s)` (projected on
//! the box) that satisfies the sufficient-decrease condition (N&W 3.4)
//!
//! ```text
//! J(z_t) <= J + c1 · Gᵀ (z_t − z)
//! ```
//!
//! With projection the actual step `z_t − z` replaces `α s`, so the test
//! stays a true sufficient-decrease test at the bound. A trial whose
//! evaluation fails (a diverging simulation) or is not finite counts as
//! not decreasing, and the step shrinks.

use nalgebra::SVector;

use super::{Bounds, Objective};

/// An accepted trial point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trial<const K: usize> {
    /// The point `z_t`.
    pub z: SVector<f32, K>,
    /// Objective there.
    pub j: f32,
    /// Gradient there.
    pub g: SVector<f32, K>,
}

/// A line search: finds an acceptable point along a direction.
pub trait LineSearch<const K: usize> {
    /// Searches from `z` (objective `j`, gradient `g`) along `dir`, counting
    /// evaluations into `evals`. `None` when no acceptable point was found.
    #[allow(clippy::too_many_arguments)]
    fn search<O: Objective<K>>(
        &self,
        obj: &mut O,
        bounds: &Bounds<K>,
        z: &SVector<f32, K>,
        j: f32,
        g: &SVector<f32, K>,
        dir: &SVector<f32, K>,
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
}

impl Default for Armijo {
    fn default() -> Self {
        Self {
            c1: 1e-4,
            shrink: 0.5,
            max_backtracks: 20,
        }
    }
}

impl Armijo {
    /// `Ok` when every setting is in range, else the name of the first
    /// that is not.
    pub fn validate(&self) -> Result<(), &'static str> {
        if !(self.c1 > 0.0 && self.c1 < 1.0) {
            return Err("armijo.c1");
        }
        if !(self.shrink > 0.0 && self.shrink < 1.0) {
            return Err("armijo.shrink");
        }
        if self.max_backtracks == 0 {
            return Err("armijo.max_backtracks");
        }
        Ok(())
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
        z: &SVector<f32, K>,
        j: f32,
        g: &SVector<f32, K>,
        dir: &SVector<f32, K>,
        evals: &mut u32,
    ) -> Option<Trial<K>> {
        let mut alpha = 1.0_f32;
        for _ in 0..=self.max_backtracks {
            let zt = bounds.project(&(z + dir * alpha));
            let step = zt - z;
            let slope = g.dot(&step);
            // A vanished step (pinned by the box, or α underflowed) or a
            // projected step that no longer descends: nothing to gain.
            if step.iter().all(|&v| v == 0.0) || slope >= 0.0 {
                return None;
            }
            *evals = evals.saturating_add(1);
            if let Ok((jt, gt)) = obj.eval(&zt)
                && jt.is_finite()
                && gt.iter().all(|v| v.is_finite())
                && self.accepts(j, jt, slope)
            {
                return Some(Trial {
                    z: zt,
                    j: jt,
                    g: gt,
                });
            }
            alpha *= self.shrink;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_and_rejects_exactly_at_the_boundary() {
        let a = Armijo {
            c1: 0.25,
            shrink: 0.5,
            max_backtracks: 4,
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
            fn eval(&mut self, z: &SVector<f32, 1>) -> Result<(f32, SVector<f32, 1>), ()> {
                Ok((z[0] * z[0], SVector::<f32, 1>::new(2.0 * z[0])))
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
    fn gives_up_after_the_cap() {
        struct Up;
        impl Objective<1> for Up {
            type Error = ();
            fn eval(&mut self, _: &SVector<f32, 1>) -> Result<(f32, SVector<f32, 1>), ()> {
                Ok((5.0, SVector::<f32, 1>::new(1.0)))
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
            }
            .validate()
        };
        assert_eq!(bad(0.0, 0.5, 3), Err("armijo.c1"));
        assert_eq!(bad(1.0, 0.5, 3), Err("armijo.c1"));
        assert_eq!(bad(f32::NAN, 0.5, 3), Err("armijo.c1"));
        assert_eq!(bad(0.1, 1.0, 3), Err("armijo.shrink"));
        assert_eq!(bad(0.1, 0.5, 0), Err("armijo.max_backtracks"));
    }
}
