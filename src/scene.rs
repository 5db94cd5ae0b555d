//! What a scene needs from a body: the exposed nodes and their coordinates, gravity and
//! initial velocity. Solvers are built from a scene, never from the whole body's node set.

use std::sync::Arc;

use nalgebra::DMatrix;

use crate::body::Body;

/// A body and the part of it a simulation couples to.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The whole validated body.
    pub body: Arc<Body>,
    /// Exposed nodes, as indices into `body.node_ids`.
    pub nodes: Vec<usize>,
    /// Initial global coordinates of the exposed nodes (same order as `nodes`).
    pub x0: Vec<[f64; 3]>,
    /// Gravity acceleration, global frame (free bodies only).
    pub gravity: [f64; 3],
    /// Initial body velocity V (free bodies only).
    pub v0: [f64; 3],
    /// Initial body angular velocity w, global frame (free bodies only).
    pub w0: [f64; 3],
}

impl Scene {
    /// A scene at rest with no gravity.
    pub fn new(body: Arc<Body>, nodes: Vec<usize>, x0: Vec<[f64; 3]>) -> Scene {
        Scene {
            body,
            nodes,
            x0,
            gravity: [0.0; 3],
            v0: [0.0; 3],
            w0: [0.0; 3],
        }
    }

    /// Rows of a mode matrix for the exposed nodes: `6 m x ncols`, row `6 k + c` is
    /// exposed node `k`, component `c`.
    pub fn exposed_rows(&self, modes: &DMatrix<f64>) -> DMatrix<f64> {
        DMatrix::from_fn(6 * self.nodes.len(), modes.ncols(), |row, j| {
            modes[(6 * self.nodes[row / 6] + row % 6, j)]
        })
    }
}
