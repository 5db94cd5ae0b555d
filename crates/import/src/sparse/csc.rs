//! [`SymCsc`]: a symmetric matrix stored by its upper triangle, column by column
//! (compressed sparse columns), the form faer's sparse factorisation reads and the one
//! CalculiX writes its matrices in. Memory: 16 bytes per stored term plus 8 per column.

use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{MatMut, MatRef};

use crate::sparse::error::SolveError;

/// A symmetric `n x n` matrix by its upper triangle (row <= column, diagonal included),
/// compressed by columns: column `j`'s terms are `row_idx[col_ptr[j]..col_ptr[j + 1]]`
/// (strictly increasing rows, all <= j) with `values` alongside. Terms that are stored
/// but zero are kept: they carry the pattern a sum `K - sigma M` needs.
#[derive(Debug, Clone, PartialEq)]
pub struct SymCsc {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
}

impl SymCsc {
    /// The matrix from its upper-triangle columns; checks the layout (pointer lengths and
    /// order, rows sorted, unique and in the upper triangle) and says what is wrong.
    pub fn from_parts(
        n: usize,
        col_ptr: Vec<usize>,
        row_idx: Vec<usize>,
        values: Vec<f64>,
    ) -> Result<SymCsc, SolveError> {
        let bad = |m: String| Err(SolveError::Input(format!("compressed columns: {m}")));
        if col_ptr.len() != n + 1 || col_ptr[0] != 0 {
            return bad(format!("{} column pointers for {n} columns", col_ptr.len()));
        }
        if col_ptr[n] != row_idx.len() || row_idx.len() != values.len() {
            return bad(format!(
                "last pointer {} but {} rows and {} values",
                col_ptr[n],
                row_idx.len(),
                values.len()
            ));
        }
        for j in 0..n {
            if col_ptr[j] > col_ptr[j + 1] {
                return bad(format!("column pointers decrease at column {j}"));
            }
            let rows = &row_idx[col_ptr[j]..col_ptr[j + 1]];
            if rows.windows(2).any(|w| w[0] >= w[1]) || rows.last().is_some_and(|&r| r > j) {
                return bad(format!(
                    "column {j}: rows not strictly increasing or below the diagonal"
                ));
            }
        }
        Ok(SymCsc {
            n,
            col_ptr,
            row_idx,
            values,
        })
    }

    /// The upper triangle of a dense symmetric matrix (row-major `n x n`), terms whose
    /// value is exactly zero left out except on the diagonal: for tests and small models.
    pub fn from_dense(n: usize, a: &[f64]) -> SymCsc {
        let mut col_ptr = vec![0];
        let (mut row_idx, mut values) = (Vec::new(), Vec::new());
        for j in 0..n {
            for i in 0..=j {
                let v = a[i * n + j];
                if v != 0.0 || i == j {
                    row_idx.push(i);
                    values.push(v);
                }
            }
            col_ptr.push(row_idx.len());
        }
        SymCsc {
            n,
            col_ptr,
            row_idx,
            values,
        }
    }

