//! Issue 26.2: Model Exchange's per-evaluation calls (set time, set states, state
//! derivatives, one position read, a load set) allocate nothing once the solver is built,
//! on the cantilever and on the truncated cantilever (whose outputs carry the residual
//! correction's feed-through). As a Model Exchange instance runs it: the state and
//! derivative variables in the table, the method parameter on implicit (ignored: Model
//! Exchange integrates the body's own equations), a state and a derivative read by value
//! reference beside the position.

use fxbody::fmu::simulation::{Phase, Simulation};
use fxbody::fmu::vars::Kind;

use crate::alloc_counter;
use crate::common::fixture_scene;

#[test]
fn model_exchange_evaluations_do_not_allocate() {
    let full = fixture_scene("cantilever", &[121, 111]);
    let truncated = full.truncated(2000.0).unwrap().0;
    for scene in [full, truncated] {
        let mut m = Simulation::new(scene.clone(), "alloc-me".into());
        m.table = m.table.clone().with_states(&scene);
        m.serve_model_exchange();
        let vr = |m: &Simulation, k: Kind| m.table.vars.iter().find(|v| v.kind == k).unwrap().vr;
        let method = m.table.vars.iter().find(|v| v.name == "method").unwrap().vr;
        m.set_integer(method, 2, Phase::Configuring).unwrap();
        m.setup(0.0, None).unwrap();
        let (fy, y) = (
            vr(&m, Kind::Load { node: 0, comp: 1 }),
            vr(&m, Kind::Position { node: 0, comp: 1 }),
        );
        let n = m.state_count().unwrap();
        let q1 = vr(&m, Kind::State(0));
        let dqd = vr(&m, Kind::Derivative(n - 1));
        let (mut x, mut dx) = (vec![0.0; n], vec![0.0; n]);
        let mut o = [0.0; 3];
        let before = alloc_counter::allocations();
        let mut moved = 0.0f64;
        for k in 0..300 {
            let t = k as f64 * 1e-5;
            m.set_real(fy, (3e3 * t).cos(), Phase::Running).unwrap();
            m.set_time(t).unwrap();
            m.set_states(&x).unwrap();
            m.derivatives(&mut dx).unwrap();
            m.get_reals(&[y, q1, dqd], &mut o).unwrap();
            assert_eq!((o[1], o[2]), (x[0], dx[n - 1]));
            // The next state: any finite one will do (no integration needed here).
            for (j, xi) in x.iter_mut().enumerate() {
                *xi = 1e-6 * (k as f64 + j as f64).sin() + 1e-12 * dx[j].tanh();
            }
            moved = moved.max((o[0] - scene.x0[0][1]).abs());
        }
        let after = alloc_counter::allocations();
        assert!(moved > 0.0, "the body did not move");
        assert_eq!(after - before, 0, "allocations in 300 evaluations");
    }
}
