//! Issue 25.3, one vocabulary: every command takes unit systems, node lists and pairs in
//! one grammar (crates/cli/src/grammar.rs), and a refusal names the flag and the form
//! it expected. Checked end to end with the built binary against what the option must
//! mean: the units declared in the FMU's OSP description (factors to SI), the Rayleigh
//! pair read back from the written body, the nodes a range selects.

use super::{assert_refused, ok, pack_cantilever, run, scratch};
use crate::common::nums;

/// The `<Unit>` elements of the OSP description beside an FMU packed with `--units`.
fn osp_units(dir: &std::path::Path, units: &str) -> String {
    let fmu = dir.join(format!("c_{}.fmu", units.replace('-', "_")));
    let name = format!("c_{}", units.replace('-', "_"));
    ok(&pack_cantilever(&[
        "--nodes",
        "121",
        "--units",
        units,
        "--name",
        &name,
        "-o",
        fmu.to_str().unwrap(),
    ]));
    let xml = std::fs::read_to_string(dir.join(format!("{name}_OspModelDescription.xml"))).unwrap();
    let start = xml.find("<UnitDefinitions>").expect("units declared");
    let end = xml.find("</UnitDefinitions>").unwrap();
    xml[start..end].to_string()
}

#[test]
fn pack_units_take_every_system_of_the_grammar() {
    let dir = scratch("grammar_units");
    // mm-kg-ms (the README's import example): a force unit kg mm / ms^2 = 1000 N (kN),
    // a velocity mm/ms = 1 m/s, a moment kN mm = 1 N m: factors to SI, by hand.
    let u = osp_units(&dir, "mm-kg-ms");
    for (name, base) in [
        ("kN", "kg=\"1\" m=\"1\" s=\"-2\" factor=\"1000.0\""),
        ("mm/ms", "m=\"1\" s=\"-1\"/>"),
        ("kN.mm", "kg=\"1\" m=\"2\" s=\"-2\"/>"),
        ("rad/ms", "s=\"-1\" rad=\"1\" factor=\"1000.0\""),
    ] {
        let at = u
            .find(&format!("<Unit name=\"{name}\">"))
            .unwrap_or_else(|| panic!("no unit {name}: {u}"));
        assert!(u[at..].contains(base), "{name}: {base} in {u}");
    }
    // m-kg-s is SI, under both names; mm-t-s keeps its names (N, N.mm).
    assert_eq!(osp_units(&dir, "m-kg-s"), osp_units(&dir, "SI"));
    let mmts = osp_units(&dir, "MM-T-S");
    assert!(
        mmts.contains("<Unit name=\"N.mm\">") && mmts.contains("<Unit name=\"N\">"),
        "{mmts}"
    );
    for bad in ["furlongs", "mm-t-s:SI", "mm-lb-s"] {
        let o = pack_cantilever(&["--units", bad, "-o", dir.join("x.fmu").to_str().unwrap()]);
        assert_refused(&o, "--units");
        assert_refused(&o, "LENGTH-MASS-TIME");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn import_damping_is_one_pair_and_the_two_word_form_still_works() {
    let dir = scratch("grammar_damping");
    let body = |tag: &str, damping: &[&str]| {
        let out = dir.join(format!("{tag}.fxb"));
        let args = [
            &[
                "import",
                "fixtures/import/bracket.pch",
                "--coords",
                "fixtures/import/bracket_grids.bdf",
                "-o",
                out.to_str().unwrap(),
            ][..],
            damping,
        ]
        .concat();
        ok(&run(&args));
        let v: serde_json::Value =
            serde_json::from_str(&ok(&run(&["info", "--json", out.to_str().unwrap()]))).unwrap();
        (v["rayleigh_alpha"].as_f64(), v["rayleigh_beta"].as_f64())
    };
    assert_eq!(
        body("comma", &["--damping", "5,1e-5"]),
        (Some(5.0), Some(1e-5))
    );
    assert_eq!(
        body("blank", &["--damping", "5, 1e-5"]),
        (Some(5.0), Some(1e-5))
    );
    assert_eq!(
        body("words", &["--damping", "5", "1e-5"]),
        (Some(5.0), Some(1e-5))
    );
    let o = run(&[
        "import",
        "fixtures/import/bracket.pch",
        "--damping",
        "5",
        "--check",
    ]);
    assert_refused(&o, "--damping");
    assert_refused(&o, "expected two numbers A,B (e.g. 5,1e-5), found '5'");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn import_units_take_one_system_or_a_conversion() {
    let dir = scratch("grammar_import_units");
    let report = |units: &[&str]| {
        let r = dir.join("r.json");
        let args = [
            &[
                "import",
                "fixtures/import/bracket.pch",
                "--coords",
                "fixtures/import/bracket_grids.bdf",
                "--check",
                "--report",
                r.to_str().unwrap(),
            ][..],
            units,
        ]
        .concat();
        let out = ok(&run(&args));
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&r).unwrap()).unwrap();
        (out, v)
    };
    let (_, plain) = report(&[]);
    // One system: no conversion, and the pack --units to declare it.
    let (out, same) = report(&["--units", "SI"]);
    assert_eq!(same["mass"], plain["mass"]);
    assert!(out.contains("fxbody pack --units SI"), "{out}");
    // SI to mm-t-s: mass in tonnes (1e-3 of kg), frequencies unchanged (seconds).
    let (out, mm) = report(&["--units", "m-kg-s:mm-t-s"]);
    assert!(out.contains("fxbody pack --units mm-t-s"), "{out}");
    let (a, b) = (
        mm["mass"]["total_mass"].as_f64().unwrap(),
        plain["mass"]["total_mass"].as_f64().unwrap(),
    );
    assert!((a / b - 1e-3).abs() < 1e-12 * 1e-3, "{a} vs {b}");
    let (fa, fb) = (nums(&mm["frequencies_hz"]), nums(&plain["frequencies_hz"]));
    for (x, y) in fa.iter().zip(&fb) {
        assert!((x / y - 1.0).abs() < 1e-9, "{x} vs {y}");
    }
    let o = run(&[
        "import",
        "fixtures/import/bracket.pch",
        "--units",
        "mm-t",
        "--check",
    ]);
    assert_refused(&o, "--units");
    assert_refused(&o, "expected FROM:TO or one system");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn node_lists_take_ranges_in_every_command() {
    let dir = scratch("grammar_nodes");
    let small = dir.join("small.fxb");
    // reduce: 101-103 and 121, in the order given.
    ok(&run(&[
        "reduce",
        "fixtures/cantilever.fxb",
        "-o",
        small.to_str().unwrap(),
        "--nodes",
        "101-103,121",
    ]));
    let v: serde_json::Value =
        serde_json::from_str(&ok(&run(&["info", "--json", small.to_str().unwrap()]))).unwrap();
    assert_eq!(nums(&v["node_ids"]), vec![101.0, 102.0, 103.0, 121.0]);
    // info: a range's nodes are the columns of the table.
    let v: serde_json::Value = serde_json::from_str(&ok(&run(&[
        "info",
        "--json",
        "--nodes",
        "120-121",
        "fixtures/cantilever.fxb",
    ])))
    .unwrap();
    let shares = v["modes"][0]["cumulative_static_share"]
        .as_object()
        .unwrap();
    assert!(
        shares.contains_key("120:Y") && shares.contains_key("121:Y"),
        "{shares:?}"
    );
    // pack: three exposed nodes from one range; a nodes file with a range.
    let out = ok(&pack_cantilever(&[
        "--nodes",
        "119-121",
        "-o",
        dir.join("r.fmu").to_str().unwrap(),
    ]));
    assert!(out.contains("3 exposed nodes"), "{out}");
    let list = dir.join("nodes.txt");
    std::fs::write(&list, "# tip region\n118-121\n").unwrap();
    let out = ok(&pack_cantilever(&[
        "--nodes-file",
        list.to_str().unwrap(),
        "--name",
        "from_file",
        "-o",
        dir.join("f.fmu").to_str().unwrap(),
    ]));
    assert!(out.contains("4 exposed nodes"), "{out}");
    // import: blanks separate too.
    let r = dir.join("i.json");
    ok(&run(&[
        "import",
        "fixtures/import/bracket.pch",
        "--coords",
        "fixtures/import/bracket_grids.bdf",
        "--nodes",
        "101 110",
        "--check",
        "--report",
        r.to_str().unwrap(),
    ]));
    // Refusals name the flag and the form, in every command.
    for cmd in [
        &["info", "fixtures/cantilever.fxb", "--nodes", "121-101"][..],
        &[
            "reduce",
            "fixtures/cantilever.fxb",
            "-o",
            "x.fxb",
            "--nodes",
            "121-101",
        ],
        &[
            "pack",
            "fixtures/cantilever.fxb",
            "-o",
            "x.fmu",
            "--nodes",
            "121-101",
        ],
        &[
            "import",
            "fixtures/import/bracket.pch",
            "--check",
            "--nodes",
            "121-101",
        ],
    ] {
        let o = run(cmd);
        assert_refused(&o, "--nodes");
        assert_refused(&o, "range '121-101' runs backwards: write 101-121");
    }
    let o = run(&["info", "fixtures/cantilever.fxb", "--nodes", "12x"]);
    assert_refused(
        &o,
        "expected node IDs or ranges A-B separated by commas and/or blanks",
    );
    let _ = std::fs::remove_dir_all(&dir);
}
