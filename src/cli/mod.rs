//! The `fxbody` subcommands, one file each; `main.rs` only dispatches.

pub mod demo;
pub mod info;
pub mod pack;
pub mod reduce;
