//! Small dense kernels on plain column-major slices, written so that the inner loops run
//! over contiguous memory without bounds checks: a dot product, a register-blocked
//! matrix-vector update, and the bilinear (and quadratic) form for energies.

use nalgebra::DMatrix;

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
/// `out` is read and written once and each column block is one contiguous load. Columns
/// whose `x` entry is zero are skipped (and when at most a quarter of `x` is nonzero, the
/// nonzero columns are added one by one): a load usually acts on few of the exposed
/// components (one force on one node), and a skipped term would add exactly zero, so the
/// bits are those of the full product either way.
#[inline]
pub fn gemv_acc(a: &[f64], x: &[f64], out: &mut [f64]) {
    let n = out.len();
    if n == 0 {
        return;
    }
    if 4 * x.iter().filter(|&&xj| xj != 0.0).count() <= x.len() {
        // Mostly zeros: one contiguous update per nonzero column is cheaper than
        // walking every column for every row block. Same terms, same order per row.
        for (col, &xj) in a.chunks_exact(n).zip(x) {
            if xj != 0.0 {
                for (o, &c) in out.iter_mut().zip(col) {
                    *o += c * xj;
                }
            }
        }
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
        if xj == 0.0 {
            continue;
        }
        let c = &col[r0..r0 + B];
        for r in 0..B {
            acc[r] += c[r] * xj;
        }
    }
    out[r0..r0 + B].copy_from_slice(&acc);
}

/// `x^T a y` for the column-major `a` (`x.len()` rows, `y.len()` columns) without
/// temporaries: energy outputs may be read at every communication step, where nothing
/// may allocate. The quadratic form `x^T k x` is `bilinear(k, x, x)`.
pub fn bilinear(a: &DMatrix<f64>, x: &[f64], y: &[f64]) -> f64 {
    debug_assert_eq!((a.nrows(), a.ncols()), (x.len(), y.len()));
    let mut total = 0.0;
    for (j, &yj) in y.iter().enumerate() {
        let col = a.column(j);
        let mut s = 0.0;
        for (i, &xi) in x.iter().enumerate() {
            s += col[i] * xi;
        }
        total += s * yj;
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    #[test]
    fn kernels_match_nalgebra() {
        // Against nalgebra's own products on sizes that exercise every block and
        // remainder path (tolerance 1e-13 relative).
        for (rows, cols) in [(1, 1), (3, 5), (12, 20), (13, 7), (21, 4)] {
            let a = DMatrix::from_fn(rows, cols, |i, j| ((i * 7 + j * 3) % 11) as f64 - 5.0);
            let x = DVector::from_fn(cols, |i, _| 0.5 * i as f64 - 1.0);
            let z = DVector::from_fn(rows, |i, _| 1.0 - 0.25 * i as f64);
            let mut out = z.clone();
            gemv_acc(a.as_slice(), x.as_slice(), out.as_mut_slice());
            let want = &z + &a * &x;
            assert!((out - &want).amax() <= 1e-13 * want.amax().max(1.0));
            // With a few zeros (blocked path) and with one nonzero (column path): skipping
            // columns changes no bit of the column-order sum.
            let mut few = x.clone();
            few[cols / 2] = 0.0;
            few[0] = -0.0;
            let one = DVector::from_fn(cols, |i, _| if i == cols - 1 { 1.5 } else { 0.0 });
            for xs in [few, one] {
                let mut skipped = z.clone();
                gemv_acc(a.as_slice(), xs.as_slice(), skipped.as_mut_slice());
                let mut full = z.clone();
                for j in 0..cols {
                    for i in 0..rows {
                        full[i] += a[(i, j)] * xs[j];
                    }
                }
                assert_eq!(skipped, full);
            }
            let d = dot(&a.as_slice()[..rows], z.as_slice());
            let dw = a.column(0).dot(&z);
            assert!((d - dw).abs() <= 1e-13 * dw.abs().max(1.0));
        }
        let k = DMatrix::from_fn(4, 4, |i, j| 1.0 / (1 + i + j) as f64);
        let x = DVector::from_fn(4, |i, _| i as f64 - 1.5);
        let q = bilinear(&k, x.as_slice(), x.as_slice());
        assert!((q - x.dot(&(&k * &x))).abs() < 1e-13 * q.abs());
        let r = DMatrix::from_fn(3, 4, |i, j| (i as f64 + 1.0) * 0.5 - j as f64);
        let u = DVector::from_fn(3, |i, _| 2.0 - i as f64);
        let b = bilinear(&r, u.as_slice(), x.as_slice());
        assert!((b - u.dot(&(&r * &x))).abs() < 1e-13 * b.abs().max(1.0));
    }
}
