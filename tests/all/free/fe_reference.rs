//! The free-free beam fixture (fixtures/freefree.*) against its full finite-element
//! reference (freefree.ref.json: exact modal superposition with all FE modes, rigid
//! modes integrated exactly), and the momentum balance of a force pulse.

use std::sync::Arc;

use crate::common::fixture;
use fxbody::body::Body;
use fxbody::body::load as load_body;
use fxbody::fxb::coords::{read_coords, to_map};
use fxbody::scene::Scene;
use fxbody::solver::{Method, Options, Solver, build};
use nalgebra::{DVector, Matrix3, Vector3};

/// Numbers of a JSON array (the reference's time series).
fn nums(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

struct Fixture {
    body: Arc<Body>,
    reference: serde_json::Value,
    coords: std::collections::HashMap<i64, [f64; 3]>,
}

fn named(name: &str) -> Fixture {
    let body = Arc::new(
        load_body(&fixture(&format!("{name}.fxb")), Default::default()).expect("fixture loads"),
    );
    let text = std::fs::read_to_string(fixture(&format!("{name}.ref.json"))).unwrap();
    let coords = to_map(&read_coords(&fixture(&format!("{name}.nodes.rad"))).unwrap());
    Fixture {
        body,
        reference: serde_json::from_str(&text).unwrap(),
        coords,
    }
}

impl Fixture {
    fn scene(&self, ids: &[i64]) -> Scene {
        let nodes: Vec<usize> = ids
            .iter()
            .map(|&id| self.body.node_index(id).unwrap())
            .collect();
        let x0 = ids.iter().map(|id| self.coords[id]).collect();
        Scene::new(self.body.clone(), nodes, x0)
    }
}

/// Linear momentum of the formulation, `s_c^T (M_R v_R + M_C(P) v_L)` per direction c,
/// from the body's matrices and the solver's coordinate velocities.
fn momentum(body: &Body, v: &DVector<f64>, p: &Matrix3<f64>) -> Vector3<f64> {
    let nr = body.nr();
    let vr = v.rows(0, nr);
    let vl = v.rows(nr, body.nl());
    let mut mv = body.m_r() * vr;
    for k in 0..3 {
        for l in 0..3 {
            mv += p[(k, l)] * (&body.m_c()[3 * k + l] * vl);
        }
    }
    Vector3::from_fn(|c, _| (0..4).map(|j| mv[3 * j + c]).sum())
}

/// Run one response case of the reference and return the largest error of the tip and
/// mid-node displacements, relative to the largest reference displacement.
fn response_error(method: Method, case: &str, stride: usize) -> (f64, f64) {
    response_error_on("freefree", method, case, stride)
}

fn response_error_on(name: &str, method: Method, case: &str, stride: usize) -> (f64, f64) {
    let fx = named(name);
    let r = fx.reference["responses"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["name"] == case)
        .unwrap()
        .clone();
    let tip = fx.reference["tip_node"].as_f64().unwrap() as i64;
    let ids: Vec<i64> = r["nodes"]
        .as_object()
        .unwrap()
        .keys()
        .map(|k| k.parse().unwrap())
        .collect();
    assert_eq!(r["load_dof"], "fy");
    assert_eq!(r["load_node"].as_f64().unwrap() as i64, tip);
    let amp = r["amplitude"].as_f64().unwrap();
    let duration = r["duration"].as_f64().unwrap_or(f64::INFINITY);
    let t = nums(&r["t"]);
    let scene = fx.scene(&ids);
    let tip_k = ids.iter().position(|&i| i == tip).unwrap();
    let mut s = build(&scene, method, &Options::default()).unwrap();
    let x0: Vec<f64> = ids.iter().flat_map(|id| fx.coords[id]).collect();
    let mut x = vec![0.0; x0.len()];
    let mut loads = vec![0.0; 6 * ids.len()];
    let refs: Vec<[Vec<f64>; 3]> = ids
        .iter()
        .map(|id| {
            let n = &r["nodes"][id.to_string()];
            [nums(&n["ux"]), nums(&n["uy"]), nums(&n["uz"])]
        })
        .collect();
    let peak = refs
        .iter()
        .flat_map(|c| c.iter().flat_map(|v| v.iter()))
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst: f64 = 0.0;
    let mut n = 0;
    while n + stride < t.len() {
        let h = t[n + stride] - t[n];
        let on = t[n] < duration - 1e-12;
        loads[6 * tip_k + 1] = if on { amp } else { 0.0 };
        s.set_loads(&loads).unwrap();
        s.step(h).unwrap();
        n += stride;
        s.positions(&mut x);
        for (k, rc) in refs.iter().enumerate() {
            for c in 0..3 {
                let u = x[3 * k + c] - x0[3 * k + c];
                worst = worst.max((u - rc[c][n]).abs());
            }
        }
    }
    (worst / peak, peak)
}

/// Pulse of 0.1 N for 2 ms at the tip, explicit: tip and mid-node displacements (all
/// three components, 70 ms) within 1.7e-3 of the peak of the full-FE reference: twice
/// the 8.5e-4 measured, which is the reduction's own error (10 of the beam's modes kept:
/// the split method at 25 us, exact between samples, misses by the same 8.5e-4).
#[test]
fn pulse_explicit_matches_fe() {
    let (err, peak) = response_error(Method::Explicit, "pulse", 1);
    println!("explicit pulse: error {err:.3e} of peak {peak:.3e} m");
    assert!(err < 1.7e-3, "explicit pulse error {err:.3e} of the peak");
}

/// Step load of 0.1 N at the tip, explicit: within 1.3e-3 of the peak of the FE
/// reference (measured 6.3e-4, the reduction's share as above).
#[test]
fn step_explicit_matches_fe() {
    let (err, peak) = response_error(Method::Explicit, "step", 1);
    println!("explicit step: error {err:.3e} of peak {peak:.3e} m");
    assert!(err < 1.3e-3, "explicit step error {err:.3e} of the peak");
}

/// Implicit at the reference sampling (25 us): the pulse within 1e-2 of the peak
/// (measured 6.7e-3: the method's period error on the 300-800 Hz modes the pulse
/// excites, over 70 ms), the step within 1.3e-3 (measured 6.2e-4, the reduction's
/// share).
#[test]
fn implicit_matches_fe() {
    for (case, tol) in [("pulse", 1e-2), ("step", 1.3e-3)] {
        let (err, peak) = response_error(Method::Implicit, case, 1);
        println!("implicit {case}, h = 25 us: error {err:.3e} of peak {peak:.3e} m");
        assert!(err < tol, "implicit {case} error {err:.3e} of the peak");
    }
}

/// Implicit with 100 us steps (omega_max h = 0.5, 20 steps in the pulse): the pulse
/// response stays within 3 % of the peak (the 2.6 % measured is the second-order period
/// error of the 300-800 Hz modes accumulated over 70 ms, about (omega h)^2/12 per
/// radian), the step response, dominated by the rigid motion, within 1.2e-3 (measured
/// 6.0e-4).
#[test]
fn implicit_large_step_matches_fe() {
    for (case, tol) in [("pulse", 0.03), ("step", 1.2e-3)] {
        let (err, peak) = response_error(Method::Implicit, case, 4);
        println!("implicit {case}, h = 100 us: error {err:.3e} of peak {peak:.3e} m");
        assert!(err < tol, "implicit {case} error {err:.3e} of the peak");
    }
}

/// The truss tower (Irot = 0, 12 rigid modes with their affine part, free-free local
/// modes and 3 inertia-relief static modes with a full static block of K_L; complete
/// modal basis, so no reduction error): pulse and step at the tip against the FE
/// reference, within about twice what was measured: explicit 1.06e-4 and 3.15e-5 of the
/// peak, implicit 1.06e-4 and 3.08e-5. (When the shipped truss's modes came from a 3-2-1
/// support, now tests/data/truss_supported.fxb, the implicit pulse was 1.2e-3 off,
/// which was put down to its period error on the kilohertz modes of the pulse.)
#[test]
fn truss_matches_fe() {
    for (method, tols) in [
        (Method::Explicit, [2.2e-4, 6.5e-5]),
        (Method::Implicit, [2.2e-4, 6.5e-5]),
    ] {
        for (case, tol) in ["pulse", "step"].into_iter().zip(tols) {
            let (err, peak) = response_error_on("truss", method, case, 1);
            println!("truss {method:?} {case}: error {err:.3e} of peak {peak:.3e} m");
            assert!(
                err < tol,
                "truss {method:?} {case}: error {err:.3e} of the peak"
            );
        }
    }
}

/// The pulse on the fixtures: the momentum change equals the impulse.
///
/// The free-free beam, exact to round-off (measured 5.9e-16 at the end of the pulse,
/// 3.1e-15 over the 2000 steps after; bound 1e-13): with the rotation on the rigid mode,
/// `s^T M_C(P) = (uniform translation)^T M Phi_L` at every attitude, zero for free-free
/// modes, so the formulation's missing `d(M_C)/dt v_L` term does not reach the momentum.
/// (Written the naive way, the beam's `s^T M_C` was 1.6e-4 and the momentum missed the
/// impulse by up to 3e-8.) The truss, the same way: 5.1e-11 at the end of the pulse,
/// 5.9e-11 at most over the 2000 steps after (bounds 1e-9): its free-free modes make
/// `s^T M_C(P)` zero too, but through the file's 10 digits (a translation is the sum of
/// four affine rigid modes, whose rows of M_C do not vanish one by one and cancel to
/// the file's rounding). With local modes from a 3-2-1 support (the truss as once
/// shipped, tests/data/truss_supported.fxb: `s^T M_C != 0`) it was 3.9e-8 and 2.1e-6.
#[test]
fn pulse_momentum_equals_impulse_on_fixture() {
    for (name, tol_end, tol_after) in [("freefree", 1e-13, 1e-13), ("truss", 1e-9, 1e-9)] {
        let (at_end, after) = fixture_impulse(name);
        assert!(
            at_end < tol_end,
            "{name}: momentum change vs impulse: {at_end:.2e}"
        );
        assert!(
            after < tol_after,
            "{name}: momentum after the pulse: {after:.2e}"
        );
    }
}

fn fixture_impulse(name: &str) -> (f64, f64) {
    let fx = named(name);
    let tip = fx.reference["tip_node"].as_f64().unwrap() as i64;
    let scene = fx.scene(&[tip]);
    let mut s = fxbody::solver::free::Explicit::new(&scene, &Options::default()).unwrap();
    let f = Vector3::new(0.03, 0.1, -0.05);
    let mut loads = [0.0; 6];
    loads[..3].copy_from_slice(f.as_slice());
    s.set_loads(&loads).unwrap();
    let h = 2.5e-5;
    let p_at = |s: &fxbody::solver::free::Explicit| {
        let f = s.frame().unwrap();
        momentum(
            &fx.body,
            &s.velocity_coordinates(),
            &Matrix3::from_row_slice(&f.p),
        )
    };
    let p0 = p_at(&s);
    for _ in 0..80 {
        s.step(h).unwrap();
    }
    let impulse = f * (80.0 * h);
    let at_end = (p_at(&s) - p0 - impulse).norm() / impulse.norm();
    let mut err: f64 = 0.0;
    println!("{name}: impulse error at the end of the pulse {at_end:.2e}");
    s.set_loads(&[0.0; 6]).unwrap();
    for _ in 0..2000 {
        s.step(h).unwrap();
        err = err.max((p_at(&s) - p0 - impulse).norm() / impulse.norm());
    }
    println!("{name}: impulse error, largest over 2000 more steps {err:.2e}");
    (at_end, err)
}

/// A long swing of the free-free beam under a constant global force at its tip (it turns
/// into the force and swings like a pendulum), implicit at 20 x 0.9 dt_fx for 18 s: every
/// step converges, the frame stays orthonormal to 1e-9, and the work-energy balance
/// `KE + SE = F . (x_tip - x_tip0)` holds within 1e-6 of the work done (measured 4.9e-7).
#[test]
fn implicit_long_swing_energy_balance() {
    let fx = named("freefree");
    let tip = fx.reference["tip_node"].as_f64().unwrap() as i64;
    let scene = fx.scene(&[tip]);
    let body = &scene.body;
    let dt_fx = fxbody::body::stable_step(*body.frequencies_hz().last().unwrap(), 0.0);
    let h = 20.0 * 0.9 * dt_fx;
    let mut s = build(&scene, Method::Implicit, &Options::default()).unwrap();
    let f = Vector3::new(0.0, 0.1, 0.0);
    let mut loads = [0.0; 6];
    loads[..3].copy_from_slice(f.as_slice());
    s.set_loads(&loads).unwrap();
    let x0 = Vector3::from(fx.coords[&tip]);
    let (mut worst, mut frame, mut wmax) = (0.0f64, 0.0f64, 0.0f64);
    let mut x = [0.0; 3];
    for _ in 0..(18.0 / h) as usize {
        s.step(h).unwrap();
        s.positions(&mut x);
        let work = f.dot(&(Vector3::from(x) - x0));
        wmax = wmax.max(work.abs());
        worst = worst.max((s.kinetic_energy() + s.strain_energy() - work).abs());
        let p = Matrix3::from_row_slice(&s.frame().unwrap().p);
        frame = frame.max((p.transpose() * p - Matrix3::identity()).abs().max());
    }
    println!(
        "long swing: energy balance {:.2e} of the work {wmax:.3e} J, frame {frame:.1e}",
        worst / wmax
    );
    assert!(frame < 1e-9, "frame {frame:.2e}");
    assert!(
        worst < 1e-6 * wmax,
        "energy balance {:.2e} of the work",
        worst / wmax
    );
}

/// The split method at a master's step: the free-free pulse and step at 25 us, 100 us
/// and 400 us (one step per reference sample, every 4th, every 16th) and the truss at
/// its sampling, against the FE reference: free-free pulse within 1.2e-3 and step
/// within 8e-4 of the peak at every step (the reduction's own error, the explicit method
/// at 25 us: 8.5e-4 and 6.3e-4; measured 8.4e-4 and 6.2e-4 at all three steps), truss
/// (complete modal basis, so no reduction error) within 1.1e-4 (pulse) and 3.5e-5
/// (step): measured 5.5e-5 and 1.7e-5.
#[test]
fn split_matches_fe_at_large_steps() {
    for stride in [1, 4, 16] {
        for case in ["pulse", "step"] {
            let (err, peak) = response_error(Method::Split, case, stride);
            println!("split {case}, stride {stride}: error {err:.3e} of peak {peak:.3e} m");
            let tol = if case == "pulse" { 1.2e-3 } else { 8e-4 };
            assert!(err < tol, "split {case} stride {stride}: error {err:.3e}");
        }
    }
    for case in ["pulse", "step"] {
        let (err, peak) = response_error_on("truss", Method::Split, case, 1);
        println!("truss split {case}: error {err:.3e} of peak {peak:.3e} m");
        let tol = if case == "pulse" { 1.1e-4 } else { 3.5e-5 };
        assert!(err < tol, "truss split {case}: error {err:.3e} of the peak");
    }
}
