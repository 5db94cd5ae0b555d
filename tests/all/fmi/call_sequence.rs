//! FMI misuse matrix (issue 9): every export called in every reachable state where the
//! call sequence forbids it (instantiated, initializationMode, stepComplete, terminated,
//! error), and every export with a NULL component. Bad arguments are in
//! bad_args.rs, states and lifetimes in states.rs.
//!
//! References, per case: the process survives; fmi2Error with "<function>: illegal call
//! in state ..." logged; the model's complete state (serialised snapshot) byte for byte
//! unchanged; the instance reports the Error state and, after fmi2Reset, a full run
//! equals an undisturbed twin's bit for bit. The state table is written here from the
//! FMI 2.0 standard and FMI.md, independently of src/fmi/state.rs.
#![cfg(all(
    target_os = "linux",
    any(target_arch = "x86_64", target_arch = "aarch64")
))]

use std::collections::BTreeMap;
use std::ptr::{null, null_mut};

use crate::common::fmu::{
    BEFORE, H, Packed, Slave, packed, print_counts, reference, run, same_bits,
};
use fxbody::fmi::exports::*;
use fxbody::fmi::fmu_state::*;
use fxbody::fmi::state::FmiState;
use fxbody::fmi::types::*;
use fxbody::fmi::values::*;

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
                    && (m
                        .text
                        .starts_with(&format!("{name}: illegal call in state"))
                        || (name == "fmi2GetDirectionalDerivative"
                            && m.text.contains("not provided")))
            });
            assert!(said, "{name} in {at:?}: logged {new:?}");
            assert!(
                s.fingerprint() == before,
                "{name} in {at:?} changed the model"
            );
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
        assert_eq!(
            std::ffi::CStr::from_ptr(fmi2GetVersion()).to_str(),
            Ok("2.0")
        );
    }
    *counts.entry("NULL component").or_insert(0) += 2;
    donor.free_state(a.state);
    print_counts("misuse matrix", &counts);
    assert_eq!(counts["illegal state"], 70);
}
