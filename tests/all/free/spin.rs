//! A torque-free spin about a non-principal axis keeps its angular momentum when the
//! body's rigid part turns with it (the exact construction of the fixtures and of
//! `fxbody import`), and loses it at the rate the load-time warning announces when it
//! does not (the naive construction, `body::invariance`).
//!
//! The angular momentum is the formulation's own (FORMULATION.md section 3): with the
//! generalised momenta `p = M_R v_R + M_C(P) v_L` of the frame points (L1, L2, L3 at
//! `x_L0 + P e_j`, L0) and of the rotational DOFs, `L = sum_a x_a x p_a + p_rot`, about
//! the global origin. It is conserved by the equations whenever their kinetic energy does
//! not depend on the attitude, and independent of how a method integrates them.

use std::sync::Arc;

use crate::common::root;
use fxbody::body::Body;
use fxbody::body::invariance::{NAIVE_BEAM_DRIFT, NAIVE_BEAM_FIGURE, measure};
use fxbody::scene::Scene;
use fxbody::solver::free::Split;
use fxbody::solver::{Options, Solver, SolverWarning};
use nalgebra::{Matrix3, Vector3};

/// Step of every spin here (s): the split method's own error on the spin's angular
/// momentum is a bounded oscillation of about `(|w| h)^2 / 10` (2.4e-6 at 1 ms and this
/// spin rate, 6e-7 at 0.5 ms), so this step keeps it below the bound of the test.
const H: f64 = 5e-4;

/// Spin rate as a fraction of the first elastic frequency: slow enough that the body is
/// rigid in all but round-off (the centrifugal deflection is (0.018)^2 of the
/// elastic scale), the rate at which issue 28 measured the naive beam.
const RATE: f64 = 0.018;

/// The formulation's angular momentum about the origin (module text).
fn angular_momentum(body: &Body, s: &Split) -> Vector3<f64> {
    let f = s.frame().expect("a free body has a frame");
    let p = Matrix3::from_row_slice(&f.p);
    let v = s.velocity_coordinates();
    let (nr, nl) = (body.nr(), body.nl());
    let vl = v.rows(nr, nl);
    let mut momenta = body.m_r() * v.rows(0, nr);
    for k in 0..3 {
        for l in 0..3 {
            momenta += (&body.m_c()[3 * k + l] * vl) * p[(k, l)];
        }
    }
    let origin = Vector3::from(f.origin);
    let mut l = Vector3::zeros();
    for (j, o) in [0, 3, 6, 9].into_iter().enumerate() {
        let x = if j < 3 { origin + p.column(j) } else { origin };
        l += x.cross(&Vector3::new(momenta[o], momenta[o + 1], momenta[o + 2]));
    }
    if nr == 15 {
        l += Vector3::new(momenta[12], momenta[13], momenta[14]);
    }
    l
}

/// Spin `body` torque-free at `RATE` of its first elastic frequency about
/// `P0 (1, -2, 3)` (not a principal axis of any body here) for `steps` split steps of
/// `H`: the largest `|L - L0| / |L0|` over the run (sampled every 100 steps), the last
/// one, and the angle turned (rad). No step may warn.
fn spin(body: Body, steps: usize) -> (f64, f64, f64) {
    let (worst, last, turned, warning) = spin_with_step(body, steps, H);
    assert_eq!(warning, None);
    (worst, last, turned)
}

/// [`spin`] with steps of `h`, and the first solver warning of the run, if any (a body
/// whose modes drag rigid motion is warned about at the first step).
fn spin_with_step(body: Body, steps: usize, h: f64) -> (f64, f64, f64, Option<SolverWarning>) {
    let body = Arc::new(body);
    let w1 = 2.0 * std::f64::consts::PI * body.frequencies_hz()[0];
    let x0 = body.rigid_mode_positions().expect("free body");
    let mut scene = Scene::new(body.clone(), vec![0], vec![x0[0]]);
    let w = body.p0() * Vector3::new(1.0, -2.0, 3.0).normalize() * (RATE * w1);
    scene.w0 = [w[0], w[1], w[2]];
    let mut s = Split::new(&scene, &Options::default()).expect("split solver");
    let l0 = angular_momentum(&body, &s);
    let (mut worst, mut last, mut warning) = (0.0f64, 0.0, None);
    for k in 1..=steps {
        let warned = s.step(h).expect("spin step");
        warning = warning.or(warned);
        if k % 100 == 0 || k == steps {
            last = (angular_momentum(&body, &s) - l0).norm() / l0.norm();
            worst = worst.max(last);
        }
    }
    (worst, last, w.norm() * h * steps as f64, warning)
}

