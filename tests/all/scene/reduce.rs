//! `fxbody reduce`: the written file reads back as a valid body whose frequencies are the
//! retained ones of the fixture's independent reference (fixtures/*.ref.json, computed in
//! Python), whose mass is the whole body's, and whose static deflection at the kept nodes
//! plus the residual flexibility is the full body's.

use std::process::Command;

use crate::common::{fixture, fixture_reference as reference};
use fxbody::body::Body;
use fxbody::body::load as load_body;
use fxbody::scene::reduce::truncate;
use nalgebra::{DMatrix, DVector};

/// Run `fxbody reduce` and read the output back.
fn reduce(name: &str, nodes: &str, fmax: f64) -> (Body, String) {
    // The tests of this binary run in parallel threads of one process: a per-call
    // serial number in the file name keeps two calls from ever sharing a file.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let serial = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let out = std::env::temp_dir().join(format!(
        "fxbody_scene_reduce_{}_{serial}_{name}.fxb",
        std::process::id()
    ));
    let run = Command::new(fxbody_host::workspace_binary("fxbody"))
        .arg("reduce")
        .arg(fixture(&format!("{name}.fxb")))
        .arg("-o")
        .arg(&out)
        .args(["--nodes", nodes, "--fmax", &fmax.to_string()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout).into_owned();
    assert!(
        run.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let body = load_body(&out, Default::default()).unwrap();
    let _ = std::fs::remove_file(&out);
    (body, stdout)
}

#[test]
fn reduced_files_read_back_with_the_retained_frequencies() {
    // Against the full file's own eigenfrequencies (Body::frequencies_hz of the input,
    // same numbers): 2e-9 relative, as the reduced file stores K_L' = omega^2 in %16.9E
    // (5e-10 relative on omega^2, 2.5e-10 on f). Against the independent Python reference
    // (computed before the fixture's own %16.9E rounding, which moves the frequencies by
    // up to 6e-7 relative): 2e-6.
    for (name, nodes, fmax) in [
        ("cantilever_damped", "121,111", 120.0),
        ("truss", "1043,1001,1022", 800.0),
        ("freefree", "521,511", 200.0),
    ] {
        let r = reference(name);
        let want: Vec<f64> = r["frequencies_hz"]["reduced"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .filter(|&f| f <= fmax)
            .collect();
        let input = load_body(&fixture(&format!("{name}.fxb")), Default::default()).unwrap();
        let (body, stdout) = reduce(name, nodes, fmax);
        print!("{stdout}");
        assert_eq!(body.nl(), want.len(), "{name}: modes kept");
        assert_eq!(
            body.nnodes(),
            nodes.split(',').count(),
            "{name}: nodes kept"
        );
        let mut worst: f64 = 0.0;
        for ((got, own), want) in body
            .frequencies_hz()
            .iter()
            .zip(input.frequencies_hz())
            .zip(&want)
        {
            worst = worst.max((got / own - 1.0).abs());
            assert!(
                (got / own - 1.0).abs() < 2e-9,
                "{name}: {got} Hz vs the input's {own} Hz"
            );
            assert!(
                (got / want - 1.0).abs() < 2e-6,
                "{name}: {got} Hz vs reference {want} Hz"
            );
        }
        println!("{name}: largest relative frequency change {worst:.1e}");
        let own = input.frequencies_hz()[want.len() - 1];
        assert!((body.freq_file() / own - 1.0).abs() < 2e-9);
        assert!(body.warnings().is_empty(), "{name}: {:?}", body.warnings());
        if let Some(m) = body.total_mass() {
            // M_R of the node subset is still the whole body's inertia: 1e-8 relative
            // (the fixture's own mass and the file rounding).
            let want_m = r["total_mass"].as_f64().unwrap();
            println!("{name}: total mass {m} vs reference {want_m}");
            assert!(
                (m / want_m - 1.0).abs() < 1e-8,
                "{name}: mass {m} vs {want_m}"
            );
        }
    }
}

/// Local-frame static displacement (6 per node) of `body` at its first `m` nodes under a
/// local load `f` at those nodes, by a direct solve with K_L.
fn static_local(body: &Body, m: usize, f: &DVector<f64>) -> DVector<f64> {
    let g = DMatrix::from_fn(6 * m, body.nl(), |row, j| body.phi_l()[(row, j)]);
    let q = body.k_l().clone().lu().solve(&(g.transpose() * f)).unwrap();
    g * q
}

#[test]
fn reduced_file_plus_residual_keeps_the_static_deflection() {
    // cantilever_damped reduced to its tip and mid-span nodes and the modes up to 50 Hz:
    // the reduced file's static deflection (read back, direct K_L solve) plus the
    // residual flexibility equals the full body's at those nodes, for a unit load in
    // each of the 12 directions, to 1e-8 of the largest displacement (file rounding).
    let full = load_body(&fixture("cantilever_damped.fxb"), Default::default()).unwrap();
    let (small, _) = reduce("cantilever_damped", "121,111", 50.0);
    let nodes = [full.node_index(121).unwrap(), full.node_index(111).unwrap()];
    let residual = truncate(&full, 50.0).unwrap().residual(&nodes);
    let full_sub = fxbody::scene::reduce::select_nodes(&full, &nodes);
    for d in 0..12 {
        let mut f = DVector::zeros(12);
        f[d] = 1.0;
        let want = static_local(&full_sub, 2, &f);
        let got = static_local(&small, 2, &f) + &residual.r * &f;
        let err = (&got - &want).amax() / want.amax();
        assert!(err < 1e-8, "direction {d}: {err:e}");
    }
}
