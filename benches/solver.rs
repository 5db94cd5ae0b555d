//! Cost of one solver step against the irreducible dense work of a co-simulation step.
//!
//! For (modes, exposed nodes) in {(20,2), (100,20), (200,100)} and each method, the time
//! of one communication cycle `set_loads + step + positions` is compared with the time
//! of the two dense products no blocked-body solver can avoid: the load projection
//! (`nL x 6m` matvec) and the position output (`3m x nL` matvec), measured in the same
//! run on the same sizes. The explicit method is also timed per internal step (one
//! communication step of 100 internal steps, divided by 100). Run with
//! `cargo bench --bench solver`.

use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

use fxbody::body::{Body, stable_step};
use fxbody::fxb::FxbFile;
use fxbody::scene::Scene;
use fxbody::solver::{Method, Options, build};
use fxbody_testkit::Rng;
use nalgebra::{DMatrix, DVector};

/// A synthetic blocked body: nL modes, `nodes` nodes all exposed, dense SPD K_L,
/// Rayleigh damping.
fn synthetic(nl: usize, nodes: usize) -> Scene {
    let mut g = Rng::new(42);
    let a: Vec<f64> = (0..nl * nl).map(|_| g.symmetric()).collect();
    let mut k_full = Vec::new();
    for r in 0..nl {
        for c in r..nl {
            let mut s: f64 = (0..nl).map(|i| a[i * nl + r] * a[i * nl + c]).sum();
            s *= 1e3 / nl as f64;
            if r == c {
                s += 1e3 * (1.0 + r as f64);
            }
            k_full.push(s);
        }
    }
    let mut file = FxbFile {
        nbmod: nl,
        nbstat: nl,
        nbnod: nodes,
        irot: true,
        idamp: true,
        iblo: true,
        ifile: false,
        node_ids: (1..=nodes as i64).collect(),
        p0: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        freq: 1.0,
        damping: Some((1.0, 1e-6)),
        rigid_modes: Vec::new(),
        local_modes: (0..nl * nodes * 6).map(|_| g.symmetric()).collect(),
        m_l: (0..nl).map(|_| 1.0 + 0.5 * g.symmetric()).collect(),
        k_full,
        k_diag: Vec::new(),
        m_r: Vec::new(),
        m_c: Vec::new(),
        k_c: Vec::new(),
    };
    // The stored Freq is the true top frequency, so that the validated constructor takes
    // the body (a Freq far below the modes is refused as corrupt).
    let mut k = nalgebra::DMatrix::zeros(nl, nl);
    let mut entries = file.k_full.iter();
    for r in 0..nl {
        for c in r..nl {
            let v = *entries.next().expect("K_L row");
            k[(r, c)] = v;
            k[(c, r)] = v;
        }
    }
    let m = nalgebra::DVector::from_column_slice(&file.m_l);
    file.freq = *fxbody::body::eigenfrequencies_hz(&k, &m)
        .last()
        .expect("local modes");
    let body = Body::from_fxb(&file, "bench body").expect("a valid bench body");
    let x0 = (0..nodes).map(|n| [n as f64, 0.0, 0.0]).collect();
    Scene::new(Arc::new(body), (0..nodes).collect(), x0)
}

/// Calls of `f` per batch so that a batch lasts about 5 ms.
fn calibrate(f: &mut dyn FnMut()) -> usize {
    let mut reps = 1usize;
    loop {
        let t = Instant::now();
        for _ in 0..reps {
            f();
        }
        if t.elapsed().as_secs_f64() > 0.005 {
            return reps;
        }
        reps *= 2;
    }
}

