//! The modes of (K_L, m_L), solved once per body: the body checks read its frequencies,
//! the reduction its sorted mode shapes, and the blocked solvers its modal coordinates.

use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// Eigen-solution of `K_L x = w^2 diag(m_L) x`, from the symmetric mass-scaled matrix
/// `m^-1/2 K_L m^-1/2 = V diag(lambda) V^T`.
///
/// The modes are kept in the order the symmetric eigen-solver returns them (the blocked
/// solvers sum over them in that order); [`Modal::ascending`] gives the order by
/// frequency.
#[derive(Debug, Clone)]
pub struct Modal {
    /// Eigenvalues `lambda = w^2` (unsorted; round-off may leave small negatives, and an
    /// overflowing body NaN).
    pub lambda: DVector<f64>,
    /// Mass-normalised mode shapes in local-mode coordinates, `S = m^-1/2 V`
    /// (`S^T diag(m_L) S = I`); column j pairs with `lambda[j]`.
    pub shapes: DMatrix<f64>,
    /// Column indices sorted by ascending eigenvalue.
    pub ascending: Vec<usize>,
}

impl Modal {
    /// Solve the modes of `K x = w^2 diag(m) x`; `m` must be positive (the body checks
    /// refuse any other before assembly).
    pub fn of(k: &DMatrix<f64>, m: &DVector<f64>) -> Modal {
        let n = m.len();
        let s = m.map(|v| 1.0 / v.sqrt());
        // nalgebra refuses an empty matrix: a body without local modes has nothing to
        // diagonalise.
        let (lambda, vectors) = if n == 0 {
            (DVector::zeros(0), DMatrix::zeros(0, 0))
        } else {
            let scaled = DMatrix::from_fn(n, n, |i, j| k[(i, j)] * s[i] * s[j]);
            diagonal_eigen(&scaled).unwrap_or_else(|| {
                let eig = SymmetricEigen::new(scaled);
                (eig.eigenvalues, eig.eigenvectors)
            })
        };
        let shapes = DMatrix::from_fn(n, n, |i, j| s[i] * vectors[(i, j)]);
        let mut ascending: Vec<usize> = (0..n).collect();
        ascending.sort_by(|&a, &b| lambda[a].total_cmp(&lambda[b]));
        Modal {
            lambda,
            shapes,
            ascending,
        }
    }

    /// Circular frequencies `sqrt(max(lambda, 0))` (rad/s) in the solver's order,
    /// column j of [`Modal::shapes`] first.
    pub fn omega(&self) -> Vec<f64> {
        self.lambda.iter().map(|&l| l.max(0.0).sqrt()).collect()
    }

    /// Eigenfrequencies in Hz, ascending. Negative round-off eigenvalues read as 0 Hz; a
    /// NaN eigenvalue (overflow) stays NaN, so that the body checks refuse it.
    pub fn frequencies_hz(&self) -> Vec<f64> {
        let mut f: Vec<f64> = self
            .lambda
            .iter()
            .map(|&l| {
                if l.is_nan() {
                    f64::NAN
                } else {
                    l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)
                }
            })
            .collect();
        f.sort_by(f64::total_cmp);
        f
    }
}

