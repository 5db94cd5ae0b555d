//! The one driver of the FMI misuse matrices (call_sequence.rs for FMI 2.0
//! co-simulation, fmi3_calls.rs for FMI 3.0 co-simulation, me_exports.rs for FMI 2.0
//! Model Exchange): a table of calls, each with the states where its standard allows
//! it, tried in every state a master can reach, and judged alike: a legal call returns
//! OK without an "illegal call" message; an illegal one returns Error, logs why (each
//! test says what "why" is), and leaves the model's complete state (serialised
//! snapshot) byte for byte unchanged; then whatever the test checks after a refusal
//! (a recovery by reset, for the co-simulation matrices). Also the co-simulation state
//! machine driven to each state, for both versions, and the recovery.

// Raw FFI: the drivers call the exported fmi2*/fmi3* functions directly, as a C master
// does.
#![allow(unsafe_code)]
#![cfg(target_os = "linux")]

use std::collections::BTreeMap;
use std::ffi::c_void;
use std::fmt::Debug;
use std::ops::Deref;
use std::ptr::null_mut;

use crate::common::fmu::{BEFORE, H, Handle, Msg, Packed, Slave, Stepper, run, same_bits};
use crate::common::fmu3::Slave3;
use fxbody::fmi::state::FmiState;

/// OK and Error, the same numbers in both versions (`fmi3OK == fmi2OK`, ...).
const OK: i32 = fxbody::fmi::types::fmi2OK;
const ERROR: i32 = fxbody::fmi::types::fmi2Error;
const _: () = assert!(OK == fxbody::fmi::fmi3::types::fmi3OK);
const _: () = assert!(ERROR == fxbody::fmi::fmi3::types::fmi3Error);

/// One row of a matrix: the function's name, the states where it is legal, and the
/// call with valid arguments `A` (so that only the state makes it illegal).
pub type Call<At, A> = (&'static str, &'static [At], fn(*mut c_void, &A) -> i32);

/// How one matrix is run and judged.
pub struct Matrix<'a, At, A, S> {
    /// The states every call is tried in.
    pub states: &'a [At],
    /// The valid arguments.
    pub args: &'a A,
    /// A fresh instance in a state.
    pub reach: &'a dyn Fn(At) -> S,
    /// Try the legal cells too (they must return OK), or leave them out.
    pub legal_too: bool,
    /// Whether what a refused call logged (its new messages) says why.
    pub said: &'a dyn Fn(&str, At, &[Msg]) -> bool,
    /// More checks on an instance after a refusal was judged (its description given).
    pub after: &'a dyn Fn(&S, &str),
}

impl<'a, At: Copy + Debug + PartialEq, A, S: Deref<Target = Handle>> Matrix<'a, At, A, S> {
    /// A matrix over `states` that tries the legal cells too.
    pub fn new(
        states: &'a [At],
        args: &'a A,
        reach: &'a dyn Fn(At) -> S,
        said: &'a dyn Fn(&str, At, &[Msg]) -> bool,
        after: &'a dyn Fn(&S, &str),
    ) -> Self {
        Matrix {
            states,
            args,
            reach,
            legal_too: true,
            said,
            after,
        }
    }

    /// Every call of `calls` in every state: legal cells counted under "legal",
    /// refusals under `refused`.
    pub fn run(
        &self,
        calls: &[Call<At, A>],
        refused: &'static str,
        counts: &mut BTreeMap<&'static str, usize>,
    ) {
        for &(name, legal_in, call) in calls {
            for &at in self.states {
                let legal = legal_in.contains(&at);
                if legal && !self.legal_too {
                    continue;
                }
                let s = (self.reach)(at);
                let before = s.fingerprint();
                let n_msgs = s.messages().len();
                let st = call(s.c, self.args);
                let new: Vec<Msg> = s.messages()[n_msgs..].to_vec();
                let what = format!("{name} in {at:?}");
                if legal {
                    let illegal = format!("{name}: illegal call in state");
                    assert_eq!(st, OK, "{what}: {new:?}");
                    assert!(
                        !new.iter()
                            .any(|m| m.status == ERROR && m.text.contains(&illegal)),
                        "{what}: {new:?}"
                    );
                    *counts.entry("legal").or_insert(0) += 1;
                    continue;
                }
                assert_eq!(st, ERROR, "{what}");
                assert!((self.said)(name, at, &new), "{what}: logged {new:?}");
                assert!(s.fingerprint() == before, "{what} changed the model");
                (self.after)(&s, &what);
                *counts.entry(refused).or_insert(0) += 1;
            }
        }
    }
}

