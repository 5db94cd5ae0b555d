//! The free-body solvers do not allocate while stepping: a counting global allocator
//! (this test binary only) sees zero allocations over many steps, loads with rates,
//! damping-free and Irot = 1 bodies included.

mod free_common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use fxbody::solver::{Method, Options, build};

struct Counting;

static ALLOCS: AtomicUsize = AtomicUsize::new(0);

// Delegates to the system allocator and only counts calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as the caller's, forwarded unchanged.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's, forwarded unchanged.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Zero allocations in `step` (and in `positions`/`velocities`/`accelerations`) for both
/// free-body methods, Irot 0 and 1.
#[test]
fn stepping_does_not_allocate() {
    // The counter itself sees allocations.
    let before = ALLOCS.load(Ordering::Relaxed);
    let probe: Vec<f64> = Vec::with_capacity(16);
    assert!(ALLOCS.load(Ordering::Relaxed) > before);
    drop(probe);
    for method in [Method::Explicit, Method::Implicit] {
        for irot in [false, true] {
            let b = free_common::cube_body(irot, 6, 2.0e4);
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
            let before = ALLOCS.load(Ordering::Relaxed);
            for _ in 0..50 {
                s.step(0.013).unwrap();
                s.positions(&mut out);
                s.velocities(&mut out);
                s.accelerations(&mut out);
            }
            let n = ALLOCS.load(Ordering::Relaxed) - before;
            assert_eq!(
                n, 0,
                "{method:?} irot={irot}: {n} allocations while stepping"
            );
        }
    }
}
