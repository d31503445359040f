//! The interface between a constrained objective and the SQP
//! ([`super::sqp`]): what the objective's linearization at a point holds
//! (`J`, its gradient, the constraint rows and the Gauss–Newton matrix)
//! and the trait it implements.

use super::dense::Mat;

/// Most constraint rows an objective gives (the rest of the QP's rows are
/// the box's).
pub(crate) const CONSTRAINTS: usize = 32;

/// An objective's linearization at a point: `J`, its gradient, and the
/// constraint rows `cᵢ >= 0` with their gradients, in the same order at
/// every point (for the planner: one per segment, grouped by track), the
/// rows' storage laid out for the objective to fill in place.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Linearized<const K: usize> {
    /// `J`, m³.
    pub j: f32,
    /// `∇J`, m².
    pub grad: [f32; K],
    /// ℓ1 infeasibility `v`, m.
    pub infeasibility: f32,
    /// Rows used.
    pub rows: usize,
    /// Each row's `c`, m (`+inf`: no constraint there).
    pub c: [f32; CONSTRAINTS],
    /// Each row's gradient, m/m.
    pub a: [[f32; K]; CONSTRAINTS],
    /// Each row's group (for the planner: the track).
    pub group: [u8; CONSTRAINTS],
    /// Rows with `c` above this (m) stay out of the QP: too far from
    /// active for their linearization to matter.
    pub band: f32,
    /// The Gauss–Newton matrix of `J` (m), when asked for.
    pub gn: Mat<K>,
}

impl<const K: usize> Default for Linearized<K> {
    fn default() -> Self {
        Self {
            j: f32::INFINITY,
            grad: [0.0; K],
            infeasibility: 0.0,
            rows: 0,
            c: [f32::INFINITY; CONSTRAINTS],
            a: [[0.0; K]; CONSTRAINTS],
            group: [0; CONSTRAINTS],
            band: f32::INFINITY,
            gn: [[0.0; K]; K],
        }
    }
}

impl<const K: usize> Linearized<K> {
    /// `(c, ∇c, group)` of the rows used.
    pub(super) fn iter(&self) -> impl Iterator<Item = (f32, &[f32; K], u8)> + '_ {
        self.c
            .iter()
            .zip(self.a.iter())
            .zip(self.group.iter())
            .take(self.rows)
            .map(|((&c, a), &g)| (c, a, g))
    }

    /// The groups (bit `g`) of the rows that bind at a one-sided kink:
    /// active (`c <= active`, m), of a group `g` in `1..n` whose own
    /// column `∂c/∂z_g` is exactly zero while an earlier one is not. For
    /// the planner that is a later track's least altitude set while its
    /// pitch reference has stayed saturated since the track began: its
    /// own depth moves it only one way (a shallower dive unsaturates
    /// sooner and lifts the sample; a deeper one changes nothing there),
    /// and the linearization shows the side that does nothing, so the
    /// earlier depths look blocked by a row the later depth could free.
    pub(crate) fn kinked(&self, active: f32, n: usize) -> u32 {
        self.iter().fold(0, |bits, (c, a, g)| {
            let g = usize::from(g);
            let own = a.get(g).copied();
            let earlier = a.get(..g).is_some_and(|e| e.iter().any(|&v| v != 0.0));
            match group_bit(g) {
                Some(b) if c <= active && g >= 1 && g < n && own == Some(0.0) && earlier => {
                    bits | b
                }
                _ => bits,
            }
        })
    }

    /// The groups (bit `g`) with a row in transition: active (`c <=
    /// active`, m), of a group `g` in `1..n`, whose own column and an
    /// earlier one are each at least [`BLENDED`] in magnitude (m/m). For the planner
    /// that is a later track's least altitude set where its dive is ending:
    /// the deeper its own depth, the longer the dive, and the more the
    /// arrival (an earlier depth) sets it, until its own depth moves it no
    /// more. The linearization sees its own depth still moving it.
    pub(crate) fn blended(&self, active: f32, n: usize) -> u32 {
        self.iter().fold(0, |bits, (c, a, g)| {
            let g = usize::from(g);
            let own = a.get(g).map_or(0.0, |v| libm::fabsf(*v));
            let earlier = a.get(..g).map_or(0.0, |e| {
                e.iter().fold(0.0_f32, |m, v| m.max(libm::fabsf(*v)))
            });
            match group_bit(g) {
                Some(b) if c <= active && g < n && own >= BLENDED && earlier >= BLENDED => bits | b,
                _ => bits,
            }
        })
    }
}

/// Group `g`'s bit in a set of groups ([`Linearized::blended`]), if it
/// has one.
pub(crate) fn group_bit(g: usize) -> Option<u32> {
    u32::try_from(g).ok().and_then(|g| 1_u32.checked_shl(g))
}

