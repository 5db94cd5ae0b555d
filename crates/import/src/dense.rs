//! The dense linear algebra of an import, done by `faer` on nalgebra matrices: the
//! symmetric eigen-solver, the Cholesky factor, triangular solves and products.
//!
//! Why not nalgebra's own: its symmetric eigen-solver (Householder tridiagonalisation
//! and implicit QR with the rotations applied to the full eigenvector matrix) took 129 s
//! at 3000 DOFs, and its Cholesky and triangular solves are unblocked. faer's blocked
//! tridiagonalisation and divide-and-conquer do the same decomposition in seconds. The
//! rest of the import keeps nalgebra's types; the copies in and out are O(n^2).
//!
//! faer 0.22's divide-and-conquer stops its secular-equation root finder on an absolute
//! tolerance (`|f_cur - f_prev| > eps`), so its eigenpairs are accurate only for a matrix
//! of norm near 1. Fed a stiffness-sized matrix (largest eigenvalue 1.45e12, a free
//! 2040-DOF grillage) its eigenvectors had residuals `|A v - lambda v|` up to 2.5e-3 of
//! the largest eigenvalue and its lowest eigenvalues were off by up to 2e-4 (LAPACK: 1e-7
//! on the same matrix). [`sym_eigen`] therefore scales the matrix to an infinity norm of 1
//! first: residuals 6e-15 of the largest eigenvalue, and the solve twice as fast (fewer
//! wasted iterations).

use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::tridiag::{self, TridiagParams};
use faer::linalg::evd::{self, ComputeEigenvectors};
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Accum, Auto, Mat, MatRef, Spec};
use nalgebra::DMatrix;

use super::tridiag::Tridiagonal;
use crate::par::par;

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
    let s = unit_scale(a)?;
    let (d, u) = evd_scaled(a, s, ComputeEigenvectors::Yes)?;
    Some((d, to_nalgebra(u.as_ref())))
}

/// faer's symmetric eigen-decomposition of `s a` (lower triangle read) with [`par`]:
/// the eigenvalues divided by `s` again, ascending, and the eigenvectors when asked.
fn evd_scaled(
    a: &DMatrix<f64>,
    s: f64,
    vectors: ComputeEigenvectors,
) -> Option<(Vec<f64>, Mat<f64>)> {
    let n = a.nrows();
    let scaled = Mat::from_fn(n, n, |i, j| a[(i, j)] * s);
    evd_of_scaled(scaled.as_ref(), s, vectors)
}

/// The one call of faer's dense symmetric eigen-solver in this crate (the dense import,
/// and the projected matrices of the sparse path): the eigen-decomposition of `scaled`,
/// which is `s A` (its lower triangle read), with [`par`]. Returns A's eigenvalues (those
/// of `scaled` divided by `s`), ascending, and the eigenvectors when `vectors` asks.
/// Scale A to a norm near 1 first: the solver's root finder stops on an absolute
/// tolerance (the module text).
pub(crate) fn evd_of_scaled(
    scaled: MatRef<'_, f64>,
    s: f64,
    vectors: ComputeEigenvectors,
) -> Option<(Vec<f64>, Mat<f64>)> {
    let n = scaled.nrows();
    let want = matches!(vectors, ComputeEigenvectors::Yes);
    let mut u = Mat::<f64>::zeros(if want { n } else { 0 }, if want { n } else { 0 });
    let mut d = Diag::<f64>::zeros(n);
    let mut mem = MemBuffer::new(evd::self_adjoint_evd_scratch::<f64>(
        n,
        vectors,
        par(),
        Default::default(),
    ));
    evd::self_adjoint_evd(
        scaled,
        d.as_mut(),
        want.then(|| u.as_mut()),
        par(),
        MemStack::new(&mut mem),
        Default::default(),
    )
    .ok()?;
    let d = d.column_vector();
    Some(((0..n).map(|i| d[i] / s).collect(), u))
}

/// Eigenvalues (ascending) of the symmetric `a` (lower triangle read), computed on the
/// matrix scaled as in [`sym_eigen`].
pub fn sym_eigenvalues(a: &DMatrix<f64>) -> Option<Vec<f64>> {
    if a.nrows() == 0 {
        return Some(Vec::new());
    }
    let s = unit_scale(a)?;
    evd_scaled(a, s, ComputeEigenvectors::No).map(|(d, _)| d)
}

