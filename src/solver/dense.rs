//! Small dense kernels that work in storage allocated once: an in-place Cholesky
//! factorisation with its solve, and the quadratic form for energies.

use nalgebra::{DMatrix, DVector};

/// Factorise the symmetric positive definite `a` in place: on return its strict lower
/// triangle holds L with `a = L L^T` and its diagonal holds `1 / L_jj` (so the solve
/// multiplies instead of dividing on its critical path); the strict upper triangle is
/// left as it was. Fails with the column whose pivot is not positive.
pub fn cholesky_in_place(a: &mut DMatrix<f64>) -> Result<(), usize> {
    let n = a.nrows();
    for j in 0..n {
        let mut d = a[(j, j)];
        for k in 0..j {
            d -= a[(j, k)] * a[(j, k)];
        }
        if d <= 0.0 || !d.is_finite() {
            return Err(j);
        }
        let inv = 1.0 / d.sqrt();
        a[(j, j)] = inv;
        for i in j + 1..n {
            let mut s = a[(i, j)];
            for k in 0..j {
                s -= a[(i, k)] * a[(j, k)];
            }
            a[(i, j)] = s * inv;
        }
    }
    Ok(())
}

/// Solve `L L^T x = b` in place (`l` from [`cholesky_in_place`]).
pub fn cholesky_solve(l: &DMatrix<f64>, b: &mut DVector<f64>) {
    let n = l.nrows();
    let s = l.as_slice();
    // Forward: L y = b; column-oriented so that the inner loop runs down a column.
    let b = b.as_mut_slice();
    for j in 0..n {
        let yj = b[j] * s[j * n + j];
        b[j] = yj;
        let col = &s[j * n + j + 1..(j + 1) * n];
        for (bi, &lij) in b[j + 1..].iter_mut().zip(col) {
            *bi -= lij * yj;
        }
    }
    // Backward: L^T x = y; row i of L^T is column i of L.
    for i in (0..n).rev() {
        let col = &s[i * n + i + 1..(i + 1) * n];
        let t = b[i] - dot(col, &b[i + 1..]);
        b[i] = t * s[i * n + i];
    }
}

/// Dot product with four independent partial sums, so that the additions pipeline
/// instead of waiting on one another.
#[inline]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    let mut tail = 0.0;
    for (x, y) in ra.iter().zip(rb) {
        tail += x * y;
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// `out += a x` for the column-major `a` (`out.len()` rows, `x.len()` columns). Rows are
/// taken in blocks of 8 (then 4, then 1) held in registers across all columns, so that
/// `out` is read and written once and each column block is one contiguous load.
#[inline]
pub fn gemv_acc(a: &[f64], x: &[f64], out: &mut [f64]) {
    let n = out.len();
    if n == 0 {
        return;
    }
    let mut r0 = 0;
    while r0 + 8 <= n {
        gemv_block::<8>(a, n, r0, x, out);
        r0 += 8;
    }
    if r0 + 4 <= n {
        gemv_block::<4>(a, n, r0, x, out);
        r0 += 4;
    }
    while r0 < n {
        gemv_block::<1>(a, n, r0, x, out);
        r0 += 1;
    }
}

/// Rows `r0..r0 + B` of [`gemv_acc`].
#[inline(always)]
fn gemv_block<const B: usize>(a: &[f64], lda: usize, r0: usize, x: &[f64], out: &mut [f64]) {
    let mut acc = [0.0; B];
    acc.copy_from_slice(&out[r0..r0 + B]);
    for (col, &xj) in a.chunks_exact(lda).zip(x) {
        let c = &col[r0..r0 + B];
        for r in 0..B {
            acc[r] += c[r] * xj;
        }
    }
    out[r0..r0 + B].copy_from_slice(&acc);
}

/// `x^T k x` without temporaries.
pub fn quadratic(k: &DMatrix<f64>, x: &DVector<f64>) -> f64 {
    let n = x.len();
    let mut total = 0.0;
    for j in 0..n {
        let col = k.column(j);
        let mut s = 0.0;
        for i in 0..n {
            s += col[i] * x[i];
        }
        total += s * x[j];
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cholesky_solves_a_known_system() {
        // A = B^T B + I; check A x = b by multiplying back (tolerance 1e-12 relative).
        let n = 7;
        let b = DMatrix::from_fn(n, n, |i, j| ((i * 3 + j * 5) % 7) as f64 - 3.0);
        let a = b.transpose() * &b + DMatrix::identity(n, n);
        let rhs = DVector::from_fn(n, |i, _| i as f64 - 2.5);
        let mut l = a.clone();
        cholesky_in_place(&mut l).unwrap();
        let mut x = rhs.clone();
        cholesky_solve(&l, &mut x);
        let r = &a * &x - &rhs;
        assert!(r.norm() < 1e-12 * rhs.norm() * a.norm(), "{}", r.norm());
        let q = quadratic(&a, &x);
        assert!((q - x.dot(&(&a * &x))).abs() < 1e-12 * q.abs());
    }

    #[test]
    fn cholesky_refuses_an_indefinite_matrix() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        let mut l = a.clone();
        assert_eq!(cholesky_in_place(&mut l), Err(1));
    }
}
