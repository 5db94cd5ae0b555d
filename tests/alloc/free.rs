//! The free-body solvers do not allocate while stepping: a counting global allocator
//! (this test binary only) sees zero allocations over many steps, loads with rates,
//! damping-free and Irot = 1 bodies included.

use fxbody::solver::{Method, Options, build};

use crate::alloc_counter;
use crate::common::springs;

/// Zero allocations in `step` (and in `positions`/`velocities`/`accelerations`) for the
/// free-body methods, Irot 0 and 1.
#[test]
fn stepping_does_not_allocate() {
    // The counter itself sees allocations.
    let before = alloc_counter::allocations();
    let probe: Vec<f64> = Vec::with_capacity(16);
    assert!(alloc_counter::allocations() > before);
    drop(probe);
    for method in [Method::Explicit, Method::Implicit, Method::Split] {
        for irot in [false, true] {
            let b = springs::cube_body(irot, 6, 2.0e4);
            let mut scene = b.scene();
            scene.w0 = [0.3, -0.2, 0.4];
            scene.gravity = [0.0, 0.0, -9.81];
            let mut s = build(&scene, method, &Options::default()).unwrap();
            let mut loads = vec![0.0; 6 * b.x.len()];
            loads[3] = 5.0;
            loads[10] = -2.0;
            s.set_loads(&loads).unwrap();
            s.set_load_rates(&vec![0.1; loads.len()]).unwrap();
            let mut out = vec![0.0; 3 * b.x.len()];
            s.step(0.01).unwrap();
            // The per-step checkpoint the FMU model takes: once the solver has saved a
            // state, saving it again allocates nothing (issue 13).
            s.checkpoint();
            let before = alloc_counter::allocations();
            for _ in 0..50 {
                s.checkpoint();
                std::hint::black_box(s.step(0.013).unwrap());
                s.positions(&mut out);
                s.velocities(&mut out);
                s.accelerations(&mut out);
                s.rotation_rates(&mut out);
                std::hint::black_box(s.kinetic_energy() + s.strain_energy());
                std::hint::black_box(s.frame());
                std::hint::black_box(s.modal().len());
            }
            let n = alloc_counter::allocations() - before;
            assert_eq!(
                n, 0,
                "{method:?} irot={irot}: {n} allocations while stepping"
            );
            // The checkpoint holds what state() saves: a rewind goes back to it.
            let saved = s.state();
            s.checkpoint();
            s.step(0.013).unwrap();
            s.rewind().unwrap();
            assert_eq!(saved, s.state());
        }
    }
}

/// The halving of an explicit internal step the frame cannot follow (its state copy is
/// preallocated) allocates nothing either: the free-free beam spinning at 3 rad/s under
/// 0.5 N m about global z (half of it along its own axis) (FORMULATION.md section 10.7), measured over steps 3 to 5,
/// where internal steps are halved, after the spin warning of step 2 (its text is
/// allocated once).
#[test]
fn halving_does_not_allocate() {
    use fxbody::body::load as load_body;
    use fxbody::fxb::coords::{read_coords, to_map};
    use fxbody::scene::Scene;
    use fxbody::solver::Solver;
    use fxbody::solver::free::Explicit;
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    let body = load_body(&root.join("freefree.fxb"), Default::default()).unwrap();
    let xyz = to_map(&read_coords(&root.join("freefree.nodes.rad")).unwrap());
    let k = body.node_index(511).unwrap();
    let mut sc = Scene::new(std::sync::Arc::new(body), vec![k], vec![xyz[&511]]);
    sc.w0 = [3.0, 0.0, 0.0];
    let mut s = Explicit::new(&sc, &Options::default()).unwrap();
    s.set_loads(&[0.0, 1.0, 0.0, 0.0, 0.0, 0.5]).unwrap();
    s.checkpoint();
    for _ in 0..2 {
        std::hint::black_box(s.step(1e-3).unwrap());
    }
    let (halved, before) = (s.halved_steps(), alloc_counter::allocations());
    for _ in 0..3 {
        s.checkpoint();
        assert!(s.step(1e-3).unwrap().is_none());
    }
    let n = alloc_counter::allocations() - before;
    assert!(
        s.halved_steps() > halved,
        "no halving in the measured steps"
    );
    assert_eq!(n, 0, "{n} allocations while halving");
}
