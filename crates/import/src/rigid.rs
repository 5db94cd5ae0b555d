//! The rigid motions of an imported body, its exact mass properties, and the rigid mass
//! matrix M_R built from them.
//!
//! Six rigid motions R (translations, small rotations about the centre of mass x_c) on
//! the DOFs with mass; `Rb = R^T M R` is exact for Guyan and Craig-Bampton reductions
//! (both represent rigid motion exactly), and gives the mass m, x_c and the inertia I
//! about x_c.
//!
//! M_R is never `Phi_R^T M Phi_R` of a reduced mass: the engine applies a constant M_R
//! against global velocities, which is right at every attitude only if the block of the
//! twelve affine modes is `W (x) I3`. With the weights (X, Y, Z, 1-X-Y-Z) of the rigid
//! modes, `s = 0` at x_c and the second moment J: `W = [[J, -J 1], [-(J 1)^T, m + 1^T J 1]]`.
//! Without rotational DOFs `J = tr(I)/2 - I`. With them (Irot = 1) the rotational modes
//! 13..15 take `d I3`, d the mean rotary inertia `tr(Phi_rot^T M Phi_rot)/3` clipped to
//! `[0, min_i(I_j + I_k - I_i)]`, and J is formed from `I - d 1`: the rigid kinetic
//! energy `m v^2/2 + w^T I w/2` is exact at every attitude.

use std::collections::BTreeMap;

use nalgebra::{DMatrix, Matrix3, SymmetricEigen, Vector3};

use super::ImportError;
use super::dofs::Reduced;
use crate::fe::Dof;

/// Names of the six rigid motions, for messages.
pub const MOTIONS: [&str; 6] = [
    "translation along x",
    "translation along y",
    "translation along z",
    "rotation about x through the CoM",
    "rotation about y through the CoM",
    "rotation about z through the CoM",
];

/// Mass properties from the six rigid motions, and those motions.
#[derive(Debug, Clone)]
pub struct MassProps {
    /// Total mass.
    pub mass: f64,
    /// Centre of mass (global).
    pub com: [f64; 3],
    /// Inertia tensor about the centre of mass (global axes).
    pub inertia: Matrix3<f64>,
    /// Mean rotary inertia of the rotational DOFs, `tr(Phi_rot^T M Phi_rot)/3`.
    pub rotary: f64,
    /// `R^T M R` about the centre of mass (6x6).
    pub rb: DMatrix<f64>,
    /// The six rigid motions on the a-set, rotations about the centre of mass.
    pub r: DMatrix<f64>,
    /// Local coordinates `x - x_c` of every grid point.
    pub local: BTreeMap<i64, [f64; 3]>,
    /// Largest relative anisotropy of the translational block of Rb (should be round-off).
    pub anisotropy: f64,
}

/// Six rigid motions on `dofs`, rotations about `p`.
fn motions(dofs: &[Dof], x: &BTreeMap<i64, [f64; 3]>, p: [f64; 3]) -> DMatrix<f64> {
    let mut r = DMatrix::zeros(dofs.len(), 6);
    for (row, d) in dofs.iter().enumerate() {
        if d.is_scalar() {
            continue;
        }
        let c = (d.comp - 1) as usize;
        if c < 3 {
            r[(row, c)] = 1.0;
            let v = Vector3::new(x[&d.id][0] - p[0], x[&d.id][1] - p[1], x[&d.id][2] - p[2]);
            for a in 0..3 {
                // (e_a x v)_c
                r[(row, 3 + a)] = Vector3::ith(a, 1.0).cross(&v)[c];
            }
        } else {
            r[(row, c)] = 1.0;
        }
    }
    r
}

