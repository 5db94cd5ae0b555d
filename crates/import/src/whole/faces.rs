//! The element faces of a node set and the area each of its nodes stands for: the weights
//! of a distributing spider ([`super::distributing`]).
//!
//! A face belongs to the set when every one of its nodes does: the faces of solids
//! (C3D4/C3D10 triangles, C3D8/C3D20 quadrilaterals, in CalculiX's node order) and shells
//! (the element itself). A node's weight is `integral of N_i dA` over the faces it is on
//! (`N_i` its shape function on the face), the load a uniform traction puts on it: a
//! quadratic triangle's corners get none and its mid-side nodes a third of its area each
//! (flat faces). The integral is by Gauss quadrature, exact for flat faces (degree 4 on
//! triangles, 3 x 3 points on quadrilaterals).

use std::collections::{BTreeMap, HashSet};

/// A face's nodes: corners first, then (quadratic) the mid-side nodes, edge `k` joining
/// corners `k` and `k + 1`.
type Face = Vec<i64>;

/// Corner node indices of each face, per solid family (CalculiX order).
const TET_FACES: [[usize; 3]; 4] = [[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]];
const HEX_FACES: [[usize; 4]; 6] = [
    [0, 1, 2, 3],
    [4, 7, 6, 5],
    [0, 4, 5, 1],
    [1, 5, 6, 2],
    [2, 6, 7, 3],
    [3, 7, 4, 0],
];
/// Mid-side node of each edge (corner pair) of a C3D10 and a C3D20.
const TET_EDGES: [(usize, usize, usize); 6] = [
    (0, 1, 4),
    (1, 2, 5),
    (2, 0, 6),
    (0, 3, 7),
    (1, 3, 8),
    (2, 3, 9),
];
const HEX_EDGES: [(usize, usize, usize); 12] = [
    (0, 1, 8),
    (1, 2, 9),
    (2, 3, 10),
    (3, 0, 11),
    (4, 5, 12),
    (5, 6, 13),
    (6, 7, 14),
    (7, 4, 15),
    (0, 4, 16),
    (1, 5, 17),
    (2, 6, 18),
    (3, 7, 19),
];

/// The mid-side node between corners `a` and `b`.
fn mid(edges: &[(usize, usize, usize)], nodes: &[i64], a: usize, b: usize) -> i64 {
    edges
        .iter()
        .find(|&&(p, q, _)| (p, q) == (a, b) || (p, q) == (b, a))
        .map_or(0, |&(_, _, m)| nodes[m])
}

/// The faces of one element (see the module text).
fn element_faces(kind: &str, nodes: &[i64]) -> Vec<Face> {
    let solid = |corners: &[usize], edges: &[(usize, usize, usize)], quadratic: bool| {
        let mut f: Face = corners.iter().map(|&c| nodes[c]).collect();
        if quadratic {
            for k in 0..corners.len() {
                f.push(mid(
                    edges,
                    nodes,
                    corners[k],
                    corners[(k + 1) % corners.len()],
                ));
            }
        }
        f
    };
    match kind {
        "C3D4" | "C3D10" | "C3D10T" => TET_FACES
            .iter()
            .map(|c| solid(c, &TET_EDGES, nodes.len() == 10))
            .collect(),
        "C3D8" | "C3D8R" | "C3D8I" | "C3D20" | "C3D20R" => HEX_FACES
            .iter()
            .map(|c| solid(c, &HEX_EDGES, nodes.len() == 20))
            .collect(),
        // Shells: the element is its own face, corners then mid-sides already.
        _ => vec![nodes.to_vec()],
    }
}

