//! Small dense linear algebra for the SQP ([`super::sqp`], [`super::qp`])
//! on the leading `n × n` block of a row-major `[[f32; K]; K]`: loops
//! bounded by `n`, not unrolled to `K` (compact firmware), and every sum
//! in index order, so that a problem padded to a larger `K` computes the
//! same bits.

/// A `K × K` matrix, row-major.
pub(crate) type Mat<const K: usize> = [[f32; K]; K];

/// Entry `(i, j)`, 0 outside.
#[inline]
pub(crate) fn at<const K: usize>(m: &Mat<K>, i: usize, j: usize) -> f32 {
    m.get(i).and_then(|r| r.get(j)).copied().unwrap_or(0.0)
}

/// Sets entry `(i, j)` (nothing outside).
#[inline]
pub(crate) fn put<const K: usize>(m: &mut Mat<K>, i: usize, j: usize, v: f32) {
    if let Some(e) = m.get_mut(i).and_then(|r| r.get_mut(j)) {
        *e = v;
    }
}

/// `aᵀb` over the first `n` entries, in index order.
#[inline]
pub(crate) fn dot(a: &[f32], b: &[f32], n: usize) -> f32 {
    a.iter()
        .zip(b.iter())
        .take(n)
        .fold(0.0, |s, (x, y)| s + x * y)
}

/// `m v` over the leading block (zero past `n`).
pub(crate) fn mul<const K: usize>(m: &Mat<K>, v: &[f32; K], n: usize) -> [f32; K] {
    let mut out = [0.0; K];
    for (o, row) in out.iter_mut().zip(m.iter()).take(n) {
        *o = dot(row, v, n);
    }
    out
}

/// The Cholesky factor `L` (lower) of the leading block of `a`: `L Lᵀ = a`;
/// `None` when it is not positive definite or not finite.
pub(crate) fn cholesky<const K: usize>(a: &Mat<K>, n: usize) -> Option<Mat<K>> {
    let mut l = [[0.0; K]; K];
    for j in 0..n {
        let row_j = *l.get(j)?;
        let d = at(a, j, j) - dot(&row_j, &row_j, j);
        if !(d > 0.0 && d.is_finite()) {
            return None;
        }
        let ljj = libm::sqrtf(d);
        put(&mut l, j, j, ljj);
        for i in j.saturating_add(1)..n {
            let row_i = *l.get(i)?;
            let v = (at(a, i, j) - dot(&row_i, &row_j, j)) / ljj;
            put(&mut l, i, j, v);
        }
    }
    Some(l)
}

/// `L⁻¹ b` (forward substitution; `L` lower, non-zero diagonal).
pub(crate) fn forward<const K: usize>(l: &Mat<K>, b: &[f32; K], n: usize) -> [f32; K] {
    let mut y = [0.0; K];
    for i in 0..n {
        let row = l.get(i).copied().unwrap_or([0.0; K]);
        let s = b.get(i).copied().unwrap_or(0.0) - dot(&row, &y, i);
        if let Some(slot) = y.get_mut(i) {
            *slot = s / at(l, i, i);
        }
    }
    y
}

/// `L⁻ᵀ y` (back substitution on `Lᵀ`).
pub(crate) fn backward<const K: usize>(l: &Mat<K>, y: &[f32; K], n: usize) -> [f32; K] {
    let mut x = [0.0; K];
    for i in (0..n).rev() {
        let mut s = y.get(i).copied().unwrap_or(0.0);
        for k in i.saturating_add(1)..n {
            s -= at(l, k, i) * x.get(k).copied().unwrap_or(0.0);
        }
        if let Some(slot) = x.get_mut(i) {
            *slot = s / at(l, i, i);
        }
    }
    x
}

/// Powell's damped BFGS update of `a` for step `s` and Lagrangian gradient
/// change `y` over the first `n` variables; returns whether it was made.
pub(crate) fn damped_update<const K: usize>(
    a: &mut Mat<K>,
    s: &[f32; K],
    y: &[f32; K],
    n: usize,
) -> bool {
    let bs = mul(a, s, n);
    let sbs = dot(s, &bs, n);
    let sy = dot(s, y, n);
    if !(sbs > 0.0 && sbs.is_finite() && sy.is_finite()) {
        return false;
    }
    let theta = if sy >= 0.2 * sbs {
        1.0
    } else {
        0.8 * sbs / (sbs - sy)
    };
    let r: [f32; K] = core::array::from_fn(|i| {
        theta * y.get(i).copied().unwrap_or(0.0) + (1.0 - theta) * bs.get(i).copied().unwrap_or(0.0)
    });
    let sr = dot(s, &r, n);
    if sr.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
        return false;
    }
    let mut next = *a;
    for i in 0..n {
        for j in 0..n {
            let (ri, rj) = (
                r.get(i).copied().unwrap_or(0.0),
                r.get(j).copied().unwrap_or(0.0),
            );
            let (bi, bj) = (
                bs.get(i).copied().unwrap_or(0.0),
                bs.get(j).copied().unwrap_or(0.0),
            );
            put(&mut next, i, j, at(a, i, j) + ri * rj / sr - bi * bj / sbs);
        }
    }
    if !next.iter().flatten().all(|v| v.is_finite()) {
        return false;
    }
    // Symmetric against rounding.
    for i in 0..n {
        for j in 0..i {
            let m = 0.5 * (at(&next, i, j) + at(&next, j, i));
            put(&mut next, i, j, m);
            put(&mut next, j, i, m);
        }
    }
    *a = next;
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cholesky_solves() {
        let a: Mat<3> = [[4.0, 2.0, 0.4], [2.0, 5.0, 1.0], [0.4, 1.0, 3.0]];
        let l = cholesky(&a, 3).unwrap();
        let b = [1.0, -2.0, 0.5];
        let x = backward(&l, &forward(&l, &b, 3), 3);
        let ax = mul(&a, &x, 3);
        for i in 0..3 {
            assert!((ax[i] - b[i]).abs() < 1e-6, "{ax:?}");
        }
        assert!(cholesky(&[[1.0, 2.0], [2.0, 1.0]], 2).is_none());
        // The leading block only.
        let l2 = cholesky(&a, 2).unwrap();
        assert_eq!(l2[2], [0.0; 3]);
    }
}
