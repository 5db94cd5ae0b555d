//! FMI misuse matrix (issues 9 and 13): every export called in every reachable state where
//! the call sequence forbids it (instantiated, initializationMode, stepComplete,
//! terminated, error entered from stepComplete, error entered from instantiated), and
//! every export with a NULL component. Then the time and call-sequence edges of issue 13:
//! reads and saves in the Error state, the communication-point tolerance at large times
//! and for accumulating masters, negative start and stop times. Bad arguments are in
//! bad_args.rs, states and lifetimes in states.rs.
//!
//! References, per case: the process survives; fmi2Error with "<function>: illegal call
//! in state ..." logged; the model's complete state (serialised snapshot) byte for byte
//! unchanged; the instance reports the Error state and, after fmi2Reset, a full run
//! equals an undisturbed twin's bit for bit. The state table is written here from the
//! FMI 2.0 standard's co-simulation table (section 4.2.4), independently of
//! src/fmi/state.rs; in Error a call is also judged by the state before the error, whose
//! values the model holds.

// Raw FFI: this test calls the exported fmi2* functions directly, as a C master does,
// which is `unsafe`; the workspace denies `unsafe_code` outside the FMI boundary.
#![allow(unsafe_code)]
// The table of calls holds one unsafe closure per FMI function under one
// `// SAFETY (every closure below):` comment, which clippy cannot attribute to them.
#![allow(clippy::undocumented_unsafe_blocks)]
#![cfg(target_os = "linux")]

use std::collections::BTreeMap;
use std::ptr::{null, null_mut};

use super::matrix::{self, CsAt, Matrix};
use crate::common::fmu::{
    AFTER, BEFORE, H, Packed, Slave, packed, print_counts, reference, run, same_bits,
};
use fxbody::fmi::exports::*;
use fxbody::fmi::fmu_state::*;
use fxbody::fmi::state::FmiState;
use fxbody::fmi::types::*;
use fxbody::fmi::values::*;

use CsAt::*;
const ALL: [CsAt; 6] = matrix::CS_ALL;
type At = CsAt;

/// Valid arguments for every call, so that only the state makes a call illegal.
struct Args {
    fy: u32,
    y: u32,
    method: u32,
    method_value: i32,
    /// A live state of another instance of the same FMU (and its bytes).
    state: fmi2FMUstate,
    bytes: Vec<u8>,
}

