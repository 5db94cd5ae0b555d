//! Bodies built by hand for the solver tests, and closed-form single-degree-of-freedom
//! solutions to test them against.
#![allow(dead_code)]

use std::sync::Arc;

use fxbody::body::Body;
use fxbody::fxb::FxbFile;
use fxbody::scene::Scene;
use fxbody::solver::{Method, Options, build};

pub use fxbody_testkit::Rng;

/// A blocked body from explicit matrices: `m_l` (nL), `k_l` (nL x nL row-major,
/// symmetric), local modes `phi` (mode-major, node, component: nL * N * 6), frame `p0`
/// (row-major), optional Rayleigh (alpha, beta).
pub fn blocked_body(
    m_l: &[f64],
    k_l: &[f64],
    phi: &[f64],
    nnodes: usize,
    p0: [f64; 9],
    damping: Option<(f64, f64)>,
) -> Body {
    let nl = m_l.len();
    let mut k_full = Vec::new();
    for r in 0..nl {
        for c in r..nl {
            k_full.push(k_l[r * nl + c]);
        }
    }
    // The stored Freq is 1 Hz, as the hand-built bodies always had (the stable-step tests
    // rely on it), unless the modes are more than FREQ_RATIO times above it: the
    // validated constructor refuses such a file as corrupt, so it stores the true top.
    let k = nalgebra::DMatrix::from_row_slice(nl, nl, k_l);
    let freqs = fxbody::body::eigenfrequencies_hz(&k, &nalgebra::DVector::from_column_slice(m_l));
    let file = FxbFile {
        nbmod: nl,
        nbstat: nl,
        nbnod: nnodes,
        irot: true,
        idamp: damping.is_some(),
        iblo: true,
        ifile: false,
        node_ids: (1..=nnodes as i64).collect(),
        p0,
        freq: freqs
            .last()
            .copied()
            .filter(|&f| f > fxbody::body::FREQ_RATIO)
            .unwrap_or(1.0),
        damping,
        rigid_modes: Vec::new(),
        local_modes: phi.to_vec(),
        m_l: m_l.to_vec(),
        k_full,
        k_diag: Vec::new(),
        m_r: Vec::new(),
        m_c: Vec::new(),
        k_c: Vec::new(),
    };
    Body::from_fxb(&file, "hand-built body").unwrap_or_else(|e| panic!("{e}"))
}

pub const IDENTITY: [f64; 9] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];

