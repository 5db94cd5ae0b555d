//! The `.fxb` text format: reading, the error messages, writing back.

mod errors;
mod read;
mod roundtrip;