/// Every export taking a component, with the states where FMI 2.0 allows it (the
/// standard's co-simulation table: in error, reads, output derivatives, FMU-state
/// functions, SetDebugLogging, Reset and the status queries; a read in error only if
/// the state before the error allows it).
fn calls() -> Vec<matrix::Call<At, Args>> {
    const INS: &[At] = &[Instantiated, InitializationMode, StepComplete];
    const GETS: &[At] = &[InitializationMode, StepComplete, Terminated, Error];
    const SAVE: &[At] = &ALL;
    const RESTORE: &[At] = SAVE;
    const OUT_DERIVS: &[At] = &[StepComplete, Terminated, Error];
    const STATUS: &[At] = &[StepComplete, Terminated, Error, ErrorEarly];
    // SAFETY (every closure below): `c` is a live instance and every pointer passed
    // points to valid, writable memory of the length given.
    vec![
        ("fmi2SetDebugLogging", SAVE, |c, _| unsafe {
            fmi2SetDebugLogging(c, fmi2True, 0, null())
        }),
        ("fmi2SetupExperiment", &[Instantiated], |c, _| unsafe {
            fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0)
        }),
        (
            "fmi2EnterInitializationMode",
            &[Instantiated],
            |c, _| unsafe { fmi2EnterInitializationMode(c) },
        ),
        (
            "fmi2ExitInitializationMode",
            &[InitializationMode],
            |c, _| unsafe { fmi2ExitInitializationMode(c) },
        ),
        ("fmi2Terminate", &[StepComplete], |c, _| unsafe {
            fmi2Terminate(c)
        }),
        ("fmi2Reset", RESTORE, |c, _| unsafe { fmi2Reset(c) }),
        ("fmi2GetReal", GETS, |c, a| unsafe {
            let mut v = [0.0];
            fmi2GetReal(c, &a.y, 1, v.as_mut_ptr())
        }),
        ("fmi2GetInteger", GETS, |c, a| unsafe {
            let mut v = [0];
            fmi2GetInteger(c, &a.method, 1, v.as_mut_ptr())
        }),
        ("fmi2GetBoolean", GETS, |c, _| unsafe {
            fmi2GetBoolean(c, null(), 0, null_mut())
        }),
        ("fmi2GetString", GETS, |c, _| unsafe {
            fmi2GetString(c, null(), 0, null_mut())
        }),
        ("fmi2SetReal", INS, |c, a| unsafe {
            fmi2SetReal(c, &a.fy, 1, &0.25)
        }),
        ("fmi2SetInteger", INS, |c, a| unsafe {
            fmi2SetInteger(c, &a.method, 1, &a.method_value)
        }),
        ("fmi2SetBoolean", INS, |c, _| unsafe {
            fmi2SetBoolean(c, null(), 0, null())
        }),
        ("fmi2SetString", INS, |c, _| unsafe {
            fmi2SetString(c, null(), 0, null())
        }),
        ("fmi2GetFMUstate", SAVE, |c, _| unsafe {
            let mut s = null_mut();
            let st = fmi2GetFMUstate(c, &mut s);
            if !s.is_null() {
                fmi2FreeFMUstate(c, &mut s);
            }
            st
        }),
        ("fmi2SetFMUstate", RESTORE, |c, a| unsafe {
            fmi2SetFMUstate(c, a.state)
        }),
        ("fmi2FreeFMUstate", RESTORE, |c, _| unsafe {
            let mut s: fmi2FMUstate = null_mut();
            fmi2FreeFMUstate(c, &mut s)
        }),
        ("fmi2SerializedFMUstateSize", SAVE, |c, a| unsafe {
            let mut n = 0;
            fmi2SerializedFMUstateSize(c, a.state, &mut n)
        }),
        ("fmi2SerializeFMUstate", SAVE, |c, a| unsafe {
            let mut buf = vec![0u8; a.bytes.len()];
            fmi2SerializeFMUstate(c, a.state, buf.as_mut_ptr().cast(), buf.len())
        }),
        ("fmi2DeSerializeFMUstate", RESTORE, |c, a| unsafe {
            let mut s = null_mut();
            let st = fmi2DeSerializeFMUstate(c, a.bytes.as_ptr().cast(), a.bytes.len(), &mut s);
            if !s.is_null() {
                fmi2FreeFMUstate(c, &mut s);
            }
            st
        }),
        // Not provided: refused in every state, for the state or for itself.
        ("fmi2GetDirectionalDerivative", &[], |c, _| unsafe {
            fmi2GetDirectionalDerivative(c, null(), 0, null(), 0, null(), null_mut())
        }),
        ("fmi2SetRealInputDerivatives", INS, |c, a| unsafe {
            fmi2SetRealInputDerivatives(c, &a.fy, 1, &1, &0.5)
        }),
        ("fmi2GetRealOutputDerivatives", OUT_DERIVS, |c, a| unsafe {
            let mut v = 0.0;
            fmi2GetRealOutputDerivatives(c, &a.y, 1, &1, &mut v)
        }),
        ("fmi2DoStep", &[StepComplete], |c, _| unsafe {
            fmi2DoStep(c, BEFORE as f64 * H, H, fmi2True)
        }),
        ("fmi2CancelStep", &[], |c, _| unsafe { fmi2CancelStep(c) }),
        ("fmi2GetStatus", STATUS, |c, _| unsafe {
            let mut v = 0;
            fmi2GetStatus(c, fmi2DoStepStatus, &mut v)
        }),
        ("fmi2GetRealStatus", STATUS, |c, _| unsafe {
            let mut v = 0.0;
            fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &mut v)
        }),
        ("fmi2GetIntegerStatus", STATUS, |c, _| unsafe {
            let mut v = 0;
            fmi2GetIntegerStatus(c, fmi2DoStepStatus, &mut v)
        }),
        ("fmi2GetBooleanStatus", STATUS, |c, _| unsafe {
            let mut v = 0;
            fmi2GetBooleanStatus(c, fmi2Terminated, &mut v)
        }),
        ("fmi2GetStringStatus", STATUS, |c, _| unsafe {
            let mut v: fmi2String = null();
            fmi2GetStringStatus(c, fmi2PendingStatus, &mut v)
        }),
    ]
}

