//! The FMI 2.0 C types, as plain aliases and integer constants. Enumerations that arrive
//! from C (status kinds, FMU type) are `int` here, never Rust enums: a value outside the
//! enumeration must be reportable, not undefined behaviour.

#![allow(non_camel_case_types, non_upper_case_globals, non_snake_case)]

use std::ffi::{c_char, c_int, c_uint, c_void};

/// An FMU instance handle (opaque).
pub type fmi2Component = *mut c_void;
/// The master's environment pointer, passed back to the callbacks.
pub type fmi2ComponentEnvironment = *mut c_void;
/// A saved FMU state handle (opaque).
pub type fmi2FMUstate = *mut c_void;
/// A value reference.
pub type fmi2ValueReference = c_uint;
/// A real.
pub type fmi2Real = f64;
/// An integer.
pub type fmi2Integer = c_int;
/// A boolean (0 or 1).
pub type fmi2Boolean = c_int;
/// A character.
pub type fmi2Char = c_char;
/// A NUL-terminated string.
pub type fmi2String = *const fmi2Char;
/// A byte of a serialised state.
pub type fmi2Byte = c_char;

/// Status returned by every function.
pub type fmi2Status = c_int;
/// All well.
pub const fmi2OK: fmi2Status = 0;
/// Something to note, results usable.
pub const fmi2Warning: fmi2Status = 1;
/// Results of this call not usable, the instance continues.
pub const fmi2Discard: fmi2Status = 2;
/// The instance cannot continue (Reset, SetFMUstate or FreeInstance only).
pub const fmi2Error: fmi2Status = 3;
/// The instance is unusable (FreeInstance only).
pub const fmi2Fatal: fmi2Status = 4;
/// An asynchronous step is running (never returned here: steps are synchronous).
pub const fmi2Pending: fmi2Status = 5;

/// Interface type asked for at instantiation.
pub type fmi2Type = c_int;
/// Model exchange (not provided by this library).
pub const fmi2ModelExchange: fmi2Type = 0;
/// Co-simulation.
pub const fmi2CoSimulation: fmi2Type = 1;

/// What fmi2Get*Status asks about.
pub type fmi2StatusKind = c_int;
/// Status of an asynchronous doStep.
pub const fmi2DoStepStatus: fmi2StatusKind = 0;
/// Text about a pending step.
pub const fmi2PendingStatus: fmi2StatusKind = 1;
/// Last time a step completed.
pub const fmi2LastSuccessfulTime: fmi2StatusKind = 2;
/// Whether the slave wants to end the simulation.
pub const fmi2Terminated: fmi2StatusKind = 3;

/// fmi2True.
pub const fmi2True: fmi2Boolean = 1;
/// fmi2False.
pub const fmi2False: fmi2Boolean = 0;

/// The logger: `logger(env, instanceName, status, category, message, ...)`, printf-style.
/// The library always passes `"%s"` and the text as the one extra argument, so text
/// holding `%` is never interpreted.
pub type fmi2CallbackLogger = Option<
    unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        fmi2Status,
        fmi2String,
        fmi2String,
        ...
    ),
>;
/// Deprecated memory allocator (calloc-like); never used (canNotUseMemoryManagementFunctions).
pub type fmi2CallbackAllocateMemory = Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>;
/// Deprecated memory release; never used.
pub type fmi2CallbackFreeMemory = Option<unsafe extern "C" fn(*mut c_void)>;
/// Asynchronous step completion; never called (steps are synchronous).
pub type fmi2StepFinished = Option<unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2Status)>;

/// The callbacks a master passes to fmi2Instantiate; every field may be NULL.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct fmi2CallbackFunctions {
    /// Logger.
    pub logger: fmi2CallbackLogger,
    /// Memory allocation (unused).
    pub allocateMemory: fmi2CallbackAllocateMemory,
    /// Memory release (unused).
    pub freeMemory: fmi2CallbackFreeMemory,
    /// Step finished (unused).
    pub stepFinished: fmi2StepFinished,
    /// The master's environment pointer.
    pub componentEnvironment: fmi2ComponentEnvironment,
}