impl MassProps {
    /// Mass properties of the reduced model (every grid point must have coordinates).
    pub fn of(model: &Reduced, x: &BTreeMap<i64, [f64; 3]>) -> Result<MassProps, ImportError> {
        let dofs = model.a_dofs();
        let ids = model.grid_ids();
        let mut p = [0.0; 3];
        for id in &ids {
            for c in 0..3 {
                p[c] += x[id][c] / ids.len() as f64;
            }
        }
        let r0 = motions(&dofs, x, p);
        let rb0 = r0.transpose() * &model.m * &r0;
        let mass = (rb0[(0, 0)] + rb0[(1, 1)] + rb0[(2, 2)]) / 3.0;
        if mass.is_nan() || mass <= 0.0 {
            return Err(ImportError::NoModes(format!(
                "the total mass is {} (rigid translation carries no mass)",
                fxbody::num::num(model.scale.mass_out(mass))
            )));
        }
        let c = rb0.view((0, 3), (3, 3));
        let s = [
            0.5 * (c[(1, 2)] - c[(2, 1)]),
            0.5 * (c[(2, 0)] - c[(0, 2)]),
            0.5 * (c[(0, 1)] - c[(1, 0)]),
        ];
        let com = [p[0] + s[0] / mass, p[1] + s[1] / mass, p[2] + s[2] / mass];
        let r = motions(&dofs, x, com);
        let mut rb = r.transpose() * &model.m * &r;
        rb = (&rb + rb.transpose()) * 0.5;
        let inertia = Matrix3::from_fn(|i, j| rb[(3 + i, 3 + j)]);
        let mut anisotropy: f64 = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                let want = if i == j { mass } else { 0.0 };
                anisotropy = anisotropy.max((rb[(i, j)] - want).abs() / mass);
            }
        }
        let mut rot = 0.0;
        for (row, d) in dofs.iter().enumerate() {
            for (col, e) in dofs.iter().enumerate() {
                if d.comp >= 4 && d.comp == e.comp {
                    rot += model.m[(row, col)];
                }
            }
        }
        let local = ids
            .iter()
            .map(|id| {
                let v = x[id];
                (*id, [v[0] - com[0], v[1] - com[1], v[2] - com[2]])
            })
            .collect();
        Ok(MassProps {
            mass,
            com,
            inertia,
            rotary: rot / 3.0,
            rb,
            r,
            local,
            anisotropy,
        })
    }

    /// The exact, rotation-invariant M_R (12x12, or 15x15 with rotational DOFs), and the
    /// rotary share d given to modes 13..15.
    pub fn m_r(&self, irot: bool) -> (DMatrix<f64>, f64) {
        let d = if irot {
            let e = SymmetricEigen::new(self.inertia).eigenvalues;
            let limit = e.sum() - 2.0 * e.max();
            self.rotary.min(limit).max(0.0)
        } else {
            0.0
        };
        let ip = self.inertia - Matrix3::identity() * d;
        let j = Matrix3::identity() * (ip.trace() / 2.0) - ip;
        let mut w = DMatrix::zeros(4, 4);
        for a in 0..3 {
            for b in 0..3 {
                w[(a, b)] = j[(a, b)];
            }
            let row: f64 = (0..3).map(|b| j[(a, b)]).sum();
            w[(a, 3)] = -row;
            w[(3, a)] = -row;
        }
        w[(3, 3)] = self.mass + j.sum();
        let nr = if irot { 15 } else { 12 };
        let mut m = DMatrix::zeros(nr, nr);
        for a in 0..4 {
            for b in 0..4 {
                for c in 0..3 {
                    m[(3 * a + c, 3 * b + c)] = w[(a, b)];
                }
            }
        }
        if irot {
            for c in 0..3 {
                m[(12 + c, 12 + c)] = d;
            }
        }
        (m, d)
    }
}

/// Value of rigid mode `mode` (0-based, FORMULATION.md order) at a node with local
/// coordinates `x`, component `comp` (1..6); rotation rows are 1 only where the node has
/// that rotational DOF (`rot`).
pub fn mode_value(x: [f64; 3], comp: u8, mode: usize, rot: bool) -> f64 {
    let c = (comp - 1) as usize;
    if c < 3 {
        match mode {
            m if m < 9 && m % 3 == c => x[m / 3],
            m if (9..12).contains(&m) && m - 9 == c => 1.0 - x[0] - x[1] - x[2],
            _ => 0.0,
        }
    } else if rot && mode == 12 + (c - 3) {
        1.0
    } else {
        0.0
    }
}