fn args(fx: &Packed, donor: &Slave) -> Args {
    let state = donor.get_state();
    let bytes = donor.serialize(state);
    let method = fx.vr("method");
    Args {
        fy: fx.vr("node_121.fy"),
        y: fx.vr("node_121.y"),
        method,
        method_value: fx.p.table.default_method as i32,
        state,
        bytes,
    }
}

#[test]
fn every_call_in_every_state_where_it_is_illegal() {
    let fx = packed("matrix");
    let twin = reference(&fx);
    let donor = Slave::started(&fx, None);
    run(&donor, &fx, 0, BEFORE).unwrap();
    let a = args(&fx, &donor);
    let mut counts = BTreeMap::new();
    let reach = |at: At| matrix::reach_cs::<Slave>(&fx, at, "matrix");
    let said = |name: &str, _: At, new: &[crate::common::fmu::Msg]| {
        new.iter().any(|m| {
            m.status == fmi2Error
                && (m
                    .text
                    .starts_with(&format!("{name}: illegal call in state"))
                    || (name == "fmi2GetDirectionalDerivative" && m.text.contains("not provided")))
        })
    };
    let after = |s: &Slave, what: &str| matrix::recovers_by_reset(s, &fx, &twin, what);
    Matrix {
        legal_too: false,
        ..Matrix::new(&ALL, &a, &reach, &said, &after)
    }
    .run(&calls(), "illegal state", &mut counts);
    // A NULL component: refused by every function, nothing else happens.
    matrix::null_refused(&calls(), &a, "NULL component", &mut counts);
    // SAFETY: NULL is explicitly allowed; static strings are returned.
    unsafe {
        fmi2FreeInstance(null_mut());
        fmi2FreeInstance(null_mut());
        assert_eq!(
            std::ffi::CStr::from_ptr(fmi2GetTypesPlatform()).to_str(),
            Ok("default")
        );
        assert_eq!(
            std::ffi::CStr::from_ptr(fmi2GetVersion()).to_str(),
            Ok("2.0")
        );
    }
    *counts.entry("NULL component").or_insert(0) += 2;
    donor.free_state(a.state);
    print_counts("misuse matrix", &counts);
    // 70 before issue 13 over 5 states; 14 calls became legal in Error (4 Gets, 3 state
    // saves, SetDebugLogging, output derivatives, 5 status queries); the new ErrorEarly
    // state adds 17 (30 calls less the 8 state, logging and reset functions and the 5
    // status queries).
    assert_eq!(counts["illegal state"], 73);
}

