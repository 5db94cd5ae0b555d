//! [`Coo`]: symmetric-matrix terms collected one by one (row, column, value, line) and
//! compressed into a [`SymCsc`], with the checks every file format shares: a term is
//! given once, and when a file gives both triangles every term's mirror is given and
//! agrees.
//!
//! Memory is proportional to the terms: 20 bytes each while collecting (row, column and
//! line as 32-bit integers, the value as a double), 16 in the result. A stream that comes
//! column by column in the upper triangle, as CalculiX writes it, is compressed without a
//! sort; any other order costs one counting sort by column and a short sort per column.

use crate::fe::{Dof, FeError, Loc, SYM_NOISE, SYM_REL_TOL};
use crate::sparse::csc::SymCsc;

/// The top bit of a stored line: the term was given in the lower triangle.
const LOWER: u32 = 1 << 31;

/// Terms of one symmetric matrix being collected from one file.
#[derive(Debug)]
pub struct Coo {
    n: usize,
    rows: Vec<u32>,
    cols: Vec<u32>,
    lines: Vec<u32>,
    values: Vec<f64>,
    /// Whether every term so far came after the previous one in column-major upper
    /// order, with no mirror and no repeat.
    sorted: bool,
}

impl Coo {
    /// An empty `n x n` collection.
    pub fn new(n: usize) -> Coo {
        Coo {
            n,
            rows: Vec::new(),
            cols: Vec::new(),
            lines: Vec::new(),
            values: Vec::new(),
            sorted: true,
        }
    }

    /// Room for `terms` more terms without reallocation.
    pub fn reserve(&mut self, terms: usize) {
        self.rows.reserve(terms);
        self.cols.reserve(terms);
        self.lines.reserve(terms);
        self.values.reserve(terms);
    }

    /// Terms collected so far.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether no term was collected.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Add the term at 0-based `(row, col)` (either triangle), read on `line` (1-based,
    /// below 2^31). The caller checked `row, col < n`.
    pub fn push(&mut self, row: usize, col: usize, value: f64, line: usize) {
        debug_assert!(row < self.n && col < self.n && line < LOWER as usize);
        let (r, c, flag) = if row <= col {
            (row as u32, col as u32, 0)
        } else {
            (col as u32, row as u32, LOWER)
        };
        if self.sorted {
            let after = match (self.rows.last(), self.cols.last()) {
                (Some(&pr), Some(&pc)) => c > pc || (c == pc && r > pr),
                _ => true,
            };
            self.sorted = after && flag == 0;
        }
        self.rows.push(r);
        self.cols.push(c);
        self.lines.push(line as u32 | flag);
        self.values.push(value);
    }

    /// The compressed matrix. `dofs` names the rows in error messages (its length is
    /// `n`); `file` is the file the terms were read from.
    pub fn finish(self, file: &str, dofs: &[Dof]) -> Result<SymCsc, FeError> {
        let n = self.n;
        let col_ptr = column_pointers(n, &self.cols);
        if self.sorted {
            let row_idx = self.rows.iter().map(|&r| r as usize).collect();
            return SymCsc::from_parts(n, col_ptr, row_idx, self.values)
                .map_err(|e| FeError::invalid(file, 0, e.to_string()));
        }
        // Counting sort by column, then each column by row (line breaks ties, so a
        // repeated term is met in file order).
        let mut next = col_ptr.clone();
        let nnz = self.values.len();
        let mut terms = vec![(0u32, 0u32, 0.0f64); nnz];
        for k in 0..nnz {
            let c = self.cols[k] as usize;
            terms[next[c]] = (self.rows[k], self.lines[k], self.values[k]);
            next[c] += 1;
        }
        drop((self.rows, self.cols, self.lines, self.values));
        for j in 0..n {
            terms[col_ptr[j]..col_ptr[j + 1]].sort_unstable_by_key(|&(r, l, _)| (r, l & !LOWER));
        }
        let max = terms.iter().fold(0.0f64, |m, t| m.max(t.2.abs()));
        let full = has_pair(&col_ptr, &terms);
        let mut out_ptr = Vec::with_capacity(n + 1);
        out_ptr.push(0);
        let mut row_idx = Vec::with_capacity(nnz);
        let mut values = Vec::with_capacity(nnz);
        for j in 0..n {
            let col = &terms[col_ptr[j]..col_ptr[j + 1]];
            let mut k = 0;
            while k < col.len() {
                let (r, line, v) = col[k];
                let same = col[k..].iter().take_while(|t| t.0 == r).count();
                let at = |l: u32| Loc::new(file, (l & !LOWER) as usize);
                let (a, b) = (dofs[r as usize], dofs[j]);
                let lower = |l: u32| l & LOWER != 0;
                let value = match same {
                    1 if full && r as usize != j => {
                        let (a, b) = if lower(line) { (b, a) } else { (a, b) };
                        return Err(FeError::NotSymmetric {
                            at: at(line),
                            a,
                            b,
                            ab: v,
                            ba: None,
                            rel: 1.0,
                        });
                    }
                    1 => v,
                    2 if lower(line) != lower(col[k + 1].1) && r as usize != j => {
                        let (l2, v2) = (col[k + 1].1, col[k + 1].2);
                        let diff = (v - v2).abs();
                        if diff > SYM_REL_TOL * v.abs().max(v2.abs()) && diff > SYM_NOISE * max {
                            let ((l1, v1), (l2, v2)) = if lower(line) {
                                ((l2, v2), (line, v))
                            } else {
                                ((line, v), (l2, v2))
                            };
                            return Err(FeError::NotSymmetric {
                                at: at(l1),
                                a,
                                b,
                                ab: v1,
                                ba: Some((v2, (l2 & !LOWER) as usize)),
                                rel: diff / v1.abs().max(v2.abs()),
                            });
                        }
                        0.5 * (v + v2)
                    }
                    _ => {
                        // In file order, the first term whose triangle was met before.
                        let group = &col[k..k + same];
                        let (first, second) = repeat(group).unwrap_or((group[0].1, line));
                        let (a, b) = if lower(second) { (b, a) } else { (a, b) };
                        return Err(FeError::Duplicate {
                            at: at(second),
                            a,
                            b,
                            first_line: (first & !LOWER) as usize,
                        });
                    }
                };
                row_idx.push(r as usize);
                values.push(value);
                k += same;
            }
            out_ptr.push(row_idx.len());
        }
        SymCsc::from_parts(n, out_ptr, row_idx, values)
            .map_err(|e| FeError::invalid(file, 0, e.to_string()))
    }
}

