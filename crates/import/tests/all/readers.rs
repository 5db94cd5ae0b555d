//! The FE readers against fixture files written by two independent writers
//! (tests/data/fe/make_fixtures.py, and pyNastran itself for pyn_written.bdf): each layout
//! reads back to the matrix the writer meant (expected_*.csv, full precision) to 1e-9
//! relative, and each refused input names the file, the line and the value or DOF.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::common;

use fxbody_import::fe::{self, Dof, SymMatrix};

fn data(name: &str) -> PathBuf {
    common::root().join("tests/data/fe").join(name)
}

/// `gi,ci,gj,cj,value` lines: the matrix the writer meant, one triangle, no zeros.
fn expected(name: &str) -> Vec<(Dof, Dof, f64)> {
    let text = std::fs::read_to_string(data(name)).unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            let d = |k: usize| Dof {
                id: c[k].parse().unwrap(),
                comp: c[k + 1].parse().unwrap(),
            };
            (d(0), d(2), c[4].parse().unwrap())
        })
        .collect()
}

/// `m` holds exactly the expected terms, each to `tol` relative, and exactly their DOFs.
fn assert_matrix(m: &SymMatrix, want: &[(Dof, Dof, f64)], tol: f64) {
    let mut dofs: Vec<Dof> = want.iter().flat_map(|&(a, b, _)| [a, b]).collect();
    dofs.sort_by_key(Dof::order_key);
    dofs.dedup();
    assert_eq!(m.dofs, dofs, "{}: DOFs", m.name);
    assert_eq!(m.terms.len(), want.len(), "{}: number of terms", m.name);
    for &(a, b, v) in want {
        let got = m.get(a, b);
        assert!(
            (got - v).abs() <= tol * v.abs(),
            "{}: ({a}, {b}) = {got}, expected {v}",
            m.name
        );
    }
    for w in m.terms.windows(2) {
        assert!(
            (w[0].0, w[0].1) < (w[1].0, w[1].1),
            "terms sorted, each once"
        );
    }
    assert!(m.terms.iter().all(|&(i, j, v)| i <= j && v != 0.0));
}

#[test]
fn nastran_punch_layout_reads_back_both_matrices() {
    let k = fe::read_dmig(&data("punch.pch"), "KAAX").unwrap();
    assert_eq!(k.name, "KAAX");
    assert_matrix(&k, &expected("expected_punch_kaax.csv"), 1e-9);
    // Grid DOFs first, scalar points (Craig-Bampton modal DOFs) last.
    assert_eq!(
        k.dofs.last(),
        Some(&Dof {
            id: 900003,
            comp: 0
        })
    );
    assert_eq!(k.dofs[0], Dof { id: 21, comp: 1 });
    let m = fe::read_dmig(&data("punch.pch"), "MAAX").unwrap();
    assert_matrix(&m, &expected("expected_punch_maax.csv"), 1e-9);
}

#[test]
fn pynastran_layouts_read_back() {
    // The layout written by our own writer in pyNastran's style ...
    let k = fe::read_dmig(&data("pyn_style.bdf"), "KAAX").unwrap();
    assert_matrix(&k, &expected("expected_punch_kaax.csv"), 1e-9);
    // ... and the file pyNastran 1.4.1 itself wrote (values touching the component field,
    // header POLAR without NCOL, SPOINT and GRID* cards around the matrices).
    let k = fe::read_dmig(&data("pyn_written.bdf"), "KAAX").unwrap();
    assert_matrix(&k, &expected("expected_punch_kaax.csv"), 1e-9);
    let m = fe::read_dmig(&data("pyn_written.bdf"), "maax").unwrap();
    assert_eq!(m.name, "maax");
    assert_matrix(&m, &expected("expected_punch_maax.csv"), 1e-9);
}

