//! FMI 3.0's getters and setters of Boolean, String, Binary and Clock, types this FMU
//! has no variables of: as the numeric ones ([`super::other_types`]), fmi3OK for no
//! value reference and a refusal naming the first otherwise.

#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::other_types::none_of;
use super::state;
use super::types::*;

/// Get Boolean variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Boolean,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3GetBoolean",
            state::GET,
            "Boolean",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Set Boolean variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Boolean,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3SetBoolean",
            state::SET,
            "Boolean",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Get String variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetString(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3String,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3GetString",
            state::GET,
            "String",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Set String variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetString(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3String,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3SetString",
            state::SET,
            "String",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Get Binary variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetBinary(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    valueSizes: *mut usize,
    values: *mut fmi3Binary,
    nValues: usize,
) -> fmi3Status {
    let _ = (valueSizes, values); // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3GetBinary",
            state::GET,
            "Binary",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Set Binary variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetBinary(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    valueSizes: *const usize,
    values: *const fmi3Binary,
    nValues: usize,
) -> fmi3Status {
    let _ = (valueSizes, values); // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3SetBinary",
            state::SET,
            "Binary",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Get clocks: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetClock(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Clock,
) -> fmi3Status {
    let _ = values; // this FMU has no clocks
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3GetClock",
            state::CLOCKS,
            "Clock",
            valueReferences,
            nValueReferences,
            nValueReferences,
        )
    }
}

/// Set clocks: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetClock(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Clock,
) -> fmi3Status {
    let _ = values; // this FMU has no clocks
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3SetClock",
            state::CLOCKS,
            "Clock",
            valueReferences,
            nValueReferences,
            nValueReferences,
        )
    }
}
