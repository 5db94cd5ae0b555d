//! The whole model projected on its Ritz basis and rewritten in the coordinates a body is
//! built from: the connection DOFs themselves and modal amplitudes (a Craig-Bampton step
//! inside the small space).
//!
//! The basis `B = [Phi, Psi, R]` (kept eigenvectors, static modes, and a free body's rigid
//! motions) spans every eigenvector below the cut and the static response to any load at
//! the connections. `K_B = B^T K B` and `M_B = B^T M B` are small and dense; every
//! eigenpair of the model below the cut is an eigenpair of `(K_B, M_B)` (Rayleigh-Ritz
//! keeps an exact eigenvector exactly), and the others lie above the cut (they are
//! M-orthogonal to the ones below).
//!
//! Within span(B), with `C = E^T B` the connection DOFs' values:
//! - the **constraint modes** are the minimum-energy motions with unit value at one
//!   connection DOF and zero at the others. A rigid motion of the connections therefore
//!   maps to the rigid motion itself (it has zero energy and is in the span), with zero
//!   modal amplitudes: the body's rigid part is the model's;
//! - the **modal amplitudes** are the fixed-interface modes of span(B) (`C y = 0`),
//!   M-orthonormal, K-diagonal.
//!
//! The change of coordinates is invertible within span(B), so the small model has the
//! same eigenvalues and statics at the connections as `(K_B, M_B)`.

use faer::Mat;
use faer::linalg::solvers::Solve;

use crate::sparse::dense::{ab, at_b, sym_eigen};
use crate::sparse::{SolveError, SymCsc};

/// Gram eigenvalues below this fraction of the largest (of the unit-M-norm columns) are
/// directions the basis does not really have: dropped (`1e-12`: directions M-independent
/// to 1e-6).
pub const GRAM_FLOOR: f64 = 1e-12;

/// The small model over `[connection DOFs, modal amplitudes]`.
#[derive(Debug, Clone)]
pub struct Small {
    /// Stiffness, `(c + q)` square, symmetric.
    pub k: Mat<f64>,
    /// Mass, same size.
    pub m: Mat<f64>,
    /// Connection DOFs (the first `c` rows).
    pub connections: usize,
    /// Basis directions dropped as dependent.
    pub dropped: usize,
}

fn sym(a: Mat<f64>) -> Mat<f64> {
    let n = a.nrows();
    Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]))
}

/// `X^T A X`.
fn congruence(a: &Mat<f64>, x: &Mat<f64>) -> Mat<f64> {
    sym(at_b(x.as_ref(), ab(a.as_ref(), x.as_ref()).as_ref()))
}

