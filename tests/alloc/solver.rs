//! No heap allocation in a solver's per-step work: a counting global allocator (this
//! test binary only) counts allocations made by this thread while loads are set,
//! steps of several sizes are taken and outputs are read, for every method.

use crate::common::blocked::random_scene;
use fxbody::solver::{Method, Options, build};

use crate::alloc_counter;

fn count() -> usize {
    alloc_counter::allocations()
}

#[test]
fn steps_and_outputs_do_not_allocate() {
    // 12 and 140 modes: the implicit method stores an inverse for the first and a
    // Cholesky factor for the second; both paths are checked.
    for (nl, method) in [12, 140]
        .into_iter()
        .flat_map(|nl| [Method::Exact, Method::Implicit, Method::Explicit].map(|m| (nl, m)))
    {
        let scene = random_scene(nl, 6, 3, 5, Some((1.0, 1e-5)));
        let built = count();
        let mut s = build(&scene, method, &Options::default()).unwrap();
        // The counter sees the build's allocations (so a zero below means something).
        assert!(count() > built);
        let loads = [0.5; 18];
        let rates = [0.1; 18];
        let mut out = [0.0; 9];
        let mut sink = 0.0;
        let before = count();
        for i in 0..50 {
            s.set_loads(&loads).unwrap();
            s.set_load_rates(&rates).unwrap();
            // Three distinct sizes, so caches are filled and replaced inside the loop.
            s.step([1e-4, 3e-3, 2e-2][i % 3]).unwrap();
            s.positions(&mut out);
            s.velocities(&mut out);
            s.accelerations(&mut out);
            s.rotation_rates(&mut out);
            sink += s.strain_energy() + s.kinetic_energy() + s.modal()[0] + out[0];
        }
        let n = count() - before;
        assert!(sink.is_finite());
        // Reference: zero allocations.
        assert_eq!(
            n, 0,
            "{method:?} ({nl} modes) allocated {n} times in 50 steps"
        );
    }
}