/// Column pointers from the (upper-triangle) column of each term.
fn column_pointers(n: usize, cols: &[u32]) -> Vec<usize> {
    let mut ptr = vec![0usize; n + 1];
    for &c in cols {
        ptr[c as usize + 1] += 1;
    }
    for j in 0..n {
        ptr[j + 1] += ptr[j];
    }
    ptr
}

/// In a group of terms at one position, sorted by line: the lines (with the triangle
/// flag) of the first term met before in its triangle and of the term that repeats it.
fn repeat(group: &[(u32, u32, f64)]) -> Option<(u32, u32)> {
    let mut seen = [None::<u32>; 2];
    for t in group {
        let tri = usize::from(t.1 & LOWER != 0);
        match seen[tri] {
            Some(first) => return Some((first, t.1)),
            None => seen[tri] = Some(t.1),
        }
    }
    None
}

/// Whether some off-diagonal term is given in both triangles (then the file stores both,
/// and every term must have its mirror).
fn has_pair(col_ptr: &[usize], terms: &[(u32, u32, f64)]) -> bool {
    (0..col_ptr.len() - 1).any(|j| {
        terms[col_ptr[j]..col_ptr[j + 1]].windows(2).any(|w| {
            w[0].0 == w[1].0 && w[0].0 as usize != j && (w[0].1 & LOWER) != (w[1].1 & LOWER)
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dofs(n: usize) -> Vec<Dof> {
        (0..n).map(|k| Dof::new(k as i64 + 1, 1)).collect()
    }

    fn build(n: usize, terms: &[(usize, usize, f64)]) -> Result<SymCsc, FeError> {
        let mut c = Coo::new(n);
        for (k, &(i, j, v)) in terms.iter().enumerate() {
            c.push(i, j, v, k + 1);
        }
        c.finish("t.sti", &dofs(n))
    }

    #[test]
    fn any_order_and_either_triangle_give_the_same_matrix() {
        let sorted = build(3, &[(0, 0, 4.0), (0, 1, 1.0), (1, 1, 3.0), (2, 2, 5.0)]).unwrap();
        let shuffled = build(3, &[(2, 2, 5.0), (1, 0, 1.0), (1, 1, 3.0), (0, 0, 4.0)]).unwrap();
        assert_eq!(sorted, shuffled);
        let full = build(
            3,
            &[
                (0, 0, 4.0),
                (1, 0, 1.0),
                (0, 1, 1.0 + 1e-9),
                (1, 1, 3.0),
                (2, 2, 5.0),
            ],
        )
        .unwrap();
        assert!((full.get(0, 1) - 1.0).abs() < 1e-9);
    }

    #[test]
    fn repeats_and_asymmetry_name_both_lines() {
        let e = build(2, &[(0, 0, 1.0), (0, 1, 2.0), (1, 1, 1.0), (0, 1, 2.0)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.sti:4: term (1.1, 2.1) given twice: first on line 2"
        );
        let e = build(2, &[(0, 1, 2.0), (1, 0, 2.1), (1, 1, 1.0)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.sti:1: not symmetric: (1.1, 2.1) = 2 but (2.1, 1.1) = 2.1 (line 2), rel. diff \
             0.04761904761904766: a mass or stiffness matrix must be symmetric"
        );
        // Full storage detected from one pair, and another pair lacks its mirror.
        let e = build(3, &[(0, 1, 2.0), (1, 0, 2.0), (2, 1, 3.0)]).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("t.sti:3: not symmetric: (3.1, 2.1)"),
            "{e}"
        );
    }
}