/// How much a row's own column and an earlier one must each move it to
/// count as in transition ([`Linearized::blended`]), m/m.
pub(crate) const BLENDED: f32 = 0.1;

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
    /// Whether a run gives up after its `iterations`-th iteration, which
    /// took `J` from `before` to `j` (m³): never, unless the objective
    /// says so (a restart kept only where it ends below a value it is far
    /// from by then, `plan/kink.rs`).
    fn abandon(&self, _iterations: u32, (_before, _j): (f32, f32)) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::super::sqp::sqp_into;
    use super::super::{BfgsConfig, Bounds, Outcome, Status};
    use super::*;

    /// Rows `(c, ∂c/∂z, group)` of a three-depth linearization.
    fn lin(rows: &[(f32, [f32; 3], u8)]) -> Linearized<3> {
        let mut l = Linearized::<3>::default();
        for (i, &(c, a, g)) in rows.iter().enumerate() {
            l.c[i] = c;
            l.a[i] = a;
            l.group[i] = g;
        }
        l.rows = rows.len();
        l
    }

    #[test]
    fn a_kink_is_an_active_later_row_blind_to_its_own_depth() {
        // Track 2's row: active, its own column zero, track 1's not.
        let kinked = (0.01, [-0.4, 0.0, 0.0], 1);
        assert_eq!(
            lin(&[(3.0, [0.5, 0.0, 0.0], 0), kinked]).kinked(0.1, 3),
            0b10
        );
        // Not active; its own column moves it; the first track's; no
        // earlier column; a group past the horizon's `n`.
        assert_eq!(lin(&[(0.5, [-0.4, 0.0, 0.0], 1)]).kinked(0.1, 3), 0);
        assert_eq!(lin(&[(0.01, [-0.4, -0.2, 0.0], 1)]).kinked(0.1, 3), 0);
        assert_eq!(lin(&[(0.0, [0.0, 0.0, 0.0], 0)]).kinked(0.1, 3), 0);
        assert_eq!(lin(&[(0.0, [0.0, 0.0, 0.0], 2)]).kinked(0.1, 3), 0);
        assert_eq!(lin(&[kinked]).kinked(0.1, 1), 0);
        // Two kinked rows: both.
        let later = (0.0, [-0.1, -0.9, 0.0], 2);
        assert_eq!(lin(&[kinked, later]).kinked(0.1, 3), 0b110);
    }

    #[test]
    fn a_row_in_transition_is_moved_by_its_own_and_an_earlier_depth() {
        // Track 2's row, active, moved by both depths (bit 1); track 3's
        // too (bit 2).
        let blended = (0.01, [-0.46, -0.57, 0.0], 1);
        assert_eq!(lin(&[blended]).blended(0.1, 3), 0b10);
        assert_eq!(
            lin(&[blended, (0.0, [0.0, -0.2, -0.8], 2)]).blended(0.1, 3),
            0b110
        );
        // Not active; settled on its own depth (the earlier column below
        // a tenth); a dive's plateau (its own column below a tenth: the
        // kink's); the first track's; a group past the horizon's `n`.
        assert_eq!(lin(&[(0.5, [-0.46, -0.57, 0.0], 1)]).blended(0.1, 3), 0);
        assert_eq!(lin(&[(0.0, [-0.05, -1.0, 0.0], 1)]).blended(0.1, 3), 0);
        assert_eq!(lin(&[(0.0, [-1.07, 0.0, 0.0], 1)]).blended(0.1, 3), 0);
        assert_eq!(lin(&[(0.0, [-1.0, 0.0, 0.0], 0)]).blended(0.1, 3), 0);
        assert_eq!(lin(&[blended]).blended(0.1, 1), 0);
    }

    /// Rosenbrock's valley, no constraint rows, its Gauss–Newton matrix
    /// (of its two residuals); a ceiling at `ceiling` after `probe`
    /// iterations, if any.
    struct Valley(Option<(u32, f32)>);

    impl Constrained<2> for Valley {
        type Error = ();
        fn linearize(&mut self, z: &[f32; 2], _: bool, out: &mut Linearized<2>) -> Result<(), ()> {
            let [x, y] = *z;
            (out.j, out.infeasibility) = self.value(z)?;
            out.grad = [
                -400.0 * x * (y - x * x) - 2.0 * (1.0 - x),
                200.0 * (y - x * x),
            ];
            // Residuals 10 (y − x²) and 1 − x: J = r ᵀ r.
            let r = [[-20.0 * x, 10.0], [-1.0, 0.0]];
            out.gn = [[0.0; 2]; 2];
            for (i, row) in out.gn.iter_mut().enumerate() {
                for (k, v) in row.iter_mut().enumerate() {
                    *v = 2.0 * (r[0][i] * r[0][k] + r[1][i] * r[1][k]);
                }
            }
            Ok(())
        }
        fn value(&mut self, z: &[f32; 2]) -> Result<(f32, f32), ()> {
            let [x, y] = *z;
            Ok((
                100.0 * (y - x * x) * (y - x * x) + (1.0 - x) * (1.0 - x),
                0.0,
            ))
        }
        fn abandon(&self, iterations: u32, (_, j): (f32, f32)) -> bool {
            self.0
                .is_some_and(|(probe, c)| iterations == probe && j >= c)
        }
    }

    /// The SQP from `(−1.2, 1)` with `ceiling`: its outcome and end.
    fn valley(ceiling: Option<(u32, f32)>) -> (Outcome<2>, bool) {
        let (z0, bounds) = ([-1.2, 1.0], Bounds::uniform(-5.0, 5.0));
        let mut out = Outcome::at(&z0);
        let cfg = BfgsConfig::default();
        let end = sqp_into(
            &mut Valley(ceiling),
            (&z0, 0.0, false),
            (&bounds, 2),
            &cfg,
            1e-3,
            &mut out,
        )
        .unwrap();
        (out, end.left.is_some() && end.lower)
    }

    #[test]
    fn a_run_gives_up_where_its_objective_abandons_it() {
        // Without a ceiling, or one it is below at the probe: on to the
        // valley's floor, (1, 1).
        let (free, _) = valley(None);
        assert!(free.iterations > 2 && free.j < 1e-3, "{free:?}");
        assert_eq!(valley(Some((2, 1e6))).0.iterations, free.iterations);
        // A ceiling below its second iterate: it stops there.
        let (given_up, left) = valley(Some((2, 1e-3)));
        assert_eq!(given_up.iterations, 2);
        assert_eq!(given_up.history.len(), 3);
        assert_eq!(given_up.status, Status::MaxIterations);
        assert!(!left);
    }
}
