//! A small dense convex quadratic program, the step of the SQP
//! ([`super::sqp`]):
//!
//! ```text
//! min ½ dᵀ G d + gᵀ d   subject to   aᵢᵀ d + cᵢ >= 0,   i = 1..m
//! ```
//!
//! over the first `n` of `K` variables (the rest are held at zero), with
//! `G` symmetric positive definite. Solved by the dual active-set method
//! of Goldfarb and Idnani (Math. Prog. 27, 1983), as R's `quadprog`:
//! from the unconstrained minimum, the most violated constraint enters the
//! active set, a full step satisfies it or a partial step drops an active
//! constraint whose multiplier would turn negative; `J = L⁻ᵀ Q` and the
//! triangular `R` are kept up to date by Givens rotations. It ends in at
//! most `m + n` additions in exact arithmetic; here it is capped at
//! `ITERATIONS`, and linearly dependent or incompatible constraints are
//! reported, never looped on.
//!
//! Each row is scaled to a unit gradient first, so that the tolerances
//! are in the unit of `d` (m for the planner). This file poses the problem
//! and picks the row that enters; the method's working state, its factors
//! and their updates, is [`super::dual`].

use super::dense::{Mat, dot};
pub(crate) use super::dual::{QP_ROWS, QpError, QpSolution};
use super::dual::{TINY, Work};

/// Most steps (additions and drops) of one solve.
const ITERATIONS: usize = 4 * QP_ROWS;

/// A row is violated when `aᵀd + c < -VIOLATION` (after scaling to a unit
/// gradient: metres of `d`).
const VIOLATION: f32 = 1e-5;

/// One linear inequality `aᵀ d + c >= 0` (unit of `c`: that of `aᵀ d`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Row<const K: usize> {
    pub a: [f32; K],
    pub c: f32,
}

/// The rows of a problem, read in place.
pub(crate) trait Rows<const K: usize> {
    /// How many.
    fn count(&self) -> usize;
    /// Row `i < count()`.
    fn row(&self, i: usize) -> Option<Row<K>>;
}

impl<const K: usize> Rows<K> for [Row<K>] {
    fn count(&self) -> usize {
        self.len()
    }
    fn row(&self, i: usize) -> Option<Row<K>> {
        self.get(i).copied()
    }
}

