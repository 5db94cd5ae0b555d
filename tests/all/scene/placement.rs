//! Issue 13 class 4: a free body's rigid modes fix every node relative to the frame
//! origin L0, so a coordinate file only places the body. Positions are computed here
//! independently from the rigid-mode rows (modes 1, 4, 7 hold X, Y, Z on the x row) and
//! P0, and the packed scene and the FMU's reloaded scene are checked against them.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::root;

use fxbody::fmu::pack::{PackNote, PackOptions, PackRequest, prepare, resource_entries};
use fxbody::fxb;
use fxbody::scene::io::{SCENE_FILE, load_resources};

const BODY: &str = "body_b0_r1_d0.fxb";

fn data(name: &str) -> PathBuf {
    root().join("tests/data").join(name)
}

fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("fxb_place_{tag}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// (id, global position with L0 at 0) from the raw file: P0 times the x rows of rigid
/// modes 1, 4 and 7 (the file's own storage order: mode, node, component).
fn positions_from_file() -> Vec<(i64, [f64; 3])> {
    let f = fxb::read_path(&data(BODY)).unwrap();
    let n = f.nbnod;
    let at = |mode: usize, node: usize| f.rigid_modes[mode * 6 * n + 6 * node];
    (0..n)
        .map(|k| {
            let l = [at(0, k), at(3, k), at(6, k)];
            let p = &f.p0; // row-major
            let g = [0, 1, 2].map(|r| (0..3).map(|c| p[3 * r + c] * l[c]).sum::<f64>());
            (f.node_ids[k], g)
        })
        .collect()
}

/// Write `positions` mapped by `f` as a CSV and return its path.
fn csv(dir: &Path, name: &str, f: impl Fn([f64; 3]) -> [f64; 3]) -> PathBuf {
    let mut s = String::from("id,x,y,z\n");
    for (id, x) in positions_from_file() {
        let y = f(x);
        s.push_str(&format!("{id},{:?},{:?},{:?}\n", y[0], y[1], y[2]));
    }
    let p = dir.join(name);
    std::fs::write(&p, s).unwrap();
    p
}

fn request(coords: Option<PathBuf>) -> PackRequest {
    PackRequest {
        body: data(BODY),
        coords,
        ..Default::default()
    }
}

#[test]
fn doubled_deck_is_refused_with_the_worst_node() {
    let d = scratch("double");
    let c = csv(&d, "double.csv", |x| x.map(|v| 2.0 * v));
    let e = prepare(&request(Some(c.clone())), &PackOptions::default(), None)
        .err()
        .unwrap()
        .to_string();
    // With L0 placed at the mean offset (the centroid), the worst node is the one
    // farthest from the centroid of the derived positions.
    let pos = positions_from_file();
    let k = pos.len() as f64;
    let cen = [0, 1, 2].map(|c| pos.iter().map(|p| p.1[c]).sum::<f64>() / k);
    let dist = |x: [f64; 3]| (0..3).map(|c| (x[c] - cen[c]).powi(2)).sum::<f64>();
    let worst = pos
        .iter()
        .max_by(|a, b| dist(a.1).total_cmp(&dist(b.1)))
        .unwrap();
    assert!(
        e.starts_with(&format!("{}: node {} is at (", c.display(), worst.0)),
        "{e}"
    );
    assert!(e.contains("more than 1e-6 of the body's size"), "{e}");
    assert!(e.contains("about 2 times the body's"), "{e}");
    assert!(!e.contains("units?"), "{e}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn deck_in_mm_for_a_body_in_m_gets_a_units_hint() {
    let d = scratch("mm");
    let c = csv(&d, "mm.csv", |x| x.map(|v| 1000.0 * v + 5.0));
    let e = prepare(&request(Some(c)), &PackOptions::default(), None)
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("units? the file's coordinates are 1000 times the body's"),
        "{e}"
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn shifted_deck_places_the_origin_and_the_fmu_keeps_deck_positions() {
    let d = scratch("shift");
    let shift = [10.0, -3.0, 0.5];
    let c = csv(&d, "shift.csv", |x| {
        [x[0] + shift[0], x[1] + shift[1], x[2] + shift[2]]
    });
    let p = prepare(&request(Some(c.clone())), &PackOptions::default(), None).unwrap();
    assert!(
        p.notes
            .iter()
            .any(|n| matches!(n, PackNote::OriginPlaced { coords, origin }
            if *coords == c && (0..3).all(|k| (origin[k] - shift[k]).abs() < 1e-9))),
        "{:?}",
        p.notes
    );
    // The FMU reads resources/ back: write them and reload as an instance does.
    let res = d.join("resources");
    std::fs::create_dir_all(&res).unwrap();
    for e in resource_entries(&p) {
        std::fs::write(d.join(&e.name), &e.data).unwrap();
    }
    let r = load_resources(&res).unwrap();
    assert_eq!(r.guid, p.guid);
    let want = positions_from_file();
    for scene in [&p.scene, &r.scene] {
        assert_eq!(scene.nodes.len(), want.len());
        for (k, &n) in scene.nodes.iter().enumerate() {
            let (id, x) = want[n];
            assert_eq!(scene.body.node_ids()[n], id);
            for c in 0..3 {
                assert!(
                    (scene.x0[k][c] - (x[c] + shift[c])).abs() < 1e-9,
                    "node {id}"
                );
            }
        }
    }
    // A tampered scene file inside the FMU is refused at load too (the coordinates are
    // in it since issue 16; the checksum catches any change). The last coordinate of
    // the NODE section (the 2nd section, after BODY's 16 + 152 bytes) moved by 1.
    let mut bad = p.scene_file.clone();
    let m = p.scene.nodes.len();
    let at = 32 + 16 + 152 + 16 + 8 * m + 8 * (3 * m - 1);
    let x = f64::from_le_bytes(bad[at..at + 8].try_into().unwrap());
    bad[at..at + 8].copy_from_slice(&(x + 1.0).to_le_bytes());
    std::fs::write(res.join(SCENE_FILE), bad).unwrap();
    let e = load_resources(&res).err().unwrap().to_string();
    assert!(e.contains("scene.fxs: checksum mismatch"), "{e}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn free_body_without_coords_has_its_origin_at_zero_and_info_says_so() {
    let p = prepare(&request(None), &PackOptions::default(), None).unwrap();
    assert!(p.notes.contains(&PackNote::CoordsDerived));
    let want = positions_from_file();
    for (k, &n) in p.scene.nodes.iter().enumerate() {
        for c in 0..3 {
            assert!((p.scene.x0[k][c] - want[n].1[c]).abs() < 1e-12);
        }
    }
    let out = Command::new(fxbody_host::workspace_binary("fxbody"))
        .args(["info", data(BODY).to_str().unwrap()])
        .output()
        .unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains(
            "`pack` without --coords puts L0 at (0, 0, 0), a --coords file only places L0"
        ),
        "{text}"
    );
}
