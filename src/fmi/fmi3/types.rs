//! The FMI 3.0 C types (fmi3PlatformTypes.h, fmi3FunctionTypes.h), as plain aliases and
//! integer constants. As for FMI 2.0 ([`crate::fmi::types`]), enumerations that arrive
//! from C are `int` here, never Rust enums: a value outside the enumeration must be
//! reportable, not undefined behaviour. `fmi3Boolean` is C's `bool`, which a C caller
//! can only pass as 0 or 1, so Rust's `bool` (same size and ABI) receives it soundly.

#![allow(non_camel_case_types, non_upper_case_globals, non_snake_case)]

use std::ffi::{c_char, c_int, c_void};

/// An FMU instance handle (opaque; the same object as an `fmi2Component`, made by an
/// FMI 3.0 instantiation function).
pub type fmi3Instance = *mut c_void;
/// The master's environment pointer, passed back to the callbacks.
pub type fmi3InstanceEnvironment = *mut c_void;
/// A saved FMU state handle (opaque).
pub type fmi3FMUState = *mut c_void;
/// A value reference.
pub type fmi3ValueReference = u32;
/// A single-precision float (no variable of this FMU has the type).
pub type fmi3Float32 = f32;
/// A double-precision float: the type of the FMU's Real variables.
pub type fmi3Float64 = f64;
/// An 8-bit signed integer.
pub type fmi3Int8 = i8;
/// An 8-bit unsigned integer.
pub type fmi3UInt8 = u8;
/// A 16-bit signed integer.
pub type fmi3Int16 = i16;
/// A 16-bit unsigned integer.
pub type fmi3UInt16 = u16;
/// A 32-bit signed integer: the type of the `method` parameter.
pub type fmi3Int32 = i32;
/// A 32-bit unsigned integer.
pub type fmi3UInt32 = u32;
/// A 64-bit signed integer.
pub type fmi3Int64 = i64;
/// A 64-bit unsigned integer.
pub type fmi3UInt64 = u64;
/// A boolean (C `bool`).
pub type fmi3Boolean = bool;
/// A character.
pub type fmi3Char = c_char;
/// A NUL-terminated UTF-8 string.
pub type fmi3String = *const fmi3Char;
/// A byte (serialised states, binary values).
pub type fmi3Byte = u8;
/// Binary data, its length given beside it.
pub type fmi3Binary = *const fmi3Byte;
/// A clock's activation (C `bool`).
pub type fmi3Clock = bool;

/// Status returned by every function: the values of FMI 2.0's first five
/// (`fmi3OK == fmi2OK`, ..., `fmi3Fatal == fmi2Fatal`, checked where the two meet,
/// [`crate::fmi::version`]); FMI 3.0 has no `Pending`.
pub type fmi3Status = c_int;
/// All well.
pub const fmi3OK: fmi3Status = 0;
/// Something to note, results usable.
pub const fmi3Warning: fmi3Status = 1;
/// Results of this call not usable, the instance continues.
pub const fmi3Discard: fmi3Status = 2;
/// The call failed: the instance is in state Terminated (FMI 3.0), where reads, the FMU
/// state functions, Reset and FreeInstance remain.
pub const fmi3Error: fmi3Status = 3;
/// The instance is unusable (FreeInstance only).
pub const fmi3Fatal: fmi3Status = 4;

/// Kind of a variable dependency (fmi3GetVariableDependencies).
pub type fmi3DependencyKind = c_int;
/// Qualifier of a clock interval (fmi3GetIntervalDecimal, fmi3GetIntervalFraction).
pub type fmi3IntervalQualifier = c_int;

/// The logger: `logMessage(instanceEnvironment, status, category, message)`. Not
/// variadic (unlike FMI 2.0's): the message is the text itself, in which FMI 3.0 reads
/// `#<valueReference>#` as a variable reference and `##` as a literal `#`.
pub type fmi3LogMessageCallback =
    Option<unsafe extern "C" fn(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String)>;
/// Intermediate update (never called: providesIntermediateUpdate="false").
pub type fmi3IntermediateUpdateCallback = Option<
    unsafe extern "C" fn(
        fmi3InstanceEnvironment,
        fmi3Float64,
        fmi3Boolean,
        fmi3Boolean,
        fmi3Boolean,
        fmi3Boolean,
        *mut fmi3Boolean,
        *mut fmi3Float64,
    ),
>;
/// Clock update of Scheduled Execution (never called: not provided).
pub type fmi3ClockUpdateCallback = Option<unsafe extern "C" fn(fmi3InstanceEnvironment)>;
/// Preemption lock of Scheduled Execution (never called).
pub type fmi3LockPreemptionCallback = Option<unsafe extern "C" fn()>;
/// Preemption unlock of Scheduled Execution (never called).
pub type fmi3UnlockPreemptionCallback = Option<unsafe extern "C" fn()>;
