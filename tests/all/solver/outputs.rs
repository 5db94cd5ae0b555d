//! The cheap output paths give exactly what the full ones give: a single position
//! (`Solver::position`, what the FMU uses when a master reads one value) against the
//! whole `positions` array, bit for bit, for every blocked method, with loads that are
//! partly zero (the load projection skips zero components) and partly not; the load
//! projection against the dense product `Phi^T P0^T f` computed here from the body's
//! matrices (through the modal accelerations of a first step from rest, and through the
//! static deflection against a dense solve with K_L); and the random scenes these tests
//! run on have what their generator promises (two decades of frequencies, a repeated
//! pair, a close cluster).

use crate::common::blocked::{random_scene, random_scene_omegas};
use fxbody::scene::Scene;
use fxbody::solver::{Method, Options, build};
use nalgebra::{DVector, Matrix3, Vector3};

#[test]
fn one_position_is_the_same_bits_as_all_positions() {
    let scene = random_scene(12, 7, 3, 42, Some((0.5, 1e-4)));
    for method in [Method::Exact, Method::Implicit, Method::Explicit] {
        let mut s = build(&scene, method, &Options::default()).unwrap();
        let mut loads = [0.0; 18];
        let mut all = [0.0; 9];
        for k in 0..200 {
            // Two of the 18 components carry a load, the rest stay zero.
            loads[1] = (0.01 * k as f64).sin();
            loads[13] = if k % 3 == 0 { 0.0 } else { 0.5 };
            s.set_loads(&loads).unwrap();
            s.step(1e-4).unwrap();
            s.positions(&mut all);
            for (i, &p) in all.iter().enumerate() {
                let one = s
                    .position(i)
                    .expect("blocked methods give one position alone");
                assert_eq!(one.to_bits(), p.to_bits(), "{method:?} step {k} value {i}");
            }
            assert_eq!(s.position(9), None, "past the last exposed node");
        }
        // The motion is real: the outputs moved away from x0.
        let moved = all
            .iter()
            .zip(scene.x0.iter().flatten())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(moved > 1e-8, "{method:?}: outputs did not move ({moved})");
    }
}

#[test]
fn loads_on_all_components_superpose_the_single_component_responses() {
    // A blocked body is linear: the response to a load on every component (the dense
    // projection) equals the sum of the responses to each component alone (the
    // projection that skips zeros), to round-off (1e-12 of the largest displacement).
    let scene = random_scene(10, 5, 2, 7, Some((0.2, 2e-4)));
    let load = |c: usize| 1.0 + 0.37 * c as f64 - 0.05 * (c * c) as f64;
    let run = |loads: &[f64; 12]| {
        let mut s = build(&scene, Method::Exact, &Options::default()).unwrap();
        s.set_loads(loads).unwrap();
        for _ in 0..50 {
            s.step(2e-4).unwrap();
        }
        let mut p = [0.0; 6];
        s.positions(&mut p);
        let x0: Vec<f64> = scene.x0.iter().flatten().copied().collect();
        std::array::from_fn::<f64, 6, _>(|i| p[i] - x0[i])
    };
    let all = run(&std::array::from_fn(load));
    let mut sum = [0.0; 6];
    for c in 0..12 {
        let mut one = [0.0; 12];
        one[c] = load(c);
        for (s, d) in sum.iter_mut().zip(run(&one)) {
            *s += d;
        }
    }
    let scale = all.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    assert!(scale > 1e-9, "the loads moved nothing ({scale})");
    for (a, b) in all.iter().zip(sum) {
        assert!((a - b).abs() <= 1e-12 * scale, "{a} vs {b}");
    }
}

/// The generalised load `g = Phi^T P0^T f` of global nodal loads `f` (force and moment
/// per exposed node), as dense products written here: the exposed nodes' rows of the
/// body's local modes, each 3-vector of `f` taken to the body frame with P0^T.
fn dense_generalised_load(scene: &Scene, f: &[f64]) -> DVector<f64> {
    let body = &scene.body;
    let p0: Matrix3<f64> = *body.p0();
    let mut g = DVector::zeros(body.nl());
    for (k, &n) in scene.nodes.iter().enumerate() {
        for part in 0..2 {
            let v = Vector3::from_column_slice(&f[6 * k + 3 * part..6 * k + 3 * part + 3]);
            let local = p0.transpose() * v;
            for j in 0..body.nl() {
                for c in 0..3 {
                    g[j] += body.phi_l()[(6 * n + 3 * part + c, j)] * local[c];
                }
            }
        }
    }
    g
}

