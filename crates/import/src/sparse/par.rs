//! The fixed parallelism of every faer call in this crate.
//!
//! faer splits its blocked work by the thread count it is given, so a result depends on
//! that count (not on the pool that runs it). Fixing it at two, the cores of CI and of
//! these machines, instead of faer's default of every core, gives the same bits on any
//! machine, whether the rayon pool has one thread or sixty-four (tested in
//! `tests/determinism.rs`).

use faer::Par;

/// Threads every faer call works with.
pub const THREADS: usize = 2;

/// The parallelism of every faer call here; never faer's global one.
pub fn par() -> Par {
    Par::rayon(THREADS)
}
