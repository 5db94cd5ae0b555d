//! From a file path to a validated [`Body`]: the one way every command and the packer
//! load a body. Reading and parsing are the format
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

/// How [`load`] reads a file. `LoadOptions::default()` reads it streaming, keeps no
/// bytes and reports no progress.
#[derive(Default)]
pub struct LoadOptions<'a> {
    /// Where to keep the file's bytes, for a caller that stores or hashes them too: the
    /// file is then read whole and parsed from memory. Without it the file is parsed as
    /// it is read, never whole in memory ([`fxb::read_path_with`]).
    pub keep_bytes: Option<&'a mut Vec<u8>>,
    /// Told (bytes parsed, total bytes) about every MiB while the file is parsed, so that
    /// a command can draw a progress bar for a large body.
    pub progress: Option<&'a mut dyn FnMut(u64, u64)>,
}

/// Read a `.fxb` file and validate it into a [`Body`] (warnings are in
/// [`Body::warnings`]), as `opts` says; the file name in errors is the path as given.
/// The one way every command and the packer load a body.
pub fn load(path: &Path, opts: LoadOptions) -> Result<Body, LoadError> {
    let name = path.display().to_string();
    let how = fxb::Reading {
        progress: opts.progress,
        ..fxb::Reading::default()
    };
    let file = match opts.keep_bytes {
        Some(keep) => {
            *keep = fxb::read_bytes(path)?;
            fxb::parse_with(keep, &name, how)?
        }
        None => fxb::read_path_with(path, how)?,
    };
    Ok(Body::from_fxb_owned(file, &name)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name)
    }

    /// Each failure names the file, from the format layer (unreadable) and from the body
    /// checks (numbers that make no body); the bytes returned are the file's own.
    #[test]
    fn every_failure_names_the_file_and_the_bytes_are_the_files() {
        let missing = data("missing.fxb");
        let e = load(&missing, LoadOptions::default()).unwrap_err();
        assert!(matches!(e, LoadError::File(_)), "{e}");
        assert!(
            e.to_string()
                .starts_with(&format!("{}: cannot read the body file", missing.display())),
            "{e}"
        );
        let bad = data("labels_r0_d0_ns1.fxb");
        let e = load(&bad, LoadOptions::default()).unwrap_err();
        assert!(matches!(e, LoadError::Body(_)), "{e}");
        assert!(e.to_string().contains("labels_r0_d0_ns1.fxb"), "{e}");
        let good = data("body_b0_r0_d1.fxb");
        let mut bytes = Vec::new();
        let how = LoadOptions {
            keep_bytes: Some(&mut bytes),
            ..LoadOptions::default()
        };
        let body = load(&good, how).unwrap();
        assert_eq!(bytes, std::fs::read(&good).unwrap());
        // Free body of the fixture generator: total mass 5 (tests/data/make_data.py).
        assert!((body.total_mass().unwrap() - 5.0).abs() < 1e-8);
    }

    /// Data flows text -> body: the format layer's code never names the body layer
    /// (comments may point to it).
    #[test]
    fn the_format_layer_does_not_depend_on_the_body_layer() {
        let sources = [
            include_str!("../fxb.rs"),
            include_str!("../fxb/coords.rs"),
            include_str!("../fxb/error.rs"),
            include_str!("../fxb/fast.rs"),
            include_str!("../fxb/fields.rs"),
            include_str!("../fxb/input.rs"),
            include_str!("../fxb/reader.rs"),
            include_str!("../fxb/writer.rs"),
        ];
        for src in sources {
            for line in src.lines().filter(|l| !l.trim_start().starts_with("//")) {
                assert!(
                    !line.contains("body::") && !line.contains("Body"),
                    "fxb uses the body layer: {line}"
                );
            }
        }
    }
}
