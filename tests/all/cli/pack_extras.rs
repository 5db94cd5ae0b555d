//! Issue 15 items 3, 4 and 7 (`pack --binary`), end to end with the built binary:
//! - the OSP model description beside the .fmu names only variables of the model
//!   description, each with the causality its group needs (forces and torques inputs,
//!   velocities outputs), type Real and the same unit; one linear port per exposed node,
//!   an angular one exactly where the node has moment inputs and angular-velocity outputs;
//! - `--step` / `--stop` set the DefaultExperiment and `--fmax auto` follows `--step`;
//! - `--method` sets the start value, which the running FMU uses (a C master that reads
//!   value references from the `--header` file, compiled with -Wall -Werror, gets the
//!   explicit method's result to 1e-12, not the exact one's), and is refused where it
//!   cannot apply;
//! - exposing a node no mode moves is warned about;
//! - `--binary PLATFORM=PATH` stores the library under binaries/PLATFORM/, records the
//!   platform in the description and the documentation, and refuses wrong platforms and
//!   files that are not that platform's shared library.

use super::{run, scratch};
use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output};

use fxbody::fmu::simulation::Simulation;
use fxbody::solver::{self, Method, Options};

use crate::common::c_build;

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn refused(o: &Output) -> String {
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Unzip `fmu` into `dir`; the files by name.
fn unzip(fmu: &Path, dir: &Path) -> HashMap<String, Vec<u8>> {
    let files = fxbody_host::zip::read(&std::fs::read(fmu).unwrap()).unwrap();
    for (name, data) in &files {
        let p = dir.join(name);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, data).unwrap();
    }
    files.into_iter().collect()
}

/// Every XML tag `(element, attributes)` of `xml` in order, closing tags as `/name`
/// (enough for the files we write: no CDATA, attributes in double quotes).
fn tags(xml: &str) -> Vec<(String, HashMap<String, String>)> {
    let mut out = Vec::new();
    for piece in xml.split('<').skip(1) {
        let Some(body) = piece.split('>').next() else {
            continue;
        };
        if body.starts_with('?') || body.starts_with('!') {
            continue;
        }
        let body = body.trim_end_matches('/');
        let (name, mut rest) = body.split_once(char::is_whitespace).unwrap_or((body, ""));
        let mut attrs = HashMap::new();
        while let Some((k, v)) = rest.split_once("=\"") {
            let (val, after) = v.split_once('"').unwrap();
            attrs.insert(k.trim().to_string(), val.to_string());
            rest = after;
        }
        out.push((name.to_string(), attrs));
    }
    out
}

/// The model description's variables: name -> (causality, type element, unit).
fn md_vars(xml: &str) -> HashMap<String, (String, String, Option<String>)> {
    let t = tags(xml);
    let mut vars = HashMap::new();
    for (k, (el, a)) in t.iter().enumerate() {
        if el == "ScalarVariable" {
            let (ty, ta) = &t[k + 1];
            vars.insert(
                a["name"].clone(),
                (a["causality"].clone(), ty.clone(), ta.get("unit").cloned()),
            );
        }
    }
    vars
}

/// Check an OSP file against its model description; returns the port names.
fn check_osp(osp: &str, md: &str) -> Vec<String> {
    let vars = md_vars(md);
    let t = tags(osp);
    assert_eq!(t[0].0, "OspModelDescription");
    assert_eq!(
        t[0].1["xmlns"],
        "https://open-simulation-platform.com/OspModelDescription/1.0.0"
    );
    let defined: Vec<&str> = t
        .iter()
        .filter(|(e, _)| e == "Unit")
        .map(|(_, a)| a["name"].as_str())
        .collect();
    let mut ports = Vec::new();
    let mut group = String::new();
    let mut n_vars = 0;
    for (el, a) in &t {
        match el.as_str() {
            "LinearMechanicalPort" | "AngularMechanicalPort" => {
                ports.push(format!("{el} {}", a["name"]))
            }
            "Force" | "Torque" | "LinearVelocity" | "AngularVelocity" => group = el.clone(),
            "Variable" => {
                n_vars += 1;
                let name = &a["ref"];
                let (causality, ty, unit) = vars
                    .get(name)
                    .unwrap_or_else(|| panic!("{name}: not in the model description"));
                let want = if group == "Force" || group == "Torque" {
                    "input"
                } else {
                    "output"
                };
                assert_eq!(causality, want, "{name} in {group}");
                assert_eq!(ty, "Real", "{name}");
                assert_eq!(unit.as_ref(), a.get("unit"), "{name}: unit");
                if let Some(u) = a.get("unit") {
                    assert!(defined.contains(&u.as_str()), "{u} not defined");
                }
                let axis = &a["axis"];
                assert!(name.ends_with(axis.as_str()), "{name} axis {axis}");
            }
            _ => {}
        }
    }
    assert_eq!(n_vars, 6 * ports.len());
    ports
}

