//! FMI 3.0 misuse matrix (issue 26.1), the counterpart of call_sequence.rs: every FMI 3.0
//! function called in every reachable state of a co-simulation instance (Instantiated,
//! InitializationMode, StepMode, Terminated, after an error in StepMode, after an error
//! in Instantiated), and with a NULL instance; FMI 2.0 functions on an FMI 3.0 instance
//! and the reverse.
//!
//! References, per case: the process survives; a call the FMI 3.0 standard's
//! co-simulation state machine forbids returns fmi3Error with "<function>: illegal call
//! in state ..." logged and the model's complete state (serialised snapshot) byte for
//! byte unchanged, and after fmi3Reset a full run equals an undisturbed twin's bit for
//! bit; a call it allows is not refused for the state (a provided one returns fmi3OK). The
//! table of allowed states is written here from the standard's state descriptions
//! (section 4.2.1 "State Machine for Co-Simulation", and the common states of 3.2),
//! independently of src/fmi/fmi3/state.rs. Functions of interfaces this FMU does not
//! provide (Model Exchange, clocks, event mode, configuration mode) are refused with a
//! logged reason in every state.

// Raw FFI: this test calls the exported fmi3* functions directly, as a C master does.
#![allow(unsafe_code)]
// One `// SAFETY (every closure below):` comment covers the table of calls.
#![allow(clippy::undocumented_unsafe_blocks)]
#![cfg(target_os = "linux")]

use std::collections::BTreeMap;
use std::ptr::{null, null_mut};

use super::matrix::{self, CsAt, Matrix};
use crate::common::fmu::{BEFORE, H, Msg, Packed, Slave, Stepper, print_counts, run};
use crate::common::fmu3::{Slave3, packed3};
use fxbody::fmi::fmi3::clocks::*;
use fxbody::fmi::fmi3::exports::*;
use fxbody::fmi::fmi3::fmu_state::*;
use fxbody::fmi::fmi3::model_exchange::*;
use fxbody::fmi::fmi3::non_numeric::*;
use fxbody::fmi::fmi3::other_types::*;
use fxbody::fmi::fmi3::types::*;
use fxbody::fmi::fmi3::values::*;

/// The states a master can reach with a co-simulation instance of this FMU (Step Mode
/// is [`CsAt::StepComplete`]).
type At = CsAt;
use CsAt::{Error, InitializationMode, Instantiated, StepComplete as StepMode, Terminated};
const ALL: [At; 6] = matrix::CS_ALL;

/// Valid arguments for every call, so that only the state makes a call illegal.
struct Args {
    fy: u32,
    y: u32,
    method: u32,
    method_value: i32,
    /// A live state of another instance of the same FMU (and its bytes).
    state: fmi3FMUState,
    bytes: Vec<u8>,
}

type Call = fn(fmi3Instance, &Args) -> fmi3Status;

