//! Tests of the step guard: the fast paths against full evaluations and a twin that
//! checks every step.

use crate::fmu::simulation::{Phase, Simulation};

/// Every Real output of `m`, read through the model as a master reads them.
fn outputs(m: &mut Simulation) -> Vec<f64> {
    let outs = m.table.output_refs();
    let mut vals = vec![0.0; outs.len()];
    m.get_reals(&outs, &mut vals).unwrap();
    vals
}

/// The fast path's claim, checked against the outputs themselves (an independent
/// evaluation): over load magnitudes from 1 to 1e301, every method, on the whole and on
/// a truncated cantilever, a step the guard accepts leaves every Real output finite,
/// and both paths run (steps accepted below the bound, accepted above it after the
/// full check, and refused).
#[test]
fn an_accepted_step_has_every_output_finite() {
    let full = crate::scene::io::cantilever_tip_scene();
    let (cut, _) = full.truncated(40.0).unwrap();
    let (mut fast, mut slow, mut refused) = (0, 0, 0);
    for scene in [full, cut] {
        for method in [1, 2, 3] {
            for k in (0..=301).step_by(7) {
                let bound = super::output_bound(&scene, &crate::solver::Options::default());
                let mut m = Simulation::new(scene.clone(), "{g}".into());
                let vr = |name: &str| m.table.vars.iter().find(|v| v.name == name).unwrap().vr;
                let (fy, meth) = (vr("node_121.fy"), vr("method"));
                m.set_integer(meth, method, Phase::Configuring).unwrap();
                m.setup(0.0, None).unwrap();
                let load = 10f64.powi(k);
                m.set_reals(&[fy], &[load], Phase::Running).unwrap();
                match m.do_step(0.0, 1e-3) {
                    Err(e) => {
                        assert!(e.to_string().contains("non-finite"), "{e}");
                        refused += 1;
                    }
                    Ok(_) => {
                        let vals = outputs(&mut m);
                        assert!(
                            vals.iter().all(|x| x.is_finite()),
                            "method {method}, load 1e{k}: {vals:?}"
                        );
                        if load < bound {
                            fast += 1;
                        } else {
                            slow += 1;
                        }
                    }
                }
            }
        }
    }
    assert!(
        fast > 0 && slow > 0 && refused > 0,
        "{fast} {slow} {refused}"
    );
}

/// Double buffering keeps its promise: wherever the solver changed between steps
/// (loads passed to read a truncated scene's outputs, an FMU state restored, a
/// method changed), a refused step still leaves the model exactly as before it, and
/// accepted steps equal a twin's whose guard saved the state before every step.
#[test]
fn a_refused_step_restores_after_any_change_between_steps() {
    let full = crate::scene::io::cantilever_tip_scene();
    let (cut, _) = full.truncated(40.0).unwrap();
    for scene in [full, cut] {
        let mut m = Simulation::new(scene.clone(), "{g}".into());
        let mut twin = Simulation::new(scene, "{g}".into());
        let vr = |name: &str| m.table.vars.iter().find(|v| v.name == name).unwrap().vr;
        let (fy, y) = (vr("node_121.fy"), vr("node_121.y"));
        for x in [&mut m, &mut twin] {
            x.setup(0.0, None).unwrap();
            x.ensure_solver().unwrap();
        }
        let h = 1e-3;
        let mut out = [0.0];
        let mut older = m.snapshot(0);
        for k in 0..12 {
            let f = (k as f64).sin();
            match k % 4 {
                // Reading a truncated scene's position passes the loads to the solver.
                1 => {
                    m.set_reals(&[fy], &[f], Phase::Running).unwrap();
                    m.get_reals(&[y], &mut out).unwrap();
                }
                // Back to a state of two steps ago, in both.
                2 => {
                    m.restore(&older).unwrap();
                    twin.restore(&older).unwrap();
                }
                _ => older = m.snapshot(0),
            }
            for x in [&mut m, &mut twin] {
                x.set_reals(&[fy], &[f], Phase::Running).unwrap();
            }
            let t = m.time();
            // A huge load is refused and leaves everything as it was.
            let before = m.snapshot(0);
            m.set_reals(&[fy], &[f64::MAX], Phase::Running).unwrap();
            assert!(m.do_step(t, h).is_err());
            m.set_reals(&[fy], &[f], Phase::Running).unwrap();
            assert_eq!(m.snapshot(0), before, "step {k}");
            // The twin never saw a refused step or a read, and its guard copies the
            // state before every step (a restore makes it forget the buffer).
            let s = twin.snapshot(0);
            twin.restore(&s).unwrap();
            m.do_step(t, h).unwrap();
            twin.do_step(t, h).unwrap();
            let (a, b) = (m.snapshot(0), twin.snapshot(0));
            assert_eq!(a.solver, b.solver, "step {k}");
        }
    }
}

