//! Smoke test of `fxbody-study --quick` (a few seconds in release): the command runs end
//! to end and its numbers agree with independent references.
//! - exact modal stepping on the cantilever step load stays within 0.5% of the fixture's
//!   full finite-element response (ref.json) at every step size, and the error the study
//!   reports is the one this test recomputes from ref.json itself (its own run of the
//!   body, its own sample alignment and peak), so a study that compared against anything
//!   else (its own runs, a shifted grid) fails here;
//! - the measured explicit stability limit is dt_fx within 1% (central difference is
//!   stable for omega_max h < 2, BENCHMARKS.md), and the exact and implicit methods are
//!   stable at 10^4 dt_fx (unconditional stability);
//! - mode-count sweep: the cantilever truncated at 30 f1 (7 of 20 modes, residual
//!   flexibility added) stays within 0.5% of the full FE step response with the exact
//!   method (recomputed here too), and the error does not grow as modes are added (it is
//!   checked against the full FE model, not against our own untruncated run);
//! - the chart has one panel per scene, and the Model Exchange points of a `me.csv`
//!   written into the output folder beforehand (as `study/me.py` does) are drawn on
//!   their scenes' panels, with their legend entry and their table;
//! - the stability maps are data: no failure word on stderr, every point without a
//!   result says "unstable (why)" or "refused (why)" in the `outcome` column, the spin
//!   trials beyond the frame tolerance say so, and the run exits 0 (issue 25.6; only a
//!   failed acceptance check makes it exit non-zero, crates/study/src/accept.rs).
//!
//! Being an integration test of the study package, it makes `cargo test` build
//! target/release/fxbody-study, which tests/all/cli runs through
//! `fxbody_host::workspace_binary`.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;

use fxbody::scene::Scene;
use fxbody::solver::{Method, Options, build};
use serde_json::Value;

fn fixtures() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("fixtures")
}

/// The cantilever with its tip exposed, at the deck's coordinates, truncated at `fmax`
/// Hz when given; and its reference.
fn cantilever_tip(fmax: Option<f64>) -> (Scene, Value) {
    let dir = fixtures();
    let reference: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("cantilever.ref.json")).unwrap())
            .unwrap();
    let tip = reference["tip_node"].as_i64().unwrap();
    let body = fxbody::body::load(&dir.join("cantilever.fxb"), Default::default()).unwrap();
    let deck = fxbody::fxb::coords::read_coords(&dir.join("cantilever.nodes.rad")).unwrap();
    let x = deck.iter().find(|(id, _)| *id == tip).unwrap().1;
    let k = body.node_index(tip).unwrap();
    let scene = Scene::new(Arc::new(body), vec![k], vec![x]);
    match fmax {
        Some(f) => (scene.truncated(f).unwrap().0, reference),
        None => (scene, reference),
    }
}

/// The largest |uy - uy_ref| over the reference samples a run with step `h` lands on,
/// relative to the reference's largest |uy|: the exact method, the step load of
/// ref.json held from t = 0 on the tip's fy. Written here from ref.json alone.
fn step_error(scene: &Scene, reference: &Value, h: f64) -> f64 {
    let resp = reference["responses"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == "step")
        .unwrap();
    let num = |v: &Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let t = num(&resp["t"]);
    let uy = num(&resp["nodes"][reference["tip_node"].to_string()]["uy"]);
    let amp = resp["amplitude"].as_f64().unwrap();
    let dt = t[1] - t[0];
    let peak = uy.iter().fold(0.0f64, |a, u| a.max(u.abs()));
    let mut s = build(scene, Method::Exact, &Options::default()).unwrap();
    s.set_loads(&[0.0, amp, 0.0, 0.0, 0.0, 0.0]).unwrap();
    let steps = (t[t.len() - 1] / h).round() as usize;
    let mut pos = [0.0; 3];
    let mut worst = 0.0f64;
    for i in 1..=steps {
        s.step(h).unwrap();
        let k = i as f64 * h / dt;
        if (k - k.round()).abs() > 1e-6 || k.round() as usize >= uy.len() {
            continue;
        }
        s.positions(&mut pos);
        worst = worst.max((pos[1] - scene.x0[0][1] - uy[k.round() as usize]).abs());
    }
    worst / peak
}

/// `got` (the study's, printed to 7 digits) equals `want` (recomputed) to its digits.
fn same(got: f64, want: f64, what: &str) {
    assert!(
        (got - want).abs() <= 1e-6 * want.abs(),
        "{what}: the study reports {got:e}, recomputed from ref.json {want:e}"
    );
}

