//! A C program (tests/c/fmu_driver.c) includes include/fxbody.h, loads a packed FMU's
//! library, runs 1,000 steps of a held tip load, and its result must equal the Rust
//! solver driven directly over the same scene.

use crate::common::c_build;
use crate::common::fmu::unpack_tip;

use std::process::Command;

use fxbody::scene::io::load_resources;
use fxbody::solver::{self, Method, Options};

#[test]
fn c_master_matches_the_rust_solver() {
    let tmp = std::env::temp_dir().join(format!("fxbody_c_{}", std::process::id()));
    let unz = tmp.join("unz");
    let (p, so) = unpack_tip(&unz);
    let exe = tmp.join("driver");
    c_build::compile_c_master("fmu_driver.c", &exe, &["-O2"]);
    let vr = |n: &str| {
        p.table
            .vars
            .iter()
            .find(|v| v.name == n)
            .unwrap()
            .vr
            .to_string()
    };
    let (h, steps, force) = (2e-4, 1000, 1.0);
    let out = Command::new(&exe)
        .arg(&so)
        .arg(fxbody_host::file_uri(&unz.join("resources")))
        .arg(&p.guid)
        .args([
            vr("node_121.fy"),
            vr("node_121.y"),
            steps.to_string(),
            h.to_string(),
            force.to_string(),
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "driver failed: {}{}",
        stdout,
        String::from_utf8_lossy(&out.stderr)
    );
    let y_c: f64 = stdout.trim().parse().unwrap();
    // The same scene and steps through the Rust API directly.
    let res = load_resources(&unz.join("resources")).unwrap();
    let mut s = solver::build(&res.scene, Method::Exact, &Options::default()).unwrap();
    let mut loads = [0.0; 6];
    loads[1] = force;
    for _ in 0..steps {
        s.set_loads(&loads).unwrap();
        s.set_load_rates(&[0.0; 6]).unwrap();
        s.step(h).unwrap();
    }
    let mut pos = [0.0; 3];
    s.positions(&mut pos);
    assert!(pos[1].abs() > 1e-5, "a real deflection: {}", pos[1]);
    assert!(
        (y_c - pos[1]).abs() <= 1e-12 * pos[1].abs(),
        "C {y_c} vs Rust {}",
        pos[1]
    );
    let _ = std::fs::remove_dir_all(&tmp);
}