/// One mode of mass `m` and stiffness `k` at one node, moving along global x
/// (the mode's translation is local x and P0 = I). Position of the node = x0 + q.
pub fn one_mode_scene(m: f64, k: f64, damping: Option<(f64, f64)>) -> Scene {
    let body = blocked_body(
        &[m],
        &[k],
        &[1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        1,
        IDENTITY,
        damping,
    );
    Scene::new(Arc::new(body), vec![0], vec![[0.5, -1.0, 2.0]])
}

/// The circular eigenfrequencies (rad/s) [`random_scene`] gives a body of `nl` modes: two
/// decades, 30 to 3000 rad/s, evenly in the logarithm; with three modes or more the first
/// two are one repeated frequency, and with five or more the modes at nl/2 and nl/2 + 1
/// are a cluster, 1e-6 apart (relative). Repeated and close eigenvalues are where an
/// eigen-solver's vectors are least determined, and the methods must not care.
pub fn random_scene_omegas(nl: usize) -> Vec<f64> {
    let (lo, hi) = (30.0f64, 3000.0f64);
    let mut w: Vec<f64> = (0..nl)
        .map(|i| {
            let x = if nl > 1 {
                i as f64 / (nl - 1) as f64
            } else {
                0.0
            };
            lo * (hi / lo).powf(x)
        })
        .collect();
    if nl >= 3 {
        w[1] = w[0];
    }
    if nl >= 5 {
        let c = nl / 2;
        w[c + 1] = w[c] * (1.0 + 1e-6);
    }
    w
}

/// A random blocked body: nL modes over `nnodes` nodes, random masses m_L, a dense SPD
/// stiffness `K_L = S Q diag(omega^2) Q^T S` (S = diag(sqrt(m_L)), Q a random orthogonal
/// matrix) whose eigenfrequencies are exactly [`random_scene_omegas`] (two decades, a
/// repeated pair and a close cluster), random mode shapes, a random rotation P0.
pub fn random_scene(
    nl: usize,
    nnodes: usize,
    exposed: usize,
    seed: u64,
    damping: Option<(f64, f64)>,
) -> Scene {
    let mut g = Rng::new(seed);
    let m_l: Vec<f64> = (0..nl).map(|_| 1.0 + 0.5 * g.symmetric()).collect();
    // Q: Gram-Schmidt (twice, for orthogonality to round-off) of a random matrix.
    let mut q: Vec<Vec<f64>> = (0..nl)
        .map(|_| (0..nl).map(|_| g.symmetric()).collect())
        .collect();
    for i in 0..nl {
        let (done, rest) = q.split_at_mut(i);
        let qi = &mut rest[0];
        for _ in 0..2 {
            for qj in done.iter() {
                let d: f64 = qi.iter().zip(qj).map(|(a, b)| a * b).sum();
                qi.iter_mut().zip(qj).for_each(|(a, b)| *a -= d * b);
            }
        }
        let n = qi.iter().map(|x| x * x).sum::<f64>().sqrt();
        qi.iter_mut().for_each(|x| *x /= n);
    }
    let w2: Vec<f64> = random_scene_omegas(nl).iter().map(|w| w * w).collect();
    let mut k = vec![0.0; nl * nl];
    for i in 0..nl {
        for j in 0..nl {
            let s: f64 = (0..nl).map(|r| q[r][i] * w2[r] * q[r][j]).sum();
            k[i * nl + j] = (m_l[i] * m_l[j]).sqrt() * s;
        }
    }
    // Exactly symmetric, as a stiffness read from a file is.
    for i in 0..nl {
        for j in 0..i {
            k[i * nl + j] = k[j * nl + i];
        }
    }
    let phi: Vec<f64> = (0..nl * nnodes * 6).map(|_| g.symmetric()).collect();
    // A rotation from a unit quaternion.
    let (w, x, y, z) = {
        let q: [f64; 4] = [0.9, 0.2, -0.3, 0.25];
        let n = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
        let n = n.sqrt();
        (q[0] / n, q[1] / n, q[2] / n, q[3] / n)
    };
    let p0 = [
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - z * w),
        2.0 * (x * z + y * w),
        2.0 * (x * y + z * w),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - x * w),
        2.0 * (x * z - y * w),
        2.0 * (y * z + x * w),
        1.0 - 2.0 * (x * x + y * y),
    ];
    let body = blocked_body(&m_l, &k, &phi, nnodes, p0, damping);
    let nodes: Vec<usize> = (0..exposed).map(|i| i * nnodes / exposed.max(1)).collect();
    let x0 = nodes
        .iter()
        .map(|&n| [n as f64, 0.1 * n as f64, -0.2])
        .collect();
    Scene::new(Arc::new(body), nodes, x0)
}