/// Every FMI 3.0 function this FMU provides that takes an instance, with the states
/// where the standard allows it for a co-simulation instance without event mode:
/// - Instantiated: set variables with a start value (inputs, parameters), enter
///   initialisation, the FMU-state functions, logging, reset;
/// - InitializationMode: get and set, exit initialisation;
/// - StepMode: get, set inputs, fmi3DoStep, output derivatives, terminate;
/// - Terminated: get, output derivatives, the FMU-state functions, logging, reset;
/// - after an error: what Terminated allows (FMI 3.0 ends a failed instance in
///   Terminated), a read only where the state before the error had values.
///
/// The typed getters and setters of types without variables are called with no value
/// reference, which is legal where the type's functions are.
fn calls() -> Vec<matrix::Call<At, Args>> {
    const SET: &[At] = &[Instantiated, InitializationMode, StepMode];
    const GET: &[At] = &[InitializationMode, StepMode, Terminated, Error];
    const ANY: &[At] = &ALL;
    const OUT_DERIVS: &[At] = &[StepMode, Terminated, Error];
    // SAFETY (every closure below): `c` is a live instance and every pointer passed
    // points to valid, writable memory of the length given.
    vec![
        ("fmi3SetDebugLogging", ANY, |c, _| unsafe {
            fmi3SetDebugLogging(c, true, 0, null())
        }),
        (
            "fmi3EnterInitializationMode",
            &[Instantiated],
            |c, _| unsafe { fmi3EnterInitializationMode(c, false, 0.0, 0.0, false, 0.0) },
        ),
        (
            "fmi3ExitInitializationMode",
            &[InitializationMode],
            |c, _| unsafe { fmi3ExitInitializationMode(c) },
        ),
        ("fmi3Terminate", &[StepMode], |c, _| unsafe {
            fmi3Terminate(c)
        }),
        ("fmi3Reset", ANY, |c, _| unsafe { fmi3Reset(c) }),
        ("fmi3GetFloat64", GET, |c, a| unsafe {
            let mut v = [0.0];
            fmi3GetFloat64(c, &a.y, 1, v.as_mut_ptr(), 1)
        }),
        ("fmi3GetInt32", GET, |c, a| unsafe {
            let mut v = [0];
            fmi3GetInt32(c, &a.method, 1, v.as_mut_ptr(), 1)
        }),
        ("fmi3SetFloat64", SET, |c, a| unsafe {
            fmi3SetFloat64(c, &a.fy, 1, &0.25, 1)
        }),
        (
            "fmi3SetInt32",
            &[Instantiated, InitializationMode],
            |c, a| unsafe { fmi3SetInt32(c, &a.method, 1, &a.method_value, 1) },
        ),
        ("fmi3GetFloat32", GET, |c, _| unsafe {
            fmi3GetFloat32(c, null(), 0, null_mut(), 0)
        }),
        ("fmi3SetFloat32", SET, |c, _| unsafe {
            fmi3SetFloat32(c, null(), 0, null(), 0)
        }),
        ("fmi3GetInt8", GET, |c, _| unsafe {
            fmi3GetInt8(c, null(), 0, null_mut(), 0)
        }),
        ("fmi3SetUInt16", SET, |c, _| unsafe {
            fmi3SetUInt16(c, null(), 0, null(), 0)
        }),
        ("fmi3GetUInt64", GET, |c, _| unsafe {
            fmi3GetUInt64(c, null(), 0, null_mut(), 0)
        }),
        ("fmi3SetInt64", SET, |c, _| unsafe {
            fmi3SetInt64(c, null(), 0, null(), 0)
        }),
        ("fmi3GetBoolean", GET, |c, _| unsafe {
            fmi3GetBoolean(c, null(), 0, null_mut(), 0)
        }),
        ("fmi3SetBoolean", SET, |c, _| unsafe {
            fmi3SetBoolean(c, null(), 0, null(), 0)
        }),
        ("fmi3GetString", GET, |c, _| unsafe {
            fmi3GetString(c, null(), 0, null_mut(), 0)
        }),
        ("fmi3SetString", SET, |c, _| unsafe {
            fmi3SetString(c, null(), 0, null(), 0)
        }),
        ("fmi3GetBinary", GET, |c, _| unsafe {
            fmi3GetBinary(c, null(), 0, null_mut(), null_mut(), 0)
        }),
        ("fmi3SetBinary", SET, |c, _| unsafe {
            fmi3SetBinary(c, null(), 0, null(), null(), 0)
        }),
        ("fmi3GetFMUState", ANY, |c, _| unsafe {
            let mut s = null_mut();
            let st = fmi3GetFMUState(c, &mut s);
            if !s.is_null() {
                fmi3FreeFMUState(c, &mut s);
            }
            st
        }),
        ("fmi3SetFMUState", ANY, |c, a| unsafe {
            fmi3SetFMUState(c, a.state)
        }),
        ("fmi3FreeFMUState", ANY, |c, _| unsafe {
            let mut s: fmi3FMUState = null_mut();
            fmi3FreeFMUState(c, &mut s)
        }),
        ("fmi3SerializedFMUStateSize", ANY, |c, a| unsafe {
            let mut n = 0;
            fmi3SerializedFMUStateSize(c, a.state, &mut n)
        }),
        ("fmi3SerializeFMUState", ANY, |c, a| unsafe {
            let mut buf = vec![0u8; a.bytes.len()];
            fmi3SerializeFMUState(c, a.state, buf.as_mut_ptr(), buf.len())
        }),
        ("fmi3DeserializeFMUState", ANY, |c, a| unsafe {
            let mut s = null_mut();
            let st = fmi3DeserializeFMUState(c, a.bytes.as_ptr(), a.bytes.len(), &mut s);
            if !s.is_null() {
                fmi3FreeFMUState(c, &mut s);
            }
            st
        }),
        ("fmi3GetOutputDerivatives", OUT_DERIVS, |c, a| unsafe {
            let mut v = 0.0;
            fmi3GetOutputDerivatives(c, &a.y, 1, &1, &mut v, 1)
        }),
        ("fmi3DoStep", &[StepMode], |c, _| unsafe {
            let (mut e, mut t, mut r, mut l) = (false, false, false, 0.0);
            fmi3DoStep(
                c,
                BEFORE as f64 * H,
                H,
                true,
                &mut e,
                &mut t,
                &mut r,
                &mut l,
            )
        }),
    ]
}

