//! Distributing spiders (`--spider NSET:distributing`, Nastran RBE3-like, Abaqus
//! distributing coupling-like): a new six-DOF node whose motion is the weighted
//! least-squares fit of a rigid motion to the set's translations. It adds no stiffness and
//! no mass: a force or moment at the node reaches the set as the load distribution that
//! motion implies, and the set deforms freely.
//!
//! With weights `w_i` (each node's share of the area of the set's element faces,
//! [`super::faces`]), `c = sum w_i x_i / W` (the node's position) and `p_i = x_i - c`:
//! - translation `u_r = sum w_i u_i / W`;
//! - rotation `theta = J^-1 sum (w_i / W) p_i x u_i`, `J = sum (w_i / W) (|p_i|^2 I - p_i p_i^T)`.
//!
//! Both are exact for a rigid motion of the set. These six equations `q = G u_s` tie the
//! node's DOFs `q` to the set's translations `u_s`. To make `q` DOFs of the model, six of
//! the set's translations (`m`, chosen by pivoting so that `G_m` is well conditioned) are
//! eliminated instead: `u_m = G_m^-1 (q - G_o u_o)`, every other DOF stays itself. That
//! change of coordinates is invertible, so the model keeps its eigenvalues and a free
//! model its six rigid motions in K's null space; the matrices become `T^T K T` and
//! `T^T M T` as for a rigid spider. A load `F` at the node does the work of `G^T F` on
//! the set (the distributed load), and the node moves by `G u`.

use std::collections::HashMap;

use nalgebra::{Matrix3, Matrix6, Vector3};

use super::faces;
use super::spider::transform;
use crate::fe::{Deck, Dof};
use crate::{ImportError, whole::WholeModel};

/// Nodes whose weight is below this fraction of the largest take no part (a flat
/// quadratic triangle's corners: their weight is rounding).
const WEIGHT_FLOOR: f64 = 1e-9;

/// What the spider was built from, for the report.
#[derive(Debug, Clone)]
pub struct Built {
    /// The new node's position: the weighted centre.
    pub centre: [f64; 3],
    /// Faces found.
    pub faces: usize,
    /// Nodes with weight.
    pub weighted: usize,
}

