//! The integration tests, one module per area of the crate (tests/README.md says where a
//! new test goes). One binary: one link instead of one per file, and libtest runs all
//! of them in one pool of threads. The allocation-counting tests are in `tests/alloc`,
//! a binary of their own because they install a counting global allocator.

#[path = "../common/mod.rs"]
mod common;

mod body;
mod cli;
mod docs;
mod fmi;
mod format;
mod free;
mod scene;
mod solver;
