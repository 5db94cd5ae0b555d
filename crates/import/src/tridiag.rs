//! Selected eigenpairs of a symmetric tridiagonal matrix: eigenvalues by bisection on
//! Sturm counts, eigenvectors by inverse iteration, as LAPACK's `dstebz` and `dstein` do.
//!
//! Why: with `--fmax` an import needs the eigenvectors of the kept modes only. faer
//! computes all of them (divide and conquer, then the n x n back-transformation): two
//! thirds of the eigen-solve's work for a result that is then dropped. Bisection gives
//! each eigenvalue to round-off of the matrix's norm (as the QR algorithm does) in
//! `O(n)` per step, and inverse iteration each vector in `O(n)` per step; the vectors of
//! close eigenvalues are kept orthogonal by Gram-Schmidt, and a last Rayleigh-Ritz step on
//! all of them settles the mixing inside clusters.

use nalgebra::DMatrix;

/// A symmetric tridiagonal matrix: diagonal `d` (n) and off-diagonal `e` (n - 1).
#[derive(Debug, Clone)]
pub struct Tridiagonal {
    /// The diagonal.
    pub d: Vec<f64>,
    /// The off-diagonal.
    pub e: Vec<f64>,
}

impl Tridiagonal {
    /// The largest absolute row sum (bounds every eigenvalue's magnitude).
    pub fn norm(&self) -> f64 {
        let n = self.d.len();
        (0..n)
            .map(|i| {
                self.d[i].abs()
                    + if i > 0 { self.e[i - 1].abs() } else { 0.0 }
                    + if i + 1 < n { self.e[i].abs() } else { 0.0 }
            })
            .fold(0.0, f64::max)
    }

    /// Smallest pivot magnitude allowed in the Sturm recurrence and the factorisation.
    fn pivmin(&self) -> f64 {
        let e2 = self.e.iter().map(|e| e * e).fold(0.0, f64::max);
        f64::MIN_POSITIVE * e2.max(1.0)
    }

    /// How many eigenvalues are below `x` (Sturm count of `T - x I`).
    pub fn count_below(&self, x: f64) -> usize {
        let pivmin = self.pivmin();
        let mut count = 0;
        let mut q = self.d[0] - x;
        for i in 0..self.d.len() {
            if i > 0 {
                q = self.d[i] - x - self.e[i - 1] * self.e[i - 1] / q;
            }
            if q.abs() < pivmin {
                q = -pivmin;
            }
            if q < 0.0 {
                count += 1;
            }
        }
        count
    }