/// A symmetric matrix reduced to tridiagonal form, `A / s = Q T Q^T` (faer's blocked
/// Householder reduction; `s` the scale of [`sym_eigen`]), for the eigenpairs of a few
/// modes ([`super::tridiag`]) without the others' eigenvectors.
pub struct Reduction {
    /// The Householder vectors below the subdiagonal (faer's layout).
    trid: Mat<f64>,
    /// The block Householder factors.
    householder: Mat<f64>,
    /// T.
    t: Tridiagonal,
    /// `s`: eigenvalues of A are those of T over `s`.
    scale: f64,
}

/// Reduce the symmetric `a` (lower triangle read) to tridiagonal form; `None` for a
/// non-finite or empty matrix.
pub fn tridiagonalize(a: &DMatrix<f64>) -> Option<Reduction> {
    let n = a.nrows();
    if n < 2 {
        return None;
    }
    let scale = unit_scale(a)?;
    let mut trid = Mat::from_fn(n, n, |i, j| a[(i.max(j), i.min(j))] * scale);
    let bs = faer::linalg::qr::no_pivoting::factor::recommended_blocksize::<f64>(n, n);
    let mut householder = Mat::<f64>::zeros(bs, n - 1);
    let params = <TridiagParams as Auto<f64>>::auto();
    let mut mem = MemBuffer::new(tridiag::tridiag_in_place_scratch::<f64>(
        n,
        par(),
        Spec::new(params),
    ));
    tridiag::tridiag_in_place(
        trid.as_mut(),
        householder.as_mut(),
        par(),
        MemStack::new(&mut mem),
        Spec::new(params),
    );
    let t = Tridiagonal {
        d: (0..n).map(|i| trid[(i, i)]).collect(),
        e: (0..n - 1).map(|i| trid[(i + 1, i)]).collect(),
    };
    Some(Reduction {
        trid,
        householder,
        t,
        scale,
    })
}

impl Reduction {
    /// Every eigenvalue of A, ascending (`None` if the QL sweeps do not converge).
    pub fn eigenvalues(&self) -> Option<Vec<f64>> {
        let v = self.t.eigenvalues()?;
        Some(v.into_iter().map(|x| x / self.scale).collect())
    }

    /// The `k`-th smallest eigenvalue of A (from 0) by bisection: for the low modes it is
    /// more accurate than the QL sweeps of [`Reduction::eigenvalues`] (a clamped
    /// grillage's lowest, 1e-9 of the largest: 2e-10 against 1.6e-8).
    pub fn eigenvalue(&self, k: usize) -> f64 {
        self.t.eigenvalue(k) / self.scale
    }

    /// Orthonormal eigenvectors of A for the eigenvalues `values` (ascending, from
    /// [`Reduction::eigenvalues`]), one column each.
    pub fn eigenvectors(&self, values: &[f64]) -> DMatrix<f64> {
        let n = self.t.d.len();
        let scaled: Vec<f64> = values.iter().map(|v| v * self.scale).collect();
        let mut u = to_faer(&self.t.eigenvectors(&scaled));
        let bs = self.householder.nrows();
        let mut mem = MemBuffer::new(
            faer::linalg::householder::apply_block_householder_sequence_on_the_left_in_place_scratch::<f64>(
                n - 1,
                bs,
                u.ncols(),
            ),
        );
        faer::linalg::householder::apply_block_householder_sequence_on_the_left_in_place_with_conj(
            self.trid.as_ref().submatrix(1, 0, n - 1, n - 1),
            self.householder.as_ref(),
            faer::Conj::No,
            u.as_mut().subrows_mut(1, n - 1),
            par(),
            MemStack::new(&mut mem),
        );
        to_nalgebra(u.as_ref())
    }
}

/// `1 / |A|_inf` (see [`inf_norm`]), so that the scaled spectrum lies in [-1, 1]; `1` for
/// a zero matrix, `None` for a non-finite one.
fn unit_scale(a: &DMatrix<f64>) -> Option<f64> {
    let norm = inf_norm(a);
    if !norm.is_finite() {
        return None;
    }
    Some(if norm > 0.0 { 1.0 / norm } else { 1.0 })
}

/// The largest absolute row sum of the symmetric `a` from its lower triangle: an upper
/// bound of its eigenvalues' magnitudes (infinite for a non-finite `a`).
pub fn inf_norm(a: &DMatrix<f64>) -> f64 {
    let n = a.nrows();
    let mut rows = vec![0.0f64; n];
    for j in 0..n {
        for i in j..n {
            let v = a[(i, j)].abs();
            rows[i] += v;
            if i != j {
                rows[j] += v;
            }
        }
    }
    if rows.iter().any(|r| !r.is_finite()) {
        return f64::INFINITY;
    }
    rows.iter().fold(0.0f64, |m, &r| m.max(r))
}

