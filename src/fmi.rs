//! The FMI C ABI, FMI 2.0 and FMI 3.0 co-simulation from one library: types, the
//! call-sequence state machines, logging, the panic barrier, FMI 2.0's 34 exports and
//! FMI 3.0's 75 ([`fmi3`]), the versions' differences in small adapters ([`version`]).
//! The only module of the product with `unsafe` and raw pointers (the workspace denies
//! `unsafe_code` everywhere else). The importer side, loading a packed FMU's library, is
//! the `fxbody-host` package (crates/host).
//!
//! Public to a library user: the C types ([`types`], [`fmi3::types`]) and the exported
//! `fmi2*` functions ([`exports`], [`values`], [`fmu_state`]) and `fmi3*` functions
//! ([`fmi3`]), which are the C ABI itself, callable from
//! Rust with the same contracts as from C (include/fxbody.h). The exports are in the
//! cdylib's symbol table whatever the visibility (`#[unsafe(no_mangle)]`).
//! `state` and `instance` are internals: private to the crate, and opened only by the
//! `test-internals` feature, which the integration tests (tests/all/fmi) turn on to check
//! the state machine and the instance behind a handle.

// The C ABI: raw pointers from the importer, `extern "C"` exports, the panic barrier.
// Every block says why it holds (clippy::undocumented_unsafe_blocks).
#![allow(unsafe_code)]

mod error;
pub mod exports;
pub mod fmi3;
pub mod fmu_state;
#[cfg(feature = "test-internals")]
#[doc(hidden)]
pub mod instance;
#[cfg(not(feature = "test-internals"))]
mod instance;
mod instantiate;
pub mod model_exchange;
#[cfg(feature = "test-internals")]
#[doc(hidden)]
pub mod state;
#[cfg(not(feature = "test-internals"))]
mod state;
pub mod types;
mod uri;
pub mod values;
pub mod version;

pub use error::FmiError;

/// The C header cbindgen generated for this build (build.rs). The committed
/// `include/fxbody.h` must equal it; `tests/all/fmi/header.rs` checks.
pub const GENERATED_HEADER: &str = include_str!(concat!(env!("OUT_DIR"), "/fxbody.h"));
