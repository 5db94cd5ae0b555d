//! A communication step through the model behind the FMI layer (setReal, input rates
//! on every other step, doStep, getReal of every Real variable, output derivatives, as the exports run them)
//! allocates nothing: counted with a global allocator wrapper in this test binary. Every
//! method on a blocked body (the cantilever) and on a free one (the free-free beam):
//! a master that logs energies, frame and velocities at every step must not allocate
//! either.

use std::path::PathBuf;

use fxbody::fmu::pack::{PackOptions, PackRequest, prepare};
use fxbody::fmu::simulation::{Phase, Simulation};
use fxbody::fmu::vars::{Causality, Kind};

use crate::alloc_counter;

fn run(body: &str, nodes: Option<Vec<i64>>, method: i32, h: f64) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let p = prepare(
        &PackRequest {
            body: root.join(format!("fixtures/{body}.fxb")),
            coords: Some(root.join(format!("fixtures/{body}.nodes.rad"))),
            nodes,
            ..PackRequest::default()
        },
        &PackOptions::default(),
        None,
    )
    .unwrap();
    let vr = |n: &str| p.table.vars.iter().find(|v| v.name == n).unwrap().vr;
    let reals: Vec<u32> = p
        .table
        .vars
        .iter()
        .filter(|v| !v.is_integer())
        .map(|v| v.vr)
        .collect();
    let positions: Vec<u32> = p
        .table
        .vars
        .iter()
        .filter(|v| matches!(v.kind, Kind::Position { .. }))
        .map(|v| v.vr)
        .collect();
    assert!(
        p.table
            .vars
            .iter()
            .any(|v| v.causality == Causality::Output && v.name == "energy.kinetic")
    );
    let mut m = Simulation::new(p.scene.clone(), p.guid.clone());
    m.set_integer(vr("method"), method, Phase::Configuring)
        .unwrap();
    m.setup(0.0, None).unwrap();
    m.ensure_solver().unwrap();
    let f = p
        .table
        .vars
        .iter()
        .find(|v| v.causality == Causality::Input && v.name.ends_with(".fy"))
        .unwrap()
        .vr;
    let mut out = vec![0.0; reals.len()];
    let mut one = [0.0];
    // Warm up (the first step sets the transition coefficients or step matrices).
    m.set_real(f, 1.0, Phase::Running).unwrap();
    m.do_step(0.0, h).unwrap();
    let before = alloc_counter::allocations();
    let mut sum = 0.0;
    for k in 1..301 {
        m.set_real(f, (k as f64 * 1e-2).sin(), Phase::Running)
            .unwrap();
        // Every other step with a rate: the exact method's guard takes both its paths
        // (bounded in advance without rates, checked with them).
        if k % 2 == 0 {
            m.set_input_rate(f, 1, 0.5).unwrap();
        }
        m.do_step(k as f64 * h, h).unwrap();
        m.get_reals(&reals, &mut out).unwrap();
        m.get_reals(&positions[..1], &mut one).unwrap();
        sum += m.get_output_derivative(positions[0], 1).unwrap();
        sum += m.get_output_derivative(positions[0], 2).unwrap();
    }
    let after = alloc_counter::allocations();
    assert!(out.iter().all(|x| x.is_finite()) && sum.is_finite());
    let ke = out[reals
        .iter()
        .position(|&r| r == vr("energy.kinetic"))
        .unwrap()];
    assert!(ke > 0.0, "{body} method {method}: the body did not move");
    assert_eq!(
        after - before,
        0,
        "{body} method {method}: allocations in 300 steps"
    );
}

#[test]
fn a_communication_step_does_not_allocate() {
    // The counter itself sees allocations.
    let before = alloc_counter::allocations();
    drop(std::hint::black_box(Vec::<f64>::with_capacity(8)));
    assert!(alloc_counter::allocations() > before);
    for method in [1, 2, 3] {
        run("cantilever", Some(vec![121, 111]), method, 2e-4);
    }
    for method in [1, 2] {
        run("freefree", None, method, 1e-4);
    }
}

/// Issue 26.1: the step loop through the FMI 3.0 exports (fmi3SetFloat64 of one load,
/// fmi3DoStep, fmi3GetFloat64 of one position and of `time`) allocates nothing either,
/// logging off as a master runs it. The counter itself is checked above.
#[test]
fn an_fmi3_communication_step_does_not_allocate() {
    use crate::common::fmu::{H, Stepper};
    use crate::common::fmu3::{Slave3, packed3};
    let fx = packed3("alloc3");
    let s = Slave3::try_with(Some(&fx.p.guid), Some(&fx.resource_path()), "a", false)
        .unwrap_or_else(|m| panic!("{m:?}"));
    assert_eq!(s.enter_init(0.0, None), 0);
    assert_eq!(s.exit_init(), 0);
    let (f, y, t) = (
        fx.vr("node_121.fy"),
        fx.vr("node_121.y"),
        fx.p.table.time_ref(),
    );
    let mut o = [0.0];
    let mut step = |k: usize| {
        let time = k as f64 * H;
        assert_eq!(s.set_real(&[f], &[(300.0 * time).cos()]), 0);
        assert!(s.do_step(time, H) <= 1);
        assert_eq!(s.get_real(&[y], &mut o), 0);
        let y = o[0];
        assert_eq!(s.get_real(&[t], &mut o), 0);
        assert_eq!(o[0], time + H);
        y
    };
    step(0);
    let before = alloc_counter::allocations();
    let mut moved = 0.0f64;
    for k in 1..301 {
        moved = moved.max(step(k).abs());
    }
    let after = alloc_counter::allocations();
    assert!(moved > 0.0);
    assert_eq!(after - before, 0, "allocations in 300 FMI 3.0 steps");
}
