//! The commands the installed `fxbody` binary offers (issue 27, point 9): the user's
//! commands, and not the research harness, which is a binary of its own
//! (`fxbody-study`). Being an integration test of the cli package, it also makes
//! `cargo test` build target/release/fxbody, which the root package's tests
//! (tests/all/cli and others) run through `fxbody_host::workspace_binary`.

use std::process::Command;

/// The subcommand names `fxbody --help` lists (the indented first words of its
/// "Commands:" section).
fn commands() -> Vec<String> {
    let out = Command::new(env!("CARGO_BIN_EXE_fxbody"))
        .arg("--help")
        .output()
        .expect("the fxbody binary runs");
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    text.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .collect()
}

#[test]
fn the_installed_command_holds_the_users_commands_and_not_the_study() {
    let names = commands();
    for want in ["info", "pack", "import", "reduce", "demo"] {
        assert!(names.iter().any(|n| n == want), "{want} missing: {names:?}");
    }
    assert!(!names.iter().any(|n| n == "study"), "{names:?}");
}

#[test]
fn study_is_refused_as_an_unknown_command() {
    let out = Command::new(env!("CARGO_BIN_EXE_fxbody"))
        .args(["study", "--quick"])
        .output()
        .expect("the fxbody binary runs");
    assert_eq!(out.status.code(), Some(2));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("unrecognized subcommand 'study'"), "{e}");
}

/// `fxbody import` of the test punch with its coordinates and `args`, refused: its
/// standard error. Nothing is written.
fn import_refused(args: &[&str]) -> String {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out = std::env::temp_dir().join(format!("fxbody_cli_import_{}.fxb", std::process::id()));
    let o = Command::new(env!("CARGO_BIN_EXE_fxbody"))
        .arg("import")
        .arg(root.join("tests/data/fe/punch.pch"))
        .arg("--coords")
        .arg(root.join("tests/data/fe/nodes.csv"))
        .args(args)
        .arg("-o")
        .arg(&out)
        .output()
        .expect("the fxbody binary runs");
    assert_eq!(o.status.code(), Some(2));
    assert!(!out.exists());
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The import library's errors name no option (issue 27.6): the command words them. A
/// cut-off frequency the library refuses is named `--fmax` once, with the value given;
/// a unit system the command's grammar cannot read is refused naming `--units` and the
/// expected form.
#[test]
fn the_command_names_the_option_of_a_bad_value() {
    let e = import_refused(&["--fmax", "0"]);
    assert!(
        e.contains("--fmax: the cut-off frequency must be finite and > 0 Hz, got 0")
            && e.matches("--fmax").count() == 1,
        "{e}"
    );
    let e = import_refused(&["--units", "mm-lb-s:m-kg-s"]);
    assert!(
        e.contains("'--units <UNITS>'") && e.contains("found 'mm-lb-s:m-kg-s'"),
        "{e}"
    );
}
