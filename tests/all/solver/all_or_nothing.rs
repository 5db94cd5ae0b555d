//! The `step` contract every method keeps (issue 27.4): a refused step leaves the state
//! bit for bit as it was; after a checkpoint a refused step, and a rewind after an
//! accepted one, go back to the checkpoint, loads set since then included; a checkpoint
//! serves the one step after it. Every method: the blocked exact, implicit and explicit
//! on the cantilever, the free explicit, implicit and split on the free-free beam, and the
//! exact method of a truncated cantilever (the residual correction keeps loads of its
//! own beside its inner solver's).

use crate::common::fixture_scene;
use fxbody::scene::Scene;
use fxbody::solver::{Method, Options, Solver, State, build};

/// The state as bits: `==` on `f64` would take 0.0 for -0.0 and refuse NaN for NaN.
fn bits(s: &dyn Solver) -> (Method, Vec<u64>) {
    let State { method, data } = s.state();
    (method, data.iter().map(|x| x.to_bits()).collect())
}

/// Every method with a scene it runs on, and whether it is a free method (whose step
/// can fail after it changed the state).
fn cases() -> Vec<(String, Scene, Method, bool)> {
    let blocked = fixture_scene("cantilever", &[121, 111]);
    let free = fixture_scene("freefree", &[511]);
    let f1 = blocked.body.frequencies_hz()[0];
    let (truncated, _) = blocked.truncated(1.5 * f1).unwrap();
    assert!(truncated.residual.is_some());
    let mut v = Vec::new();
    for m in [Method::Exact, Method::Implicit, Method::Explicit] {
        v.push((format!("blocked {m:?}"), blocked.clone(), m, false));
    }
    for m in [Method::Explicit, Method::Implicit, Method::Split] {
        v.push((format!("free {m:?}"), free.clone(), m, true));
    }
    v.push(("truncated Exact".into(), truncated, Method::Exact, false));
    v
}

/// Loads of `scale` on every component, each a little different.
fn loads(n: usize, scale: f64) -> Vec<f64> {
    (0..n).map(|k| scale * (1.0 + 0.1 * k as f64)).collect()
}