/// The lower Cholesky factor `L` of the symmetric `a` (`a = L L^T`, lower triangle
/// read); `None` when `a` is not positive definite.
pub fn cholesky(a: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let n = a.nrows();
    let mut l = to_faer(a);
    let mut mem = MemBuffer::new(
        faer::linalg::cholesky::llt::factor::cholesky_in_place_scratch::<f64>(
            n,
            par(),
            Default::default(),
        ),
    );
    faer::linalg::cholesky::llt::factor::cholesky_in_place(
        l.as_mut(),
        Default::default(),
        par(),
        MemStack::new(&mut mem),
        Default::default(),
    )
    .ok()?;
    // The factor is in the lower triangle; the upper one still holds `a`.
    Some(DMatrix::from_fn(
        n,
        n,
        |i, j| if i >= j { l[(i, j)] } else { 0.0 },
    ))
}

/// How definite a symmetric matrix is in working precision: the Cholesky factor of the
/// matrix scaled to a unit diagonal (`D A D`, `D = diag(a_ii)^-1/2`), whose pivots do
/// not depend on the units of each row; see [`definiteness`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Definiteness {
    /// The smallest pivot (`L_ii^2`) of the unit-diagonal matrix, in (0, 1]; zero or
    /// negative when the factorisation failed or a diagonal entry is not positive.
    pub min_pivot: f64,
    /// The row of that pivot (or of the failure).
    pub at: usize,
}

/// [`Definiteness`] of the symmetric `a` (lower triangle read). Positive definite
/// matrices of stiffness type keep pivots far from round-off (a 2,970-DOF frame: 1.6e-8,
/// however small its lowest eigenvalue, 4e-14 of the largest); a singular one fails or
/// leaves a pivot at round-off.
pub fn definiteness(a: &DMatrix<f64>) -> Definiteness {
    let n = a.nrows();
    if let Some(at) = (0..n).find(|&i| !(a[(i, i)] > 0.0 && a[(i, i)].is_finite())) {
        return Definiteness { min_pivot: 0.0, at };
    }
    let d: Vec<f64> = (0..n).map(|i| 1.0 / a[(i, i)].sqrt()).collect();
    let mut l = Mat::from_fn(n, n, |i, j| a[(i.max(j), i.min(j))] * d[i] * d[j]);
    let mut mem = MemBuffer::new(
        faer::linalg::cholesky::llt::factor::cholesky_in_place_scratch::<f64>(
            n,
            par(),
            Default::default(),
        ),
    );
    match faer::linalg::cholesky::llt::factor::cholesky_in_place(
        l.as_mut(),
        Default::default(),
        par(),
        MemStack::new(&mut mem),
        Default::default(),
    ) {
        Ok(_) => {
            let (at, min_pivot) = (0..n)
                .map(|i| (i, l[(i, i)] * l[(i, i)]))
                .min_by(|x, y| x.1.total_cmp(&y.1))
                .unwrap_or((0, 1.0));
            Definiteness { min_pivot, at }
        }
        Err(faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index }) => {
            Definiteness {
                min_pivot: 0.0,
                at: index.min(n.saturating_sub(1)),
            }
        }
    }
}

/// `L^-1 B` for a lower-triangular `l` with a nonzero diagonal.
pub fn solve_lower(l: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    let lf = to_faer(l);
    let mut x = to_faer(b);
    solve_lower_triangular_in_place(lf.as_ref(), x.as_mut(), par());
    to_nalgebra(x.as_ref())
}

/// `L^-T B` for a lower-triangular `l` with a nonzero diagonal.
pub fn solve_lower_transposed(l: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    let lf = to_faer(l);
    let mut x = to_faer(b);
    solve_upper_triangular_in_place(lf.transpose(), x.as_mut(), par());
    to_nalgebra(x.as_ref())
}

/// `L^-1 K L^-T` for a lower-triangular `l` (nonzero diagonal) and a symmetric `k`,
/// symmetrised.
pub fn congruence_inverse(l: &DMatrix<f64>, k: &DMatrix<f64>) -> DMatrix<f64> {
    let lf = to_faer(l);
    let mut x = to_faer(k);
    solve_lower_triangular_in_place(lf.as_ref(), x.as_mut(), par());
    let mut y = x.transpose().to_owned();
    solve_lower_triangular_in_place(lf.as_ref(), y.as_mut(), par());
    let n = y.nrows();
    DMatrix::from_fn(n, n, |i, j| 0.5 * (y[(i, j)] + y[(j, i)]))
}

/// The product `A^T B` (A's transpose is not formed).
pub fn tr_mul(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    product(to_faer(a).transpose(), to_faer(b).as_ref())
}

