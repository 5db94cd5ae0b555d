//! The FMU-state exports: get, set, free, serialise and deserialise a complete
//! snapshot (solver state, inputs, time, FMI phase). A state handle is a boxed
//! [`Handle`]: a fixed-layout [`Header`] (magic number, layout tag, the GUID of the FMU
//! whose instance made it), then the [`Snapshot`]. Every function that receives a handle
//! checks the header first and refuses, naming both GUIDs, a handle made by an instance
//! of another FMU, before touching anything else.
//!
//! Residual risk: FMI handles are untyped pointers, so a handle from a library that is
//! not fxbody can only be recognised by reading its first 8 bytes (the magic number).
//! That read is sound for any live heap object of 8 bytes or more, which every FMU state
//! known to us is; a smaller or freed object, or a pointer that is not one at all, is
//! undefined behaviour the C ABI gives no way to detect. The rest of the header is read
//! only after the magic number matched, and the snapshot only after the layout tag (crate
//! version and sizes) and the GUID matched: that is, only a handle made by this same
//! build for this same FMU.

#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::FmiError;
use super::instance::*;
use super::state::{self, FmiState};
use super::types::*;
use crate::fmu::hash::{FNV_OFFSET, fnv1a64};
use crate::fmu::snapshot::Snapshot;

/// "FXBSTHDL" read as a little-endian u64: the first 8 bytes of every handle made here.
const MAGIC: u64 = u64::from_le_bytes(*b"FXBSTHDL");
/// How many bytes of the GUID a header keeps for messages (the full GUID is compared by
/// length and hash).
const GUID_TEXT: usize = 60;

/// The fixed-layout start of a state handle: readable by any fxbody build, whatever the
/// layout of what follows.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct Header {
    magic: u64,
    /// [`layout_tag`] of the build that made the handle.
    layout: u64,
    /// FNV-1a 64 of the GUID of the FMU whose instance made the handle.
    guid_hash: u64,
    guid_len: u32,
    guid_text: [u8; GUID_TEXT],
}

/// A state handle: header, then the snapshot.
#[repr(C)]
pub struct Handle {
    header: Header,
    snap: Snapshot,
}

/// A tag of this build's handle layout: crate version, sizes and alignments of the
/// handle and snapshot. Handles of builds with another tag are refused unread.
fn layout_tag() -> u64 {
    let mut h = fnv1a64(FNV_OFFSET, env!("CARGO_PKG_VERSION").as_bytes());
    for n in [
        std::mem::size_of::<Handle>(),
        std::mem::align_of::<Handle>(),
        std::mem::size_of::<Snapshot>(),
    ] {
        h = fnv1a64(h, &(n as u64).to_le_bytes());
    }
    h
}

fn header_for(guid: &str) -> Header {
    let mut guid_text = [0u8; GUID_TEXT];
    let n = guid.len().min(GUID_TEXT);
    guid_text[..n].copy_from_slice(&guid.as_bytes()[..n]);
    Header {
        magic: MAGIC,
        layout: layout_tag(),
        guid_hash: fnv1a64(FNV_OFFSET, guid.as_bytes()),
        guid_len: u32::try_from(guid.len()).unwrap_or(u32::MAX),
        guid_text,
    }
}

impl Header {
    fn guid(&self) -> String {
        let n = (self.guid_len as usize).min(GUID_TEXT);
        let text = String::from_utf8_lossy(&self.guid_text[..n]).into_owned();
        if self.guid_len as usize > GUID_TEXT {
            format!("{text}...")
        } else {
            text
        }
    }
}

/// A state handle this instance cannot use: NULL, not an fxbody state, or made by
/// another build or another FMU.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum HandleError {
    /// NULL.
    #[error("FMUstate is NULL")]
    Null,
    /// Not aligned as an fxbody handle is.
    #[error("FMUstate was not made by an fxbody FMU (misaligned handle)")]
    Misaligned,
    /// No fxbody header.
    #[error(
        "FMUstate was not made by an fxbody FMU (no fxbody state header): a state \
         belongs to the FMU whose instance made it"
    )]
    NoHeader,
    /// Made by an fxbody build with another handle layout.
    #[error(
        "FMUstate was made by another fxbody build (layout tag {layout:016x}, this build \
         {this_layout:016x}) for GUID {guid}; this instance is {instance}"
    )]
    OtherBuild {
        /// The handle's layout tag.
        layout: u64,
        /// This build's.
        this_layout: u64,
        /// The GUID in the handle.
        guid: String,
        /// This instance's GUID.
        instance: String,
    },
    /// Made by another FMU.
    #[error(
        "FMUstate belongs to the FMU with GUID {guid}, this instance is GUID {instance}: a \
         state can only be restored into an instance of the FMU that made it"
    )]
    OtherFmu {
        /// The GUID in the handle.
        guid: String,
        /// This instance's GUID.
        instance: String,
    },
}

