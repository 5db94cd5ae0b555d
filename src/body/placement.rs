//! Where a free body's nodes are: its rigid modes fix every node relative to the frame
//! origin L0 ([`Body::rigid_mode_positions`]), so a coordinate file can only place L0.
//! A file whose nodes contradict the modes (wrong units, a different mesh, a scaled
//! deck) is refused: positions from the file with motion from the modes would be a
//! silently wrong body.

use std::collections::HashMap;

use super::Body;
use crate::num::num;

/// Relative tolerance, against the body's size, between the coordinate file and the
/// positions the rigid modes give (10 printed digits in the file leave ~1e-9).
pub const PLACEMENT_TOL: f64 = 1e-6;

/// A node ID, its position in the file and its position from the modes (L0 at 0).
type Pair = (i64, [f64; 3], [f64; 3]);

fn show(x: &[f64; 3]) -> String {
    format!("({}, {}, {})", num(x[0]), num(x[1]), num(x[2]))
}

/// A coordinate file whose nodes contradict a free body's rigid modes: the worst node,
/// where the file and the modes put it, and what the misfit looks like.
#[derive(Debug, thiserror::Error)]
#[error(
    "{coords}: node {id} is at {} but the rigid modes of {body} put it at {} \
     (frame origin L0 at {} from the file's mean offset): off by {}, more than {} of the \
     body's size {}; a coordinate file only places a free body, its nodes must match the modes{hint}",
    show(.at_file), show(.at_modes), show(.origin), num(*.off), num(PLACEMENT_TOL), num(*.size)
)]
pub struct PlacementError {
    /// The coordinate file.
    pub coords: String,
    /// The body file.
    pub body: String,
    /// The worst node's ID.
    pub id: i64,
    /// Its position in the coordinate file.
    pub at_file: [f64; 3],
    /// Its position from the rigid modes, placed at `origin`.
    pub at_modes: [f64; 3],
    /// The frame origin L0 the file's mean offset gives.
    pub origin: [f64; 3],
    /// The distance between the two positions.
    pub off: f64,
    /// The body's size (bounding-box diagonal).
    pub size: f64,
    /// A units hint when the file looks scaled (starts with "; "), or empty.
    pub hint: String,
}

/// Check the coordinates `xyz` (by node ID) of a free body against its rigid modes and
/// return the frame origin L0 they place it at (the mean offset). Nothing to check, and
/// `None`, for a blocked body or when `xyz` lists none of the body's nodes. Refused when
/// some node is off by more than [`PLACEMENT_TOL`] times the body's size: the message
/// names the worst node, both positions and, when the file is the modes' positions
/// scaled by a power of ten, a hint about units. `coords_name` and `body_name` name the
/// files in the message. The error is boxed: it carries both positions and is large.
pub fn check_coords(
    body: &Body,
    xyz: &HashMap<i64, [f64; 3]>,
    coords_name: &str,
    body_name: &str,
) -> Result<Option<[f64; 3]>, Box<PlacementError>> {
    let Some(derived) = body.rigid_mode_positions() else {
        return Ok(None);
    };
    let pairs: Vec<Pair> = body
        .node_ids
        .iter()
        .zip(&derived)
        .filter_map(|(id, d)| xyz.get(id).map(|x| (*id, *x, *d)))
        .collect();
    if pairs.is_empty() {
        return Ok(None);
    }
    let k = pairs.len() as f64;
    let mean = |f: &dyn Fn(&Pair) -> [f64; 3]| -> [f64; 3] {
        let mut m = [0.0; 3];
        for p in &pairs {
            let v = f(p);
            (0..3).for_each(|c| m[c] += v[c] / k);
        }
        m
    };
    let origin = mean(&|(_, x, d)| [x[0] - d[0], x[1] - d[1], x[2] - d[2]]);
    // The body's size: the diagonal of the bounding box of all its nodes.
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for d in &derived {
        for c in 0..3 {
            lo[c] = lo[c].min(d[c]);
            hi[c] = hi[c].max(d[c]);
        }
    }
    let size = (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f64>().sqrt();
    let dist = |a: [f64; 3], b: [f64; 3]| (0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f64>().sqrt();
    let placed = |d: [f64; 3]| [d[0] + origin[0], d[1] + origin[1], d[2] + origin[2]];
    let (id, x, d) = pairs
        .iter()
        .copied()
        .max_by(|a, b| dist(a.1, placed(a.2)).total_cmp(&dist(b.1, placed(b.2))))
        .expect("pairs is not empty");
    let err = dist(x, placed(d));
    if err.is_nan() || err > PLACEMENT_TOL * size {
        let xm = mean(&|p| p.1);
        let dm = mean(&|p| p.2);
        let (mut num_s, mut den) = (0.0, 0.0);
        for (_, x, d) in &pairs {
            for c in 0..3 {
                num_s += (x[c] - xm[c]) * (d[c] - dm[c]);
                den += (d[c] - dm[c]).powi(2);
            }
        }
        let s = num_s / den;
        let mut hint = String::new();
        if s.is_finite() && s > 0.0 {
            let e = s.log10().round();
            if e != 0.0 && (s / 10f64.powf(e) - 1.0).abs() < 1e-3 {
                hint = format!(
                    "; units? the file's coordinates are {} times the body's (ratio 1e{e}: e.g. a deck in mm for a body in m)",
                    num(10f64.powf(e))
                );
            } else {
                hint = format!(
                    "; the file's coordinates are about {} times the body's",
                    num(s)
                );
            }
        }
        return Err(Box::new(PlacementError {
            coords: coords_name.to_string(),
            body: body_name.to_string(),
            id,
            at_file: x,
            at_modes: placed(d),
            origin,
            off: err,
            size,
            hint,
        }));
    }
    Ok(Some(origin))
}
