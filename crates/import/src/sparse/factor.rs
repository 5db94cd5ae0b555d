//! The sparse symmetric factorisation `P (K - sigma M) P^T = L D L^T` (faer's supernodal
//! LDL^T without pivoting, after an approximate-minimum-degree ordering P), its inertia
//! and solves with many right-hand sides.
//!
//! The ordering and the supernodal structure depend only on the pattern, so they are
//! computed once ([`Analysis`]) and shared by every shift. Without pivoting, LDL^T is
//! backward stable for a positive definite matrix (the shifts the Lanczos iteration and
//! the static modes use); for the indefinite `K - sigma M` of an inertia count it is what
//! the Sturm-sequence checks of FE eigen-solvers use, and its signs give Sylvester's
//! count as long as no pivot is exactly zero (refused: [`SolveError::Singular`]).

use std::sync::Arc;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::{LdltError, LdltRegularization};
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LdltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky, simplicial, supernodal,
};
use faer::{Conj, MatMut, Par, Side, Spec};

use crate::par::{par, threads};
use crate::sparse::csc::SymCsc;
use crate::sparse::error::SolveError;

/// The fill-reducing ordering and the structure of L for one pattern.
#[derive(Debug, Clone)]
pub struct Analysis {
    symbolic: Arc<SymbolicCholesky<usize>>,
    /// The pattern it was made for: column pointers and rows.
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
}

impl Analysis {
    /// Order and analyse the pattern of `a` (its upper triangle).
    pub fn new(a: &SymCsc) -> Result<Analysis, SolveError> {
        let symbolic = factorize_symbolic_cholesky(
            a.as_faer().symbolic(),
            Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| SolveError::Input(format!("sparse analysis failed: {e:?}")))?;
        Ok(Analysis {
            symbolic: Arc::new(symbolic),
            col_ptr: a.col_ptr().to_vec(),
            row_idx: a.row_idx().to_vec(),
        })
    }

    /// Stored values of L (its memory is 8 bytes each).
    pub fn factor_len(&self) -> usize {
        self.symbolic.len_val()
    }

    /// Floating-point operations of one numerical factorisation (multiply-adds counted
    /// twice), from the column counts of L.
    pub fn flops(&self) -> f64 {
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(s) => (0..s.n_supernodes())
                .map(|k| {
                    let sn = s.supernode(k);
                    let w = (s.supernode_end()[k] - s.supernode_begin()[k]) as f64;
                    let h = sn.pattern().len() as f64 + w;
                    // Columns of heights h, h - 1, ..., h - w + 1: sum of c^2.
                    (0..w as usize).map(|j| (h - j as f64).powi(2)).sum::<f64>()
                })
                .sum(),
            SymbolicCholeskyRaw::Simplicial(s) => {
                let p = s.col_ptr();
                (0..s.nrows())
                    .map(|j| ((p[j + 1] - p[j]) as f64).powi(2))
                    .sum()
            }
        }
    }
}

/// Sylvester's inertia: how many eigenvalues of the factored matrix are negative, zero
/// and positive (for `K - sigma M` with M positive semi-definite: how many eigenvalues of
/// the pencil lie below sigma, at it, and above).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Inertia {
    /// Negative pivots.
    pub negative: usize,
    /// Zero pivots.
    pub zero: usize,
    /// Positive pivots.
    pub positive: usize,
}

/// `K - sigma M = P^T L D L^T P`, numerically.
#[derive(Debug)]
pub struct Factor {
    analysis: Analysis,
    values: Vec<f64>,
    sigma: f64,
}

impl Factor {
    /// Factor `a` (`K - sigma M`, formed by the caller; `sigma` is kept for messages),
    /// whose pattern must be the one `analysis` was made for.
    pub fn new(analysis: &Analysis, a: &SymCsc, sigma: f64) -> Result<Factor, SolveError> {
        if a.col_ptr() != analysis.col_ptr.as_slice() || a.row_idx() != analysis.row_idx {
            return Err(SolveError::Input(
                "the matrix to factor does not have the analysed pattern".into(),
            ));
        }
        let symbolic = &*analysis.symbolic;
        let mut values = vec![0.0; symbolic.len_val()];
        let params: Spec<_, f64> = Default::default();
        let mut mem = MemBuffer::new(symbolic.factorize_numeric_ldlt_scratch::<f64>(par(), params));
        let result = symbolic.factorize_numeric_ldlt(
            &mut values,
            a.as_faer(),
            Side::Upper,
            LdltRegularization::default(),
            par(),
            MemStack::new(&mut mem),
            params,
        );
        match result {
            Ok(_) => Ok(Factor {
                analysis: analysis.clone(),
                values,
                sigma,
            }),
            Err(LdltError::ZeroPivot { index }) => Err(SolveError::Singular {
                sigma,
                index,
                hint: "the shift is an eigenvalue, or K has a zero-energy mode that M does not \
                       reach (a mechanism, or a DOF with neither stiffness nor mass)",
            }),
        }
    }

    /// The shift this factor was made with.
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// Rows and columns.
    pub fn n(&self) -> usize {
        self.analysis.symbolic.nrows()
    }

