//! write(read(f)) over every .fxb file in tests/data and fixtures/: the text reads back to
//! the same numbers within the printed precision (10 significant digits), a second write
//! gives identical text, and the data lines of a hand-written Radioss-layout file come
//! out unchanged.

use crate::common::fxb_files::fxb_files;
use std::path::Path;

use fxbody::fxb::{self, FxbFile};

fn values(f: &FxbFile) -> Vec<f64> {
    let mut v = f.p0.to_vec();
    v.push(f.freq);
    if let Some((a, b)) = f.damping {
        v.extend([a, b]);
    }
    for block in [
        &f.rigid_modes,
        &f.local_modes,
        &f.m_l,
        &f.k_full,
        &f.k_diag,
        &f.m_r,
        &f.m_c,
        &f.k_c,
    ] {
        v.extend_from_slice(block);
    }
    v
}

#[test]
fn round_trip_every_file() {
    let files = fxb_files();
    assert!(
        files.len() >= 13,
        "tests/data holds 13 .fxb files, found {}",
        files.len()
    );
    for path in files {
        let name = path.display().to_string();
        let f1 = fxb::read_path(&path).unwrap_or_else(|e| panic!("{e}"));
        let t1 = fxb::write(&f1);
        assert_eq!(t1, fxb::write(&f1), "{name}: writing is deterministic");
        let f2 = fxb::parse(&t1, &name).unwrap_or_else(|e| panic!("re-reading {name}: {e}"));
        assert_eq!(
            (
                f1.nbmod, f1.nbstat, f1.nbnod, f1.irot, f1.idamp, f1.iblo, f1.ifile
            ),
            (
                f2.nbmod, f2.nbstat, f2.nbnod, f2.irot, f2.idamp, f2.iblo, f2.ifile
            )
        );
        assert_eq!(f1.node_ids, f2.node_ids);
        let (a, b) = (values(&f1), values(&f2));
        assert_eq!(a.len(), b.len());
        for (k, (x, y)) in a.iter().zip(&b).enumerate() {
            // 1PE16.9 keeps 10 significant digits: relative error <= 5e-10.
            assert!(
                (x - y).abs() <= 5.000001e-10 * x.abs(),
                "{name}: value {k}: {x} vs {y}"
            );
        }
        let t2 = fxb::write(&f2);
        assert_eq!(t1, t2, "{name}: a second round gives identical text");
        assert_eq!(fxb::parse(&t2, &name).unwrap(), f2);
    }
}

#[test]
fn writer_reproduces_a_hand_written_radioss_layout() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fmt_fixed.fxb");
    let original = std::fs::read_to_string(&path).unwrap();
    let written = fxb::write(&fxb::read_path(&path).unwrap());
    let data = |t: &str| -> Vec<String> {
        t.lines()
            .filter(|l| !l.starts_with('#'))
            .map(String::from)
            .collect()
    };
    assert_eq!(data(&written), data(&original));
    // Every block is introduced by a comment line naming it.
    for b in [
        "block 1:",
        "block 2:",
        "block 3:",
        "block 4:",
        "block 7:",
        "block 8:",
        "block 9:",
        "block 10:",
    ] {
        assert!(
            written.contains(&format!("# {b}")),
            "missing comment for {b}"
        );
    }
}

#[test]
fn free_body_layout_has_sub_block_comments_and_two_lines_per_node() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/body_b0_r1_d1.fxb");
    let f = fxb::read_path(&path).unwrap();
    let written = fxb::write(&f);
    for m in 1..=9 {
        let (k, l) = ((m - 1) / 3 + 1, (m - 1) % 3 + 1);
        assert!(written.contains(&format!("# M_C,{k}{l} (sub-block {m})")));
        assert!(written.contains(&format!("# K_C,{k}{l} (sub-block {m})")));
    }
    // Mode lines: 5 fields of 16 then 1 field of 16, alternating, 15 + 3 modes x 4 nodes.
    let data: Vec<&str> = written.lines().filter(|l| !l.starts_with('#')).collect();
    let start = 1 + 1 + 2 + 1; // header, node IDs, frame (2 lines), damping
    for node in 0..(18 * 4) {
        assert_eq!(data[start + 2 * node].len(), 80);
        assert_eq!(data[start + 2 * node + 1].len(), 16);
    }
    // M_R: 120 values = 24 full lines.
    assert_eq!(f.m_r.len(), 120);
}

/// A free body with no local modes (Nbmod = 0): blocks 12 and 13 are absent; it reads,
/// validates (mass from M_R alone) and round-trips.
#[test]
fn rigid_only_body_without_local_modes() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/body_b0_r0_d0.fxb");
    let mut f = fxb::read_path(&path).unwrap();
    f.nbmod = 0;
    f.nbstat = 0;
    f.freq = 0.0;
    for v in [
        &mut f.local_modes,
        &mut f.m_l,
        &mut f.k_full,
        &mut f.k_diag,
        &mut f.m_c,
        &mut f.k_c,
    ] {
        v.clear();
    }
    let text = fxb::write(&f);
    assert!(!text.contains("block 12") && !text.contains("block 13"));
    let back = fxb::parse(&text, "rigid.fxb").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(back, f);
    let b = fxbody::body::Body::from_fxb(&back, "rigid.fxb").unwrap();
    assert!(b.frequencies_hz().is_empty());
    assert!((b.total_mass().unwrap() - 5.0).abs() < 1e-8);
    // Data left over where blocks 12-13 would be is an error, not silently ignored.
    let extra = format!("{text} 1.000000000E+00\n");
    let e = fxb::parse(&extra, "rigid.fxb").unwrap_err().to_string();
    assert!(
        e.contains("block 11") && e.contains("data after the last block"),
        "{e}"
    );
}