/// Issue 13: in the Error state reads and saves answer for the state before the error.
/// Reference: the undisturbed twin (its value after BEFORE steps, and its future).
#[test]
fn reads_and_saves_in_the_error_state() {
    let fx = packed("errread");
    let twin = reference(&fx);
    let y = fx.vr("node_121.y");
    let s = Slave::started(&fx, None);
    run(&s, &fx, 0, BEFORE).unwrap();
    let before = s.fingerprint();
    // A refused step (the master is 0.5 s ahead): Error, nothing changed.
    let t = BEFORE as f64 * H;
    assert_eq!(s.do_step(t + 0.5, H), fmi2Error);
    assert_eq!(s.fmi_state(), FmiState::Error);
    assert!(s.fingerprint() == before);
    // GetReal in Error: the last consistent values, the twin's after BEFORE steps.
    let mut o = [0.0];
    assert_eq!(s.get_real(&[y], &mut o), fmi2OK, "{}", s.last_error());
    assert_eq!(o[0].to_bits(), twin[BEFORE - 1].to_bits());
    // The status queries are allowed in Error: fmi2LastSuccessfulTime is the time before
    // the refused step (the twin's after BEFORE steps), and the instance stays in Error.
    let mut last = f64::NAN;
    // SAFETY: a live instance, a writable status.
    assert_eq!(
        unsafe { fmi2GetRealStatus(s.c, fmi2LastSuccessfulTime, &mut last) },
        fmi2OK
    );
    assert_eq!(last, BEFORE as f64 * H);
    assert_eq!(s.fmi_state(), FmiState::Error);
    // GetFMUstate in Error saves the state before the error (stepComplete), which
    // restores into a fresh instance and there continues like the twin.
    let saved = s.get_state();
    let bytes = s.serialize(saved);
    assert_eq!(s.fmi_state(), FmiState::Error);
    let fresh = Slave::started(&fx, None);
    let (st, h) = fresh.deserialize(&bytes);
    assert_eq!(st, fmi2OK);
    assert_eq!(fresh.set_state(h), fmi2OK);
    assert_eq!(fresh.fmi_state(), FmiState::StepComplete);
    assert!(same_bits(
        &run(&fresh, &fx, BEFORE, AFTER).unwrap(),
        &twin[BEFORE..]
    ));
    fresh.free_state(h);
    // And in the instance itself: SetFMUstate is the way out of Error.
    assert_eq!(s.set_state(saved), fmi2OK);
    assert_eq!(s.fmi_state(), FmiState::StepComplete);
    assert!(same_bits(
        &run(&s, &fx, BEFORE, AFTER).unwrap(),
        &twin[BEFORE..]
    ));
    s.free_state(saved);

    // Error before initialisation: no values exist, so a read is refused (naming the
    // state before the error) and changes nothing; a save records instantiated.
    let e = Slave::new(&fx, "early");
    assert_eq!(e.do_step(0.0, H), fmi2Error);
    let print = e.fingerprint();
    assert_eq!(e.get_real(&[y], &mut o), fmi2Error);
    assert!(
        e.last_error()
            .contains("Error entered from state Instantiated"),
        "{}",
        e.last_error()
    );
    assert!(e.fingerprint() == print);
    let early = e.get_state();
    let other = Slave::new(&fx, "other");
    assert_eq!(other.set_state(early), fmi2OK);
    assert_eq!(other.fmi_state(), FmiState::Instantiated);
    assert_eq!(other.setup(0.0, None), fmi2OK);
    // SAFETY: a live instance.
    unsafe {
        assert_eq!(fmi2EnterInitializationMode(other.c), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(other.c), fmi2OK);
    }
    assert!(same_bits(&run(&other, &fx, 0, twin.len()).unwrap(), &twin));
    e.free_state(early);
    println!("error state: 2 reads, 1 status query, 2 saves restored");
}

/// `a - b` in ulps at the larger of `|a|`, `|b|`, `|start|`.
fn ulps(a: f64, b: f64, start: f64) -> f64 {
    let big = a.abs().max(b.abs()).max(start.abs());
    (a - b).abs() / (f64::from_bits(big.to_bits() + 1) - big)
}