/// The bounded path is a shortcut, not another answer. The exact method on the
/// cantilever, loads from 1e-3 to 1e301 in one run, restored states and a second
/// step size in between, against a twin whose guard checks every step: the same
/// steps accepted and refused, the same solver state bit for bit after each, the
/// outputs finite after every accepted one; and the run took both paths and refused
/// some steps.
#[test]
fn a_bounded_step_is_one_the_checked_path_accepts_alike() {
    let scene = crate::scene::io::cantilever_tip_scene();
    let mut m = Simulation::new(scene.clone(), "{g}".into());
    let mut twin = Simulation::new(scene, "{g}".into());
    let vr = |name: &str| m.table.vars.iter().find(|v| v.name == name).unwrap().vr;
    let (fy, meth) = (vr("node_121.fy"), vr("method"));
    for x in [&mut m, &mut twin] {
        x.set_integer(meth, 3, Phase::Configuring).unwrap();
        x.setup(0.0, None).unwrap();
        x.ensure_solver().unwrap();
    }
    twin.guard_mut().checked_only = true;
    let start = m.snapshot(0);
    let (mut bounded, mut checked, mut refused) = (0, 0, 0);
    for k in 0..400usize {
        if k % 25 == 0 {
            // Back to the start (the guard measures the state again).
            m.restore(&start).unwrap();
            twin.restore(&start).unwrap();
        }
        let h = if k % 9 == 8 { 3e-3 } else { 1e-3 };
        // Mostly ordinary loads; every fifth one of 10^(0..301).
        let load = if k % 5 == 0 {
            10f64.powi((k * 37 % 302) as i32)
        } else {
            1e-3 * (k as f64).sin()
        };
        for x in [&mut m, &mut twin] {
            x.set_reals(&[fy], &[load], Phase::Running).unwrap();
        }
        let t = m.time();
        let (a, b) = (m.do_step(t, h), twin.do_step(t, h));
        assert_eq!(a.is_ok(), b.is_ok(), "step {k}, load {load:e}: {a:?} {b:?}");
        assert_eq!(m.snapshot(0).solver, twin.snapshot(0).solver, "step {k}");
        if a.is_err() {
            refused += 1;
            continue;
        }
        let vals = outputs(&mut m);
        assert!(vals.iter().all(|x| x.is_finite()), "step {k}: {vals:?}");
        if m.guard_mut().bounded() {
            bounded += 1;
        } else {
            checked += 1;
        }
    }
    // Bounded: 50 of 400 (the bound is 5e23 on this body: a step after one of the huge
    // loads stays on the checked path until the restore every 25 steps).
    assert!(
        bounded > 25 && checked > 50 && refused > 10,
        "{bounded} bounded, {checked} checked, {refused} refused"
    );
}

/// The bound's claim, checked where parameters make the methods' coefficients huge: a
/// state whose every entry is below [`super::output_bound`] (half of it over the square
/// root of the state's length, alternating signs, so that the guard's sum of squares is
/// below the bound's square) gives finite outputs and output derivatives, on the blocked
/// cantilever and the free-free beam, every method, under `damping.ratio` up to f64::MAX
/// and gravity of 1e300. A bound from the body's matrices alone (the guard before issue
/// 28) let such a state through with accelerations of 1e378 = inf (exact method,
/// damping.ratio 1e300: `d v` with `d` = 1e300).
#[test]
fn a_state_below_the_bound_gives_finite_outputs_whatever_the_parameters() {
    use crate::solver::{Method, Options, build};
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let blocked = crate::scene::io::cantilever_tip_scene();
    let free = {
        let body =
            crate::body::load(&root.join("fixtures/freefree.fxb"), Default::default()).unwrap();
        let x = body.rigid_mode_positions().unwrap();
        crate::scene::Scene::new(std::sync::Arc::new(body), vec![20], vec![x[20]])
    };
    let mut checked = 0;
    for (scene, methods) in [
        (blocked, [Method::Exact, Method::Implicit, Method::Explicit]),
        (free, [Method::Split, Method::Implicit, Method::Explicit]),
    ] {
        for zeta in [0.0, 1e150, 1e300, f64::MAX] {
            for g in [0.0, 1e300] {
                if g != 0.0 && scene.body.is_blocked() {
                    continue;
                }
                let mut scene = scene.clone();
                scene.gravity = [0.0, 0.0, g];
                let opts = Options {
                    damping_ratio: zeta,
                    ..Options::default()
                };
                let bound = super::output_bound(&scene, &opts);
                for method in methods {
                    // A build the solver refuses (explicit under damping.ratio MAX, a
                    // start that overflows) has no state to check.
                    let Ok(mut s) = build(&scene, method, &opts) else {
                        continue;
                    };
                    let mut st = s.state();
                    let c = 0.5 * bound / (st.data.len() as f64).sqrt();
                    for (k, x) in st.data.iter_mut().enumerate() {
                        *x = if k % 2 == 0 { c } else { -c };
                    }
                    if s.set_state(&st).is_err() {
                        continue;
                    }
                    let n = 3 * scene.nodes.len();
                    let mut out = vec![0.0; 6 * n];
                    let (a, b) = out.split_at_mut(3 * n);
                    s.positions(&mut a[..n]);
                    s.velocities(&mut a[n..2 * n]);
                    s.rotations(&mut a[2 * n..]);
                    s.rotation_rates(&mut b[..n]);
                    s.accelerations(&mut b[n..2 * n]);
                    s.rotation_accelerations(&mut b[2 * n..]);
                    out.push(s.kinetic_energy());
                    out.push(s.strain_energy());
                    assert!(
                        out.iter().all(|x| x.is_finite()),
                        "{method:?}, damping.ratio {zeta:e}, gravity {g:e}, state entries \
                         {c:e} (bound {bound:e}): {out:?}"
                    );
                    checked += 1;
                }
            }
        }
    }
    assert!(checked >= 20, "{checked}");
}
