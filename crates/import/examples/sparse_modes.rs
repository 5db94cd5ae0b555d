//! Every mode of a CalculiX model below a frequency, and static modes at connection
//! nodes, with the time of each stage and the peak memory, as JSON on stdout: the
//! command-line face of the crate for scripts and the bench.
//!
//! ```text
//! sparse_modes JOB --fmax HZ [--free --nodes nodes.csv --rot Q1,Q2] [--connect N1,N2,...]
//! ```
//!
//! `JOB` is the path of `JOB.sti`, `JOB.mas` and `JOB.dof` without the extension.
//! `--free` treats the body as unsupported: the rigid motions come from `nodes.csv`
//! (`id,x,y,z` lines) with the spiders' ROT nodes `--rot` read as rotations. `--connect`
//! names the nodes whose DOFs get static modes.

#[path = "../tests/common/mod.rs"]
mod common;

use std::collections::HashSet;
use std::path::Path;
use std::time::Instant;

use fxbody_import::sparse::eigen::{Options, Solver, Support, hz, lambda};
use fxbody_import::sparse::{read_job, rigid, statics};

fn ids(s: &str) -> Vec<i64> {
    s.split(',')
        .filter(|t| !t.is_empty())
        .map(|t| t.parse().expect("node ID"))
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let job = args
        .get(1)
        .expect("usage: sparse_modes JOB --fmax HZ [...]");
    let get = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .map(|k| args[k + 1].clone())
    };
    let fmax: f64 = get("--fmax")
        .expect("--fmax HZ")
        .parse()
        .expect("--fmax HZ");
    let free = args.iter().any(|a| a == "--free");
    let clock = Instant::now();
    let mut times = serde_json::Map::new();
    let mut stage = |name: &str, t: &mut Instant| {
        times.insert(name.into(), t.elapsed().as_secs_f64().into());
        *t = Instant::now();
    };
    let mut t = Instant::now();
    let model = read_job(Path::new(job)).unwrap_or_else(|e| panic!("{e}"));
    stage("read", &mut t);
    let support = if free {
        let nodes = common::read_nodes(Path::new(&get("--nodes").expect("--free needs --nodes")));
        let rot: HashSet<i64> = get("--rot")
            .map(|s| ids(&s))
            .unwrap_or_default()
            .into_iter()
            .collect();
        let origin = common::centroid(&nodes);
        let r = rigid::rigid_motions(&model.dofs, &nodes, &rot, origin)
            .unwrap_or_else(|e| panic!("{e}"));
        Support::Free { rigid: Some(r) }
    } else {
        Support::Blocked
    };
    let lmax = lambda(fmax);
    let solver = Solver::new(&model.k, &model.m, &support, lmax).unwrap_or_else(|e| panic!("{e}"));
    stage("factor", &mut t);
    let mut opt = Options::default();
    if let Some(b) = get("--block") {
        opt.block = b.parse().expect("--block N");
    }
    let modes = solver.modes(&opt).unwrap_or_else(|e| panic!("{e}"));
    stage("eigen", &mut t);
    let connect: Vec<usize> = get("--connect")
        .map(|s| ids(&s))
        .unwrap_or_default()
        .into_iter()
        .flat_map(|id| {
            model
                .dofs
                .iter()
                .enumerate()
                .filter(move |(_, d)| d.id == id)
                .map(|(k, _)| k)
        })
        .collect();
    let statics =
        statics::static_modes(&solver, &connect, &modes).unwrap_or_else(|e| panic!("{e}"));
    stage("static", &mut t);
    let out = serde_json::json!({
        "dofs": model.dofs.len(),
        "nnz_k": model.k.nnz(),
        "factor_values": solver.analysis().factor_len(),
        "factor_flops": solver.analysis().flops(),
        "hz": modes.lambda.iter().map(|&l| hz(l)).collect::<Vec<_>>(),
        "count": modes.count,
        "rigid_locked": modes.rigid_locked,
        "residual_max": modes.residual.iter().fold(0.0f64, |a, &b| a.max(b)),
        "lanczos_steps": modes.steps,
        "lanczos_runs": modes.runs,
        "static_modes": statics.ncols(),
        "seconds": times,
        "total_seconds": clock.elapsed().as_secs_f64(),
        "peak_mb": common::peak_mb(),
    });
    println!("{}", serde_json::to_string_pretty(&out).expect("json"));
}
