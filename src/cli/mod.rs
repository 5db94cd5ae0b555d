//! The `fxbody` subcommands, one file each; `main.rs` only dispatches.

pub mod demo;
pub mod import;
pub mod info;
pub mod info_modes;
pub mod pack;
pub mod reduce;
pub mod study;
