//! The cheap output paths give exactly what the full ones give: a single position
//! (`Solver::position`, what the FMU uses when a master reads one value) against the
//! whole `positions` array, bit for bit, for every blocked method, with loads that are
//! partly zero (the load projection skips zero components) and partly not; and the
//! load projection against the dense product computed here.

use crate::common::blocked::random_scene;
use fxbody::solver::{Method, Options, build};

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
