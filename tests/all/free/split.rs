//! The split (Strang) free-body method: conservation laws, the closed-form rigid spin,
//! its own convergence order, agreement with the implicit method, and the full
//! finite-element model at a master's step.

use super::implicit::max_diff;
use crate::common::springs::*;
use fxbody::solver::free::Split;
use fxbody::solver::{Method, Options, Solver, build};
use nalgebra::{Matrix3, Rotation3, Vector3};

/// Free flight without load, 1e5 steps of 10 ms (about 25 times dt_fx): linear
/// momentum to round-off (1e-12), angular momentum and energy bounded without drift
/// (the change over the last 5e4 steps no larger than over the first 5e4), frame a
/// rotation to 1e-12.
#[test]
fn free_flight_conserves() {
    for irot in [false, true] {
        let b = cube_body(irot, 6, 2.0e4);
        let mut scene = b.scene();
        scene.v0 = [0.3, -0.2, 0.1];
        scene.w0 = [0.5, 0.3, -0.4];
        let mut s = Split::new(&scene, &Options::default()).unwrap();
        let (p0, l0, e0) = (
            momentum(&b, &s),
            angular_momentum(&b, &s),
            s.kinetic_energy(),
        );
        let (mut pe, mut fe) = (0.0f64, 0.0f64);
        let (mut le, mut ee) = ([0.0f64; 2], [0.0f64; 2]);
        for k in 0..100_000 {
            s.step(0.01).unwrap();
            let half = k / 50_000;
            pe = pe.max((momentum(&b, &s) - p0).norm() / p0.norm());
            le[half] = le[half].max((angular_momentum(&b, &s) - l0).norm() / l0.norm());
            ee[half] = ee[half].max(((s.kinetic_energy() + s.strain_energy()) - e0).abs() / e0);
            fe = fe.max(frame_error(&s));
        }
        println!(
            "split irot={irot}: momentum {pe:.1e}, angular momentum {:.2e} / {:.2e}, \
             energy {:.2e} / {:.2e} (first / second half of 1e5 steps), frame {fe:.1e}",
            le[0], le[1], ee[0], ee[1]
        );
        assert!(pe < 1e-12, "momentum {pe:.2e}");
        assert!(fe < 1e-12, "frame {fe:.2e}");
        assert!(
            le[1] < 1e-5 && le[1] <= 1.5 * le[0],
            "angular momentum {le:?}"
        );
        assert!(ee[1] < 1e-5 && ee[1] <= 1.5 * ee[0], "energy {ee:?}");
    }
}

/// Inertia tensor about the centre of mass (nodal masses and rotary inertias).
fn inertia(b: &SpringBody) -> (Vector3<f64>, Matrix3<f64>) {
    let c: Vector3<f64> =
        b.x.iter()
            .zip(&b.mass)
            .map(|(x, m)| Vector3::from(*x) * *m)
            .sum::<Vector3<f64>>()
            / b.total_mass();
    let mut j = Matrix3::zeros();
    for (k, x) in b.x.iter().enumerate() {
        let r = Vector3::from(*x) - c;
        j += b.mass[k] * (Matrix3::identity() * r.norm_squared() - r * r.transpose());
        j += Matrix3::identity() * b.jrot[k];
    }
    (c, j)
}

