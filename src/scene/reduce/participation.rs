//! What truncation costs, mode by mode: the share of the static deflection each mode of
//! (K_L, m_L) carries at chosen nodes, and the effective mass of each mode of a free
//! body. Both use the mass-normalised modes of [`super::ModalBasis`].

use nalgebra::{DMatrix, Matrix3};

use super::ModalBasis;
use crate::body::Body;

/// Static participation at some nodes: `fraction[(i, 6 k + c)]` is the share of the
/// static deflection of node k in global direction c (X Y Z XX YY ZZ) under a unit load
/// at that node and direction carried by mode i (ascending frequency). The shares of all
/// modes sum to 1 (a mode with zero frequency carries none: its share is 0 and a body
/// with such modes has no static deflection). A column with no deflection (a clamped or
/// mode-free DOF) is all zeros.
#[derive(Debug, Clone)]
pub struct Participation {
    /// Mode frequencies, Hz, ascending.
    pub frequencies_hz: Vec<f64>,
    /// Shares, `nL x 6m`.
    pub fraction: DMatrix<f64>,
    /// Static deflection per column (m/N or rad/(N m)), from all modes.
    pub deflection: Vec<f64>,
}

/// The static participation of each mode at `nodes` (indices into the node list), the
/// directions taken in the global frame at P0.
pub fn static_participation(body: &Body, nodes: &[usize]) -> Participation {
    let basis = ModalBasis::of(body);
    let nl = body.nl();
    let m = nodes.len();
    // phi(6k + c, i): mode i at node k, component c, rotated to the global frame by P0.
    let p0: Matrix3<f64> = body.p0;
    let phi = DMatrix::from_fn(6 * m, nl, |row, i| {
        let (k, c) = (row / 6, row % 6);
        let base = 6 * nodes[k] + 3 * (c / 3);
        (0..3)
            .map(|b| {
                p0[(c % 3, b)]
                    * (0..nl)
                        .map(|j| body.phi_l[(base + b, j)] * basis.psi[(j, i)])
                        .sum::<f64>()
            })
            .sum::<f64>()
    });
    let mut fraction = DMatrix::zeros(nl, 6 * m);
    let mut deflection = vec![0.0; 6 * m];
    for col in 0..6 * m {
        for i in 0..nl {
            let w = basis.omega[i];
            if w > 0.0 {
                fraction[(i, col)] = phi[(col, i)].powi(2) / (w * w);
            }
        }
        let total: f64 = fraction.column(col).sum();
        deflection[col] = total;
        if total > 0.0 {
            fraction.column_mut(col).scale_mut(1.0 / total);
        }
    }
    Participation {
        frequencies_hz: basis.frequencies_hz(),
        fraction,
        deflection,
    }
}

/// Effective mass of each mode of a free body along the global X, Y, Z at P0:
/// `(phi_i^T M r_c)^2 / (phi_i^T M phi_i)` with `phi_i^T M r_c = s_c^T M_C(P0) psi_i`
/// (`s_c` the rigid translation along c: rigid modes c, 3+c, 6+c, 9+c) and
/// `phi_i^T M phi_i = 1` (mass-normalised). `nL x 3`; `None` for a blocked body (no M_C
/// in its file). Modes of a free-free body are mass-orthogonal to the rigid motions and
/// have none; the modes of a supported body carry the mass that moves with them.
pub fn effective_mass(body: &Body) -> Option<DMatrix<f64>> {
    if body.is_blocked() || body.nr() < 12 {
        return None;
    }
    let basis = ModalBasis::of(body);
    let nl = body.nl();
    let mut mc = DMatrix::zeros(body.nr(), nl);
    for k in 0..3 {
        for l in 0..3 {
            mc += &body.m_c[3 * k + l] * body.p0[(k, l)];
        }
    }
    let proj = &mc * &basis.psi;
    Some(DMatrix::from_fn(nl, 3, |i, c| {
        [c, 3 + c, 6 + c, 9 + c]
            .iter()
            .map(|&r| proj[(r, i)])
            .sum::<f64>()
            .powi(2)
    }))
}
