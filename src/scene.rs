//! What a scene needs from a body: the exposed nodes and their coordinates, gravity and
//! initial velocity. Solvers are built from a scene, never from the whole body's node set.

use std::sync::Arc;

use nalgebra::DMatrix;

use crate::body::Body;
pub mod file;
pub mod io;
pub mod reduce;

use reduce::{ReduceError, Residual, Truncation, truncate};

/// A body and the part of it a simulation couples to.
///
/// A scene exposing the cantilever's mid-span and tip nodes, at the coordinates of its
/// `/NODE` deck:
///
/// ```
/// use std::{path::Path, sync::Arc};
///
/// use fxbody::body::load as load_body;
/// use fxbody::fxb::coords;
/// use fxbody::scene::Scene;
///
/// let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
/// let body = load_body(&dir.join("cantilever.fxb"), Default::default())?;
/// let xyz = coords::to_map(&coords::read_coords(&dir.join("cantilever.nodes.rad"))?);
/// let ids = [111, 121];
/// let nodes = ids.iter().map(|id| body.node_index(*id).ok_or("no such node"));
/// let nodes = nodes.collect::<Result<Vec<usize>, _>>()?;
/// let scene = Scene::new(Arc::new(body), nodes, ids.iter().map(|id| xyz[id]).collect());
/// assert_eq!(scene.nodes, [10, 20]); // positions in the node list 101..=121
/// assert_eq!(scene.x0[1], [1.0, 0.0, 0.0]); // the tip, 1 m along X
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
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
    /// Static flexibility of modes the body no longer carries, at the exposed nodes
    /// (local frame); `None` for an untruncated body. [`crate::solver::build`] adds its
    /// quasi-static displacement `R f` to the outputs.
    pub residual: Option<Arc<Residual>>,
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
            residual: None,
        }
    }

    /// The same scene with the body truncated to the modes of (K_L, m_L) up to
    /// `fmax_hz` and the dropped modes' static flexibility at the exposed nodes kept as
    /// the residual ([`crate::scene::reduce`]). Truncating an already truncated scene keeps its
    /// residual and adds the newly dropped modes' flexibility to it.
    pub fn truncated(&self, fmax_hz: f64) -> Result<(Scene, Truncation), ReduceError> {
        let t = truncate(&self.body, fmax_hz)?;
        let mut residual = t.residual(&self.nodes);
        if let Some(old) = &self.residual {
            residual.r += &old.r;
            residual.dropped += old.dropped;
        }
        let mut scene = self.clone();
        let mut body = t.body.clone();
        // The scene keeps the file's stored Freq (what its documentation page shows beside
        // the kept modes' highest); no solver reads it, and `fxbody reduce` writes the
        // truncation's own body, whose Freq is the kept modes' highest.
        body.freq_file = self.body.freq_file;
        scene.body = Arc::new(body);
        // Nothing dropped (fmax above every mode): no residual correction, and so no
        // feedthrough to declare.
        scene.residual = (residual.dropped > 0).then(|| Arc::new(residual));
        Ok((scene, t))
    }

    /// Whether exposed node `k` (index into `nodes`) has rotational DOFs: the body's own
    /// test ([`Body::node_has_rotation`]) or, for a truncated scene, the dropped modes'
    /// residual flexibility. A node keeps its moments and rotations whatever `--fmax`
    /// drops: if its rotation rows are non-zero in the full body's local modes, they are
    /// non-zero in the kept modes or in the residual (the modal basis is invertible), so
    /// the FMU's interface does not change with `--fmax` (issue 25.4).
    pub fn node_has_rotation(&self, k: usize) -> bool {
        let body = &self.body;
        body.irot
            && (body.node_has_rotation(self.nodes[k])
                || self.residual.as_ref().is_some_and(|r| r.rotates(k)))
    }

    /// Rows of a mode matrix for the exposed nodes: `6 m x ncols`, row `6 k + c` is
    /// exposed node `k`, component `c`.
    pub fn exposed_rows(&self, modes: &DMatrix<f64>) -> DMatrix<f64> {
        DMatrix::from_fn(6 * self.nodes.len(), modes.ncols(), |row, j| {
            modes[(6 * self.nodes[row / 6] + row % 6, j)]
        })
    }
}
