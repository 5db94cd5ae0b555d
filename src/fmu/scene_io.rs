//! From files to a scene: the exposed node list and coordinates, and the content GUID.
//! Shared by `fxbody pack` (from the user's files) and the FMU at instantiation (from
//! its resources/ folder), so both derive the same scene and the same GUID.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use super::hash::content_guid;
use super::options::SceneOptions;
use crate::body::Body;
use crate::fxb::{self, coords};
use crate::scene::Scene;

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
) -> Result<Scene, String> {
    let mut nodes = Vec::with_capacity(opts.nodes.len());
    let mut x0 = Vec::with_capacity(opts.nodes.len());
    for &id in &opts.nodes {
        let Some(k) = body.node_index(id) else {
            return Err(format!(
                "{body_name}: node {id} is not a node of this body (its nodes: {})",
                summary(&body.node_ids)
            ));
        };
        if nodes.contains(&k) {
            return Err(format!("node {id} is listed twice"));
        }
        let Some(&x) = xyz.get(&id) else {
            return Err(format!(
                "no coordinates for node {id}: the coordinate file does not list it"
            ));
        };
        nodes.push(k);
        x0.push(x);
    }
    if nodes.is_empty() {
        return Err("no exposed nodes: give at least one node ID".into());
    }
    let scene = Scene::new(Arc::new(body), nodes, x0);
    match opts.fmax {
        // Truncated from the full file at every load, so the residual flexibility (which
        // the .fxb format cannot hold) is exact.
        Some(f) => scene
            .truncated(f)
            .map(|(s, _)| s)
            .map_err(|e| format!("{body_name}: {e}")),
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
pub fn load_resources(dir: &Path) -> Result<Resources, String> {
    let read = |name: &str| {
        let p = dir.join(name);
        fxb::input::read_regular(&p).map_err(|e| format!("cannot read {}: {e}", p.display()))
    };
    let body_bytes = read(BODY_FILE)?;
    let coords_bytes = read(COORDS_FILE)?;
    let options_bytes = read(OPTIONS_FILE)?;
    let options_text = String::from_utf8(options_bytes)
        .map_err(|_| format!("{}: not UTF-8 text", dir.join(OPTIONS_FILE).display()))?;
    let body_path = dir.join(BODY_FILE).display().to_string();
    let options =
        SceneOptions::parse(&options_text, &dir.join(OPTIONS_FILE).display().to_string())?;
    let file = fxb::parse(&body_bytes, &body_path).map_err(|e| e.to_string())?;
    let body = Body::from_fxb(&file, &body_path).map_err(|e| e.to_string())?;
    let xyz = coords::parse_csv(&coords_bytes, &dir.join(COORDS_FILE).display().to_string())
        .map_err(|e| e.to_string())?;
    let map = coords::to_map(&xyz);
    crate::body::placement::check_coords(
        &body,
        &map,
        &dir.join(COORDS_FILE).display().to_string(),
        &body_path,
    )?;
    let scene = make_scene(body, &map, &options, &body_path)?;
    Ok(Resources {
        scene,
        guid: guid(&body_bytes, &coords_bytes, &options_text),
        options,
    })
}
