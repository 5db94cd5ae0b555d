//! Benchmark of issue 16 item 2: the 2-node scene of the large grillage (5,151 nodes, 200
//! modes, `python fixtures/generate.py --large`, about 45 s, about 100 MB): FMU size, time
//! of fmi2Instantiate plus initialisation, and resident memory per additional instance,
//! from the scene file (the packed FMU, through its C ABI), beside the same figures for
//! the `.fxb` path every instance took before (read and parse the body file, check the
//! coordinates, build the scene, hash the body for the GUID, build the solver: what
//! fmi2Instantiate and initialisation did, measured here in-process), in one run.
//! Prints figures and ratios; a speed is never asserted.
//!
//! Run: `cargo bench --bench instantiate` (looks for fixtures/large.fxb and its deck
//! large.nodes.rad, or the folder in `FXBODY_LARGE_DIR`; the exposed nodes, tip and
//! corner, are found from the deck: [`large_scene`]).

use std::path::PathBuf;
use std::time::Instant;

use fxbody::fmu::pack::{PackOptions, PackRequest, find_library, pack};
use fxbody::fmu::simulation::Simulation;
use fxbody::fmu::{hash::content_guid, options::SceneOptions};
use fxbody::fxb::coords;
use fxbody::scene::io::make_scene;
use fxbody_host::FmuLibrary;

#[path = "common/large_scene.rs"]
mod large_scene;

/// Resident set size of this process, bytes (/proc/self/statm, 4 KiB pages).
fn rss() -> f64 {
    let s = std::fs::read_to_string("/proc/self/statm").unwrap();
    let pages: f64 = s.split_whitespace().nth(1).unwrap().parse().unwrap();
    pages * 4096.0
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let dir = std::env::var_os("FXBODY_LARGE_DIR")
        .map(PathBuf::from)
        .unwrap_or(root.join("fixtures"));
    let fxb = dir.join("large.fxb");
    if !fxb.is_file() {
        println!(
            "instantiate: skipped: no {} (run `python fixtures/generate.py --large`, or set FXBODY_LARGE_DIR)",
            fxb.display()
        );
        return;
    }
    let deck = dir.join("large.nodes.rad");
    let nodes = large_scene::two_nodes(&deck);
    let tmp = std::env::temp_dir().join(format!("fxbody_bench_inst_{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let lib = find_library(None).expect("libfxbody.so next to the bench executable");
    let req = PackRequest {
        body: fxb.clone(),
        coords: Some(deck.clone()),
        nodes: Some(nodes.clone()),
        name: Some("large2".into()),
        ..PackRequest::default()
    };
    let fmu = tmp.join("large2.fmu");
    let t = Instant::now();
    let p = pack(&req, &PackOptions::default(), &lib, &fmu, None).unwrap();
    let pack_s = t.elapsed().as_secs_f64();
    let with_source = tmp.join("large2_src.fmu");
    pack(
        &PackRequest {
            embed_source: true,
            ..req.clone()
        },
        &PackOptions::default(),
        &lib,
        &with_source,
        None,
    )
    .unwrap();
    let size = |p: &PathBuf| std::fs::metadata(p).unwrap().len() as f64 / 1e6;
    for (name, data) in fxbody_host::zip::read(&std::fs::read(&fmu).unwrap()).unwrap() {
        let path = tmp.join(&name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, data).unwrap();
    }
    println!(
        "instantiate: large grillage ({:.1} MB .fxb, {} local modes), 2 exposed nodes {nodes:?}, pack {pack_s:.1} s",
        size(&fxb),
        p.scene.body.nl()
    );
    println!(
        "  FMU size: {:.2} MB (library {:.2} MB, scene file {:.2} MB); with --embed-source (the body inside, as before) {:.1} MB",
        size(&fmu),
        size(&lib),
        p.scene_file.len() as f64 / 1e6,
        size(&with_source)
    );

    // New: through the packed FMU's C ABI, N instances kept alive.
    let n_new = 50;
    let so = FmuLibrary::open(&tmp.join("binaries/linux64/large2.so")).unwrap();
    let uri = fxbody_host::file_uri(&tmp.join("resources"));
    // One instance first, so the library's own pages are resident before measuring.
    let warm = so.instantiate("warm", &p.guid, &uri, false).unwrap();
    drop(warm);
    let before = rss();
    let mut times = Vec::new();
    let mut keep = Vec::new();
    for i in 0..n_new {
        let t = Instant::now();
        let s = so
            .instantiate(&format!("i{i}"), &p.guid, &uri, false)
            .unwrap();
        s.initialise(0.0, None).unwrap();
        times.push(t.elapsed().as_secs_f64() * 1e3);
        keep.push(s);
    }
    let new_rss = (rss() - before) / n_new as f64 / 1e6;
    let new_ms = median(&mut times);
    drop(keep);

    // Before: the .fxb path of every instance, in-process (the same library calls).
    let n_old = 3;
    let options = SceneOptions {
        name: "large2".into(),
        nodes: nodes.clone(),
        ..SceneOptions::default()
    };
    let before = rss();
    let mut times = Vec::new();
    let mut keep = Vec::new();
    for _ in 0..n_old {
        let t = Instant::now();
        let mut bytes = Vec::new();
        let how = fxbody::body::LoadOptions {
            keep_bytes: Some(&mut bytes),
            ..Default::default()
        };
        let body = fxbody::body::load(&fxb, how).unwrap();
        let csv = std::fs::read(&deck).unwrap();
        let map = coords::to_map(&coords::read_coords(&deck).unwrap());
        fxbody::body::placement::check_coords(&body, &map, "deck", "body").unwrap();
        let scene = make_scene(body, &map, &options, "body").unwrap();
        let guid = content_guid(&[b"fxbody", &bytes, &csv, options.to_text().as_bytes()]);
        drop(bytes);
        let mut m = Simulation::new(scene, guid);
        m.setup(0.0, None).unwrap();
        m.ensure_solver().unwrap();
        times.push(t.elapsed().as_secs_f64() * 1e3);
        keep.push(m);
    }
    let old_rss = (rss() - before) / n_old as f64 / 1e6;
    let old_ms = median(&mut times);
    drop(keep);
    println!(
        "  fmi2Instantiate + initialisation: {new_ms:8.2} ms from the scene file (median of {n_new}), {old_ms:8.1} ms from the .fxb (median of {n_old}): {:.0}x faster",
        old_ms / new_ms
    );
    println!(
        "  resident memory per additional instance: {new_rss:6.2} MB from the scene file ({n_new} alive), {old_rss:6.1} MB from the .fxb ({n_old} alive): {:.0}x less",
        old_rss / new_rss.max(1e-3)
    );
    let _ = std::fs::remove_dir_all(&tmp);
}
