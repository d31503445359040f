//! The working state of the QP's dual active-set method (Goldfarb and
//! Idnani, [`super::qp`]): the factors `J = L⁻ᵀ Q` and `R`, kept up to
//! date by Givens rotations as a violated row enters and as active rows
//! whose multipliers would turn negative leave, and the solution they
//! give. `qp.rs` poses the problem and picks the rows that enter.

use heapless::Vec;

use super::dense::{Mat, at, backward, cholesky, dot, forward, put};

/// Most constraint rows of one problem.
pub(crate) const QP_ROWS: usize = 64;

/// A row whose gradient is shorter than this is ignored.
pub(super) const TINY: f32 = 1e-12;

/// Why the QP has no solution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum QpError {
    /// `G` is not positive definite (or not finite).
    NotDefinite,
    /// The constraints have no common point.
    Incompatible,
    /// The iteration cap came first.
    Iterations,
}

/// The solution: the step `d` and one multiplier per row (`λᵢ >= 0`,
/// zero for inactive rows), in the rows' own unit.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct QpSolution<const K: usize> {
    pub d: [f32; K],
    pub lambda: Vec<f32, QP_ROWS>,
}

impl<const K: usize> Default for QpSolution<K> {
    fn default() -> Self {
        Self {
            d: [0.0; K],
            lambda: Vec::new(),
        }
    }
}

/// The working state of the dual method.
pub(super) struct Work<const K: usize> {
    /// Variables used.
    n: usize,
    /// `J = L⁻ᵀ Q`: columns `0..q` span the active gradients.
    j: Mat<K>,
    /// Upper triangular `R` (`q × q` in the top left).
    r: Mat<K>,
    /// Active rows and their multipliers.
    pub(super) active: Vec<usize, K>,
    u: Vec<f32, K>,
    pub(super) x: [f32; K],
}

/// The Givens reflection `(c, s)` taking `(a, b)` to `(h, 0)`, `h >= 0`
/// (`√(a² + b²)` scaled by the larger magnitude against overflow, in f32:
/// libm's `hypotf` works in f64, which a Cortex-M4F does in software).
fn givens(a: f32, b: f32) -> (f32, f32, f32) {
    let m = libm::fabsf(a).max(libm::fabsf(b));
    if !(m > 0.0 && m.is_finite()) {
        return (1.0, 0.0, 0.0);
    }
    let (x, y) = (a / m, b / m);
    let h = m * libm::sqrtf(x * x + y * y);
    (a / h, b / h, h)
}

/// Columns `p`, `p + 1` of the first `n` rows of `m` reflected by
/// `(c, s)`: `(c x + s y, s x − c y)`.
fn reflect_columns<const K: usize>(m: &mut Mat<K>, n: usize, p: usize, (c, s): (f32, f32)) {
    let q = p.saturating_add(1);
    for row in m.iter_mut().take(n) {
        if let (Some(&x), Some(&y)) = (row.get(p), row.get(q)) {
            if let Some(e) = row.get_mut(p) {
                *e = c * x + s * y;
            }
            if let Some(e) = row.get_mut(q) {
                *e = s * x - c * y;
            }
        }
    }
}

impl<const K: usize> Work<K> {
    /// The unconstrained minimum `x = −G⁻¹ g`, `J = L⁻ᵀ`, nothing active.
    /// (Inlined into the solve, as when both were one file: out of line,
    /// the state it returns by value is a second copy on the QP's stack.)
    #[inline(always)]
    pub(super) fn start(g_mat: &Mat<K>, g: &[f32; K], n: usize) -> Result<Self, QpError> {
        let l = cholesky(g_mat, n).ok_or(QpError::NotDefinite)?;
        // Row i of J = L⁻ᵀ is L⁻¹ eᵢ.
        let mut j = [[0.0; K]; K];
        for (i, row) in j.iter_mut().enumerate().take(n) {
            let mut e = [0.0; K];
            if let Some(v) = e.get_mut(i) {
                *v = 1.0;
            }
            *row = forward(&l, &e, n);
        }
        let mut x = backward(&l, &forward(&l, g, n), n);
        x.iter_mut().for_each(|v| *v = -*v);
        if !x.iter().chain(j.iter().flatten()).all(|v| v.is_finite()) {
            return Err(QpError::NotDefinite);
        }
        Ok(Self {
            n,
            j,
            r: [[0.0; K]; K],
            active: Vec::new(),
            u: Vec::new(),
            x,
        })
    }

