//! The careless C master (tests/c/robust_driver.c) against a packed FMU: every misuse it
//! makes is refused, the run completes, and its result equals the Rust solver driven
//! directly with the same loads (the misuse changed nothing). When valgrind is on PATH,
//! a short pass runs under memcheck too: no invalid access, no definite or indirect
//! leak (scripts/robust-long.sh runs the long one).
#![cfg(target_os = "linux")]

use crate::common::c_build;

use std::process::Command;

use crate::common::fmu::{H, packed};

#[test]
fn careless_c_master_and_short_valgrind_pass() {
    let fx = packed("cdriver");
    let exe = fx.dir.join("robust_driver");
    c_build::compile_c_master("robust_driver.c", &exe, &["-g", "-O1"]);
    let args = |steps: usize| {
        vec![
            fx.so.display().to_string(),
            fx.uri.clone(),
            fx.p.guid.clone(),
            fx.vr("node_121.fy").to_string(),
            fx.vr("node_121.y").to_string(),
            steps.to_string(),
        ]
    };
    let steps = 2000;
    let out = Command::new(&exe).args(args(steps)).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "driver: {text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let y_c: f64 = text.lines().nth(1).unwrap().trim().parse().unwrap();
    let checks: usize = text.split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!(checks > 10_000, "{text}");

    // Reference: the Rust solver over the same scene with the driver's loads (input
    // rates included: the driver sets d/dt of the load each step).
    let res = fxbody::fmu::scene_io::load_resources(&fx.dir.join("resources")).unwrap();
    let method = fx.p.table.default_method;
    let mut s =
        fxbody::solver::build(&res.scene, method, &fxbody::solver::Options::default()).unwrap();
    let (mut loads, mut rates) = ([0.0; 6], [0.0; 6]);
    for k in 0..steps {
        let t = k as f64 * H;
        loads[1] = (300.0 * t).sin() + if k % 50 == 0 { 0.5 } else { 0.0 };
        rates[1] = 300.0 * (300.0 * t).cos();
        s.set_loads(&loads).unwrap();
        s.set_load_rates(&rates).unwrap();
        s.step(H).unwrap();
    }
    let mut pos = [0.0; 3];
    s.positions(&mut pos);
    assert!(pos[1].abs() > 1e-7, "a real deflection {}", pos[1]);
    assert!(
        (y_c - pos[1]).abs() <= 1e-12 * pos[1].abs(),
        "C {y_c} vs Rust {}",
        pos[1]
    );

    // The short memcheck pass, if valgrind is here.
    let Ok(v) = Command::new("valgrind").arg("--version").output() else {
        println!("valgrind not found: memcheck pass skipped (scripts/robust-long.sh)");
        return;
    };
    assert!(v.status.success());
    let log = fx.dir.join("memcheck.log");
    let out = Command::new("valgrind")
        .args([
            "-q",
            "--error-exitcode=99",
            "--leak-check=full",
            "--show-leak-kinds=definite,indirect",
            "--errors-for-leak-kinds=definite,indirect",
        ])
        .arg(format!("--log-file={}", log.display()))
        .arg(&exe)
        .args(args(100))
        .output()
        .unwrap();
    let report = std::fs::read_to_string(&log).unwrap_or_default();
    assert!(
        out.status.success(),
        "memcheck (exit {:?}): {report}{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout)
    );
    println!(
        "C master: {checks} checks; under memcheck (100 steps): clean, {}",
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .next()
            .unwrap_or("")
    );
}
