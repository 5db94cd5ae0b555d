//! Issue 28 point 9, names and warnings of `pack`, end to end with the built binary:
//! - two packs of one body into one folder no longer overwrite each other's OSP model
//!   description (libcosim finds it by model name, `<name>_OspModelDescription.xml`): the
//!   second is refused before anything is written, naming the FMU the file describes;
//!   with its own `--name` both FMUs get a description of their own nodes; the same FMU
//!   packed again, or one whose FMU is gone, is overwritten; a file fxbody did not write
//!   is never overwritten;
//! - the header's macros are named after the header file (`tip.h`: `TIP_*`), so the
//!   headers of two packs of one body compile together; a file name that makes no C
//!   identifier is refused;
//! - `--name` (and a body file name used as the model name) refuses C keywords, `main`,
//!   FMI 2.0 names and identifiers C reserves;
//! - the DefaultExperiment warns above 1e9 steps and below 1e-9 of the lowest period,
//!   and not at either bound.

use std::path::Path;
use std::process::{Command, Output};

use super::{assert_refused, pack_cantilever as pack, run, scratch};

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The variable names an OSP model description refers to.
fn osp_refs(osp: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(osp).unwrap();
    text.split("ref=\"")
        .skip(1)
        .map(|s| s.split('"').next().unwrap().to_string())
        .collect()
}

