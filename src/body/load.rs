//! From a file path to a validated [`Body`]: the one way every command, the packer and
//! the FMU (its `resources/body.fxb`) load a body. Reading and parsing are the format
//! layer's ([`crate::fxb`]); the physical checks are [`Body::from_fxb`]'s. Every error
//! names the file.

use std::path::Path;

use super::{Body, BodyError};
use crate::fxb::{self, FxbError};

/// Why [`load`] failed: the file could not be read or parsed, or its numbers do not make
/// a valid body. Boxed to keep `Result<Body, LoadError>` small.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// Reading or parsing failed.
    #[error(transparent)]
    File(Box<FxbError>),
    /// The numbers failed a physical check.
    #[error(transparent)]
    Body(Box<BodyError>),
}

impl From<FxbError> for LoadError {
    fn from(e: FxbError) -> Self {
        LoadError::File(Box::new(e))
    }
}

impl From<BodyError> for LoadError {
    fn from(e: BodyError) -> Self {
        LoadError::Body(Box::new(e))
    }
}

/// Read a `.fxb` file and validate it into a [`Body`] (warnings are in
/// `Body::warnings`); the file name in errors is the path as given.
pub fn load(path: &Path) -> Result<Body, LoadError> {
    load_with_bytes(path).map(|(body, _)| body)
}

/// [`load`], also returning the file's bytes: the packer stores them unchanged in the
/// FMU and hashes them into the GUID, and the FMU hashes them again at instantiation.
pub fn load_with_bytes(path: &Path) -> Result<(Body, Vec<u8>), LoadError> {
    let name = path.display().to_string();
    let bytes = fxb::read_bytes(path)?;
    let file = fxb::parse(&bytes, &name)?;
    let body = Body::from_fxb(&file, &name)?;
    Ok((body, bytes))
}