/// Shape functions and their derivatives at (r, s) for a face of `n` nodes (3, 6: the
/// triangle's area coordinates r, s, 1 - r - s; 4, 8: the square [-1, 1]^2).
fn shape(n: usize, r: f64, s: f64) -> (Vec<f64>, Vec<[f64; 2]>) {
    match n {
        3 => (
            vec![1.0 - r - s, r, s],
            vec![[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]],
        ),
        6 => {
            let t = 1.0 - r - s;
            (
                vec![
                    t * (2.0 * t - 1.0),
                    r * (2.0 * r - 1.0),
                    s * (2.0 * s - 1.0),
                    4.0 * t * r,
                    4.0 * r * s,
                    4.0 * s * t,
                ],
                vec![
                    [1.0 - 4.0 * t, 1.0 - 4.0 * t],
                    [4.0 * r - 1.0, 0.0],
                    [0.0, 4.0 * s - 1.0],
                    [4.0 * (t - r), -4.0 * r],
                    [4.0 * s, 4.0 * r],
                    [-4.0 * s, 4.0 * (t - s)],
                ],
            )
        }
        4 => {
            let c = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
            (
                c.iter()
                    .map(|&(a, b)| 0.25 * (1.0 + a * r) * (1.0 + b * s))
                    .collect(),
                c.iter()
                    .map(|&(a, b)| [0.25 * a * (1.0 + b * s), 0.25 * b * (1.0 + a * r)])
                    .collect(),
            )
        }
        _ => {
            // Serendipity quadrilateral: corners, then mid-sides of edges 1-2, 2-3, 3-4, 4-1.
            let c = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
            let m = [(0.0, -1.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0)];
            let mut n = Vec::with_capacity(8);
            let mut d = Vec::with_capacity(8);
            for &(a, b) in &c {
                let (p, q) = (1.0 + a * r, 1.0 + b * s);
                n.push(0.25 * p * q * (a * r + b * s - 1.0));
                d.push([
                    0.25 * a * q * (2.0 * a * r + b * s),
                    0.25 * b * p * (a * r + 2.0 * b * s),
                ]);
            }
            for &(a, b) in &m {
                if a == 0.0 {
                    n.push(0.5 * (1.0 - r * r) * (1.0 + b * s));
                    d.push([-r * (1.0 + b * s), 0.5 * b * (1.0 - r * r)]);
                } else {
                    n.push(0.5 * (1.0 + a * r) * (1.0 - s * s));
                    d.push([0.5 * a * (1.0 - s * s), -s * (1.0 + a * r)]);
                }
            }
            (n, d)
        }
    }
}

/// Quadrature points (r, s, weight) for a face of `n` nodes.
fn points(n: usize) -> Vec<(f64, f64, f64)> {
    if n == 3 || n == 6 {
        // Six points, degree 4 (Dunavant), weights summing to the reference area 1/2.
        let (a, wa) = (0.445_948_490_915_965, 0.223_381_589_678_011 / 2.0);
        let (b, wb) = (0.091_576_213_509_771, 0.109_951_743_655_322 / 2.0);
        let (a2, b2) = (1.0 - 2.0 * a, 1.0 - 2.0 * b);
        vec![
            (a, a, wa),
            (a2, a, wa),
            (a, a2, wa),
            (b, b, wb),
            (b2, b, wb),
            (b, b2, wb),
        ]
    } else {
        let g = (0.6f64).sqrt();
        let x = [(-g, 5.0 / 9.0), (0.0, 8.0 / 9.0), (g, 5.0 / 9.0)];
        x.iter()
            .flat_map(|&(r, wr)| x.iter().map(move |&(s, ws)| (r, s, wr * ws)))
            .collect()
    }
}

/// What [`weights`] found.
#[derive(Debug, Clone)]
pub struct Weights {
    /// Each node of the set on a face, with `integral of N_i dA` (area units).
    pub nodes: BTreeMap<i64, f64>,
    /// Faces of the set.
    pub faces: usize,
    /// Their total area.
    pub area: f64,
}

