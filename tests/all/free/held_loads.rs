//! Held inputs are held, by every free method: an input set before a step acts over that
//! step and only over it (FMI 2.0 co-simulation), or as the polynomial value + rate when
//! input derivatives are set. Reference: the impulse-momentum law, the body's linear
//! momentum changing over each step by exactly the impulse of that step's forces,
//! whatever the body does inside (tumbles, deforms).

use fxbody::body::mass_props::mass_properties;
use fxbody::solver::{Method, Options, build};
use nalgebra::Vector3;

use crate::common::blocked::Rng;
use crate::common::fixture_scene;
use crate::common::springs::{cube_body, momentum};

/// The methods with the options they are tried with.
fn methods() -> Vec<(Method, Options)> {
    let rho = |rho_inf| Options {
        rho_inf,
        ..Options::default()
    };
    vec![
        (Method::Explicit, Options::default()),
        (Method::Implicit, rho(0.9)),
        (Method::Implicit, rho(0.5)),
        (Method::Split, Options::default()),
    ]
}

/// The free-free fixture beam pushed for 0.1 s and then released, at h = 1 ms and
/// 0.1 ms: its momentum afterwards is the impulse `F 0.1 s` to round-off (1e-10
/// relative; measured at most 1.4e-12, split, and 3e-15 for the others). The force acts
/// at the node nearest the centre of mass (from M_R), so the beam translates and bends
/// without turning: its momentum `s^T M v` is then conserved by the equations of motion
/// whatever construction gave M_R and M_C. Before the implicit method integrated held
/// loads as held it ended 5.0e-3 off at 1 ms and 5.0e-4 at 0.1 ms (h / (2 T): half a
/// step of impulse at each jump).
#[test]
fn a_pulse_gives_its_impulse_on_the_fixture() {
    let probe = fixture_scene("freefree", &[511]);
    let body = &probe.body;
    let cog = mass_properties(body).unwrap().cog_from_l0;
    let x = body.rigid_mode_positions().unwrap();
    let nearest = (0..body.nnodes())
        .min_by(|&a, &b| {
            let d = |n: usize| (Vector3::from(x[n]) - cog).norm();
            d(a).total_cmp(&d(b))
        })
        .unwrap();
    let id = body.node_ids()[nearest];
    let f = Vector3::new(0.0, 1.0, 0.5);
    for (method, opts) in methods() {
        for h in [1e-3f64, 1e-4] {
            let scene = fixture_scene("freefree", &[id]);
            let mut s = build(&scene, method, &opts).unwrap();
            let p0 = Vector3::from(s.momentum().unwrap());
            s.set_loads(&[f[0], f[1], f[2], 0.0, 0.0, 0.0]).unwrap();
            let n = (0.1 / h).round() as usize;
            for _ in 0..n {
                s.step(h).unwrap();
            }
            s.set_loads(&[0.0; 6]).unwrap();
            for _ in 0..n {
                s.step(h).unwrap();
            }
            let p = Vector3::from(s.momentum().unwrap());
            let err = (p - p0 - f * 0.1).norm() / (f * 0.1).norm();
            println!(
                "{method:?} rho_inf {}, h = {h:e}: momentum after the pulse off by {err:.1e}",
                opts.rho_inf
            );
            assert!(err < 1e-10, "{method:?} h {h}: {err:.2e}");
        }
    }
}

/// A tumbling spring body with loads at two nodes that jump at every communication
/// point, steps of varying size, loads from t = 0 or from mid-run, input derivatives on
/// every third step: each step's change of the momentum (from node velocities and nodal
/// masses) is that step's impulse `sum (F0 + F1 h/2) h`, to 1e-10 of the largest impulse,
/// by every method, with and without rotational DOFs.
#[test]
fn each_step_delivers_its_impulse() {
    for irot in [false, true] {
        for (method, opts) in methods() {
            for (start, rates) in [(0, false), (5, false), (0, true), (5, true)] {
                let b = cube_body(irot, 6, 2.0e4);
                let mut scene = b.scene();
                scene.w0 = [0.3, -0.2, 0.5];
                let mut s = build(&scene, method, &opts).unwrap();
                let n6 = 6 * b.x.len();
                let mut g = Rng::new(11 + start as u64);
                let (mut err, mut big) = (0.0f64, 0.0f64);
                let mut p = momentum(&b, s.as_ref());
                for k in 0..40 {
                    let h = 4e-3 * (1.0 + 0.3 * g.symmetric());
                    let (mut loads, mut rate) = (vec![0.0; n6], vec![0.0; n6]);
                    if k >= start {
                        for node in [2, 5] {
                            for c in 0..6 {
                                loads[6 * node + c] = 3.0 * g.symmetric();
                                if rates && k % 3 == 1 {
                                    rate[6 * node + c] = 200.0 * g.symmetric();
                                }
                            }
                        }
                    }
                    s.set_loads(&loads).unwrap();
                    s.set_load_rates(&rate).unwrap();
                    s.step(h).unwrap();
                    let impulse: Vector3<f64> = [2, 5]
                        .iter()
                        .map(|&node| {
                            let o = 6 * node;
                            Vector3::from_fn(|c, _| (loads[o + c] + 0.5 * rate[o + c] * h) * h)
                        })
                        .sum();
                    let p1 = momentum(&b, s.as_ref());
                    err = err.max((p1 - p - impulse).norm());
                    big = big.max(impulse.norm());
                    p = p1;
                }
                let rel = err / big;
                println!(
                    "irot {irot}, {method:?} rho_inf {}, loads from step {start}, rates \
                     {rates}: per-step impulse error {rel:.1e}",
                    opts.rho_inf
                );
                assert!(rel < 1e-10, "{method:?}: {rel:.2e}");
            }
        }
    }
}
