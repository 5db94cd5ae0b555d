//! fxbody: a Radioss flexible-body file (`/FXBODY`, `.fxb`) as an FMI 2.0 co-simulation
//! unit.
//!
//! Data flows one way: text ([`fxb`]) -> validated body ([`body`]) -> scene ([`scene`]) ->
//! solver ([`solver`]) -> FMI boundary ([`fmi`]); [`fmu`] writes the description and the
//! package.

// `unsafe_code` is denied and `missing_docs` warned by the workspace lints (Cargo.toml);
// `unsafe` is allowed in `fmi` only.

// The FMI exports catch every panic at the C boundary (`catch_unwind` in fmi::instance and fmi::exports)
// and turn it into fmi2Error with a logged reason. With `panic = "abort"` there is
// nothing to catch: a panic would kill the importing process. Refuse to build so.
#[cfg(panic = "abort")]
compile_error!(
    "fxbody must be built with panic = \"unwind\": the FMI exports' panic barrier \
     (catch_unwind) needs unwinding to turn a panic into fmi2Error instead of aborting \
     the importing process"
);

pub mod body;
pub mod fmi;
pub mod fmu;
pub mod fxb;
pub mod num;
pub mod scene;
pub mod solver;
pub mod units;
