//! Issue 13 on free bodies: a free body stays a rigid frame plus small deformation, or
//! says it does not. One test per class: a bad value in, the refusal (or warning) with
//! its figures and the state unchanged out, then recovery; and a long run under torque
//! against the analytic spin-up about a principal axis.

use crate::common::{data_scene, fixture_scene};
use fxbody::scene::Scene;
use fxbody::solver::free::{Explicit, MAX_FRAME_ERROR, MAX_HALVINGS, SPIN_STEP, SPIN_WARN_RATIO};
use fxbody::solver::{MAX_INTERNAL_STEPS, Method, Options, Solver, SolverError, build};
use nalgebra::{Matrix3, Vector3};

/// A fixture body with one node exposed.
fn scene(name: &str, node: i64) -> Scene {
    fixture_scene(name, &[node])
}

/// Column `j` of P0 (local axis j in global components).
fn axis(sc: &Scene, j: usize) -> Vector3<f64> {
    sc.body.p0().column(j).into_owned()
}

fn frame_error(s: &dyn Solver) -> f64 {
    let p = Matrix3::from_row_slice(&s.frame().unwrap().p);
    (p.transpose() * p - Matrix3::identity()).abs().max()
}

/// First local mode's circular frequency (rad/s).
fn omega1(sc: &Scene) -> f64 {
    2.0 * std::f64::consts::PI * sc.body.frequencies_hz()[0]
}

/// Class 1: a step that needs more internal steps than the budget is refused at once
/// with the count and the largest step that fits; the state is unchanged; a normal step
/// follows. At rest the internal step is 0.9 dt_fx; spinning, SPIN_STEP / |omega|.
#[test]
fn explicit_step_over_the_budget_is_refused_before_work() {
    for w in [0.0, 60.0] {
        let mut sc = scene("freefree", 511);
        let e3 = axis(&sc, 2) * w;
        sc.w0 = [e3[0], e3[1], e3[2]];
        let mut s = Explicit::new(&sc, &Options::default()).unwrap();
        let internal = if w == 0.0 {
            0.9 * s.stable_step()
        } else {
            (0.9 * s.stable_step()).min(SPIN_STEP / w)
        };
        let before = s.state();
        let t0 = std::time::Instant::now();
        match s.step(1e300) {
            Err(SolverError::TooManySteps {
                h,
                steps,
                internal: i,
                max_h,
            }) => {
                assert_eq!(h, 1e300);
                assert!((steps / (1e300 / internal) - 1.0).abs() < 1e-9, "{steps}");
                assert!((i / internal - 1.0).abs() < 1e-9, "{i} vs {internal}");
                assert!((max_h / (MAX_INTERNAL_STEPS * internal) - 1.0).abs() < 1e-9);
            }
            other => panic!("expected TooManySteps, got {other:?}"),
        }
        // "At once": no internal step was taken (a single one would change the state).
        assert_eq!(s.state(), before);
        let msg = s.step(1e300).unwrap_err().to_string();
        assert!(
            msg.contains("1e300") && msg.contains("use steps of at most"),
            "{msg}"
        );
        println!("w = {w}: {msg} ({:.1e} s)", t0.elapsed().as_secs_f64());
        // Just over the budget is refused; just under runs.
        let max_h = MAX_INTERNAL_STEPS * internal;
        assert!(matches!(
            s.step(max_h * 1.01),
            Err(SolverError::TooManySteps { .. })
        ));
        s.step(1e-3).unwrap();
        assert!(s.time() == 1e-3 && frame_error(&s) < 1e-7);
    }
}

