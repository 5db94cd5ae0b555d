//! The explicit and split methods integrate the Radioss equations (FORMULATION.md
//! section 3): on a body whose local modes drag rigid motion they say so at load, with the
//! measured consequence and the remedy, through the solver's warning (the FMU passes it
//! on as fmi2Warning); the figures the warning quotes are measured here.

use std::sync::Arc;

use crate::common::root;
use fxbody::body::Body;
use fxbody::scene::Scene;
use fxbody::solver::free::{
    DRAG_WARN, TRUSS_DRAGGED, TRUSS_GAIN_EXPLICIT, TRUSS_GAIN_SPLIT, TRUSS_IMPLICIT_400,
    TRUSS_SPLIT_300,
};
use fxbody::solver::{Method, Options, SolverWarning, build};
use nalgebra::{DMatrix, Vector3};

fn load(path: &str) -> Body {
    fxbody::body::load(&root().join(path), Default::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// The dragged fraction written out from the body's matrices by another route than the
/// solver's (an `nl x nl` symmetric eigenproblem instead of a 6 x 6 one): the largest
/// eigenvalue of `diag(m_L)^-1/2 B M6^-1 B^T diag(m_L)^-1/2`, `B = M_C(P0)^T G(P0)`, with
/// `G` the frame points' velocities of the rigid motion `(V, omega)` (section 2: L1..L3
/// at rows 0..9 move with `V + omega x e_j`, L0 at rows 9..12 with `V`, the rotational
/// DOFs with `omega`).
fn dragged(body: &Body) -> f64 {
    let (nr, nl) = (body.nr(), body.nl());
    let p = body.p0();
    let mut g = DMatrix::<f64>::zeros(nr, 6);
    for pt in 0..4 {
        let o = if pt < 3 { 3 * pt } else { 9 };
        for c in 0..3 {
            g[(o + c, c)] = 1.0;
        }
        if pt < 3 {
            let e: Vector3<f64> = p.column(pt).into_owned();
            for a in 0..3 {
                let r = Vector3::ith(a, 1.0).cross(&e);
                for c in 0..3 {
                    g[(o + c, 3 + a)] = r[c];
                }
            }
        }
    }
    if nr == 15 {
        for a in 0..3 {
            g[(12 + a, 3 + a)] = 1.0;
        }
    }
    let mut mc = DMatrix::<f64>::zeros(nr, nl);
    for k in 0..3 {
        for l in 0..3 {
            mc += &body.m_c()[3 * k + l] * p[(k, l)];
        }
    }
    let b = mc.transpose() * &g;
    let m6 = g.transpose() * body.m_r() * &g;
    let d = DMatrix::from_fn(nl, nl, |i, j| {
        (body.m_l()[i] * body.m_l()[j]).sqrt().recip()
    });
    let x = (&b * m6.try_inverse().unwrap() * b.transpose()).component_mul(&d);
    ((&x + x.transpose()) * 0.5)
        .symmetric_eigen()
        .eigenvalues
        .max()
}

/// The first step's warning of `method` on `path`, at rest (no spin warning).
fn first_warning(path: &str, method: Method) -> Option<SolverWarning> {
    let body = Arc::new(load(path));
    let x0 = body.rigid_mode_positions().expect("free body");
    let scene = Scene::new(body, vec![0], vec![x0[0]]);
    let mut s = build(&scene, method, &Options::default()).expect("solver");
    let first = s.step(1e-3).expect("step");
    let second = s.step(1e-3).expect("step");
    assert_eq!(second, None, "warned once");
    first
}

/// The truss tower's modes come from a support: the first step of the explicit and of
/// the split method warns with the dragged fraction (equal to the independent figure
/// above to 1e-9), the figure the message quotes for the truss (`TRUSS_DRAGGED`, the
/// same to 1e-3), the method's measured energy gain per radian and the remedy (the
/// implicit method); the implicit method does not warn. The free-free beam (exact
/// construction) drags nothing but round-off (8.5e-21) and is not warned about. The
/// defect it guards against, the check absent from either method, fails the first
/// assertion for that method (no warning on the truss).
#[test]
fn explicit_and_split_warn_at_load_when_modes_drag_rigid_motion() {
    let want = dragged(&load("fixtures/truss.fxb"));
    for (method, gain) in [
        (Method::Explicit, fxbody::num::num(TRUSS_GAIN_EXPLICIT)),
        (Method::Split, fxbody::num::num(TRUSS_GAIN_SPLIT)),
    ] {
        let Some(w @ SolverWarning::ModesDragRigidMotion { fraction, split }) =
            first_warning("fixtures/truss.fxb", method)
        else {
            panic!("no drag warning on the truss from {method:?}");
        };
        println!(
            "truss, {method:?}: dragged fraction {fraction:.6e} (independent {want:.6e})\n{w}"
        );
        assert_eq!(split, method == Method::Split);
        assert!(fraction > DRAG_WARN);
        assert!(
            (fraction / want - 1.0).abs() < 1e-9,
            "{fraction:e} vs {want:e}"
        );
        assert!((TRUSS_DRAGGED / fraction - 1.0).abs() < 1e-3);
        let text = w.to_string();
        let name = format!("the {} method", if split { "split" } else { "explicit" });
        for part in [
            name.as_str(),
            "energy per radian",
            "Use the implicit method",
            &gain,
        ] {
            assert!(text.contains(part), "message lacks {part:?}: {text}");
        }
    }
    assert_eq!(first_warning("fixtures/truss.fxb", Method::Implicit), None);
    let path = "fixtures/freefree.fxb";
    let figure = dragged(&load(path));
    println!("{path}: dragged fraction {figure:.3e}");
    assert!(figure < 1e-3 * DRAG_WARN);
    for method in [Method::Explicit, Method::Split] {
        assert_eq!(
            first_warning(path, method),
            None,
            "{path} warned by {method:?}"
        );
    }
}

/// The relative energy change per radian of the truss spun torque-free at 0.018 of its
/// first frequency about `P0 (1, -2, 3)` by `method` with 1 ms steps over `rad` radians,
/// and the change over the whole run.
fn energy_change(method: Method, rad: f64) -> (f64, f64) {
    let body = Arc::new(load("fixtures/truss.fxb"));
    let w1 = 2.0 * std::f64::consts::PI * body.frequencies_hz()[0];
    let x0 = body.rigid_mode_positions().expect("free body");
    let mut scene = Scene::new(body.clone(), vec![0], vec![x0[0]]);
    let w = body.p0() * Vector3::new(1.0, -2.0, 3.0).normalize() * (0.018 * w1);
    scene.w0 = [w[0], w[1], w[2]];
    let h = 1e-3;
    let mut s = build(&scene, method, &Options::default()).expect("solver");
    let e0 = s.kinetic_energy() + s.strain_energy();
    let steps = (rad / (w.norm() * h)).round() as usize;
    for _ in 0..steps {
        s.step(h).expect("spin step");
    }
    let de = (s.kinetic_energy() + s.strain_energy()) / e0 - 1.0;
    let turned = w.norm() * h * steps as f64;
    println!("truss, {method:?}: {turned:.1} rad turned, dE/E {de:+.3e}");
    (de / turned, de)
}

/// The figures the warning quotes, measured: the explicit method's energy gain per
/// radian over 27 rad (`TRUSS_GAIN_EXPLICIT`), the split method's over its first 100 rad
/// (`TRUSS_GAIN_SPLIT`) and in all after 300 rad (`TRUSS_SPLIT_300`), the implicit
/// method's change over 400 rad (`TRUSS_IMPLICIT_400`), each within 10 %. Reference: the
/// exact equations conserve the energy (study/spin_reference.py integrates them and
/// keeps the truss's energy to 1e-8 over this spin), so every change measured here is
/// the method's and its equations'. About 20 s in a release build.
#[test]
fn drag_gain_figures() {
    // (method, radians, per radian (else in all), quoted figure)
    for (method, rad, per_rad, quoted) in [
        (Method::Explicit, 27.0, true, TRUSS_GAIN_EXPLICIT),
        (Method::Split, 100.0, true, TRUSS_GAIN_SPLIT),
        (Method::Split, 300.0, false, TRUSS_SPLIT_300),
        (Method::Implicit, 400.0, false, TRUSS_IMPLICIT_400),
    ] {
        let (rate, total) = energy_change(method, rad);
        let got = if per_rad { rate } else { total };
        assert!(
            (got / quoted - 1.0).abs() < 0.1,
            "{method:?} over {rad} rad: measured {got:.3e}, quoted {quoted:.3e}"
        );
    }
}