#[test]
fn a_second_pack_of_one_model_name_into_a_folder_is_refused() {
    let d = scratch("names_osp");
    let (tip, root_fmu) = (d.join("tip.fmu"), d.join("root.fmu"));
    let osp = d.join("cantilever_OspModelDescription.xml");
    let o = pack(&["--nodes", "121", "-o", tip.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let before = std::fs::read(&osp).unwrap();
    assert!(osp_refs(&osp).contains(&"node_121.fx".to_string()));

    // The second pack of the same model name: refused, nothing written.
    let o = pack(&["--nodes", "111", "-o", root_fmu.to_str().unwrap()]);
    assert_refused(
        &o,
        "cantilever_OspModelDescription.xml describes tip.fmu, another FMU of the model name 'cantilever'",
    );
    assert_refused(&o, "give this pack another --name");
    assert!(!root_fmu.exists());
    assert_eq!(std::fs::read(&osp).unwrap(), before);

    // With a name of its own: a description of its own nodes beside the first.
    let o = pack(&[
        "--nodes",
        "111",
        "--name",
        "root",
        "-o",
        root_fmu.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let root_refs = osp_refs(&d.join("root_OspModelDescription.xml"));
    assert!(
        root_refs.iter().all(|r| r.starts_with("node_111.")),
        "{root_refs:?}"
    );
    assert!(osp_refs(&osp).iter().all(|r| r.starts_with("node_121.")));

    // The same FMU packed again is overwritten; so is one whose FMU is gone.
    let o = pack(&[
        "--nodes",
        "121",
        "--units",
        "SI",
        "-o",
        tip.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        std::fs::read_to_string(&osp)
            .unwrap()
            .contains("unit=\"N\"")
    );
    std::fs::remove_file(&tip).unwrap();
    let other = d.join("other.fmu");
    let o = pack(&["--nodes", "111", "-o", other.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(osp_refs(&osp).iter().all(|r| r.starts_with("node_111.")));

    // A description fxbody did not write is never overwritten.
    std::fs::write(&osp, "<OspModelDescription/>\n").unwrap();
    let o = pack(&["--nodes", "111", "-o", other.to_str().unwrap()]);
    assert_refused(
        &o,
        "exists and was not written by fxbody pack (no record of the FMU it describes)",
    );
    assert_eq!(
        std::fs::read_to_string(&osp).unwrap(),
        "<OspModelDescription/>\n"
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn header_macros_are_named_after_the_header_file() {
    let d = scratch("names_header");
    // One body, one model name (cantilever), two FMUs in folders of their own, two
    // headers side by side.
    for (node, name) in [("121", "tip"), ("111", "mid")] {
        let h = d.join(format!("{name}.h"));
        std::fs::create_dir_all(d.join(name)).unwrap();
        let fmu = d.join(name).join("cantilever.fmu");
        let o = pack(&[
            "--nodes",
            node,
            "--header",
            h.to_str().unwrap(),
            "-o",
            fmu.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let text = std::fs::read_to_string(&h).unwrap();
        let prefix = name.to_ascii_uppercase();
        assert!(
            text.contains(&format!("#define {prefix}_VR_NODE_{node}_FY "))
                && text.contains(&format!("#define {prefix}_MODEL_IDENTIFIER \"cantilever\"")),
            "{text}"
        );
    }
    // Both headers in one translation unit, every macro used: no redefinition.
    let c = d.join("both.c");
    std::fs::write(
        &c,
        "#include \"tip.h\"\n#include \"mid.h\"\n\
         unsigned vrs[] = {TIP_VR_NODE_121_FY, MID_VR_NODE_111_FY};\n\
         const char *guids[] = {TIP_GUID, MID_GUID};\n",
    )
    .unwrap();
    let cc = Command::new("cc")
        .args(["-std=c99", "-Wall", "-Werror", "-fsyntax-only"])
        .arg(&c)
        .current_dir(&d)
        .output()
        .unwrap();
    assert!(
        cc.status.success(),
        "{}",
        String::from_utf8_lossy(&cc.stderr)
    );
    // A file name that makes no C identifier: refused before anything is written.
    let bad = d.join("2tip.h");
    let o = pack(&[
        "--nodes",
        "121",
        "--header",
        bad.to_str().unwrap(),
        "-o",
        d.join("x.fmu").to_str().unwrap(),
    ]);
    assert_refused(
        &o,
        "named after its file name ('2TIP_GUID', ...), which must start with a letter",
    );
    // The library names the file; the command names the option.
    assert_refused(
        &o,
        &format!("--header {}: the header's macros", bad.display()),
    );
    assert!(!d.join("x.fmu").exists() && !bad.exists());
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn names_c_or_fmi_reserve_are_refused() {
    let d = scratch("names_reserved");
    let out = d.join("x.fmu");
    for (name, why) in [
        ("int", "is a C keyword"),
        ("while", "is a C keyword"),
        ("_Bool", "is a C keyword"),
        ("main", "is the C program's entry point"),
        ("fmi2DoStep", "is in FMI 2.0's namespace"),
        ("fmi2Component", "is in FMI 2.0's namespace"),
        ("_Tip", "is reserved by C for the implementation"),
        ("__tip", "is reserved by C for the implementation"),
    ] {
        let o = pack(&[
            "--nodes",
            "121",
            "--name",
            name,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_refused(&o, &format!("--name: '{name}' {why}"));
        assert!(!out.exists());
    }
    // Near misses are names like any other.
    for name in ["integer", "main_body", "fmi_body", "_tip"] {
        let o = pack(&[
            "--nodes",
            "121",
            "--name",
            name,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
    }
    // The body file's name as the model name is checked alike.
    let body = d.join("int.fxb");
    std::fs::copy("fixtures/cantilever.fxb", &body).unwrap();
    let o = run(&[
        "pack",
        body.to_str().unwrap(),
        "--coords",
        "fixtures/cantilever.nodes.rad",
        "-o",
        d.join("y.fmu").to_str().unwrap(),
    ]);
    assert_refused(
        &o,
        "the model identifier would be the file name's 'int', which is a C keyword: give --name",
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn the_default_experiment_warns_beyond_its_bounds_only() {
    let d = scratch("names_experiment");
    let out = d.join("x.fmu");
    let o = out.to_str().unwrap();
    let warned = |args: &[&str], what: &str| -> bool {
        let r = pack(&[&["--nodes", "121", "-o", o][..], args].concat());
        assert!(r.status.success(), "{args:?}: {}", stderr(&r));
        stderr(&r).contains(what)
    };
    let steps = "steps, more than 1e9";
    // 1e9 steps exactly, and one step more.
    assert!(!warned(&["--step", "1e-3", "--stop", "1e6"], steps));
    assert!(warned(&["--step", "1e-3", "--stop", "1.000001e6"], steps));
    // The cantilever's lowest mode: 6.684139054836714 Hz, period 0.1496 s; 1e-9 of it
    // is 1.496e-10 s.
    let period = "of the lowest mode's period";
    assert!(!warned(&["--step", "1.5e-10", "--stop", "1e-3"], period));
    assert!(warned(&["--step", "1.49e-10", "--stop", "1e-3"], period));
    // The derived experiment warns of nothing.
    let r = pack(&["--nodes", "121", "-o", o]);
    assert!(!stderr(&r).contains("warning"), "{}", stderr(&r));
    std::fs::remove_dir_all(&d).ok();
}
