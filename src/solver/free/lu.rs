//! A dense LU factorisation with partial pivoting that works in place on preallocated
//! storage, so that the per-step saddle-point solves of the free-body methods never
//! allocate. The systems are small (18 to 24 unknowns for the explicit scheme, a few
//! dozen for the implicit one), where a plain row-major loop is as fast as anything.

/// In-place LU factorisation `P A = L U` of a square matrix, row-major.
#[derive(Debug, Clone)]
pub(crate) struct Lu {
    n: usize,
    a: Vec<f64>,
    piv: Vec<usize>,
}

impl Lu {
    /// Storage for `n x n` systems.
    pub(crate) fn new(n: usize) -> Lu {
        Lu {
            n,
            a: vec![0.0; n * n],
            piv: vec![0; n],
        }
    }

    /// Set every entry to zero before filling a new matrix.
    pub(crate) fn clear(&mut self) {
        self.a.iter_mut().for_each(|v| *v = 0.0);
    }

    /// Mutable access to entry (i, j) of the matrix being filled.
    #[inline]
    pub(crate) fn at(&mut self, i: usize, j: usize) -> &mut f64 {
        &mut self.a[i * self.n + j]
    }

    /// Mutable row `i` of the matrix being filled.
    #[inline]
    pub(crate) fn row_mut(&mut self, i: usize) -> &mut [f64] {
        &mut self.a[i * self.n..(i + 1) * self.n]
    }

    /// Factor in place. Returns the ratio of the smallest to the largest pivot magnitude
    /// (0 for an exactly singular matrix); the caller decides what counts as singular.
    pub(crate) fn factor(&mut self) -> f64 {
        let n = self.n;
        let a = &mut self.a;
        let mut pmin = f64::INFINITY;
        let mut pmax = 0.0f64;
        for k in 0..n {
            // Largest magnitude in column k at or below the diagonal (first one on ties).
            let mut best = k;
            let mut bval = a[k * n + k].abs();
            for i in k + 1..n {
                let v = a[i * n + k].abs();
                if v > bval {
                    best = i;
                    bval = v;
                }
            }
            self.piv[k] = best;
            if best != k {
                let (upper, lower) = a.split_at_mut(best * n);
                upper[k * n..(k + 1) * n].swap_with_slice(&mut lower[..n]);
            }
            pmin = pmin.min(bval);
            pmax = pmax.max(bval);
            if bval == 0.0 {
                continue;
            }
            let d = a[k * n + k];
            // Row k is above every row i > k: split there so that both are plain slices.
            let (top, bottom) = a.split_at_mut((k + 1) * n);
            let pivot_row = &top[k * n + k + 1..(k + 1) * n];
            for row in bottom.chunks_exact_mut(n) {
                let l = row[k] / d;
                row[k] = l;
                if l != 0.0 {
                    for (x, &y) in row[k + 1..].iter_mut().zip(pivot_row) {
                        *x -= l * y;
                    }
                }
            }
        }
        if n == 0 || pmax == 0.0 {
            return if n == 0 { 1.0 } else { 0.0 };
        }
        pmin / pmax
    }

    /// Solve `A x = b` in place with the factors of the last [`Lu::factor`].
    pub(crate) fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        let a = &self.a;
        for (k, &pk) in self.piv.iter().enumerate() {
            b.swap(k, pk);
        }
        for i in 0..n {
            let row = &a[i * n..i * n + i];
            let mut s = b[i];
            for (&x, &y) in row.iter().zip(&b[..i]) {
                s -= x * y;
            }
            b[i] = s;
        }
        for i in (0..n).rev() {
            let row = &a[i * n + i + 1..(i + 1) * n];
            let mut s = b[i];
            for (&x, &y) in row.iter().zip(&b[i + 1..n]) {
                s -= x * y;
            }
            b[i] = s / a[i * n + i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Lu;

    /// A 3x3 system that needs a row exchange, against its hand-computed solution.
    #[test]
    fn solves_with_pivoting() {
        let m = [[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [2.0, 0.0, 3.0]];
        let mut lu = Lu::new(3);
        for (i, row) in m.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                *lu.at(i, j) = *v;
            }
        }
        assert!(lu.factor() > 0.1);
        // x = (1, 2, 3): b = (7, 3, 11).
        let mut b = [7.0, 3.0, 11.0];
        lu.solve(&mut b);
        for (x, e) in b.iter().zip([1.0, 2.0, 3.0]) {
            assert!((x - e).abs() < 1e-14, "{x} vs {e}");
        }
    }
}
