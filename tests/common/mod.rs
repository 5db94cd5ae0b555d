//! Helpers shared by the test binaries (`tests/all` and `tests/alloc` both compile this
//! module): where the repository and its fixtures are, and the bodies, FMUs and files the
//! tests of several areas build on. A helper used by two test files lives here, once.
#![allow(dead_code)] // each binary uses the part it needs

pub mod blocked;
pub mod c_build;
pub mod fmu;
pub mod fxb_files;
pub mod hand;
pub mod springs;