    /// Rows and columns.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Stored terms (upper triangle with the diagonal).
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    /// Column pointers (`n + 1`).
    pub fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }

    /// Row of each stored term.
    pub fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }

    /// Value of each stored term.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The value at `(i, j)` (either triangle; 0 when not stored).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (i, j) = (i.min(j), i.max(j));
        let rows = &self.row_idx[self.col_ptr[j]..self.col_ptr[j + 1]];
        rows.binary_search(&i)
            .map_or(0.0, |k| self.values[self.col_ptr[j] + k])
    }

    /// The diagonal.
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.n).map(|j| self.get(j, j)).collect()
    }

    /// The largest absolute stored value (0 for an empty matrix).
    pub fn max_abs(&self) -> f64 {
        self.values.iter().fold(0.0, |m, v| m.max(v.abs()))
    }

    /// The first stored term that is not finite, as (row, column).
    pub fn first_non_finite(&self) -> Option<(usize, usize)> {
        let k = self.values.iter().position(|v| !v.is_finite())?;
        let j = self.col_ptr.partition_point(|&p| p <= k) - 1;
        Some((self.row_idx[k], j))
    }

    /// faer's view of the stored triangle (upper, [`faer::Side::Upper`]).
    pub fn as_faer(&self) -> SparseColMatRef<'_, usize, f64> {
        // The layout was checked when the matrix was made (from_parts), so this cannot
        // fail; faer checks it again.
        let symbolic = SymbolicSparseColMatRef::new_checked(
            self.n,
            self.n,
            &self.col_ptr,
            None,
            &self.row_idx,
        );
        SparseColMatRef::new(symbolic, &self.values)
    }

    /// `self + s other` over the union of the two patterns (the same pattern, as
    /// CalculiX writes K and M, costs one pass over the values).
    pub fn add_scaled(&self, s: f64, other: &SymCsc) -> Result<SymCsc, SolveError> {
        if self.n != other.n {
            return Err(SolveError::Size(format!(
                "adding a {}-row matrix to a {}-row one",
                other.n, self.n
            )));
        }
        if self.col_ptr == other.col_ptr && self.row_idx == other.row_idx {
            let values = self
                .values
                .iter()
                .zip(&other.values)
                .map(|(a, b)| a + s * b)
                .collect();
            return Ok(SymCsc {
                values,
                ..self.clone()
            });
        }
        let mut col_ptr = Vec::with_capacity(self.n + 1);
        col_ptr.push(0);
        let cap = self.nnz().max(other.nnz());
        let (mut row_idx, mut values) = (Vec::with_capacity(cap), Vec::with_capacity(cap));
        for j in 0..self.n {
            let (mut a, ae) = (self.col_ptr[j], self.col_ptr[j + 1]);
            let (mut b, be) = (other.col_ptr[j], other.col_ptr[j + 1]);
            while a < ae || b < be {
                let ra = if a < ae { self.row_idx[a] } else { usize::MAX };
                let rb = if b < be { other.row_idx[b] } else { usize::MAX };
                let r = ra.min(rb);
                let mut v = 0.0;
                if ra == r {
                    v += self.values[a];
                    a += 1;
                }
                if rb == r {
                    v += s * other.values[b];
                    b += 1;
                }
                row_idx.push(r);
                values.push(v);
            }
            col_ptr.push(row_idx.len());
        }
        Ok(SymCsc {
            n: self.n,
            col_ptr,
            row_idx,
            values,
        })
    }

    /// `y = self x` for every column of `x` (`n x b`). The columns are cut in two fixed
    /// halves done on two threads, each in one pass over the stored triangle; a column's
    /// arithmetic does not depend on the split, so the bits do not depend on the pool.
    pub fn mul(&self, x: MatRef<'_, f64>, y: MatMut<'_, f64>) {
        let (n, b) = (self.n, x.ncols());
        assert!(x.nrows() == n && y.nrows() == n && y.ncols() == b);
        if b >= 2 && crate::par::threads() > 1 && self.nnz() * b >= 1 << 16 {
            let h = b / 2;
            let (yl, yr) = y.split_at_col_mut(h);
            rayon::join(
                || self.mul_seq(x.subcols(0, h), yl),
                || self.mul_seq(x.subcols(h, b - h), yr),
            );
        } else {
            self.mul_seq(x, y);
        }
    }

    /// [`SymCsc::mul`] on one thread.
    fn mul_seq(&self, x: MatRef<'_, f64>, mut y: MatMut<'_, f64>) {
        let (n, b) = (self.n, x.ncols());
        // Row-major copies: each stored term then updates b contiguous values.
        let mut xr = vec![0.0; n * b];
        for c in 0..b {
            for i in 0..n {
                xr[i * b + c] = x[(i, c)];
            }
        }
        let mut yr = vec![0.0; n * b];
        for j in 0..n {
            let xj = j * b;
            for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                let (i, a) = (self.row_idx[k], self.values[k]);
                let xi = i * b;
                if i == j {
                    for c in 0..b {
                        yr[xj + c] += a * xr[xj + c];
                    }
                } else {
                    for c in 0..b {
                        yr[xi + c] += a * xr[xj + c];
                        yr[xj + c] += a * xr[xi + c];
                    }
                }
            }
        }
        for c in 0..b {
            for i in 0..n {
                y[(i, c)] = yr[i * b + c];
            }
        }
    }

    /// `V^T A V` for the columns of `v` (`n x k`): the matrix in a reduced basis.
    pub fn project(&self, v: MatRef<'_, f64>) -> faer::Mat<f64> {
        let mut av = faer::Mat::zeros(self.n, v.ncols());
        self.mul(v, av.as_mut());
        crate::sparse::dense::at_b(v, av.as_ref())
    }

    /// The full matrix, row-major: for tests and small matrices.
    pub fn to_dense(&self) -> Vec<f64> {
        let n = self.n;
        let mut a = vec![0.0; n * n];
        for j in 0..n {
            for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                let i = self.row_idx[k];
                a[i * n + j] = self.values[k];
                a[j * n + i] = self.values[k];
            }
        }
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    fn sample() -> SymCsc {
        // [[4, 1, 0], [1, 3, 2], [0, 2, 5]]
        SymCsc::from_dense(3, &[4.0, 1.0, 0.0, 1.0, 3.0, 2.0, 0.0, 2.0, 5.0])
    }

    #[test]
    fn product_matches_the_dense_matrix() {
        let a = sample();
        let x = Mat::from_fn(3, 2, |i, c| {
            (i + 1) as f64 * if c == 0 { 1.0 } else { -0.5 }
        });
        let mut y = Mat::zeros(3, 2);
        a.mul(x.as_ref(), y.as_mut());
        let d = a.to_dense();
        for c in 0..2 {
            for i in 0..3 {
                let want: f64 = (0..3).map(|k| d[i * 3 + k] * x[(k, c)]).sum();
                assert_eq!(y[(i, c)], want);
            }
        }
    }

    #[test]
    fn sum_over_different_patterns() {
        let a = sample();
        let b = SymCsc::from_dense(3, &[1.0, 0.0, 7.0, 0.0, 1.0, 0.0, 7.0, 0.0, 1.0]);
        let c = a.add_scaled(-2.0, &b).unwrap();
        let (da, db, dc) = (a.to_dense(), b.to_dense(), c.to_dense());
        for k in 0..9 {
            assert_eq!(dc[k], da[k] - 2.0 * db[k]);
        }
        assert_eq!(c.nnz(), 6);
        assert_eq!(c.get(2, 0), -14.0);
    }

    #[test]
    fn layout_errors_are_refused() {
        let e = SymCsc::from_parts(2, vec![0, 1, 3], vec![0, 1, 0], vec![1.0; 3]).unwrap_err();
        assert!(e.to_string().contains("column 1"), "{e}");
        let e = SymCsc::from_parts(2, vec![0, 1, 2], vec![1, 1], vec![1.0; 2]).unwrap_err();
        assert!(e.to_string().contains("column 0"), "{e}");
    }
}
