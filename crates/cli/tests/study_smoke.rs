//! Smoke test of `fxbody study --quick` (a few seconds in release): the command runs end
//! to end and its numbers agree with independent references.
//! - exact modal stepping on the cantilever step load stays within 0.5% of the fixture's
//!   full finite-element response (ref.json) at every step size;
//! - the measured explicit stability limit is dt_fx within 1% (central difference is
//!   stable for omega_max h < 2, BENCHMARKS.md), and the exact and implicit methods are
//!   stable at 10^4 dt_fx (unconditional stability);
//! - mode-count sweep: the cantilever truncated at 30 f1 (7 of 20 modes, residual
//!   flexibility added) stays within 0.5% of the full FE step response with the exact
//!   method, and the error does not grow as modes are added (it is checked against the
//!   full FE model, not against our own untruncated run);
//! - the chart has one panel per scene.
//!
//! It stays in the cli package (the study is a package of its own, run through the
//! command), and being an integration test of that package it makes `cargo test` build
//! target/release/fxbody, which the root package's tests (tests/all/cli and others) run
//! through `fxbody_host::workspace_binary`.

use std::path::PathBuf;
use std::process::Command;

fn run_quick() -> PathBuf {
    let out = std::env::temp_dir().join(format!("fxbody_study_smoke_{}", std::process::id()));
    let fixtures = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("fixtures");
    let status = Command::new(env!("CARGO_BIN_EXE_fxbody"))
        .args(["study", "--quick", "--fixtures"])
        .arg(&fixtures)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("the fxbody binary runs");
    assert!(
        status.status.success(),
        "fxbody study --quick failed: {}",
        String::from_utf8_lossy(&status.stderr)
    );
    out
}

fn csv(path: &PathBuf) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[test]
fn quick_study_matches_independent_references() {
    let out = run_quick();
    let rows = csv(&out.join("study.csv"));
    let exact_step: Vec<f64> = rows
        .iter()
        .filter(|r| r[0] == "cantilever step" && r[1] == "exact")
        .map(|r| r[4].parse().expect("error is a number"))
        .collect();
    assert!(exact_step.len() >= 3, "{exact_step:?}");
    for e in &exact_step {
        assert!(*e < 5e-3, "exact vs full FE, step load: {e}");
    }

    let modes = csv(&out.join("modes.csv"));
    let exact_modes: Vec<(usize, f64)> = modes
        .iter()
        .filter(|r| r[0] == "cantilever step" && r[4] == "exact")
        .map(|r| {
            (
                r[3].parse().expect("modes kept"),
                r[6].parse().expect("error is a number"),
            )
        })
        .collect();
    assert!(exact_modes.len() >= 5, "{exact_modes:?}");
    let at30 = modes
        .iter()
        .find(|r| r[0] == "cantilever step" && r[1] == "30 f1" && r[4] == "exact")
        .expect("30 f1 row");
    let e30: f64 = at30[6].parse().expect("error is a number");
    assert!(e30 < 5e-3, "30 f1 truncation vs full FE: {e30}");
    for w in exact_modes.windows(2) {
        assert!(
            w[1].0 >= w[0].0,
            "modes kept grow with fmax: {exact_modes:?}"
        );
        assert!(
            w[1].1 <= w[0].1 * 1.05,
            "error grows with more modes: {exact_modes:?}"
        );
    }

    let stab = csv(&out.join("stability.csv"));
    let explicit = stab
        .iter()
        .find(|r| r[0] == "cantilever (blocked)" && r[1] == "explicit")
        .expect("explicit row");
    let ratio: f64 = explicit[3].parse().expect("a measured ratio");
    assert!(
        (0.99..=1.01).contains(&ratio),
        "explicit limit {ratio} dt_fx"
    );
    for r in stab.iter().filter(|r| r[1] != "explicit") {
        assert!(
            r[3].starts_with(">="),
            "{} {} unstable at {}",
            r[0],
            r[1],
            r[3]
        );
    }

    let svg = std::fs::read_to_string(out.join("study.svg")).expect("chart written");
    for panel in [
        "cantilever step",
        "cantilever pulse",
        "free-free pulse",
        "free tumble",
    ] {
        assert!(svg.contains(panel), "no panel {panel}");
    }
    let _ = std::fs::remove_dir_all(&out);
}