    /// The pivots D, in factorisation order.
    pub fn pivots(&self) -> Vec<f64> {
        let mut d = Vec::with_capacity(self.n());
        match self.analysis.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(s) => {
                let l = supernodal::SupernodalLdltRef::new(s, &self.values);
                for k in 0..s.n_supernodes() {
                    let block = l.supernode(k).val();
                    d.extend((0..block.ncols()).map(|j| block[(j, j)]));
                }
            }
            SymbolicCholeskyRaw::Simplicial(s) => {
                // Each column of the simplicial factor starts with its pivot.
                let l = simplicial::SimplicialLdltRef::new(s, &self.values);
                let col_ptr = s.col_ptr();
                d.extend((0..s.nrows()).map(|j| l.values()[col_ptr[j]]));
            }
        }
        d
    }

    /// Sylvester's inertia of the factored matrix (the signs of the pivots).
    pub fn inertia(&self) -> Inertia {
        let d = self.pivots();
        let negative = d.iter().filter(|&&x| x < 0.0).count();
        let zero = d.iter().filter(|&&x| x == 0.0).count();
        Inertia {
            negative,
            zero,
            positive: d.len() - negative - zero,
        }
    }

    /// The smallest `|pivot| / |diagonal term of its row of a|` (`a` the matrix factored):
    /// how close the factorisation came to breaking down.
    pub fn smallest_relative_pivot(&self, a: &SymCsc) -> f64 {
        let d = self.pivots();
        let diag = a.diagonal();
        let perm = self.analysis.symbolic.perm();
        (0..d.len())
            .map(|i| {
                let row = perm.map_or(i, |p| p.arrays().0[i]);
                d[i].abs() / diag[row].abs()
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The first pivot (index in factorisation order) that is not positive or is below
    /// `rel` times the diagonal term of its row of `a`, the matrix factored: a factor meant
    /// to be of a positive definite matrix checks itself with this (a singular matrix
    /// gives pivots of rounding size, of either sign).
    pub fn first_non_positive_relative(&self, a: &SymCsc, rel: f64) -> Option<usize> {
        let d = self.pivots();
        let diag = a.diagonal();
        let perm = self.analysis.symbolic.perm();
        (0..d.len()).find(|&i| {
            let row = perm.map_or(i, |p| p.arrays().0[i]);
            d[i].is_nan() || d[i] <= rel * diag[row].abs()
        })
    }

    /// Overwrite every column of `rhs` (`n x b`) with the solution of
    /// `(K - sigma M) x = rhs`. The columns are cut in two fixed halves solved on two
    /// threads, each one pass over L with faer's sequential kernels (its parallel solve
    /// waits on barriers at every supernode and ran 1.5-2.5x slower on a busy machine);
    /// a column's arithmetic does not depend on the pool, so neither do the bits.
    pub fn solve_in_place(&self, rhs: MatMut<'_, f64>) {
        let b = rhs.ncols();
        if b >= 2 && threads() > 1 {
            let (left, right) = rhs.split_at_col_mut(b / 2);
            rayon::join(|| self.solve_seq(left), || self.solve_seq(right));
        } else {
            self.solve_seq(rhs);
        }
    }

    fn solve_seq(&self, rhs: MatMut<'_, f64>) {
        let symbolic = &*self.analysis.symbolic;
        let mut mem = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(rhs.ncols(), Par::Seq));
        LdltRef::new(symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(&mut mem),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    /// A 1D chain: K tridiagonal (2, -1), M identity; eigenvalues 2 - 2 cos(k pi/(n+1)).
    fn chain(n: usize) -> (SymCsc, SymCsc) {
        let mut k = vec![0.0; n * n];
        let mut m = vec![0.0; n * n];
        for i in 0..n {
            k[i * n + i] = 2.0;
            m[i * n + i] = 1.0;
            if i + 1 < n {
                k[i * n + i + 1] = -1.0;
                k[(i + 1) * n + i] = -1.0;
            }
        }
        (SymCsc::from_dense(n, &k), SymCsc::from_dense(n, &m))
    }

    #[test]
    fn inertia_counts_eigenvalues_below_the_shift() {
        let n = 40;
        let (k, m) = chain(n);
        let pattern = k.add_scaled(0.0, &m).unwrap();
        let analysis = Analysis::new(&pattern).unwrap();
        for sigma in [0.3, 1.1, 2.5, 3.9] {
            let a = k.add_scaled(-sigma, &m).unwrap();
            let f = Factor::new(&analysis, &a, sigma).unwrap();
            let below = (1..=n)
                .filter(|&j| {
                    2.0 - 2.0 * (j as f64 * std::f64::consts::PI / (n + 1) as f64).cos() < sigma
                })
                .count();
            assert_eq!(f.inertia().negative, below, "sigma {sigma}");
            assert_eq!(f.inertia().zero, 0);
        }
    }

    #[test]
    fn an_exact_zero_pivot_is_refused() {
        // [[1, -1], [-1, 1]]: sigma = 1 is an eigenvalue of the 2-DOF chain; the second
        // pivot is 1 - 1/1 = 0.
        let (k, m) = chain(2);
        let a = k.add_scaled(-1.0, &m).unwrap();
        let f = Factor::new(&Analysis::new(&a).unwrap(), &a, 1.0);
        assert!(matches!(f, Err(SolveError::Singular { .. })), "{f:?}");
    }

    #[test]
    fn solves_many_right_hand_sides() {
        let (k, m) = chain(30);
        let analysis = Analysis::new(&k).unwrap();
        let f = Factor::new(&analysis, &k, 0.0).unwrap();
        assert_eq!(f.first_non_positive_relative(&k, 1e-13), None);
        let b = Mat::from_fn(30, 3, |i, c| ((i * 7 + c * 3) % 11) as f64 - 5.0);
        let mut x = b.clone();
        f.solve_in_place(x.as_mut());
        let mut r = Mat::zeros(30, 3);
        k.mul(x.as_ref(), r.as_mut());
        let err = (&r - &b).norm_max();
        assert!(err < 1e-12, "{err}");
        let _ = m;
    }
}
