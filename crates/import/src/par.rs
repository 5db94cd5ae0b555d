//! The fixed parallelism of every faer call and every split of work in this crate, dense
//! and sparse.
//!
//! faer splits its blocked work by the thread count it is given, so the rounding of a
//! result depends on that count (not on the pool that runs it). Fixing it at
//! [`THREADS`], instead of faer's default of every core, makes an import repeat bit for
//! bit on one machine whatever the size of the rayon pool (tested in `dense` and in
//! `tests/all/ccx.rs` with pools of 1, 2 and 3 threads). It does not make it repeat across
//! machines: faer picks its SIMD kernels (AVX2, AVX-512) when it runs, per CPU, and those
//! round differently, so two CPUs write files that differ in their last digits; no test
//! compares an imported file's bytes with a committed one (scripts/test.sh imports at one
//! and two threads, `FXBODY_IMPORT_THREADS`).

use faer::Par;

/// Threads every faer call works with, unless `FXBODY_IMPORT_THREADS` says otherwise:
/// two, what CI and these machines have. Measured on the 3000-DOF free grillage, quiet
/// machine, the dense eigen-solve 6.3 s -> 3.4 s.
pub const THREADS: usize = 2;

/// [`THREADS`], or `FXBODY_IMPORT_THREADS` when it is 1 to 64 (anything else is ignored).
pub fn threads() -> usize {
    std::env::var("FXBODY_IMPORT_THREADS")
        .ok()
        .and_then(|v| v.trim().parse().ok())
        .filter(|n| (1..=64).contains(n))
        .unwrap_or(THREADS)
}

/// The parallelism of every faer call here (see [`threads`]); never faer's global one.
pub fn par() -> Par {
    Par::rayon(threads())
}