/// The handle behind `s`, if it is a live handle made by this build for the FMU with
/// `guid`; otherwise a message naming what it is.
///
/// # Safety
/// `s` is NULL or points to a live object of at least 8 bytes (FMI: a state handle
/// returned by some FMU and not yet freed).
unsafe fn handle<'a>(s: fmi2FMUstate, guid: &str) -> Result<&'a mut Handle, HandleError> {
    if s.is_null() {
        return Err(HandleError::Null);
    }
    if s.cast::<Header>()
        .align_offset(std::mem::align_of::<Header>())
        != 0
    {
        return Err(HandleError::Misaligned);
    }
    // SAFETY: non-null, aligned, and by the caller's contract at least 8 live bytes.
    let magic = unsafe { s.cast::<u64>().read() };
    if magic != MAGIC {
        return Err(HandleError::NoHeader);
    }
    // SAFETY: the magic number says this is a handle of some fxbody build, all of which
    // start with this fixed-layout (repr(C)) header; it is copied out, not referenced.
    let head = unsafe { s.cast::<Header>().read() };
    if head.layout != layout_tag() {
        return Err(HandleError::OtherBuild {
            layout: head.layout,
            this_layout: layout_tag(),
            guid: head.guid(),
            instance: guid.to_string(),
        });
    }
    let mine = header_for(guid);
    if head.guid_hash != mine.guid_hash || head.guid_len != mine.guid_len {
        return Err(HandleError::OtherFmu {
            guid: head.guid(),
            instance: guid.to_string(),
        });
    }
    // SAFETY: header, layout tag and GUID match: `s` is a Box<Handle> this build made
    // for this FMU (from fmi2GetFMUstate or fmi2DeSerializeFMUstate), not yet freed; FMI
    // forbids concurrent calls, so no other reference to it is in use.
    Ok(unsafe { &mut *s.cast::<Handle>() })
}

fn snapshot_of(inst: &Instance) -> Snapshot {
    // In Error the model holds the state before the error: record that one, so that a
    // state saved in Error restores to a legal state.
    inst.simulation.snapshot(inst.phase().code())
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
        // SAFETY: the caller's contract, passed on.
        unsafe { save_state(inst, state) }
    })
}

/// The body of fmi2GetFMUstate and fmi3GetFMUState.
///
/// # Safety
/// `state` points to a writable handle that is NULL or was returned by this library.
pub(crate) unsafe fn save_state(inst: &mut Instance, state: *mut fmi2FMUstate) -> Outcome {
    if state.is_null() {
        return Err(FmiError::Null("FMUstate pointer"));
    }
    let snap = snapshot_of(inst);
    // SAFETY: non-null and writable (FMI contract).
    unsafe { store_state(state, snap, &inst.simulation.guid) }
}

/// Write `snap` into `*state`: a new handle for NULL, else the existing handle (checked
/// to be this FMU's) overwritten in place.
///
/// # Safety
/// `state` is non-null and writable; `*state` is NULL or a live state handle.
unsafe fn store_state(state: *mut fmi2FMUstate, snap: Snapshot, guid: &str) -> Outcome {
    // SAFETY: `state` is non-null and writable (caller's contract).
    let old = unsafe { *state };
    if old.is_null() {
        let h = Box::new(Handle {
            header: header_for(guid),
            snap,
        });
        // SAFETY: as above.
        unsafe { *state = Box::into_raw(h).cast() };
    } else {
        // SAFETY: a non-null `*state` is a live handle (caller's contract); checked.
        unsafe { handle(old, guid) }?.snap = snap;
    }
    Ok(fmi2OK)
}

fn restore(inst: &mut Instance, snap: &Snapshot) -> Outcome {
    let phase = FmiState::from_code(snap.phase).ok_or(FmiError::UnknownPhase(snap.phase))?;
    inst.simulation.restore(snap)?;
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
        // SAFETY: the caller's contract, passed on.
        unsafe { restore_state(inst, state) }
    })
}

