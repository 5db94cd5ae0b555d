//! FMI 3.0's FMU-state exports: get, set, free, serialise and deserialise, with FMI 2.0's
//! bodies ([`crate::fmi::fmu_state`]): the same handles and bytes, so a state saved by an
//! instance of the FMU packed for one version restores into an instance of the same FMU
//! (same GUID) packed for the other.

#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::V3;
use super::state;
use super::types::*;
use crate::fmi::fmu_state::{
    deserialize_state, free_state, restore_state, save_state, serialize_state, state_size,
};
use crate::fmi::instance::enter_as;

/// Save the complete state (solver, inputs, time, FMI state). A non-NULL `*FMUState`
/// from an earlier call is overwritten in place.
///
/// # Safety
/// `instance` is an instance; `FMUState` points to a writable handle that is NULL or was
/// returned by this library.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    enter_as(
        instance,
        V3,
        "fmi3GetFMUState",
        state::GET_FMU_STATE,
        |inst| {
            // SAFETY: the caller's contract, passed on.
            unsafe { save_state(inst, FMUState) }
        },
    )
}

/// Restore a saved state (also the way out of an error).
///
/// # Safety
/// `instance` is an instance; `FMUState` is a live state of the same FMU.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
) -> fmi3Status {
    enter_as(
        instance,
        V3,
        "fmi3SetFMUState",
        state::SET_FMU_STATE,
        |inst| {
            // SAFETY: the caller's contract, passed on.
            unsafe { restore_state(inst, FMUState) }
        },
    )
}

/// Free a saved state and set `*FMUState` to NULL.
///
/// # Safety
/// `instance` is an instance; `FMUState` points to NULL or a live state.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    enter_as(
        instance,
        V3,
        "fmi3FreeFMUState",
        state::SET_FMU_STATE,
        |inst| {
            // SAFETY: the caller's contract, passed on.
            unsafe { free_state(inst, FMUState) }
        },
    )
}

/// Size in bytes of a state's serialised form.
///
/// # Safety
/// `instance` is an instance; `FMUState` is a live state; `size` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    size: *mut usize,
) -> fmi3Status {
    enter_as(
        instance,
        V3,
        "fmi3SerializedFMUStateSize",
        state::GET_FMU_STATE,
        // SAFETY: the caller's contract, passed on.
        |inst| unsafe { state_size(inst, FMUState, size) },
    )
}

/// Serialise a state into `serializedState` (`size` bytes, from
/// fmi3SerializedFMUStateSize).
///
/// # Safety
/// `instance` is an instance; `FMUState` is live; `serializedState` holds `size`
/// writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializeFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    serializedState: *mut fmi3Byte,
    size: usize,
) -> fmi3Status {
    enter_as(
        instance,
        V3,
        "fmi3SerializeFMUState",
        state::GET_FMU_STATE,
        // SAFETY: the caller's contract, passed on.
        |inst| unsafe { serialize_state(inst, FMUState, serializedState, size) },
    )
}

/// Read a serialised state; foreign or damaged bytes are refused with a message.
///
/// # Safety
/// `instance` is an instance; `serializedState` holds `size` bytes; `FMUState` points to
/// NULL or a live state.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    instance: fmi3Instance,
    serializedState: *const fmi3Byte,
    size: usize,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    enter_as(
        instance,
        V3,
        "fmi3DeserializeFMUState",
        state::SET_FMU_STATE,
        // SAFETY: the caller's contract, passed on.
        |inst| unsafe { deserialize_state(inst, serializedState, size, FMUState) },
    )
}
