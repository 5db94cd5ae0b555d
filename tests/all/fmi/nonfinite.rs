//! Issue 13, classes 1 and 2 on a blocked body, through the crate's FMI exports.
//!
//! Class 2, no non-finite result from finite input: for each method, a load of
//! f64::MAX (or an input rate of 1e308) is refused at doStep with fmi2Error naming the
//! output that would be non-finite and the input that caused it; the model's solver
//! state is the one from before the step (fingerprint byte for byte, once the load is set
//! back), and a run continued after fmi2SetFMUstate equals, bit for bit, a twin that
//! never saw the bad load.
//!
//! Class 1, no unbounded work: on the explicit method h = 6.8e4 s and h = 1e300 s are
//! refused before any work (the test simply finishes) with the internal-step count and
//! the largest step that fits, in compact numbers; the instance then carries on like the
//! twin.

// Raw FFI: this test calls the exported fmi2* functions directly, as a C master does,
// which is `unsafe`; the workspace denies `unsafe_code` outside the FMI boundary.
#![allow(unsafe_code)]
#![cfg(target_os = "linux")]

use crate::common::fmu::{AFTER, BEFORE, H, Packed, Slave, load, packed, run, same_bits};
use fxbody::fmi::exports as x;
use fxbody::fmi::state::FmiState;
use fxbody::fmi::types::*;

/// A slave with `method` (1 explicit, 2 implicit, 3 exact), set up and initialised.
fn started(fx: &Packed, method: i32) -> Slave {
    let s = Slave::new(fx, "nonfinite");
    assert_eq!(s.setup(0.0, None), fmi2OK);
    let vr = fx.vr("method");
    // SAFETY: a live instance, arrays of one element.
    unsafe {
        assert_eq!(
            fxbody::fmi::values::fmi2SetInteger(s.c, &vr, 1, &method),
            fmi2OK
        );
        assert_eq!(x::fmi2EnterInitializationMode(s.c), fmi2OK);
        assert_eq!(x::fmi2ExitInitializationMode(s.c), fmi2OK);
    }
    s
}

/// A refused step: fmi2Error, the Error state, and a logged reason holding each of `says`.
fn refused(s: &Slave, st: fmi2Status, says: &[&str], what: &str) -> String {
    assert_eq!(st, fmi2Error, "{what}");
    assert_eq!(s.fmi_state(), FmiState::Error, "{what}");
    let e = s.last_error();
    println!("{what}: {e}");
    for w in says {
        assert!(e.contains(w), "{what}: logged '{e}', expected '{w}'");
    }
    e
}

/// After a refusal at step BEFORE: with the tip load set back to its last value, the
/// model is byte for byte the one saved before; continued (white box) and after
/// fmi2SetFMUstate, the next AFTER steps equal the twin's bit for bit.
fn recovers(s: &Slave, fx: &Packed, saved: fmi2FMUstate, print: &[u8], twin: &[f64], what: &str) {
    assert_eq!(
        s.set_state(saved),
        fmi2OK,
        "{what}: SetFMUstate after the refusal"
    );
    assert_eq!(s.fingerprint(), print, "{what}: restored model");
    let again = run(s, fx, BEFORE, AFTER).unwrap();
    assert!(
        same_bits(&again, &twin[BEFORE..]),
        "{what} (restored): {again:?}"
    );
    assert_eq!(s.set_state(saved), fmi2OK);
}

