//! Helpers shared by the test binaries (`tests/all` and `tests/alloc` both compile this
//! module): where the repository and its fixtures are, and the bodies, FMUs and files the
//! tests of several areas build on. A helper used by two test files lives here, once.
#![allow(dead_code)] // each binary uses the part it needs

pub mod blocked;
pub mod c_build;
pub mod fmu;
pub mod fmu3;
pub mod free_hand_step;
pub mod fxb_files;
pub mod springs;

use std::path::PathBuf;
use std::sync::Arc;

use fxbody::body::load as load_body;
use fxbody::fxb::coords;
use fxbody::scene::Scene;
use fxbody::solver::Solver;
use serde_json::Value;

/// Whether every tool the suite uses must be there (`FXBODY_REQUIRE_ALL=1`, which
/// scripts/test.sh sets when `CI=true`): a test that would skip a part for want of a tool
/// fails instead.
pub fn require_all() -> bool {
    std::env::var("FXBODY_REQUIRE_ALL").as_deref() == Ok("1")
}

/// Whether the tool `name` runs (`name --version` succeeds). When it does not: a panic
/// under [`require_all`], else `false` with the skipped part said on stdout.
pub fn tool_available(name: &str, skipped: &str) -> bool {
    let ok = std::process::Command::new(name)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        assert!(
            !require_all(),
            "{name} is required (FXBODY_REQUIRE_ALL=1, set by scripts/test.sh in CI) but does not run: install it ({skipped} needs it)"
        );
        println!("{name} not found: {skipped} skipped");
    }
    ok
}

/// Whether golden files are to be rewritten rather than compared (`FXBODY_BLESS` set,
/// by hand). Never in a CI run: there a blessed golden file would pass whatever the
/// product writes, so a set `FXBODY_BLESS` under [`require_all`] fails the test
/// (scripts/test.sh unsets it besides).
pub fn blessing() -> bool {
    let bless = std::env::var_os("FXBODY_BLESS").is_some();
    assert!(
        !(bless && require_all()),
        "FXBODY_BLESS is set in a CI run (FXBODY_REQUIRE_ALL=1): golden files are compared there, never rewritten"
    );
    bless
}

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
    scene_in(&root().join("fixtures"), name, ids)
}

/// As [`fixture_scene`], for a test body of tests/data with a `/NODE` deck (the truss
/// with modes from a support, `truss_supported`).
pub fn data_scene(name: &str, ids: &[i64]) -> Scene {
    scene_in(&root().join("tests").join("data"), name, ids)
}

fn scene_in(dir: &std::path::Path, name: &str, ids: &[i64]) -> Scene {
    let body = load_body(&dir.join(format!("{name}.fxb")), Default::default()).unwrap();
    let xyz = coords::to_map(&coords::read_coords(&dir.join(format!("{name}.nodes.rad"))).unwrap());
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