/// Tie set `set` to a new node `id` by the distributing equations (see the module text).
pub fn distributing(
    model: &WholeModel,
    set_name: &str,
    set: &[i64],
    deck: &Deck,
    deck_name: &str,
    id: i64,
) -> Result<(WholeModel, Built), ImportError> {
    let w = faces::weights(&deck.elements, set, &deck.nodes).map_err(|n| {
        ImportError::NoCoordinates {
            id: n,
            file: deck_name.to_string(),
        }
    })?;
    if w.faces == 0 {
        return Err(ImportError::BadSpider(format!(
            "{set_name}:distributing: no element face of {deck_name} has all its nodes in set \
             {set_name} (the weights are the faces' areas; faces are read from *ELEMENT \
             blocks of types {})",
            crate::fe::FACE_TYPES
                .iter()
                .map(|(t, _)| *t)
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    let top = w.nodes.values().fold(0.0f64, |a, &b| a.max(b.abs()));
    let nodes: Vec<(i64, f64)> = w
        .nodes
        .iter()
        .filter(|(_, a)| a.abs() > WEIGHT_FLOOR * top)
        .map(|(&n, &a)| (n, a))
        .collect();
    let total: f64 = nodes.iter().map(|(_, a)| a).sum();
    let mut centre = [0.0; 3];
    for (n, a) in &nodes {
        for (c, x) in centre.iter_mut().zip(deck.nodes[n]) {
            *c += a / total * x;
        }
    }
    let p: HashMap<i64, (f64, Vector3<f64>)> = nodes
        .iter()
        .map(|&(n, a)| {
            let x = deck.nodes[&n];
            (
                n,
                (
                    a / total,
                    Vector3::new(x[0] - centre[0], x[1] - centre[1], x[2] - centre[2]),
                ),
            )
        })
        .collect();
    let mut j = Matrix3::zeros();
    for (wi, pi) in p.values() {
        j += *wi * (pi.norm_squared() * Matrix3::identity() - pi * pi.transpose());
    }
    let jinv = j.try_inverse().filter(|_| {
        let e = j.symmetric_eigenvalues();
        e.min() > 1e-10 * e.max()
    });
    let Some(jinv) = jinv else {
        return Err(ImportError::BadSpider(format!(
            "{set_name}:distributing: the weighted nodes of set {set_name} lie on a line, so \
             they cannot carry a moment about it; give a set that spans a surface"
        )));
    };
    // G's column for each of the set's translations that has an equation.
    let mut cols: Vec<(usize, [f64; 6])> = Vec::new();
    for (old, d) in model.dofs.iter().enumerate() {
        let Some((wi, pi)) = p.get(&d.id) else {
            continue;
        };
        if !(1..=3).contains(&d.comp) {
            continue;
        }
        let mut e = Vector3::zeros();
        e[d.comp as usize - 1] = 1.0;
        let r = jinv * (*wi * pi.cross(&e));
        let mut g = [0.0; 6];
        g[d.comp as usize - 1] = *wi;
        g[3..].copy_from_slice(r.as_slice());
        cols.push((old, g));
    }
    let scale = j.trace().sqrt();
    let m = pivots(&cols, scale).ok_or_else(|| {
        ImportError::BadSpider(format!(
            "{set_name}:distributing: the set's free translations cannot carry all six \
             motions of the spider (too many of them held, or the set on a line)"
        ))
    })?;
    let gm = Matrix6::from_fn(|r, c| cols[m[c]].1[r]);
    let ginv = gm.try_inverse().ok_or_else(|| {
        ImportError::BadSpider(format!(
            "{set_name}:distributing: the equations of the spider are singular"
        ))
    })?;
    let dependent: HashMap<usize, usize> =
        m.iter().enumerate().map(|(a, &c)| (cols[c].0, a)).collect();
    let mut dofs = Vec::new();
    let mut index = vec![usize::MAX; model.dofs.len()];
    for (old, d) in model.dofs.iter().enumerate() {
        if !dependent.contains_key(&old) {
            index[old] = dofs.len();
            dofs.push(*d);
        }
    }
    let first = dofs.len();
    dofs.extend((1..=6).map(|c| Dof::new(id, c)));
    // u_m = G_m^-1 q - sum over the other columns o of (G_m^-1 G_o) u_o.
    let mut rows: Vec<Vec<(usize, f64)>> =
        (0..6).map(|_| Vec::with_capacity(cols.len() + 6)).collect();
    for (a, row) in rows.iter_mut().enumerate() {
        row.extend((0..6).map(|k| (first + k, ginv[(a, k)])));
    }
    for (old, g) in &cols {
        if dependent.contains_key(old) {
            continue;
        }
        let h = ginv * nalgebra::Vector6::from_column_slice(g);
        for (a, row) in rows.iter_mut().enumerate() {
            if h[a] != 0.0 {
                row.push((index[*old], -h[a]));
            }
        }
    }
    let map: Vec<Vec<(usize, f64)>> = (0..model.dofs.len())
        .map(|old| match dependent.get(&old) {
            Some(&a) => rows[a].clone(),
            None => vec![(index[old], 1.0)],
        })
        .collect();
    let n = dofs.len();
    let err = |e: crate::sparse::SolveError| ImportError::Whole(e.to_string());
    let k = transform(&model.k, &map, n).map_err(err)?;
    let mm = transform(&model.m, &map, n).map_err(err)?;
    Ok((
        WholeModel {
            dofs,
            k,
            m: mm,
            name: model.name.clone(),
        },
        Built {
            centre,
            faces: w.faces,
            weighted: nodes.len(),
        },
    ))
}

/// Six columns of G (rotation rows scaled by `scale`, a length of the set) chosen by
/// Gram-Schmidt with column pivoting: indices into `cols`, or `None` when G has rank
/// below six.
fn pivots(cols: &[(usize, [f64; 6])], scale: f64) -> Option<Vec<usize>> {
    let mut v: Vec<[f64; 6]> = cols
        .iter()
        .map(|(_, g)| {
            let mut x = *g;
            for r in &mut x[3..] {
                *r *= scale;
            }
            x
        })
        .collect();
    let first: f64 = v
        .iter()
        .map(|x| x.iter().map(|a| a * a).sum::<f64>())
        .fold(0.0, f64::max);
    let mut chosen = Vec::new();
    for _ in 0..6 {
        let (best, norm) = v
            .iter()
            .enumerate()
            .filter(|(i, _)| !chosen.contains(i))
            .map(|(i, x)| (i, x.iter().map(|a| a * a).sum::<f64>()))
            .fold((usize::MAX, 0.0), |a, b| if b.1 > a.1 { b } else { a });
        if best == usize::MAX || norm <= 1e-20 * first {
            return None;
        }
        chosen.push(best);
        let q: Vec<f64> = v[best].iter().map(|a| a / norm.sqrt()).collect();
        for x in v.iter_mut() {
            let d: f64 = x.iter().zip(&q).map(|(a, b)| a * b).sum();
            for (a, b) in x.iter_mut().zip(&q) {
                *a -= d * b;
            }
        }
    }
    Some(chosen)
}
