//! The `fxbody` command run end to end as a user runs it, with the helpers its tests
//! share: running the built binary and a scratch folder per test.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::common::root;

mod first_use;
mod grammar;
mod info;
mod info_nodes;
mod input_kinds;
mod inputs;
mod numbers;
mod pack_extras;
mod pack_names;
mod progress;

/// Run the built `fxbody` with `args` in `dir`.
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(fxbody_host::workspace_binary("fxbody"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run fxbody")
}

/// Run the built `fxbody` with `args` in the repository's root.
pub fn run(args: &[&str]) -> Output {
    run_in(&root(), args)
}

/// A fresh, empty scratch folder for one test (`tag` names it; the process ID keeps
/// concurrent runs apart).
pub fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("fxb_cli_{tag}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `fxbody pack` of the shipped cantilever at its deck's coordinates, with `args` after.
pub fn pack_cantilever(args: &[&str]) -> Output {
    let base = [
        "pack",
        "fixtures/cantilever.fxb",
        "--coords",
        "fixtures/cantilever.nodes.rad",
    ];
    run(&[&base[..], args].concat())
}

/// The stdout of a run that must succeed (its stderr shown when it did not).
pub fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout.clone()).unwrap()
}

/// Assert that `o` is a refusal (exit code 2) whose message holds `says`.
pub fn assert_refused(o: &Output, says: &str) {
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        o.status.code(),
        Some(2),
        "expected a refusal saying '{says}': {e}"
    );
    assert!(e.contains(says), "expected '{says}' in: {e}");
}
