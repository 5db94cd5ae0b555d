//! One test per reader error kind: each breaks the hand-written tests/data/fmt_fixed.fxb
//! (or another data file) at a known line and checks that the message names that line,
//! the right block, and what was expected.

use std::path::Path;

use fxbody::fxb::{self, FxbError};

fn base() -> Vec<String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fmt_fixed.fxb");
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(String::from)
        .collect()
}

/// fmt_fixed.fxb with 1-based line `n` replaced.
fn with_line(n: usize, text: &str) -> String {
    let mut l = base();
    l[n - 1] = text.to_string();
    l.join("\n") + "\n"
}

fn err(text: &str) -> (FxbError, String) {
    let e = fxb::parse(text, "t.fxb").expect_err("the text must be refused");
    let msg = e.to_string();
    (e, msg)
}

fn assert_names(msg: &str, line: usize, block: &str, words: &[&str]) {
    let prefix = format!("t.fxb:{line}: {block}");
    assert!(
        msg.starts_with(&prefix),
        "expected prefix '{prefix}' in: {msg}"
    );
    for w in words {
        assert!(msg.contains(w), "expected '{w}' in: {msg}");
    }
}

#[test]
fn the_base_file_reads() {
    assert!(fxb::parse(base().join("\n"), "t.fxb").is_ok());
}

#[test]
fn unexpected_end_of_file() {
    let l = base();
    let (e, msg) = err(&(l[..19].join("\n") + "\n"));
    assert!(matches!(e, FxbError::UnexpectedEof { .. }));
    assert_names(
        &msg,
        19,
        "block 10 (local stiffness K_L, diagonal part)",
        &["unexpected end of file", "expected 1 more value(s)"],
    );
}

#[test]
fn unparsable_field() {
    let (e, msg) = err(&with_line(18, " 2.0000x0000E+00 5.000000000E-01"));
    assert!(matches!(e, FxbError::Unparsable { .. }));
    assert_names(
        &msg,
        18,
        "block 8 (local mass m_L)",
        &["columns 1-16", "2.0000x0000E+00", "a real number"],
    );
}

#[test]
fn non_utf8_bytes_are_an_unparsable_field() {
    let mut bytes = with_line(
        8,
        " 0.000000000E+00 0.000000000E+00 0.000000000E+00 1.000000000E+00 4.8254XX972E+00",
    )
    .into_bytes();
    let p = bytes.windows(2).position(|w| w == b"XX").unwrap();
    bytes[p] = 0xff;
    bytes[p + 1] = 0xfe;
    let e = fxb::parse(&bytes, "t.fxb").unwrap_err();
    assert!(matches!(e, FxbError::Unparsable { .. }));
    assert_names(
        &e.to_string(),
        8,
        "block 3 (initial frame P0 and Freq)",
        &["columns 65-80"],
    );
    // Non-UTF-8 bytes in a comment are harmless.
    let mut ok = base().join("\n").into_bytes();
    ok[2] = 0xe9;
    assert!(fxb::parse(&ok, "t.fxb").is_ok());
}

#[test]
fn short_line_inside_a_block() {
    let (e, msg) = err(&with_line(
        7,
        " 1.000000000E+00 0.000000000E+00 0.000000000E+00 0.000000000E+00",
    ));
    assert!(matches!(
        e,
        FxbError::ShortLine {
            expected: 5,
            found: 4,
            ..
        }
    ));
    assert_names(
        &msg,
        7,
        "block 3 (initial frame P0 and Freq)",
        &["short line", "expected 5", "found 4"],
    );
}

#[test]
fn short_mode_line_names_mode_and_node() {
    let (e, msg) = err(&with_line(
        12,
        " 0.000000000E+00-1.250000000E+01 0.000000000E+00 0.000000000E+00",
    ));
    assert!(matches!(e, FxbError::ShortLine { .. }));
    assert_names(
        &msg,
        12,
        "block 7 (local modes)",
        &["local mode 1, node 9 (node 2 of 2)", "X Y Z XX YY"],
    );
}

#[test]
fn too_many_values_on_a_mode_line() {
    // Six values on one line: the ZZ of a node belongs on its own line.
    let (e, msg) = err(&with_line(
        10,
        " 0.000000000E+00 0.000000000E+00 0.000000000E+00 0.000000000E+00 0.000000000E+00 0.000000000E+00",
    ));
    // Fixed columns stop at 100, so the fixed reading sees 6 values as well.
    assert!(
        matches!(
            e,
            FxbError::TooManyValues {
                expected: 5,
                found: 6,
                ..
            }
        ),
        "{msg}"
    );
    assert_names(&msg, 10, "block 7 (local modes)", &["local mode 1, node 7"]);
}

#[test]
fn negative_count() {
    let (e, msg) = err(&with_line(
        5,
        "       2       1      -2       1       1       1       1",
    ));
    assert!(matches!(
        e,
        FxbError::NegativeCount {
            name: "Nbnod",
            found: -2,
            ..
        }
    ));
    assert_names(
        &msg,
        5,
        "block 1 (general data",
        &["Nbnod must be a count >= 0, found -2"],
    );
}

#[test]
fn flag_not_zero_or_one() {
    let (e, msg) = err(&with_line(
        5,
        "       2       1       2       1       1       2       1",
    ));
    assert!(matches!(
        e,
        FxbError::BadFlag {
            name: "Iblo",
            found: 2,
            ..
        }
    ));
    assert_names(
        &msg,
        5,
        "block 1 (general data",
        &["Iblo must be 0 or 1, found 2"],
    );
}