/// Closed-form response of `m q'' + c q' + k q = f0 + f1 t` from `(q0, v0)` at time t:
/// returns (q, v). Covers k > 0 (under-, critically, over-damped) and k = 0.
#[allow(clippy::too_many_arguments)]
pub fn sdof(m: f64, c: f64, k: f64, f0: f64, f1: f64, q0: f64, v0: f64, t: f64) -> (f64, f64) {
    let d = c / m;
    if k == 0.0 {
        if d == 0.0 {
            let q = q0 + v0 * t + f0 * t * t / (2.0 * m) + f1 * t * t * t / (6.0 * m);
            let v = v0 + f0 * t / m + f1 * t * t / (2.0 * m);
            return (q, v);
        }
        // v = vp(t) + (v0 - vp(0)) e^{-dt}, vp = (f0 + f1 t)/(m d) - f1/(m d^2).
        let vp0 = f0 / (m * d) - f1 / (m * d * d);
        let e = (-d * t).exp();
        let v = (f0 + f1 * t) / (m * d) - f1 / (m * d * d) + (v0 - vp0) * e;
        let q = q0 + f0 * t / (m * d) + f1 * t * t / (2.0 * m * d) - f1 * t / (m * d * d)
            + (v0 - vp0) * (1.0 - e) / d;
        return (q, v);
    }
    // Particular solution (f0 + f1 t)/k - c f1/k^2.
    let qp = (f0 + f1 * t) / k - c * f1 / (k * k);
    let vp = f1 / k;
    let a0 = q0 - (f0 / k - c * f1 / (k * k));
    let b0 = v0 - f1 / k;
    let w0 = (k / m).sqrt();
    let lam = d / 2.0;
    let (qh, vh) = if lam < w0 {
        let wd = (w0 * w0 - lam * lam).sqrt();
        let b = (b0 + lam * a0) / wd;
        let (s, co) = (wd * t).sin_cos();
        let e = (-lam * t).exp();
        let q = e * (a0 * co + b * s);
        let v = e * (-lam * (a0 * co + b * s) + wd * (-a0 * s + b * co));
        (q, v)
    } else if lam == w0 {
        let b = b0 + lam * a0;
        let e = (-lam * t).exp();
        (e * (a0 + b * t), e * (b - lam * (a0 + b * t)))
    } else {
        let s = (lam * lam - w0 * w0).sqrt();
        let (r1, r2) = (-lam + s, -lam - s);
        let c2 = (b0 - r1 * a0) / (r2 - r1);
        let c1 = a0 - c2;
        (
            c1 * (r1 * t).exp() + c2 * (r2 * t).exp(),
            c1 * r1 * (r1 * t).exp() + c2 * r2 * (r2 * t).exp(),
        )
    };
    (qp + qh, vp + vh)
}

/// Steady forced response of `m q'' + c q' + k q = F sin(W t)` from rest, closed form
/// (k > 0, under-damped): returns (q, v) at t.
pub fn sdof_sine(m: f64, c: f64, k: f64, f: f64, big_w: f64, t: f64) -> (f64, f64) {
    let kk = k - m * big_w * big_w;
    let cw = c * big_w;
    let den = kk * kk + cw * cw;
    let a = f * kk / den;
    let b = -f * cw / den;
    let qp = a * (big_w * t).sin() + b * (big_w * t).cos();
    let vp = big_w * (a * (big_w * t).cos() - b * (big_w * t).sin());
    // Homogeneous part cancels qp(0) = b, vp(0) = a W.
    let (qh, vh) = sdof(m, c, k, 0.0, 0.0, -b, -a * big_w, t);
    (qp + qh, vp + vh)
}

/// Largest displacement error over [0, 2] s for a sine load sampled every h, held or
/// with its derivative as rate.
pub fn sine_error(method: Method, n: usize, linear: bool, opts: &Options) -> f64 {
    let (m, k, alpha) = (1.0, (2.0 * std::f64::consts::PI * 2.0f64).powi(2), 0.5);
    let (f, big_w) = (3.0, 2.0 * std::f64::consts::PI * 0.7);
    let scene = one_mode_scene(m, k, Some((alpha, 0.0)));
    let mut s = build(&scene, method, opts).unwrap();
    let h = 2.0 / n as f64;
    let mut err = 0.0f64;
    for i in 0..n {
        let t = i as f64 * h;
        s.set_loads(&[f * (big_w * t).sin(), 0.0, 0.0, 0.0, 0.0, 0.0])
            .unwrap();
        if linear {
            s.set_load_rates(&[f * big_w * (big_w * t).cos(), 0.0, 0.0, 0.0, 0.0, 0.0])
                .unwrap();
        }
        s.step(h).unwrap();
        let mut p = [0.0; 3];
        s.positions(&mut p);
        let q = p[0] - 0.5;
        let (qr, _) = sdof_sine(m, alpha * m, k, f, big_w, t + h);
        err = err.max((q - qr).abs());
    }
    err
}

/// Convergence orders from three step counts n0, 2 n0, 4 n0 (the two log2 ratios).
pub fn orders(method: Method, linear: bool, n0: usize, opts: &Options) -> (f64, f64) {
    let e: Vec<f64> = [n0, 2 * n0, 4 * n0]
        .iter()
        .map(|&n| sine_error(method, n, linear, opts))
        .collect();
    println!("{method:?} linear={linear}: errors {e:?}");
    ((e[0] / e[1]).log2(), (e[1] / e[2]).log2())
}
