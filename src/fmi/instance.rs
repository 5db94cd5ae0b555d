//! One FMU instance behind an `fmi2Component` or an `fmi3Instance`: the copied callbacks
//! and name, the logging switches, the FMI version and state, and the model. Also the
//! entry wrapper every export of either version goes through: null check, version and
//! state mask, panic barrier, error logging.

use std::ffi::{CStr, CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

use super::FmiError;
use super::fmi3::types::{fmi3InstanceEnvironment, fmi3LogMessageCallback};
use super::state::FmiState;
use super::types::*;
use super::version::{FmiVersion, Interface, fmi3_text, state_name};
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

/// The master's logger, as each version declares it.
#[derive(Clone, Copy)]
enum Logger {
    /// FMI 2.0: C-variadic, printf-style, with the instance name.
    Fmi2(fmi2CallbackLogger),
    /// FMI 3.0: four fixed arguments, the message as text.
    Fmi3(fmi3LogMessageCallback),
}

/// Where log messages go: the master's logger and environment, and the instance name,
/// all copied at instantiation.
pub struct Log {
    logger: Logger,
    env: fmi2ComponentEnvironment,
    name: CString,
    /// Errors and warnings are passed on whatever `enabled` says (FMI 2.0); FMI 3.0
    /// calls no logger at all unless loggingOn or fmi3SetDebugLogging asks for it.
    always_errors: bool,
    /// Categories switched on (for FMI 2.0, the debug categories).
    pub enabled: [bool; CATEGORIES.len()],
}

impl Log {
    /// A log over an FMI 2.0 master's callbacks; `debug` switches every category on.
    pub fn new(functions: &fmi2CallbackFunctions, name: &str, debug: bool) -> Log {
        Log {
            logger: Logger::Fmi2(functions.logger),
            env: functions.componentEnvironment,
            name: c_text(name),
            always_errors: true,
            enabled: [debug; CATEGORIES.len()],
        }
    }

    /// A log over an FMI 3.0 master's logMessage; `logging_on` switches every category
    /// on, and without it nothing is logged until fmi3SetDebugLogging switches
    /// categories on (FMI 3.0: "If loggingOn == fmi3False, then any logging is disabled
    /// and the logMessage callback function is not called by the FMU").
    pub fn new3(
        env: fmi3InstanceEnvironment,
        logger: fmi3LogMessageCallback,
        name: &str,
        logging_on: bool,
    ) -> Log {
        Log {
            logger: Logger::Fmi3(logger),
            env,
            name: c_text(name),
            always_errors: false,
            enabled: [logging_on; CATEGORIES.len()],
        }
    }

    /// Whether category `cat` would be passed on.
    pub fn on(&self, cat: usize) -> bool {
        (self.always_errors && cat <= LOG_WARNING) || self.enabled[cat]
    }

    /// Send `text` to the logger (if any and if the category is on). An FMI 3.0 logger
    /// reads the shared layers' FMI 2.0 function names as their FMI 3.0 names.
    pub fn send(&self, status: fmi2Status, cat: usize, text: &str) {
        self.emit(status, cat, text, true);
    }

    /// [`Log::send`] with the function names left as written (a message about a call of
    /// the other version's function).
    pub fn send_verbatim(&self, status: fmi2Status, cat: usize, text: &str) {
        self.emit(status, cat, text, false);
    }

    fn emit(&self, status: fmi2Status, cat: usize, text: &str, rename: bool) {
        if !self.on(cat) {
            return;
        }
        match self.logger {
            Logger::Fmi2(Some(logger)) => {
                let msg = c_text(text);
                // SAFETY: `logger` is the master's function pointer, valid for the
                // instance's life (FMI 2.0: callbacks stay valid until
                // fmi2FreeInstance). All pointers passed are NUL-terminated strings that
                // outlive the call. The format is "%s" with exactly one char* argument,
                // so printf-style handling in the logger reads exactly what we pass
                // whatever the text holds.
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
            Logger::Fmi3(Some(logger)) => {
                // FMI 3.0's logger has no instance name: the message starts with it.
                let name = self.name.to_string_lossy();
                let msg = c_text(&fmi3_text(&format!("{name}: {text}"), rename));
                // SAFETY: `logger` is the master's logMessage, valid for the instance's
                // life (FMI 3.0: callbacks stay valid until fmi3FreeInstance), called with
                // its four declared arguments (not variadic); the strings are
                // NUL-terminated and outlive the call.
                unsafe { logger(self.env, status, CATEGORIES[cat].as_ptr(), msg.as_ptr()) }
            }
            Logger::Fmi2(None) | Logger::Fmi3(None) => {}
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
    /// The FMI version whose instantiation function made the instance: only that
    /// version's functions may be called on it ([`enter_as`]).
    pub version: FmiVersion,
    /// The interface it serves.
    pub interface: Interface,
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

/// [`enter_as`] for an FMI 2.0 export.
#[inline(always)]
pub fn enter(
    c: fmi2Component,
    func: &str,
    mask: u16,
    body: impl FnOnce(&mut Instance) -> Outcome,
) -> fmi2Status {
    enter_as(c, FmiVersion::Fmi2, func, mask, body)
}

/// Run an export's body on the instance behind `c`: refuse NULL, refuse an instance
/// another FMI version made, check the call is legal in the current state (`mask`; in
/// Error, also in the state before the error, whose values the model holds), catch
/// panics (Fatal), log errors. The status returned is both versions' (the same
/// numbers, [`super::version`]). Inlined into every export: the success path is a null
/// test, a version and a mask test, one flag test for `logCalls` and the panic barrier;
/// refusing, logging and the panic's report are out of line.
#[inline(always)]
pub fn enter_as(
    c: fmi2Component,
    version: FmiVersion,
    func: &str,
    mask: u16,
    body: impl FnOnce(&mut Instance) -> Outcome,
) -> fmi2Status {
    if c.is_null() {
        return fmi2Error;
    }
    let ptr = c.cast::<Instance>();
    let result = {
        // SAFETY: a non-null fmi2Component or fmi3Instance is a pointer this library
        // returned from an instantiation function (Box::into_raw) and that no
        // FreeInstance has freed yet; FMI forbids concurrent calls on one instance, so
        // this is the only reference.
        let inst = unsafe { &mut *ptr };
        // Outside Error the phase is the state itself: one test.
        if inst.version != version
            || mask & inst.state.bit() == 0
            || (inst.state == FmiState::Error && mask & inst.before_error.bit() == 0)
        {
            return illegal(inst, version, func, mask);
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

/// A call not allowed on the instance (another version made it) or in its state:
/// logged; outside Error the instance enters Error.
#[cold]
#[inline(never)]
fn illegal(inst: &mut Instance, version: FmiVersion, func: &str, mask: u16) -> fmi2Status {
    let name = |s| state_name(inst.version, s);
    if inst.version != version {
        let msg = format!(
            "{func}: an FMI {} function called on an instance made by FMI {}'s \
             instantiation: use the fmi{}* functions on it",
            version.number(),
            inst.version.number(),
            &inst.version.number()[..1]
        );
        inst.log.send_verbatim(fmi2Error, LOG_ERROR, &msg);
        inst.fail();
    } else if mask & inst.state.bit() == 0 {
        let msg = format!("{func}: illegal call in state {}", name(inst.state));
        inst.log.send(fmi2Error, LOG_ERROR, &msg);
        inst.fail();
    } else {
        let msg = format!(
            "{func}: illegal call in state {} entered from state {}, where the call is \
             not allowed (the model holds that state's values)",
            name(FmiState::Error),
            name(inst.before_error)
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
            version: FmiVersion::Fmi2,
            interface: Interface::CoSimulation,
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
