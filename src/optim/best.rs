//! The best feasible point an SQP run has linearized, to go back to
//! (`sqp.rs`).

use super::Tolerances;
use super::constrained::{Constrained, Linearized};

/// The feasible iterate of least `J` a run has linearized (the start
/// included). The ℓ1 merit may accept a step that leaves the feasible set
/// for a lower `J`, and from there a nonconvex problem can lead the run to
/// a feasible end far worse than where it was: on a random line
/// (`check_planner.py --seed 90317`, `unseen_90317_1`) the cold horizon
/// started feasible at `J` 1.07e8 m³, stepped out to 4.5e7 and ended
/// feasible at 3.78e8 m³, a climb held over a deep track. The run returns
/// to this point when it ends infeasible or worse by more than the
/// tolerance.
#[derive(Default)]
pub(super) struct BestFeasible<const K: usize> {
    at: Option<([f32; K], f32)>,
}

impl<const K: usize> BestFeasible<K> {
    /// Takes the run's point `z` (linearized as `lin`) if it is feasible
    /// within `feas_tol` (m) and lower than the best so far.
    pub(super) fn see(&mut self, z: &[f32; K], lin: &Linearized<K>, feas_tol: f32) {
        if lin.infeasibility <= feas_tol && self.at.is_none_or(|(_, j)| lin.j < j) {
            self.at = Some((*z, lin.j));
        }
    }

    /// Moves the finished run's point `z` and linearization `lin` back to
    /// the best feasible point (one more linearization) where it ended
    /// infeasible, or feasible and higher by more than `tol`'s threshold;
    /// a failed linearization leaves the run where it ended. True when it
    /// moved.
    pub(super) fn return_to<O: Constrained<K>>(
        &self,
        obj: &mut O,
        (z_end, lin): (&mut [f32; K], &mut Linearized<K>),
        (feas_tol, tol): (f32, &Tolerances),
    ) -> bool {
        let Some((z, j)) = self.at else { return false };
        let worse = lin.infeasibility > feas_tol || lin.j - j > tol.j_threshold(j);
        if !worse {
            return false;
        }
        crate::log::debug!("sqp: back to the best feasible iterate, J {=f32} m3", j);
        // Into `lin` itself, not a copy (a linearization is about 1 KB of
        // stack at K = 5): a failed one is the flight budget's, which stops
        // before writing anything, and `z` was linearized before.
        if obj.linearize(&z, false, lin).is_ok() {
            *z_end = z;
            return true;
        }
        // (The objective's own state back at the run's end.)
        let _ = obj.linearize(z_end, false, lin);
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `J = (z − 3)²`, infeasible (`v = z − 2`) above `z = 2`.
    struct Parabola;

    impl Constrained<1> for Parabola {
        type Error = ();
        fn linearize(&mut self, z: &[f32; 1], _: bool, out: &mut Linearized<1>) -> Result<(), ()> {
            let (j, v) = self.value(z)?;
            out.j = j;
            out.infeasibility = v;
            out.grad = [2.0 * (z[0] - 3.0)];
            Ok(())
        }
        fn value(&mut self, z: &[f32; 1]) -> Result<(f32, f32), ()> {
            Ok(((z[0] - 3.0) * (z[0] - 3.0), (z[0] - 2.0).max(0.0)))
        }
    }

    fn at(z: f32) -> ([f32; 1], Linearized<1>) {
        let mut lin = Linearized::default();
        Parabola.linearize(&[z], false, &mut lin).unwrap();
        ([z], lin)
    }

    #[test]
    fn keeps_the_lowest_feasible_iterate_and_goes_back_to_it() {
        let mut best = BestFeasible::default();
        let tol = Tolerances::default();
        // Feasible 0 (J 9), feasible 1.5 (J 2.25), infeasible 2.8 (J 0.04),
        // feasible 1 (J 4): the run ends worse than 1.5.
        for z in [0.0, 1.5, 2.8, 1.0] {
            let (z, lin) = at(z);
            best.see(&z, &lin, 1e-3);
        }
        let (mut z, mut lin) = at(1.0);
        assert!(best.return_to(&mut Parabola, (&mut z, &mut lin), (1e-3, &tol)));
        assert_eq!((z[0], lin.j), (1.5, 2.25));
        // Ended infeasible: back to the best feasible too.
        let (mut z, mut lin) = at(2.8);
        assert!(best.return_to(&mut Parabola, (&mut z, &mut lin), (1e-3, &tol)));
        assert_eq!(z[0], 1.5);
        // Ended at it, or lower and feasible: stays.
        let (mut z, mut lin) = at(1.5);
        assert!(!best.return_to(&mut Parabola, (&mut z, &mut lin), (1e-3, &tol)));
        let (mut z, mut lin) = at(1.9);
        assert!(!best.return_to(&mut Parabola, (&mut z, &mut lin), (1e-3, &tol)));
        assert_eq!(z[0], 1.9);
    }

    #[test]
    fn without_a_feasible_iterate_nothing_moves() {
        let best = BestFeasible::<1>::default();
        let (mut z, mut lin) = at(2.8);
        let tol = Tolerances::default();
        assert!(!best.return_to(&mut Parabola, (&mut z, &mut lin), (1e-3, &tol)));
        assert_eq!(z[0], 2.8);
    }
}
