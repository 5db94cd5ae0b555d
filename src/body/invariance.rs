//! Whether a free body's rigid part turns with the body: the identities that the exact
//! construction of M_R and M_C satisfies and the construction OpenRadioss uses breaks
//! whenever the mass couples directions (a consistent or a reduced mass).
//!
//! The equations (FORMULATION.md section 3) hold M_R constant against the global
//! frame-point velocities and form `M_C = sum P_kl M_C,kl`. Seen from the body, a rigid
//! motion with body-frame velocity and angular velocity `u = (V_b, w_b)` moves the frame
//! points by `B(P) G0 u`, with `G0` the motion of the unit frame and `B(P)` the frame P on
//! every triplet of rigid coordinates. The rigid mass and the rigid-elastic coupling the
//! equations use are then
//!
//! ```text
//! Rb(P) = G0^T B(P)^T M_R B(P) G0        C(P) = M_C(P)^T B(P) G0
//! ```
//!
//! and a body is rotation-invariant when neither changes with P: its kinetic energy is
//! then the same function of `u` at every attitude, and a torque-free spin keeps its
//! angular momentum. The exact construction (`fxbody import`) gives `M_R = W (x) I3` on
//! the twelve affine modes, `d I3` on the rotations and no affine-rotation coupling (every
//! triplet block a multiple of I3, so `B^T M_R B = M_R`) and
//! `M_C,kl(i,j) = (T_lk Phi_R,i)^T M Phi_L,j` (so `C(P) = Phi_L^T M r_local` for every P).
//! `Phi_R^T M Phi_R` and the rotation on the local mode give the same only for nodal
//! masses that are the same in every direction.
//!
//! Measured (tests/all/free/spin.rs) on the free-free beam with consistent mass written
//! both ways, spun torque-free about a non-principal axis: built naively, its rigid mass
//! changes by [`NAIVE_BEAM_FIGURE`] when turned, and the spin loses angular momentum
//! steadily, [`NAIVE_BEAM_DRIFT`] per radian turned; between the two constructions the
//! loss is close to proportional to the figure (within 11 %). Built exactly, the figures
//! are round-off (7e-16) and over 2,400 rad the angular momentum stays within 6.1e-7.

use nalgebra::{DMatrix, Matrix3, SMatrix};

use super::Body;
use crate::num::num;

/// Above this, a body is warned about: the exact construction, written with 10
/// significant digits, stays below 1e-9 (round-off of the printed numbers).
pub const TOL: f64 = 1e-8;

/// The naive free-free beam's rigid-mass figure ([`Invariance::rigid_mass`]),
/// tests/data/freefree_naive.fxb.
pub const NAIVE_BEAM_FIGURE: f64 = 1.29e-3;

/// Angular momentum lost per radian turned by the naive free-free beam in a torque-free
/// spin (split method, 0.5 ms steps, spin 0.018 of the first elastic frequency about
/// `P0 (1, -2, 3)`, 120 rad; 9.8e-5 at 1 ms steps over 480 rad: a property of the body,
/// not of the step). tests/all/free/spin.rs measures it.
pub const NAIVE_BEAM_DRIFT: f64 = 9.9e-5;

/// Attitudes at which the identities are checked: quarter turns about each axis and two
/// oblique turns. `Rb(P)` and `C(P)` are quadratic in P, so a change anywhere shows at
/// some of these.
const TURNS: [([f64; 3], f64); 5] = [
    ([1.0, 0.0, 0.0], 90.0),
    ([0.0, 1.0, 0.0], 90.0),
    ([0.0, 0.0, 1.0], 90.0),
    ([1.0, 2.0, 3.0], 50.0),
    ([-2.0, 1.0, 0.5], 130.0),
];