/// Class 1, implicit: its work per call is bounded by construction (Newton iterations
/// over at most 2^12 halvings); an absurd step returns, and either fails with the state
/// unchanged or succeeds with finite numbers; a normal step follows.
#[test]
fn implicit_absurd_step_returns() {
    let sc = scene("freefree", 511);
    let mut s = build(&sc, Method::Implicit, &Options::default()).unwrap();
    s.set_loads(&[0.0, 1.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
    let before = s.state();
    match s.step(1e300) {
        Err(e) => {
            println!("implicit h = 1e300: {e}");
            assert_eq!(s.state(), before);
        }
        Ok(_) => {
            let mut x = [0.0; 3];
            s.positions(&mut x);
            assert!(x.iter().all(|v| v.is_finite()));
            s.set_state(&before).unwrap();
        }
    }
    s.step(1e-3).unwrap();
    assert!(frame_error(s.as_ref()) < 1e-12);
}

/// Class 5: a step that would leave |P^T P - I| above 1e-6 is refused with the figure and
/// advice, the state is as before, and the same step with a sane load runs. The explicit
/// frame update's error grows with the frame points' relative acceleration, and an
/// internal step past 1e-7 is redone in halves down to dt / 2^MAX_HALVINGS: a torque of
/// 1e12 N m on the 0.75 kg beam is beyond even that smallest step. (Before the halving,
/// 1e4 N m was refused already; the halving now follows it.)
#[test]
fn frame_no_longer_a_rotation_is_refused() {
    let sc = scene("freefree", 511);
    let mut s = Explicit::new(&sc, &Options::default()).unwrap();
    s.step(1e-3).unwrap();
    let before = s.state();
    let m = axis(&sc, 2) * TORQUE_REFUSED;
    s.set_loads(&[0.0, 0.0, 0.0, m[0], m[1], m[2]]).unwrap();
    let loaded = s.state();
    let err = s.step(1e-3).unwrap_err();
    let msg = err.to_string();
    println!("{msg}");
    assert!(matches!(err, SolverError::Invalid(_)), "{err:?}");
    assert!(
        msg.contains("no longer a rotation")
            && msg.contains("|P^T P - I| = ")
            && msg.contains(&format!("halved {MAX_HALVINGS} times"))
            && msg.contains("reduce the torque")
            && msg.contains("implicit method")
            && !msg.contains("smaller communication steps"),
        "{msg}"
    );
    let figure: f64 = msg
        .split("|P^T P - I| = ")
        .nth(1)
        .and_then(|r| r.split(',').next())
        .and_then(|x| x.parse().ok())
        .unwrap();
    assert!(figure > MAX_FRAME_ERROR, "{figure}");
    assert_eq!(s.state(), loaded);
    assert!(frame_error(&s) < 1e-12);
    // The refusal left the solver usable: back to the state of before the load, the
    // same steps as a twin that never saw it (bit for bit).
    s.set_state(&before).unwrap();
    let mut twin = Explicit::new(&sc, &Options::default()).unwrap();
    twin.step(1e-3).unwrap();
    // Recovery: a torque the frame update can follow.
    let m = axis(&sc, 2) * 0.01;
    for x in [&mut s, &mut twin] {
        x.set_loads(&[0.0, 0.0, 0.0, m[0], m[1], m[2]]).unwrap();
        for _ in 0..10 {
            x.step(1e-3).unwrap();
        }
    }
    assert_eq!(s.state(), twin.state());
    assert!(frame_error(&s) < 1e-12);
}

/// A torque (N m, about the beam's transverse axis) that even the smallest halved
/// internal step cannot follow.
const TORQUE_REFUSED: f64 = 1e12;

/// The lead's scene (issue 13 regression): the beam spinning at 3 rad/s about global x,
/// 1 N on node 511's fy and 0.5 N m on its mz (half of it along the beam's axis, small
/// inertia: the spin about it grows by 16 rad/s per ms, about 1.6e4 rad/s^2). One internal step at 0.9 dt_fx left
/// |P^T P - I| = 1.1e-6 and the first communication step was refused. With the halving
/// the explicit method runs 0.01 s, the frame stays within 1e-7 at every step, and node
/// 511's y and the frame origin's x agree with the implicit method at h = 1e-5 s (an
/// independent second method, itself converged: at 1e-3 s it differs by 9e-7 m).
#[test]
fn angular_acceleration_is_followed_by_halving() {
    let mut sc = scene("freefree", 511);
    sc.w0 = [3.0, 0.0, 0.0];
    let loads = [0.0, 1.0, 0.0, 0.0, 0.0, 0.5];
    let run = |s: &mut dyn Solver, h: f64, every: usize| -> (Vec<[f64; 2]>, f64) {
        s.set_loads(&loads).unwrap();
        let (mut out, mut worst) = (Vec::new(), 0.0f64);
        for k in 1..=10 * every {
            let _ = s.step(h).unwrap();
            worst = worst.max(frame_error(s));
            if k % every == 0 {
                let mut x = [0.0; 3];
                s.positions(&mut x);
                out.push([x[1], s.frame().unwrap().origin[0]]);
            }
        }
        (out, worst)
    };
    let mut exp = Explicit::new(&sc, &Options::default()).unwrap();
    let (e, fe) = run(&mut exp, 1e-3, 1);
    let mut imp = build(&sc, Method::Implicit, &Options::default()).unwrap();
    let (i, _) = run(imp.as_mut(), 1e-5, 100);
    let y0 = {
        let s = build(&sc, Method::Implicit, &Options::default()).unwrap();
        let mut x = [0.0; 3];
        s.positions(&mut x);
        x[1]
    };
    let travel = (i[9][0] - y0).abs();
    let (mut dy, mut dx) = (0.0f64, 0.0f64);
    for (a, b) in e.iter().zip(&i) {
        dy = dy.max((a[0] - b[0]).abs());
        dx = dx.max((a[1] - b[1]).abs());
    }
    println!(
        "explicit: frame error {fe:.2e}, {} internal steps halved; node 511 y travel \
         {travel:.3e} m, explicit - implicit(1e-5): y {dy:.2e} m, frame x {dx:.2e} m",
        exp.halved_steps()
    );
    assert!(fe <= 1e-7, "{fe}");
    assert!(exp.halved_steps() > 0);
    assert!(dy <= 1e-3 * travel, "{dy} vs {travel}");
    assert!(dx <= 1e-10, "{dx}");
    // The plain scheme (no halving, no check) leaves the frame past the refusal on the
    // first step (the test can fail), and its frame error falls about 16 times per
    // halving of the internal step, (dt^2 |alpha|)^2 (docs/STUDY.md): one internal step
    // of 0.9 dt_fx / 2^k from the loaded state.
    let mut errs = Vec::new();
    for k in 0..5 {
        let opts = Options {
            subcycle: false,
            ..Options::default()
        };
        let mut plain = Explicit::new(&sc, &opts).unwrap();
        plain.set_spin_limits(SPIN_STEP, f64::INFINITY);
        plain.set_loads(&loads).unwrap();
        let dt = 0.9 * plain.stable_step() / f64::from(1u32 << k);
        plain.step(dt).unwrap();
        errs.push(frame_error(&plain));
    }
    let shown: Vec<String> = errs.iter().map(|e| format!("{e:.2e}")).collect();
    println!("plain scheme, one step of 0.9 dt_fx / 2^k, k = 0..4: frame error {shown:?}");
    let mut plain = Explicit::new(&sc, &Options::default()).unwrap();
    plain.set_spin_limits(SPIN_STEP, f64::INFINITY);
    plain.set_loads(&loads).unwrap();
    plain.step(1e-3).unwrap();
    let first = frame_error(&plain);
    println!("plain scheme, sub-cycled at 0.9 dt_fx: frame error {first:.2e} after 1e-3 s");
    assert!(first > MAX_FRAME_ERROR, "{first}");
    for w in errs.windows(2) {
        assert!(w[1] < w[0] / 8.0, "{errs:?}");
    }
}

/// Class 5: a spin above SPIN_WARN_RATIO x omega_1 raises a warning once per solver,
/// with the figures and what to do; a new solver warns again; below it, no warning. Spin
/// about the beam axis (e1), which the frame follows exactly, so only the warning is
/// tested.
#[test]
fn spin_near_the_first_mode_warns_once() {
    for method in [Method::Explicit, Method::Implicit, Method::Split] {
        let mut sc = scene("freefree", 511);
        let w1 = omega1(&sc);
        for (ratio, warns) in [
            (0.5 * SPIN_WARN_RATIO, false),
            (1.5 * SPIN_WARN_RATIO, true),
        ] {
            let e1 = axis(&sc, 0) * (ratio * w1);
            sc.w0 = [e1[0], e1[1], e1[2]];
            for _instance in 0..2 {
                let mut s = build(&sc, method, &Options::default()).unwrap();
                let w = s.step(1e-4).unwrap().map(|w| w.to_string());
                assert_eq!(w.is_some(), warns, "{method:?} {ratio}: {w:?}");
                if let Some(w) = w {
                    assert!(
                        w.contains("first local mode")
                            && w.contains(&fxbody::num::num(w1))
                            && w.contains("Reduce the spin rate"),
                        "{w}"
                    );
                    println!("{method:?}: {w}");
                }
                for _ in 0..5 {
                    let again = s.step(1e-4).unwrap();
                    assert!(again.is_none(), "{method:?}: warned twice");
                }
            }
        }
    }
}

/// Class 5: a singular saddle-point system during a run names the step and spin rate,
/// not the "nodes on one line" of a degenerate body (which the collinear-body tests keep
/// at build). The truss built on a 3-2-1 support (tests/data/truss_supported.*, modes
/// that drag rigid motion) spun fast diverges (outside the model's validity); the raw
/// scheme (limits lifted) runs until its system is singular.
#[test]
fn singular_system_during_a_run_names_step_and_spin() {
    let mut sc = data_scene("truss_supported", &[1044]);
    let w = Vector3::new(1.0, 2.0, 3.0).normalize() * 300.0;
    sc.w0 = [w[0], w[1], w[2]];
    let opts = Options {
        subcycle: false,
        ..Options::default()
    };
    let mut s = Explicit::new(&sc, &opts).unwrap();
    s.set_spin_limits(f64::INFINITY, f64::INFINITY);
    let h = 0.5 * s.stable_step();
    let err = (0..200_000)
        .find_map(|_| s.step(h).err())
        .expect("the raw scheme diverges");
    let msg = err.to_string();
    println!("{msg}");
    assert!(matches!(err, SolverError::Singular(_)), "{err:?}");
    assert!(
        msg.contains("internal step") && msg.contains("spin rate") && !msg.contains("one line"),
        "{msg}"
    );
}

/// The long run under torque (reduced to seconds): 3 N m about the beam's transverse
/// principal axis for 2 s in steps of 1 ms; the spin reaches 95 rad/s (w dt 0.03 at
/// 0.9 dt_fx without the spin limit). The frame stays a rotation (<= 2e-8 at every
/// step, against 9e-8 for the raw scheme), the implicit energy equals the work done,
/// (T t)^2 / (2 I), and the explicit one stays below it by the scheme's known rotational
/// drain (docs/STUDY.md), which shrinks with the spin step.
#[test]
fn long_spin_up_under_torque_keeps_the_frame() {
    let sc = scene("freefree", 511);
    let (tq, h, n) = (3.0, 1e-3, 2000);
    let m = axis(&sc, 2) * tq;
    let loads = [0.0, 0.0, 0.0, m[0], m[1], m[2]];
    // Inertia about e3 through the centre of mass from the rigid mass matrix is not
    // needed: the implicit run and the analytic value share I; take it from the beam
    // (uniform, 1 m, 0.7536 kg): m L^2 / 12.
    let inertia = 0.7536 / 12.0;
    let analytic = (tq * h * n as f64).powi(2) / (2.0 * inertia);
    let run = |s: &mut dyn Solver| -> (f64, f64) {
        s.set_loads(&loads).unwrap();
        let mut worst: f64 = 0.0;
        for _ in 0..n {
            let _ = s.step(h).unwrap();
            worst = worst.max(frame_error(s));
        }
        (worst, s.kinetic_energy() + s.strain_energy())
    };
    let mut imp = build(&sc, Method::Implicit, &Options::default()).unwrap();
    let (fi, ei) = run(imp.as_mut());
    let mut exp = Explicit::new(&sc, &Options::default()).unwrap();
    let (fe, ee) = run(&mut exp);
    let mut fine = Explicit::new(&sc, &Options::default()).unwrap();
    fine.set_spin_limits(SPIN_STEP / 10.0, MAX_FRAME_ERROR);
    let (ff, ef) = run(&mut fine);
    println!(
        "analytic {analytic:.4} J; implicit {ei:.4} J (frame {fi:.1e}); explicit {ee:.4} J \
         (frame {fe:.1e}); explicit at SPIN_STEP/10 {ef:.4} J (frame {ff:.1e})"
    );
    assert!(fi <= 1e-12 && fe <= 2e-8 && ff <= 1e-10, "{fi} {fe} {ff}");
    assert!(
        (ei / analytic - 1.0).abs() < 1e-2,
        "implicit {ei} vs {analytic}"
    );
    // The explicit drain, as docs/STUDY.md records it (explicit 123.5 J, at SPIN_STEP/10
    // 253.8 J, of 286.6 J: losses of 57% and 11%, about 2 c per radian turned): within a
    // percentage point of each, and shrinking with the spin step.
    let (de, df) = (1.0 - ee / analytic, 1.0 - ef / analytic);
    println!(
        "explicit energy loss {:.2}%, at SPIN_STEP/10 {:.2}%",
        100.0 * de,
        100.0 * df
    );
    assert!(
        (de - 0.569).abs() < 0.01,
        "explicit loss {de:.4} vs STUDY.md's 0.569"
    );
    assert!(
        (df - 0.114).abs() < 0.01,
        "loss at SPIN_STEP/10 {df:.4} vs STUDY.md's 0.114"
    );
    assert!(df < 0.5 * de, "drain {df} at SPIN_STEP/10 vs {de}");
    // Without the spin limit (the scheme before issue 13) the same run leaves the frame
    // further from a rotation, which shows this test can fail.
    let mut raw = Explicit::new(&sc, &Options::default()).unwrap();
    raw.set_spin_limits(f64::INFINITY, f64::INFINITY);
    let (fr, _) = run(&mut raw);
    assert!(fr > 4.0 * fe, "raw frame error {fr} vs {fe}");
}
