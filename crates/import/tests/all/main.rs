//! The import crate's integration tests, one binary of modules: the FE readers against
//! files from independent writers (`readers`), and the sparse path against CalculiX on a
//! real part (`ccx`).

#[path = "../common/mod.rs"]
mod common;

mod ccx;
mod readers;