/// How far a free body's rigid part is from turning with the body (module text); each
/// figure is relative and dimensionless, zero for an exact body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Invariance {
    /// Largest change of `Rb(P)` over the turns, the translation rows and columns scaled
    /// by `1/sqrt(m)`, the rotation ones by `1/sqrt(I_max)` (I_max the largest principal
    /// inertia about L0): a fraction of the mass or of the largest inertia.
    pub rigid_mass: f64,
    /// Largest change of `C(P)` over the turns, row j scaled by `1/sqrt(m_L,j)` and the
    /// columns as above (a fraction of the Cauchy-Schwarz bound of the coupling).
    pub coupling: f64,
    /// Largest departure of a triplet block of M_R from a multiple of I3, scaled by the
    /// largest diagonal entry of M_R: the structural form `W (x) I3` the exact
    /// construction writes.
    pub form: f64,
}

impl Invariance {
    /// The largest of the figures.
    pub fn worst(&self) -> f64 {
        self.rigid_mass.max(self.coupling).max(self.form)
    }
}

/// `G0`: frame-point velocities (rows: L1, L2, L3, L0, then the rotational DOFs; `nr`
/// of them) of the body-frame motion `(V_b, w_b)` of the unit frame: `v_L0 = V_b`,
/// `v_Lj = V_b + w_b x e_j`, `v_rot = w_b`.
fn unit_motion(nr: usize) -> DMatrix<f64> {
    let mut g = DMatrix::zeros(nr, 6);
    for point in 0..4 {
        let o = if point == 0 { 9 } else { 3 * (point - 1) };
        for c in 0..3 {
            g[(o + c, c)] = 1.0;
        }
        if point > 0 {
            // w x e_j: column a is e_a x e_j
            let j = point - 1;
            for a in 0..3 {
                let e = nalgebra::Vector3::ith(a, 1.0).cross(&nalgebra::Vector3::ith(j, 1.0));
                for c in 0..3 {
                    g[(o + c, 3 + a)] = e[c];
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

/// `B(P)`: P on every triplet of the `nr` rigid coordinates.
fn on_triplets(p: &Matrix3<f64>, nr: usize) -> DMatrix<f64> {
    let mut b = DMatrix::zeros(nr, nr);
    for t in 0..nr / 3 {
        b.view_mut((3 * t, 3 * t), (3, 3)).copy_from(p);
    }
    b
}

/// `Rb(P)` and `C(P)` of the module text.
fn seen_from_body(
    body: &Body,
    p: &Matrix3<f64>,
    g0: &DMatrix<f64>,
) -> (DMatrix<f64>, DMatrix<f64>) {
    let b = on_triplets(p, body.nr());
    let bg = &b * g0;
    let rb = bg.transpose() * &body.m_r * &bg;
    let mut mc = DMatrix::zeros(body.nr(), body.nl());
    for k in 0..3 {
        for l in 0..3 {
            mc += &body.m_c[3 * k + l] * p[(k, l)];
        }
    }
    (rb, mc.transpose() * bg)
}

/// Rotation by `deg` degrees about `axis` (any length).
fn turn(axis: [f64; 3], deg: f64) -> Matrix3<f64> {
    let a = nalgebra::Unit::new_normalize(nalgebra::Vector3::from(axis));
    nalgebra::Rotation3::from_axis_angle(&a, deg.to_radians()).into_inner()
}

/// The figures of a free body; `None` for a blocked one or one without rigid mass.
pub fn measure(body: &Body) -> Option<Invariance> {
    let nr = body.nr();
    if body.is_blocked() || nr < 12 {
        return None;
    }
    let g0 = unit_motion(nr);
    let (rb0, c0) = seen_from_body(body, &body.p0, &g0);
    let mass = (rb0[(0, 0)] + rb0[(1, 1)] + rb0[(2, 2)]) / 3.0;
    let inertia = SMatrix::<f64, 3, 3>::from_fn(|i, j| rb0[(3 + i, 3 + j)]);
    let i_max = inertia.symmetric_eigenvalues().max();
    if !(mass > 0.0 && i_max > 0.0) {
        return None;
    }
    let col = |k: usize| if k < 3 { mass.sqrt() } else { i_max.sqrt() };
    let mut rigid_mass: f64 = 0.0;
    let mut coupling: f64 = 0.0;
    for (axis, deg) in TURNS {
        let (rb, c) = seen_from_body(body, &(turn(axis, deg) * body.p0), &g0);
        for r in 0..6 {
            for s in 0..6 {
                rigid_mass = rigid_mass.max((rb[(r, s)] - rb0[(r, s)]).abs() / (col(r) * col(s)));
            }
        }
        for j in 0..body.nl() {
            let mj = body.m_l[j].sqrt();
            for s in 0..6 {
                coupling = coupling.max((c[(j, s)] - c0[(j, s)]).abs() / (mj * col(s)));
            }
        }
    }
    let scale = body.m_r.diagonal().amax();
    let mut form: f64 = 0.0;
    for a in 0..nr / 3 {
        for b in 0..nr / 3 {
            let blk = body.m_r.view((3 * a, 3 * b), (3, 3));
            let mean = blk.trace() / 3.0;
            for i in 0..3 {
                for j in 0..3 {
                    let want = if i == j { mean } else { 0.0 };
                    form = form.max((blk[(i, j)] - want).abs() / scale);
                }
            }
        }
    }
    Some(Invariance {
        rigid_mass,
        coupling,
        form,
    })
}

/// Two significant digits, for the figures of a message.
fn two_digits(x: f64) -> f64 {
    format!("{x:.1e}").parse().unwrap_or(x)
}

/// The warning for a free body whose rigid part does not turn with it (any figure above
/// [`TOL`]): the figures, what follows (angular momentum is not conserved; the expected
/// drift per radian turned, scaled from the measured naive beam) and the remedy. `None`
/// for a rotation-invariant or a blocked body. `source` names the file.
pub fn check(body: &Body, source: &str) -> Option<String> {
    let f = measure(body)?;
    if f.worst() <= TOL {
        return None;
    }
    let drift = two_digits(NAIVE_BEAM_DRIFT * f.rigid_mass / NAIVE_BEAM_FIGURE);
    Some(format!(
        "{source}: blocks 11-12 (M_R, M_C): the rigid part does not turn with the body: \
         turned from P0, the rigid mass the equations use changes by {} of the mass or \
         largest inertia and the rigid-elastic coupling by {} (M_R departs from the \
         rotation-invariant form W (x) I3 by {}); angular momentum is not conserved: expect \
         a drift of about {} per radian the body turns (measured {} per radian on a \
         free-free beam whose rigid mass changes by {}). Such files come from M_R = Phi_R^T \
         M Phi_R and M_C with the rotation on the local mode (as OpenRadioss writes them), \
         right only for nodal masses that are the same in every direction; rebuild the body \
         with `fxbody import` from its FE matrices",
        num(two_digits(f.rigid_mass)),
        num(two_digits(f.coupling)),
        num(two_digits(f.form)),
        num(drift),
        num(NAIVE_BEAM_DRIFT),
        num(NAIVE_BEAM_FIGURE),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `G0` moves the unit frame rigidly: `w x e_j` on L_j, nothing on L0's rotation
    /// columns, and with rotational DOFs `w` itself.
    #[test]
    fn unit_motion_is_a_rigid_motion_of_the_unit_frame() {
        let g = unit_motion(15);
        let w = nalgebra::Vector3::new(0.3, -1.2, 0.7);
        let u = nalgebra::DVector::from_vec(vec![0.0, 0.0, 0.0, w[0], w[1], w[2]]);
        let v = &g * u;
        for j in 0..3 {
            let want = w.cross(&nalgebra::Vector3::ith(j, 1.0));
            for c in 0..3 {
                assert!((v[3 * j + c] - want[c]).abs() < 1e-15);
            }
        }
        for c in 0..3 {
            assert_eq!(v[9 + c], 0.0);
            assert_eq!(v[12 + c], w[c]);
        }
    }
}
