//! From files to a scene: the exposed node list and coordinates, and the content GUID.
//! Shared by `fxbody pack` (from the user's files) and the FMU at instantiation (from
//! its resources/ folder), so both derive the same scene and the same GUID.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::hash::content_guid;
use super::options::{OptionsError, SceneOptions};
use crate::body::placement::PlacementError;
use crate::body::{self, Body, LoadError};
use crate::fxb::{self, coords};
use crate::reduce::ReduceError;
use crate::scene::Scene;

/// Why the exposed nodes do not make a scene (shared by `pack` and the FMU).
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// An exposed node ID the body does not have.
    #[error("{body}: node {id} is not a node of this body (its nodes: {nodes})")]
    UnknownNode {
        /// The body file.
        body: String,
        /// The node ID.
        id: i64,
        /// A summary of the body's node IDs ([`summary`]).
        nodes: String,
    },
    /// An exposed node ID given twice.
    #[error("node {0} is listed twice")]
    Repeated(i64),
    /// An exposed node without coordinates.
    #[error("no coordinates for node {0}: the coordinate file does not list it")]
    NoCoordinates(i64),
    /// No exposed node at all.
    #[error("no exposed nodes: give at least one node ID")]
    NoNodes,
    /// `method = exact` for a free body.
    #[error(
        "method exact: exact modal stepping needs a blocked body; {body} is free and offers explicit or implicit"
    )]
    ExactOnFree {
        /// The body file.
        body: String,
    },
    /// Mode truncation (`fmax`) failed.
    #[error("{body}: {source}")]
    Truncation {
        /// The body file.
        body: String,
        /// Why.
        source: ReduceError,
    },
}