/// Every call of `calls` with a NULL instance: refused (Error), nothing else happens;
/// counted under `key`.
pub fn null_refused<At, A>(
    calls: &[Call<At, A>],
    args: &A,
    key: &'static str,
    counts: &mut BTreeMap<&'static str, usize>,
) {
    for &(name, _, call) in calls {
        assert_eq!(call(null_mut(), args), ERROR, "{name}(NULL)");
        *counts.entry(key).or_insert(0) += 1;
    }
}

/// The co-simulation states a master can reach, in both versions (FMI 3.0's Step Mode
/// is FMI 2.0's stepComplete).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CsAt {
    Instantiated,
    InitializationMode,
    StepComplete,
    Terminated,
    /// Error after a refused step in stepComplete / Step Mode.
    Error,
    /// Error after an illegal call in instantiated (no values exist yet).
    ErrorEarly,
}

/// Every co-simulation state.
pub const CS_ALL: [CsAt; 6] = [
    CsAt::Instantiated,
    CsAt::InitializationMode,
    CsAt::StepComplete,
    CsAt::Terminated,
    CsAt::Error,
    CsAt::ErrorEarly,
];

/// What driving a co-simulation instance through its state machine needs, in either
/// version.
pub trait CsMachine: Stepper + Deref<Target = Handle> {
    /// A fresh instance of `fx`, logging on.
    fn fresh(fx: &Packed, name: &str) -> Self;
    /// Start time 0, no stop time, into initialisation mode.
    fn enter_init(&self) -> i32;
    /// Out of initialisation mode.
    fn exit_init(&self) -> i32;
    /// Terminate.
    fn terminate(&self) -> i32;
    /// Reset.
    fn reset(&self) -> i32;
}

impl CsMachine for Slave {
    fn fresh(fx: &Packed, name: &str) -> Slave {
        Slave::new(fx, name)
    }
    fn enter_init(&self) -> i32 {
        let st = self.setup(0.0, None);
        if st != OK {
            return st;
        }
        // SAFETY: a live instance.
        unsafe { fxbody::fmi::exports::fmi2EnterInitializationMode(self.c) }
    }
    fn exit_init(&self) -> i32 {
        // SAFETY: a live instance.
        unsafe { fxbody::fmi::exports::fmi2ExitInitializationMode(self.c) }
    }
    fn terminate(&self) -> i32 {
        // SAFETY: a live instance.
        unsafe { fxbody::fmi::exports::fmi2Terminate(self.c) }
    }
    fn reset(&self) -> i32 {
        // SAFETY: a live instance.
        unsafe { fxbody::fmi::exports::fmi2Reset(self.c) }
    }
}

impl CsMachine for Slave3 {
    fn fresh(fx: &Packed, name: &str) -> Slave3 {
        Slave3::new(fx, name)
    }
    fn enter_init(&self) -> i32 {
        Slave3::enter_init(self, 0.0, None)
    }
    fn exit_init(&self) -> i32 {
        Slave3::exit_init(self)
    }
    fn terminate(&self) -> i32 {
        // SAFETY: a live instance.
        unsafe { fxbody::fmi::fmi3::exports::fmi3Terminate(self.c) }
    }
    fn reset(&self) -> i32 {
        // SAFETY: a live instance.
        unsafe { fxbody::fmi::fmi3::exports::fmi3Reset(self.c) }
    }
}

/// A fresh instance of `fx` in state `at` (stepComplete and later after BEFORE steps).
pub fn reach_cs<S: CsMachine>(fx: &Packed, at: CsAt, name: &str) -> S {
    let s = S::fresh(fx, name);
    if at == CsAt::Instantiated {
        return s;
    }
    if at == CsAt::ErrorEarly {
        assert_eq!(s.do_step(0.0, H), ERROR);
        return s;
    }
    assert_eq!(s.enter_init(), OK);
    if at == CsAt::InitializationMode {
        return s;
    }
    assert_eq!(s.exit_init(), OK);
    run(&s, fx, 0, BEFORE).unwrap();
    match at {
        CsAt::Terminated => assert_eq!(s.terminate(), OK),
        CsAt::Error => assert_eq!(s.do_step(1.0, H), ERROR),
        _ => {}
    }
    s
}

/// After a refusal the instance says so (Error) and recovers by Reset: a full run from
/// there equals the undisturbed `twin` bit for bit.
pub fn recovers_by_reset<S: CsMachine>(s: &S, fx: &Packed, twin: &[f64], what: &str) {
    assert_eq!(s.fmi_state(), FmiState::Error, "{what}");
    assert_eq!(s.reset(), OK, "{what}: {}", s.last_error());
    assert_eq!(s.enter_init(), OK, "{what}");
    assert_eq!(s.exit_init(), OK, "{what}");
    assert!(
        same_bits(&run(s, fx, 0, twin.len()).unwrap(), twin),
        "{what}"
    );
}
