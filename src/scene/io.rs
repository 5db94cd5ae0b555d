//! From files to a scene: the exposed node list and coordinates, and the content GUID.
//! `fxbody pack` builds the scene from the user's files ([`make_scene`]) and stores it
//! in the scene file ([`scenefile`]); the FMU reads that file back at instantiation
//! ([`load_resources`]), so both hold the same scene and derive the same GUID.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::file as scenefile;
use crate::body::Body;
use crate::fmu::hash::content_guid;
use crate::fmu::options::{OptionsError, SceneOptions};
use crate::fxb;
use crate::scene::Scene;
use crate::scene::reduce::ReduceError;

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
        "method exact: exact modal stepping needs a blocked body; {body} is free and offers split (its default), implicit or explicit"
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
    /// scene.fxs could not be read or was refused.
    #[error(transparent)]
    SceneFile(#[from] scenefile::ReadError),
    /// scene.txt and scene.fxs describe different scenes.
    #[error(
        "{}: {what}; the resources are from different packs: pack the FMU again",
        .dir.display()
    )]
    Mismatch {
        /// The resources folder.
        dir: PathBuf,
        /// What differs.
        what: String,
    },
}

/// The scene file inside `resources/` ([`scenefile`]): what the solver needs.
pub const SCENE_FILE: &str = "scene.fxs";
/// The original body file, inside `resources/` only when packed with `--embed-source`
/// (for traceability: the FMU never reads it).
pub const SOURCE_FILE: &str = "source.fxb";
/// The pack options.
pub const OPTIONS_FILE: &str = "scene.txt";

/// The GUID of a packed scene: a hash of the scene file's checksum (which covers every
/// number the solver reads), the options text and the crate version (a state saved by
/// one build is not loaded by another).
pub fn guid(scene_checksum: u64, options: &str) -> String {
    content_guid(&[
        b"fxbody",
        env!("CARGO_PKG_VERSION").as_bytes(),
        &scene_checksum.to_le_bytes(),
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
    if opts.method == Some(crate::solver::Method::Exact) && !body.is_blocked() {
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

/// Read `resources/` (the scene file and the options) and rebuild the scene and GUID:
/// one read of each file, no `.fxb` parsing, no eigen-solution. The options must name
/// the nodes the scene file holds, and truncation (`fmax`) exactly when it holds a
/// residual flexibility.
pub fn load_resources(dir: &Path) -> Result<Resources, ResourceError> {
    let options_path = dir.join(OPTIONS_FILE);
    let options_bytes =
        fxb::input::read_regular(&options_path).map_err(|source| ResourceError::Read {
            path: options_path.clone(),
            source,
        })?;
    let options_text = String::from_utf8(options_bytes)
        .map_err(|_| ResourceError::NotUtf8(options_path.clone()))?;
    let options = SceneOptions::parse(&options_text, &options_path.display().to_string())?;
    let stored = scenefile::read(&dir.join(SCENE_FILE))?;
    let scene = stored.scene;
    let mismatch = |what: String| ResourceError::Mismatch {
        dir: dir.to_path_buf(),
        what,
    };
    if scene.body.node_ids != options.nodes {
        return Err(mismatch(format!(
            "{OPTIONS_FILE} exposes the nodes {}, {SCENE_FILE} holds {}",
            summary(&options.nodes),
            summary(&scene.body.node_ids)
        )));
    }
    if options.fmax.is_some() != scene.residual.is_some() {
        return Err(mismatch(format!(
            "{OPTIONS_FILE} {} fmax, {SCENE_FILE} {} a residual flexibility",
            if options.fmax.is_some() {
                "gives"
            } else {
                "has no"
            },
            if scene.residual.is_some() {
                "holds"
            } else {
                "has no"
            }
        )));
    }
    Ok(Resources {
        scene,
        guid: guid(stored.checksum, &options_text),
        options,
    })
}

/// The shipped cantilever with its tip node 121 exposed (at x = 1 m), for the unit tests
/// of the FMU model and the FMI layer.
#[cfg(test)]
pub(crate) fn cantilever_tip_scene() -> Scene {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let body =
        crate::body::load(&root.join("fixtures/cantilever.fxb"), Default::default()).unwrap();
    let xyz = HashMap::from([(121, [1.0, 0.0, 0.0])]);
    let opts = SceneOptions {
        name: "t".into(),
        nodes: vec![121],
        ..SceneOptions::default()
    };
    make_scene(body, &xyz, &opts, "cantilever").unwrap()
}
