//! The physical limit of a communication step: the two dense products no blocked-body
//! solver can avoid (projecting the exposed loads on the modes, `nL x 6m`, and the
//! exposed positions from the modal state, `3m x nL`), timed in the same run as one
//! communication cycle (`set_loads + step + positions`) of each method on the same body.

use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

use fxbody::scene::Scene;
use fxbody::solver::build;
use nalgebra::{DMatrix, DVector};

use super::scenes::Variant;

/// Calls per batch so that a batch lasts about 2 ms.
fn calibrate(f: &mut dyn FnMut()) -> usize {
    let mut reps = 1usize;
    loop {
        let t = Instant::now();
        for _ in 0..reps {
            f();
        }
        if t.elapsed().as_secs_f64() > 0.002 || reps > 1 << 24 {
            return reps;
        }
        reps *= 2;
    }
}

/// Nanoseconds per call of each closure: interleaved batches, fastest batch kept, so
/// that load from other processes hits all alike and is filtered out.
pub fn time_ns(fs: &mut [&mut dyn FnMut()], rounds: usize) -> Vec<f64> {
    let reps: Vec<usize> = fs.iter_mut().map(|f| calibrate(&mut **f)).collect();
    let mut best = vec![f64::INFINITY; fs.len()];
    for _ in 0..rounds {
        for (k, f) in fs.iter_mut().enumerate() {
            let t = Instant::now();
            for _ in 0..reps[k] {
                f();
            }
            best[k] = best[k].min(t.elapsed().as_secs_f64() * 1e9 / reps[k] as f64);
        }
    }
    best
}

/// One row of the bound table.
pub struct BoundRow {
    /// Exposed nodes.
    pub nodes: usize,
    /// Local modes.
    pub modes: usize,
    /// Step used (s).
    pub h: f64,
    /// ns of the two dense products.
    pub bound_ns: f64,
    /// (method label, ns per communication cycle).
    pub methods: Vec<(String, f64)>,
}

/// Time the bound and each method's cycle on `scene` with all of `nodes` exposed.
pub fn measure(
    scene: &Scene,
    nodes: Vec<usize>,
    x0: Vec<[f64; 3]>,
    variants: &[Variant],
    h: f64,
    rounds: usize,
) -> Result<BoundRow, String> {
    let sc = Scene::new(Arc::clone(&scene.body), nodes, x0);
    let m = sc.nodes.len();
    let nl = sc.body.nl();
    let proj = sc.exposed_rows(sc.body.phi_l());
    let outm = DMatrix::from_fn(3 * m, nl, |r, j| proj[(6 * (r / 3) + r % 3, j)]);
    let loads: Vec<f64> = (0..6 * m).map(|i| 1e-3 * (i as f64 + 1.0)).collect();
    let lv = DVector::from_vec(loads.clone());
    let mut f = DVector::zeros(nl);
    let q = DVector::from_fn(nl, |i, _| 1e-6 * (i as f64 + 1.0));
    let mut o = DVector::zeros(3 * m);
    let mut bound = || {
        f.gemv_tr(1.0, black_box(&proj), black_box(&lv), 0.0);
        o.gemv(1.0, black_box(&outm), black_box(&q), 0.0);
        black_box((&f, &o));
    };
    let mut solvers = Vec::new();
    for v in variants {
        solvers.push(build(&sc, v.method, &v.opts).map_err(|e| e.to_string())?);
    }
    let mut outs = vec![vec![0.0; 3 * m]; solvers.len()];
    let mut cycles: Vec<Box<dyn FnMut() + '_>> = solvers
        .iter_mut()
        .zip(outs.iter_mut())
        .map(|(s, out)| {
            let l = &loads;
            Box::new(move || {
                s.set_loads(black_box(l))
                    .expect("loads of the right length");
                s.step(h).expect("a positive finite step");
                s.positions(out);
                black_box(&*out);
            }) as Box<dyn FnMut() + '_>
        })
        .collect();
    let mut fs: Vec<&mut dyn FnMut()> = vec![&mut bound];
    for c in cycles.iter_mut() {
        fs.push(&mut **c);
    }
    let t = time_ns(&mut fs, rounds);
    Ok(BoundRow {
        nodes: m,
        modes: nl,
        h,
        bound_ns: t[0],
        methods: variants
            .iter()
            .zip(&t[1..])
            .map(|(v, &ns)| (v.label.to_string(), ns))
            .collect(),
    })
}