/// The faces of `elements` whose nodes all lie in `set`, and each node's share of their
/// area (see the module text). `coords` gives positions; a face node without one is an
/// error naming it.
pub fn weights(
    elements: &[(String, Vec<i64>)],
    set: &[i64],
    coords: &BTreeMap<i64, [f64; 3]>,
) -> Result<Weights, i64> {
    let in_set: HashSet<i64> = set.iter().copied().collect();
    let mut seen: HashSet<Vec<i64>> = HashSet::new();
    let mut out = Weights {
        nodes: BTreeMap::new(),
        faces: 0,
        area: 0.0,
    };
    for (kind, nodes) in elements {
        for face in element_faces(kind, nodes) {
            if !face.iter().all(|n| in_set.contains(n)) {
                continue;
            }
            // A face shared by two elements (an inner face of the set) counts once.
            let mut key = face.clone();
            key.sort_unstable();
            if !seen.insert(key) {
                continue;
            }
            let x: Vec<[f64; 3]> = face
                .iter()
                .map(|n| coords.get(n).copied().ok_or(*n))
                .collect::<Result<_, _>>()?;
            for (r, s, w) in points(face.len()) {
                let (n, d) = shape(face.len(), r, s);
                let mut t = [[0.0; 3]; 2];
                for (xi, di) in x.iter().zip(&d) {
                    for k in 0..3 {
                        t[0][k] += di[0] * xi[k];
                        t[1][k] += di[1] * xi[k];
                    }
                }
                let cross = [
                    t[0][1] * t[1][2] - t[0][2] * t[1][1],
                    t[0][2] * t[1][0] - t[0][0] * t[1][2],
                    t[0][0] * t[1][1] - t[0][1] * t[1][0],
                ];
                let da = w * (cross[0].powi(2) + cross[1].powi(2) + cross[2].powi(2)).sqrt();
                out.area += da;
                for (node, ni) in face.iter().zip(&n) {
                    *out.nodes.entry(*node).or_insert(0.0) += da * ni;
                }
            }
            out.faces += 1;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat quadratic triangle: corners carry nothing, mid-sides a third of the area
    /// each; a flat serendipity square: corners -1/12 and mid-sides 1/3 of its area (the
    /// consistent loads of a uniform traction); a linear square: a quarter each.
    #[test]
    fn nodal_areas_of_flat_faces() {
        let mut coords = BTreeMap::new();
        let pts = [
            (1, [0.0, 0.0, 0.0]),
            (2, [2.0, 0.0, 0.0]),
            (3, [2.0, 2.0, 0.0]),
            (4, [0.0, 2.0, 0.0]),
            (5, [1.0, 0.0, 0.0]),
            (6, [2.0, 1.0, 0.0]),
            (7, [1.0, 2.0, 0.0]),
            (8, [0.0, 1.0, 0.0]),
            (9, [1.0, 1.0, 0.0]),
        ];
        for (n, x) in pts {
            coords.insert(n, x);
        }
        let all: Vec<i64> = (1..=9).collect();
        let tri = vec![("S6".to_string(), vec![1, 2, 3, 5, 6, 9])];
        let w = weights(&tri, &all, &coords).unwrap();
        assert!((w.area - 2.0).abs() < 1e-14);
        for n in [1, 2, 3] {
            assert!(w.nodes[&n].abs() < 1e-14, "{n}: {}", w.nodes[&n]);
        }
        for n in [5, 6, 9] {
            assert!((w.nodes[&n] - 2.0 / 3.0).abs() < 1e-14);
        }
        let quad8 = vec![("S8".to_string(), vec![1, 2, 3, 4, 5, 6, 7, 8])];
        let w = weights(&quad8, &all, &coords).unwrap();
        assert!((w.area - 4.0).abs() < 1e-14);
        assert!((w.nodes[&1] + 4.0 / 12.0).abs() < 1e-14, "{}", w.nodes[&1]);
        assert!((w.nodes[&5] - 4.0 / 3.0).abs() < 1e-14, "{}", w.nodes[&5]);
        let quad4 = vec![("S4".to_string(), vec![1, 2, 3, 4])];
        let w = weights(&quad4, &all, &coords).unwrap();
        assert!((w.nodes[&3] - 1.0).abs() < 1e-14);
        // Only faces whose nodes all lie in the set count.
        let w = weights(&quad4, &[1, 2, 3], &coords).unwrap();
        assert_eq!((w.faces, w.nodes.len()), (0, 0));
    }

    /// A unit cube C3D8: the set of its z = 0 face's nodes gets that face (once), whatever
    /// the element's other faces.
    #[test]
    fn solid_faces_in_the_set() {
        let mut coords = BTreeMap::new();
        for (k, x) in [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ]
        .into_iter()
        .enumerate()
        {
            coords.insert(k as i64 + 1, x);
        }
        let hex = vec![("C3D8".to_string(), (1..=8).collect())];
        let w = weights(&hex, &[1, 2, 3, 4], &coords).unwrap();
        assert_eq!(w.faces, 1);
        assert!((w.area - 1.0).abs() < 1e-14);
        assert!(w.nodes.values().all(|&a| (a - 0.25).abs() < 1e-14));
    }
}