/// Nanoseconds per call for each closure: batches of the closures are interleaved over
/// `ROUNDS` rounds and the fastest batch of each is kept, so that load from other
/// processes on a shared machine hits all of them alike and is filtered out.
fn time_ns(fs: &mut [&mut dyn FnMut()]) -> Vec<f64> {
    const ROUNDS: usize = 25;
    let reps: Vec<usize> = fs.iter_mut().map(|f| calibrate(&mut **f)).collect();
    let mut best = vec![f64::INFINITY; fs.len()];
    for _ in 0..ROUNDS {
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

fn main() {
    println!("one communication cycle (set_loads + step + positions) vs the dense bound");
    println!("bound = load projection (nL x 6m) + position output (3m x nL), same run\n");
    println!(
        "{:>5} {:>5} | {:>10} | {:>10} {:>6} | {:>10} {:>6} | {:>10} {:>6} | {:>12} {:>6}",
        "modes",
        "nodes",
        "bound ns",
        "exact ns",
        "ratio",
        "implicit",
        "ratio",
        "explicit",
        "ratio",
        "expl/intern",
        "ratio"
    );
    for (nl, m) in [(20usize, 2usize), (100, 20), (200, 100)] {
        let scene = synthetic(nl, m);
        let mut g = Rng::new(7);
        let loads: Vec<f64> = (0..6 * m).map(|_| g.symmetric()).collect();
        let mut out = vec![0.0; 3 * m];

        // The irreducible products.
        let proj = DMatrix::from_fn(6 * m, nl, |_, _| g.symmetric());
        let outm = DMatrix::from_fn(3 * m, nl, |_, _| g.symmetric());
        let lv = DVector::from_vec(loads.clone());
        let mut f = DVector::zeros(nl);
        let q = DVector::from_fn(nl, |_, _| g.symmetric());
        let mut o = DVector::zeros(3 * m);
        let mut bound = || {
            f.gemv_tr(1.0, black_box(&proj), black_box(&lv), 0.0);
            o.gemv(1.0, black_box(&outm), black_box(&q), 0.0);
            black_box((&f, &o));
        };
        let fmax = *scene.body.frequencies_hz().last().unwrap();
        let dt = 0.9 * stable_step(fmax, 1e-6);
        // One internal explicit step per cycle; the same h for the other methods.
        let h = 0.999 * dt;
        let mut solvers: Vec<_> = [Method::Exact, Method::Implicit, Method::Explicit]
            .iter()
            .map(|&method| build(&scene, method, &Options::default()).unwrap())
            .collect();
        let mut internal = build(&scene, Method::Explicit, &Options::default()).unwrap();
        let (mut o1, mut o2, mut o3, mut o4) = (out.clone(), out.clone(), out.clone(), out.clone());
        let (l1, l2, l3, l4) = (&loads, &loads, &loads, &loads);
        let [s1, s2, s3] = &mut solvers[..] else {
            unreachable!()
        };
        let mut exact = || {
            s1.set_loads(black_box(l1)).unwrap();
            s1.step(h).unwrap();
            s1.positions(&mut o1);
            black_box(&o1);
        };
        let mut implicit = || {
            s2.set_loads(black_box(l2)).unwrap();
            s2.step(h).unwrap();
            s2.positions(&mut o2);
            black_box(&o2);
        };
        let mut explicit = || {
            s3.set_loads(black_box(l3)).unwrap();
            s3.step(h).unwrap();
            s3.positions(&mut o3);
            black_box(&o3);
        };
        // 100 internal steps in one communication step.
        let mut hundred = || {
            internal.set_loads(black_box(l4)).unwrap();
            internal.step(99.9 * dt).unwrap();
            internal.positions(&mut o4);
            black_box(&o4);
        };
        let t = time_ns(&mut [
            &mut bound,
            &mut exact,
            &mut implicit,
            &mut explicit,
            &mut hundred,
        ]);
        let (bound, row, per_internal) = (t[0], [t[1], t[2], t[3]], t[4] / 100.0);
        let _ = &mut out;
        println!(
            "{:>5} {:>5} | {:>10.0} | {:>10.0} {:>6.2} | {:>10.0} {:>6.2} | {:>10.0} {:>6.2} | {:>12.0} {:>6.2}",
            nl,
            m,
            bound,
            row[0],
            row[0] / bound,
            row[1],
            row[1] / bound,
            row[2],
            row[2] / bound,
            per_internal,
            per_internal / bound
        );
    }
}