/// Project K and M on the columns of `b` (`n x nb`) and change coordinates to the DOFs
/// `connection` (equation indices) and fixed-interface modal amplitudes (see the module
/// text).
pub fn reduce(
    k: &SymCsc,
    m: &SymCsc,
    b: &Mat<f64>,
    connection: &[usize],
) -> Result<Small, SolveError> {
    let c = connection.len();
    let kb = sym(k.project(b.as_ref()));
    let mb = sym(m.project(b.as_ref()));
    let nb = b.ncols();
    // Unit M-norm columns, then an M-orthonormal basis of what they span: X = S U D^-1/2.
    let s: Vec<f64> = (0..nb).map(|j| 1.0 / mb[(j, j)].sqrt()).collect();
    if let Some(j) = (0..nb).find(|&j| !s[j].is_finite()) {
        return Err(SolveError::Input(format!(
            "basis vector {j} has no mass: the static modes or eigenvectors are not of M"
        )));
    }
    let g = Mat::from_fn(nb, nb, |i, j| mb[(i, j)] * s[i] * s[j]);
    let (d, u) = sym_eigen(g.as_ref())
        .ok_or_else(|| SolveError::Input("the basis's Gram matrix is not finite".into()))?;
    let top = d[nb - 1];
    let keep: Vec<usize> = (0..nb).filter(|&i| d[i] > GRAM_FLOOR * top).collect();
    let x = Mat::from_fn(nb, keep.len(), |i, j| {
        s[i] * u[(i, keep[j])] / d[keep[j]].sqrt()
    });
    let w = keep.len();
    let kw = congruence(&kb, &x);
    let mw = congruence(&mb, &x);
    // C = E^T B X, rows scaled to unit length (row scaling keeps the null space).
    let cw = Mat::from_fn(c, w, |r, j| {
        (0..nb)
            .map(|i| b[(connection[r], i)] * x[(i, j)])
            .sum::<f64>()
    });
    let dr: Vec<f64> = (0..c)
        .map(|r| 1.0 / (0..w).map(|j| cw[(r, j)].powi(2)).sum::<f64>().sqrt())
        .collect();
    if let Some(r) = (0..c).find(|&r| !dr[r].is_finite()) {
        return Err(SolveError::Input(format!(
            "connection DOF {r} does not move in the basis (no static mode reaches it)"
        )));
    }
    let cs = Mat::from_fn(c, w, |r, j| cw[(r, j)] * dr[r]);
    // C_s^T = Q R: Q's first c columns span C's rows, the others its null space.
    let q = cs.transpose().to_owned().qr().compute_Q();
    let q1 = q.subcols(0, c).to_owned();
    let q2 = q.subcols(c, w - c).to_owned();
    // Y = Q1 (C_s Q1)^-1 D: C Y = I.
    let cq = ab(cs.as_ref(), q1.as_ref());
    let cq_diag = (0..c).map(|i| cq[(i, i)].abs());
    let (lo, hi) = cq_diag.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if lo.is_nan() || lo <= 1e-10 * hi {
        return Err(SolveError::Input(format!(
            "the connection DOFs are not independent in the basis (their values span a \
             space of rank below {c}; a DOF listed twice?)"
        )));
    }
    let dmat = Mat::from_fn(c, c, |i, j| if i == j { dr[i] } else { 0.0 });
    let y = ab(q1.as_ref(), cq.partial_piv_lu().solve(&dmat).as_ref());
    // Fixed-interface part: K_N, M_N on Q2; modes V with V^T M_N V = I.
    let kn = congruence(&kw, &q2);
    let mn = congruence(&mw, &q2);
    let nq = w - c;
    let (mu, mv) = sym_eigen(mn.as_ref())
        .ok_or_else(|| SolveError::Input("fixed-interface mass not finite".into()))?;
    if nq > 0 && (mu[0].is_nan() || mu[0] <= 0.0) {
        return Err(SolveError::Input(
            "the fixed-interface mass is not positive definite".into(),
        ));
    }
    let mhalf = Mat::from_fn(nq, nq, |i, j| mv[(i, j)] / mu[j].sqrt());
    let kt = congruence(&kn, &mhalf);
    let (lam, z) = sym_eigen(kt.as_ref())
        .ok_or_else(|| SolveError::Input("fixed-interface stiffness not finite".into()))?;
    if nq > 0 && (lam[0].is_nan() || lam[0] <= 1e-12 * lam[nq - 1].abs()) {
        return Err(SolveError::Input(format!(
            "with the connection DOFs held, the model can still move without strain \
             (lowest fixed-interface eigenvalue {:e} of {:e}): a free body needs connection \
             DOFs that hold all six rigid motions (a six-DOF node, or three nodes not in \
             line)",
            lam[0],
            lam[nq - 1]
        )));
    }
    let v = ab(mhalf.as_ref(), z.as_ref());
    let modal = ab(q2.as_ref(), v.as_ref());
    // Constraint modes: Y - Q2 V Lambda^-1 V^T Q2^T K_W Y (K-orthogonal to the modal part).
    let kwy = ab(kw.as_ref(), y.as_ref());
    let g = at_b(modal.as_ref(), kwy.as_ref());
    let scaled = Mat::from_fn(nq, c, |i, j| g[(i, j)] / lam[i]);
    let psi = &y - ab(modal.as_ref(), scaled.as_ref());
    let t = Mat::from_fn(w, c + nq, |i, j| {
        if j < c {
            psi[(i, j)]
        } else {
            modal[(i, j - c)]
        }
    });
    Ok(Small {
        k: congruence(&kw, &t),
        m: congruence(&mw, &t),
        connections: c,
        dropped: nb - w,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A spring chain 0-1-2-3 with unit masses, free: the Ritz basis is the whole space,
    /// so the small model has the chain's eigenvalues, its first rows are the DOFs given,
    /// and a rigid translation of them maps to zero modal amplitudes (K_s annihilates
    /// [1, 1, 0, 0]).
    #[test]
    fn whole_space_keeps_eigenvalues_and_maps_rigid_motion_to_no_modes() {
        let n = 4;
        let mut kd = vec![0.0; n * n];
        for e in 0..n - 1 {
            let s = [1.0, 2.0, 3.0][e];
            kd[e * n + e] += s;
            kd[(e + 1) * n + e + 1] += s;
            kd[e * n + e + 1] -= s;
            kd[(e + 1) * n + e] -= s;
        }
        let k = SymCsc::from_dense(n, &kd);
        let md: Vec<f64> = (0..n * n)
            .map(|i| {
                if i % (n + 1) == 0 {
                    1.0 + (i / n) as f64
                } else {
                    0.0
                }
            })
            .collect();
        let m = SymCsc::from_dense(n, &md);
        let b = Mat::from_fn(n, n, |i, j| if i == j { 3.0 } else { 0.0 });
        let small = reduce(&k, &m, &b, &[0, 3]).unwrap();
        let kr = Mat::from_fn(n, n, |i, j| kd[i * n + j]);
        let mr = Mat::from_fn(n, n, |i, j| md[i * n + j]);
        let eig = |k: &Mat<f64>, m: &Mat<f64>| {
            let (mu, mv) = sym_eigen(m.as_ref()).unwrap();
            let h = Mat::from_fn(n, n, |i, j| mv[(i, j)] / mu[j].sqrt());
            sym_eigen(congruence(k, &h).as_ref()).unwrap().0
        };
        let (a, b) = (eig(&kr, &mr), eig(&small.k, &small.m));
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-12 * a[n - 1], "{a:?} {b:?}");
        }
        let rigid = [1.0, 1.0, 0.0, 0.0];
        for i in 0..n {
            let r: f64 = (0..n).map(|j| small.k[(i, j)] * rigid[j]).sum();
            assert!(r.abs() < 1e-12, "row {i}: {r:e}");
        }
        // The modal part is M-orthonormal.
        assert!((small.m[(2, 2)] - 1.0).abs() < 1e-12 && small.m[(2, 3)].abs() < 1e-12);
    }
}
