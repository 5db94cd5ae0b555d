//! FMI misuse matrix (issue 9): every export called in every reachable state where the
//! call sequence forbids it, and with the arguments a careless master passes (NULL
//! component and arrays, nvr = 0, unknown value references, values on outputs, NaN and
//! infinite forces, bad step sizes and times, steps past stopTime, damaged serialised
//! states, double frees, '%' in instance names). The calls go straight to the crate's
//! `extern "C"` functions.
//!
//! References, per case: the process survives; the status is what FMI 2.0 and
//! docs/ROBUSTNESS.md say (fmi2Error for every refusal, with a logged reason); the
//! instance then either continues exactly as an undisturbed twin (same bits) or reports
//! the Error state and recovers by fmi2Reset / fmi2SetFMUstate to the twin's bits; a
//! refused call leaves the model's complete state (parameters, inputs, times, solver:
//! its serialised snapshot) byte for byte unchanged. Each test prints its case counts.
#![cfg(all(target_os = "linux", any(target_arch = "x86_64", target_arch = "aarch64")))]

mod robust_common;

use std::collections::BTreeMap;
use std::ffi::{CString, c_char};
use std::ptr::{null, null_mut};

use fxbody::fmi::exports::*;
use fxbody::fmi::state::FmiState;
use fxbody::fmi::types::*;
use fxbody::fmu::snapshot::Snapshot;
use fxbody::fmu::vars::Causality;
use robust_common::{H, Packed, Slave, packed, run, same_bits};

/// Steps run before a misuse, and after it.
const BEFORE: usize = 5;
const AFTER: usize = 5;

/// The states a master can reach: where each case starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum At {
    Instantiated,
    InitializationMode,
    StepComplete,
    Terminated,
    Error,
}
use At::*;
const ALL: [At; 5] = [
    Instantiated,
    InitializationMode,
    StepComplete,
    Terminated,
    Error,
];

/// Reach `at` with a fresh instance (StepComplete and later after BEFORE steps).
fn reach(fx: &Packed, at: At) -> Slave {
    let s = Slave::new(fx, "matrix");
    if at == Instantiated {
        return s;
    }
    assert_eq!(s.setup(0.0, None), fmi2OK);
    // SAFETY: a live instance.
    assert_eq!(unsafe { fmi2EnterInitializationMode(s.c) }, fmi2OK);
    if at == InitializationMode {
        return s;
    }
    // SAFETY: a live instance.
    assert_eq!(unsafe { fmi2ExitInitializationMode(s.c) }, fmi2OK);
    run(&s, fx, 0, BEFORE).unwrap();
    match at {
        // SAFETY: a live instance.
        Terminated => assert_eq!(unsafe { fmi2Terminate(s.c) }, fmi2OK),
        Error => assert_eq!(s.do_step(1.0, H), fmi2Error),
        _ => {}
    }
    s
}

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

type Call = fn(fmi2Component, &Args) -> fmi2Status;

/// Every export taking a component, with the states where FMI 2.0 allows it (the
/// standard's co-simulation table, plus the documented rule of FMI.md: after an error
/// only Reset, SetFMUstate, FreeInstance, and the state functions that go with them).
fn calls() -> Vec<(&'static str, &'static [At], Call)> {
    const INS: &[At] = &[Instantiated, InitializationMode, StepComplete];
    const GETS: &[At] = &[InitializationMode, StepComplete, Terminated];
    const SAVE: &[At] = &[Instantiated, InitializationMode, StepComplete, Terminated];
    const RESTORE: &[At] = &[
        Instantiated,
        InitializationMode,
        StepComplete,
        Terminated,
        Error,
    ];
    const RUNNING: &[At] = &[StepComplete, Terminated];
    // SAFETY (every closure below): `c` is a live instance and every pointer passed
    // points to valid, writable memory of the length given.
    vec![
        ("fmi2SetDebugLogging", SAVE, |c, _| unsafe {
            fmi2SetDebugLogging(c, fmi2True, 0, null())
        }),
        ("fmi2SetupExperiment", &[Instantiated], |c, _| unsafe {
            fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0)
        }),
        ("fmi2EnterInitializationMode", &[Instantiated], |c, _| unsafe {
            fmi2EnterInitializationMode(c)
        }),
        ("fmi2ExitInitializationMode", &[InitializationMode], |c, _| unsafe {
            fmi2ExitInitializationMode(c)
        }),
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
        ("fmi2GetRealOutputDerivatives", RUNNING, |c, a| unsafe {
            let mut v = 0.0;
            fmi2GetRealOutputDerivatives(c, &a.y, 1, &1, &mut v)
        }),
        ("fmi2DoStep", &[StepComplete], |c, _| unsafe {
            fmi2DoStep(c, BEFORE as f64 * H, H, fmi2True)
        }),
        ("fmi2CancelStep", &[], |c, _| unsafe { fmi2CancelStep(c) }),
        ("fmi2GetStatus", RUNNING, |c, _| unsafe {
            let mut v = 0;
            fmi2GetStatus(c, fmi2DoStepStatus, &mut v)
        }),
        ("fmi2GetRealStatus", RUNNING, |c, _| unsafe {
            let mut v = 0.0;
            fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &mut v)
        }),
        ("fmi2GetIntegerStatus", RUNNING, |c, _| unsafe {
            let mut v = 0;
            fmi2GetIntegerStatus(c, fmi2DoStepStatus, &mut v)
        }),
        ("fmi2GetBooleanStatus", RUNNING, |c, _| unsafe {
            let mut v = 0;
            fmi2GetBooleanStatus(c, fmi2Terminated, &mut v)
        }),
        ("fmi2GetStringStatus", RUNNING, |c, _| unsafe {
            let mut v: fmi2String = null();
            fmi2GetStringStatus(c, fmi2PendingStatus, &mut v)
        }),
    ]
}

