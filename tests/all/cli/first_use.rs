//! Issue 15, "what a new user also tripped over", end to end with the built binary:
//! `info --json --nodes` is one JSON object, `info --nodes 999` fails before printing,
//! `info --json` has the Rayleigh coefficients and (free bodies) the mass properties,
//! free-body effective masses are 0 instead of round-off, `--nodes` accepts blanks,
//! counts take the singular, `demo` outside the repository says where the fixtures are
//! and `study` does not write into docs/ by default.

use super::{ok, run, run_in, scratch};

use crate::common::{fixture, fixture_reference, nums, root};

#[test]
fn info_json_with_nodes_is_one_object_with_mass_properties() {
    let out = ok(&run(&[
        "info",
        "--json",
        "--nodes",
        "521, 501",
        "fixtures/freefree.fxb",
    ]));
    let v: serde_json::Value = serde_json::from_str(&out).expect("one JSON document");
    let modes = v["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 10);
    assert!(modes[0]["cumulative_local_share"]["501:Y"].is_number());
    // Free-free modes carry no net translation: exactly 0, not round-off.
    for m in modes {
        assert_eq!(nums(&m["effective_mass"]), vec![0.0, 0.0, 0.0], "{m}");
    }
    // Centre of gravity: L0 + offset against the FE model's centre of mass; inertia
    // trace against the finite-element model's, which tests/all/body/mass_props.rs sums
    // from the elements' consistent mass and finds equal to the rod's m L^2 / 12 to
    // round-off (Hermite cubics are exact on a rigid rotation); 1e-9: the file's digits.
    let r = fixture_reference("freefree");
    let (c, x0) = (nums(&v["cog_from_l0"]), nums(&r["frame"]["x_L0"]));
    let com = nums(&r["center_of_mass"]);
    for k in 0..3 {
        assert!((x0[k] + c[k] - com[k]).abs() < 1e-9, "{c:?}");
    }
    let inertia: Vec<Vec<f64>> = v["inertia_at_cog"]
        .as_array()
        .unwrap()
        .iter()
        .map(nums)
        .collect();
    let trace: f64 = (0..3).map(|k| inertia[k][k]).sum();
    let m = r["total_mass"].as_f64().unwrap();
    let axial = r["model"]["rho"].as_f64().unwrap() * r["model"]["section"]["Ip"].as_f64().unwrap();
    // Two transverse axes at m L^2/12 (L = 1 m) plus the axial rho Ip L.
    let expect = 2.0 * m / 12.0 + axial;
    assert!(
        (trace - expect).abs() < 1e-9 * expect,
        "{trace} vs {expect}"
    );
    assert!(v["rayleigh_alpha"].is_null() && v["rayleigh_beta"].is_null());
}

#[test]
fn info_json_has_the_rayleigh_coefficients() {
    let v: serde_json::Value = serde_json::from_str(&ok(&run(&[
        "info",
        "--json",
        "fixtures/cantilever_damped.fxb",
    ])))
    .unwrap();
    let r = fixture_reference("cantilever_damped");
    assert_eq!(v["rayleigh_alpha"], r["damping"]["alpha"]);
    assert_eq!(v["rayleigh_beta"], r["damping"]["beta"]);
    assert!(v["cog_from_l0"].is_null(), "a blocked body has no M_R");
}

#[test]
fn info_with_an_unknown_node_fails_before_printing() {
    let o = run(&["info", "--nodes", "999", "fixtures/cantilever.fxb"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        o.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("999"));
}

#[test]
fn text_effective_masses_state_the_round_off_threshold() {
    // Printed only where a mode has effective mass (the truss built on a 3-2-1 support,
    // tests/data/truss_supported.fxb; the shipped free bodies' are all zero and not
    // printed, tests/all/cli/info_nodes.rs).
    let out = ok(&run(&[
        "info",
        "--nodes",
        "1001",
        "tests/data/truss_supported.fxb",
    ]));
    assert!(out.contains("below 1e-12 of the total mass"), "{out}");
}

#[test]
fn pack_takes_blanks_in_nodes_and_says_one_node() {
    let d = scratch("first_nodes");
    let fmu = d.join("c.fmu");
    // The last one packed (one node) is read below.
    for (nodes, said) in [
        ("121, 111", "2 exposed nodes"),
        (" 121 ", "1 exposed node,"),
    ] {
        let out = ok(&run(&[
            "pack",
            "fixtures/cantilever.fxb",
            "--coords",
            "fixtures/cantilever.nodes.rad",
            "--nodes",
            nodes,
            "-o",
            fmu.to_str().unwrap(),
        ]));
        assert!(out.contains(said), "{nodes:?}: {out}");
    }
    let files = fxbody_host::zip::read(&std::fs::read(&fmu).unwrap()).unwrap();
    let xml = String::from_utf8(
        files
            .iter()
            .find(|f| f.0 == "modelDescription.xml")
            .unwrap()
            .1
            .clone(),
    )
    .unwrap();
    assert!(xml.contains("1 exposed node)"), "{xml}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn demo_outside_the_repository_says_where_the_fixtures_are() {
    let d = scratch("first_demo");
    let o = run_in(&d, &["demo"]);
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("fixtures/cantilever.fxb: not found") && e.contains("--fixtures"),
        "{e}"
    );
    assert!(!d.join("out").exists(), "nothing written on failure");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn study_writes_beside_the_user_not_into_docs() {
    let d = scratch("first_study");
    let docs_spin = root().join("docs/spin.csv");
    let before = std::fs::metadata(&docs_spin)
        .and_then(|m| m.modified())
        .ok();
    let fixtures = fixture("");
    let o = std::process::Command::new(fxbody_host::workspace_binary("fxbody-study"))
        .current_dir(&d)
        .args(["--quick", "--spin-only", "--fixtures"])
        .arg(&fixtures)
        .output()
        .expect("fxbody-study runs");
    ok(&o);
    assert!(d.join("study-out/spin.csv").is_file());
    let after = std::fs::metadata(&docs_spin)
        .and_then(|m| m.modified())
        .ok();
    assert_eq!(before, after, "docs/spin.csv untouched");
    let _ = std::fs::remove_dir_all(&d);
}