/// A load on every component of both exposed nodes.
fn all_components() -> [f64; 12] {
    std::array::from_fn(|c| 1.0 + 0.37 * c as f64 - 0.05 * (c * c) as f64)
}

#[test]
fn load_projection_equals_the_dense_product() {
    // Modal accelerations: from rest, undamped, the exact method's first step of h gives
    // alpha = M^-1 g h^2 / 2 up to a relative (omega_max h)^2 / 12 = 7.5e-9 at
    // h = 1e-7 s (omega_max = 3000 rad/s; measured 1.9e-9). Bound 5e-9, relative to the
    // largest.
    let scene = random_scene(10, 5, 2, 7, None);
    let f = all_components();
    let g = dense_generalised_load(&scene, &f);
    let h = 1e-7;
    let want: Vec<f64> = (0..scene.body.nl())
        .map(|j| g[j] / scene.body.m_l()[j] * h * h / 2.0)
        .collect();
    let mut s = build(&scene, Method::Exact, &Options::default()).unwrap();
    s.set_loads(&f).unwrap();
    s.step(h).unwrap();
    let got = s.modal();
    let scale = want.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let err = got
        .iter()
        .zip(&want)
        .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()))
        / scale;
    println!("modal accelerations vs dense Phi^T P0^T f / m_L: {err:.2e}");
    assert!(err < 5e-9, "{err:e}");

    // Static deflection, damped: the exact method settled (steps of 1000 s) against
    // u = P0 G K_L^-1 g by a dense LU solve, at every exposed node, to round-off: 5e-13
    // of the largest displacement (measured 8.9e-14).
    let scene = random_scene(10, 5, 2, 7, Some((0.2, 2e-4)));
    let g = dense_generalised_load(&scene, &f);
    let body = &scene.body;
    let q = body.k_l().clone().lu().solve(&g).unwrap();
    let mut want = Vec::new();
    for &n in &scene.nodes {
        let local = Vector3::from_fn(|c, _| {
            (0..body.nl())
                .map(|j| body.phi_l()[(6 * n + c, j)] * q[j])
                .sum()
        });
        want.extend((body.p0() * local).iter().copied());
    }
    let mut s = build(&scene, Method::Exact, &Options::default()).unwrap();
    s.set_loads(&f).unwrap();
    for _ in 0..10 {
        s.step(1000.0).unwrap();
    }
    let mut p = [0.0; 6];
    s.positions(&mut p);
    let x0: Vec<f64> = scene.x0.iter().flatten().copied().collect();
    let scale = want.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let err = (0..6).fold(0.0f64, |a, i| a.max((p[i] - x0[i] - want[i]).abs())) / scale;
    println!("static deflection vs dense P0 G K_L^-1 Phi^T P0^T f: {err:.2e}");
    assert!(scale > 1e-6 && err < 5e-13, "{err:e} (scale {scale:e})");
}

#[test]
fn random_scenes_have_repeated_and_clustered_frequencies_over_two_decades() {
    // The body's own eigenfrequencies (computed from K_L and m_L at load) against the
    // generator's: two decades, the first pair repeated to round-off, the cluster 1e-6
    // apart; for the sizes the solver tests use.
    for nl in [3, 6, 8, 10, 20, 140] {
        let scene = random_scene(nl, 3, 1, 9, None);
        let want = random_scene_omegas(nl);
        let got: Vec<f64> = scene
            .body
            .frequencies_hz()
            .iter()
            .map(|f| 2.0 * std::f64::consts::PI * f)
            .collect();
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() <= 1e-9 * w, "nl {nl}: {g} vs {w}");
        }
        assert!(
            got[nl - 1] / got[0] >= 99.9,
            "nl {nl}: span {}",
            got[nl - 1] / got[0]
        );
        assert!(
            (got[1] - got[0]).abs() <= 1e-10 * got[0],
            "nl {nl}: no repeated pair"
        );
        if nl >= 5 {
            let c = nl / 2;
            let gap = (got[c + 1] - got[c]) / got[c];
            assert!((gap - 1e-6).abs() < 1e-8, "nl {nl}: cluster gap {gap:e}");
        }
    }
}
