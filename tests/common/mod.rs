//! Helpers shared by the test binaries (`tests/all` and `tests/alloc` both compile this
//! module): where the repository and its fixtures are, and the bodies, FMUs and files the
//! tests of several areas build on. A helper used by two test files lives here, once.
#![allow(dead_code)] // each binary uses the part it needs

pub mod blocked;
pub mod c_build;
pub mod fmu;
pub mod free_hand_step;
pub mod fxb_files;
pub mod springs;

use std::path::PathBuf;
use std::sync::Arc;

use fxbody::fxb::{coords, load_body};
use fxbody::scene::Scene;
use fxbody::solver::Solver;
use serde_json::Value;

/// The repository's root folder.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A file of fixtures/ (the finite-element bodies and their references).
pub fn fixture(name: &str) -> PathBuf {
    root().join("fixtures").join(name)
}

/// The body of fixture `name` exposing the nodes `ids` (node IDs), at the coordinates of
/// its `/NODE` deck.
pub fn fixture_scene(name: &str, ids: &[i64]) -> Scene {
    let body = load_body(&fixture(&format!("{name}.fxb"))).unwrap();
    let xyz = coords::to_map(&coords::read_coords(&fixture(&format!("{name}.nodes.rad"))).unwrap());
    let nodes = ids.iter().map(|id| body.node_index(*id).unwrap()).collect();
    let x0 = ids.iter().map(|id| xyz[id]).collect();
    Scene::new(Arc::new(body), nodes, x0)
}

/// The independent full finite-element reference of fixture `name` (`name.ref.json`).
pub fn fixture_reference(name: &str) -> Value {
    let text = std::fs::read_to_string(fixture(&format!("{name}.ref.json"))).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// [`fixture_scene`] and [`fixture_reference`] together.
pub fn fixture_scene_and_reference(name: &str, ids: &[i64]) -> (Scene, Value) {
    (fixture_scene(name, ids), fixture_reference(name))
}

/// A JSON array of numbers.
pub fn nums(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// Displacements (3 per exposed node) of the scene's exposed nodes from their initial
/// positions.
pub fn displacements(s: &dyn Solver, scene: &Scene) -> Vec<f64> {
    let mut p = vec![0.0; 3 * scene.nodes.len()];
    s.positions(&mut p);
    p.iter()
        .enumerate()
        .map(|(i, x)| x - scene.x0[i / 3][i % 3])
        .collect()
}