fn load(path: &str) -> Body {
    fxbody::body::load(&root().join(path), Default::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// The free-free beam as shipped (consistent mass, exact construction): over a million
/// split steps of 0.5 ms (500 s, 2,400 rad turned about a non-principal axis) its angular
/// momentum stays within 1e-6 of the start (measured 6.1e-7, a slow bounded oscillation
/// from the step, not a drift), and the load check has nothing to say. The same beam
/// built the naive way (tests/data/freefree_naive.fxb) is 1e-3 off after a tenth of the
/// run. Release build: about 15 s.
///
#[test]
fn exact_free_beam_keeps_its_angular_momentum_over_a_million_steps() {
    let body = load("fixtures/freefree.fxb");
    assert!(body.warnings().is_empty(), "{:?}", body.warnings());
    let (worst, last, turned) = spin(body, 1_000_000);
    println!(
        "exact free-free beam: {turned:.0} rad turned, |dL|/|L| at most {worst:.2e} \
         (last {last:.2e})"
    );
    assert!(turned > 2000.0);
    assert!(worst < 1e-6, "angular momentum off by {worst:.2e}");
    let (naive, _, turned) = spin(load("tests/data/freefree_naive.fxb"), 100_000);
    println!("naive free-free beam: {turned:.0} rad turned, |dL|/|L| {naive:.2e}");
    assert!(
        naive > 1e-3,
        "the naive beam keeps its momentum ({naive:.2e})?"
    );
}

/// Step of the truss's spin (s): the same 2.4e-3 rad per step as the beam's at `H` (the
/// truss's first elastic frequency, 483 Hz, is 11.4 times the beam's, and so is its
/// spin). At `H` itself (27,000 rad turned) the split method's own bounded error on the
/// truss's angular momentum is 5.0e-5, and 1.24e-5 at `H / 2`: the `(|w| h)^2`
/// oscillation of the module text, a quarter per halving, not a drift.
const H_TRUSS: f64 = 4.4e-5;

/// The truss tower as shipped (built as `fxbody import` builds a free body: local modes
/// M-orthogonal to the rigid motions, complete basis), spun as the beam above: over a
/// million split steps (44 s, 2,400 rad turned about a non-principal axis) its angular
/// momentum stays within 1e-6 of the start (measured 3.8e-7, last 1.9e-7), with no
/// warning at load or at any step. The truss built on a 3-2-1 support
/// (tests/data/truss_supported.fxb, modes that drag rigid motion, which the formulation
/// does not allow for: FORMULATION.md section 3) is warned about at its first step and
/// loses the formulation's angular momentum at once (measured 9.7 of it after 41 rad).
/// Release build: about 40 s on a loaded machine (the beam's run: 25 s in the same run).
#[test]
fn exact_free_truss_keeps_its_angular_momentum_over_a_million_steps() {
    let body = load("fixtures/truss.fxb");
    assert!(body.warnings().is_empty(), "{:?}", body.warnings());
    let (worst, last, turned, warning) = spin_with_step(body, 1_000_000, H_TRUSS);
    println!(
        "exact free truss: {turned:.0} rad turned, |dL|/|L| at most {worst:.2e} \
         (last {last:.2e})"
    );
    assert_eq!(warning, None);
    assert!(turned > 2000.0);
    assert!(worst < 1e-6, "angular momentum off by {worst:.2e}");
    let supported = load("tests/data/truss_supported.fxb");
    let (off, _, turned, warning) = spin_with_step(supported, 100_000, H_TRUSS);
    println!("supported truss: {turned:.0} rad turned, |dL|/|L| {off:.2e}");
    assert!(
        matches!(warning, Some(SolverWarning::ModesDragRigidMotion { .. })),
        "{warning:?}"
    );
    assert!(
        off > 1e-3,
        "the supported truss keeps its momentum ({off:.2e})?"
    );
}

/// The beam with its rigid part between the exact and the naive construction,
/// `M = M_exact + s (M_naive - M_exact)` for M_R and every M_C,kl: the invariance figure
/// grows as s, and the measured loss of angular momentum per radian turned is what the
/// warning estimates from the figure (`NAIVE_BEAM_DRIFT` per `NAIVE_BEAM_FIGURE`): within
/// 5 % at s = 1, where the constants were measured (so a change of the solvers or of
/// the figure's definition shows), and within 25 % at s = 0.3 and 0.1 (measured 9 % and
/// 11 % below the estimate: the loss is close to proportional to the figure).
#[test]
fn naive_rigid_part_loses_angular_momentum_at_the_warned_rate() {
    let exact = load("fixtures/freefree.fxb");
    let naive = load("tests/data/freefree_naive.fxb");
    let full = measure(&naive).unwrap().rigid_mass;
    for (s, tol) in [(1.0, 0.05), (0.3, 0.25), (0.1, 0.25)] {
        let mut parts = exact.clone().into_parts();
        parts.m_r = exact.m_r() + (naive.m_r() - exact.m_r()) * s;
        for (m, (e, n)) in parts
            .m_c
            .iter_mut()
            .zip(exact.m_c().iter().zip(naive.m_c()))
        {
            *m = e + (n - e) * s;
        }
        let b = Body::from_parts(parts, "blend").unwrap_or_else(|e| panic!("{e}"));
        let figure = measure(&b).unwrap().rigid_mass;
        assert!(
            (figure / (s * full) - 1.0).abs() < 1e-2,
            "figure {figure:.3e} at s = {s}, {full:.3e} at 1"
        );
        let (_, last, turned) = spin(b, 50_000);
        let per_rad = last / turned;
        let warned = NAIVE_BEAM_DRIFT * figure / NAIVE_BEAM_FIGURE;
        println!(
            "s = {s}: figure {figure:.3e}, drift {per_rad:.3e} per rad over {turned:.0} rad, \
             warned {warned:.3e}"
        );
        assert!(
            (per_rad / warned - 1.0).abs() < tol,
            "s = {s}: {per_rad:.3e} per rad measured, {warned:.3e} warned"
        );
    }
}
