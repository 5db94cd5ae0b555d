//! One FMU instance behind an `fmi2Component`: the copied callbacks and name, the
//! logging switches, the FMI state, and the model. Also the entry wrapper every export
//! goes through: null check, state mask, panic barrier, error logging.

use std::ffi::{CStr, CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

use super::FmiError;
use super::state::FmiState;
use super::types::*;
use crate::fmu::simulation::Simulation;

/// Log categories, in the order of `crate::fmu::xml::LOG_CATEGORIES` (a test checks).
pub const CATEGORIES: [&CStr; 4] = [
    c"logStatusError",
    c"logStatusWarning",
    c"logCalls",
    c"logSolver",
];
/// Index of logStatusError.
pub const LOG_ERROR: usize = 0;
/// Index of logStatusWarning.
pub const LOG_WARNING: usize = 1;
/// Index of logCalls.
pub const LOG_CALLS: usize = 2;
/// Index of logSolver.
pub const LOG_SOLVER: usize = 3;

/// Where log messages go: the master's logger and environment, and the instance name,
/// all copied at instantiation.
pub struct Log {
    logger: fmi2CallbackLogger,
    env: fmi2ComponentEnvironment,
    name: CString,
    /// Debug categories switched on (errors and warnings are always passed on).
    pub enabled: [bool; CATEGORIES.len()],
}

impl Log {
    /// A log over the master's callbacks; `debug` switches every category on.
    pub fn new(functions: &fmi2CallbackFunctions, name: &str, debug: bool) -> Log {
        Log {
            logger: functions.logger,
            env: functions.componentEnvironment,
            name: c_text(name),
            enabled: [debug; CATEGORIES.len()],
        }
    }

    /// Whether category `cat` would be passed on.
    pub fn on(&self, cat: usize) -> bool {
        cat <= LOG_WARNING || self.enabled[cat]
    }

    /// Send `text` to the logger (if any and if the category is on).
    pub fn send(&self, status: fmi2Status, cat: usize, text: &str) {
        if !self.on(cat) {
            return;
        }
        let Some(logger) = self.logger else { return };
        let msg = c_text(text);
        // SAFETY: `logger` is the master's function pointer, valid for the instance's
        // life (FMI 2.0: callbacks stay valid until fmi2FreeInstance). All pointers
        // passed are NUL-terminated strings that outlive the call. The format is "%s"
        // with exactly one char* argument, so printf-style handling in the logger reads
        // exactly what we pass whatever the text holds.
        unsafe {
            logger(
                self.env,
                self.name.as_ptr(),
                status,
                CATEGORIES[cat].as_ptr(),
                c"%s".as_ptr(),
                msg.as_ptr(),
            );
        }
    }
}

/// A C string from text, with any NUL byte replaced (a message is never lost).
pub fn c_text(s: &str) -> CString {
    CString::new(s.replace('\0', "\u{fffd}")).unwrap_or_default()
}

/// Text of a C string argument; `None` for NULL.
///
/// # Safety
/// `p` is NULL or a NUL-terminated string valid for the call.
pub unsafe fn text_arg(p: *const c_char) -> Option<String> {
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null and NUL-terminated by the caller's contract.
    Some(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
}

/// An FMU instance.
pub struct Instance {
    /// The log.
    pub log: Log,
    /// FMI state.
    pub state: FmiState,
    /// The state the instance was in when it last entered the Error state. In Error the
    /// model holds that state's values (a failed call changes nothing), so a read or a
    /// save in Error answers as that state would, and a state saved in Error restores to
    /// it (never to Error).
    pub before_error: FmiState,
    /// The simulation behind the handle: parameters, inputs, the solver, outputs.
    pub simulation: Simulation,
}

impl Instance {
    /// The state the model's values belong to: the current state, or in Error the
    /// state before the error.
    pub fn phase(&self) -> FmiState {
        if self.state == FmiState::Error {
            self.before_error
        } else {
            self.state
        }
    }

    /// Enter the Error state, remembering the state left.
    pub fn fail(&mut self) {
        if !matches!(self.state, FmiState::Error | FmiState::Fatal) {
            self.before_error = self.state;
            self.state = FmiState::Error;
        }
    }
}

/// What an export's body returns: a status to pass on (OK, Warning, Discard), or why
/// the call was refused (logged, the instance goes to the Error state, fmi2Error
/// returned).
pub type Outcome = Result<fmi2Status, FmiError>;

/// Run an export's body on the instance behind `c`: refuse NULL, check the call is legal
/// in the current state (`mask`; in Error, also in the state before the error, whose
/// values the model holds), catch panics (fmi2Fatal), log errors. Inlined into every
/// export: the success path is a null test, a mask test, one flag test for `logCalls`
/// and the panic barrier; refusing, logging and the panic's report are out of line.
#[inline(always)]
pub fn enter(
    c: fmi2Component,
    func: &str,
    mask: u16,
    body: impl FnOnce(&mut Instance) -> Outcome,
) -> fmi2Status {
    if c.is_null() {
        return fmi2Error;
    }
    let ptr = c.cast::<Instance>();
    let result = {
        // SAFETY: a non-null fmi2Component is a pointer this library returned from
        // fmi2Instantiate (Box::into_raw) and that fmi2FreeInstance has not yet freed;
        // FMI forbids concurrent calls on one instance, so this is the only reference.
        let inst = unsafe { &mut *ptr };
        // Outside Error the phase is the state itself: one test.
        if mask & inst.state.bit() == 0
            || (inst.state == FmiState::Error && mask & inst.before_error.bit() == 0)
        {
            return illegal(inst, func, mask);
        }
        if inst.log.enabled[LOG_CALLS] {
            log_call(inst, func);
        }
        // A refusal is logged inside, so that what crosses the unwind boundary is the
        // status alone (a small value, not the error moved about on every call).
        catch_unwind(AssertUnwindSafe(|| match body(inst) {
            Ok(status) => status,
            Err(error) => failed(inst, func, error),
        }))
    };
    match result {
        Ok(status) => status,
        Err(panic) => {
            // SAFETY: as above; the borrow inside the closure has ended.
            panicked(unsafe { &mut *ptr }, func, panic)
        }
    }
}

/// The `logCalls` line of a call, out of the call's way.
#[cold]
#[inline(never)]
fn log_call(inst: &Instance, func: &str) {
    inst.log.send(fmi2OK, LOG_CALLS, func);
}

/// A call not allowed in the instance's state: logged; outside Error the instance
/// enters Error.
#[cold]
#[inline(never)]
fn illegal(inst: &mut Instance, func: &str, mask: u16) -> fmi2Status {
    if mask & inst.state.bit() == 0 {
        let msg = format!("{func}: illegal call in state {:?}", inst.state);
        inst.log.send(fmi2Error, LOG_ERROR, &msg);
        inst.fail();
    } else {
        let msg = format!(
            "{func}: illegal call in state Error entered from state {:?}, where the \
             call is not allowed (the model holds that state's values)",
            inst.before_error
        );
        inst.log.send(fmi2Error, LOG_ERROR, &msg);
    }
    fmi2Error
}

/// A refused call: the reason logged, the instance in Error.
#[cold]
#[inline(never)]
fn failed(inst: &mut Instance, func: &str, error: FmiError) -> fmi2Status {
    inst.log
        .send(fmi2Error, LOG_ERROR, &format!("{func}: {error}"));
    inst.fail();
    fmi2Error
}

/// A caught panic: the instance is Fatal for good.
#[cold]
#[inline(never)]
fn panicked(inst: &mut Instance, func: &str, panic: Box<dyn std::any::Any + Send>) -> fmi2Status {
    let what = panic_text(&*panic);
    inst.state = FmiState::Fatal;
    // Logging itself must not unwind out of the library.
    let _ = catch_unwind(AssertUnwindSafe(|| {
        inst.log.send(
            fmi2Fatal,
            LOG_ERROR,
            &format!("{func}: internal error (panic): {what}"),
        )
    }));
    fmi2Fatal
}

/// The message of a caught panic.
pub fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".to_string()
    }
}

