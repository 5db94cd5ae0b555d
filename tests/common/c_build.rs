//! Compile a C master from tests/c against the generated header (include/fxbody.h), the
//! way a C user would: strict C99, warnings as errors, linked with libdl and libm.

use std::path::Path;
use std::process::Command;

/// Compile `tests/c/<source>` into `exe` with the extra flags `opt` (optimisation,
/// debug info); panics with the compiler's message when it fails.
pub fn compile_c_master(source: &str, exe: &Path, opt: &[&str]) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let cc = Command::new("cc")
        .args(opt)
        .args([
            "-Wall",
            "-Werror",
            "-std=c99",
            "-D_POSIX_C_SOURCE=200809L",
            "-I",
        ])
        .arg(root.join("include"))
        .arg(root.join("tests/c").join(source))
        .arg("-o")
        .arg(exe)
        .args(["-ldl", "-lm"])
        .output()
        .expect("a C compiler `cc` on PATH");
    assert!(
        cc.status.success(),
        "cc failed on {source}: {}",
        String::from_utf8_lossy(&cc.stderr)
    );
}