/// Why an FMU could not load its `resources/` folder: each error names the file.
#[derive(Debug, thiserror::Error)]
pub enum ResourceError {
    /// A file could not be read.
    #[error("cannot read {}: {source}", .path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The reader's error.
        source: std::io::Error,
    },
    /// scene.txt is not UTF-8.
    #[error("{}: not UTF-8 text", .0.display())]
    NotUtf8(PathBuf),
    /// scene.txt was refused.
    #[error(transparent)]
    Options(#[from] OptionsError),
    /// body.fxb could not be read or is not a valid body.
    #[error(transparent)]
    Body(#[from] LoadError),
    /// coords.csv could not be parsed.
    #[error(transparent)]
    Coords(#[from] coords::CoordsError),
    /// coords.csv contradicts the body's rigid modes.
    #[error(transparent)]
    Placement(#[from] Box<PlacementError>),
    /// The exposed nodes do not make a scene.
    #[error(transparent)]
    Scene(#[from] SceneError),
}

/// File names inside `resources/`.
pub const BODY_FILE: &str = "body.fxb";
/// Coordinates of the body's nodes, CSV `id,x,y,z`.
pub const COORDS_FILE: &str = "coords.csv";
/// The pack options.
pub const OPTIONS_FILE: &str = "scene.txt";

/// The GUID of a packed scene: a hash of the body bytes, the coordinate text, the
/// options text and the crate version (a state saved by one build is not loaded by
/// another).
pub fn guid(body: &[u8], coords_csv: &[u8], options: &str) -> String {
    content_guid(&[
        b"fxbody",
        env!("CARGO_PKG_VERSION").as_bytes(),
        body,
        coords_csv,
        options.as_bytes(),
    ])
}

/// The scene for `body`: exposed nodes from `opts.nodes`, their coordinates from
/// `xyz`. Errors name the unknown node or the node without coordinates.
pub fn make_scene(
    body: Body,
    xyz: &HashMap<i64, [f64; 3]>,
    opts: &SceneOptions,
    body_name: &str,
) -> Result<Scene, SceneError> {
    if opts.method == Some(crate::solver::Method::Exact) && !body.iblo {
        return Err(SceneError::ExactOnFree {
            body: body_name.to_string(),
        });
    }
    let mut nodes = Vec::with_capacity(opts.nodes.len());
    let mut x0 = Vec::with_capacity(opts.nodes.len());
    for &id in &opts.nodes {
        let Some(k) = body.node_index(id) else {
            return Err(SceneError::UnknownNode {
                body: body_name.to_string(),
                id,
                nodes: summary(&body.node_ids),
            });
        };
        if nodes.contains(&k) {
            return Err(SceneError::Repeated(id));
        }
        let Some(&x) = xyz.get(&id) else {
            return Err(SceneError::NoCoordinates(id));
        };
        nodes.push(k);
        x0.push(x);
    }
    if nodes.is_empty() {
        return Err(SceneError::NoNodes);
    }
    let scene = Scene::new(Arc::new(body), nodes, x0);
    match opts.fmax {
        // Truncated from the full file at every load, so the residual flexibility (which
        // the .fxb format cannot hold) is exact.
        Some(f) => scene
            .truncated(f)
            .map(|(s, _)| s)
            .map_err(|source| SceneError::Truncation {
                body: body_name.to_string(),
                source,
            }),
        None => Ok(scene),
    }
}

/// A short list of IDs for messages: all when few, else the first and last ones.
pub fn summary(ids: &[i64]) -> String {
    if ids.len() <= 12 {
        ids.iter()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    } else {
        format!(
            "{}, ..., {} ({} nodes)",
            ids[..5]
                .iter()
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            ids[ids.len() - 3..]
                .iter()
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            ids.len()
        )
    }
}

/// Coordinates as the CSV text stored in resources (full f64 precision, file order).
pub fn coords_csv(coords: &[(i64, [f64; 3])]) -> String {
    let mut s = String::from("id,x,y,z\n");
    for (id, [x, y, z]) in coords {
        s.push_str(&format!("{id},{x:?},{y:?},{z:?}\n"));
    }
    s
}

/// Global coordinates of every node of a free body from its rigid modes, with the frame
/// origin L0 at (0, 0, 0) ([`Body::rigid_mode_positions`]); `None` for a blocked body.
pub fn coords_from_rigid_modes(body: &Body) -> Option<Vec<(i64, [f64; 3])>> {
    let x = body.rigid_mode_positions()?;
    Some(body.node_ids.iter().copied().zip(x).collect())
}

/// Everything an FMU instance reads from its resources folder.
pub struct Resources {
    /// The scene.
    pub scene: Scene,
    /// The options.
    pub options: SceneOptions,
    /// The GUID these files give.
    pub guid: String,
}

/// Read `resources/` (body, coordinates, options) and rebuild the scene and GUID.
pub fn load_resources(dir: &Path) -> Result<Resources, ResourceError> {
    let read = |name: &str| {
        let path = dir.join(name);
        fxb::input::read_regular(&path).map_err(|source| ResourceError::Read { path, source })
    };
    let body_path = dir.join(BODY_FILE);
    let (body, body_bytes) = body::load_with_bytes(&body_path)?;
    let coords_bytes = read(COORDS_FILE)?;
    let options_bytes = read(OPTIONS_FILE)?;
    let options_text = String::from_utf8(options_bytes)
        .map_err(|_| ResourceError::NotUtf8(dir.join(OPTIONS_FILE)))?;
    let body_name = body_path.display().to_string();
    let options =
        SceneOptions::parse(&options_text, &dir.join(OPTIONS_FILE).display().to_string())?;
    let coords_name = dir.join(COORDS_FILE).display().to_string();
    let xyz = coords::parse_csv(&coords_bytes, &coords_name)?;
    let map = coords::to_map(&xyz);
    crate::body::placement::check_coords(&body, &map, &coords_name, &body_name)?;
    let scene = make_scene(body, &map, &options, &body_name)?;
    Ok(Resources {
        scene,
        guid: guid(&body_bytes, &coords_bytes, &options_text),
        options,
    })
}

/// The shipped cantilever with its tip node 121 exposed (at x = 1 m), for the unit tests
/// of the FMU model and the FMI layer.
#[cfg(test)]
pub(crate) fn cantilever_tip_scene() -> Scene {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let body = crate::body::load(&root.join("fixtures/cantilever.fxb")).unwrap();
    let xyz = HashMap::from([(121, [1.0, 0.0, 0.0])]);
    let opts = SceneOptions {
        name: "t".into(),
        nodes: vec![121],
        ..SceneOptions::default()
    };
    make_scene(body, &xyz, &opts, "cantilever").unwrap()
}