/// Solves the problem of the module docs into `out` (written only on
/// success; in place, not returned: a solution is 284 B at K = 5, and
/// each copy of it was stack). `g_mat` and `g` beyond `n` are ignored, as
/// are the rows' entries beyond `n`.
///
/// # Errors
/// [`QpError`]: `G` not definite, rows incompatible, or the cap reached.
pub(crate) fn solve<const K: usize, R: Rows<K> + ?Sized>(
    g_mat: &Mat<K>,
    g: &[f32; K],
    n: usize,
    rows: &R,
    out: &mut QpSolution<K>,
) -> Result<(), QpError> {
    let n = n.min(K);
    let m = rows.count().min(QP_ROWS);
    // Each row `i` is used as `(aᵢ, cᵢ) · scale[i]`: a unit gradient over
    // the first `n` variables (a row without one is ignored).
    let mut scale = [0.0_f32; QP_ROWS];
    for (i, s) in scale.iter_mut().enumerate().take(m) {
        let Some(r) = rows.row(i) else { continue };
        let len = libm::sqrtf(dot(&r.a, &r.a, n));
        *s = if len > TINY && len.is_finite() {
            1.0 / len
        } else {
            0.0
        };
    }
    let unit = |i: usize| -> Option<([f32; K], f32)> {
        let s = *scale.get(i)?;
        let r = rows.row(i)?;
        let mut a = [0.0; K];
        for (dst, &src) in a.iter_mut().zip(r.a.iter()).take(n) {
            *dst = src * s;
        }
        (s > 0.0).then_some((a, r.c * s))
    };
    let mut w = Work::start(g_mat, g, n)?;
    for _ in 0..ITERATIONS {
        // The most violated row not active.
        let mut worst: Option<(usize, f32)> = None;
        for i in 0..m {
            if w.active.contains(&i) {
                continue;
            }
            let Some((a, c)) = unit(i) else { continue };
            let s = dot(&a, &w.x, n) + c;
            if s < -VIOLATION && worst.is_none_or(|(_, v)| s < v) {
                worst = Some((i, s));
            }
        }
        let Some((p, _)) = worst else {
            w.solution(m, &scale, out);
            return Ok(());
        };
        let Some((np, cp)) = unit(p) else {
            return Err(QpError::Incompatible);
        };
        w.add(&np, cp, p)?;
    }
    Err(QpError::Iterations)
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use heapless::Vec;

    /// [`solve`], its solution returned.
    fn solve<const K: usize>(
        g_mat: &Mat<K>,
        g: &[f32; K],
        n: usize,
        rows: &[Row<K>],
    ) -> Result<QpSolution<K>, QpError> {
        let mut out = QpSolution::default();
        super::solve(g_mat, g, n, rows, &mut out).map(|()| out)
    }

    struct Lcg(u64);
    impl Lcg {
        fn unit(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn sym(&mut self) -> f64 {
            2.0 * self.unit() - 1.0
        }
    }

    /// Brute force in f64: every active set of at most `n` rows, its
    /// equality-constrained minimum, kept if feasible with multipliers
    /// >= 0; the least objective wins.
    fn brute(
        g_mat: &[[f64; 4]; 4],
        g: &[f64; 4],
        n: usize,
        rows: &[([f64; 4], f64)],
    ) -> Option<([f64; 4], f64)> {
        let m = rows.len();
        let mut best: Option<([f64; 4], f64)> = None;
        for mask in 0u32..(1 << m) {
            let act: Vec<usize, 16> = (0..m).filter(|i| mask >> i & 1 == 1).collect();
            if act.len() > n {
                continue;
            }
            // KKT: [G -Aᵀ; A 0] [d; λ] = [-g; -c] (at most 8 unknowns).
            let s = n + act.len();
            let mut kk = [[0.0f64; 9]; 8];
            for i in 0..n {
                for j in 0..n {
                    kk[i][j] = g_mat[i][j];
                }
                for (k, &r) in act.iter().enumerate() {
                    kk[i][n + k] = -rows[r].0[i];
                    kk[n + k][i] = rows[r].0[i];
                }
                kk[i][s] = -g[i];
            }
            for (k, &r) in act.iter().enumerate() {
                kk[n + k][s] = -rows[r].1;
            }
            // Gaussian elimination with pivoting.
            let mut ok = true;
            for c in 0..s {
                let p = (c..s)
                    .max_by(|&a, &b| kk[a][c].abs().total_cmp(&kk[b][c].abs()))
                    .unwrap();
                if kk[p][c].abs() < 1e-12 {
                    ok = false;
                    break;
                }
                kk.swap(c, p);
                for r in 0..s {
                    if r != c {
                        let f = kk[r][c] / kk[c][c];
                        for k in c..=s {
                            kk[r][k] -= f * kk[c][k];
                        }
                    }
                }
            }
            if !ok {
                continue;
            }
            let sol: [f64; 8] =
                core::array::from_fn(|i| if i < s { kk[i][s] / kk[i][i] } else { 0.0 });
            let d = &sol[..n];
            if sol[n..s].iter().any(|&l| l < -1e-9) {
                continue;
            }
            if rows
                .iter()
                .any(|(a, c)| (0..n).map(|i| a[i] * d[i]).sum::<f64>() + c < -1e-7)
            {
                continue;
            }
            let f: f64 = (0..n)
                .map(|i| 0.5 * d[i] * (0..n).map(|j| g_mat[i][j] * d[j]).sum::<f64>() + g[i] * d[i])
                .sum();
            if best.as_ref().is_none_or(|b| f < b.1) {
                best = Some((
                    core::array::from_fn(|i| d.get(i).copied().unwrap_or(0.0)),
                    f,
                ));
            }
        }
        best
    }

    #[test]
    fn matches_brute_force_on_random_problems() {
        let mut rng = Lcg(7);
        let mut solved = 0;
        for case in 0..400 {
            let n = 1 + (rng.unit() * 4.0) as usize;
            let m = (rng.unit() * 9.0) as usize;
            // G = BᵀB + small I, scaled over decades.
            let mut b = [[0.0f64; 4]; 4];
            for row in b.iter_mut() {
                for v in row.iter_mut() {
                    *v = rng.sym();
                }
            }
            let scale = 10f64.powf(rng.sym() * 3.0);
            let mut gm = [[0.0f64; 4]; 4];
            for i in 0..4 {
                for j in 0..4 {
                    gm[i][j] = scale
                        * ((0..4).map(|k| b[k][i] * b[k][j]).sum::<f64>()
                            + if i == j { 0.1 } else { 0.0 });
                }
            }
            let g: [f64; 4] = core::array::from_fn(|_| scale * 10.0 * rng.sym());
            let mut rows: Vec<([f64; 4], f64), 10> = (0..m)
                .map(|_| (core::array::from_fn(|_| rng.sym()), 5.0 * rng.sym()))
                .collect();
            // Near-parallel rows, as neighbouring segments of one track
            // give: a copy of a row nudged by 1e-3.
            if m > 0 && m < 9 && case % 3 == 0 {
                let (a, c) = rows[0];
                let _ = rows.push((a.map(|v| v + 1e-3 * rng.sym()), c + 1e-3 * rng.sym()));
            }
            let expect = brute(&gm, &g, n, &rows);
            let g_mat: Mat<4> = core::array::from_fn(|i| core::array::from_fn(|j| gm[i][j] as f32));
            let gv: [f32; 4] = core::array::from_fn(|i| g[i] as f32);
            let qrows: Vec<Row<4>, QP_ROWS> = rows
                .iter()
                .map(|(a, c)| Row {
                    a: a.map(|v| v as f32),
                    c: *c as f32,
                })
                .collect();
            let got = solve(&g_mat, &gv, n, &qrows[..]);
            match (expect, got) {
                (Some((d, _)), Ok(sol)) => {
                    solved += 1;
                    let dn = d.iter().map(|v| v.abs()).fold(1.0, f64::max);
                    for i in 0..n {
                        assert!(
                            (sol.d[i] as f64 - d[i]).abs() <= 2e-3 * dn,
                            "case {case}: d {:?} vs {d:?}",
                            sol.d
                        );
                    }
                    for i in n..4 {
                        assert_eq!(sol.d[i], 0.0);
                    }
                    assert!(sol.lambda.iter().all(|&l| l >= 0.0));
                }
                (None, Err(_)) => {}
                (e, g) => panic!("case {case}: brute {e:?}, solver {g:?}"),
            }
        }
        // (Most random problems have a solution: the test compares them.)
        assert!(solved > 250, "{solved} of 400 solved");
    }

    #[test]
    fn unconstrained_and_bound() {
        let g_mat: Mat<2> = [[2.0, 0.0], [0.0, 2.0]];
        let g = [-2.0, -4.0];
        let sol = solve(&g_mat, &g, 2, &[][..]).unwrap();
        assert!((sol.d[0] - 1.0).abs() < 1e-6 && (sol.d[1] - 2.0).abs() < 1e-6);
        // d1 <= 1: -d1 + 1 >= 0.
        let rows = [Row {
            a: [0.0, -1.0],
            c: 1.0,
        }];
        let sol = solve(&g_mat, &g, 2, &rows[..]).unwrap();
        assert!((sol.d[1] - 1.0).abs() < 1e-5, "{:?}", sol.d);
        assert!((sol.lambda[0] - 2.0).abs() < 1e-4, "{:?}", sol.lambda);
        // Incompatible: d0 >= 1 and d0 <= 0.
        let rows = [
            Row {
                a: [1.0, 0.0],
                c: -1.0,
            },
            Row {
                a: [-1.0, 0.0],
                c: 0.0,
            },
        ];
        assert_eq!(solve(&g_mat, &g, 2, &rows[..]), Err(QpError::Incompatible));
    }
}