/// The rigid modes (nR columns) on a DOF list, optionally with `T_kl` applied at every
/// node triplet (component `l` moved to component `k`, both 0-based; scalar points, on
/// which every rigid mode is zero, stay zero). `has` tells whether a DOF exists.
pub fn modes_on(
    dofs: &[Dof],
    local: &BTreeMap<i64, [f64; 3]>,
    nr: usize,
    tkl: Option<(usize, usize)>,
    has: &dyn Fn(Dof) -> bool,
) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(dofs.len(), nr);
    for (row, d) in dofs.iter().enumerate() {
        if d.is_scalar() {
            continue;
        }
        let c = (d.comp - 1) as usize;
        let src = match tkl {
            None => d.comp,
            Some((k, l)) if c % 3 == k => (3 * (c / 3) + l + 1) as u8,
            Some(_) => continue,
        };
        let rot = src >= 4
            && has(Dof {
                id: d.id,
                comp: src,
            });
        for mode in 0..nr {
            out[(row, mode)] = mode_value(local[&d.id], src, mode, rot);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rigid-mode amplitudes of a translation (columns 0..3) and of a small rotation about
    /// L0 (columns 3..6), P0 = I (FORMULATION.md: modes 3j+c are X_j e_c, 9+c the rest).
    fn rigid_map(nr: usize) -> DMatrix<f64> {
        let mut g = DMatrix::zeros(nr, 6);
        for c in 0..3 {
            for j in 0..4 {
                g[(3 * j + c, c)] = 1.0;
            }
            for j in 0..3 {
                let v = Vector3::ith(c, 1.0).cross(&Vector3::ith(j, 1.0));
                for r in 0..3 {
                    g[(3 * j + r, 3 + c)] = v[r];
                }
            }
            if nr == 15 {
                g[(12 + c, 3 + c)] = 1.0;
            }
        }
        g
    }

    #[test]
    fn exact_m_r_gives_the_rigid_mass_and_inertia_with_and_without_rotations() {
        let inertia = Matrix3::new(1.38, -0.99, -0.19, -0.99, 2.13, -0.29, -0.19, -0.29, 3.17);
        for (irot, rotary) in [(false, 0.0), (true, 0.05), (true, 10.0)] {
            let props = MassProps {
                mass: 18.84,
                com: [0.0; 3],
                inertia,
                rotary,
                rb: DMatrix::zeros(6, 6),
                r: DMatrix::zeros(0, 6),
                local: BTreeMap::new(),
                anisotropy: 0.0,
            };
            let (m_r, d) = props.m_r(irot);
            let g = rigid_map(m_r.nrows());
            let rb = g.transpose() * &m_r * &g;
            for i in 0..6 {
                for j in 0..6 {
                    let want = match (i < 3, j < 3) {
                        (true, true) => f64::from(u8::from(i == j)) * 18.84,
                        (false, false) => inertia[(i - 3, j - 3)],
                        _ => 0.0,
                    };
                    assert!((rb[(i, j)] - want).abs() < 1e-12, "irot {irot}: ({i},{j})");
                }
            }
            // W (x) I3: the same block for every direction, so every attitude alike
            for c in 1..3 {
                for a in 0..4 {
                    for b in 0..4 {
                        assert_eq!(m_r[(3 * a + c, 3 * b + c)], m_r[(3 * a, 3 * b)]);
                        assert_eq!(m_r[(3 * a + c, 3 * b)], 0.0);
                    }
                }
            }
            // the rotary share is clipped so that the affine part stays semi-definite
            let e = SymmetricEigen::new(inertia).eigenvalues;
            assert!(d >= 0.0 && d <= e.sum() - 2.0 * e.max() + 1e-15);
            let w = SymmetricEigen::new(m_r.view((0, 0), (12, 12)).into_owned()).eigenvalues;
            assert!(
                w.min() > -1e-12,
                "irot {irot}, d {d}: M_R not semi-definite"
            );
        }
    }
}
