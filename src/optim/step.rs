//! The QP step of an SQP iteration (`sqp.rs`): the quadratic program on
//! the metric, the linearized rows within the objective's band and the
//! box, relaxed where incompatible; and, for a careful run, solved again
//! with the rows beyond the band that its step would cross.

use heapless::Vec;

use super::Bounds;
use super::constrained::{CONSTRAINTS, Linearized};
use super::dense::{Mat, at, dot, put};
use super::qp::{self, QP_ROWS, QpError, QpSolution, Row, Rows};

/// Relaxations of an incompatible QP: the share of each shortfall left.
const RELAXATIONS: [f32; 4] = [0.0, 0.5, 0.9, 1.0];

/// Relative regularization of the metric's diagonal in the QP.
pub(super) const REGULARIZATION: f32 = 1e-6;

/// The QP step at `z`: `(d, λ per constraint row, σ)` with the least
/// relaxation `σ` that makes the QP compatible; `None` when none does
/// (the metric not definite).
pub(super) fn step<const K: usize>(
    a: &Mat<K>,
    lin: &Linearized<K>,
    z: &[f32; K],
    (bounds, n): (&Bounds<K>, usize),
    (max_step, careful): (f32, bool),
) -> Option<([f32; K], Vec<f32, CONSTRAINTS>, f32)> {
    let mean = (0..n).fold(0.0, |s, i| s + at(a, i, i)) / (n.max(1) as f32);
    let delta = REGULARIZATION * mean.max(0.0) + REGULARIZATION;
    let mut a_reg = *a;
    for i in 0..n {
        put(&mut a_reg, i, i, at(a, i, i) + delta);
    }
    // (One frame for both solves: two calls of a helper that returned
    // the step grew the horizon's stack by 440 B on the M4F.)
    let mut band = lin.band;
    let mut sol = QpSolution::default();
    'bands: loop {
        for &sigma in &RELAXATIONS {
            let rows = StepRows::new(lin, (z, bounds, n), (sigma, band));
            match qp::solve(&a_reg, &lin.grad, n, &rows, &mut sol) {
                Ok(()) => {
                    let longest = sol.d.iter().fold(0.0_f32, |m, v| m.max(libm::fabsf(*v)));
                    let mut d = sol.d;
                    if longest > max_step {
                        d.iter_mut().for_each(|v| *v *= max_step / longest);
                    }
                    if careful && band.is_finite() && crosses(lin, &d, n) {
                        band = f32::INFINITY;
                        continue 'bands;
                    }
                    let mut lambda: Vec<f32, CONSTRAINTS> = Vec::new();
                    for _ in 0..lin.rows {
                        let _ = lambda.push(0.0);
                    }
                    for (i, &l) in sol.lambda.iter().enumerate().take(rows.general) {
                        let at = rows.index.get(i).map(|&k| usize::from(k));
                        if let Some(slot) = at.and_then(|k| lambda.get_mut(k)) {
                            *slot = l;
                        }
                    }
                    return Some((d, lambda, sigma));
                }
                Err(QpError::Incompatible | QpError::Iterations) => {}
                Err(QpError::NotDefinite) => return None,
            }
        }
        return None;
    }
}

/// Whether the step `d` crosses, by the linearization, a row left out of
/// the QP for being beyond the band (`c + ∇c·d < 0` with `c >= band`).
fn crosses<const K: usize>(lin: &Linearized<K>, d: &[f32; K], n: usize) -> bool {
    lin.iter()
        .any(|(c, a, _)| c >= lin.band && c.is_finite() && c + dot(a, d, n) < 0.0)
}

/// The QP's rows at relaxation `σ`, read in place: the near-active
/// constraints with a gradient (`index`: which of the objective's rows),
/// then two box rows per variable around `z`.
pub(super) struct StepRows<'l, const K: usize> {
    lin: &'l Linearized<K>,
    index: [u8; CONSTRAINTS],
    general: usize,
    z: &'l [f32; K],
    bounds: &'l Bounds<K>,
    n: usize,
    sigma: f32,
}

impl<'l, const K: usize> StepRows<'l, K> {
    pub(super) fn new(
        lin: &'l Linearized<K>,
        (z, bounds, n): (&'l [f32; K], &'l Bounds<K>, usize),
        (sigma, band): (f32, f32),
    ) -> Self {
        let mut index = [0_u8; CONSTRAINTS];
        let mut general = 0_usize;
        for (i, (c, a, _)) in lin.iter().enumerate() {
            let moves = a.iter().take(n).any(|&v| v != 0.0);
            if moves
                && c < band
                && c.is_finite()
                && let Some(slot) = index.get_mut(general)
            {
                *slot = u8::try_from(i).unwrap_or(u8::MAX);
                general = general.saturating_add(1);
            }
        }
        Self {
            lin,
            index,
            general,
            z,
            bounds,
            n,
            sigma,
        }
    }
}

impl<const K: usize> Rows<K> for StepRows<'_, K> {
    fn count(&self) -> usize {
        self.general
            .saturating_add(self.n.saturating_mul(2))
            .min(QP_ROWS)
    }

    fn row(&self, i: usize) -> Option<Row<K>> {
        if i < self.general {
            let k = usize::from(*self.index.get(i)?);
            let (&c, &a) = (self.lin.c.get(k)?, self.lin.a.get(k)?);
            let c = if c < 0.0 { (1.0 - self.sigma) * c } else { c };
            return Some(Row { a, c });
        }
        let b = i.checked_sub(self.general)?;
        let (v, up) = (b / 2, b % 2 == 0);
        let (&zi, &lo, &hi) = (
            self.z.get(v)?,
            self.bounds.lo.get(v)?,
            self.bounds.hi.get(v)?,
        );
        let mut a = [0.0; K];
        *a.get_mut(v)? = if up { 1.0 } else { -1.0 };
        Some(Row {
            a,
            c: if up { zi - lo } else { hi - zi },
        })
    }
}
