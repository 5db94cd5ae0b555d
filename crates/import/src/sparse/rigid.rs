//! The six rigid motions of a model over its DOFs, with CalculiX's spider reading, and
//! the check that they lie in K's null space.
//!
//! A rigid motion with translation `v` and rotation `w` (small) moves a point at `x` by
//! `v + w x (x - o)` and turns every rotational DOF by `w`. Over a DOF list:
//! - a node's direction c = 1..3 gets `(v + w x (x - o))_c`;
//! - a node's direction c = 4..6 (shells, beams) gets `w_(c-3)`;
//! - a CalculiX `*RIGID BODY` ROT node's directions 1..3 are the spider's rotations, so
//!   they get `w_c` (the node's coordinates do not matter); the REF node is an ordinary
//!   node whose translations are the spider's;
//! - a scalar point (direction 0) gets 0.
//!
//! Read that way, a free CalculiX model's K annihilates the six motions to rounding; read
//! the ROT node as an ordinary node, it does not (tested in `tests/ccx.rs`).

use std::collections::{HashMap, HashSet};

use faer::Mat;

use crate::fe::Dof;
use crate::sparse::csc::SymCsc;
use crate::sparse::eigen::inf_norm;
use crate::sparse::error::SolveError;

/// The six rigid motions (columns: translations x, y, z, then rotations about x, y, z
/// through `origin`) over `dofs`. `coords` gives each node's position; `rot_nodes` are
/// the ROT nodes of the model's spiders. Fails naming the first node without coordinates.
pub fn rigid_motions(
    dofs: &[Dof],
    coords: &HashMap<i64, [f64; 3]>,
    rot_nodes: &HashSet<i64>,
    origin: [f64; 3],
) -> Result<Mat<f64>, SolveError> {
    let mut r = Mat::zeros(dofs.len(), 6);
    for (i, d) in dofs.iter().enumerate() {
        let c = d.comp as usize;
        if c == 0 {
            continue;
        }
        if rot_nodes.contains(&d.id) {
            if c > 3 {
                return Err(SolveError::Input(format!(
                    "DOF {d}: a spider's ROT node carries rotations in directions 1-3 only"
                )));
            }
            r[(i, 3 + c - 1)] = 1.0;
            continue;
        }
        if c > 3 {
            r[(i, c - 1)] = 1.0;
            continue;
        }
        let x = coords.get(&d.id).ok_or_else(|| {
            SolveError::Input(format!("node {} (DOF {d}) has no coordinates", d.id))
        })?;
        let p = [x[0] - origin[0], x[1] - origin[1], x[2] - origin[2]];
        r[(i, c - 1)] = 1.0;
        // (e_k x p)_c for the rotation about axis k.
        for k in 0..3 {
            r[(i, 3 + k)] = cross_unit(k, p)[c - 1];
        }
    }
    Ok(r)
}

/// `e_k x p`.
fn cross_unit(k: usize, p: [f64; 3]) -> [f64; 3] {
    match k {
        0 => [0.0, -p[2], p[1]],
        1 => [p[2], 0.0, -p[0]],
        _ => [-p[1], p[0], 0.0],
    }
}

/// How far rigid motions are from K's null space: the worst column's
/// `|K r|_inf / (|K|_inf |r|_inf)`, that column and the row of its largest term.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NullResidual {
    /// The relative residual.
    pub residual: f64,
    /// Its column (0-2 translations, 3-5 rotations).
    pub column: usize,
    /// The row (DOF index) where `K r` is largest.
    pub row: usize,
}

/// [`NullResidual`] of the columns of `r` against `k`.
pub fn null_residual(k: &SymCsc, r: &Mat<f64>) -> NullResidual {
    let mut kr = Mat::zeros(r.nrows(), r.ncols());
    k.mul(r.as_ref(), kr.as_mut());
    let norm = inf_norm(k);
    let mut worst = NullResidual {
        residual: 0.0,
        column: 0,
        row: 0,
    };
    for c in 0..r.ncols() {
        let rn = (0..r.nrows()).map(|i| r[(i, c)].abs()).fold(0.0, f64::max);
        let (row, top) = (0..r.nrows())
            .map(|i| (i, kr[(i, c)].abs()))
            .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
        let rel = top / (norm * rn);
        if rel > worst.residual {
            worst = NullResidual {
                residual: rel,
                column: c,
                row,
            };
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_moves_points_and_turns_rot_nodes() {
        let dofs = [
            Dof::new(1, 1),
            Dof::new(1, 2),
            Dof::new(9, 3),
            Dof::new(2, 6),
        ];
        let coords = HashMap::from([(1, [1.0, 2.0, 3.0]), (2, [0.0, 0.0, 0.0])]);
        let rot = HashSet::from([9]);
        let r = rigid_motions(&dofs, &coords, &rot, [1.0, 0.0, 0.0]).unwrap();
        // Rotation about z through (1, 0, 0) moves (1, 2, 3) by (-2, 0, 0).
        assert_eq!(r[(0, 5)], -2.0);
        assert_eq!(r[(1, 5)], 0.0);
        // Rotation about x moves it by (0, -3, 2): its y component.
        assert_eq!(r[(1, 3)], -3.0);
        assert_eq!(r[(2, 5)], 1.0);
        assert_eq!(r[(2, 2)], 0.0);
        assert_eq!(r[(3, 5)], 1.0);
        let e = rigid_motions(&[Dof::new(4, 1)], &coords, &rot, [0.0; 3]).unwrap_err();
        assert_eq!(e.to_string(), "node 4 (DOF 4.1) has no coordinates");
    }
}
