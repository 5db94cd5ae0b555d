//! The dense steps of the eigen-solver and the static modes, done by faer with a fixed
//! split of the work ([`crate::par`]): products of tall blocks, and the
//! eigen-decomposition of the small projected matrices.
//!
//! faer 0.22's symmetric eigen-solver (divide and conquer) stops its secular-equation
//! root finder on an absolute tolerance, so it is accurate only for a matrix of norm
//! near 1; [`sym_eigen`] scales its input to an infinity norm of 1 first (a shift-invert
//! Lanczos matrix has entries of 1/lambda, 1e-8 and smaller).

use faer::linalg::evd::ComputeEigenvectors;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par};

use crate::par::threads;

/// Rows per half when a tall product is split over [`threads`] threads, or `None` when
/// it is too small to be worth it. The split depends only on the shape.
fn halves(rows: usize, work: usize) -> Option<usize> {
    (threads() > 1 && rows >= 2 && work >= 1 << 16).then_some(rows / 2)
}

/// `a^T b` for tall `a` and `b` (`n x m`, `n x k`, n large). faer's own parallel split of
/// this shape (a long inner dimension) is 10-30x slower than one thread; here the rows
/// are cut in two fixed halves, each product runs on one thread, and the two are added
/// in a fixed order: the same bits whatever the pool.
pub fn at_b(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let seq = |a: MatRef<'_, f64>, b: MatRef<'_, f64>| {
        let mut c = Mat::zeros(a.ncols(), b.ncols());
        matmul(c.as_mut(), Accum::Replace, a.transpose(), b, 1.0, Par::Seq);
        c
    };
    match halves(a.nrows(), a.nrows() * a.ncols() * b.ncols()) {
        Some(h) => {
            let (top, bottom) = rayon::join(
                || seq(a.subrows(0, h), b.subrows(0, h)),
                || seq(a.subrows(h, a.nrows() - h), b.subrows(h, b.nrows() - h)),
            );
            top + bottom
        }
        None => seq(a, b),
    }
}

/// `c += alpha a b` for tall `a` (`n x m`, n large), the rows in two fixed halves on two
/// threads (see [`at_b`]).
fn add_ab(c: MatMut<'_, f64>, a: MatRef<'_, f64>, b: MatRef<'_, f64>, alpha: f64) {
    let accum = |c: MatMut<'_, f64>, a: MatRef<'_, f64>| {
        matmul(c, Accum::Add, a, b, alpha, Par::Seq);
    };
    match halves(a.nrows(), a.nrows() * a.ncols() * b.ncols()) {
        Some(h) => {
            let n = a.nrows();
            let (ct, cb) = c.split_at_row_mut(h);
            rayon::join(
                || accum(ct, a.subrows(0, h)),
                || accum(cb, a.subrows(h, n - h)),
            );
        }
        None => accum(c, a),
    }
}

/// `a b`, for tall `a`.
pub fn ab(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let mut c = Mat::zeros(a.nrows(), b.ncols());
    add_ab(c.as_mut(), a, b, 1.0);
    c
}

/// `c -= a b`, for tall `a`.
pub fn sub_ab(c: MatMut<'_, f64>, a: MatRef<'_, f64>, b: MatRef<'_, f64>) {
    add_ab(c, a, b, -1.0);
}

/// Eigenvalues (ascending) and orthonormal eigenvectors (one column each, same order) of
/// the symmetric `a` (its lower triangle is read), computed on `a` scaled to an infinity
/// norm of 1; `None` for a non-finite matrix or if the solver does not converge.
pub fn sym_eigen(a: MatRef<'_, f64>) -> Option<(Vec<f64>, Mat<f64>)> {
    let n = a.nrows();
    if n == 0 {
        return Some((Vec::new(), Mat::zeros(0, 0)));
    }
    let norm = (0..n)
        .map(|i| (0..n).map(|j| a[(i.max(j), i.min(j))].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    if !norm.is_finite() {
        return None;
    }
    let s = if norm > 0.0 { 1.0 / norm } else { 1.0 };
    let scaled = Mat::from_fn(n, n, |i, j| a[(i.max(j), i.min(j))] * s);
    crate::dense::evd_of_scaled(scaled.as_ref(), s, ComputeEigenvectors::Yes)
}

/// A deterministic block of pseudo-random values in [-1, 1) (xorshift64*, seeded): start
/// vectors that are the same on every machine.
pub fn random_block(n: usize, b: usize, seed: u64) -> Mat<f64> {
    let mut x = seed ^ 0x9e37_79b9_7f4a_7c15;
    if x == 0 {
        x = 1;
    }
    Mat::from_fn(n, b, |_, _| {
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        let r = x.wrapping_mul(0x2545_f491_4f6c_dd1d);
        (r >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigenpairs_of_a_badly_scaled_matrix() {
        // diag(1, 2, 3) * 1e-9, rotated: eigenvalues kept to rounding.
        let c = (0.3f64).cos();
        let s = (0.3f64).sin();
        let q = Mat::from_fn(3, 3, |i, j| match (i, j) {
            (0, 0) | (1, 1) => c,
            (0, 1) => -s,
            (1, 0) => s,
            (2, 2) => 1.0,
            _ => 0.0,
        });
        let d = Mat::from_fn(
            3,
            3,
            |i, j| if i == j { (i + 1) as f64 * 1e-9 } else { 0.0 },
        );
        let a = ab(ab(q.as_ref(), d.as_ref()).as_ref(), q.transpose());
        let (w, v) = sym_eigen(a.as_ref()).unwrap();
        for (k, w) in w.iter().enumerate() {
            assert!((w / ((k + 1) as f64 * 1e-9) - 1.0).abs() < 1e-14, "{w}");
        }
        let av = ab(a.as_ref(), v.as_ref());
        for k in 0..3 {
            for i in 0..3 {
                assert!((av[(i, k)] - w[k] * v[(i, k)]).abs() < 1e-23);
            }
        }
    }
}