#[test]
fn small_and_free_field_read_back() {
    // Small field: lower triangle, continuation lines, the value written 1.23E+8, 1.23+8,
    // 1.23D8 and .123+9 in turn, blank components for some scalar points: exact.
    let k = fe::read_dmig(&data("small.bdf"), "KAAX").unwrap();
    assert_matrix(&k, &expected("expected_small.csv"), 0.0);
    // Free field: values at full precision, exact.
    let k = fe::read_dmig(&data("free.bdf"), "KAAX").unwrap();
    assert_matrix(&k, &expected("expected_punch_kaax.csv"), 0.0);
}

#[test]
fn abaqus_lower_and_full_storage_read_back() {
    let k = fe::read_abaqus(&data("model_STIF1.mtx")).unwrap();
    assert_eq!(k.name, "model_STIF1");
    assert_matrix(&k, &expected("expected_abaqus_stif.csv"), 0.0);
    let m = fe::read_abaqus(&data("model_MASS1.mtx")).unwrap();
    assert_matrix(&m, &expected("expected_abaqus_mass.csv"), 0.0);
}

#[test]
fn calculix_matrices_map_through_the_dof_file() {
    let k = fe::read_calculix(&data("job.sti"), &data("job.dof")).unwrap();
    assert_eq!(k.name, "job");
    assert_matrix(&k, &expected("expected_abaqus_stif.csv"), 1e-12);
    let m = fe::read_calculix(&data("job.mas"), &data("job.dof")).unwrap();
    assert_matrix(&m, &expected("expected_abaqus_mass.csv"), 1e-12);
}

