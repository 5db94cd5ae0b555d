//! fxbody: a Radioss flexible-body file (`/FXBODY`, `.fxb`) as an FMI 2.0 co-simulation
//! unit.
//!
//! Data flows one way: text ([`fxb`]) -> validated body ([`body`]) -> scene ([`scene`]) ->
//! solver ([`solver`]) -> FMI boundary ([`fmi`]); [`fmu`] writes the description and the
//! package.

// Every public item says what it is and why (the project's standard), checked by clippy.
#![warn(missing_docs)]

pub mod body;
pub mod fe;
pub mod fmi;
pub mod fmu;
pub mod fxb;
pub mod import;
pub mod num;
pub mod reduce;
pub mod scene;
pub mod solver;