#[test]
fn huge_loads_and_rates_are_refused_and_the_instance_recovers() {
    let fx = packed("nonfinite");
    let (fy, y) = (fx.vr("node_121.fy"), fx.vr("node_121.y"));
    for (method, name) in [(1, "explicit"), (2, "implicit"), (3, "exact")] {
        let twin = run(&started(&fx, method), &fx, 0, BEFORE + AFTER).unwrap();
        assert!(twin.iter().all(|v| v.is_finite()) && twin.iter().any(|v| v.abs() > 1e-9));
        let s = started(&fx, method);
        run(&s, &fx, 0, BEFORE).unwrap();
        let saved = s.get_state();
        let print = s.fingerprint();
        let t = BEFORE as f64 * H;
        let mut before = [0.0];
        assert_eq!(s.get_real(&[y], &mut before), fmi2OK);

        // A load of f64::MAX.
        assert_eq!(s.set_real(&[fy], &[f64::MAX]), fmi2OK);
        let e = refused(
            &s,
            s.do_step(t, H),
            &[
                "non-finite",
                "node_121.fy = 1.7976931348623157e308",
                "keeps its state",
            ],
            name,
        );
        assert!(e.len() < 400, "{name}: short message: {e}");
        // The solver holds the pre-step state: with the load set back (white box, out
        // of the Error state), the model's snapshot is the saved one byte for byte.
        s.force_state(FmiState::StepComplete);
        assert_eq!(s.set_real(&[fy], &[load(t - H)]), fmi2OK);
        assert_eq!(s.fingerprint(), print, "{name}: model after the refusal");
        let mut now = [0.0];
        assert_eq!(s.get_real(&[y], &mut now), fmi2OK);
        assert_eq!(now[0].to_bits(), before[0].to_bits(), "{name}: tip y kept");
        // Continued with sane loads: the twin's numbers.
        let cont = run(&s, &fx, BEFORE, AFTER).unwrap();
        assert!(
            same_bits(&cont, &twin[BEFORE..]),
            "{name} continued: {cont:?}"
        );
        recovers(&s, &fx, saved, &print, &twin, name);

        // An input rate of 1e308 (held load finite).
        let order = 1;
        // SAFETY: arrays of one element.
        let st = unsafe {
            fxbody::fmi::values::fmi2SetRealInputDerivatives(s.c, &fy, 1, &order, &1e308)
        };
        assert_eq!(st, fmi2OK);
        refused(
            &s,
            s.do_step(t, H),
            &["non-finite", "d/dt node_121.fy = 1e308"],
            name,
        );
        recovers(&s, &fx, saved, &print, &twin, name);
        let mut st = saved;
        // SAFETY: the live state of this instance, freed once.
        unsafe { fxbody::fmi::fmu_state::fmi2FreeFMUstate(s.c, &mut st) };
    }
}