#[test]
fn coordinates_from_every_format_agree() {
    let want: BTreeMap<i64, [f64; 3]> = std::fs::read_to_string(data("expected_nodes.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let c: Vec<f64> = l.split(',').map(|s| s.parse().unwrap()).collect();
            (c[0] as i64, [c[1], c[2], c[3]])
        })
        .collect();
    // In order of node ID, whatever the file's order.
    let want: Vec<(i64, [f64; 3])> = want.into_iter().collect();
    for f in [
        "grids.bdf",
        "pyn_written.bdf",
        "nodes.rad",
        "nodes.inp",
        "nodes.csv",
    ] {
        let got = fe::read_model_coords(&data(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        assert_eq!(got, want, "{f}");
    }
}

/// The error of reading fixture `file` with `read`, as text; it must name the file.
fn error_of(file: &str, read: impl Fn(&Path) -> Result<(), fe::FeError>) -> String {
    let path = data(file);
    let e = read(&path).expect_err(file).to_string();
    assert!(
        e.starts_with(&path.display().to_string()),
        "{file}: message does not start with the file name: {e}"
    );
    e
}

fn dmig(name: &'static str) -> impl Fn(&Path) -> Result<(), fe::FeError> {
    move |p| fe::read_dmig(p, name).map(drop)
}

fn abaqus(p: &Path) -> Result<(), fe::FeError> {
    fe::read_abaqus(p).map(drop)
}

#[test]
fn refused_dmig_inputs_name_file_line_and_value() {
    let cases: [(&str, &str, &[&str]); 8] = [
        (
            "err_names.pch",
            "KAAX",
            &[
                "err_names.pch: no DMIG named KAAX in",
                "(found: K2GG, MAAX)",
            ],
        ),
        (
            "err_ifo9.pch",
            "KAAX",
            &["err_ifo9.pch:1: DMIG KAAX has IFO=9 (rectangular): not supported"],
        ),
        (
            "err_tin3.pch",
            "KAAX",
            &["err_tin3.pch:1: DMIG KAAX has TIN=3 (complex): not supported"],
        ),
        (
            "err_real.pch",
            "KAAX",
            &["err_real.pch:4: cols 41-56: cannot read '1.2.3' as a real"],
        ),
        (
            "err_twice.pch",
            "KAAX",
            &["err_twice.pch:5: term (21.1, 21.1) given twice: first on line 3"],
        ),
        (
            "err_comp0and3.pch",
            "KAAX",
            &["err_comp0and3.pch:5: node 12 appears with component 0 (line 4) and 3"],
        ),
        (
            "err_dof7.pch",
            "KAAX",
            &["err_dof7.pch:4: cols 25-40: DOF 12.7 not supported (only 1..6"],
        ),
        (
            "err_nonsym.pch",
            "KAAX",
            &[
                "err_nonsym.pch:6: not symmetric: (21.1, 40.1) = 200000 but (40.1, 21.1) = \
                 210000 (line 4), rel. diff 0.047619047619047616",
            ],
        ),
    ];
    for (file, name, parts) in cases {
        let e = error_of(file, dmig(name));
        for p in parts {
            assert!(e.contains(p), "{file}: '{e}' lacks '{p}'");
        }
    }
}

#[test]
fn refused_abaqus_calculix_and_coordinate_inputs_name_file_line_and_value() {
    let cases: [(&str, &str); 5] = [
        (
            "err_negative.mtx",
            "err_negative.mtx:2: node label -7: Abaqus writes negative labels for its internal and Lagrange-multiplier nodes",
        ),
        (
            "err_dof7.mtx",
            "err_dof7.mtx:2: DOF 12.7 not supported (only 1..6)",
        ),
        (
            "err_nonsym.mtx",
            "err_nonsym.mtx:2: not symmetric: (12.3, 40.1) = 210000 but (40.1, 12.3) = 200000 (line 3)",
        ),
        (
            "err_coordinate.mtx",
            "err_coordinate.mtx:1: cannot read '1 , 1, 2.5' as a matrix line: expected 5 comma-separated fields node, dof, node, dof, value, found 3 (3 fields look like FORMAT=COORDINATE",
        ),
        (
            "err_missing_mirror.mtx",
            "err_missing_mirror.mtx:4: not symmetric: (1.1, 3.1) = 0.25 but (3.1, 1.1) = 0 (not given, while the file stores both triangles)",
        ),
    ];
    for (file, want) in cases {
        let e = error_of(file, abaqus);
        assert!(e.contains(want), "{file}: '{e}' lacks '{want}'");
    }
    let e = error_of("err_temperature.dof", |p| {
        fe::read_calculix(&data("job.sti"), p).map(drop)
    });
    assert!(
        e.contains("err_temperature.dof:3: DOF 12.0 not supported (only directions 1..6) (0 is temperature)"),
        "{e}"
    );
    let e = error_of("err_eq.sti", |p| {
        fe::read_calculix(p, &data("err_eq.dof")).map(drop)
    });
    assert!(
        e.contains("err_eq.sti:3: equation 3 is not in ")
            && e.contains("err_eq.dof, which lists 2 DOFs"),
        "{e}"
    );
    let e = error_of("err_cd5.bdf", |p| fe::read_model_coords(p).map(drop));
    assert!(
        e.contains("err_cd5.bdf:3: GRID 12 has CD=5: its components (the matrices' DOFs) are in a local frame"),
        "{e}"
    );
}

#[test]
fn devices_directories_and_endless_lines_are_refused() {
    for p in ["/dev/zero", "/dev/null"] {
        let e = fe::read_dmig(Path::new(p), "KAAX").unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("{p}: expected a regular file")),
            "{e}"
        );
    }
    let dir = data("");
    let e = fe::read_abaqus(&dir).unwrap_err().to_string();
    assert!(e.contains("expected a regular file"), "{e}");
    let e = fe::read_model_coords(&dir).unwrap_err().to_string();
    assert!(e.contains("expected a regular file"), "{e}");
    // A file that is one endless line (a binary file given by mistake).
    let tmp =
        std::env::temp_dir().join(format!("format_fe_endless_line_{}.mtx", std::process::id()));
    std::fs::write(&tmp, vec![b'1'; 3 << 20]).unwrap();
    let e = fe::read_abaqus(&tmp).unwrap_err().to_string();
    std::fs::remove_file(&tmp).unwrap();
    assert!(e.contains(":1: a line longer than 1048576 bytes"), "{e}");
}
