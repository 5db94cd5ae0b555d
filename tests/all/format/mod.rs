//! The `.fxb` text format: reading, the error messages, writing back; and the FE matrix and
//! coordinate readers `fxbody import` uses (`fe`).

mod errors;
mod fast;
mod fe;
mod read;
mod roundtrip;
