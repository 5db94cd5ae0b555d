//! C masters (tests/c/fmu_driver.c for FMI 2.0, tests/c/fmu3_driver.c for FMI 3.0)
//! include include/fxbody.h, load a packed FMU's library, run 1,000 steps of a held tip
//! load, and print the tip's y. The FMI 2.0 driver's result must equal the Rust solver
//! driven directly over the same scene; the FMI 3.0 driver's, on the same body packed
//! with `--fmi 3`, must equal the FMI 2.0 driver's bit for bit (one library, the same
//! method) and so the Rust solver as well.

use crate::common::c_build;
use crate::common::fmu::{unpack_as, unpack_tip};

use std::path::Path;
use std::process::Command;

use fxbody::fmu::fmi_version::FmiVersion;
use fxbody::fmu::pack::Prepared;
use fxbody::scene::io::load_resources;
use fxbody::solver::{self, Method, Options};

const H: f64 = 2e-4;
const STEPS: usize = 1000;
const FORCE: f64 = 1.0;

/// Build the C program `source` under `tmp` and run it on the unpacked FMU (`p`, its
/// library `so`), resources passed as `resources` (a URI for FMI 2.0, a path for 3.0):
/// the tip's y it prints.
fn run_driver(source: &str, tmp: &Path, p: &Prepared, so: &Path, resources: &str) -> f64 {
    let exe = tmp.join(source.trim_end_matches(".c"));
    c_build::compile_c_master(source, &exe, &["-O2"]);
    let vr = |n: &str| {
        p.table
            .vars
            .iter()
            .find(|v| v.name == n)
            .unwrap()
            .vr
            .to_string()
    };
    let out = Command::new(&exe)
        .arg(so)
        .arg(resources)
        .arg(&p.guid)
        .args([
            vr("node_121.fy"),
            vr("node_121.y"),
            STEPS.to_string(),
            H.to_string(),
            FORCE.to_string(),
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{source} failed: {}{}",
        stdout,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout.trim().parse().unwrap()
}

/// The same scene and steps through the Rust API directly: the exact method, the load
/// held. Returns the tip's y.
fn rust_reference(resources: &Path) -> f64 {
    let res = load_resources(resources).unwrap();
    let mut s = solver::build(&res.scene, Method::Exact, &Options::default()).unwrap();
    let mut loads = [0.0; 6];
    loads[1] = FORCE;
    for _ in 0..STEPS {
        s.set_loads(&loads).unwrap();
        s.set_load_rates(&[0.0; 6]).unwrap();
        s.step(H).unwrap();
    }
    let mut pos = [0.0; 3];
    s.positions(&mut pos);
    assert!(pos[1].abs() > 1e-5, "a real deflection: {}", pos[1]);
    pos[1]
}

#[test]
fn c_master_matches_the_rust_solver() {
    let tmp = std::env::temp_dir().join(format!("fxbody_c_{}", std::process::id()));
    let unz = tmp.join("unz");
    let (p, so) = unpack_tip(&unz);
    let uri = fxbody_host::file_uri(&unz.join("resources"));
    let y_c = run_driver("fmu_driver.c", &tmp, &p, &so, &uri);
    let y = rust_reference(&unz.join("resources"));
    assert!((y_c - y).abs() <= 1e-12 * y.abs(), "C {y_c} vs Rust {y}");
    let _ = std::fs::remove_dir_all(&tmp);
}

/// FMI 3.0 from C: the same body packed with `--fmi 3`, driven by fmu3_driver.c
/// (instantiate, an illegal step refused and reset, initialise, 1,000 x set and step
/// with the step flags checked, get), against fmu_driver.c on the FMI 2.0 FMU: equal
/// bit for bit, and both at the Rust solver's value to 1e-12.
#[test]
fn c_master_fmi3_equals_the_fmi2_driver() {
    let tmp = std::env::temp_dir().join(format!("fxbody_c3_{}", std::process::id()));
    let (unz2, unz3) = (tmp.join("unz2"), tmp.join("unz3"));
    let (p2, so2) = unpack_tip(&unz2);
    let (p3, so3) = unpack_as(&unz3, "cantilever", 121, None, FmiVersion::Fmi3);
    let uri = fxbody_host::file_uri(&unz2.join("resources"));
    let y2 = run_driver("fmu_driver.c", &tmp, &p2, &so2, &uri);
    let path = format!("{}/", unz3.join("resources").display());
    let y3 = run_driver("fmu3_driver.c", &tmp, &p3, &so3, &path);
    println!("tip y after {STEPS} steps: FMI 3.0 C driver {y3:e}, FMI 2.0 C driver {y2:e}");
    assert_eq!(
        y3.to_bits(),
        y2.to_bits(),
        "FMI 3.0 {y3:e} vs FMI 2.0 {y2:e}"
    );
    let y = rust_reference(&unz3.join("resources"));
    assert!((y3 - y).abs() <= 1e-12 * y.abs(), "C {y3} vs Rust {y}");
    let _ = std::fs::remove_dir_all(&tmp);
}
