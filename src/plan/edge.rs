//! The feasible set's edge between an SQP run's best feasible iterate
//! and where the run left it.
//!
//! A run that ends infeasible, or higher than its best feasible iterate,
//! goes back there (`optim/best.rs`). Where it had reached a lower `J`
//! before, the edge of the feasible set on the segment between the two
//! often holds most of that gain: a row violated by a saturated dive has
//! no gradient, so the SQP cannot step back to it. On a random canyon line
//! (`check_planner.py --seed 1302`, `unseen_1302_7`) track 1's least
//! altitude falls from 80 m at 501.7 m to 60 m at 556.3 m and then stays
//! at 59.75 m (a dive held at the pitch limit) whatever the depth; the run
//! went from the scan's 501.7 m to 674 m, 0.27 m short, found no step
//! and went back: the line's `J` 1.81× the f64 best safe plan's. Found
//! by bisection (8 plain flights), the edge starts the careful restart
//! that follows a run's return (`solve.rs`) where its `J` is lower than
//! the best feasible iterate's, and a restart that went back to its own
//! start runs once more from it (`Planner::sqp_restart`), kept only if
//! lower: 1.0028×.

use super::Planner;
use super::objective::PlanObjective;
use crate::optim::sqp::Constrained;

/// Bisections of the segment (its length over 2⁸).
const BISECTIONS: u32 = 8;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The edge of the feasible set (within `tol`, m) on the segment from
    /// the workspace's depths to `left`, by bisection: of the points it
    /// found feasible, the one of lowest `J`, if lower than the
    /// workspace's; `None` also when a flight fails or the budget stops
    /// it. Plain flights, counted in `obj`'s evaluations.
    pub(super) fn edge_toward(
        &self,
        obj: &mut PlanObjective<'_, N>,
        left: &[f32; K],
        tol: f32,
    ) -> Option<[f32; K]> {
        let (from, j0) = (self.work.z, self.work.j);
        let at = |t: f32| crate::num::between(&from, left, t);
        let (mut lo, mut hi) = (0.0_f32, 1.0_f32);
        let mut best: Option<([f32; K], f32)> = None;
        for _ in 0..BISECTIONS {
            let t = 0.5 * (lo + hi);
            let p = at(t);
            let (j, v) = obj.value(&p).ok()?;
            if v <= tol {
                lo = t;
                if j < best.map_or(j0, |b| b.1) {
                    best = Some((p, j));
                }
            } else {
                hi = t;
            }
        }
        best.map(|b| b.0)
    }
}
