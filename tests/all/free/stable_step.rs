//! The explicit free-body scheme's stable step is that of the local modes coupled to the
//! rigid motion (src/solver/free/explicit/stable.rs): the truss with local modes from a
//! 3-2-1 support (tests/data/truss_supported.*, modes that drag rigid motion) truncated at
//! its middle mode (its top kept local modes couple strongly) runs the explicit method as
//! the split method runs it, and the bound is the scheme's real one: 5 % beyond it the
//! raw scheme blows up, 5 % below it stays with the reference. (The shipped truss's modes
//! are free-free: they do not couple, and its bound is that of the local modes.)

use crate::common::root;
use fxbody::fmu::pack::{Fmax, PackOptions, PackRequest, prepare};
use fxbody::scene::Scene;
use fxbody::solver::free::Explicit;
use fxbody::solver::{Method, Options, Solver, build};

/// The supported truss with its middle and last node exposed, truncated at its middle
/// mode's frequency (residual correction on), under gravity and a spin.
fn truncated_truss() -> Scene {
    let data = root().join("tests/data");
    let req = |nodes| PackRequest {
        body: data.join("truss_supported.fxb"),
        coords: Some(data.join("truss_supported.nodes.rad")),
        nodes,
        ..PackRequest::default()
    };
    let all = prepare(&req(None), &PackOptions::default(), None).unwrap();
    let ids = all.scene.body.node_ids();
    let nodes = vec![ids[ids.len() / 2], ids[ids.len() - 1]];
    let hz = all.scene.body.frequencies_hz();
    let mut scene = prepare(
        &req(Some(nodes)),
        &PackOptions {
            fmax: Some(Fmax::Hz(hz[hz.len() / 2])),
            ..PackOptions::default()
        },
        None,
    )
    .unwrap()
    .scene;
    assert!(scene.residual.is_some());
    scene.gravity = [0.0, 0.0, -9.81];
    scene.w0 = [0.0, 0.0, 0.1];
    scene
}

/// Loads on every input at step `k` of `h` (those of the scene-file test).
fn loads(k: usize, h: f64, n: usize) -> Vec<f64> {
    let t = k as f64 * h;
    (0..n)
        .map(|i| 0.01 * (1.0 + (i % 6) as f64) * (300.0 * t + i as f64).cos())
        .collect()
}

/// Positions of the exposed nodes and the kinetic energy after each of `steps` steps
/// of `h`, or the step that was refused.
fn run(s: &mut dyn Solver, h: f64, steps: usize) -> Result<Vec<(Vec<f64>, f64)>, String> {
    let mut out = Vec::new();
    let mut x = vec![0.0; 6];
    for k in 0..steps {
        s.set_loads(&loads(k, h, 12)).map_err(|e| e.to_string())?;
        s.step(h).map_err(|e| format!("step {k}: {e}"))?;
        s.positions(&mut x);
        out.push((x.clone(), s.kinetic_energy()));
    }
    Ok(out)
}

/// Largest position difference (m) and largest relative kinetic-energy difference.
fn differences(a: &[(Vec<f64>, f64)], b: &[(Vec<f64>, f64)]) -> (f64, f64) {
    let mut dx: f64 = 0.0;
    let mut de: f64 = 0.0;
    for ((xa, ea), (xb, eb)) in a.iter().zip(b) {
        for (p, q) in xa.iter().zip(xb) {
            dx = dx.max((p - q).abs());
        }
        de = de.max((ea - eb).abs() / eb.abs().max(1e-12));
    }
    (dx, de)
}

#[test]
fn a_truncated_free_truss_runs_the_explicit_method_as_the_split_method() {
    let scene = truncated_truss();
    let h = 5e-4;
    let opts = Options::default();
    let mut ex = build(&scene, Method::Explicit, &opts).unwrap();
    let mut sp = build(&scene, Method::Split, &opts).unwrap();
    // Before the fix: refused at step 79 after the energy grew from 1e-3 J to 4e6 J.
    let a = run(ex.as_mut(), h, 300).unwrap();
    let b = run(sp.as_mut(), h, 300).unwrap();
    let (dx, de) = differences(&a, &b);
    println!("explicit vs split: positions within {dx} m, kinetic energy within {de}");
    // The frame moves by 2e-3 m over the run (gravity); both methods are second order.
    assert!(dx < 1e-7, "positions differ by {dx} m");
    assert!(de < 1e-4, "kinetic energy differs by {de} (relative)");
}

#[test]
fn the_explicit_stable_step_of_a_truncated_free_truss_is_the_schemes_real_bound() {
    let mut scene = truncated_truss();
    scene.residual = None;
    let bound = Explicit::new(&scene, &Options::default())
        .unwrap()
        .stable_step();
    // The local modes alone would give 2 / omega_L,max; the coupling lowers the bound.
    let local = scene.body.explicit_stable_step();
    println!("stable step {bound} s, local modes alone {local} s");
    assert!(bound < 0.8 * local, "{bound} vs {local}");
    let steps = 600;
    let reference = run(
        build(&scene, Method::Split, &Options::default())
            .unwrap()
            .as_mut(),
        0.95 * bound,
        steps,
    )
    .unwrap();
    let raw = |factor: f64| {
        let opts = Options {
            subcycle: false,
            ..Options::default()
        };
        let mut s = Explicit::new(&scene, &opts).unwrap();
        run(&mut s, factor * bound, steps)
    };
    let (dx, _) = differences(&raw(0.95).unwrap(), &reference);
    println!("at 0.95 x the bound: positions within {dx} m of the split method");
    assert!(dx < 1e-7, "{dx} m");
    // Beyond the bound the scheme's top mode grows (refused, or the energy explodes).
    match raw(1.05) {
        Err(e) => println!("at 1.05 x the bound: {e}"),
        Ok(r) => {
            let e = r.last().unwrap().1;
            let e_ref = reference.last().unwrap().1;
            println!("at 1.05 x the bound: kinetic energy {e} J, reference {e_ref} J");
            assert!(e > 1e3 * e_ref, "{e} J vs {e_ref} J");
        }
    }
}
