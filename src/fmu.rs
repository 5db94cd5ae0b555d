//! modelDescription.xml from a scene, the running model behind an FMU instance, and
//! packaging the `.fmu` archive. Safe Rust only; the C ABI is in [`crate::fmi`].

pub mod doc;
pub mod fmi_version;
pub mod guard;
pub mod hash;
pub mod header;
pub mod interface;
pub mod options;
pub mod osp;
pub mod pack;
pub mod platforms;
pub mod simulation;
mod simulation_error;
pub mod snapshot;
mod time;
pub mod vars;
pub mod xml;
pub mod xml3;
pub mod zip;