#[test]
fn osp_ports_name_the_description_s_variables() {
    let d = scratch("pack_osp");
    for (body, coords, nodes) in [
        (
            "cantilever",
            Some("fixtures/cantilever.nodes.rad"),
            "121, 111",
        ),
        ("freefree", None, "521,501"),
        ("truss", Some("fixtures/truss.nodes.rad"), "1001"),
    ] {
        let fmu = d.join(format!("{body}.fmu"));
        let fxb = format!("fixtures/{body}.fxb");
        let mut args = vec!["pack", fxb.as_str(), "--nodes", nodes, "--units", "SI"];
        if let Some(c) = coords {
            args.extend(["--coords", c]);
        }
        args.extend(["-o", fmu.to_str().unwrap()]);
        ok(&run(&args));
        let files = unzip(&fmu, &d.join(body));
        let md = String::from_utf8(files["modelDescription.xml"].clone()).unwrap();
        let osp = std::fs::read_to_string(d.join(format!("{body}_OspModelDescription.xml")))
            .expect("the OSP file beside the .fmu");
        let ports = check_osp(&osp, &md);
        let vars = md_vars(&md);
        let ids: Vec<&str> = nodes.split([',', ' ']).filter(|s| !s.is_empty()).collect();
        let mut expect = Vec::new();
        for id in &ids {
            expect.push(format!("LinearMechanicalPort node_{id}.linear"));
            let angular = ["mx", "wx"]
                .iter()
                .all(|s| vars.contains_key(&format!("node_{id}.{s}")));
            if angular {
                expect.push(format!("AngularMechanicalPort node_{id}.angular"));
            }
        }
        assert_eq!(ports, expect, "{body}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn step_stop_and_method_reach_the_description_and_the_running_fmu() {
    let d = scratch("pack_exp");
    let fmu = d.join("tip.fmu");
    let header = d.join("tip.h");
    let err = ok(&run(&[
        "pack",
        "fixtures/cantilever.fxb",
        "--coords",
        "fixtures/cantilever.nodes.rad",
        "--nodes",
        "121, 101",
        "--name",
        "tip",
        "--step",
        "5e-4",
        "--stop",
        "2",
        "--fmax",
        "auto",
        "--method",
        "explicit",
        "--header",
        header.to_str().unwrap(),
        "-o",
        fmu.to_str().unwrap(),
    ]));
    // Node 101 is the clamped root: no mode moves it.
    assert!(err.contains("warning: node 101 is fully blocked"), "{err}");
    assert!(!err.contains("node 121 is fully blocked"), "{err}");
    assert!(err.contains("--fmax auto: 2000 Hz"), "{err}");
    let unz = d.join("unz");
    let files = unzip(&fmu, &unz);
    let md = String::from_utf8(files["modelDescription.xml"].clone()).unwrap();
    assert!(
        md.contains("<DefaultExperiment startTime=\"0.0\" stopTime=\"2.0\" stepSize=\"0.0005\"/>"),
        "{md}"
    );
    let t = tags(&md);
    let k = t
        .iter()
        .position(|(e, a)| e == "ScalarVariable" && a["name"] == "method")
        .unwrap();
    assert_eq!(t[k + 1].1["start"], "1", "explicit");
    let scene = String::from_utf8(files["resources/scene.txt"].clone()).unwrap();
    assert!(scene.contains("fmax = 2000.0\n") && scene.contains("method = explicit\n"));
    let model = Simulation::from_resources(&unz.join("resources")).unwrap();
    assert_eq!(model.method(), Method::Explicit);
    // fmi2Reset goes back to the start values the description declares: the packed
    // method, not the body's default (exact; it did until issue 27).
    let mut reset = Simulation::from_resources(&unz.join("resources")).unwrap();
    reset.reset();
    assert_eq!(reset.method(), Method::Explicit, "after fmi2Reset");

    // A C master naming variables through the header drives the FMU with its start method.
    let exe = d.join("header_driver");
    c_build::compile_c_master(
        "header_driver.c",
        &exe,
        &["-O1", "-include", header.to_str().unwrap()],
    );
    let (h, steps, force) = (2e-4, 500, 1.0);
    let out = Command::new(&exe)
        .arg(unz.join("binaries/linux64/tip.so"))
        .arg(fxbody_host::file_uri(&unz.join("resources")))
        .args([steps.to_string(), h.to_string(), force.to_string()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let f: Vec<&str> = stdout.split_whitespace().collect();
    let y_c: f64 = f[0].parse().unwrap();
    assert_eq!(f[1], "1", "method read back through TIP_VR_METHOD");
    assert_eq!(f[2], model.table.vars.len().to_string());
    let res = fxbody::scene::io::load_resources(&unz.join("resources")).unwrap();
    let run_rust = |m: Method| {
        let mut s = solver::build(&res.scene, m, &Options::default()).unwrap();
        let mut loads = vec![0.0; 12];
        loads[1] = force;
        for _ in 0..steps {
            s.set_loads(&loads).unwrap();
            s.set_load_rates(&[0.0; 12]).unwrap();
            s.step(h).unwrap();
        }
        let mut pos = [0.0; 6];
        s.positions(&mut pos);
        pos[1]
    };
    let (y_explicit, y_exact) = (run_rust(Method::Explicit), run_rust(Method::Exact));
    assert!(
        (y_c - y_explicit).abs() <= 1e-12 * y_explicit.abs(),
        "C {y_c} vs explicit {y_explicit}"
    );
    assert!(
        (y_explicit - y_exact).abs() > 1e-9 * y_exact.abs(),
        "the methods differ: {y_explicit} vs {y_exact}"
    );
    // Every constant is unique and names a variable.
    let text = std::fs::read_to_string(&header).unwrap();
    let mut names: Vec<&str> = text
        .lines()
        .filter_map(|l| l.strip_prefix("#define TIP_VR_"))
        .map(|l| l.split_whitespace().next().unwrap())
        .collect();
    assert_eq!(names.len(), model.table.vars.len());
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), model.table.vars.len());
    assert!(text.contains(&format!("#define TIP_GUID \"{}\"", res.guid)));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn pack_options_are_refused_where_they_cannot_apply() {
    let d = scratch("pack_refuse");
    let out = d.join("f.fmu");
    let o = out.to_str().unwrap();
    let free = "fixtures/freefree.fxb";
    let e = refused(&run(&["pack", free, "--method", "exact", "-o", o]));
    assert!(
        e.contains("method exact: exact modal stepping needs a blocked body"),
        "{e}"
    );
    let e = refused(&run(&["pack", free, "--method", "fast", "-o", o]));
    assert!(
        e.contains("--method: expected explicit, implicit, exact or split, found 'fast'"),
        "{e}"
    );
    let e = refused(&run(&["pack", free, "--step", "2", "-o", o]));
    assert!(
        e.contains("--step 2 s is longer than the DefaultExperiment stop time"),
        "{e}"
    );
    let e = refused(&run(&["pack", free, "--step=-1e-3", "-o", o]));
    assert!(
        e.contains("--step: expected a time > 0 (s), found -0.001"),
        "{e}"
    );
    assert!(!out.exists(), "nothing written");
    ok(&run(&["pack", free, "--method", "explicit", "-o", o]));
    let unz = d.join("unz");
    unzip(&out, &unz);
    let m = Simulation::from_resources(&unz.join("resources")).unwrap();
    assert_eq!(m.method(), Method::Explicit);
    let _ = std::fs::remove_dir_all(&d);
}

/// A minimal 64-bit PE DLL header (what `cargo build --release` writes on Windows starts
/// so): MZ, the PE signature at 0x80, machine x86-64, characteristics with IMAGE_FILE_DLL.
fn pe64_dll() -> Vec<u8> {
    let mut b = vec![0u8; 0x200];
    b[..2].copy_from_slice(b"MZ");
    b[0x3c..0x40].copy_from_slice(&0x80u32.to_le_bytes());
    b[0x80..0x84].copy_from_slice(b"PE\0\0");
    b[0x84..0x86].copy_from_slice(&0x8664u16.to_le_bytes());
    b[0x96..0x98].copy_from_slice(&0x2022u16.to_le_bytes());
    b
}

#[test]
fn binary_adds_a_checked_library_for_another_platform() {
    let d = scratch("pack_bin");
    let dll = d.join("fxbody.dll");
    std::fs::write(&dll, pe64_dll()).unwrap();
    let fmu = d.join("tip.fmu");
    let base = [
        "pack",
        "fixtures/cantilever.fxb",
        "--coords",
        "fixtures/cantilever.nodes.rad",
        "--nodes",
        "121",
        "--name",
        "tip",
        "-o",
        fmu.to_str().unwrap(),
    ];
    let with = |extra: &[&str]| {
        let mut a = base.to_vec();
        a.extend_from_slice(extra);
        run(&a)
    };
    let win = format!("win64={}", dll.display());
    ok(&with(&["--binary", &win]));
    let files = unzip(&fmu, &d.join("unz"));
    assert_eq!(files["binaries/win64/tip.dll"], pe64_dll());
    assert!(files.contains_key("binaries/linux64/tip.so"));
    let md = String::from_utf8(files["modelDescription.xml"].clone()).unwrap();
    assert!(
        md.contains("<Platforms native=\"linux64\" added=\"win64\"/>"),
        "{md}"
    );
    let doc = String::from_utf8(files["documentation/index.html"].clone()).unwrap();
    assert!(doc.contains("<li>Platforms: linux64, win64</li>"), "{doc}");

    let so = d.join("unz/binaries/linux64/tip.so");
    let e = refused(&with(&["--binary", &format!("win64={}", so.display())]));
    assert!(
        e.contains("expected a PE 64-bit DLL for win64, found: ELF 64-bit shared library"),
        "{e}"
    );
    let e = refused(&with(&["--binary", &format!("win32={}", dll.display())]));
    assert!(e.contains("found: PE 64-bit DLL"), "{e}");
    let e = refused(&with(&["--binary", &format!("linux64={}", so.display())]));
    assert!(e.contains("give it with --lib"), "{e}");
    let e = refused(&with(&["--binary", &format!("windows={}", dll.display())]));
    assert!(e.contains("unknown FMI 2.0 platform 'windows'"), "{e}");
    let _ = std::fs::remove_dir_all(&d);
}