/// A torque-free rigid spin about each principal axis (a body without local modes):
/// every node on the exact circle `c + exp(t [w]) (x0 - c)` to 1e-10 m over 1,000
/// steps of 1 ms at |w| = 10 rad/s, and the frame `exp(t [w]) P0` to 1e-10.
#[test]
fn rigid_spin_about_a_principal_axis_is_exact() {
    for irot in [false, true] {
        let b = cube_body(irot, 0, 2.0e4);
        let (c, j) = inertia(&b);
        let axes = j.symmetric_eigen().eigenvectors;
        for a in 0..3 {
            let w = axes.column(a).into_owned() * 10.0;
            let mut scene = b.scene();
            scene.w0 = [w[0], w[1], w[2]];
            let mut s = Split::new(&scene, &Options::default()).unwrap();
            let p0 = Matrix3::from_row_slice(&s.frame().unwrap().p);
            let n = b.x.len();
            let mut x = vec![0.0; 3 * n];
            let mut worst = 0.0f64;
            let mut worst_p = 0.0f64;
            for k in 1..=1000 {
                s.step(1e-3).unwrap();
                let rot = Rotation3::new(w * (k as f64 * 1e-3)).into_inner();
                s.positions(&mut x);
                for (i, x0) in b.x.iter().enumerate() {
                    let want = c + rot * (Vector3::from(*x0) - c);
                    let got = Vector3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
                    worst = worst.max((got - want).norm());
                }
                let p = Matrix3::from_row_slice(&s.frame().unwrap().p);
                worst_p = worst_p.max((p - rot * p0).abs().max());
            }
            println!(
                "split rigid spin irot={irot} axis {a}: nodes {worst:.1e} m, frame {worst_p:.1e}"
            );
            assert!(worst < 1e-10, "nodes {worst:.2e}");
            assert!(worst_p < 1e-10, "frame {worst_p:.2e}");
        }
    }
}

/// Positions after 1 s of the loaded tumble of the implicit method's tests (the soft
/// cube, stiffness 200), for a step h.
fn tumble(method: Method, h: f64) -> Vec<f64> {
    super::implicit::tumble(method, h, 200.0, &Options::default())
}

/// Second order on the loaded tumble: halving the step divides the error against a 16
/// times finer run by 3.5 to 4.5; and the converged split and implicit runs agree.
#[test]
fn second_order_on_a_loaded_tumble() {
    let fine = tumble(Method::Split, 1.0 / 1600.0);
    let errs: Vec<f64> = [100.0, 200.0, 400.0]
        .iter()
        .map(|n| max_diff(&tumble(Method::Split, 1.0 / n), &fine))
        .collect();
    println!(
        "split errors at h = 1/100, 1/200, 1/400: {:.3e} {:.3e} {:.3e}",
        errs[0], errs[1], errs[2]
    );
    for k in 0..2 {
        let r = errs[k] / errs[k + 1];
        assert!((3.5..4.5).contains(&r), "error ratio {r:.2} at halving {k}");
    }
    let imp = tumble(Method::Implicit, 1.0 / 1600.0);
    let peak = fine.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let d = max_diff(&imp, &fine) / peak;
    println!("split vs implicit at h = 1/1600: {d:.2e} of the peak {peak:.3e}");
    assert!(d < 1e-5, "split and implicit differ by {d:.2e}");
}

/// Invalid inputs get the same errors and messages as the implicit method: loads of the
/// wrong length, non-finite loads or rates, a non-positive step, a body whose nodes lie on
/// one line (at build); a refused call leaves the state unchanged.
#[test]
fn invalid_inputs_as_the_other_free_methods() {
    use fxbody::solver::SolverError;
    let b = cube_body(false, 6, 2.0e4);
    let mut scene = b.scene();
    scene.w0 = [0.3, -0.2, 0.25];
    let mut sp = build(&scene, Method::Split, &Options::default()).unwrap();
    let mut im = build(&scene, Method::Implicit, &Options::default()).unwrap();
    sp.step(0.01).unwrap();
    im.step(0.01).unwrap();
    let n = 6 * b.x.len();
    let before = sp.state();
    let mut nan = vec![0.0; n];
    nan[3] = f64::NAN;
    for (what, bad) in [("short", vec![0.0; n - 1]), ("nan", nan)] {
        let (a, c) = (sp.set_loads(&bad), im.set_loads(&bad));
        assert!(a.is_err(), "{what}");
        assert_eq!(a, c, "{what}: loads");
        assert_eq!(
            sp.set_load_rates(&bad),
            im.set_load_rates(&bad),
            "{what}: rates"
        );
    }
    for h in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = sp.step(h).unwrap_err();
        assert!(matches!(e, SolverError::BadStep(_)), "{e}");
        assert_eq!(e.to_string(), im.step(h).unwrap_err().to_string());
    }
    assert_eq!(sp.state(), before, "refused calls leave the state");
    // A body on one line is refused where it is built (free::explicit::collinear_body_is_reported).
}
