//! `pack --fmax` end to end in safe Rust (the FMU's model, built from what `pack`
//! prepares): the description declares the direct feedthrough of loads to positions, a
//! load set at t = 0 moves the tip at once by the dropped modes' static deflection (from
//! direct K_L solves of the full and the truncated body), and the tip step response
//! stays within 2% of the full-FE reference (fixtures/cantilever.ref.json).

use crate::common::root;
use fxbody::body::Body;
use fxbody::body::load as load_body;
use fxbody::fmu::pack::{Fmax, PackOptions, PackRequest, Prepared, prepare};
use fxbody::fmu::simulation::{Phase, Simulation};
use fxbody::fmu::vars::Kind;
use nalgebra::DMatrix;
use serde_json::Value;

/// `req` prepared with the modes up to `fmax` Hz.
fn truncated(req: &PackRequest, fmax: f64) -> Prepared {
    let opts = PackOptions {
        fmax: Some(Fmax::Hz(fmax)),
        ..PackOptions::default()
    };
    prepare(req, &opts, None).unwrap()
}

/// Component `comp` (0..6: ux uy uz rx ry rz) of node `tip`'s displacement under a unit
/// load along the same component, direct solve with K_L (P0 = I in this fixture).
fn static_u(body: &Body, tip: usize, comp: usize) -> f64 {
    let g = DMatrix::from_fn(6, body.nl(), |r, j| body.phi_l()[(6 * tip + r, j)]);
    let f = nalgebra::DVector::from_fn(6, |r, _| if r == comp { 1.0 } else { 0.0 });
    let q = body.k_l().clone().lu().solve(&(g.transpose() * f)).unwrap();
    (g * q)[comp]
}

#[test]
fn packed_truncation_feeds_through_and_tracks_the_reference() {
    let text = std::fs::read_to_string(root().join("fixtures/cantilever.ref.json")).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    let tip = reference["tip_node"].as_i64().unwrap();
    let full = load_body(&root().join("fixtures/cantilever.fxb"), Default::default()).unwrap();
    let fmax = 2.0 * full.frequencies_hz()[0];
    let req = PackRequest {
        body: root().join("fixtures/cantilever.fxb"),
        coords: Some(root().join("fixtures/cantilever.nodes.rad")),
        nodes: Some(vec![tip]),
        ..PackRequest::default()
    };
    let p = truncated(&req, fmax);
    assert_eq!(p.options.fmax, Some(fmax));
    let vr = |want: Kind| {
        p.table
            .vars
            .iter()
            .find(|v| v.kind == want)
            .map(|v| v.vr)
            .unwrap()
    };
    let fy = vr(Kind::Load { node: 0, comp: 1 });
    let uy = vr(Kind::Position { node: 0, comp: 1 });
    // ModelStructure: the position's Unknown lists the fy input (indices are vr + 1).
    let line = format!("<Unknown index=\"{}\" dependencies=\"", uy + 1);
    let deps = p
        .xml
        .split(&line)
        .nth(1)
        .unwrap()
        .split('"')
        .next()
        .unwrap();
    assert!(
        deps.split(' ').any(|d| d == (fy + 1).to_string()),
        "position depends on '{deps}'"
    );
    let y0 = p.scene.x0[0][1];
    let truncated = p.scene.body.clone();
    let mut m = Simulation::new(p.scene, p.guid);
    m.setup(0.0, None).unwrap();
    m.set_real(fy, 1.0, Phase::Configuring).unwrap();
    let mut out = [0.0];
    m.get_reals(&[uy], &mut out).unwrap();
    // At t = 0 the kept modes have not moved: the tip is displaced by the dropped modes'
    // static share, full minus kept (1e-9 relative to it).
    let k = full.node_index(tip).unwrap();
    let want = static_u(&full, k, 1) - static_u(&truncated, k, 1);
    println!(
        "instant tip uy {:e}, dropped-mode static share {want:e}",
        out[0] - y0
    );
    assert!(((out[0] - y0) / want - 1.0).abs() < 1e-9);
    // Step response at the reference's sampling, default method: within 2% of the
    // largest reference value (the scene_truncation test measures 1.47% with the exact
    // method).
    let resp = &reference["responses"][0];
    assert_eq!(resp["name"], "step");
    let t: Vec<f64> = resp["t"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let r: Vec<f64> = resp["nodes"][tip.to_string()]["uy"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let peak = r.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let mut err: f64 = 0.0;
    for i in 1..t.len() {
        m.do_step(t[i - 1], t[i] - t[i - 1]).unwrap();
        m.get_reals(&[uy], &mut out).unwrap();
        err = err.max((out[0] - y0 - r[i]).abs());
    }
    println!(
        "FMU step response error {:.3}% ({:?})",
        100.0 * err / peak,
        m.method()
    );
    assert!(err < 0.02 * peak, "{}", err / peak);
}

/// Issue 25.4: the FMU's interface does not change with `--fmax`. With `--fmax 1` (below
/// the cantilever's first mode, 10.03 Hz: no mode kept) the tip keeps its moment inputs
/// and rotation outputs, with the same names and value references as the untruncated
/// FMU, and they work: a unit moment at t = 0 turns the tip at once by the full body's
/// static rotation (every mode dropped, so the residual flexibility is all of K_L^-1;
/// 1e-9 relative to a direct K_L solve).
#[test]
fn a_low_fmax_keeps_every_variable_and_value_reference() {
    let tip = 121;
    let req = PackRequest {
        body: root().join("fixtures/cantilever.fxb"),
        coords: Some(root().join("fixtures/cantilever.nodes.rad")),
        nodes: Some(vec![tip]),
        ..PackRequest::default()
    };
    let names = |p: &fxbody::fmu::pack::Prepared| -> Vec<(u32, String)> {
        p.table
            .vars
            .iter()
            .map(|v| (v.vr, v.name.clone()))
            .collect()
    };
    let full = prepare(&req, &PackOptions::default(), None).unwrap();
    let mut seen = Vec::new();
    for fmax in [1.0, 15.0, 1e9] {
        let p = truncated(&req, fmax);
        assert_eq!(names(&p), names(&full), "--fmax {fmax}");
        seen.push(p.table.vars.len());
        // The description lists the same variables too.
        for v in &full.table.vars {
            assert!(
                p.xml
                    .contains(&format!("name=\"{}\" valueReference=\"{}\"", v.name, v.vr))
            );
        }
    }
    println!(
        "variables at fmax 1, 15, 1e9 Hz and untruncated: {seen:?}, {}",
        full.table.vars.len()
    );
    assert_eq!(full.table.vars.len(), 23);
    let p = truncated(&req, 1.0);
    let vr = |want: Kind| p.table.vars.iter().find(|v| v.kind == want).unwrap().vr;
    let mz = vr(Kind::Load { node: 0, comp: 5 });
    let rz = vr(Kind::Rotation { node: 0, comp: 2 });
    let body = load_body(&root().join("fixtures/cantilever.fxb"), Default::default()).unwrap();
    let want = static_u(&body, body.node_index(tip).unwrap(), 5);
    let mut m = Simulation::new(p.scene, p.guid);
    m.setup(0.0, None).unwrap();
    m.set_real(mz, 1.0, Phase::Configuring).unwrap();
    let mut out = [0.0];
    m.get_reals(&[rz], &mut out).unwrap();
    println!(
        "--fmax 1: tip rz under a unit mz {:e}, K_L solve {want:e}",
        out[0]
    );
    assert!((out[0] / want - 1.0).abs() < 1e-9, "{} vs {want}", out[0]);
}
