//! The `.fxb` text format: reading, the error messages, writing back. (The FE matrix and
//! coordinate readers of `fxbody import` are tested with their crate, crates/import.)

mod errors;
mod fast;
mod read;
mod roundtrip;