/// A `me.csv` as `study/me.py` writes it: two finite points on the cantilever step (CPU
/// times no method of the study reaches, so the panel's x axis must stretch to 1e3 for
/// them), one on the free-free pulse, and one CVode gave up on (not drawn).
const ME_CSV: &str = "scene,rtol,error_rel_peak,cpu_s_per_sim_s,outputs,compared_samples,note\n\
    cantilever step,1e-04,2.5e-02,1.2e3,2245,2245,\n\
    cantilever step,1e-08,6.8e-04,2.4e3,2245,2245,\n\
    free-free pulse,1e-08,8.5e-04,2.0,2822,2822,\n\
    truss pulse,1e-11,NaN,NaN,0,0,CVode gave up\n";

fn run_quick() -> (PathBuf, String) {
    let out = std::env::temp_dir().join(format!("fxbody_study_smoke_{}", std::process::id()));
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("me.csv"), ME_CSV).unwrap();
    let fixtures = fixtures();
    let status = Command::new(env!("CARGO_BIN_EXE_fxbody-study"))
        .args(["--quick", "--fixtures"])
        .arg(&fixtures)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("the fxbody-study binary runs");
    assert!(
        status.status.success(),
        "fxbody-study --quick failed: {}",
        String::from_utf8_lossy(&status.stderr)
    );
    (out, String::from_utf8_lossy(&status.stderr).into_owned())
}

fn csv(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[test]
fn quick_study_matches_independent_references() {
    let (out, stderr) = run_quick();
    assert!(
        !stderr.contains("FAIL"),
        "a failure word on stderr:\n{stderr}"
    );
    let rows = csv(&out.join("study.csv"));
    let outcomes: Vec<&String> = rows.iter().map(|r| r.last().unwrap()).collect();
    assert!(
        outcomes
            .iter()
            .all(|o| o.is_empty() || o.starts_with("unstable (") || o.starts_with("refused (")),
        "{outcomes:?}"
    );
    // The spin map has trials beyond the frame tolerance (large rotations per step):
    // reported as data, in spin.csv (`passes` false) and on stderr, never as a failure.
    let spin = csv(&out.join("spin.csv"));
    let beyond = spin.iter().filter(|r| r[8] == "false").count();
    assert!(
        beyond > 0 && stderr.contains("beyond tolerance"),
        "{beyond} trials beyond tolerance"
    );
    let exact_step: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r[0] == "cantilever step" && r[1] == "exact")
        .map(|r| {
            (
                r[2].parse().expect("h is a number"),
                r[4].parse().expect("error is a number"),
            )
        })
        .collect();
    assert!(exact_step.len() >= 3, "{exact_step:?}");
    let (tip, reference) = cantilever_tip(None);
    for &(h, e) in &exact_step {
        let want = step_error(&tip, &reference, h);
        println!("cantilever step, exact, h = {h:e}: study {e:e}, recomputed {want:e}");
        same(e, want, &format!("exact at h = {h:e}"));
        assert!(want < 5e-3, "exact vs full FE, step load: {want}");
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
    let (fmax, kept, h): (f64, usize, f64) = (
        at30[2].parse().unwrap(),
        at30[3].parse().unwrap(),
        at30[5].parse().unwrap(),
    );
    let (cut, _) = cantilever_tip(Some(fmax));
    assert_eq!(cut.body.nl(), kept, "modes below {fmax} Hz");
    let want = step_error(&cut, &reference, h);
    println!("cantilever step, 30 f1 ({kept} modes), exact: study {e30:e}, recomputed {want:e}");
    same(e30, want, "30 f1 truncation");
    assert!(want < 5e-3, "30 f1 truncation vs full FE: {want}");
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
    // The Model Exchange points: one legend entry, a dot per finite point (black, the
    // curve's colour; no method or peer uses it), the cantilever step panel's x axis
    // stretched to their CPU times, and the table in study_results.md.
    let label = ">Model Exchange + CVode (fmpy)</text>";
    assert_eq!(svg.matches(label).count(), 1, "legend entry");
    assert_eq!(
        svg.matches(r##"r="2.8" fill="#000000"/>"##).count(),
        3,
        "Model Exchange points drawn"
    );
    assert!(svg.contains(">1e3</text>"), "x axis reaches 1e3 s/s");
    let md = std::fs::read_to_string(out.join("study_results.md")).unwrap();
    assert!(
        md.contains("| cantilever step | 1e-8 | 6.80e-4 | 2.40e3 |  |")
            && md.contains("| truss pulse | 1e-11 | NaN | NaN | CVode gave up |"),
        "{md}"
    );
    let _ = std::fs::remove_dir_all(&out);
}
