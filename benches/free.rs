//! Cost of a free-body communication step, explicit, implicit and split, on the
//! free-free fixture, the truss tower (54 modes, a complete basis) and (when generated
//! with `python fixtures/generate.py --large`) on the 200-mode, 5151-node `large_free`
//! body.
//!
//! For each body: 2 exposed nodes and all nodes exposed; the explicit method at one
//! internal step per communication step (h = 0.9 dt_fx), the implicit and split methods
//! at the same h and at 20 times it, at rest under a tip force that changes sign, and
//! (`spin` rows) spinning at 0.018 of the first frequency about a non-principal axis.
//! Prints the time per communication step and per simulated second. Run with
//! `cargo bench --bench free`; `split`, `implicit`, `explicit` keep one method, a body's
//! name keeps that body.

use std::hint::black_box;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use fxbody::body::load as load_body;
use fxbody::body::{Body, stable_step};
use fxbody::scene::Scene;
use fxbody::solver::{Method, Options, build};

/// Best time per step (seconds) over `rounds` rounds of `steps` steps each.
fn time_steps(scene: &Scene, method: Method, h: f64, steps: usize, rounds: usize) -> f64 {
    let mut solver = build(scene, method, &Options::default()).expect("solver builds");
    let m = scene.nodes.len();
    let mut loads = vec![0.0; 6 * m];
    let mut pos = vec![0.0; 3 * m];
    let mut best = f64::INFINITY;
    for round in 0..rounds {
        let t0 = Instant::now();
        for k in 0..steps {
            // A small transverse tip force that changes sign: the body bends and turns.
            loads[1] = if (round * steps + k) % 200 < 100 {
                0.01
            } else {
                -0.01
            };
            solver.set_loads(&loads).expect("loads");
            solver.step(h).expect("step");
            solver.positions(&mut pos);
            black_box(&pos);
        }
        best = best.min(t0.elapsed().as_secs_f64() / steps as f64);
    }
    best
}

fn scene(body: &Arc<Body>, nodes: Vec<usize>, spin: bool) -> Scene {
    let all = body.rigid_mode_positions().unwrap_or_default();
    let x0 = nodes.iter().map(|&n| all[n]).collect();
    let mut s = Scene::new(body.clone(), nodes, x0);
    if spin {
        let w1 = 2.0 * std::f64::consts::PI * body.frequencies_hz()[0];
        let w = body.p0() * nalgebra::Vector3::new(1.0, -2.0, 3.0).normalize() * (0.018 * w1);
        s.w0 = [w[0], w[1], w[2]];
    }
    s
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let has = |w: &str| args.iter().any(|a| a == w);
    let bodies: Vec<&str> = ["freefree", "truss", "large_free"]
        .into_iter()
        .filter(|b| {
            has(b)
                || !args
                    .iter()
                    .any(|a| a == "freefree" || a == "truss" || a == "large_free")
        })
        .collect();
    let methods: Vec<(Method, f64)> = [
        (Method::Explicit, 0.9),
        (Method::Implicit, 0.9),
        (Method::Implicit, 18.0),
        (Method::Split, 0.9),
        (Method::Split, 18.0),
    ]
    .into_iter()
    .filter(|(m, _)| {
        let only = ["explicit", "implicit", "split"]
            .into_iter()
            .filter(|w| has(w))
            .collect::<Vec<_>>();
        only.is_empty() || only.contains(&format!("{m:?}").to_lowercase().as_str())
    })
    .collect();
    println!("free-body step cost (best of rounds; shared machine, figures vary)");
    println!(
        "{:<12} {:>5} {:>7} {:>8} {:>10} {:>18} {:>14} {:>14}",
        "body",
        "nL",
        "nodes",
        "method",
        "h / dt_fx",
        "us per comm. step",
        "us per int.",
        "s per sim. s"
    );
    for name in bodies {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("fixtures/{name}.fxb"));
        if !path.is_file() {
            println!("{name}: not generated (python fixtures/generate.py --large)");
            continue;
        }
        let body = Arc::new(load_body(&path, Default::default()).expect("fixture reads"));
        let fmax = body.frequencies_hz().last().copied().unwrap_or(0.0);
        let beta = body.damping().map_or(0.0, |d| d.beta);
        let dt_fx = stable_step(fmax, beta);
        let n = body.nnodes();
        let big = n > 1000;
        let (steps, rounds) = if has("quick") {
            (if big { 5 } else { 200 }, 1)
        } else if big {
            (20, 3)
        } else {
            (2000, 5)
        };
        let mut selections = vec![(vec![0, n - 1], "2".to_string(), false)];
        if !has("two") {
            selections.push(((0..n).collect(), n.to_string(), false));
        }
        selections.push((vec![0, n - 1], "2 spin".to_string(), true));
        for (nodes, label, spin) in selections {
            let sc = scene(&body, nodes, spin);
            for &(method, factor) in &methods {
                if spin && method == Method::Explicit {
                    // Not timed spinning: the explicit method's step is not a spinning
                    // body's (FORMULATION.md, the spin limit), so its cost would say little.
                    continue;
                }
                let h = factor * dt_fx;
                let t = time_steps(&sc, method, h, steps, rounds);
                let internal = if method == Method::Explicit {
                    format!("{:.2}", t * 1e6 / (h / (0.9 * dt_fx)).ceil())
                } else {
                    "-".into()
                };
                println!(
                    "{:<12} {:>5} {:>7} {:>8} {:>10.1} {:>18.2} {:>14} {:>14.4}",
                    name,
                    body.nl(),
                    label,
                    format!("{method:?}").to_lowercase(),
                    factor,
                    t * 1e6,
                    internal,
                    t / h
                );
            }
        }
    }
}