#[test]
fn a_refused_step_leaves_the_state_bit_for_bit() {
    for (name, scene, method, free) in cases() {
        let n = 6 * scene.nodes.len();
        let mut s = build(&scene, method, &Options::default()).unwrap();
        let h = 1e-4;
        // A state away from rest, with loads and rates on.
        s.set_loads(&loads(n, 2.0)).unwrap();
        s.set_load_rates(&loads(n, 0.5)).unwrap();
        for _ in 0..5 {
            s.step(h).unwrap();
        }
        let before = bits(s.as_ref());
        let saved = s.state();

        // Refused before any work: a step that is no step.
        for bad in [f64::NAN, -h, 0.0, f64::INFINITY] {
            assert!(s.step(bad).is_err(), "{name}: h = {bad} taken");
            assert_eq!(
                bits(s.as_ref()),
                before,
                "{name}: h = {bad} changed the state"
            );
        }

        // Refused partway: loads that overflow the free methods' frame and accelerations
        // (a blocked method's step is a linear map that completes whatever the numbers).
        if free {
            s.set_loads(&loads(n, 1e300)).unwrap();
            let loaded = bits(s.as_ref());
            let e = s
                .step(h)
                .expect_err(&format!("{name}: overflowing step taken"));
            println!("{name}: {e}");
            assert_eq!(bits(s.as_ref()), loaded, "{name}: partway refusal");
            // Loads set now differ from those set at the start in the time they were
            // set: back to the state before them.
            s.set_state(&saved).unwrap();
            assert_eq!(bits(s.as_ref()), before, "{name}: set_state");
        }

        // After a checkpoint a refused step goes back to it, loads and rates included.
        s.checkpoint();
        s.set_loads(&loads(n, -7.0)).unwrap();
        s.set_load_rates(&loads(n, 3.0)).unwrap();
        assert_ne!(
            bits(s.as_ref()),
            before,
            "{name}: loads are part of the state"
        );
        assert!(s.step(f64::NAN).is_err());
        assert_eq!(
            bits(s.as_ref()),
            before,
            "{name}: refusal after a checkpoint"
        );

        // A rewind after an accepted step goes back to the checkpoint, and again.
        s.checkpoint();
        s.set_loads(&loads(n, -7.0)).unwrap();
        s.step(h).unwrap();
        let after = bits(s.as_ref());
        assert_ne!(after, before, "{name}: the step moved nothing");
        s.rewind().unwrap();
        assert_eq!(bits(s.as_ref()), before, "{name}: rewind");
        s.set_loads(&loads(n, -7.0)).unwrap();
        s.step(h).unwrap();
        assert_eq!(
            bits(s.as_ref()),
            after,
            "{name}: the step again, bit for bit"
        );
        s.rewind().unwrap();
        assert_eq!(bits(s.as_ref()), before, "{name}: second rewind");

        // A checkpoint serves one step: the refusal of the second goes back to the state
        // before it, not to the checkpoint.
        s.checkpoint();
        s.step(h).unwrap();
        let one = bits(s.as_ref());
        assert!(s.step(f64::NAN).is_err());
        assert_eq!(
            bits(s.as_ref()),
            one,
            "{name}: refusal after the served step"
        );
        assert!(s.rewind().is_err(), "{name}: rewind past the served step");
        assert_eq!(
            bits(s.as_ref()),
            one,
            "{name}: a refused rewind changed the state"
        );

        // A state set wholesale ends the checkpoint.
        s.checkpoint();
        let st = s.state();
        s.set_state(&st).unwrap();
        assert!(s.rewind().is_err(), "{name}: rewind after set_state");
        assert_eq!(bits(s.as_ref()), one, "{name}: set_state, refused rewind");
    }
}

/// The copy [`Solver::state_below`] measures after a step becomes the next checkpoint
/// when nothing changed the state in between (the two buffers swap): a rewind goes back
/// to the state at the checkpoint. Any change between the measure and the checkpoint
/// (loads, rates, a state set, a rewind, the continuous states of Model Exchange) makes
/// the checkpoint copy the state afresh, so the rewind still goes back to the state at
/// the checkpoint and not to the one measured.
#[test]
fn a_checkpoint_after_a_measure_holds_the_state_of_its_time() {
    for (name, scene, method, _) in cases() {
        let n = 6 * scene.nodes.len();
        let mut s = build(&scene, method, &Options::default()).unwrap();
        let h = 1e-4;
        s.set_loads(&loads(n, 2.0)).unwrap();
        s.step(h).unwrap();
        let early = s.state();
        for change in 0..6 {
            s.step(h).unwrap();
            assert!(s.state_below(1e300), "{name}: a finite state is below");
            match change {
                0 => {}
                1 => s.set_loads(&loads(n, -3.0 - change as f64)).unwrap(),
                2 => s.set_load_rates(&loads(n, 1.0)).unwrap(),
                3 => s.set_state(&early).unwrap(),
                4 => {
                    // Measured after the step, then rewound before it.
                    s.checkpoint();
                    s.step(h).unwrap();
                    assert!(s.state_below(1e300));
                    s.rewind().unwrap();
                }
                _ => match s.continuous() {
                    Some(c) => {
                        let mut x = vec![0.0; c.state_count()];
                        c.states(&mut x);
                        x[0] += 1e-6;
                        c.set_states(0.5, &x).unwrap();
                    }
                    None => continue,
                },
            }
            let at = bits(s.as_ref());
            s.checkpoint();
            s.set_loads(&loads(n, 5.0)).unwrap();
            s.step(h).unwrap();
            assert_ne!(bits(s.as_ref()), at, "{name}: the step moved nothing");
            s.rewind().unwrap();
            assert_eq!(
                bits(s.as_ref()),
                at,
                "{name}: checkpoint after change {change}"
            );
        }
    }
}
