//! What modelling no more than a scene needs buys, on the large fixtures (5151 nodes,
//! 200 local modes; `python fixtures/generate.py --large`, not committed):
//! the time of one communication cycle `set_loads + step(H) + positions` with every node
//! exposed and every mode kept, against 2 exposed nodes and 20 modes (fmax at the 20th
//! frequency, static correction for the rest), per method, printed as ratios; and the
//! explicit method's stable step with all modes vs the kept ones.
//! Run with `cargo bench --bench scene`; skipped with a message when the fixture is absent.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use fxbody::body::load as load_body;
use fxbody::body::stable_step;
use fxbody::fxb::coords;
use fxbody::scene::Scene;
use fxbody::scene::reduce::ModalBasis;
use fxbody::solver::{Method, Options, build};

/// Median time (s) of one cycle over `reps` cycles, after one warm-up cycle.
fn cycle_time(scene: &Scene, method: Method, h: f64, reps: usize) -> Option<f64> {
    let mut s = match build(scene, method, &Options::default()) {
        Ok(s) => s,
        Err(e) => {
            println!("  {method:?}: {e}");
            return None;
        }
    };
    let m = scene.nodes.len();
    let mut loads = vec![0.0; 6 * m];
    let mut pos = vec![0.0; 3 * m];
    let mut times = Vec::with_capacity(reps);
    for k in 0..=reps {
        loads[6 * (m - 1) + 2] = 1.0 + 0.1 * (k % 7) as f64;
        let t = Instant::now();
        s.set_loads(&loads).unwrap();
        s.step(h).unwrap();
        s.positions(&mut pos);
        std::hint::black_box(&pos);
        if k > 0 {
            times.push(t.elapsed().as_secs_f64());
        }
    }
    times.sort_by(f64::total_cmp);
    Some(times[times.len() / 2])
}

fn run(name: &str, h: f64) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    let fxb = root.join(format!("{name}.fxb"));
    if !fxb.is_file() {
        println!(
            "{name}: {} absent, run `python fixtures/generate.py --large`",
            fxb.display()
        );
        return;
    }
    let t0 = Instant::now();
    let body = load_body(&fxb, Default::default()).unwrap();
    let xyz =
        coords::to_map(&coords::read_coords(&root.join(format!("{name}.nodes.rad"))).unwrap());
    println!(
        "{name}: {} nodes, {} modes, read in {:.1} s; communication step H = {h} s",
        body.nnodes(),
        body.nl(),
        t0.elapsed().as_secs_f64()
    );
    let all: Vec<usize> = (0..body.nnodes()).collect();
    let basis = ModalBasis::of(&body);
    let hz = basis.frequencies_hz();
    let fmax = hz[19];
    let body = Arc::new(body);
    let ids = body.node_ids().to_vec();
    let x0 = |nodes: &[usize]| nodes.iter().map(|&n| xyz[&ids[n]]).collect();
    let full = Scene::new(body.clone(), all.clone(), x0(&all));
    // Two nodes: the last one (a free corner) and the middle of the node list.
    let two = vec![body.nnodes() - 1, body.nnodes() / 2];
    let small_all_modes = Scene::new(body.clone(), two.clone(), x0(&two));
    let (small, t) = small_all_modes.truncated(fmax).unwrap();
    println!(
        "  fmax = {fmax:.3} Hz: {} modes kept, {} dropped (highest {:.1} Hz)",
        t.kept,
        t.dropped_hz.len(),
        hz.last().unwrap()
    );
    let beta = body.damping().map_or(0.0, |d| d.beta);
    let dt_full = stable_step(*hz.last().unwrap(), beta);
    let dt_small = stable_step(fmax, beta);
    println!(
        "  explicit stable step: all modes {dt_full:.3e} s ({} internal steps per H), 20 modes {dt_small:.3e} s ({} per H): {:.1}x larger",
        (h / (0.9 * dt_full)).ceil(),
        (h / (0.9 * dt_small)).ceil(),
        dt_small / dt_full
    );
    let methods: &[Method] = if body.is_blocked() {
        &[Method::Exact, Method::Implicit, Method::Explicit]
    } else {
        &[Method::Implicit, Method::Explicit]
    };
    for &method in methods {
        let reps = if method == Method::Explicit { 5 } else { 21 };
        let (Some(a), Some(b), Some(c)) = (
            cycle_time(&full, method, h, reps),
            cycle_time(&small_all_modes, method, h, reps),
            cycle_time(&small, method, h, reps),
        ) else {
            continue;
        };
        println!(
            "  {method:?}: all nodes + all modes {:.3e} s/cycle, 2 nodes + all modes {:.3e}, 2 nodes + 20 modes {:.3e}: ratio {:.0}x (nodes alone {:.0}x, modes alone {:.1}x)",
            a,
            b,
            c,
            a / c,
            a / b,
            b / c
        );
    }
}

fn main() {
    run("large", 1e-3);
    run("large_free", 1e-3);
}
