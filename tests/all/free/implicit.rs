//! The implicit (generalised-alpha) free-body method against independent references:
//! conservation laws, closed-form rigid motion, its own convergence order, the explicit
//! reference scheme on a slow loaded tumble, and the Irot = 1 frame rate.

use crate::common::springs::*;
use fxbody::solver::free::{Explicit, Implicit};
use fxbody::solver::{Method, Options, Solver, SolverError, build};
use nalgebra::{Matrix3, Vector3};

/// Free flight without load, 5,000 steps of 10 ms (about 25 times dt_fx) at
/// rho_inf = 0.9: momentum exact (1e-12), angular momentum and energy within 2e-6 over
/// the run (below 1e-6 per 1,000 steps), frame orthonormal to 1e-12.
#[test]
fn free_flight_conserves() {
    for irot in [false, true] {
        let b = cube_body(irot, 6, 2.0e4);
        let mut scene = b.scene();
        scene.v0 = [0.3, -0.2, 0.1];
        scene.w0 = [0.5, 0.3, -0.4];
        let mut s = Implicit::new(&scene, &Options::default()).unwrap();
        let (p0, l0, e0) = (
            momentum(&b, &s),
            angular_momentum(&b, &s),
            s.kinetic_energy(),
        );
        let (mut pe, mut le, mut ee, mut fe) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let mut per_k = 0.0f64;
        let mut l_prev = l0;
        for k in 1..=5000 {
            s.step(0.01).unwrap();
            let l = angular_momentum(&b, &s);
            pe = pe.max((momentum(&b, &s) - p0).norm() / p0.norm());
            le = le.max((l - l0).norm() / l0.norm());
            ee = ee.max(((s.kinetic_energy() + s.strain_energy()) - e0).abs() / e0);
            fe = fe.max(frame_error(&s));
            if k % 1000 == 0 {
                per_k = per_k.max((l - l_prev).norm() / l0.norm());
                l_prev = l;
            }
        }
        println!(
            "implicit irot={irot}: momentum {pe:.1e}, angular momentum {le:.2e} (per 1000 \
             steps {per_k:.2e}), energy {ee:.2e}, frame {fe:.1e}"
        );
        assert!(pe < 1e-12, "momentum {pe:.2e}");
        assert!(
            per_k < 1e-6,
            "angular momentum drift per 1000 steps {per_k:.2e}"
        );
        assert!(le < 2e-6, "angular momentum {le:.2e}");
        assert!(ee < 2e-6, "energy {ee:.2e}");
        assert!(fe < 1e-12, "frame {fe:.2e}");
    }
}

/// Mass-proportional forces and gravity together: the centre of mass follows
/// `v0 t + (F/m + g) t^2 / 2` exactly (1e-10) and the body does not deform.
#[test]
fn uniform_loads_move_the_centre_of_mass_exactly() {
    let b = cube_body(true, 6, 2.0e4);
    let mut scene = b.scene();
    scene.gravity = [0.0, 0.0, -9.81];
    scene.v0 = [0.5, 0.0, 1.0];
    let mut s = Implicit::new(&scene, &Options::default()).unwrap();
    let acc = Vector3::new(1.0, -2.0, 0.0);
    let mut loads = vec![0.0; 6 * b.x.len()];
    for (k, m) in b.mass.iter().enumerate() {
        for c in 0..3 {
            loads[6 * k + c] = m * acc[c];
        }
    }
    s.set_loads(&loads).unwrap();
    let c0 = centre_of_mass(&b, &s);
    let total = acc + Vector3::from(scene.gravity);
    for n in 1..=50 {
        s.step(0.02).unwrap();
        let t = n as f64 * 0.02;
        let want = c0 + Vector3::from(scene.v0) * t + total * (t * t / 2.0);
        let err = (centre_of_mass(&b, &s) - want).norm() / (total.norm() * t * t / 2.0);
        assert!(err < 1e-10, "t={t}: err {err:.2e}");
    }
    let amax = s.modal().iter().fold(0.0f64, |m, a| m.max(a.abs()));
    assert!(amax < 1e-12, "modal amplitudes {amax:.2e}");
}

/// Positions after 1 s of a loaded tumble on a soft body (all modes resolved), for a
/// step h.
pub(super) fn tumble(method: Method, h: f64, stiffness: f64, opts: &Options) -> Vec<f64> {
    let b = cube_body(true, 6, stiffness);
    let mut scene = b.scene();
    scene.w0 = [0.3, -0.2, 0.25];
    scene.v0 = [0.1, 0.0, -0.1];
    let mut s = build(&scene, method, opts).unwrap();
    let mut loads = vec![0.0; 6 * b.x.len()];
    loads[6 * 6] = 2.0;
    loads[6 * 6 + 2] = -1.0;
    loads[6 * 2 + 4] = 0.5;
    s.set_loads(&loads).unwrap();
    s.set_load_rates(&vec![0.2; loads.len()]).unwrap();
    let n = (1.0 / h).round() as usize;
    for _ in 0..n {
        s.step(h).unwrap();
    }
    let mut x = vec![0.0; 3 * b.x.len()];
    s.positions(&mut x);
    x.iter()
        .zip(b.x.iter().flatten())
        .map(|(x, x0)| x - x0)
        .collect()
}

