//! Issue 16 item 2: a 2-node scene of a body the size of the large grillage (5,151
//! nodes, 200 local modes of which 6 static, blocked) packs to an FMU under 2 MB, library
//! included, and 100 instances of it live in one process, each running bit for bit as
//! the model built from the `.fxb` file. The body is synthetic (deterministic mode
//! shapes, a diagonally dominant K_L), written here in a few seconds: the grillage of
//! `fixtures/generate.py --large` takes about 20 s of Python to build.
//! `cargo bench --bench instantiate` measures time and memory on the grillage itself.

use fxbody::fmu::pack::{PackOptions, PackRequest, find_library, pack};
use fxbody::fmu::simulation::{Phase, Simulation};
use fxbody::fxb::FxbFile;
use fxbody_host::FmuLibrary;

const NODES: usize = 5151;
const MODES: usize = 200;
const STATIC: usize = 6;

/// The synthetic body: node IDs 100001.., modes `sin(0.37 row + 1.3 j) / 100`, m_L = 1,
/// K_L with the squared circular frequencies of 1..200 Hz on the diagonal and static
/// rows coupled at 1% of the geometric mean of the diagonals (positive definite).
fn synthetic() -> FxbFile {
    let w2 = |i: usize| (2.0 * std::f64::consts::PI * (1.0 + i as f64)).powi(2);
    let mut k_full = Vec::new();
    for r in 0..STATIC {
        for c in r..MODES {
            k_full.push(if r == c {
                w2(r)
            } else {
                0.01 * (w2(r) * w2(c)).sqrt() / MODES as f64
            });
        }
    }
    FxbFile {
        nbmod: MODES,
        nbstat: STATIC,
        nbnod: NODES,
        irot: true,
        idamp: false,
        iblo: true,
        ifile: false,
        node_ids: (0..NODES as i64).map(|k| 100_001 + k).collect(),
        p0: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        freq: MODES as f64,
        damping: None,
        rigid_modes: Vec::new(),
        local_modes: (0..MODES * 6 * NODES)
            .map(|k| {
                let (j, row) = (k / (6 * NODES), k % (6 * NODES));
                0.01 * (0.37 * row as f64 + 1.3 * j as f64).sin()
            })
            .collect(),
        m_l: vec![1.0; MODES],
        k_full,
        k_diag: (STATIC..MODES).map(w2).collect(),
        m_r: Vec::new(),
        m_c: Vec::new(),
        k_c: Vec::new(),
    }
}

#[test]
fn a_hundred_instances_of_a_two_node_scene_of_a_large_body() {
    let dir = std::env::temp_dir().join(format!("fxbody_many_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fxb = dir.join("big.fxb");
    std::fs::write(&fxb, fxbody::fxb::write(&synthetic())).unwrap();
    let coords = dir.join("big.csv");
    let mut csv = String::from("id,x,y,z\n");
    for k in 0..NODES {
        csv.push_str(&format!(
            "{},{},{},0\n",
            100_001 + k,
            (k % 101) as f64 * 0.02,
            (k / 101) as f64 * 0.02
        ));
    }
    std::fs::write(&coords, csv).unwrap();
    let (a, b) = (102_626, 105_151);
    let req = PackRequest {
        body: fxb.clone(),
        coords: Some(coords),
        nodes: Some(vec![a, b]),
        name: Some("big".into()),
        ..PackRequest::default()
    };
    let lib = find_library(None).unwrap();
    let fmu = dir.join("big.fmu");
    let p = pack(&req, &PackOptions::default(), &lib, &fmu, None).unwrap();
    let (fmu_size, fxb_size) = (
        std::fs::metadata(&fmu).unwrap().len(),
        std::fs::metadata(&fxb).unwrap().len(),
    );
    println!(
        "FMU {fmu_size} bytes (library {} bytes) for a {fxb_size}-byte body",
        std::fs::metadata(&lib).unwrap().len()
    );
    // Scene-sized: what the FMU carries besides the library (the scene file, the model
    // description, the documentation page) is a small fraction of the body (measured
    // 0.4 MB for the 101 MB body); the library's own size grows with the interfaces
    // it exports and is not the body's.
    let mut resources = 0;
    for (name, data) in fxbody_host::zip::read(&std::fs::read(&fmu).unwrap()).unwrap() {
        if !name.starts_with("binaries/") {
            resources += data.len() as u64;
        }
        let path = dir.join(&name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, data).unwrap();
    }
    println!("resources {resources} bytes (uncompressed)");
    assert!(resources < fxb_size / 100, "{resources} bytes of resources");
    let vr = |name: &str| p.table.vars.iter().find(|v| v.name == name).unwrap().vr;
    let (fy, fz) = (vr(&format!("node_{a}.fy")), vr(&format!("node_{b}.fz")));
    let out_vrs = [vr(&format!("node_{a}.y")), vr(&format!("node_{b}.z"))];
    let h = 1e-3;
    let load = |k: usize| (20.0 * k as f64 * h).sin();
    // The reference: the model built from the .fxb file, in safe Rust.
    let mut m = Simulation::new(p.scene.clone(), p.guid.clone());
    m.setup(0.0, None).unwrap();
    let mut want = Vec::new();
    let mut o = [0.0; 2];
    for k in 0..10 {
        m.set_reals(&[fy, fz], &[load(k), -load(k)], Phase::Running)
            .unwrap();
        m.do_step(k as f64 * h, h).unwrap();
        m.get_reals(&out_vrs, &mut o).unwrap();
        want.extend(o.map(f64::to_bits));
    }
    assert!(want.iter().any(|&x| x != want[0]), "the outputs move");
    // 100 instances alive at once, all initialised, then each steps.
    let so = FmuLibrary::open(&dir.join("binaries/linux64/big.so")).unwrap();
    let uri = fxbody_host::file_uri(&dir.join("resources"));
    let start = std::time::Instant::now();
    let instances: Vec<_> = (0..100)
        .map(|i| {
            let s = so
                .instantiate(&format!("i{i}"), &p.guid, &uri, false)
                .unwrap();
            s.initialise(0.0, None).unwrap();
            s
        })
        .collect();
    println!(
        "100 instances instantiated and initialised in {:.1} ms",
        start.elapsed().as_secs_f64() * 1e3
    );
    for (i, s) in instances.iter().enumerate() {
        let mut got = Vec::new();
        for k in 0..10 {
            s.set_real(&[fy, fz], &[load(k), -load(k)]).unwrap();
            s.do_step(k as f64 * h, h).unwrap();
            s.get_real(&out_vrs, &mut o).unwrap();
            got.extend(o.map(f64::to_bits));
        }
        assert_eq!(got, want, "instance {i}");
    }
    drop(instances);
    drop(so);
    let _ = std::fs::remove_dir_all(&dir);
}