/// The undisturbed twin: BEFORE + AFTER steps from a fresh start.
fn reference(fx: &Packed) -> Vec<f64> {
    let r = run(&Slave::started(fx, None), fx, 0, BEFORE + AFTER).unwrap();
    assert!(r.iter().any(|v| v.abs() > 1e-9), "a real response: {r:?}");
    r
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

fn print_counts(what: &str, counts: &BTreeMap<&str, usize>) {
    let total: usize = counts.values().sum();
    for (k, n) in counts {
        println!("{what}: {k}: {n}");
    }
    println!("{what}: total {total}");
}

/// After a refusal the instance says so (Error) and recovers by Reset: a full run from
/// there equals the twin.
fn recovers_by_reset(s: &Slave, fx: &Packed, twin: &[f64]) {
    assert_eq!(s.fmi_state(), FmiState::Error);
    // SAFETY: a live instance.
    assert_eq!(unsafe { fmi2Reset(s.c) }, fmi2OK, "{}", s.last_error());
    assert_eq!(s.setup(0.0, None), fmi2OK);
    // SAFETY: a live instance.
    unsafe {
        assert_eq!(fmi2EnterInitializationMode(s.c), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(s.c), fmi2OK);
    }
    assert!(same_bits(&run(s, fx, 0, twin.len()).unwrap(), twin));
}

#[test]
fn every_call_in_every_state_where_it_is_illegal() {
    let fx = packed("matrix");
    let twin = reference(&fx);
    let donor = Slave::started(&fx, None);
    run(&donor, &fx, 0, BEFORE).unwrap();
    let a = args(&fx, &donor);
    let mut counts = BTreeMap::new();
    for (name, legal, call) in calls() {
        for at in ALL {
            if legal.contains(&at) {
                continue;
            }
            let s = reach(&fx, at);
            let before = s.fingerprint();
            let n_msgs = s.messages().len();
            let st = call(s.c, &a);
            assert_eq!(st, fmi2Error, "{name} in {at:?}");
            let new: Vec<_> = s.messages()[n_msgs..].to_vec();
            let said = new.iter().any(|m| {
                m.status == fmi2Error
                    && (m.text.starts_with(&format!("{name}: illegal call in state"))
                        || (name == "fmi2GetDirectionalDerivative"
                            && m.text.contains("not provided")))
            });
            assert!(said, "{name} in {at:?}: logged {new:?}");
            assert!(s.fingerprint() == before, "{name} in {at:?} changed the model");
            recovers_by_reset(&s, &fx, &twin);
            *counts.entry("illegal state").or_insert(0) += 1;
        }
    }
    // A NULL component: refused by every function, nothing else happens.
    for (name, _, call) in calls() {
        assert_eq!(call(null_mut(), &a), fmi2Error, "{name}(NULL)");
        *counts.entry("NULL component").or_insert(0) += 1;
    }
    // SAFETY: NULL is explicitly allowed; static strings are returned.
    unsafe {
        fmi2FreeInstance(null_mut());
        fmi2FreeInstance(null_mut());
        assert_eq!(
            std::ffi::CStr::from_ptr(fmi2GetTypesPlatform()).to_str(),
            Ok("default")
        );
        assert_eq!(std::ffi::CStr::from_ptr(fmi2GetVersion()).to_str(), Ok("2.0"));
    }
    *counts.entry("NULL component").or_insert(0) += 2;
    donor.free_state(a.state);
    print_counts("misuse matrix", &counts);
    assert_eq!(counts["illegal state"], 70);
}

/// A slave after BEFORE steps, its saved state and fingerprint.
struct Midway {
    s: Slave,
    saved: fmi2FMUstate,
    print: Vec<u8>,
}

fn midway(fx: &Packed, stop: Option<f64>) -> Midway {
    let s = Slave::started(fx, stop);
    run(&s, fx, 0, BEFORE).unwrap();
    let saved = s.get_state();
    let print = s.fingerprint();
    Midway { s, saved, print }
}

impl Midway {
    /// The refused call left the model untouched: the fingerprint is the same, and
    /// (white box) allowed to continue, the next steps equal the twin's bit for bit;
    /// then the FMI way out, SetFMUstate, gives the same bits again.
    fn unchanged(&self, fx: &Packed, twin: &[f64], what: &str) {
        let s = &self.s;
        assert!(s.fingerprint() == self.print, "{what}: model changed");
        if s.fmi_state() == FmiState::Error {
            s.force_state(FmiState::StepComplete);
        }
        let cont = run(s, fx, BEFORE, AFTER).unwrap();
        assert!(same_bits(&cont, &twin[BEFORE..]), "{what}: {cont:?}");
        assert_eq!(s.set_state(self.saved), fmi2OK);
        let again = run(s, fx, BEFORE, AFTER).unwrap();
        assert!(same_bits(&again, &twin[BEFORE..]), "{what} (restored)");
        assert_eq!(s.set_state(self.saved), fmi2OK);
    }

    /// A call refused with fmi2Error and a logged reason holding `says`.
    fn refused(&self, st: fmi2Status, says: &str, what: &str) {
        assert_eq!(st, fmi2Error, "{what}");
        assert_eq!(self.s.fmi_state(), FmiState::Error, "{what}");
        let e = self.s.last_error();
        assert!(e.contains(says), "{what}: logged '{e}', expected '{says}'");
    }
}

impl Drop for Midway {
    fn drop(&mut self) {
        let mut s = self.saved;
        // SAFETY: the live state of this instance, freed once.
        unsafe { fmi2FreeFMUstate(self.s.c, &mut s) };
    }
}

#[test]
fn bad_arguments_are_refused_and_change_nothing() {
    let fx = packed("args");
    let twin = reference(&fx);
    let m = midway(&fx, None);
    let (c, fy, fz, y) = (
        m.s.c,
        fx.vr("node_121.fy"),
        fx.vr("node_121.fz"),
        fx.vr("node_121.y"),
    );
    let mut counts = BTreeMap::new();
    let mut count = |k| *counts.entry(k).or_insert(0usize) += 1;
    let mut v = [0.0; 2];
    let mut iv = [0; 2];
    let mut bv = [0; 2];
    let mut sv: [fmi2String; 2] = [null(); 2];
    let t = BEFORE as f64 * H;

    // NULL arrays with nvr > 0: each call runs from StepComplete (the previous refusal
    // is undone by `unchanged`, which ends with SetFMUstate).
    type Bad = Box<dyn Fn() -> fmi2Status>;
    let (pv, piv, pbv, psv, saved) = (
        v.as_mut_ptr(),
        iv.as_mut_ptr(),
        bv.as_mut_ptr(),
        sv.as_mut_ptr(),
        m.saved,
    );
    let zeros = [0 as c_char; 64];
    let pz = zeros.as_ptr();
    // SAFETY (all closures): `c` is live; each non-NULL pointer is valid for the length
    // given; the NULL pointers are what is being tested.
    let null_cases: Vec<(&str, &str, Bad)> = vec![
        ("GetReal vr", "vr is NULL", Box::new(move || unsafe { fmi2GetReal(c, null(), 1, pv) })),
        ("GetReal value", "value is NULL", Box::new(move || unsafe { fmi2GetReal(c, &y, 1, null_mut()) })),
        ("SetReal vr", "vr is NULL", Box::new(move || unsafe { fmi2SetReal(c, null(), 1, pv) })),
        ("SetReal value", "value is NULL", Box::new(move || unsafe { fmi2SetReal(c, &fy, 1, null()) })),
        ("GetInteger vr", "vr is NULL", Box::new(move || unsafe { fmi2GetInteger(c, null(), 1, piv) })),
        ("SetInteger value", "value is NULL", Box::new(move || unsafe { fmi2SetInteger(c, &y, 1, null()) })),
        ("GetBoolean vr", "vr is NULL", Box::new(move || unsafe { fmi2GetBoolean(c, null(), 1, pbv) })),
        ("SetBoolean vr", "vr is NULL", Box::new(move || unsafe { fmi2SetBoolean(c, null(), 1, pbv) })),
        ("GetString vr", "vr is NULL", Box::new(move || unsafe { fmi2GetString(c, null(), 1, psv) })),
        ("SetString vr", "vr is NULL", Box::new(move || unsafe { fmi2SetString(c, null(), 1, psv) })),
        ("SetRealInputDerivatives order", "order is NULL", Box::new(move || unsafe { fmi2SetRealInputDerivatives(c, &fy, 1, null(), pv) })),
        ("SetRealInputDerivatives value", "value is NULL", Box::new(move || unsafe { fmi2SetRealInputDerivatives(c, &fy, 1, &1, null()) })),
        ("GetRealOutputDerivatives value", "value is NULL", Box::new(move || unsafe { fmi2GetRealOutputDerivatives(c, &y, 1, &1, null_mut()) })),
        ("SetDebugLogging categories", "categories is NULL", Box::new(move || unsafe { fmi2SetDebugLogging(c, fmi2True, 3, null()) })),
        ("SetDebugLogging category", "category name is NULL", Box::new(move || unsafe { fmi2SetDebugLogging(c, fmi2True, 1, [null()].as_ptr()) })),
        ("GetFMUstate", "pointer is NULL", Box::new(move || unsafe { fmi2GetFMUstate(c, null_mut()) })),
        ("SetFMUstate", "FMUstate is NULL", Box::new(move || unsafe { fmi2SetFMUstate(c, null_mut()) })),
        ("SerializedFMUstateSize state", "FMUstate is NULL", Box::new(move || unsafe { fmi2SerializedFMUstateSize(c, null_mut(), &mut 0) })),
        ("SerializedFMUstateSize size", "size pointer is NULL", Box::new(move || unsafe { fmi2SerializedFMUstateSize(c, saved, null_mut()) })),
        ("SerializeFMUstate buffer", "buffer is", Box::new(move || unsafe { fmi2SerializeFMUstate(c, saved, null_mut(), 16) })),
        ("DeSerializeFMUstate bytes", "serializedState is NULL", Box::new(move || unsafe { fmi2DeSerializeFMUstate(c, null(), 64, &mut null_mut()) })),
        ("DeSerializeFMUstate state", "FMUstate pointer is NULL", Box::new(move || unsafe { fmi2DeSerializeFMUstate(c, pz, 64, null_mut()) })),
        ("GetRealStatus value", "value pointer is NULL", Box::new(move || unsafe { fmi2GetRealStatus(c, fmi2LastSuccessfulTime, null_mut()) })),
        ("GetBooleanStatus value", "value pointer is NULL", Box::new(move || unsafe { fmi2GetBooleanStatus(c, fmi2Terminated, null_mut()) })),
    ];
    for (what, says, call) in &null_cases {
        m.refused(call(), says, what);
        m.unchanged(&fx, &twin, what);
        count("NULL array");
    }

    // nvr = 0 with NULL arrays: nothing to do, OK, nothing changes, no error state.
    // SAFETY (all closures): nvr = 0, so no pointer is read.
    let empty: Vec<(&str, Bad)> = vec![
        ("GetReal", Box::new(move || unsafe { fmi2GetReal(c, null(), 0, null_mut()) })),
        ("SetReal", Box::new(move || unsafe { fmi2SetReal(c, null(), 0, null()) })),
        ("GetInteger", Box::new(move || unsafe { fmi2GetInteger(c, null(), 0, null_mut()) })),
        ("SetInteger", Box::new(move || unsafe { fmi2SetInteger(c, null(), 0, null()) })),
        ("GetBoolean", Box::new(move || unsafe { fmi2GetBoolean(c, null(), 0, null_mut()) })),
        ("SetBoolean", Box::new(move || unsafe { fmi2SetBoolean(c, null(), 0, null()) })),
        ("GetString", Box::new(move || unsafe { fmi2GetString(c, null(), 0, null_mut()) })),
        ("SetString", Box::new(move || unsafe { fmi2SetString(c, null(), 0, null()) })),
        ("SetRealInputDerivatives", Box::new(move || unsafe { fmi2SetRealInputDerivatives(c, null(), 0, null(), null()) })),
        ("GetRealOutputDerivatives", Box::new(move || unsafe { fmi2GetRealOutputDerivatives(c, null(), 0, null(), null_mut()) })),
    ];
    for (what, call) in &empty {
        assert_eq!(call(), fmi2OK, "{what} with nvr = 0");
        assert_eq!(m.s.fmi_state(), FmiState::StepComplete, "{what}");
        m.unchanged(&fx, &twin, what);
        count("nvr = 0");
    }

    // Unknown value references, in every function that takes one.
    let n = fx.p.table.vars.len() as u32;
    for bad in [n, n + 1, 99_999, u32::MAX] {
        let b = [bad];
        let pb = b.as_ptr();
        // SAFETY (all closures): arrays of one element.
        let unknown: Vec<(&str, &str, Bad)> = vec![
            ("GetReal", "unknown value reference", Box::new(move || unsafe { fmi2GetReal(c, pb, 1, pv) })),
            ("SetReal", "unknown value reference", Box::new(move || unsafe { fmi2SetReal(c, pb, 1, &1.0) })),
            ("GetInteger", "unknown value reference", Box::new(move || unsafe { fmi2GetInteger(c, pb, 1, piv) })),
            ("SetInteger", "unknown value reference", Box::new(move || unsafe { fmi2SetInteger(c, pb, 1, &1) })),
            ("GetBoolean", "no Boolean variables", Box::new(move || unsafe { fmi2GetBoolean(c, pb, 1, pbv) })),
            ("SetBoolean", "no Boolean variables", Box::new(move || unsafe { fmi2SetBoolean(c, pb, 1, &1) })),
            ("GetString", "no String variables", Box::new(move || unsafe { fmi2GetString(c, pb, 1, psv) })),
            ("SetString", "no String variables", Box::new(move || unsafe { fmi2SetString(c, pb, 1, [c"x".as_ptr()].as_ptr()) })),
            ("SetRealInputDerivatives", "unknown value reference", Box::new(move || unsafe { fmi2SetRealInputDerivatives(c, pb, 1, &1, &1.0) })),
            ("GetRealOutputDerivatives", "unknown value reference", Box::new(move || unsafe { fmi2GetRealOutputDerivatives(c, pb, 1, &1, pv) })),
        ];
        for (what, says, call) in &unknown {
            m.refused(call(), says, &format!("{what} vr {bad}"));
            m.unchanged(&fx, &twin, what);
            count("unknown value reference");
        }
        // A good reference first and the unknown one second: still all refused.
        let pair = [fy, bad];
        m.refused(
            // SAFETY: arrays of two elements.
            unsafe { fmi2SetReal(c, pair.as_ptr(), 2, [3.0, 1.0].as_ptr()) },
            "unknown value reference",
            "SetReal good + unknown",
        );
        m.unchanged(&fx, &twin, "SetReal good + unknown");
        count("unknown value reference");
    }

    // Values set on outputs, and on parameters after initialisation; the wrong type.
    for var in &fx.p.table.vars {
        let (st, says) = if var.is_integer() {
            // SAFETY: arrays of one element.
            (unsafe { fmi2SetReal(c, &var.vr, 1, &1.0) }, "fmi2SetInteger")
        } else {
            // SAFETY: arrays of one element.
            (unsafe { fmi2SetInteger(c, &var.vr, 1, &1) }, "fmi2SetReal")
        };
        m.refused(st, says, &format!("wrong type on {}", var.name));
        m.unchanged(&fx, &twin, &var.name);
        count("wrong type");
        let says = match var.causality {
            Causality::Input => continue,
            Causality::Output => "is an output",
            Causality::Parameter => "fixed parameter",
        };
        let st = if var.is_integer() {
            // SAFETY: arrays of one element.
            unsafe { fmi2SetInteger(c, &var.vr, 1, &1) }
        } else {
            // SAFETY: arrays of one element.
            unsafe { fmi2SetReal(c, &var.vr, 1, &0.5) }
        };
        m.refused(st, says, &var.name);
        m.unchanged(&fx, &twin, &var.name);
        count(if var.causality == Causality::Output {
            "set an output"
        } else {
            "set a parameter after initialisation"
        });
    }

    // NaN and infinite forces and force rates: alone, and after a valid value in the
    // same call (the valid one must not be applied either).
    for bad in [f64::NAN, -f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        m.refused(m.s.set_real(&[fy], &[bad]), "must be finite", "bad force");
        m.unchanged(&fx, &twin, "bad force");
        m.refused(m.s.set_real(&[fz, fy], &[2.0, bad]), "must be finite", "good + bad");
        m.unchanged(&fx, &twin, "good + bad force");
        m.refused(
            // SAFETY: arrays of two elements.
            unsafe { fmi2SetRealInputDerivatives(c, [fz, fy].as_ptr(), 2, [1, 1].as_ptr(), [2.0, bad].as_ptr()) },
            "must be finite",
            "bad force rate",
        );
        m.unchanged(&fx, &twin, "bad force rate");
        count("non-finite force");
        count("non-finite force");
        count("non-finite force");
    }
    // Derivative orders that do not exist.
    for order in [0, 2, 3, -1, i32::MAX] {
        m.refused(
            // SAFETY: arrays of one element.
            unsafe { fmi2SetRealInputDerivatives(c, &fy, 1, &order, &1.0) },
            "order",
            "input derivative order",
        );
        m.unchanged(&fx, &twin, "input derivative order");
        count("bad derivative order");
    }
    for order in [0, 3, -1, i32::MIN] {
        m.refused(
            // SAFETY: arrays of one element.
            unsafe { fmi2GetRealOutputDerivatives(c, &y, 1, &order, pv) },
            "no derivative of order",
            "output derivative order",
        );
        m.unchanged(&fx, &twin, "output derivative order");
        count("bad derivative order");
    }

    // Step sizes and communication points that are wrong.
    for h in [0.0, -0.0, -H, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -f64::MIN_POSITIVE] {
        m.refused(m.s.do_step(t, h), "communicationStepSize", &format!("h = {h}"));
        m.unchanged(&fx, &twin, "bad h");
        count("h <= 0 or not finite");
    }
    for tc in [t + H, t - H, 0.0, 1e9, -t, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, t * (1.0 + 1e-6)] {
        m.refused(m.s.do_step(tc, H), "current time", &format!("t = {tc}"));
        m.unchanged(&fx, &twin, "wrong time");
        count("wrong current time");
    }
    // Status kinds that do not exist: Discard, nothing written, the instance continues.
    for kind in [-1, 4, 99, i32::MIN] {
        let mut r = -7.0;
        let mut b = -7;
        // SAFETY: writable values.
        let (s1, s2) = unsafe {
            (
                fmi2GetRealStatus(c, kind, &mut r),
                fmi2GetBooleanStatus(c, kind, &mut b),
            )
        };
        assert_eq!((s1, s2, r, b), (fmi2Discard, fmi2Discard, -7.0, -7));
        assert_eq!(m.s.fmi_state(), FmiState::StepComplete);
        m.unchanged(&fx, &twin, "status kind");
        count("unknown status kind");
    }
    // Unknown log categories (with '%' in the name: the text reaches the log as is).
    let cat = CString::new("%s%n%d").unwrap();
    m.refused(
        // SAFETY: one valid category string.
        unsafe { fmi2SetDebugLogging(c, fmi2True, 1, [cat.as_ptr()].as_ptr()) },
        "unknown log category '%s%n%d'",
        "category",
    );
    m.unchanged(&fx, &twin, "category");
    count("unknown log category");
    print_counts("bad arguments", &counts);
}

#[test]
fn steps_past_stop_time_are_refused() {
    let fx = packed("stop");
    let twin = reference(&fx);
    let stop = (BEFORE + AFTER) as f64 * H;
    let m = midway(&fx, Some(stop));
    let t = BEFORE as f64 * H;
    let mut n = 0;
    for h in [stop, 2.0 * stop, (AFTER as f64 + 0.01) * H, 1e300] {
        m.refused(m.s.do_step(t, h), "past stopTime", &format!("h = {h}"));
        m.unchanged(&fx, &twin, "past stopTime");
        n += 1;
    }
    // Right up to stopTime is fine; one more step is not.
    assert_eq!(run(&m.s, &fx, BEFORE, AFTER).unwrap(), twin[BEFORE..].to_vec());
    assert_eq!(m.s.do_step(stop, H), fmi2Error);
    assert!(m.s.last_error().contains("past stopTime"));
    // A stop time before the start, or NaN, is refused at setup.
    for (start, stop) in [(1.0, 0.5), (0.0, f64::NAN), (f64::NAN, 1.0), (f64::INFINITY, 1.0)] {
        let s = Slave::new(&fx, "setup");
        assert_eq!(s.setup(start, Some(stop)), fmi2Error, "{start} {stop}");
        n += 1;
    }
    println!("past stopTime: {} cases", n + 1);
}

/// FNV-free crafting: states built as Snapshots, then serialised by the library's own
/// writer (so the checksum is right and the reader must judge the content).
fn crafted(good: &Snapshot) -> Vec<(&'static str, Snapshot)> {
    let mut out = Vec::new();
    let mut add = |what, f: &dyn Fn(&mut Snapshot)| {
        let mut s = good.clone();
        f(&mut s);
        out.push((what, s));
    };
    add("time NaN", &|s| s.time = f64::NAN);
    add("time Inf", &|s| s.time = f64::INFINITY);
    add("start NaN", &|s| s.start_time = f64::NAN);
    add("stop NaN", &|s| s.stop_time = Some(f64::NAN));
    add("stop before time", &|s| s.stop_time = Some(s.time - 1.0));
    add("rho_inf NaN", &|s| s.rho_inf = f64::NAN);
    add("rho_inf 2", &|s| s.rho_inf = 2.0);
    add("gravity Inf", &|s| s.gravity[1] = f64::INFINITY);
    add("v0 NaN", &|s| s.v0[0] = f64::NAN);
    add("w0 NaN", &|s| s.w0[2] = f64::NAN);
    add("load NaN", &|s| s.loads[1] = f64::NAN);
    add("rate Inf", &|s| s.rates[1] = f64::NEG_INFINITY);
    add("one load too many", &|s| s.loads.push(0.0));
    add("one rate too few", &|s| {
        s.rates.pop();
    });
    add("phase 99", &|s| s.phase = 99);
    add("phase Error", &|s| s.phase = 7);
    add("method 0", &|s| s.method = 0);
    add("method 99", &|s| s.method = 99);
    add("solver data short", &|s| {
        if let Some(st) = s.solver.as_mut() {
            st.data.pop();
        }
    });
    add("solver data long", &|s| {
        if let Some(st) = s.solver.as_mut() {
            st.data.push(1.0);
        }
    });
    add("solver data NaN", &|s| {
        if let Some(st) = s.solver.as_mut() {
            st.data[0] = f64::NAN;
        }
    });
    add("solver method differs", &|s| {
        if let Some(st) = s.solver.as_mut() {
            st.method = if st.method == fxbody::solver::Method::Exact {
                fxbody::solver::Method::Implicit
            } else {
                fxbody::solver::Method::Exact
            };
        }
    });
    out
}

#[test]
fn damaged_serialised_states_are_refused() {
    let fx = packed("deser");
    let twin = reference(&fx);
    let m = midway(&fx, None);
    let good = m.s.serialize(m.saved);
    let mut counts = BTreeMap::new();
    // Every check: refused with fmi2Error (the instance reports it), the model
    // unchanged, and SetFMUstate of the good state continues like the twin.
    let mut refuse = |bytes: &[u8], kind: &'static str| {
        let (st, h) = m.s.deserialize(bytes);
        assert_eq!(st, fmi2Error, "{kind}: {} bytes accepted", bytes.len());
        assert!(h.is_null());
        assert!(m.s.fingerprint() == m.print, "{kind}");
        *counts.entry(kind).or_insert(0usize) += 1;
    };
    for n in 0..good.len() {
        refuse(&good[..n], "truncated");
    }
    let mut longer = good.clone();
    longer.push(0);
    refuse(&longer, "truncated");
    for p in 0..good.len() {
        for mask in [0x01u8, 0x80, 0xff] {
            let mut b = good.clone();
            b[p] ^= mask;
            refuse(&b, "byte flip");
        }
    }
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        rng
    };
    for k in 0..1000 {
        let n = (next() % 2048) as usize;
        let mut b: Vec<u8> = (0..n).map(|_| next() as u8).collect();
        if k % 2 == 0 && b.len() >= 8 {
            b[..8].copy_from_slice(b"FXBSTATE");
        }
        refuse(&b, "random bytes");
    }
    // Well-formed bytes (right checksum) with content that must not be restored.
    let snap = Snapshot::from_bytes(&good, &fx.p.guid).unwrap();
    for (what, bad) in crafted(&snap) {
        let bytes = bad.to_bytes(&fx.p.guid);
        let (st, h) = m.s.deserialize(&bytes);
        if st == fmi2OK {
            let st = m.s.set_state(h);
            let mut hh = h;
            // SAFETY: the live state just made, freed once.
            unsafe { fmi2FreeFMUstate(m.s.c, &mut hh) };
            assert_eq!(st, fmi2Error, "{what}: restored");
        } else {
            assert_eq!(st, fmi2Error, "{what}");
        }
        assert_eq!(m.s.fmi_state(), FmiState::Error, "{what}");
        m.unchanged(&fx, &twin, what);
        *counts.entry("crafted content").or_insert(0) += 1;
    }
    // And the good bytes still restore to the twin's future.
    let (st, h) = m.s.deserialize(&good);
    assert_eq!(st, fmi2OK);
    assert_eq!(m.s.set_state(h), fmi2OK);
    assert!(same_bits(&run(&m.s, &fx, BEFORE, AFTER).unwrap(), &twin[BEFORE..]));
    m.s.free_state(h);
    assert_eq!(m.s.set_state(m.saved), fmi2OK);
    // A buffer of the wrong size for fmi2SerializeFMUstate.
    for n in [0, good.len() - 1, good.len() + 1] {
        let mut buf = vec![0u8; n.max(1)];
        // SAFETY: `buf` holds at least `n` writable bytes.
        let st = unsafe { fmi2SerializeFMUstate(m.s.c, m.saved, buf.as_mut_ptr().cast(), n) };
        assert_eq!(st, fmi2Error, "buffer of {n} bytes");
        m.unchanged(&fx, &twin, "serialise buffer");
        *counts.entry("serialise buffer size").or_insert(0) += 1;
    }
    print_counts("deserialise", &counts);
}