pub(super) fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Second order: halving the step divides the error by about 4 (ratios within 3.2 to
/// 4.8), against a run with a 16 times smaller step.
#[test]
fn second_order() {
    let opts = Options::default();
    let fine = tumble(Method::Implicit, 1.0 / 1600.0, 200.0, &opts);
    let errs: Vec<f64> = [100.0, 200.0, 400.0]
        .iter()
        .map(|n| max_diff(&tumble(Method::Implicit, 1.0 / n, 200.0, &opts), &fine))
        .collect();
    println!(
        "implicit errors at h = 1/100, 1/200, 1/400: {:.3e} {:.3e} {:.3e}",
        errs[0], errs[1], errs[2]
    );
    for k in 0..2 {
        let r = errs[k] / errs[k + 1];
        assert!((3.2..4.8).contains(&r), "error ratio {r:.2} at halving {k}");
    }
}

/// Explicit (reference scheme, sub-cycled) and implicit (h = 1 ms) agree within 0.1 % of
/// the largest displacement after a slow loaded tumble of 1 s on a stiff body.
#[test]
fn explicit_and_implicit_agree() {
    let opts = Options::default();
    let e = tumble(Method::Explicit, 1e-3, 2.0e4, &opts);
    let i = tumble(Method::Implicit, 1e-3, 2.0e4, &opts);
    let peak = e.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let d = max_diff(&e, &i) / peak;
    println!("explicit vs implicit: {d:.2e} of the peak displacement {peak:.3e}");
    assert!(
        d < 1e-3,
        "explicit and implicit differ by {d:.2e} of the peak"
    );
}

/// Irot = 1: the rotational DOF rates equal the frame angular velocity of section 2 at
/// every step (velocity constraint, 1e-10), and follow the frame's actual rotation
/// between steps (rotation vector of `P_(k+1) P_k^T` over h vs the mean rate, 1e-4).
#[test]
fn rotational_dofs_follow_frame() {
    let b = cube_body(true, 6, 2.0e4);
    let mut scene = b.scene();
    scene.w0 = [0.8, -0.6, 0.4];
    let mut s = Implicit::new(&scene, &Options::default()).unwrap();
    let mut loads = vec![0.0; 6 * b.x.len()];
    loads[6 * 3 + 1] = 20.0;
    loads[6 * 5 + 5] = 3.0;
    s.set_loads(&loads).unwrap();
    let h = 0.01;
    let frame = |s: &Implicit| Matrix3::from_row_slice(&s.frame().unwrap().p);
    let rates = |s: &Implicit| {
        let v = s.velocity_coordinates();
        Vector3::new(v[12], v[13], v[14])
    };
    let (mut worst_c, mut worst_f) = (0.0f64, 0.0f64);
    for _ in 0..200 {
        let (p_a, r_a) = (frame(&s), rates(&s));
        s.step(h).unwrap();
        let (p_b, r_b) = (frame(&s), rates(&s));
        // Section 2 formula, written out here: omega = P (-e2.de3, e1.de3, -e1.de2).
        let v = s.velocity_coordinates();
        let de =
            |j: usize| Vector3::new(v[3 * j] - v[9], v[3 * j + 1] - v[10], v[3 * j + 2] - v[11]);
        let (e1, e2) = (p_b.column(0).into_owned(), p_b.column(1).into_owned());
        let wl = Vector3::new(-e2.dot(&de(2)), e1.dot(&de(2)), -e1.dot(&de(1)));
        let w_formula = p_b * wl;
        worst_c = worst_c.max((r_b - w_formula).norm() / w_formula.norm());
        let r = p_b * p_a.transpose();
        let angle = ((r.trace() - 1.0) / 2.0).clamp(-1.0, 1.0).acos();
        let axis = Vector3::new(
            r[(2, 1)] - r[(1, 2)],
            r[(0, 2)] - r[(2, 0)],
            r[(1, 0)] - r[(0, 1)],
        );
        let w_frame = axis * (angle / (2.0 * angle.sin() * h));
        worst_f = worst_f.max(((r_a + r_b) / 2.0 - w_frame).norm() / w_frame.norm());
    }
    println!(
        "implicit rotational rates: constraint {worst_c:.2e}, vs frame rotation {worst_f:.2e}"
    );
    assert!(worst_c < 1e-10, "velocity constraint {worst_c:.2e}");
    assert!(worst_f < 1e-4, "vs frame rotation {worst_f:.2e}");
}

/// Saving and restoring the state continues bit for bit; rho_inf outside [0, 0.99] is
/// refused with a reason.
#[test]
fn restart_and_options() {
    let b = cube_body(false, 6, 2.0e4);
    let mut scene = b.scene();
    scene.w0 = [0.3, 0.2, -0.5];
    let mut s = build(&scene, Method::Implicit, &Options::default()).unwrap();
    let mut loads = vec![0.0; 6 * b.x.len()];
    loads[4] = 2.0;
    s.set_loads(&loads).unwrap();
    for _ in 0..5 {
        s.step(0.02).unwrap();
    }
    let saved = s.state();
    let run = |s: &mut Box<dyn Solver>| {
        for _ in 0..7 {
            s.step(0.017).unwrap();
        }
        s.state()
    };
    let first = run(&mut s);
    let mut other = build(&scene, Method::Implicit, &Options::default()).unwrap();
    other.set_state(&saved).unwrap();
    assert_eq!(first, run(&mut other));
    for rho in [1.0, -0.1, f64::NAN] {
        let opts = Options {
            rho_inf: rho,
            ..Options::default()
        };
        assert!(matches!(
            Implicit::new(&scene, &opts),
            Err(SolverError::Unsupported { .. })
        ));
    }
    let _ = Explicit::new(&scene, &Options::default()).unwrap();
}
