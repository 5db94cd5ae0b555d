//! Reading the hand-made files of tests/data: where every value lands (against the storage
//! orders of FORMULATION.md section 1, written out again here), every flag combination,
//! and the fixed-column / free-format variants of one body.

use std::path::{Path, PathBuf};

use fxbody::body::{Body, BodyParts};
use fxbody::fxb::{self, FxbFile};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn read(name: &str) -> FxbFile {
    fxb::read_path(&data(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// 1-based value number of K_L(r, c), c >= r, in block 9 (FORMULATION.md section 1).
fn k_full_index(r: usize, c: usize, nl: usize) -> usize {
    (r - 1) * (2 * nl - r + 2) / 2 + (c - r + 1)
}

/// 1-based value number of M_R(i, j), j >= i, in block 11 (upper triangle row by row).
fn m_r_index(i: usize, j: usize, nr: usize) -> usize {
    (i - 1) * nr - (i - 1) * (i - 2) / 2 + (j - i + 1)
}

/// The labelled files hold, for each value, a number that encodes its position.
fn check_labelled(name: &str, nr: usize, nl: usize, ns: usize, ids: &[i64]) {
    let f = read(name);
    assert_eq!(
        (f.nbmod, f.nbstat, f.nbnod, f.nr()),
        (nl, ns, ids.len(), nr)
    );
    assert_eq!(f.node_ids, ids);
    let b = BodyParts::assemble(&f, name).unwrap();
    let n = ids.len();
    for r in 0..3 {
        for c in 0..3 {
            assert_eq!(
                b.p0[(r, c)],
                31.0 + (3 * r + c) as f64,
                "P0({r},{c}) is row-major"
            );
        }
    }
    assert_eq!(b.freq_file, 40.0);
    for p in 1..=n {
        for c in 1..=6 {
            let row = 6 * (p - 1) + (c - 1);
            for i in 1..=nr {
                let want = 1e6 + 1000.0 * i as f64 + 10.0 * p as f64 + c as f64;
                assert_eq!(
                    b.phi_r[(row, i - 1)],
                    want,
                    "rigid mode {i} node {p} comp {c}"
                );
            }
            for j in 1..=nl {
                let want = 2e6 + 1000.0 * j as f64 + 10.0 * p as f64 + c as f64;
                assert_eq!(
                    b.phi_l[(row, j - 1)],
                    want,
                    "local mode {j} node {p} comp {c}"
                );
            }
        }
    }
    for j in 1..=nl {
        assert_eq!(b.m_l[j - 1], 30.0 + j as f64);
    }
    for r in 1..=nl {
        for c in 1..=nl {
            let (lo, hi) = (r.min(c), r.max(c));
            let want = if lo <= ns {
                900.0 + k_full_index(lo, hi, nl) as f64
            } else if r == c {
                800.0 + (r - ns) as f64
            } else {
                0.0
            };
            assert_eq!(b.k_l[(r - 1, c - 1)], want, "K_L({r},{c})");
        }
    }
    for i in 1..=nr {
        for j in 1..=nr {
            let want = 1100.0 + m_r_index(i.min(j), i.max(j), nr) as f64;
            assert_eq!(b.m_r[(i - 1, j - 1)], want, "M_R({i},{j})");
        }
    }
    for m in 1..=9 {
        for i in 1..=nr {
            for j in 1..=nl {
                let tail = 10000.0 * m as f64 + 100.0 * i as f64 + j as f64;
                assert_eq!(
                    b.m_c[m - 1][(i - 1, j - 1)],
                    12e6 + tail,
                    "M_C sub {m} ({i},{j})"
                );
                assert_eq!(
                    b.k_c[m - 1][(i - 1, j - 1)],
                    13e6 + tail,
                    "K_C sub {m} ({i},{j})"
                );
            }
        }
    }
}

#[test]
fn placement_irot_damped_two_static_modes() {
    check_labelled("labels_r1_d1_ns2.fxb", 15, 3, 2, &[101, 102]);
    // The same facts written out by hand for this file (nL = 3, nS = 2).
    let b = BodyParts::assemble(&read("labels_r1_d1_ns2.fxb"), "labels_r1_d1_ns2.fxb").unwrap();
    let k = [
        [901.0, 902.0, 903.0],
        [902.0, 904.0, 905.0],
        [903.0, 905.0, 801.0],
    ];
    for (r, row) in k.iter().enumerate() {
        for (c, &v) in row.iter().enumerate() {
            assert_eq!(b.k_l[(r, c)], v);
        }
    }
    assert_eq!(
        b.m_c[4][(1, 0)],
        12_050_201.0,
        "M_C sub-block 5 entry (2,1)"
    );
    assert_eq!(b.m_r[(1, 0)], 1102.0, "M_R(2,1) = value 2 of block 11");
    assert_eq!(b.m_r[(1, 1)], 1116.0, "M_R(2,2) = value 16 of block 11");
    assert_eq!(
        b.phi_r[(6 + 5, 14)],
        1_015_026.0,
        "rigid mode 15, node 2, ZZ"
    );
    assert_eq!(b.damping.map(|d| (d.alpha, d.beta)), Some((4.5, 0.25)));
    assert!(b.ifile);
}

#[test]
fn placement_no_rotation_one_static_mode() {
    check_labelled("labels_r0_d0_ns1.fxb", 12, 2, 1, &[5, 6, 7]);
    let b = BodyParts::assemble(&read("labels_r0_d0_ns1.fxb"), "labels_r0_d0_ns1.fxb").unwrap();
    assert_eq!(b.k_l[(0, 1)], 902.0);
    assert_eq!(b.k_l[(1, 1)], 801.0);
    assert!(b.damping.is_none());
}

/// Design values of tests/data/make_data.py: eigenfrequencies 3, 7, 12.5 Hz, masses
/// summing to 5 kg, rotations only at the first two nodes.
#[test]
fn every_flag_combination() {
    for iblo in [false, true] {
        for irot in [false, true] {
            for idamp in [false, true] {
                let name = format!(
                    "body_b{}_r{}_d{}.fxb",
                    u8::from(iblo),
                    u8::from(irot),
                    u8::from(idamp)
                );
                let f = read(&name);
                assert_eq!((f.iblo, f.irot, f.idamp), (iblo, irot, idamp), "{name}");
                let ns = if (u8::from(iblo) + u8::from(irot) + u8::from(idamp)) % 2 == 1 {
                    2
                } else {
                    0
                };
                assert_eq!(f.nbstat, ns, "{name}");
                let b = Body::from_fxb(&f, &name).unwrap_or_else(|e| panic!("{e}"));
                assert!(b.warnings().is_empty(), "{name}: {:?}", b.warnings());
                assert_eq!(
                    b.nr(),
                    if iblo {
                        0
                    } else if irot {
                        15
                    } else {
                        12
                    }
                );
                for (got, want) in b.frequencies_hz().iter().zip([3.0, 7.0, 12.5]) {
                    assert!((got - want).abs() < 1e-8 * want, "{name}: {got} vs {want}");
                }
                match b.total_mass() {
                    Some(m) => {
                        assert!(!iblo);
                        assert!((m - 5.0).abs() < 1e-8, "{name}: mass {m}");
                    }
                    None => assert!(iblo, "{name}: free body without mass"),
                }
                let damping = b.damping().map(|d| (d.alpha, d.beta));
                assert_eq!(damping, idamp.then_some((0.8, 2.0e-4)), "{name}");
                for k in 0..4 {
                    assert_eq!(b.node_has_rotation(k), irot && k < 2, "{name} node {k}");
                }
                assert!(!b.node_has_rotation(4));
            }
        }
    }
}

#[test]
fn fixed_tabs_and_d_exponent_variants_read_the_same_numbers() {
    let fixed = read("fmt_fixed.fxb");
    assert_eq!(read("fmt_tabs.fxb"), fixed);
    assert_eq!(read("fmt_dexp.fxb"), fixed);
    let text = std::fs::read(data("fmt_fixed.fxb")).unwrap();
    let bom = [b"\xEF\xBB\xBF".as_slice(), &text].concat();
    assert_eq!(
        fxb::parse(&bom, "bom.fxb").unwrap(),
        fixed,
        "a byte-order mark is skipped"
    );
    assert_eq!(fixed.node_ids, vec![7, 9]);
    assert!(fixed.iblo && fixed.irot && fixed.idamp && fixed.ifile);
    assert_eq!(fixed.damping, Some((0.5, 1.0e-4)));
    let b = Body::from_fxb(&fixed, "fmt_fixed.fxb").unwrap();
    // Mode 1, node 9 (second node): Y = -12.5 touches the X before it; ZZ = -0.5.
    assert_eq!(b.phi_l()[(6 + 1, 0)], -12.5);
    assert_eq!(b.phi_l()[(6 + 5, 0)], -0.5);
    assert_eq!(b.phi_l()[(6 + 2, 1)], 1.0e-3);
    assert_eq!(b.phi_l()[(6 + 3, 1)], 2.5);
    assert_eq!(b.phi_l().iter().filter(|v| **v != 0.0).count(), 4);
    assert_eq!(b.k_l()[(0, 1)], -100.0);
    assert_eq!(b.k_l()[(1, 0)], -100.0);
    assert_eq!((b.k_l()[(0, 0)], b.k_l()[(1, 1)]), (800.0, 450.0));
    // det(K - lambda diag(2, 0.5)) = lambda^2 - 1300 lambda + 350000 = 0.
    let two_pi = 2.0 * std::f64::consts::PI;
    let root = 290_000f64.sqrt();
    let want = [
        ((1300.0 - root) / 2.0).sqrt() / two_pi,
        ((1300.0 + root) / 2.0).sqrt() / two_pi,
    ];
    for (got, want) in b.frequencies_hz().iter().zip(want) {
        assert!((got - want).abs() < 1e-12 * want, "{got} vs {want}");
    }
    assert!(b.warnings().is_empty());
    assert!(b.node_has_rotation(1) && !b.node_has_rotation(0));
}

#[test]
fn coordinates_from_a_node_deck_and_from_csv() {
    use fxbody::fxb::coords;
    let deck = coords::read_coords(&data("nodes.rad")).unwrap_or_else(|e| panic!("{e}"));
    let want = vec![
        (11, [0.0, 0.0, 0.0]),
        (12, [2.0, 0.0, 0.0]),
        (13, [0.0, 1.0, 0.0]),
        (14, [0.5, 0.5, 1.5]),
        (15, [-1.25e-3, 3.0, 1.0e10]),
    ];
    assert_eq!(deck, want);
    let csv = coords::read_coords(&data("nodes.csv")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(csv, want);
    assert_eq!(coords::to_map(&csv)[&14], [0.5, 0.5, 1.5]);
}

#[test]
fn coordinate_errors_name_file_and_line() {
    use fxbody::fxb::coords::{parse_csv, parse_node_deck};
    let dup = "/NODE\n        11                 0.0                 0.0                 0.0\n11 1.0 2.0 3.0\n";
    let e = parse_node_deck(dup.as_bytes(), "d.rad")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("d.rad:3:") && e.contains("duplicate node ID 11") && e.contains("line 2"),
        "{e}"
    );
    let bad = "/NODE\n11 1.0 2.0\n";
    let e = parse_node_deck(bad.as_bytes(), "d.rad")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("d.rad:2:") && e.contains("cannot read a node line"),
        "{e}"
    );
    let amb = "/NODE\n1 2 3 4\n";
    let e = parse_node_deck(amb.as_bytes(), "d.rad")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("d.rad:2:") && e.contains("ambiguous"), "{e}");
    let e = parse_node_deck(b"/PART\n1 2 3 4\n", "d.rad")
        .unwrap_err()
        .to_string();
    assert!(e.contains("no nodes"), "{e}");
    let e = parse_csv(b"id,x,y,z\n1,2,3,4\n2,x,3,4\n", "c.csv")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("c.csv:3:") && e.contains("id,x,y,z"), "{e}");
}
