//! The sparse import core on a ~100k-DOF solid against scipy, in one run on the same
//! matrices: the L-bracket of `tests/fe_models/bracket.py` meshed finer (largest edge
//! 3.1 mm: 104,148 DOFs free, about 130 MB per matrix file), generated on first use into
//! `target/fe_models/` (outside git).
//!
//! Ours: read `free.sti/.mas/.dof`, analyse and factor (with the inertia count), every
//! mode below 20 kHz, inertia-relief static modes at both spiders' 12 DOFs. scipy's: the
//! core of Exudyn's Hurty-Craig-Bampton import, `eigsh` in shift-invert mode for as many
//! modes at our shift (SuperLU inside) and `splu` plus a solve for the 12 connection
//! DOFs. Printed: each stage's wall time, the ratio, both peak memories. Timings are
//! printed, never asserted: the machine is shared.
//!
//! Run with `cargo bench -p fxbody-import --bench sparse` (about 5 minutes; `SPARSE_BENCH_SIZE`
//! sets another mesh size).

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use fxbody_import::fe::Dof;
use fxbody_import::sparse::eigen::{Options, Solver, Support, hz, lambda};
use fxbody_import::sparse::rigid::rigid_motions;
use fxbody_import::sparse::{read_job, statics};

const FMAX: f64 = 20_000.0;

fn main() {
    let size: f64 = std::env::var("SPARSE_BENCH_SIZE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3.1);
    let dir = common::bracket(size, false);
    let job = dir.join("free");
    let (a, b) = common::spiders(&dir);

    // Reading speed against a plain read of the same bytes, same run.
    let files = ["free.sti", "free.mas", "free.dof"].map(|f| dir.join(f));
    let bytes: u64 = files
        .iter()
        .map(|f| std::fs::metadata(f).map_or(0, |m| m.len()))
        .sum();
    let t = Instant::now();
    let plain: usize = files
        .iter()
        .map(|f| std::fs::read(f).map_or(0, |b| b.len()))
        .sum();
    let t_plain = t.elapsed().as_secs_f64();
    assert_eq!(plain as u64, bytes);
    let cpu0 = common::cpu_seconds();
    let start = Instant::now();
    let mut t = Instant::now();
    let model = read_job(&job).unwrap_or_else(|e| panic!("{e}"));
    let t_read = t.elapsed().as_secs_f64();
    t = Instant::now();
    let xyz = common::nodes(&dir);
    let r = rigid_motions(
        &model.dofs,
        &xyz,
        &common::rot_nodes(&dir),
        common::centroid(&xyz),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let support = Support::Free { rigid: Some(r) };
    let solver =
        Solver::new(&model.k, &model.m, &support, lambda(FMAX)).unwrap_or_else(|e| panic!("{e}"));
    let t_factor = t.elapsed().as_secs_f64();
    t = Instant::now();
    let modes = solver
        .modes(&Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let t_eigen = t.elapsed().as_secs_f64();
    t = Instant::now();
    let conn: Vec<usize> = [a.reference, a.rotation, b.reference, b.rotation]
        .iter()
        .flat_map(|&id| (1..=3).map(move |c| Dof::new(id, c)))
        .map(|d| {
            model
                .dofs
                .iter()
                .position(|&x| x == d)
                .expect("connection DOF")
        })
        .collect();
    let psi = statics::static_modes(&solver, &conn, &modes).unwrap_or_else(|e| panic!("{e}"));
    let t_static = t.elapsed().as_secs_f64();
    let total = start.elapsed().as_secs_f64();
    let our_peak = common::peak_mb();
    let our_cpu = common::cpu_seconds() - cpu0;
    let ours_solve = t_factor + t_eigen + t_static;

    println!(
        "model: {} DOFs, {} stored terms in K, L has {} values ({:.2e} flops)",
        model.dofs.len(),
        model.k.nnz(),
        solver.analysis().factor_len(),
        solver.analysis().flops()
    );
    println!(
        "modes below {FMAX} Hz: {} by inertia (6 rigid), {} elastic found in {} Lanczos steps; {} static modes",
        modes.count,
        modes.lambda.len(),
        modes.steps,
        psi.ncols()
    );
    let mb = bytes as f64 / 1e6;
    println!(
        "read: {mb:.0} MB in {t_read:.2} s = {:.0} MB/s (a plain read of the bytes: {:.0} MB/s)",
        mb / t_read,
        mb / t_plain
    );
    println!(
        "ours:  read {t_read:.2} s, analyse+count+factor {t_factor:.2} s, eigen {t_eigen:.2} s, static {t_static:.2} s; total {total:.2} s wall ({our_cpu:.1} s CPU), peak {our_peak:.0} MB"
    );

    let conn_text: Vec<String> = conn.iter().map(|c| c.to_string()).collect();
    let out = std::process::Command::new(common::python())
        .arg(common::root().join("crates/import/benches/scipy_ref.py"))
        .arg(&job)
        .arg(solver.shift().to_string())
        .arg(modes.count.to_string())
        .arg(conn_text.join(","))
        .env("OMP_NUM_THREADS", "2")
        .env("OPENBLAS_NUM_THREADS", "2")
        .output()
        .expect("run scipy_ref.py");
    if !out.status.success() {
        println!(
            "scipy reference failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        return;
    }
    let s: serde_json::Value = serde_json::from_slice(&out.stdout).expect("scipy json");
    let (s_read, s_eig, s_static) = (
        s["read"].as_f64().unwrap(),
        s["eigsh"].as_f64().unwrap(),
        s["splu_static"].as_f64().unwrap(),
    );
    println!(
        "scipy: read {s_read:.2} s, eigsh {s_eig:.2} s, splu static {s_static:.2} s ({:.1} s CPU after reading), peak {:.0} MB",
        s["cpu"].as_f64().unwrap(),
        s["peak_mb"].as_f64().unwrap()
    );
    println!(
        "ratio scipy/ours: solve (eigen + static) {:.1}x, with reading {:.1}x",
        (s_eig + s_static) / ours_solve,
        (s_read + s_eig + s_static) / total
    );
    // Same eigenvalues: scipy's elastic ones (after its six near zero) against ours.
    let theirs: Vec<f64> = s["lambda"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let worst = modes
        .lambda
        .iter()
        .zip(&theirs[6..])
        .map(|(x, y)| ((hz(*x) - hz(*y)) / hz(*y)).abs())
        .fold(0.0f64, f64::max);
    println!("largest relative frequency difference to scipy: {worst:.1e}");
}
