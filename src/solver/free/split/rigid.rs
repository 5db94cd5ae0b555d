//! The rigid frame of the split method as a rigid body on the rotation group: the
//! constant body-frame mass `M6b` of the motion `(V, omega)` (velocity of L0, angular
//! velocity), the map `G(P)` from that motion to the frame-point coordinates of
//! FORMULATION.md section 2, and the implicit-midpoint drift that moves the frame with
//! the momenta held (FORMULATION.md section 11).

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

/// `diag(P, P)`: body components of a 6-vector `(V, omega)` to global ones.
pub(crate) fn r6(p: &Matrix3<f64>) -> Matrix6<f64> {
    let mut r = Matrix6::zeros();
    r.fixed_view_mut::<3, 3>(0, 0).copy_from(p);
    r.fixed_view_mut::<3, 3>(3, 3).copy_from(p);
    r
}

/// Rotation by the rotation vector `phi` (Rodrigues): a rotation to round-off whatever
/// `phi`.
pub(crate) fn exp_so3(phi: &Vector3<f64>) -> Matrix3<f64> {
    Rotation3::new(*phi).into_inner()
}

/// Largest number of fixed-point passes of the midpoint drift. The pass is a
/// contraction by about `|omega| dt / 2` times the inertia anisotropy; with the
/// rotation per step bounded by `ROT_STEP` it converges to round-off in a handful.
pub(crate) const MAX_FIXED_POINT: usize = 60;

/// Rigid velocity `(V, omega)` (global) from the momenta about L0 `mu` (global) and the
/// modes' share `B^T v_L` given in body components `bv`:
/// `v6 = R6 M6b^-1 (R6^T mu - bv)`.
#[inline]
pub(crate) fn velocity(
    m6b_inv: &Matrix6<f64>,
    p: &Matrix3<f64>,
    mu: &Vector6<f64>,
    bv: &Vector6<f64>,
) -> Vector6<f64> {
    let r = r6(p);
    r * (m6b_inv * (r.tr_mul(mu) - bv))
}

/// Momenta about L0 from momenta about the global origin: `(p, L_O - X x p)`.
#[inline]
pub(crate) fn about(h: &Vector6<f64>, x: &Vector3<f64>) -> Vector6<f64> {
    let p = Vector3::new(h[0], h[1], h[2]);
    let l = Vector3::new(h[3], h[4], h[5]) - x.cross(&p);
    Vector6::new(p[0], p[1], p[2], l[0], l[1], l[2])
}

/// The drift of the frame over `dt` with the momenta `h` (about the global origin) and
/// the modes' velocities held: the implicit midpoint on the rotation group,
/// `v_mid = v6(P_mid, X_mid)`, `P_mid = exp(dt/2 [omega_mid]) P`, `X_mid = X + dt/2 V_mid`,
/// then `P <- exp(dt [omega_mid]) P`, `X <- X + dt V_mid`. `v` holds the start guess and
/// returns the midpoint velocity. Returns the number of passes, or `None` when the
/// iteration did not converge.
pub(crate) fn drift(
    m6b_inv: &Matrix6<f64>,
    h: &Vector6<f64>,
    bv: &Vector6<f64>,
    dt: f64,
    x: &mut Vector3<f64>,
    p: &mut Matrix3<f64>,
    v: &mut Vector6<f64>,
) -> Option<usize> {
    let mut prev = f64::INFINITY;
    for pass in 1..=MAX_FIXED_POINT {
        let w = Vector3::new(v[3], v[4], v[5]);
        let vt = Vector3::new(v[0], v[1], v[2]);
        let pm = exp_so3(&(w * (0.5 * dt))) * *p;
        let xm = *x + vt * (0.5 * dt);
        let next = velocity(m6b_inv, &pm, &about(h, &xm), bv);
        let change = (next - *v).amax();
        let size = next.amax();
        *v = next;
        if !change.is_finite() {
            return None;
        }
        // Converged: at round-off, or no longer decreasing once near it.
        if change <= 8.0 * f64::EPSILON * size || (change >= prev && change <= 1e-12 * size) {
            let w = Vector3::new(v[3], v[4], v[5]);
            *x += Vector3::new(v[0], v[1], v[2]) * dt;
            *p = exp_so3(&(w * dt)) * *p;
            return Some(pass);
        }
        prev = change;
    }
    None
}