#[test]
fn double_frees_and_percent_names() {
    let fx = packed("free");
    let twin = reference(&fx);
    let mut n = 0;
    // FreeFMUstate sets the handle to NULL, so freeing the same variable twice is a
    // no-op; a NULL handle pointer is ignored too.
    let s = Slave::started(&fx, None);
    let mut st = s.get_state();
    // SAFETY: a live state, then the NULL it was set to; then a NULL pointer.
    unsafe {
        assert_eq!(fmi2FreeFMUstate(s.c, &mut st), fmi2OK);
        assert!(st.is_null());
        assert_eq!(fmi2FreeFMUstate(s.c, &mut st), fmi2OK);
        assert_eq!(fmi2FreeFMUstate(s.c, null_mut()), fmi2OK);
    }
    n += 3;
    assert!(same_bits(&run(&s, &fx, 0, twin.len()).unwrap(), &twin));
    // FreeInstance(NULL), twice, between live instances: ignored.
    // SAFETY: NULL is allowed.
    unsafe {
        fmi2FreeInstance(null_mut());
        fmi2FreeInstance(null_mut());
    }
    n += 2;
    // A freed instance whose handle the master clears (as fmpy does) can be "freed"
    // again: that is FreeInstance(NULL). Freeing a dangling handle is undefined in FMI
    // and not detected (docs/ROBUSTNESS.md): no global registry of instances exists.
    let mut t = Slave::new(&fx, "freed");
    // SAFETY: a live instance, freed once; the handle is then cleared.
    unsafe { fmi2FreeInstance(t.c) };
    t.c = null_mut();
    drop(t);
    n += 1;
    println!("double free: {n} cases");

    // '%' in the instance name: every message reaches the logger with the format "%s"
    // and the name verbatim.
    let name = "100%s %n %d%% %";
    let p = Slave::new(&fx, name);
    assert_eq!(p.do_step(0.0, H), fmi2Error);
    // SAFETY: a live instance.
    assert_eq!(unsafe { fmi2Reset(p.c) }, fmi2OK);
    let msgs = p.messages();
    assert!(msgs.len() >= 3, "{msgs:?}");
    for msg in &msgs {
        assert_eq!(msg.format, "%s", "{msg:?}");
        assert_eq!(msg.name, name, "{msg:?}");
    }
    assert!(msgs.iter().any(|m| m.text.contains("illegal call")));
    // Instantiation that fails still logs through "%s" with the name.
    let msgs = Slave::try_with(&fx.p.guid, "file:///no/such/%25s/dir", name)
        .err()
        .unwrap();
    assert!(!msgs.is_empty());
    for msg in &msgs {
        assert_eq!((msg.format.as_str(), msg.name.as_str()), ("%s", name));
    }
    println!("percent in names: {} messages checked", p.messages().len() + msgs.len());
}