/// The functions of what this FMU does not provide: event mode, configuration mode,
/// clocks and discrete states, Scheduled Execution, Model Exchange, partial derivatives
/// and dependency queries. Each is refused with a logged reason in every state.
fn not_provided() -> Vec<(&'static str, Call)> {
    // SAFETY (every closure below): as in `calls`.
    vec![
        ("fmi3EnterEventMode", |c, _| unsafe {
            fmi3EnterEventMode(c)
        }),
        ("fmi3EnterStepMode", |c, _| unsafe { fmi3EnterStepMode(c) }),
        ("fmi3EnterConfigurationMode", |c, _| unsafe {
            fmi3EnterConfigurationMode(c)
        }),
        ("fmi3ExitConfigurationMode", |c, _| unsafe {
            fmi3ExitConfigurationMode(c)
        }),
        ("fmi3GetClock", |c, a| unsafe {
            let mut v = false;
            fmi3GetClock(c, &a.y, 1, &mut v)
        }),
        ("fmi3SetClock", |c, a| unsafe {
            fmi3SetClock(c, &a.y, 1, &true)
        }),
        ("fmi3GetIntervalDecimal", |c, a| unsafe {
            let (mut v, mut q) = (0.0, 0);
            fmi3GetIntervalDecimal(c, &a.y, 1, &mut v, &mut q)
        }),
        ("fmi3SetShiftFraction", |c, a| unsafe {
            fmi3SetShiftFraction(c, &a.y, 1, &1, &2)
        }),
        ("fmi3EvaluateDiscreteStates", |c, _| unsafe {
            fmi3EvaluateDiscreteStates(c)
        }),
        ("fmi3UpdateDiscreteStates", |c, _| unsafe {
            let (mut a, mut b, mut d, mut e, mut f, mut t) =
                (false, false, false, false, false, 0.0);
            fmi3UpdateDiscreteStates(c, &mut a, &mut b, &mut d, &mut e, &mut f, &mut t)
        }),
        ("fmi3ActivateModelPartition", |c, a| unsafe {
            fmi3ActivateModelPartition(c, a.y, 0.0)
        }),
        ("fmi3EnterContinuousTimeMode", |c, _| unsafe {
            fmi3EnterContinuousTimeMode(c)
        }),
        ("fmi3CompletedIntegratorStep", |c, _| unsafe {
            let (mut e, mut t) = (false, false);
            fmi3CompletedIntegratorStep(c, true, &mut e, &mut t)
        }),
        ("fmi3SetTime", |c, _| unsafe { fmi3SetTime(c, 0.0) }),
        ("fmi3GetContinuousStates", |c, _| unsafe {
            let mut x = [0.0];
            fmi3GetContinuousStates(c, x.as_mut_ptr(), 1)
        }),
        ("fmi3GetNumberOfContinuousStates", |c, _| unsafe {
            let mut n = 7;
            fmi3GetNumberOfContinuousStates(c, &mut n)
        }),
        ("fmi3GetDirectionalDerivative", |c, a| unsafe {
            let mut out = 0.0;
            fmi3GetDirectionalDerivative(c, &a.y, 1, &a.fy, 1, &1.0, 1, &mut out, 1)
        }),
        ("fmi3GetAdjointDerivative", |c, a| unsafe {
            let mut out = 0.0;
            fmi3GetAdjointDerivative(c, &a.y, 1, &a.fy, 1, &1.0, 1, &mut out, 1)
        }),
        ("fmi3GetNumberOfVariableDependencies", |c, a| unsafe {
            let mut n = 7;
            fmi3GetNumberOfVariableDependencies(c, a.y, &mut n)
        }),
    ]
}

fn args(fx: &Packed, donor: &Slave3) -> Args {
    let state = donor.get_state();
    let bytes = donor.serialize(state);
    Args {
        fy: fx.vr("node_121.fy"),
        y: fx.vr("node_121.y"),
        method: fx.vr("method"),
        method_value: fx.p.table.default_method as i32,
        state,
        bytes,
    }
}

