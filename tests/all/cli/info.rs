//! `fxbody info` end to end, running the built binary: JSON keys exactly as specified,
//! numbers against closed forms, exit code 2 and a message naming the line on errors.

use super::run;
use std::f64::consts::PI;

use crate::common::root;

/// The top-level `"key": value` pairs of the one-key-per-line JSON that `info` prints.
fn fields(json: &str) -> Vec<(String, String)> {
    let body = json.trim();
    assert!(body.starts_with('{') && body.ends_with('}'), "{json}");
    body[1..body.len() - 1]
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .map(|l| {
            let l = l.strip_suffix(',').unwrap_or(l);
            let (k, v) = l.split_once(": ").unwrap_or_else(|| panic!("bad line {l}"));
            (k.trim_matches('"').to_string(), v.to_string())
        })
        .collect()
}

fn get<'a>(f: &'a [(String, String)], key: &str) -> &'a str {
    &f.iter()
        .find(|(k, _)| k == key)
        .unwrap_or_else(|| panic!("no key {key}"))
        .1
}

fn numbers(v: &str) -> Vec<f64> {
    let inner = v.trim_start_matches('[').trim_end_matches(']');
    inner
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse().unwrap())
        .collect()
}

// Issue 15 added the Rayleigh coefficients and the free-body mass properties (null
// when absent) before "warnings".
const KEYS: [&str; 18] = [
    "nbmod",
    "nbstat",
    "nbnod",
    "irot",
    "idamp",
    "iblo",
    "ifile",
    "node_ids",
    "freq_file_hz",
    "freq_max_hz",
    "frequencies_hz",
    "dt_stab_s",
    "mass",
    "rayleigh_alpha",
    "rayleigh_beta",
    "cog_from_l0",
    "inertia_at_cog",
    "warnings",
];

#[test]
fn info_json_on_a_damped_blocked_body() {
    let out = run(&["info", "--json", "tests/data/fmt_dexp.fxb"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json = String::from_utf8(out.stdout).unwrap();
    let f = fields(&json);
    let keys: Vec<&str> = f.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(keys, KEYS);
    assert_eq!(get(&f, "nbmod"), "2");
    assert_eq!(get(&f, "nbstat"), "1");
    assert_eq!(get(&f, "nbnod"), "2");
    for flag in ["irot", "idamp", "iblo", "ifile"] {
        assert_eq!(get(&f, flag), "1");
    }
    assert_eq!(get(&f, "node_ids"), "[7, 9]");
    assert_eq!(get(&f, "mass"), "null");
    assert_eq!(get(&f, "warnings"), "[]");
    let freq: f64 = get(&f, "freq_file_hz").parse().unwrap();
    assert_eq!(freq, 4.825461972);
    // K = [[800, -100], [-100, 450]], m = (2, 0.5): lambda^2 - 1300 lambda + 350000 = 0.
    let root = 290_000f64.sqrt();
    let want = [
        ((1300.0 - root) / 2.0).sqrt() / (2.0 * PI),
        ((1300.0 + root) / 2.0).sqrt() / (2.0 * PI),
    ];
    let got = numbers(get(&f, "frequencies_hz"));
    assert_eq!(got.len(), 2);
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() < 1e-12 * w, "{g} vs {w}");
    }
    let fmax: f64 = get(&f, "freq_max_hz").parse().unwrap();
    assert!((fmax - want[1]).abs() < 1e-12 * want[1]);
    // beta = 1e-4 from block 4, omega from the largest computed frequency (issue 13:
    // the step the solvers use, not the stored Freq's).
    let (beta, w) = (1.0e-4, 2.0 * PI * want[1]);
    let dt_want =
        ((((beta * w) * (beta * w) + 4.0).sqrt() - beta * w) / w).min(2.0 / (beta * w * w));
    let dt: f64 = get(&f, "dt_stab_s").parse().unwrap();
    assert!((dt - dt_want).abs() < 1e-15, "{dt} vs {dt_want}");
}

