//! The `.fxb` files the reader tests run over: tests/data, fixtures/, and a directory
//! named by FXBODY_FXB_DIR. Files over 5 MB (the generated benchmark bodies
//! fixtures/large*.fxb, ~100 MB each) are skipped: a mutation test over them would take
//! many minutes and exercise nothing the small files do not.

use std::path::{Path, PathBuf};

/// Largest file the reader tests take.
const MAX_BYTES: u64 = 5 << 20;

/// Sorted paths of the test bodies.
pub fn fxb_files() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    let extra = std::env::var("FXBODY_FXB_DIR").unwrap_or_default();
    for dir in ["tests/data", "fixtures", extra.as_str()] {
        if dir.is_empty() {
            continue;
        }
        let Ok(entries) = std::fs::read_dir(root.join(dir)) else {
            continue;
        };
        for e in entries.flatten() {
            // The file's own size, through a symlink (fixtures/large*.fxb are links to
            // the generated bodies; a DirEntry's metadata would be the link's).
            let small = std::fs::metadata(e.path()).is_ok_and(|m| m.len() <= MAX_BYTES);
            if small && e.path().extension().is_some_and(|x| x == "fxb") {
                out.push(e.path());
            }
        }
    }
    out.sort();
    out
}