    /// The `k`-th smallest eigenvalue (from 0), bisected to the last bits of its own value.
    pub fn eigenvalue(&self, k: usize) -> f64 {
        let t = self.norm();
        let (mut lo, mut hi) = (-t - f64::MIN_POSITIVE, t + f64::MIN_POSITIVE);
        // Down to the last bits of the eigenvalue itself, not of the norm: the Sturm count
        // resolves small eigenvalues of a definite T far below `eps |T|`.
        let tol = self.pivmin();
        for _ in 0..2200 {
            if hi - lo <= tol.max(2.0 * f64::EPSILON * lo.abs().max(hi.abs())) {
                break;
            }
            let mid = 0.5 * (lo + hi);
            if self.count_below(mid) > k {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// Every eigenvalue, ascending, by the implicit QL algorithm without vectors
    /// (`O(n^2)`); `None` if an eigenvalue needs more than 60 sweeps.
    pub fn eigenvalues(&self) -> Option<Vec<f64>> {
        let n = self.d.len();
        let mut d = self.d.clone();
        let mut e = self.e.clone();
        e.push(0.0);
        for l in 0..n {
            let mut iter = 0;
            loop {
                let mut m = l;
                while m + 1 < n {
                    let dd = d[m].abs() + d[m + 1].abs();
                    if e[m].abs() <= f64::EPSILON * dd {
                        break;
                    }
                    m += 1;
                }
                if m == l {
                    break;
                }
                iter += 1;
                if iter > 60 {
                    return None;
                }
                let mut g = (d[l + 1] - d[l]) / (2.0 * e[l]);
                let mut r = g.hypot(1.0);
                g = d[m] - d[l] + e[l] / (g + r.copysign(g));
                let (mut s, mut c, mut p) = (1.0f64, 1.0f64, 0.0f64);
                let mut underflow = false;
                for i in (l..m).rev() {
                    let f = s * e[i];
                    let b = c * e[i];
                    r = f.hypot(g);
                    e[i + 1] = r;
                    if r == 0.0 {
                        d[i + 1] -= p;
                        e[m] = 0.0;
                        underflow = true;
                        break;
                    }
                    s = f / r;
                    c = g / r;
                    g = d[i + 1] - p;
                    r = (d[i] - g) * s + 2.0 * c * b;
                    p = s * r;
                    d[i + 1] = g + p;
                    g = c * r - b;
                }
                if underflow {
                    continue;
                }
                d[l] -= p;
                e[l] = g;
                e[m] = 0.0;
            }
        }
        if d.iter().any(|x| !x.is_finite()) {
            return None;
        }
        d.sort_by(f64::total_cmp);
        Some(d)
    }

    /// Orthonormal eigenvectors (one column each) of the eigenvalues `values` (ascending,
    /// from [`Tridiagonal::eigenvalue`]).
    pub fn eigenvectors(&self, values: &[f64]) -> DMatrix<f64> {
        let n = self.d.len();
        let p = values.len();
        let t = self.norm().max(f64::MIN_POSITIVE);
        // Eigenvalues closer than this share a cluster: their vectors are orthogonalised
        // against each other at every step (LAPACK's dstein uses the same 1e-3).
        let ortol = 1e-3 * t;
        let mut v = DMatrix::<f64>::zeros(n, p);
        let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
        let mut cluster_start = 0;
        let mut x = vec![0.0; n];
        for j in 0..p {
            if j > 0 && values[j] - values[j - 1] > ortol {
                cluster_start = j;
            }
            // Identical eigenvalues get slightly separated shifts, as in dstein.
            let mut shift = values[j];
            if j > cluster_start && shift - values[j - 1] < 10.0 * f64::EPSILON * t {
                shift = values[j - 1] + 10.0 * f64::EPSILON * t;
            }
            let lu = TridiagLu::new(self, shift, f64::EPSILON * t);
            for xi in x.iter_mut() {
                seed = seed
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                *xi = (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            }
            for _ in 0..5 {
                lu.solve(&mut x);
                for k in cluster_start..j {
                    let c = v.column(k);
                    let dot: f64 = c.iter().zip(&x).map(|(a, b)| a * b).sum();
                    for (xi, ci) in x.iter_mut().zip(c.iter()) {
                        *xi -= dot * ci;
                    }
                }
                let norm = x.iter().map(|a| a * a).sum::<f64>().sqrt();
                if norm == 0.0 || !norm.is_finite() {
                    break;
                }
                x.iter_mut().for_each(|a| *a /= norm);
            }
            v.column_mut(j).copy_from_slice(&x);
        }
        // Rayleigh-Ritz on the span: orthonormalise (twice, for round-off), then rotate by
        // the eigenvectors of V^T T V.
        for _ in 0..2 {
            for j in 0..p {
                for k in 0..j {
                    let dot = v.column(k).dot(&v.column(j));
                    let ck = v.column(k).into_owned();
                    v.column_mut(j).axpy(-dot, &ck, 1.0);
                }
                let norm = v.column(j).norm();
                v.column_mut(j).scale_mut(1.0 / norm);
            }
        }
        let tv = self.mul(&v);
        let h = v.transpose() * &tv;
        let h = (&h + h.transpose()) * 0.5;
        match super::dense::sym_eigen(&h) {
            Some((_, y)) => v * y,
            None => v,
        }
    }

    /// `T V`.
    fn mul(&self, v: &DMatrix<f64>) -> DMatrix<f64> {
        let n = self.d.len();
        let mut out = DMatrix::zeros(n, v.ncols());
        for j in 0..v.ncols() {
            for i in 0..n {
                let mut s = self.d[i] * v[(i, j)];
                if i > 0 {
                    s += self.e[i - 1] * v[(i - 1, j)];
                }
                if i + 1 < n {
                    s += self.e[i] * v[(i + 1, j)];
                }
                out[(i, j)] = s;
            }
        }
        out
    }
}

/// `T - shift I = P L U` by Gaussian elimination with row interchanges (LAPACK's
/// `dgttrf`); pivots below `tiny` are replaced by `tiny` (the matrix is singular to
/// round-off at an eigenvalue: that is what inverse iteration wants).
struct TridiagLu {
    dl: Vec<f64>,
    d: Vec<f64>,
    du: Vec<f64>,
    du2: Vec<f64>,
    swap: Vec<bool>,
}

impl TridiagLu {
    fn new(t: &Tridiagonal, shift: f64, tiny: f64) -> TridiagLu {
        let n = t.d.len();
        let mut d: Vec<f64> = t.d.iter().map(|x| x - shift).collect();
        let mut dl = t.e.clone();
        let mut du = t.e.clone();
        let mut du2 = vec![0.0; n.saturating_sub(2)];
        let mut swap = vec![false; n.saturating_sub(1)];
        for i in 0..n.saturating_sub(1) {
            if d[i].abs() >= dl[i].abs() {
                if d[i].abs() < tiny {
                    d[i] = if d[i] < 0.0 { -tiny } else { tiny };
                }
                let f = dl[i] / d[i];
                dl[i] = f;
                d[i + 1] -= f * du[i];
            } else {
                let f = d[i] / dl[i];
                d[i] = dl[i];
                dl[i] = f;
                let temp = du[i];
                du[i] = d[i + 1];
                d[i + 1] = temp - f * d[i + 1];
                if i + 2 < n {
                    du2[i] = du[i + 1];
                    du[i + 1] *= -f;
                }
                swap[i] = true;
            }
        }
        if let Some(last) = d.last_mut()
            && last.abs() < tiny
        {
            *last = if *last < 0.0 { -tiny } else { tiny };
        }
        TridiagLu {
            dl,
            d,
            du,
            du2,
            swap,
        }
    }

    /// `b <- (T - shift I)^-1 b`.
    fn solve(&self, b: &mut [f64]) {
        let n = b.len();
        for i in 0..n.saturating_sub(1) {
            if self.swap[i] {
                let temp = b[i];
                b[i] = b[i + 1];
                b[i + 1] = temp - self.dl[i] * b[i];
            } else {
                b[i + 1] -= self.dl[i] * b[i];
            }
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            if i + 1 < n {
                s -= self.du[i] * b[i + 1];
            }
            if i + 2 < n {
                s -= self.du2[i] * b[i + 2];
            }
            b[i] = s / self.d[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tridiagonal with known eigenpairs: the 1D Laplacian `2, -1` (eigenvalues
    /// `2 - 2 cos(k pi / (n + 1))`, vectors `sin(i k pi / (n + 1))`), with a doubled
    /// eigenvalue added by gluing two copies (a cluster the vectors must split).
    #[test]
    fn bisection_and_inverse_iteration_match_the_analytic_pairs() {
        let n = 300;
        let t = Tridiagonal {
            d: vec![2.0; n],
            e: vec![-1.0; n - 1],
        };
        let exact = |k: usize| 2.0 - 2.0 * (k as f64 * std::f64::consts::PI / (n + 1) as f64).cos();
        let values: Vec<f64> = (0..12).map(|k| t.eigenvalue(k)).collect();
        let all = t.eigenvalues().expect("converges");
        for (k, v) in values.iter().enumerate() {
            assert!(
                (v - exact(k + 1)).abs() <= 4.0 * f64::EPSILON * 4.0,
                "{k}: {v}"
            );
        }
        for (k, v) in all.iter().enumerate() {
            assert!(
                (v - exact(k + 1)).abs() <= 64.0 * f64::EPSILON,
                "QL {k}: {v}"
            );
        }
        assert_eq!(t.count_below(0.5 * (exact(5) + exact(6))), 5);
        let v = t.eigenvectors(&values);
        for k in 0..12 {
            let s: DMatrix<f64> = DMatrix::from_fn(n, 1, |i, _| {
                ((i + 1) as f64 * (k + 1) as f64 * std::f64::consts::PI / (n + 1) as f64).sin()
            });
            let s = &s / s.norm();
            let c = s.column(0).dot(&v.column(k)).abs();
            assert!((1.0 - c).abs() <= 1e-12, "mode {k}: |cos| = {c}");
        }
        // two uncoupled copies: every eigenvalue doubled
        let mut e = vec![-1.0; 2 * n - 1];
        e[n - 1] = 0.0;
        let t2 = Tridiagonal {
            d: vec![2.0; 2 * n],
            e,
        };
        let values: Vec<f64> = (0..6).map(|k| t2.eigenvalue(k)).collect();
        let v = t2.eigenvectors(&values);
        assert!((v.transpose() * &v - DMatrix::identity(6, 6)).amax() <= 1e-12);
        let res = t2.mul(&v) - &v * DMatrix::from_diagonal(&nalgebra::DVector::from_vec(values));
        assert!(res.amax() <= 1e-12, "residual {}", res.amax());
    }
}
