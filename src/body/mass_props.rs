//! Rigid-body mass properties of a free body from its rigid mass M_R: the mass, the
//! centre of gravity and the inertia tensor at it, which `fxbody info` reports so a user
//! can check a body against the model it came from.
//!
//! Rigid mode `3j + c` (j, c = 0..2) is `X_j e_c` and mode `9 + c` is `W e_c` with
//! `W = 1 - X - Y - Z` (FORMULATION.md section 1), so for any direction c the 4 x 4 block
//! `J(a, b) = M_R(idx(a, c), idx(b, c))` over the functions `(X, Y, Z, W)` holds the mass
//! moments: since `1 = X + Y + Z + W`, the mass is the sum of all of J, the first moment
//! `int X_j dm` is row j's sum and the second moment `int X_j X_k dm` is `J(j, k)`. The
//! three directions are averaged (they are equal for a mass that is the same in every
//! direction, the usual lumped or consistent case). With Irot the rotation rows (modes
//! 13..15, global frame) add the nodes' own rotary inertia `M_R(12 + a, 12 + b)`.

use nalgebra::{Matrix3, Vector3};

use super::Body;

/// Mass, centre of gravity and inertia of a free body.
#[derive(Debug, Clone, PartialEq)]
pub struct MassProperties {
    /// Total mass.
    pub mass: f64,
    /// Centre of gravity relative to the frame origin L0, in global axes at P0
    /// (`P0 c_local`): add L0's position to place it.
    pub cog_from_l0: Vector3<f64>,
    /// Inertia tensor at the centre of gravity, global axes at P0.
    pub inertia: Matrix3<f64>,
}

/// The mass properties of a free body; `None` for a blocked body (no M_R) or a body
/// without mass.
pub fn mass_properties(body: &Body) -> Option<MassProperties> {
    if body.is_blocked() || body.nr() < 12 {
        return None;
    }
    let idx = |a: usize, c: usize| if a < 3 { 3 * a + c } else { 9 + c };
    let mut j = [[0.0; 4]; 4];
    for (a, row) in j.iter_mut().enumerate() {
        for (b, v) in row.iter_mut().enumerate() {
            *v = (0..3)
                .map(|c| body.m_r[(idx(a, c), idx(b, c))])
                .sum::<f64>()
                / 3.0;
        }
    }
    let mass: f64 = j.iter().flatten().sum();
    if mass.is_nan() || mass <= 0.0 {
        return None;
    }
    let first = Vector3::from_fn(|a, _| j[a].iter().sum::<f64>());
    let second = Matrix3::from_fn(|a, b| j[a][b]);
    let c = first / mass;
    // Second moments about the centre of gravity, local axes; inertia = tr(E) I - E.
    let e = second - c * c.transpose() * mass;
    let local = Matrix3::identity() * e.trace() - e;
    let mut inertia = body.p0 * local * body.p0.transpose();
    if body.nr() >= 15 {
        inertia += Matrix3::from_fn(|a, b| body.m_r[(12 + a, 12 + b)]);
    }
    Some(MassProperties {
        mass,
        cog_from_l0: body.p0 * c,
        inertia,
    })
}
