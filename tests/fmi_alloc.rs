//! A communication step through the model behind the FMI layer (setReal, doStep,
//! getReal, as fmi2SetReal/fmi2DoStep/fmi2GetReal run them) allocates nothing: counted
//! with a global allocator wrapper in this test binary.

use std::path::PathBuf;

use fxbody::fmu::model::{Model, Phase};
use fxbody::fmu::pack::{PackRequest, prepare};

mod alloc_counter;

#[global_allocator]
static GLOBAL: alloc_counter::Counting = alloc_counter::Counting;

#[test]
fn a_communication_step_does_not_allocate() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let p = prepare(&PackRequest {
        body: root.join("fixtures/cantilever.fxb"),
        coords: Some(root.join("fixtures/cantilever.nodes.rad")),
        nodes: Some(vec![121, 111]),
        ..PackRequest::default()
    })
    .unwrap();
    let vr = |n: &str| p.table.vars.iter().find(|v| v.name == n).unwrap().vr;
    let mut m = Model::new(p.scene.clone(), p.guid.clone());
    m.setup(0.0, None).unwrap();
    m.ensure_solver().unwrap();
    let (f, outs) = (
        vr("node_121.fy"),
        [vr("node_121.y"), vr("node_111.vy"), vr("energy.strain")],
    );
    let mut out = [0.0; 3];
    let h = 2e-4;
    // Warm up (first step sets the transition coefficients).
    m.set_real(f, 1.0, Phase::Running).unwrap();
    m.do_step(0.0, h).unwrap();
    let before = alloc_counter::allocations();
    for k in 1..1001 {
        m.set_real(f, (k as f64 * 1e-2).sin(), Phase::Running)
            .unwrap();
        m.set_input_rate(f, 1, 0.5).unwrap();
        m.do_step(k as f64 * h, h).unwrap();
        m.get_reals(&outs, &mut out).unwrap();
    }
    let after = alloc_counter::allocations();
    assert!(out[0].abs() > 0.0 && out[2] > 0.0);
    assert_eq!(after - before, 0, "allocations in 1000 steps");
}
