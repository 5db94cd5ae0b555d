//! Issue 26.2: Model Exchange's per-evaluation calls (set time, set states, state
//! derivatives, a directional derivative (exact on a blocked body, a central difference
//! on a free one; its work arrays sized at its first call, made before counting), a
//! completed integrator step, one position read, a load set) allocate
//! nothing once the solver is built, on the cantilever and on the truncated cantilever
//! (whose outputs carry the residual correction's feed-through); the free case uses the
//! same loop (`free_me.rs`). As a Model Exchange instance runs it: the method parameter
//! ignored on a blocked body (set to implicit: Model Exchange integrates the body's own
//! equations), and there the state and derivative variables in the table, a state and a
//! derivative read by value reference beside the position.

use fxbody::fmu::simulation::{Phase, Simulation};
use fxbody::fmu::vars::Kind;
use fxbody::scene::Scene;

use crate::alloc_counter;
use crate::common::fixture_scene;

#[test]
fn model_exchange_evaluations_do_not_allocate() {
    let full = fixture_scene("cantilever", &[121, 111]);
    let truncated = full.truncated(2000.0).unwrap().0;
    // Implicit: ignored under Model Exchange, which integrates the exact method's
    // equations (the body's own).
    evaluations_do_not_allocate([full, truncated], 2);
}

/// 300 Model Exchange evaluations of each scene on `method` (a load set, set time, set
/// states, derivatives, a completed integrator step, one position read, and on a blocked
/// body a state and a derivative variable), from the model's start states moved by up to
/// 1e-6, allocate nothing; returns how many completed steps changed the states.
pub(crate) fn evaluations_do_not_allocate(scenes: [Scene; 2], method: i32) -> usize {
    let mut changed = 0;
    for scene in scenes {
        let blocked = scene.body.is_blocked();
        let mut m = Simulation::new(scene.clone(), "alloc-me".into());
        m.table = m.table.clone().with_states(&scene);
        m.serve_model_exchange();
        let vr = |m: &Simulation, k: Kind| m.table.vars.iter().find(|v| v.kind == k).unwrap().vr;
        let method_vr = m.table.vars.iter().find(|v| v.name == "method").unwrap().vr;
        m.set_integer(method_vr, method, Phase::Configuring)
            .unwrap();
        m.setup(0.0, None).unwrap();
        let (fy, y) = (
            vr(&m, Kind::Load { node: 0, comp: 1 }),
            vr(&m, Kind::Position { node: 0, comp: 1 }),
        );
        let n = m.state_count().unwrap();
        // A state and a derivative variable beside the position (blocked bodies), else
        // the position alone.
        let reads: Vec<u32> = if blocked {
            vec![y, vr(&m, Kind::State(0)), vr(&m, Kind::Derivative(n - 1))]
        } else {
            vec![y]
        };
        let (mut x, mut dx) = (vec![0.0; n], vec![0.0; n]);
        m.states(&mut x).unwrap();
        let start = x.clone();
        let mut o = vec![0.0; reads.len()];
        // The directional derivative: every state derivative with respect to the first
        // and last states and the load.
        let ders: Vec<u32> = (0..n).map(|i| vr(&m, Kind::Derivative(i))).collect();
        let knowns = [vr(&m, Kind::State(0)), vr(&m, Kind::State(n - 1)), fy];
        let mut jd = vec![0.0; n];
        m.directional_derivative(&ders, &knowns, &[1.0, 0.5, 0.2], &mut jd)
            .unwrap();
        let before = alloc_counter::allocations();
        let mut moved = 0.0f64;
        for k in 0..300 {
            let t = k as f64 * 1e-5;
            m.set_real(fy, (3e3 * t).cos(), Phase::Running).unwrap();
            m.set_time(t).unwrap();
            m.set_states(&x).unwrap();
            m.derivatives(&mut dx).unwrap();
            m.directional_derivative(&ders, &knowns, &[1.0, 0.5, 0.2], &mut jd)
                .unwrap();
            m.get_reals(&reads, &mut o).unwrap();
            if blocked {
                assert_eq!((o[1], o[2]), (x[0], dx[n - 1]));
            }
            if m.completed_step().unwrap() {
                changed += 1;
            }
            // The next state: any finite one will do (no integration needed here).
            for (j, xi) in x.iter_mut().enumerate() {
                *xi = start[j] + 1e-6 * (k as f64 + j as f64).sin() + 1e-12 * dx[j].tanh();
            }
            moved = moved.max((o[0] - scene.x0[0][1]).abs());
        }
        let after = alloc_counter::allocations();
        assert!(moved > 0.0, "the body did not move");
        assert_eq!(after - before, 0, "allocations in 300 evaluations");
    }
    changed
}