#[test]
fn info_json_on_a_free_body() {
    let out = run(&["info", "--json", "tests/data/body_b0_r1_d0.fxb"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let f = fields(&String::from_utf8(out.stdout).unwrap());
    // Point masses 1 + 2 + 1.5 + 0.5 kg (tests/data/make_data.py).
    let mass: f64 = get(&f, "mass").parse().unwrap();
    assert!((mass - 5.0).abs() < 1e-8, "{mass}");
    // Undamped: 2/omega of the largest computed frequency (stored Freq 12.5 Hz).
    let fmax: f64 = get(&f, "freq_max_hz").parse().unwrap();
    assert!((fmax - 12.5).abs() < 1e-6, "{fmax}");
    let dt: f64 = get(&f, "dt_stab_s").parse().unwrap();
    assert!((dt - 1.0 / (PI * fmax)).abs() < 1e-15);
    assert_eq!(get(&f, "node_ids"), "[11, 12, 13, 14]");
    assert_eq!(get(&f, "irot"), "1");
    assert_eq!(get(&f, "iblo"), "0");
}

#[test]
fn info_text_mode() {
    let out = run(&["info", "tests/data/body_b0_r0_d0.fxb"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("total mass (from M_R): 5.0000000")
            || text.contains("total mass (from M_R): 4.9999999"),
        "{text}"
    );
    assert!(text.contains("node IDs: 11 12 13 14"), "{text}");
}

#[test]
fn info_on_a_bad_file_exits_2_with_the_line() {
    let dir = std::env::temp_dir().join(format!("fxbody-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.fxb");
    let text = std::fs::read_to_string(root().join("tests/data/fmt_fixed.fxb"))
        .unwrap()
        .replace("       7       9", "       7       7");
    std::fs::write(&bad, text).unwrap();
    let out = run(&["info", "--json", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("bad.fxb:6: block 2 (node IDs): duplicate node ID 7"),
        "{err}"
    );
    assert!(out.stdout.is_empty());
    let out = run(&["info", "/nonexistent/x.fxb"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/x.fxb: cannot read"));
    // A body that reads but fails validation is a file error too.
    let labels = run(&["info", "tests/data/labels_r0_d0_ns1.fxb"]);
    assert_eq!(labels.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&labels.stderr).contains("block 3"));
    std::fs::remove_dir_all(&dir).ok();
}

/// The number after `"key":` in a JSON text (first occurrence).
fn json_number(text: &str, key: &str) -> Option<f64> {
    let at = text.find(&format!("\"{key}\":"))? + key.len() + 3;
    let rest = text[at..].trim_start();
    let end = rest.find([',', '}', '\n']).unwrap_or(rest.len());
    rest[..end].trim().parse().ok()
}

/// The array of numbers after `"key":` in a JSON text (first occurrence).
fn json_array(text: &str, key: &str) -> Option<Vec<f64>> {
    let at = text.find(&format!("\"{key}\":"))? + key.len() + 3;
    let rest = text[at..].trim_start().strip_prefix('[')?;
    let end = rest.find(']')?;
    Some(numbers(&rest[..end]))
}

/// The fixtures' reference JSON (full finite-element model) against `info`: total mass
/// and the reduced eigenfrequencies, and the /NODE deck against the file's node list.
/// Runs on fixtures/ when the fixtures are present (or on FXBODY_FIXTURES_DIR).
#[test]
fn info_agrees_with_the_fixture_references() {
    let dir = std::env::var("FXBODY_FIXTURES_DIR")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|_| root().join("fixtures"));
    let names = ["cantilever", "cantilever_damped", "freefree", "truss"];
    let mut checked = 0;
    for name in names {
        let path = dir.join(format!("{name}.ref.json"));
        let reference = std::fs::read_to_string(&path).unwrap_or_else(|e| {
            panic!(
                "{}: {e}: every shipped body has its reference",
                path.display()
            )
        });
        let fxb = dir.join(format!("{name}.fxb"));
        let out = run(&["info", "--json", fxb.to_str().unwrap()]);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let f = fields(&String::from_utf8(out.stdout).unwrap());
        let want = json_array(&reference, "reduced").expect("reduced frequencies");
        let got = numbers(get(&f, "frequencies_hz"));
        assert_eq!(got.len(), want.len(), "{name}");
        for (g, w) in got.iter().zip(&want) {
            assert!(
                (g - w).abs() <= 1e-7 * w.abs().max(1.0),
                "{name}: {g} vs {w}"
            );
        }
        match get(&f, "mass") {
            "null" => assert_eq!(get(&f, "iblo"), "1", "{name}"),
            m => {
                let m: f64 = m.parse().unwrap();
                let w = json_number(&reference, "total_mass").unwrap();
                assert!((m - w).abs() <= 1e-8 * w, "{name}: mass {m} vs {w}");
            }
        }
        let deck =
            fxbody::fxb::coords::read_coords(&dir.join(format!("{name}.nodes.rad"))).unwrap();
        let ids: Vec<String> = deck.iter().map(|(id, _)| id.to_string()).collect();
        assert_eq!(
            format!("[{}]", ids.join(", ")),
            get(&f, "node_ids"),
            "{name}"
        );
        checked += 1;
    }
    println!("fixtures checked: {checked}");
    assert_eq!(checked, names.len(), "every shipped body checked");
}

/// Issue 13 class 3: `info` on a body with a negative beta is refused naming block 4.
#[test]
fn info_refuses_negative_damping() {
    let dir = std::env::temp_dir().join(format!("fxb_i13_neg_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut f = fxbody::fxb::read_path(&root().join("tests/data/fmt_dexp.fxb")).unwrap();
    f.damping = Some((0.0, -1e-4));
    let p = dir.join("neg.fxb");
    std::fs::write(&p, fxbody::fxb::write(&f)).unwrap();
    let out = run(&["info", p.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("block 4 (Rayleigh damping): beta must be >= 0, found beta = -0.0001"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn info_reports_the_free_explicit_step_the_solver_uses() {
    // The truss built on a 3-2-1 support (tests/data/truss_supported.fxb) is free and its
    // modes coupled to the rigid motion are stiffer than its local modes (5583 Hz coupled
    // against 5458 Hz local): `info` must report the step the free explicit solver
    // takes, not the local modes' longer one. The shipped truss's modes are free-free
    // (they do not couple): there the two steps are the same (to 1e-9).
    for (path, coupled) in [
        ("tests/data/truss_supported.fxb", true),
        ("fixtures/truss.fxb", false),
    ] {
        let out = run(&["info", "--json", path]);
        assert!(out.status.success());
        let f = fields(&String::from_utf8(out.stdout).unwrap());
        let dt: f64 = get(&f, "dt_stab_s").parse().unwrap();
        let body = std::sync::Arc::new(
            fxbody::body::load(&root().join(path), Default::default()).unwrap(),
        );
        let local = body.explicit_stable_step();
        let scene = fxbody::scene::Scene::new(body, vec![0], vec![[0.0; 3]]);
        let solver =
            fxbody::solver::free::Explicit::new(&scene, &fxbody::solver::Options::default())
                .unwrap();
        println!(
            "{path}: info {dt:e} s, solver {:e} s, local modes {local:e} s",
            solver.stable_step()
        );
        assert_eq!(
            dt.to_bits(),
            solver.stable_step().to_bits(),
            "{dt} vs {}",
            solver.stable_step()
        );
        if coupled {
            assert!(dt < 0.99 * local, "{dt} vs the local modes' {local}");
        } else {
            assert!((dt / local - 1.0).abs() < 1e-9, "{dt} vs {local}");
        }
    }
}