/// The body of fmi2SetFMUstate and fmi3SetFMUState.
///
/// # Safety
/// `state` is NULL or a live state handle.
pub(crate) unsafe fn restore_state(inst: &mut Instance, state: fmi2FMUstate) -> Outcome {
    // SAFETY: `state` is a live state (FMI contract); its header is checked first.
    let snap = unsafe { handle(state, &inst.simulation.guid) }?
        .snap
        .clone();
    restore(inst, &snap)
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
    enter(c, "fmi2FreeFMUstate", state::SET_FMU_STATE, |inst| {
        // SAFETY: the caller's contract, passed on.
        unsafe { free_state(inst, state) }
    })
}

/// The body of fmi2FreeFMUstate and fmi3FreeFMUState.
///
/// # Safety
/// `state` is NULL or points to NULL or a live state handle.
pub(crate) unsafe fn free_state(inst: &mut Instance, state: *mut fmi2FMUstate) -> Outcome {
    if state.is_null() {
        return Ok(fmi2OK);
    }
    // SAFETY: `state` is writable (FMI contract).
    let s = unsafe { *state };
    if s.is_null() {
        return Ok(fmi2OK);
    }
    // SAFETY: a live handle (FMI contract); checked to be this build's for this FMU, so
    // it is a Box<Handle> made here, freed once as `*state` is then cleared.
    unsafe {
        let h: *mut Handle = handle(s, &inst.simulation.guid)?;
        drop(Box::from_raw(h));
        *state = std::ptr::null_mut();
    }
    Ok(fmi2OK)
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
        // SAFETY: the caller's contract, passed on.
        |inst| unsafe { state_size(inst, state, size) },
    )
}

/// The body of fmi2SerializedFMUstateSize and fmi3SerializedFMUStateSize.
///
/// # Safety
/// `state` is NULL or a live state handle; `size` is NULL or writable.
pub(crate) unsafe fn state_size(
    inst: &mut Instance,
    state: fmi2FMUstate,
    size: *mut usize,
) -> Outcome {
    // SAFETY: `state` is a live state; its header is checked first.
    let snap = &unsafe { handle(state, &inst.simulation.guid) }?.snap;
    if size.is_null() {
        return Err(FmiError::Null("size pointer"));
    }
    let n = snap.to_bytes(&inst.simulation.guid).len();
    // SAFETY: non-null and writable (FMI contract).
    unsafe { *size = n };
    Ok(fmi2OK)
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
        // SAFETY: the caller's contract, passed on.
        unsafe { serialize_state(inst, state, serializedState.cast(), size) }
    })
}

/// The body of fmi2SerializeFMUstate and fmi3SerializeFMUState.
///
/// # Safety
/// `state` is NULL or a live state handle; `out` holds `size` writable bytes.
pub(crate) unsafe fn serialize_state(
    inst: &mut Instance,
    state: fmi2FMUstate,
    out: *mut u8,
    size: usize,
) -> Outcome {
    // SAFETY: `state` is a live state; its header is checked first.
    let snap = &unsafe { handle(state, &inst.simulation.guid) }?.snap;
    let bytes = snap.to_bytes(&inst.simulation.guid);
    if size != bytes.len() {
        return Err(FmiError::BufferTooSmall {
            size,
            needs: bytes.len(),
        });
    }
    // SAFETY: `out` holds `size` writable bytes.
    let out = unsafe { slice_mut(out, size, "serializedState") }?;
    out.copy_from_slice(&bytes);
    Ok(fmi2OK)
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
        // SAFETY: the caller's contract, passed on.
        unsafe { deserialize_state(inst, serializedState.cast(), size, state) }
    })
}

/// The body of fmi2DeSerializeFMUstate and fmi3DeserializeFMUState.
///
/// # Safety
/// `bytes` holds `size` bytes; `state` is NULL or points to NULL or a live state.
pub(crate) unsafe fn deserialize_state(
    inst: &mut Instance,
    bytes: *const u8,
    size: usize,
    state: *mut fmi2FMUstate,
) -> Outcome {
    // SAFETY: `bytes` holds `size` bytes.
    let bytes = unsafe { slice(bytes, size, "serializedState") }?;
    if state.is_null() {
        return Err(FmiError::Null("FMUstate pointer"));
    }
    let snap = Snapshot::from_bytes(bytes, &inst.simulation.guid)?;
    if snap.loads.len() != 6 * inst.simulation.scene().nodes.len() {
        return Err(FmiError::StateInputs);
    }
    // SAFETY: `state` is non-null and writable, `*state` NULL or live (FMI contract).
    unsafe { store_state(state, snap, &inst.simulation.guid) }
}
