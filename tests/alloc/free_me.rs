//! Issue 26.2, free bodies: Model Exchange's per-evaluation calls on a free body (set
//! time, set states, state derivatives, a completed integrator step that normalises the
//! quaternion, one position read, a load set) allocate nothing once the solver is built,
//! on the free-free beam and on the beam truncated with the static correction.

use fxbody::fmu::simulation::{Phase, Simulation};
use fxbody::fmu::vars::Kind;

use crate::alloc_counter;
use crate::common::fixture_scene;

#[test]
fn free_model_exchange_evaluations_do_not_allocate() {
    let full = fixture_scene("freefree", &[521, 511]);
    let truncated = full.truncated(300.0).unwrap().0;
    for scene in [full, truncated] {
        let mut m = Simulation::new(scene.clone(), "alloc-free-me".into());
        let vr = |m: &Simulation, k: Kind| m.table.vars.iter().find(|v| v.kind == k).unwrap().vr;
        let method = m.table.vars.iter().find(|v| v.name == "method").unwrap().vr;
        m.set_integer(method, 4, Phase::Configuring).unwrap();
        m.setup(0.0, None).unwrap();
        let (fy, y) = (
            vr(&m, Kind::Load { node: 0, comp: 1 }),
            vr(&m, Kind::Position { node: 0, comp: 1 }),
        );
        let n = m.state_count().unwrap();
        let (mut x, mut dx) = (vec![0.0; n], vec![0.0; n]);
        m.states(&mut x).unwrap();
        let start = x.clone();
        let mut o = [0.0];
        let (mut moved, mut projected) = (0.0f64, 0);
        let before = alloc_counter::allocations();
        for k in 0..300 {
            let t = k as f64 * 1e-5;
            m.set_real(fy, (3e3 * t).cos(), Phase::Running).unwrap();
            m.set_time(t).unwrap();
            m.set_states(&x).unwrap();
            m.derivatives(&mut dx).unwrap();
            if m.completed_step().unwrap() {
                projected += 1;
            }
            // The next state: a moved one whose quaternion is 1e-6 off its norm.
            for (j, xi) in x.iter_mut().enumerate() {
                *xi = start[j] + 1e-6 * (k as f64 + j as f64).sin() + 1e-12 * dx[j].tanh();
            }
            m.get_reals(&[y], &mut o).unwrap();
            moved = moved.max((o[0] - scene.x0[0][1]).abs());
        }
        let after = alloc_counter::allocations();
        assert!(moved > 0.0, "the body did not move");
        assert!(projected > 0, "no completed step normalised the quaternion");
        assert_eq!(after - before, 0, "allocations in 300 evaluations");
    }
}