#[test]
fn explicit_steps_over_the_budget_are_refused_at_once() {
    let fx = packed("budget");
    let twin = run(&started(&fx, 1), &fx, 0, BEFORE + AFTER).unwrap();
    let s = started(&fx, 1);
    run(&s, &fx, 0, BEFORE).unwrap();
    let saved = s.get_state();
    let print = s.fingerprint();
    let t = BEFORE as f64 * H;
    for h in [6.8e4, 1e300] {
        let e = refused(
            &s,
            s.do_step(t, h),
            &[
                "internal steps",
                "budget of 1000000",
                "use steps of at most",
            ],
            &format!("h = {}", fxbody::num::num(h)),
        );
        assert!(e.len() < 400, "compact: {e}");
        let shown = fxbody::num::num(h);
        assert!(e.contains(&format!("h = {shown}")), "{e}");
        // The step count: h over the largest internal step, printed compactly.
        let steps: f64 = e
            .split(" needs ")
            .nth(1)
            .and_then(|r| r.split(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("step count in '{e}'"));
        let max_h: f64 = e
            .rsplit("at most ")
            .next()
            .and_then(|r| r.split(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("largest step in '{e}'"));
        assert!(
            steps > 1e6 && (steps * max_h / 1e6 / h - 1.0).abs() < 1e-6,
            "{e}"
        );
        assert_eq!(s.fingerprint(), print, "h = {h}: model unchanged");
        recovers(&s, &fx, saved, &print, &twin, &format!("h = {h}"));
    }
    // The largest step the message names is taken (on a fresh instance).
    let e = {
        let s2 = started(&fx, 1);
        s2.do_step(0.0, 1e300);
        s2.last_error()
    };
    let max_h: f64 = e
        .rsplit("at most ")
        .next()
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap();
    let s3 = started(&fx, 1);
    assert_eq!(s3.do_step(0.0, max_h * 0.999), fmi2OK, "{e}");
    let mut st = saved;
    // SAFETY: the live state of this instance, freed once.
    unsafe { fxbody::fmi::fmu_state::fmi2FreeFMUstate(s.c, &mut st) };
}

/// Issue 28, point 5: no non-finite or absurd output from a legal parameter. Every
/// parameter at its extremes (damping.ratio from 1e-300 to f64::MAX, rho_inf 0 and 1,
/// gravity, v0 and w0 up to f64::MAX), every method, on the blocked cantilever and the
/// free-free beam, under a 1 N tip load, steps of 1 ms and of 1 s: every step the model
/// accepts leaves every output finite, and every refusal (at the build or at a step)
/// that advises a number advises a usable one (finite, positive, a normal f64) and
/// prints no NaN. Measured: 732 steps accepted, 178 refusals. Before issue 28 it failed
/// at once: the explicit method under damping.ratio 1e8 advised "use steps of at most
/// 0 s" (the stable step's cancellation), and further on an output call never returned
/// (nalgebra's nearest-rotation search on a NaN frame), free implicit starts whose
/// accelerations overflowed could not be put back after a refused step, and singular
/// systems printed "pivot ratio NaN".
#[test]
fn extreme_parameters_give_finite_outputs_or_a_usable_refusal() {
    use fxbody::fmu::simulation::{Phase, Simulation};

    use crate::common::fixture_scene;

    let big = f64::MAX;
    let mut cases: Vec<(&str, f64)> = Vec::new();
    for z in [1e-300, 1e-10, 0.5, 1.0, 1e6, 1e8, 1e150, 1e200, 1e300, big] {
        cases.push(("damping.ratio", z));
    }
    cases.extend([("rho_inf", 0.0), ("rho_inf", 1.0)]);
    let free_cases: Vec<(&str, f64)> = ["gravity.x", "gravity.z", "v0.y", "w0.x", "w0.z"]
        .iter()
        .flat_map(|&n| [1e3, 1e10, 1e150, 1e300, -big, big].map(|v| (n, v)))
        .collect();
    let bodies = [
        ("cantilever", 121, vec![1, 2, 3]),
        ("freefree", 521, vec![1, 2, 4]),
    ];
    let (mut accepted, mut refusals, mut bad) = (0usize, Vec::new(), Vec::new());
    for (body, tip, methods) in bodies {
        let scene = fixture_scene(body, &[tip]);
        let all: Vec<(&str, f64)> = if body == "freefree" {
            cases.iter().chain(&free_cases).copied().collect()
        } else {
            cases.clone()
        };
        for &method in &methods {
            for &(name, value) in &all {
                for h in [1e-3, 1.0] {
                    let what = format!("{body} method {method} {name} = {value:e} h = {h}");
                    let mut m = Simulation::new(scene.clone(), "g".into());
                    let vr = |m: &Simulation, n: &str| {
                        m.table.vars.iter().find(|v| v.name == n).unwrap().vr
                    };
                    let (pvr, mvr) = (vr(&m, name), vr(&m, "method"));
                    let fy = vr(&m, &format!("node_{tip}.fy"));
                    m.set_integer(mvr, method, Phase::Configuring).unwrap();
                    m.set_real(pvr, value, Phase::Configuring).unwrap();
                    m.setup(0.0, None).unwrap();
                    m.set_real(fy, 1.0, Phase::Configuring).unwrap();
                    let outs = m.table.output_refs();
                    let mut out = vec![0.0; outs.len()];
                    for k in 0..5 {
                        match m.do_step(k as f64 * h, h) {
                            Ok(_) => {
                                accepted += 1;
                                m.get_reals(&outs, &mut out).unwrap();
                                if let Some(i) = out.iter().position(|v| !v.is_finite()) {
                                    let n = &m.table.vars[outs[i] as usize].name;
                                    bad.push(format!(
                                        "{what}: step {k} accepted with {n} = {}",
                                        out[i]
                                    ));
                                }
                            }
                            Err(e) => {
                                let text = e.to_string();
                                if let Err(why) = check_advice(&text) {
                                    bad.push(format!("{what}: {why}: {text}"));
                                }
                                refusals.push(format!("{what}: {text}"));
                                break;
                            }
                        }
                    }
                }
            }
        }
    }
    println!(
        "{accepted} steps accepted with finite outputs, {} refusals:",
        refusals.len()
    );
    for r in &refusals {
        println!("  {r}");
    }
    assert!(
        bad.is_empty(),
        "{} violations:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

/// Every number a refusal advises ("use steps of at most X s") is usable: finite,
/// positive, a normal f64; and no refusal prints NaN.
fn check_advice(text: &str) -> Result<(), String> {
    if text.contains("NaN") {
        return Err("NaN in the message".into());
    }
    let advice = "use steps of at most ";
    for (k, _) in text.match_indices(advice) {
        let rest = &text[k + advice.len()..];
        let word: String = rest
            .chars()
            .take_while(|c| !c.is_whitespace() && *c != ';' && *c != ',' && *c != ')')
            .collect();
        match word.parse::<f64>() {
            Ok(x) if x.is_finite() && x.is_normal() && x > 0.0 => {}
            _ => return Err(format!("advice 'at most {word}' is no usable number")),
        }
    }
    Ok(())
}
