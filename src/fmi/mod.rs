//! The FMI 2.0 co-simulation C ABI: types, the call-sequence state machine, logging,
//! the panic barrier and the 34 exports; and the host side (loading a packed FMU's
//! library) used by `fxbody demo` and the tests. The only module with `unsafe` and raw
//! pointers.

pub mod exports;
pub mod fmu_state;
pub mod host;
pub mod instance;
pub mod state;
pub mod types;
pub mod uri;
pub mod values;

/// The C header cbindgen generated for this build (build.rs). The committed
/// `include/fxbody.h` must equal it; `tests/fmi_header.rs` checks.
pub const GENERATED_HEADER: &str = include_str!(concat!(env!("OUT_DIR"), "/fxbody.h"));
