//! The FMI 2.0 C types the host uses, declared here from the standard's headers
//! (fmi2TypesPlatform.h, fmi2FunctionTypes.h) rather than taken from the product: the
//! host reads the FMU as any importer would, so a wrong declaration on the FMU side
//! shows up as a failing call instead of being shared.

#![allow(non_camel_case_types, non_upper_case_globals, non_snake_case)]

use std::ffi::{c_char, c_int, c_uint, c_void};

/// An FMU instance handle.
pub type fmi2Component = *mut c_void;
/// The importer's environment pointer, passed back to the logger.
pub type fmi2ComponentEnvironment = *mut c_void;
/// A saved FMU state handle.
pub type fmi2FMUstate = *mut c_void;
/// A value reference.
pub type fmi2ValueReference = c_uint;
/// A real.
pub type fmi2Real = f64;
/// An integer.
pub type fmi2Integer = c_int;
/// A boolean (0 or 1).
pub type fmi2Boolean = c_int;
/// A NUL-terminated string.
pub type fmi2String = *const c_char;
/// A byte of a serialised state.
pub type fmi2Byte = c_char;
/// The status every function returns.
pub type fmi2Status = c_int;
/// fmi2OK.
pub const fmi2OK: fmi2Status = 0;
/// The interface type asked for at instantiation.
pub type fmi2Type = c_int;
/// fmi2CoSimulation.
pub const fmi2CoSimulation: fmi2Type = 1;
/// fmi2True.
pub const fmi2True: fmi2Boolean = 1;
/// fmi2False.
pub const fmi2False: fmi2Boolean = 0;

/// fmi2CallbackLogger: `printf`-style, C-variadic.
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

/// fmi2CallbackFunctions, with the three callbacks the host does not provide as plain
/// nullable pointers.
#[repr(C)]
pub struct fmi2CallbackFunctions {
    /// The logger.
    pub logger: fmi2CallbackLogger,
    /// allocateMemory (NULL: the FMU uses its own allocator).
    pub allocateMemory: *const c_void,
    /// freeMemory (NULL).
    pub freeMemory: *const c_void,
    /// stepFinished (NULL: steps are synchronous).
    pub stepFinished: *const c_void,
    /// The environment passed back to the logger.
    pub componentEnvironment: fmi2ComponentEnvironment,
}