#[test]
fn nbstat_greater_than_nbmod() {
    let (e, msg) = err(&with_line(
        5,
        "       2       3       2       1       1       1       1",
    ));
    assert!(matches!(
        e,
        FxbError::NbstatExceedsNbmod {
            nbstat: 3,
            nbmod: 2,
            ..
        }
    ));
    assert_names(
        &msg,
        5,
        "block 1 (general data",
        &["expected Nbstat <= 2, found Nbstat = 3"],
    );
}

#[test]
fn duplicate_node_ids() {
    let (e, msg) = err(&with_line(6, "       7       7"));
    assert!(matches!(
        e,
        FxbError::DuplicateNodeId {
            id: 7,
            first_line: 6,
            ..
        }
    ));
    assert_names(&msg, 6, "block 2 (node IDs)", &["duplicate node ID 7"]);
}

#[test]
fn non_positive_node_id() {
    let (e, msg) = err(&with_line(6, "       0       9"));
    assert!(matches!(e, FxbError::BadNodeId { id: 0, .. }));
    assert_names(
        &msg,
        6,
        "block 2 (node IDs)",
        &["node ID must be > 0, found 0"],
    );
}

#[test]
fn data_after_the_last_block() {
    let text = base().join("\n") + "\n# fine\n 1.000000000E+00\n";
    let (e, msg) = err(&text);
    assert!(matches!(e, FxbError::TrailingData { .. }));
    assert_names(
        &msg,
        22,
        "block 10",
        &[
            "data after the last block",
            "expected end of file",
            "1.000000000E+00",
        ],
    );
}

#[test]
fn ambiguous_line() {
    // Fixed columns read "5 1" as 51; blank-separated as 5 and 1.
    let (e, msg) = err(&with_line(9, "5 1"));
    assert!(matches!(e, FxbError::Ambiguous { .. }));
    assert_names(
        &msg,
        9,
        "block 4 (Rayleigh damping)",
        &["ambiguous line", "[51]", "[5, 1]"],
    );
    // Integers separated by single blanks in the header are ambiguous too.
    let (e, msg) = err(&with_line(5, "2 1 2 1 1 1 1"));
    assert!(matches!(e, FxbError::Ambiguous { .. }));
    assert_names(
        &msg,
        5,
        "block 1",
        &["[2121, 111]", "[2, 1, 2, 1, 1, 1, 1]"],
    );
}

#[test]
fn sub_block_is_named() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/body_b0_r0_d0.fxb");
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let c = lines
        .iter()
        .position(|l| l == "# block 12 sub-block 5")
        .unwrap();
    lines[c + 1].truncate(64); // 4 of 5 values
    let (e, msg) = err(&lines.join("\n"));
    assert!(matches!(e, FxbError::ShortLine { .. }));
    assert_names(
        &msg,
        c + 2,
        "block 12 (coupled mass M_C), sub-block 5 (M_C,22)",
        &["short line"],
    );
}

#[test]
fn rigid_modes_13_to_15_are_block_6() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/body_b0_r1_d1.fxb");
    let mut lines: Vec<String> = std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    // Rigid modes start after "# blocks 5+6"; mode 13, node 1 starts 12 * 4 * 2 lines later.
    let start = lines.iter().position(|l| l == "# blocks 5+6").unwrap() + 1;
    let line = start + 12 * 4 * 2;
    lines[line].push_str(" 1.0");
    let (_, msg) = err(&lines.join("\n"));
    assert_names(
        &msg,
        line + 1,
        "block 6 (rotational rigid modes 13-15)",
        &["rigid mode 13, node 11"],
    );
}

#[test]
fn header_claiming_a_billion_nodes_fails_at_once() {
    // 1000000000 does not fit an 8-column field: written blank-separated, as a user would.
    let mut text = String::from("0 0 1000000000 0 0 1 0\n");
    while text.len() < 300 {
        text.push_str(" 1.000000000E+00\n");
    }
    let (e, msg) = err(&text);
    assert!(matches!(e, FxbError::TooLarge { .. }), "{msg}");
    assert_names(
        &msg,
        1,
        "block 1",
        &["Nbnod = 1000000000", "bytes remain", "also ambiguous"],
    );
    // In 8-column fields, the largest count there is.
    let text = format!(
        "{:>8}{:>8}{:>8}       1       0       0       0\n",
        1, 0, 9_999_999
    );
    let (e, msg) = err(&text);
    assert!(matches!(e, FxbError::TooLarge { .. }), "{msg}");
    assert_names(
        &msg,
        1,
        "block 1",
        &["Nbnod = 9999999", "needs at least 970000305 more values"],
    );
    // N + 10 + (nR + nL) 6 N + 2 nL + nR (nR + 1) / 2 + 18 nR nL with N = 9999999, nL = 1, nR = 15.
    // Counts whose products overflow 64 bits are refused the same way.
    let text = "+99999999 +0 +99999999999999 +0 +0 +0 +0\n";
    let (e, msg) = err(text);
    assert!(matches!(e, FxbError::TooLarge { .. }), "{msg}");
}

#[test]
fn io_error_names_the_file() {
    let e = fxb::read_path(Path::new("/nonexistent/dir/x.fxb")).unwrap_err();
    assert!(matches!(e, FxbError::Io { .. }));
    assert!(
        e.to_string()
            .starts_with("/nonexistent/dir/x.fxb: cannot read the body file"),
        "{e}"
    );
}

#[test]
fn non_finite_and_huge_numbers_are_refused() {
    for bad in [
        "             NaN",
        "        Infinity",
        "         1.0E400",
        "         1.0+999",
    ] {
        let line = format!(" 0.000000000E+00 0.000000000E+00 0.000000000E+00 1.000000000E+00{bad}");
        let (e, msg) = err(&with_line(8, &line));
        assert!(matches!(e, FxbError::Unparsable { .. }), "{bad}: {msg}");
        assert_names(&msg, 8, "block 3", &["columns 65-80"]);
    }
}
