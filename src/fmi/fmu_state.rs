//! The FMU-state exports: get, set, free, serialise and deserialise a complete
//! snapshot (solver state, inputs, time, FMI phase). A state handle is a boxed
//! [`Snapshot`] owned by the master until fmi2FreeFMUstate.

#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::instance::*;
use super::state::{self, FmiState};
use super::types::*;
use crate::fmu::snapshot::Snapshot;

fn snapshot_of(inst: &Instance) -> Snapshot {
    inst.model.snapshot(inst.state.code())
}

/// Save the complete state (solver, inputs, time, FMI phase). A non-NULL `*state`
/// from an earlier call is overwritten in place.
///
/// # Safety
/// `c` is an instance; `state` points to a writable fmi2FMUstate that is NULL or was
/// returned by this instance's library.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetFMUstate(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    enter(c, "fmi2GetFMUstate", state::GET_FMU_STATE, |inst| {
        if state.is_null() {
            return Err("FMUstate pointer is NULL".into());
        }
        let snap = snapshot_of(inst);
        store_state(state, snap);
        Ok(fmi2OK)
    })
}

/// Write `snap` into `*state`, reusing an existing allocation.
fn store_state(state: *mut fmi2FMUstate, snap: Snapshot) {
    // SAFETY: `state` is non-null and writable (checked by the callers); a non-null
    // `*state` is a Box<Snapshot> this library created (FMI contract: states are only
    // passed back to the library that made them).
    unsafe {
        if (*state).is_null() {
            *state = Box::into_raw(Box::new(snap)).cast();
        } else {
            *(*state).cast::<Snapshot>() = snap;
        }
    }
}

/// Borrow the snapshot behind a state handle.
///
/// # Safety
/// `s` is NULL or a live state from fmi2GetFMUstate / fmi2DeSerializeFMUstate.
unsafe fn snapshot_ref<'a>(s: fmi2FMUstate) -> Result<&'a Snapshot, String> {
    if s.is_null() {
        return Err("FMUstate is NULL".into());
    }
    // SAFETY: non-null states are Box<Snapshot> created by this library, not yet freed.
    Ok(unsafe { &*s.cast::<Snapshot>() })
}

fn restore(inst: &mut Instance, snap: &Snapshot) -> Outcome {
    let phase = FmiState::from_code(snap.phase)
        .ok_or_else(|| format!("saved state has an unknown phase code {}", snap.phase))?;
    inst.model.restore(snap)?;
    inst.state = phase;
    Ok(fmi2OK)
}

/// Restore a saved state (also the way out of the Error state).
///
/// # Safety
/// `c` is an instance; `state` is a live state of the same FMU.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status {
    enter(c, "fmi2SetFMUstate", state::SET_FMU_STATE, |inst| {
        // SAFETY: `state` is a live state (FMI contract).
        let snap = unsafe { snapshot_ref(state) }?.clone();
        restore(inst, &snap)
    })
}

/// Free a saved state and set `*state` to NULL.
///
/// # Safety
/// `c` is an instance; `state` points to NULL or a live state.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    enter(c, "fmi2FreeFMUstate", state::SET_FMU_STATE, |_| {
        if state.is_null() {
            return Ok(fmi2OK);
        }
        // SAFETY: `state` is writable; a non-null `*state` is a Box<Snapshot> made here.
        unsafe {
            if !(*state).is_null() {
                drop(Box::from_raw((*state).cast::<Snapshot>()));
                *state = std::ptr::null_mut();
            }
        }
        Ok(fmi2OK)
    })
}

/// Size in bytes of a state's serialised form.
///
/// # Safety
/// `c` is an instance; `state` is a live state; `size` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    enter(
        c,
        "fmi2SerializedFMUstateSize",
        state::GET_FMU_STATE,
        |inst| {
            // SAFETY: `state` is a live state.
            let snap = unsafe { snapshot_ref(state) }?;
            if size.is_null() {
                return Err("size pointer is NULL".into());
            }
            let n = snap.to_bytes(&inst.model.guid).len();
            // SAFETY: non-null and writable (FMI contract).
            unsafe { *size = n };
            Ok(fmi2OK)
        },
    )
}

/// Serialise a state into `serializedState` (`size` bytes, from
/// fmi2SerializedFMUstateSize).
///
/// # Safety
/// `c` is an instance; `state` is live; `serializedState` holds `size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    state: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    enter(c, "fmi2SerializeFMUstate", state::GET_FMU_STATE, |inst| {
        // SAFETY: `state` is a live state.
        let snap = unsafe { snapshot_ref(state) }?;
        let bytes = snap.to_bytes(&inst.model.guid);
        if size != bytes.len() {
            return Err(format!(
                "buffer is {size} bytes, the state needs {} (use fmi2SerializedFMUstateSize)",
                bytes.len()
            ));
        }
        // SAFETY: `serializedState` holds `size` writable bytes.
        let out = unsafe { slice_mut(serializedState.cast::<u8>(), size, "serializedState") }?;
        out.copy_from_slice(&bytes);
        Ok(fmi2OK)
    })
}

/// Read a serialised state; foreign or damaged bytes are refused with a message.
///
/// # Safety
/// `c` is an instance; `serializedState` holds `size` bytes; `state` points to NULL or
/// a live state.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    serializedState: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    enter(c, "fmi2DeSerializeFMUstate", state::SET_FMU_STATE, |inst| {
        // SAFETY: `serializedState` holds `size` bytes.
        let bytes = unsafe { slice(serializedState.cast::<u8>(), size, "serializedState") }?;
        if state.is_null() {
            return Err("FMUstate pointer is NULL".into());
        }
        let snap = Snapshot::from_bytes(bytes, &inst.model.guid)?;
        if snap.loads.len() != 6 * inst.model.scene().nodes.len() {
            return Err("serialized state has a different number of inputs than this FMU".into());
        }
        store_state(state, snap);
        Ok(fmi2OK)
    })
}
