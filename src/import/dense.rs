//! The dense linear algebra of an import, done by `faer` on nalgebra matrices: the
//! symmetric eigen-solver, the Cholesky factor, triangular solves and products.
//!
//! Why not nalgebra's own: its symmetric eigen-solver (Householder tridiagonalisation
//! and implicit QR with the rotations applied to the full eigenvector matrix) took 129 s
//! at 3000 DOFs, and its Cholesky and triangular solves are unblocked. faer's blocked
//! tridiagonalisation and divide-and-conquer do the same decomposition in seconds. The
//! rest of the import keeps nalgebra's types; the copies in and out are O(n^2).

use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Mat, MatRef, Par, Side};
use nalgebra::DMatrix;

fn to_faer(a: &DMatrix<f64>) -> Mat<f64> {
    Mat::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)])
}

fn to_nalgebra(a: MatRef<'_, f64>) -> DMatrix<f64> {
    DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)])
}

/// Eigenvalues (ascending) and orthonormal eigenvectors (one column each, in the same
/// order) of the symmetric `a` (its lower triangle is read); `None` when the solver does
/// not converge (a non-finite input).
pub fn sym_eigen(a: &DMatrix<f64>) -> Option<(Vec<f64>, DMatrix<f64>)> {
    if a.nrows() == 0 {
        return Some((Vec::new(), DMatrix::zeros(0, 0)));
    }
    let e = to_faer(a).self_adjoint_eigen(Side::Lower).ok()?;
    let s = e.S().column_vector();
    let values = (0..s.nrows()).map(|i| s[i]).collect();
    Some((values, to_nalgebra(e.U())))
}

/// Eigenvalues (ascending) of the symmetric `a` (lower triangle read).
pub fn sym_eigenvalues(a: &DMatrix<f64>) -> Option<Vec<f64>> {
    if a.nrows() == 0 {
        return Some(Vec::new());
    }
    to_faer(a).self_adjoint_eigenvalues(Side::Lower).ok()
}

/// The lower Cholesky factor `L` of the symmetric `a` (`a = L L^T`, lower triangle
/// read); `None` when `a` is not positive definite.
pub fn cholesky(a: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let llt = to_faer(a).llt(Side::Lower).ok()?;
    Some(to_nalgebra(llt.L()))
}

/// `L^-1 B` for a lower-triangular `l` with a nonzero diagonal.
pub fn solve_lower(l: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    let lf = to_faer(l);
    let mut x = to_faer(b);
    solve_lower_triangular_in_place(lf.as_ref(), x.as_mut(), Par::Seq);
    to_nalgebra(x.as_ref())
}

/// `L^-T B` for a lower-triangular `l` with a nonzero diagonal.
pub fn solve_lower_transposed(l: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    let lf = to_faer(l);
    let mut x = to_faer(b);
    solve_upper_triangular_in_place(lf.transpose(), x.as_mut(), Par::Seq);
    to_nalgebra(x.as_ref())
}

/// `L^-1 K L^-T` for a lower-triangular `l` (nonzero diagonal) and a symmetric `k`,
/// symmetrised.
pub fn congruence_inverse(l: &DMatrix<f64>, k: &DMatrix<f64>) -> DMatrix<f64> {
    let lf = to_faer(l);
    let mut x = to_faer(k);
    solve_lower_triangular_in_place(lf.as_ref(), x.as_mut(), Par::Seq);
    let mut y = x.transpose().to_owned();
    solve_lower_triangular_in_place(lf.as_ref(), y.as_mut(), Par::Seq);
    let n = y.nrows();
    DMatrix::from_fn(n, n, |i, j| 0.5 * (y[(i, j)] + y[(j, i)]))
}

/// The product `A^T B` (A's transpose is not formed).
pub fn tr_mul(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    let p = to_faer(a).transpose() * to_faer(b);
    to_nalgebra(p.as_ref())
}

/// The product `A B`.
pub fn mul(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    let p = to_faer(a) * to_faer(b);
    to_nalgebra(p.as_ref())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SymmetricEigen;

    fn spd(n: usize, seed: u64) -> DMatrix<f64> {
        let mut s = seed;
        let mut r = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let b = DMatrix::from_fn(n, n, |_, _| r());
        b.transpose() * &b + DMatrix::identity(n, n) * 0.1
    }

    /// faer's eigen-solver against nalgebra's (a second implementation), and its pairs
    /// against the definition `A v = lambda v`, `V^T V = I`.
    #[test]
    fn eigen_matches_nalgebra_and_definition() {
        let a = spd(60, 7);
        let (values, v) = sym_eigen(&a).expect("converges");
        let mut want: Vec<f64> = SymmetricEigen::new(a.clone())
            .eigenvalues
            .iter()
            .copied()
            .collect();
        want.sort_by(f64::total_cmp);
        let top = want[59];
        for (g, w) in values.iter().zip(&want) {
            assert!((g - w).abs() <= 1e-13 * top, "{g} vs {w}");
        }
        let res = &a * &v - &v * DMatrix::from_diagonal(&nalgebra::DVector::from_vec(values));
        assert!(res.amax() <= 1e-12 * top);
        assert!((v.transpose() * &v - DMatrix::identity(60, 60)).amax() <= 1e-13);
    }

    /// Cholesky, the triangular solves and the products against nalgebra's.
    #[test]
    fn factor_solves_and_products_match_nalgebra() {
        let m = spd(40, 3);
        let k = spd(40, 5);
        let l = cholesky(&m).expect("positive definite");
        assert!((&l * l.transpose() - &m).amax() <= 1e-13 * m.amax());
        let nl = m.clone().cholesky().expect("positive definite").l();
        assert!((&l - &nl).amax() <= 1e-13 * nl.amax());
        let a = congruence_inverse(&l, &k);
        let x = nl.solve_lower_triangular(&k).expect("nonzero diagonal");
        let want = nl
            .solve_lower_triangular(&x.transpose())
            .expect("nonzero diagonal");
        assert!((&a - &want).amax() <= 1e-11 * want.amax());
        let y = solve_lower_transposed(&l, &k);
        assert!((l.transpose() * &y - &k).amax() <= 1e-11 * k.amax());
        let z = solve_lower(&l, &k);
        assert!((&l * &z - &k).amax() <= 1e-11 * k.amax());
        assert!((tr_mul(&m, &k) - m.transpose() * &k).amax() <= 1e-13 * (&m * &k).amax());
        assert!((mul(&m, &k) - &m * &k).amax() <= 1e-13 * (&m * &k).amax());
        assert!(cholesky(&(-m)).is_none());
    }
}
