//! Benchmark of issue 6: cost of one communication step (setReal + doStep + getReal) on
//! a blocked body with 20 modes and 2 exposed nodes, exact method:
//! (a) a C master through the packed FMU's C ABI (tests/c/fmu_driver.c, built here),
//! (b) the Rust solver called directly, (c) the same scene as a numpy loop over the exact
//! discrete state space (what a Python user would write). Prints times and ratios; a
//! speed is never asserted. Run: `cargo bench --bench fmi_step`.
//!
//! The FMI layer's cost is reported as issue 16 defines it: (C master's time per step -
//! solver's own time per step) / solver's own time per step, where the solver's own step
//! is the same load, step and output read called directly in Rust. (a) and (b) run
//! alternately, `ROUNDS` times each, and the best of each is kept, so that a change in
//! the machine's load during the run hits both sides alike.

use std::path::PathBuf;
use std::process::Command;
use std::time::Instant;

use fxbody::fmu::pack::{PackOptions, PackRequest, find_library, pack};
use fxbody::scene::Scene;
use fxbody::scene::io::load_resources;
use fxbody::solver::{self, Method, Options, Solver};

/// Rounds of (a) and (b), alternating.
const ROUNDS: usize = 5;

/// One run of `steps` cycles of the exact solver on `scene` (the bench's load sequence
/// on tip fy, then `read` on the outputs), in ns per cycle. Generic in `read` so that
/// the call is inlined and the timing holds no indirect call; never inlined itself, so
/// that callgrind counts it as one function (see `FXBODY_BENCH_STEPS` below).
#[inline(never)]
fn time_direct(
    scene: &Scene,
    steps: usize,
    h: f64,
    force: f64,
    mut read: impl FnMut(&dyn Solver),
) -> f64 {
    let mut s = solver::build(scene, Method::Exact, &Options::default()).unwrap();
    let mut loads = [0.0; 12];
    let start = Instant::now();
    for k in 0..steps {
        loads[1] = force * (1e-3 * k as f64).sin();
        s.set_loads(&loads).unwrap();
        s.step(h).unwrap();
        read(s.as_ref());
    }
    start.elapsed().as_secs_f64() * 1e9 / steps as f64
}

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let tmp = std::env::temp_dir().join(format!("fxbody_bench_{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let lib = find_library(None).expect("libfxbody.so next to the bench executable");
    let fmu = tmp.join("bench.fmu");
    let req = PackRequest {
        body: root.join("fixtures/cantilever.fxb"),
        coords: Some(root.join("fixtures/cantilever.nodes.rad")),
        nodes: Some(vec![121, 111]),
        name: Some("bench".into()),
        ..PackRequest::default()
    };
    let p = pack(&req, &PackOptions::default(), &lib, &fmu, None).unwrap();
    for (name, data) in fxbody_host::zip::read(&std::fs::read(&fmu).unwrap()).unwrap() {
        let path = tmp.join(&name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, data).unwrap();
    }
    // FXBODY_BENCH_STEPS: fewer steps, for counting instructions under callgrind: the
    // difference between two step counts, per step, of `time_direct` (inclusive) and of
    // the C driver run on the kept folder (FXBODY_BENCH_KEEP) gives the solver's and the
    // FMI layer's instructions per step.
    let steps = std::env::var("FXBODY_BENCH_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000usize);
    let (h, force) = (2e-4, 1.0);
    let vr = |n: &str| {
        p.table
            .vars
            .iter()
            .find(|v| v.name == n)
            .unwrap()
            .vr
            .to_string()
    };

    // (a) C master.
    let exe = tmp.join("driver");
    let cc = Command::new("cc")
        .args(["-O2", "-std=c99", "-D_POSIX_C_SOURCE=200809L", "-I"])
        .arg(root.join("include"))
        .arg(root.join("tests/c/fmu_driver.c"))
        .arg("-o")
        .arg(&exe)
        .args(["-ldl", "-lm"])
        .status()
        .expect("cc");
    assert!(cc.success());
    let run_c = || -> (f64, f64) {
        let out = Command::new(&exe)
            .arg(tmp.join("binaries/linux64/bench.so"))
            .arg(fxbody_host::file_uri(&tmp.join("resources")))
            .arg(&p.guid)
            .args([vr("node_121.fy"), vr("node_121.y")])
            .args([
                steps.to_string(),
                h.to_string(),
                force.to_string(),
                "bench".into(),
            ])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).to_string();
        assert!(
            out.status.success(),
            "{text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let mut lines = text.lines();
        let y = lines.next().unwrap().parse().unwrap();
        let ns = lines
            .next()
            .unwrap()
            .split_whitespace()
            .nth(1)
            .unwrap()
            .parse::<f64>()
            .unwrap();
        (y, ns)
    };

    // (b) The solver directly, same scene and load sequence, alternating with (a).
    let res = load_resources(&tmp.join("resources")).unwrap();
    let (mut c, mut d, mut y_c, mut y_direct) = (f64::INFINITY, f64::INFINITY, 0.0, 0.0);
    for _ in 0..ROUNDS {
        let (y, ns) = run_c();
        (y_c, c) = (y, c.min(ns));
        // The one value the C master reads (tip y).
        let ns = time_direct(&res.scene, steps, h, force, |s| {
            y_direct = s
                .position(1)
                .expect("the exact method gives one position alone");
        });
        d = d.min(ns);
    }
    // (b2) Every output a coupled master usually reads: all positions and velocities of
    // both nodes (12 values).
    let (mut pos, mut vel) = ([0.0; 6], [0.0; 6]);
    let all = (0..3)
        .map(|_| {
            time_direct(&res.scene, steps, h, force, |s| {
                s.positions(&mut pos);
                s.velocities(&mut vel);
            })
        })
        .fold(f64::INFINITY, f64::min);
    std::hint::black_box((pos, vel));

    // (c) numpy, from the body's own matrices (local frame = global: P0 = I here).
    let body = &res.scene.body;
    let row = |node: usize, c: usize| -> Vec<f64> {
        (0..body.nl())
            .map(|j| body.phi_l()[(6 * node + c, j)])
            .collect()
    };
    let n121 = res.scene.nodes[0];
    let k: Vec<Vec<f64>> = (0..body.nl())
        .map(|i| (0..body.nl()).map(|j| body.k_l()[(i, j)]).collect())
        .collect();
    let m: Vec<f64> = body.m_l().iter().copied().collect();
    let json = serde_json::json!({"k_l": k, "m_l": m, "phi_in": row(n121, 1), "phi_out": [row(n121, 1)], "force": force});
    let mats = tmp.join("mats.json");
    std::fs::write(&mats, json.to_string()).unwrap();
    let py = std::env::var("FXBODY_PYTHON")
        .map(PathBuf::from)
        .unwrap_or(root.join(".venv/bin/python"));
    let np_steps = 100_000;
    let np = Command::new(&py)
        .arg(root.join("benches/fmi_numpy.py"))
        .arg(&mats)
        .args([np_steps.to_string(), h.to_string()])
        .output();
    let (np_ns, y_np) = match np {
        Ok(o) if o.status.success() => {
            let t = String::from_utf8_lossy(&o.stdout).to_string();
            let val = |key: &str| {
                t.lines()
                    .find_map(|l| l.strip_prefix(key))
                    .map(|v| v.trim().parse::<f64>().unwrap())
            };
            (val("ns_per_step"), val("y_final"))
        }
        _ => (None, None),
    };

    println!(
        "fmi_step: blocked cantilever, {} modes, 2 exposed nodes, exact method, h = {h} s",
        body.nl()
    );
    println!(
        "  C master through the FMU ABI (setReal + doStep + getReal): {c:8.1} ns/step (best of {ROUNDS} x {steps}, alternating with the next line)"
    );
    println!(
        "  Rust solver called directly (set_loads + step + position):  {d:8.1} ns/step (best of {ROUNDS} x {steps})"
    );
    println!("  Rust solver, all 6 positions and 6 velocities read per step:  {all:8.1} ns/step");
    // Issue 16's figure: the FMI layer's cost per step over the solver's own step.
    println!(
        "  FMI layer per step: {:8.1} ns; ratio (C - direct) / direct = {:.2} (issue 16 asks <= 0.3)",
        c - d,
        (c - d) / d
    );
    match np_ns {
        Some(n) => println!(
            "  numpy loop over the exact discrete state space:            {n:8.1} ns/step ({:.1}x slower than the C ABI)",
            n / c
        ),
        None => println!("  numpy loop: skipped ({} not usable)", py.display()),
    }
    // Same physics, three implementations: after 1e6 steps (C, Rust) they must agree.
    println!("  tip y after {steps} steps: C {y_c:.12e}, Rust {y_direct:.12e}");
    if let Some(y) = y_np {
        // numpy ran fewer steps: compare with the Rust solver over the same steps.
        let mut s = solver::build(&res.scene, Method::Exact, &Options::default()).unwrap();
        let mut loads = [0.0; 12];
        let mut pos = [0.0; 6];
        for k in 0..np_steps {
            loads[1] = force * (1e-3 * k as f64).sin();
            s.set_loads(&loads).unwrap();
            s.step(h).unwrap();
        }
        s.positions(&mut pos);
        let x0 = res.scene.x0[0][1];
        println!(
            "  tip displacement after {np_steps} steps: numpy {y:.12e}, Rust {:.12e} (relative difference {:.1e})",
            pos[1] - x0,
            (y - (pos[1] - x0)).abs() / y.abs()
        );
    }
    if std::env::var_os("FXBODY_BENCH_KEEP").is_none() {
        let _ = std::fs::remove_dir_all(&tmp);
    } else {
        println!("  kept {}", tmp.display());
    }
}
