//! Two `pack` behaviours that a user meets without asking for them: `--fmax auto`
//! (keep the modes up to 1/H, twice the Nyquist frequency of the DefaultExperiment step
//! H) and the warning when exposing every node makes more than 1,000 variables.

use crate::common::blocked::{IDENTITY, blocked_body};
use crate::common::root;
use fxbody::fmu::pack::{Fmax, PackNote, PackOptions, PackRequest, prepare};
use fxbody::fxb::write;
use fxbody::scene::reduce::to_fxb;
use serde_json::Value;

fn cantilever() -> PackRequest {
    PackRequest {
        body: root().join("fixtures/cantilever.fxb"),
        coords: Some(root().join("fixtures/cantilever.nodes.rad")),
        nodes: Some(vec![121]),
        ..PackRequest::default()
    }
}

/// The `stepSize` of the DefaultExperiment in a modelDescription.xml.
fn step_size(xml: &str) -> f64 {
    let at = xml.find("<DefaultExperiment").unwrap();
    let tail = &xml[at..];
    let v = tail.split("stepSize=\"").nth(1).unwrap();
    v[..v.find('"').unwrap()].parse().unwrap()
}

#[test]
fn fmax_auto_keeps_the_modes_up_to_one_over_the_default_step() {
    let full = prepare(&cantilever(), &PackOptions::default(), None).unwrap();
    let h = step_size(&full.xml);
    let auto = prepare(
        &cantilever(),
        &PackOptions {
            fmax: Some(Fmax::Auto),
            ..PackOptions::default()
        },
        None,
    )
    .unwrap();
    assert_eq!(auto.options.fmax, Some(1.0 / h));
    // Independent count: the reduced body's frequencies computed by the Python generator.
    let text = std::fs::read_to_string(root().join("fixtures/cantilever.ref.json")).unwrap();
    let r: Value = serde_json::from_str(&text).unwrap();
    let freqs: Vec<f64> = r["frequencies_hz"]["reduced"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let want = freqs.iter().filter(|&&f| f <= 1.0 / h).count();
    assert!(
        want > 0 && want < freqs.len(),
        "the test must drop some modes"
    );
    assert_eq!(auto.scene.body.nl(), want, "modes kept at {} Hz", 1.0 / h);
    assert!(auto.scene.residual.is_some());
    assert!(
        auto.notes.contains(&PackNote::FmaxAuto {
            hz: 1000.0,
            step: h
        }),
        "{:?}",
        auto.notes
    );
    // The same choice on the command line.
    let out = root().join("target/scene_pack_options_auto.fmu");
    let o = std::process::Command::new(fxbody_host::workspace_binary("fxbody"))
        .args(["pack", "fixtures/cantilever.fxb", "--coords"])
        .arg("fixtures/cantilever.nodes.rad")
        .args(["--nodes", "121", "--fmax", "auto", "--lib"])
        .arg(std::env::current_exe().unwrap())
        .arg("-o")
        .arg(&out)
        .current_dir(root())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains(&format!("{want} of {} modes kept", freqs.len())),
        "{err}"
    );
    let _ = std::fs::remove_file(out);
}

/// A blocked body with `n` nodes (all with rotational DOFs) and two local modes, written as an
/// .fxb file with a coordinate CSV beside it.
fn write_body(dir: &std::path::Path, n: usize) -> PackRequest {
    let nl = 2;
    let mut local = vec![0.0; nl * n * 6];
    for j in 0..nl {
        for k in 0..n {
            // Bending-like shapes: uy grows along x, one sine each.
            let a = std::f64::consts::FRAC_PI_2 * (2 * j + 1) as f64;
            let s = (k + 1) as f64 / n as f64;
            local[(j * n + k) * 6 + 1] = (a * s).sin();
            // The slope as the rotation about z: every node has rotational DOFs.
            local[(j * n + k) * 6 + 5] = a * (a * s).cos();
        }
    }
    let (w1, w2) = (
        2.0 * std::f64::consts::PI * 5.0,
        2.0 * std::f64::consts::PI * 40.0,
    );
    let k_l = [w1 * w1, 0.0, 0.0, w2 * w2];
    let mut b = blocked_body(&[1.0; 2], &k_l, &local, n, IDENTITY, None).into_parts();
    // Store the true top frequency, so the file draws no Freq warning.
    b.freq_file = 40.0;
    let b = fxbody::body::Body::from_parts(b, "big").unwrap_or_else(|e| panic!("{e}"));
    let body = dir.join(format!("big{n}.fxb"));
    std::fs::write(&body, write(&to_fxb(&b))).unwrap();
    let mut csv = String::from("id,x,y,z\n");
    for k in 1..=n {
        csv.push_str(&format!("{k},{},0,0\n", k as f64 * 0.01));
    }
    let coords = dir.join(format!("big{n}.csv"));
    std::fs::write(&coords, csv).unwrap();
    PackRequest {
        body,
        coords: Some(coords),
        ..PackRequest::default()
    }
}

#[test]
fn exposing_every_node_warns_past_1000_variables() {
    let dir = std::env::temp_dir().join(format!("fxbody_pack_opts_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let warned = |p: &fxbody::fmu::pack::Prepared| {
        p.notes
            .iter()
            .any(|n| matches!(n, PackNote::AllNodesExposed { .. }) && n.is_warning())
    };
    // Per node with rotations: 6 inputs, 3 positions, 3 velocities, 3 rotations, 3
    // angular velocities (issue 15); plus method, rho_inf, damping.ratio and the two
    // energies: 18 n + 5 variables.
    for (n, want) in [(55, false), (56, true)] {
        let req = write_body(&dir, n);
        let p = prepare(&req, &PackOptions::default(), None).unwrap();
        assert_eq!(p.table.vars.len(), 18 * n + 5, "{n} nodes");
        assert_eq!(warned(&p), want, "{n} nodes: {:?}", p.notes);
        if want {
            assert!(p.notes.contains(&PackNote::AllNodesExposed {
                nodes: n,
                variables: 1013
            }));
            // Choosing the nodes silences it: the user asked for them.
            let chosen = PackRequest {
                nodes: Some((1..=n as i64).collect()),
                ..req
            };
            assert!(!warned(
                &prepare(&chosen, &PackOptions::default(), None).unwrap()
            ));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