/// The undisturbed twin, run through FMI 3.0.
fn twin(fx: &Packed) -> Vec<f64> {
    let r = run(&Slave3::started(fx, None), fx, 0, 2 * BEFORE).unwrap();
    assert!(r.iter().any(|v| v.abs() > 1e-9), "a real response: {r:?}");
    r
}

#[test]
fn every_fmi3_call_in_every_state() {
    let fx = packed3("matrix3");
    let twin = twin(&fx);
    let donor = Slave3::started(&fx, None);
    run(&donor, &fx, 0, BEFORE).unwrap();
    let a = args(&fx, &donor);
    let mut counts = BTreeMap::new();
    let reach = |at: At| matrix::reach_cs::<Slave3>(&fx, at, "matrix3");
    let after = |s: &Slave3, what: &str| matrix::recovers_by_reset(s, &fx, &twin, what);
    let said = |name: &str, at: At, new: &[Msg]| {
        let illegal = format!("{name}: illegal call in state");
        new.iter()
            .any(|m| m.status == fmi3Error && m.text.contains(&illegal))
            // `method` is a fixed parameter: in Step Mode the setter is legal but the
            // variable refuses, saying so.
            || (name == "fmi3SetInt32"
                && at == StepMode
                && new.iter().any(|m| m.text.contains("is a fixed parameter")))
    };
    Matrix::new(&ALL, &a, &reach, &said, &after).run(&calls(), "illegal state", &mut counts);
    let not_provided: Vec<matrix::Call<At, Args>> = not_provided()
        .into_iter()
        .map(|(name, call)| (name, &[] as &[At], call))
        .collect();
    let said_why = |name: &str, _: At, new: &[Msg]| {
        new.iter().any(|m| {
            m.status == fmi3Error
                && m.text.contains(&format!("{name}: "))
                && m.text.len() > name.len() + 30
        })
    };
    Matrix::new(&ALL, &a, &reach, &said_why, &after).run(
        &not_provided,
        "not provided",
        &mut counts,
    );
    // A NULL instance: refused by every function, nothing else happens.
    matrix::null_refused(&calls(), &a, "NULL instance", &mut counts);
    matrix::null_refused(&not_provided, &a, "NULL instance", &mut counts);
    // SAFETY: NULL is explicitly allowed; a static string is returned.
    unsafe {
        fmi3FreeInstance(null_mut());
        assert_eq!(
            std::ffi::CStr::from_ptr(fmi3GetVersion()).to_str(),
            Ok("3.0")
        );
    }
    donor.free_state(a.state);
    print_counts("fmi3 misuse matrix", &counts);
    // Written out from the table in `calls`: 29 functions in 6 states.
    assert_eq!(counts["legal"] + counts["illegal state"], 29 * 6);
    assert_eq!(counts["illegal state"], 64);
    assert_eq!(counts["not provided"], 19 * 6);
}

/// One library, two versions: an FMI 2.0 function on an FMI 3.0 instance (and the
/// reverse) is refused with a reason naming the versions, and changes nothing.
#[test]
fn functions_of_the_other_version_are_refused() {
    use fxbody::fmi::exports as e2;
    use fxbody::fmi::types::fmi2Error;
    let fx3 = packed3("crossver3");
    let s3 = Slave3::started(&fx3, None);
    run(&s3, &fx3, 0, BEFORE).unwrap();
    let before = s3.fingerprint();
    // SAFETY: a live instance (of the other version: refused before it is read).
    assert_eq!(
        unsafe { e2::fmi2DoStep(s3.c, BEFORE as f64 * H, H, 1) },
        fmi2Error
    );
    let e = s3.last_error();
    assert!(
        e.contains("fmi2DoStep") && e.contains("FMI 2.0") && e.contains("FMI 3.0"),
        "{e}"
    );
    assert!(s3.fingerprint() == before);
    let fx2 = crate::common::fmu::packed("crossver2");
    let s2 = Slave::started(&fx2, None);
    run(&s2, &fx2, 0, BEFORE).unwrap();
    let before = s2.fingerprint();
    let (mut a, mut b, mut c, mut l) = (false, false, false, 0.0);
    // SAFETY: a live instance (of the other version: refused before it is read).
    let st = unsafe {
        fmi3DoStep(
            s2.c,
            BEFORE as f64 * H,
            H,
            true,
            &mut a,
            &mut b,
            &mut c,
            &mut l,
        )
    };
    assert_eq!(st, fmi3Error);
    let e = s2.last_error();
    assert!(e.contains("fmi3DoStep") && e.contains("FMI 3.0"), "{e}");
    assert!(s2.fingerprint() == before);
}