/// Issue 13: the communication point must be the FMU's time within a few ulps (plus
/// 1e-9 h), at any magnitude. Masters that keep time in floating point in the usual
/// ways pass over a million steps; a point 0.5 s ahead at t = 1e9 is refused.
#[test]
fn communication_point_tolerance_scales_with_the_time() {
    use fxbody::fmu::simulation::check_step_times;
    let h = 1e-3;
    let n = 1_000_000;
    // Three masters, the FMU adopting the master's t + h after each step:
    // accumulating (t += h), multiplying (t = start + k h), and fmpy's (next = start +
    // (k + 1) h, step size = next - t; fmpy/simulation.py simulateCS).
    for start in [0.0, -0.5 - 1000.0, 1e6] {
        let (mut acc, mut worst, mut drift) = (start, 0.0f64, 0.0f64);
        let (mut fmu_a, mut fmu_m, mut fmu_f) = (start, start, start);
        for k in 0..n {
            let mult = start + k as f64 * h;
            check_step_times(acc, h, fmu_a, start, None).unwrap();
            check_step_times(mult, h, fmu_m, start, None).unwrap();
            let next = start + (k + 1) as f64 * h;
            check_step_times(mult, next - mult, fmu_f, start, None).unwrap();
            worst = worst
                .max(ulps(mult, fmu_m, start))
                .max(ulps(mult, fmu_f, start));
            fmu_a = acc + h;
            fmu_m = mult + h;
            fmu_f = mult + (next - mult);
            acc += h;
            drift = drift.max((acc - (start + (k + 1) as f64 * h)).abs());
        }
        println!(
            "start {start}: accumulating master drifts {drift:e} s from k h ({:.0} ulps); \
             multiplying/fmpy masters differ from the FMU's t + h by at most {worst} ulps",
            ulps(acc, start + n as f64 * h, 0.0)
        );
        assert!(worst <= 2.0, "{worst} ulps");
        // The drift is real (many ulps), yet the accumulating master passed every step.
        assert!(ulps(acc, start + n as f64 * h, 0.0) > 100.0);
    }
    // Large times: a point 0.5 s (or one step, or 1e-5 s = 84 ulps) off is refused; one
    // ulp off is accepted.
    let t = 1e9;
    for off in [0.5, -0.5, h, 1e-5] {
        let e = check_step_times(t + off, h, t, t, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("is not the FMU's current time"), "{e}");
    }
    check_step_times(f64::from_bits(t.to_bits() + 1), h, t, t, None).unwrap();
    // Negative stop: landing on it (from either side of the rounding) is accepted, one
    // step past it is not.
    let stop = -0.5;
    let t0 = stop - h;
    check_step_times(t0, h, t0, -1.0, Some(stop)).unwrap();
    check_step_times(t0, stop - t0, t0, -1.0, Some(stop)).unwrap();
    assert!(
        check_step_times(stop, h, stop, -1.0, Some(stop))
            .unwrap_err()
            .to_string()
            .contains("past stopTime")
    );
}

/// Issue 13 through the exports: a run starting at t = 1e9 refuses a point 0.5 s ahead
/// (state unchanged), then continues; and a run with negative start and stop times
/// lands on stopTime = -0.5 and refuses the step past it. Reference: the twin started
/// at 0 (the body's response does not depend on the absolute time), bit for bit.
#[test]
fn large_and_negative_times_through_the_exports() {
    let fx = packed("times");
    let twin = reference(&fx);
    let (f, y) = (fx.vr("node_121.fy"), fx.vr("node_121.y"));
    let steps = twin.len();
    for (start, stop) in [
        (1e9, None),
        (-0.5 - steps as f64 * H, Some(-0.5)),
        (-3.0, Some(-3.0 + steps as f64 * H)),
    ] {
        let s = Slave::new(&fx, "times");
        assert_eq!(s.setup(start, stop), fmi2OK, "{}", s.last_error());
        // SAFETY: a live instance.
        unsafe {
            assert_eq!(fmi2EnterInitializationMode(s.c), fmi2OK);
            assert_eq!(fmi2ExitInitializationMode(s.c), fmi2OK);
        }
        let mut out = Vec::new();
        let mut o = [0.0];
        let mut t = start;
        for k in 0..steps {
            assert_eq!(
                s.set_real(&[f], &[crate::common::fmu::load(k as f64 * H)]),
                fmi2OK
            );
            if k == BEFORE {
                // Ahead by 0.5 s: refused, nothing changed, then the right point works.
                let print = s.fingerprint();
                assert_eq!(s.do_step(t + 0.5, H), fmi2Error);
                assert!(s.last_error().contains("is not the FMU's current time"));
                assert!(s.fingerprint() == print);
                s.force_state(FmiState::StepComplete);
            }
            assert_eq!(
                s.do_step(t, H),
                fmi2OK,
                "start {start} step {k}: {}",
                s.last_error()
            );
            assert_eq!(s.get_real(&[y], &mut o), fmi2OK);
            out.push(o[0]);
            // A master that accumulates its time.
            t += H;
        }
        assert!(same_bits(&out, &twin), "start {start}");
        if let Some(stop) = stop {
            let print = s.fingerprint();
            assert_eq!(s.do_step(t, H), fmi2Error);
            assert!(
                s.last_error().contains("past stopTime"),
                "{}",
                s.last_error()
            );
            assert!(s.fingerprint() == print);
            // The time reached is stopTime (within the tolerance).
            assert!((t - stop).abs() < 1e-12, "{t} {stop}");
        }
    }
}
