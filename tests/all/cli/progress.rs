//! The progress bar of `info` and `pack`: drawn on stderr only when it is a terminal and
//! the work takes longer than a second, silent otherwise. `FXBODY_PROGRESS_DELAY_MS=0`
//! makes the bar due at once on a small body, so that both sides are seen: under a
//! pseudo-terminal (`script`, util-linux) the bar is drawn, with stderr a pipe nothing is.

use std::process::{Command, Output};

use crate::common::root;

fn fxbody(args: &[&str], delay_ms: &str) -> Output {
    Command::new(fxbody_host::workspace_binary("fxbody"))
        .args(args)
        .current_dir(root())
        .env("FXBODY_PROGRESS_DELAY_MS", delay_ms)
        .output()
        .expect("run fxbody")
}

/// `fxbody ARGS` under a pseudo-terminal, stdout discarded: what the terminal shows.
fn on_terminal(args: &str, delay_ms: &str) -> String {
    let exe = fxbody_host::workspace_binary("fxbody");
    let out = Command::new("script")
        .args([
            "-qec",
            &format!("{} {args} > /dev/null", exe.display()),
            "/dev/null",
        ])
        .current_dir(root())
        .env("FXBODY_PROGRESS_DELAY_MS", delay_ms)
        .output()
        .expect("script (util-linux) runs a command under a pseudo-terminal");
    assert!(out.status.success(), "{out:?}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn info_draws_a_bar_on_a_terminal_only() {
    let shown = on_terminal("info fixtures/truss.fxb", "0");
    assert!(shown.contains("reading ["), "{shown:?}");
    assert!(shown.contains("KiB"), "{shown:?}");
    // Not drawn before it is due (5 s here, for a loaded machine): the small body is
    // read long before.
    let quick = on_terminal("info fixtures/truss.fxb", "5000");
    assert!(!quick.contains("reading"), "{quick:?}");
    let piped = fxbody(&["info", "fixtures/truss.fxb"], "0");
    assert!(piped.status.success());
    assert!(
        piped.stderr.is_empty(),
        "{:?}",
        String::from_utf8_lossy(&piped.stderr)
    );
    // The report itself is the same with or without a bar due.
    assert_eq!(
        piped.stdout,
        fxbody(&["info", "fixtures/truss.fxb"], "1000").stdout
    );
}

#[test]
fn pack_draws_a_bar_on_a_terminal_only() {
    let dir = std::env::temp_dir().join(format!("fxbody_progress_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fmu = dir.join("t.fmu");
    let args = format!(
        "pack fixtures/truss.fxb --coords fixtures/truss.nodes.rad -o {}",
        fmu.display()
    );
    let shown = on_terminal(&args, "0");
    assert!(shown.contains("reading ["), "{shown:?}");
    std::fs::remove_file(&fmu).unwrap();
    let piped = fxbody(
        &[
            "pack",
            "fixtures/truss.fxb",
            "--coords",
            "fixtures/truss.nodes.rad",
            "-o",
            fmu.to_str().unwrap(),
        ],
        "0",
    );
    assert!(piped.status.success(), "{piped:?}");
    let err = String::from_utf8_lossy(&piped.stderr);
    // Only the packer's notes, one per line, no bar, no cursor control.
    assert!(
        err.lines().all(|l| l.starts_with("fxbody pack: ")) && !err.contains('\r'),
        "{err:?}"
    );
    assert!(
        !err.contains("reading") && !err.contains('\u{1b}'),
        "{err:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