/// A slice from a C array; empty for `n == 0` whatever the pointer.
///
/// # Safety
/// For `n > 0`, `p` is NULL (reported as an error) or points to `n` valid elements.
pub unsafe fn slice<'a, T>(p: *const T, n: usize, what: &'static str) -> Result<&'a [T], FmiError> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(FmiError::NullArray { what, n });
    }
    // SAFETY: non-null and `n` valid elements by the caller's contract.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// A mutable slice from a C array; empty for `n == 0`.
///
/// # Safety
/// For `n > 0`, `p` is NULL (reported) or points to `n` writable elements not aliased
/// by any other argument.
pub unsafe fn slice_mut<'a, T>(
    p: *mut T,
    n: usize,
    what: &'static str,
) -> Result<&'a mut [T], FmiError> {
    if n == 0 {
        return Ok(&mut []);
    }
    if p.is_null() {
        return Err(FmiError::NullArray { what, n });
    }
    // SAFETY: non-null and `n` writable, unaliased elements by the caller's contract.
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn instance() -> Box<Instance> {
        let scene = crate::scene::io::cantilever_tip_scene();
        let callbacks = fmi2CallbackFunctions {
            logger: None,
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: std::ptr::null_mut(),
        };
        Box::new(Instance {
            log: Log::new(&callbacks, "t", false),
            state: FmiState::Instantiated,
            before_error: FmiState::Instantiated,
            simulation: Simulation::new(scene, "{g}".into()),
        })
    }

    #[test]
    fn a_panic_becomes_fatal_and_the_instance_stays_fatal() {
        let raw = Box::into_raw(instance());
        let c: fmi2Component = raw.cast();
        let all = u16::MAX;
        assert_eq!(enter(c, "fmi2Test", all, |_| Ok(fmi2OK)), fmi2OK);
        assert_eq!(
            enter(c, "fmi2Test", all & !FmiState::Fatal.bit(), |_| panic!(
                "boom"
            )),
            fmi2Fatal
        );
        // SAFETY: `raw` is the live box created above.
        assert_eq!(unsafe { (*raw).state }, FmiState::Fatal);
        // Fatal: every masked call is illegal now, and it stays Fatal.
        let mut ran = false;
        assert_eq!(
            enter(c, "fmi2Test", all & !FmiState::Fatal.bit(), |_| {
                ran = true;
                Ok(fmi2OK)
            }),
            fmi2Error
        );
        assert!(!ran);
        // SAFETY: as above; freed once.
        let back = unsafe { Box::from_raw(raw) };
        assert_eq!(back.state, FmiState::Fatal);
        assert_eq!(
            enter(std::ptr::null_mut(), "fmi2Test", all, |_| Ok(fmi2OK)),
            fmi2Error
        );
    }

    #[test]
    fn an_error_or_an_illegal_call_moves_to_the_error_state() {
        let raw = Box::into_raw(instance());
        let c: fmi2Component = raw.cast();
        assert_eq!(
            enter(c, "fmi2Test", FmiState::Instantiated.bit(), |_| Err(
                FmiError::NoDirectionalDerivative
            )),
            fmi2Error
        );
        // SAFETY: `raw` is the live box created above.
        assert_eq!(unsafe { (*raw).state }, FmiState::Error);
        // SAFETY: as above.
        unsafe { (*raw).state = FmiState::Instantiated };
        assert_eq!(
            enter(c, "fmi2Test", FmiState::StepComplete.bit(), |_| Ok(fmi2OK)),
            fmi2Error
        );
        // SAFETY: as above; freed once.
        let back = unsafe { Box::from_raw(raw) };
        assert_eq!(back.state, FmiState::Error);
    }

    #[test]
    fn categories_match_the_description() {
        let names: Vec<&str> = CATEGORIES.iter().map(|c| c.to_str().unwrap()).collect();
        let declared: Vec<&str> = crate::fmu::xml::LOG_CATEGORIES
            .iter()
            .map(|c| c.0)
            .collect();
        assert_eq!(names, declared);
    }
}
