//! FMI 3.0's getters and setters of the numeric types this FMU has no variables of
//! (Float32, the 8-, 16- and 64-bit and unsigned integers; Boolean, String, Binary and
//! Clock are in [`super::non_numeric`]): each accepts no value reference at all
//! (fmi3OK) and otherwise refuses, naming the first value reference, after the same
//! state and `nValues` checks as the types it has.

#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::state;
use super::types::*;
use super::{V3, scalars};
use crate::fmi::instance::*;
use crate::fmi::values::no_variables;

/// The whole of a getter or setter of a type without variables: `func` in the states of
/// `mask`, `nValues` checked, then fmi3OK for no value reference and a refusal naming
/// the first otherwise.
///
/// # Safety
/// `vr` holds `n_refs` value references.
pub(super) unsafe fn none_of(
    instance: fmi3Instance,
    func: &str,
    mask: u16,
    kind: &'static str,
    vr: *const fmi3ValueReference,
    n_refs: usize,
    n_values: usize,
) -> fmi3Status {
    enter_as(instance, V3, func, mask, |_| {
        scalars(n_refs, n_values)?;
        // SAFETY: `vr` holds `n_refs` value references (the caller's contract).
        no_variables(kind, unsafe { slice(vr, n_refs, "valueReferences") }?)
    })
}

/// Get Float32 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFloat32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Float32,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3GetFloat32",
            state::GET,
            "Float32",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Set Float32 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFloat32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Float32,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3SetFloat32",
            state::SET,
            "Float32",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Get Int8 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetInt8(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int8,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3GetInt8",
            state::GET,
            "Int8",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Set Int8 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetInt8(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int8,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3SetInt8",
            state::SET,
            "Int8",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Get UInt8 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetUInt8(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3UInt8,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3GetUInt8",
            state::GET,
            "UInt8",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Set UInt8 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetUInt8(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3UInt8,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3SetUInt8",
            state::SET,
            "UInt8",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Get Int16 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetInt16(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int16,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3GetInt16",
            state::GET,
            "Int16",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Set Int16 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetInt16(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int16,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3SetInt16",
            state::SET,
            "Int16",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Get UInt16 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetUInt16(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3UInt16,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3GetUInt16",
            state::GET,
            "UInt16",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Set UInt16 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetUInt16(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3UInt16,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3SetUInt16",
            state::SET,
            "UInt16",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Get UInt32 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetUInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3UInt32,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3GetUInt32",
            state::GET,
            "UInt32",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Set UInt32 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetUInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3UInt32,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3SetUInt32",
            state::SET,
            "UInt32",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Get Int64 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int64,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3GetInt64",
            state::GET,
            "Int64",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Set Int64 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int64,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3SetInt64",
            state::SET,
            "Int64",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Get UInt64 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetUInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3UInt64,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3GetUInt64",
            state::GET,
            "UInt64",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}

/// Set UInt64 variables: there are none.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetUInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3UInt64,
    nValues: usize,
) -> fmi3Status {
    let _ = values; // no variable has the type
    // SAFETY: the caller's contract, passed on.
    unsafe {
        none_of(
            instance,
            "fmi3SetUInt64",
            state::SET,
            "UInt64",
            valueReferences,
            nValueReferences,
            nValues,
        )
    }
}