/// The product `A B`.
pub fn mul(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    product(to_faer(a).as_ref(), to_faer(b).as_ref())
}

/// `lhs rhs` by faer's blocked product with [`par`].
fn product(lhs: MatRef<'_, f64>, rhs: MatRef<'_, f64>) -> DMatrix<f64> {
    let mut p = Mat::<f64>::zeros(lhs.nrows(), rhs.ncols());
    faer::linalg::matmul::matmul(p.as_mut(), Accum::Replace, lhs, rhs, 1.0, par());
    to_nalgebra(p.as_ref())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SymmetricEigen;

    fn spd(n: usize, seed: u64) -> DMatrix<f64> {
        let mut rng = fxbody_testkit::Rng::new(seed);
        let mut r = || rng.uniform() - 0.5;
        let b = DMatrix::from_fn(n, n, |_, _| r());
        b.transpose() * &b + DMatrix::identity(n, n) * 0.1
    }

    /// The same bits whatever the thread pool, on this machine: faer splits its work by
    /// [`crate::par::threads`], not by the pool's size, so an import repeats bit for bit
    /// on one CPU (not across CPUs: faer's SIMD kernels are chosen per CPU).
    /// Sizes past faer's blocking thresholds, so that its parallel paths run.
    #[test]
    fn results_do_not_depend_on_the_pool() {
        let a = spd(400, 7);
        let b = spd(400, 11);
        let run = |threads: usize| {
            fxbody_testkit::in_pool(threads, || {
                let (d, v) = sym_eigen(&a).unwrap();
                let l = cholesky(&b).unwrap();
                let c = congruence_inverse(&l, &a);
                (d, v, c, mul(&a, &b), tr_mul(&a, &b))
            })
        };
        let one = run(1);
        for threads in [2, 5] {
            let other = run(threads);
            assert!(
                one.0
                    .iter()
                    .zip(&other.0)
                    .all(|(x, y)| x.to_bits() == y.to_bits())
            );
            assert_eq!(one.1, other.1, "{threads} threads");
            assert_eq!(one.2, other.2, "{threads} threads");
            assert_eq!(one.3, other.3, "{threads} threads");
            assert_eq!(one.4, other.4, "{threads} threads");
        }
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

    /// A stiffness-sized matrix (a clamped 2D grid Laplacian, 400 DOFs, so that faer
    /// divides and conquers, times 1e12): every pair satisfies `A v = lambda v` to
    /// round-off of the largest eigenvalue, and the lowest eigenvalues equal the analytic
    /// ones to 1e-9 relative. Unscaled, faer 0.22 left residuals of 1e-3 here.
    #[test]
    fn eigen_of_a_large_norm_matrix_is_accurate() {
        let (nx, ny) = (20, 20);
        let n = nx * ny;
        let c = 1e12;
        let mut a = DMatrix::zeros(n, n);
        for j in 0..ny {
            for i in 0..nx {
                let p = i + nx * j;
                a[(p, p)] = 4.0 * c;
                if i + 1 < nx {
                    a[(p, p + 1)] = -c;
                    a[(p + 1, p)] = -c;
                }
                if j + 1 < ny {
                    a[(p, p + nx)] = -c;
                    a[(p + nx, p)] = -c;
                }
            }
        }
        let (values, v) = sym_eigen(&a).expect("converges");
        let top = values[n - 1];
        let res =
            &a * &v - &v * DMatrix::from_diagonal(&nalgebra::DVector::from_vec(values.clone()));
        let worst = res.column_iter().map(|c| c.norm()).fold(0.0, f64::max);
        assert!(worst <= 1e-13 * top, "residual {worst:e} of {top:e}");
        // lambda_pq = c (4 - 2 cos(p pi/(nx+1)) - 2 cos(q pi/(ny+1))), p, q >= 1
        let mut exact: Vec<f64> = (1..=nx)
            .flat_map(|p| (1..=ny).map(move |q| (p, q)))
            .map(|(p, q)| {
                let t =
                    |k: usize, m: usize| (k as f64 * std::f64::consts::PI / (m + 1) as f64).cos();
                c * (4.0 - 2.0 * t(p, nx) - 2.0 * t(q, ny))
            })
            .collect();
        exact.sort_by(f64::total_cmp);
        for (g, w) in values.iter().zip(&exact).take(10) {
            assert!((g / w - 1.0).abs() <= 1e-9, "{g} vs {w}");
        }
        let only = sym_eigenvalues(&a).expect("converges");
        assert!((only[0] / exact[0] - 1.0).abs() <= 1e-9);
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
