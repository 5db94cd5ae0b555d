//! The tests that count heap use, in a binary of their own because they install a
//! counting global allocator (alloc_counter.rs). Allocation calls and live bytes are
//! counted per thread, so these tests may run in parallel threads of this process and
//! each sees only its own allocations.

#[path = "../common/mod.rs"]
mod common;

mod alloc_counter;

#[global_allocator]
static GLOBAL: alloc_counter::Counting = alloc_counter::Counting;

mod fmi;
mod format;
mod free;
mod free_me;
mod me;
mod mutation;
mod scene;
mod solver;
