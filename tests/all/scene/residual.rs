//! The residual-flexibility decorator: velocities from load rates against the time
//! derivative of the positions (central differences), bit-for-bit state round trips, and
//! for a free body the linear-static identity work = 2 x strain energy of the
//! correction.

use crate::common::fixture_scene as scene;
use fxbody::solver::{Method, Options, build};

#[test]
fn velocities_are_the_derivative_of_positions_under_ramped_loads() {
    // cantilever_damped (rotated P0) truncated at 2 f1, tip and mid node, ramped loads in
    // all 12 directions, exact method (exact for linear loads). At t = 0.05 s the
    // velocity output equals (x(t+d) - x(t-d)) / 2d with d = 1e-6 s to 1e-6 of the
    // largest velocity; the residual's share R fdot is far above that tolerance.
    let full = scene("cantilever_damped", &[121, 111]);
    let (sc, _) = full.truncated(2.0 * full.body.frequencies_hz()[0]).unwrap();
    let f0: Vec<f64> = (0..12).map(|k| 0.3 + 0.1 * k as f64).collect();
    let fd: Vec<f64> = (0..12).map(|k| 20.0 - 3.0 * k as f64).collect();
    let run = |t: f64| {
        let mut s = build(&sc, Method::Exact, &Options::default()).unwrap();
        s.set_loads(&f0).unwrap();
        s.set_load_rates(&fd).unwrap();
        s.step(t).unwrap();
        let (mut p, mut v) = (vec![0.0; 6], vec![0.0; 6]);
        s.positions(&mut p);
        s.velocities(&mut v);
        (p, v)
    };
    let d = 1e-6;
    let (_, v) = run(0.05);
    let (pp, _) = run(0.05 + d);
    let (pm, _) = run(0.05 - d);
    let vmax = v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let mut bare = sc.clone();
    bare.residual = None;
    let mut s = build(&bare, Method::Exact, &Options::default()).unwrap();
    s.set_loads(&f0).unwrap();
    s.set_load_rates(&fd).unwrap();
    s.step(0.05).unwrap();
    let mut v_bare = vec![0.0; 6];
    s.velocities(&mut v_bare);
    let share = v
        .iter()
        .zip(&v_bare)
        .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
    for c in 0..6 {
        let fdiff = (pp[c] - pm[c]) / (2.0 * d);
        assert!(
            (v[c] - fdiff).abs() < 1e-6 * vmax,
            "{c}: {} vs {fdiff}",
            v[c]
        );
    }
    println!(
        "residual velocity share {:.2e} of the largest velocity",
        share / vmax
    );
    assert!(share > 1e-3 * vmax);
}

#[test]
fn state_round_trip_is_bit_for_bit() {
    for (name, ids, method) in [
        ("cantilever_damped", vec![121, 111], Method::Implicit),
        ("truss", vec![1043, 1022], Method::Explicit),
    ] {
        let full = scene(name, &ids);
        let (sc, _) = full.truncated(2.0 * full.body.frequencies_hz()[0]).unwrap();
        let mut s = build(&sc, method, &Options::default()).unwrap();
        let loads: Vec<f64> = (0..12).map(|k| 0.01 * (k as f64 - 5.0)).collect();
        s.set_loads(&loads).unwrap();
        s.set_load_rates(&[0.02; 12]).unwrap();
        s.step(1e-3).unwrap();
        let saved = s.state();
        let mut first = vec![0.0; 6];
        s.step(1e-3).unwrap();
        s.positions(&mut first);
        s.set_loads(&[0.0; 12]).unwrap();
        s.step(1e-3).unwrap();
        s.set_state(&saved).unwrap();
        let mut again = vec![0.0; 6];
        s.step(1e-3).unwrap();
        s.positions(&mut again);
        assert_eq!(first, again, "{name}");
    }
}

#[test]
fn free_body_correction_work_is_twice_its_energy() {
    // Truss (free body) truncated at 2 f1, two nodes, loads applied at t = 0: before any
    // step the kept modes and the frame have not moved, so the displacement is the
    // correction alone, u = P R P^T f, and f . u = 2 x (strain energy) for a linear static
    // response (1e-9 relative: u ~ 1e-6 m is read as position minus x0 ~ 1 m, which
    // leaves about 1e-10 relative). The energy is computed from R and the loads, the
    // displacement from the positions: two paths.
    let full = scene("truss", &[1043, 1022]);
    let (sc, _) = full.truncated(2.0 * full.body.frequencies_hz()[0]).unwrap();
    let mut s = build(&sc, Method::Explicit, &Options::default()).unwrap();
    let f: Vec<f64> = (0..12)
        .map(|k| if k % 6 < 3 { 1.0 + 0.5 * k as f64 } else { 0.0 })
        .collect();
    s.set_loads(&f).unwrap();
    let mut p = vec![0.0; 6];
    s.positions(&mut p);
    let work: f64 = (0..2)
        .flat_map(|k| (0..3).map(move |c| (k, c)))
        .map(|(k, c)| f[6 * k + c] * (p[3 * k + c] - sc.x0[k][c]))
        .sum();
    let e = s.strain_energy();
    println!("work {work:e}, 2 x energy {:e}", 2.0 * e);
    assert!(work > 0.0);
    assert!((work - 2.0 * e).abs() < 1e-9 * work);
}
