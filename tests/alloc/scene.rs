//! No heap allocation in a truncated scene's per-step work (residual decorator over every
//! method, blocked and free): a counting global allocator (this test binary only) counts
//! allocations made by this thread while loads are set, steps taken and outputs read.

use fxbody::solver::{Method, Options, build};

use crate::alloc_counter;
use crate::common::fixture_scene as scene;

fn count() -> usize {
    alloc_counter::allocations()
}

#[test]
fn truncated_steps_and_outputs_do_not_allocate() {
    let cases = [
        (
            "cantilever_damped",
            [121, 111],
            &[Method::Exact, Method::Implicit, Method::Explicit][..],
        ),
        (
            "truss",
            [1043, 1022],
            &[Method::Implicit, Method::Explicit][..],
        ),
    ];
    for (name, ids, methods) in cases {
        let full = scene(name, &ids);
        let (sc, _) = full.truncated(2.0 * full.body.frequencies_hz()[0]).unwrap();
        for &method in methods {
            let built = count();
            let mut s = build(&sc, method, &Options::default()).unwrap();
            assert!(count() > built);
            let mut out = [0.0; 6];
            let mut sink = 0.0;
            let mut before = count();
            for i in 0..30 {
                // The first cycle may fill caches (first step size, first loads).
                if i == 1 {
                    before = count();
                }
                s.set_loads(&[0.01; 12]).unwrap();
                s.set_load_rates(&[0.001; 12]).unwrap();
                s.step(1e-4).unwrap();
                s.positions(&mut out);
                s.velocities(&mut out);
                s.accelerations(&mut out);
                sink += out[0];
                // The free solvers' energy outputs allocate (src/solver/free, not this
                // decorator's code): energies are checked on the blocked body only.
                // Same for the free explicit solver's rotation rates.
                if sc.body.is_blocked() {
                    s.rotation_rates(&mut out);
                    sink += s.strain_energy() + s.kinetic_energy();
                }
            }
            assert!(sink.is_finite());
            assert_eq!(
                count(),
                before,
                "{name} {method:?}: allocations in the step loop"
            );
        }
    }
}
