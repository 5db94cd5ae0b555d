//! The rigid frame of the split method on the rotation group: the map `G(P)` from the
//! motion `(V, omega)` (velocity of L0, angular velocity) to the frame-point
//! coordinates of FORMULATION.md section 2, the rigid mass `G^T M_R G` and the implicit
//! midpoint step that moves the frame with the modes held (FORMULATION.md section 11).

use nalgebra::{Matrix3, Matrix6, Rotation3, SMatrix, Vector3, Vector6};

use super::super::point_offset;

/// `G(P)`: frame-point velocities (`nr` rows, 12 or 15, the rest zero) of the rigid
/// motion `(V, omega)`: `v_L0 = V`, `v_Lj = V + omega x e_j` (e_j column j of P), and
/// with Irot = 1 `v_rot = omega`.
pub(crate) fn g_matrix(p: &Matrix3<f64>, nr: usize) -> SMatrix<f64, 15, 6> {
    let mut g = SMatrix::<f64, 15, 6>::zeros();
    for pt in 0..4 {
        let o = point_offset(pt);
        for c in 0..3 {
            g[(o + c, c)] = 1.0;
        }
        if pt > 0 {
            let e = p.column(pt - 1);
            // omega x e = -[e]x omega: column a is e_a x e.
            for a in 0..3 {
                let mut ea = Vector3::zeros();
                ea[a] = 1.0;
                let r = ea.cross(&e);
                for c in 0..3 {
                    g[(o + c, 3 + a)] = r[c];
                }
            }
        }
    }
    if nr == 15 {
        for a in 0..3 {
            g[(12 + a, 3 + a)] = 1.0;
        }
    }
    g
}

/// Rotation by the rotation vector `phi` (Rodrigues): a rotation to round-off whatever
/// `phi`.
pub(crate) fn exp_so3(phi: &Vector3<f64>) -> Matrix3<f64> {
    Rotation3::new(*phi).into_inner()
}

/// Largest number of fixed-point passes of the midpoint step. The pass is a
/// contraction by about `|omega| dt / 2`; with the rotation per step bounded by
/// `ROT_STEP` it converges to round-off in a handful.
pub(crate) const MAX_FIXED_POINT: usize = 60;

/// `M6(P) = G(P)^T M_R G(P)`: the rigid mass of the motion `(V, omega)` at the frame P,
/// from the file's M_R as the other methods use it (held in the global frame). `m_r` is
/// M_R row-major (`nr x nr`); plain arrays, skipping the zeros of G (about half).
pub(crate) fn rigid_mass(m_r: &[f64], nr: usize, p: &Matrix3<f64>) -> Matrix6<f64> {
    let g = g_matrix(p, nr);
    let mut mg = [[0.0; 6]; 15];
    for (i, row) in mg.iter_mut().enumerate().take(nr) {
        let mr = &m_r[i * nr..(i + 1) * nr];
        for (j, &mij) in mr.iter().enumerate() {
            for (k, o) in row.iter_mut().enumerate() {
                let gjk = g[(j, k)];
                if gjk != 0.0 {
                    *o += mij * gjk;
                }
            }
        }
    }
    let mut out = Matrix6::zeros();
    for a in 0..6 {
        for b in a..6 {
            let mut s = 0.0;
            for (i, row) in mg.iter().enumerate().take(nr) {
                let gia = g[(i, a)];
                if gia != 0.0 {
                    s += gia * row[b];
                }
            }
            out[(a, b)] = s;
            out[(b, a)] = s;
        }
    }
    out
}

/// The implicit midpoint step of the frame over `dt` on the rotation group, the modes
/// held: with `v_mid = (v + v_new) / 2`, `P_mid = exp(dt/2 [omega_mid]) P` and
/// `X_mid = X + dt/2 V_mid`, solve `v_new = v + dt a(P_mid, v_mid)` by fixed point, then
/// `P <- exp(dt [omega_mid]) P`, `X <- X + dt V_mid`, `v <- v_new`. Symmetric, second
/// order, and P stays a rotation to round-off. Returns the passes, or `None` when the
/// iteration did not converge (or `accel` failed).
pub(crate) fn midpoint(
    dt: f64,
    x: &mut Vector3<f64>,
    p: &mut Matrix3<f64>,
    v: &mut Vector6<f64>,
    mut accel: impl FnMut(&Matrix3<f64>, &Vector6<f64>) -> Option<Vector6<f64>>,
) -> Option<usize> {
    let v0 = *v;
    let mut vn = v0;
    let mut prev = f64::INFINITY;
    for pass in 1..=MAX_FIXED_POINT {
        let vm = (v0 + vn) * 0.5;
        let pm = exp_so3(&(Vector3::new(vm[3], vm[4], vm[5]) * (0.5 * dt))) * *p;
        let next = v0 + accel(&pm, &vm)? * dt;
        let change = (next - vn).amax();
        let size = next.amax().max(v0.amax());
        vn = next;
        if !change.is_finite() {
            return None;
        }
        // Converged: at round-off, or no longer decreasing once near it.
        if change <= 8.0 * f64::EPSILON * size || (change >= prev && change <= 1e-12 * size) {
            let vm = (v0 + vn) * 0.5;
            *x += Vector3::new(vm[0], vm[1], vm[2]) * dt;
            *p = exp_so3(&(Vector3::new(vm[3], vm[4], vm[5]) * dt)) * *p;
            *v = vn;
            return Some(pass);
        }
        prev = change;
    }
    None
}
