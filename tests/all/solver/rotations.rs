//! Node rotations and angular velocities of blocked bodies (issue 15) against the full
//! finite-element reference (fixtures/cantilever_damped.ref.json: the FE static
//! solution, global nodal rotations, under each tip load), and the rotation's rate
//! against the angular-velocity output.

use super::fe_reference::{dof, every_node};
use crate::common::{fixture_scene_and_reference as scene, nums};
use fxbody::solver::{Method, Options, build};

#[test]
fn steady_rotations_equal_the_fe_static_rotations() {
    // cantilever_damped: rotated P0 and Rayleigh damping; every tip load case, every
    // method, 6 s of 10 ms steps. The reduced model holds the tip's static modes, so it
    // is exact for static tip loads: the floor is the vibration left after 6 s (exact
    // and explicit: e^-2.5 t, measured up to 1.5e-6 of the largest FE rotation; the
    // implicit method at 10 ms steps damps the first mode less than Rayleigh does and
    // leaves up to 1.2e-4, its angular velocity then 7.5e-4 rad/s). The same test and
    // setting as the translations' (`fe_reference::steady_state_equals_fe_static_deflection`,
    // bound 1e-3). Bounds: 1e-5 (exact, explicit) and 3e-4 (implicit) of the largest FE
    // rotation of the case.
    let (sc, reference, ids, k_tip) = every_node("cantilever_damped");
    let mut worst: f64 = 0.0;
    for case in reference["static"].as_array().unwrap() {
        let name = case["load_dof"].as_str().unwrap();
        let d = dof(name);
        let want: Vec<f64> = ids
            .iter()
            .flat_map(|id| nums(&case["displacements"][id.to_string()])[3..].to_vec())
            .collect();
        let big = want.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for method in [Method::Exact, Method::Implicit, Method::Explicit] {
            let mut s = build(&sc, method, &Options::default()).unwrap();
            let mut loads = vec![0.0; 6 * ids.len()];
            loads[6 * k_tip + d] = case["load_value"].as_f64().unwrap();
            s.set_loads(&loads).unwrap();
            for _ in 0..600 {
                s.step(0.01).unwrap();
            }
            let mut got = vec![0.0; 3 * ids.len()];
            s.rotations(&mut got);
            let err = got
                .iter()
                .zip(&want)
                .map(|(g, w)| (g - w).abs())
                .fold(0.0, f64::max)
                / big;
            let mut w = vec![0.0; 3 * ids.len()];
            s.rotation_rates(&mut w);
            let still = w.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            println!(
                "static {name} {method:?}: rotation error {err:.2e} of the largest FE rotation \
                 {big:.3e} rad; largest angular velocity {still:.1e} rad/s"
            );
            worst = worst.max(err);
            let bound = if method == Method::Implicit {
                3e-4
            } else {
                1e-5
            };
            assert!(err < bound, "{method:?} {name}: {err:e}");
        }
    }
    println!("worst: {worst:.2e}");
}

#[test]
fn rotation_rate_is_the_angular_velocity_output() {
    // Blocked rotations are linear in the modes: their time derivative (central
    // difference of the exact method over 2 us) equals the angular-velocity output to
    // the difference's truncation, (w h)^2 / 6 of the fastest moving mode.
    let (sc, _) = scene("cantilever", &[121, 111]);
    let mut s = build(&sc, Method::Exact, &Options::default()).unwrap();
    s.set_loads(&[0.0, 1.0, 0.5, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.02, 0.0])
        .unwrap();
    s.step(0.0123).unwrap();
    let h = 1e-6;
    let (mut r0, mut r1, mut w) = ([0.0; 6], [0.0; 6], [0.0; 6]);
    s.rotations(&mut r0);
    s.step(h).unwrap();
    s.rotation_rates(&mut w);
    s.step(h).unwrap();
    s.rotations(&mut r1);
    let big = w.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    for c in 0..6 {
        let fd = (r1[c] - r0[c]) / (2.0 * h);
        assert!((fd - w[c]).abs() < 1e-4 * big, "{c}: {fd} vs {}", w[c]);
    }
}