    /// Adds row `p` (`npᵀ x + cp >= 0`, currently violated): partial steps
    /// drop active rows until a full step satisfies it and it enters.
    pub(super) fn add(&mut self, np: &[f32; K], cp: f32, p: usize) -> Result<(), QpError> {
        let n = self.n;
        let mut u_new: f32 = 0.0;
        for _ in 0..=K {
            let q = self.active.len();
            // d = Jᵀ n_p.
            let mut d = [0.0_f32; K];
            for (k, dk) in d.iter_mut().enumerate().take(n) {
                *dk = (0..n).fold(0.0, |s, i| {
                    s + at(&self.j, i, k) * np.get(i).copied().unwrap_or(0.0)
                });
            }
            // Primal direction in the null space of the active rows.
            let mut z = [0.0_f32; K];
            for (i, zi) in z.iter_mut().enumerate().take(n) {
                *zi = (q..n).fold(0.0, |s, k| {
                    s + at(&self.j, i, k) * d.get(k).copied().unwrap_or(0.0)
                });
            }
            // Dual direction: R r = d₁.
            let r = self.back_substitute(&d, q);
            // Partial step: the first active multiplier to reach zero.
            let mut t1: Option<(f32, usize)> = None;
            for (k, (&uk, &rk)) in self.u.iter().zip(r.iter()).enumerate().take(q) {
                if rk > 0.0 {
                    let t = uk / rk;
                    if t1.is_none_or(|(best, _)| t < best) {
                        t1 = Some((t, k));
                    }
                }
            }
            let zn = dot(&z, np, n);
            let s = dot(np, &self.x, n) + cp;
            // Full step: the row satisfied exactly.
            let t2 = (zn > TINY).then(|| -s / zn);
            let (t, drop) = match (t1, t2) {
                (None, None) => return Err(QpError::Incompatible),
                (Some((a, k)), Some(b)) if a < b => (a, Some(k)),
                (Some((a, k)), None) => (a, Some(k)),
                (_, Some(b)) => (b, None),
            };
            if !t.is_finite() {
                return Err(QpError::Incompatible);
            }
            if t2.is_some() {
                for (xi, zi) in self.x.iter_mut().zip(z.iter()).take(n) {
                    *xi += t * zi;
                }
            }
            for (uk, &rk) in self.u.iter_mut().zip(r.iter()).take(q) {
                *uk -= t * rk;
            }
            u_new += t;
            match drop {
                None => return self.enter(d, p, u_new),
                Some(k) => self.leave(k),
            }
        }
        Err(QpError::Iterations)
    }

    /// `R⁻¹ d₁` over the `q` active rows.
    fn back_substitute(&self, d: &[f32; K], q: usize) -> [f32; K] {
        let mut r = [0.0_f32; K];
        for i in (0..q).rev() {
            let mut s = d.get(i).copied().unwrap_or(0.0);
            for k in i.saturating_add(1)..q {
                s -= at(&self.r, i, k) * r.get(k).copied().unwrap_or(0.0);
            }
            let rii = at(&self.r, i, i);
            if let Some(slot) = r.get_mut(i) {
                *slot = if rii != 0.0 { s / rii } else { 0.0 };
            }
        }
        r
    }

    /// Row `p` enters: `d = Jᵀ n_p` is rotated so that its entries past
    /// `q` vanish into entry `q`, which with `d₁` is `R`'s new column.
    fn enter(&mut self, mut d: [f32; K], p: usize, u: f32) -> Result<(), QpError> {
        let q = self.active.len();
        let mut k = self.n.saturating_sub(1);
        while k > q {
            let below = k.saturating_sub(1);
            let (a, b) = (
                d.get(below).copied().unwrap_or(0.0),
                d.get(k).copied().unwrap_or(0.0),
            );
            if b != 0.0 {
                let (c, s, h) = givens(a, b);
                reflect_columns(&mut self.j, self.n, below, (c, s));
                if let Some(e) = d.get_mut(below) {
                    *e = h;
                }
                if let Some(e) = d.get_mut(k) {
                    *e = 0.0;
                }
            }
            k = below;
        }
        let rqq = d.get(q).copied().unwrap_or(0.0);
        if libm::fabsf(rqq) <= TINY {
            // Dependent on the active rows: cannot enter.
            return Err(QpError::Incompatible);
        }
        for (i, &di) in d.iter().enumerate().take(q.saturating_add(1)) {
            put(&mut self.r, i, q, di);
        }
        self.active.push(p).map_err(|_| QpError::Iterations)?;
        self.u.push(u).map_err(|_| QpError::Iterations)?;
        Ok(())
    }

    /// Active row `k` leaves: its column of `R` is removed and `R`
    /// brought back to triangular form by reflections of rows (and of
    /// `J`'s columns) `i, i + 1`, `i >= k`.
    fn leave(&mut self, k: usize) {
        let q = self.active.len();
        if k >= q {
            return;
        }
        for row in self.r.iter_mut().take(q) {
            for col in k..q.saturating_sub(1) {
                let next = row.get(col.saturating_add(1)).copied().unwrap_or(0.0);
                if let Some(e) = row.get_mut(col) {
                    *e = next;
                }
            }
            if let Some(e) = row.get_mut(q.saturating_sub(1)) {
                *e = 0.0;
            }
        }
        // (By hand: `remove` asserts its index, and moves by `memmove`.)
        for i in k..q.saturating_sub(1) {
            let next = i.saturating_add(1);
            if let (Some(&a), Some(&u)) = (self.active.get(next), self.u.get(next)) {
                if let Some(slot) = self.active.get_mut(i) {
                    *slot = a;
                }
                if let Some(slot) = self.u.get_mut(i) {
                    *slot = u;
                }
            }
        }
        self.active.truncate(q.saturating_sub(1));
        self.u.truncate(q.saturating_sub(1));
        let q = q.saturating_sub(1);
        for i in k..q {
            let next = i.saturating_add(1);
            let (a, b) = (at(&self.r, i, i), at(&self.r, next, i));
            if b == 0.0 {
                continue;
            }
            let (c, s, _) = givens(a, b);
            for col in i..q {
                let (x, y) = (at(&self.r, i, col), at(&self.r, next, col));
                put(&mut self.r, i, col, c * x + s * y);
                put(&mut self.r, next, col, s * x - c * y);
            }
            reflect_columns(&mut self.j, self.n, i, (c, s));
        }
    }

    /// The step and the multipliers in the rows' own units, into `out`.
    pub(super) fn solution(&self, m: usize, scale: &[f32; QP_ROWS], out: &mut QpSolution<K>) {
        out.d = self.x;
        out.lambda.clear();
        for _ in 0..m {
            let _ = out.lambda.push(0.0);
        }
        for (&i, &u) in self.active.iter().zip(self.u.iter()) {
            if let (Some(l), Some(&s)) = (out.lambda.get_mut(i), scale.get(i)) {
                *l = u * s;
            }
        }
    }
}