#[test]
fn instantiate_refuses_bad_arguments() {
    let fx = packed("inst");
    let twin = reference(&fx);
    let sink: robust_common::LogSink = std::sync::Mutex::new(Vec::new());
    let cb = fmi2CallbackFunctions {
        logger: robust_common::logger(),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: (&sink as *const robust_common::LogSink).cast_mut().cast(),
    };
    let guid = CString::new(fx.p.guid.as_str()).unwrap();
    let uri = CString::new(fx.uri.as_str()).unwrap();
    let name = c"inst";
    let raw = |s: &[u8]| CString::new(s).unwrap();
    let uris = [
        raw(b""),
        raw(b"file://otherhost/x"),
        raw(b"file:///no/such/dir"),
        raw(b"http://example.com/resources"),
        raw(b"file://%zz%"),
        raw(b"%"),
        raw(b"file:///\xff\xfe/resources"),
        raw(b"file:///tmp/%00x"),
    ];
    let other_guid = raw(b"{00000000-0000-0000-0000-000000000000}");
    let mut cases: Vec<(String, fmi2Component)> = Vec::new();
    // SAFETY (all calls): every pointer is NULL or a valid C string / callback struct
    // for the call.
    unsafe {
        let mut try_one = |what: &str, n: fmi2String, ty, g: fmi2String, u: fmi2String, f: *const fmi2CallbackFunctions| {
            cases.push((what.to_string(), fmi2Instantiate(n, ty, g, u, f, fmi2False, fmi2False)));
        };
        try_one("NULL name", null(), fmi2CoSimulation, guid.as_ptr(), uri.as_ptr(), &cb);
        try_one("empty name", c"".as_ptr(), fmi2CoSimulation, guid.as_ptr(), uri.as_ptr(), &cb);
        try_one("model exchange", name.as_ptr(), fmi2ModelExchange, guid.as_ptr(), uri.as_ptr(), &cb);
        try_one("type 7", name.as_ptr(), 7, guid.as_ptr(), uri.as_ptr(), &cb);
        try_one("NULL GUID", name.as_ptr(), fmi2CoSimulation, null(), uri.as_ptr(), &cb);
        try_one("other GUID", name.as_ptr(), fmi2CoSimulation, other_guid.as_ptr(), uri.as_ptr(), &cb);
        try_one("NULL URI", name.as_ptr(), fmi2CoSimulation, guid.as_ptr(), null(), &cb);
        try_one("NULL callbacks", name.as_ptr(), fmi2CoSimulation, guid.as_ptr(), uri.as_ptr(), null());
        for u in &uris {
            try_one(&format!("URI {u:?}"), name.as_ptr(), fmi2CoSimulation, guid.as_ptr(), u.as_ptr(), &cb);
        }
    }
    for (what, c) in &cases {
        assert!(c.is_null(), "{what}: instantiated");
    }
    // Every refusal with callbacks was logged, through "%s".
    let msgs = sink.lock().unwrap().clone();
    assert_eq!(msgs.len(), cases.len() - 1, "{msgs:#?}");
    assert!(msgs.iter().all(|m| m.format == "%s" && m.status >= fmi2Error));
    // A logger-less master (all callbacks NULL) is refused or served without a crash.
    let quiet = fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: null_mut(),
    };
    // SAFETY: valid strings and callbacks.
    let c = unsafe {
        fmi2Instantiate(name.as_ptr(), fmi2CoSimulation, guid.as_ptr(), uri.as_ptr(), &quiet, fmi2False, fmi2True)
    };
    assert!(!c.is_null());
    // SAFETY: a live instance; an illegal call logs to nobody.
    unsafe {
        assert_eq!(fmi2DoStep(c, 0.0, H, fmi2True), fmi2Error);
        assert_eq!(fmi2Reset(c), fmi2OK);
        fmi2FreeInstance(c);
    }
    // The instances that were refused left nothing behind that disturbs a good one.
    assert!(same_bits(&run(&Slave::started(&fx, None), &fx, 0, twin.len()).unwrap(), &twin));
    println!("instantiate refused: {} cases, 1 logger-less instance", cases.len());
}