/// What nalgebra's symmetric eigen-solver returns for a diagonal matrix (finite, every
/// off-diagonal entry +0.0), bit for bit, in O(n^2) instead of O(n^3): it scales the
/// matrix by its largest entry, finds no Householder reflection and no rotation to do,
/// and scales the diagonal back; the eigenvectors are the identity. `None` for any
/// other matrix. A body without static modes (every `fxbody import` without `--fmax`)
/// has a diagonal K_L with up to thousands of modes, where the full solver took minutes.
fn diagonal_eigen(a: &DMatrix<f64>) -> Option<(DVector<f64>, DMatrix<f64>)> {
    let n = a.nrows();
    let off_zero = (0..n).all(|j| (0..n).all(|i| i == j || a[(i, j)].to_bits() == 0));
    if !off_zero || !a.iter().all(|v| v.is_finite()) {
        return None;
    }
    let amax = a.camax();
    let d = DVector::from_fn(n, |i, _| {
        if amax == 0.0 {
            a[(i, i)]
        } else {
            (a[(i, i)] / amax) * amax
        }
    });
    Some((d, DMatrix::identity(n, n)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The diagonal shortcut is nalgebra's answer bit for bit (eigenvalues, their order
    /// and the vectors), so bodies keep every output bit; and it declines a matrix with
    /// an off-diagonal term or a -0.0 off the diagonal (nalgebra's sign of that
    /// reflection).
    #[test]
    fn diagonal_shortcut_is_nalgebra_bit_for_bit() {
        let mut rng = fxbody_testkit::Rng::new(11);
        let mut r = || rng.uniform();
        for n in [1usize, 2, 7, 40] {
            for zeros in [false, true] {
                let a = DMatrix::from_fn(n, n, |i, j| {
                    if i != j || (zeros && i % 3 == 1) {
                        0.0
                    } else {
                        (r() * 1e3).powi(3) * if i % 5 == 2 { -1e-9 } else { 1.0 }
                    }
                });
                let (d, v) = diagonal_eigen(&a).expect("diagonal");
                let e = SymmetricEigen::new(a.clone());
                let bits = |m: &[f64]| m.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(d.as_slice()), bits(e.eigenvalues.as_slice()), "n {n}");
                assert_eq!(bits(v.as_slice()), bits(e.eigenvectors.as_slice()), "n {n}");
            }
        }
        let mut a = DMatrix::<f64>::identity(3, 3);
        a[(0, 1)] = 1e-300;
        assert!(diagonal_eigen(&a).is_none());
        a[(0, 1)] = -0.0;
        assert!(diagonal_eigen(&a).is_none());
    }

    /// Two masses, springs k to ground and k between: w^2 = k/m and 3k/m (analytic).
    #[test]
    fn two_mass_chain_against_analytic() {
        let (k, m) = (400.0, 2.0);
        let kk = DMatrix::from_row_slice(2, 2, &[2.0 * k, -k, -k, 2.0 * k]);
        let mm = DVector::from_vec(vec![m, m]);
        let modal = Modal::of(&kk, &mm);
        let tau = 2.0 * std::f64::consts::PI;
        let f = modal.frequencies_hz();
        assert!((f[0] - (k / m).sqrt() / tau).abs() < 1e-12 * f[0]);
        assert!((f[1] - (3.0 * k / m).sqrt() / tau).abs() < 1e-12 * f[1]);
        // Mass-normalised and K-diagonal: S^T M S = I, S^T K S = diag(lambda).
        let s = &modal.shapes;
        let sms = s.transpose() * DMatrix::from_diagonal(&mm) * s;
        let sks = s.transpose() * &kk * s;
        for i in 0..2 {
            for j in 0..2 {
                let id = if i == j { 1.0 } else { 0.0 };
                assert!((sms[(i, j)] - id).abs() < 1e-12);
                let l = if i == j { modal.lambda[i] } else { 0.0 };
                assert!((sks[(i, j)] - l).abs() < 1e-9);
            }
        }
        let w = modal.omega();
        let lo = modal.ascending[0];
        assert!((w[lo] - (k / m).sqrt()).abs() < 1e-12 * w[lo]);
    }

    /// The frequencies equal those of the eigenvalue-only solve of the same scaled
    /// matrix bit for bit (the decomposition's values do not depend on whether the
    /// vectors are accumulated), so bodies, golden files and stable steps keep their bits.
    #[test]
    fn frequencies_match_eigenvalue_only_solve_bitwise() {
        let n = 7;
        let k = DMatrix::from_fn(n, n, |i, j| {
            let d = (i as f64 - j as f64).abs();
            if i == j {
                10.0 + i as f64
            } else {
                1.0 / (1.0 + d * d)
            }
        });
        let m = DVector::from_fn(n, |i, _| 0.5 + 0.3 * i as f64);
        let s = m.map(|v| 1.0 / v.sqrt());
        let scaled = DMatrix::from_fn(n, n, |i, j| k[(i, j)] * s[i] * s[j]);
        let mut want: Vec<f64> = scaled
            .symmetric_eigenvalues()
            .iter()
            .map(|&l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect();
        want.sort_by(f64::total_cmp);
        let got = Modal::of(&k, &m).frequencies_hz();
        assert_eq!(
            got.iter().map(|f| f.to_bits()).collect::<Vec<_>>(),
            want.iter().map(|f| f.to_bits()).collect::<Vec<_>>()
        );
    }

    #[test]
    fn empty_body_has_no_modes() {
        let modal = Modal::of(&DMatrix::zeros(0, 0), &DVector::zeros(0));
        assert!(modal.frequencies_hz().is_empty());
        assert_eq!(modal.shapes.shape(), (0, 0));
    }
}
