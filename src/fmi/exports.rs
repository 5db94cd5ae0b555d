//! The 34 FMI 2.0 co-simulation functions, exported unprefixed. Each one converts its
//! pointer arguments and hands over to [`enter`] (state mask, panic barrier, logging)
//! and the safe model in [`crate::fmu::model`].

#![allow(non_snake_case, clippy::missing_safety_doc)]

use std::ffi::c_char;
use std::panic::{AssertUnwindSafe, catch_unwind};

use super::instance::*;
use super::state::{self, FmiState};
use super::types::*;
use super::uri::resource_path;
use crate::fmu::model::{Model, Phase};
use crate::fmu::snapshot::Snapshot;

/// "default": the standard C types of fmi2TypesPlatform.h.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// "2.0".
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// Switch debug log categories: all (n = 0) or the named ones, on or off.
///
/// # Safety
/// `c` is an instance from fmi2Instantiate; `categories` holds `nCategories` strings.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    loggingOn: fmi2Boolean,
    nCategories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    enter(c, "fmi2SetDebugLogging", state::SET_DEBUG_LOGGING, |inst| {
        let on = loggingOn != fmi2False;
        // SAFETY: `categories` holds `nCategories` pointers (FMI contract).
        let names = unsafe { slice(categories, nCategories, "categories") }?;
        if names.is_empty() {
            inst.log.enabled = [on; CATEGORIES.len()];
            return Ok(fmi2OK);
        }
        for &p in names {
            // SAFETY: each entry is a NUL-terminated string (FMI contract).
            let name = unsafe { text_arg(p) }.ok_or("a category name is NULL")?;
            let k = CATEGORIES
                .iter()
                .position(|c| c.to_bytes() == name.as_bytes())
                .ok_or_else(|| {
                    let known: Vec<_> = CATEGORIES.iter().map(|c| c.to_string_lossy()).collect();
                    format!(
                        "unknown log category '{name}' (declared: {})",
                        known.join(", ")
                    )
                })?;
            inst.log.enabled[k] = on;
        }
        Ok(fmi2OK)
    })
}

/// Create an instance: copy the arguments, decode the resource URI, read the body and
/// scene from resources/, check the GUID. NULL (with a logged reason) on any failure.
///
/// # Safety
/// String arguments are NULL or NUL-terminated; `functions` is NULL or valid for the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    instanceName: fmi2String,
    fmuType: fmi2Type,
    fmuGUID: fmi2String,
    fmuResourceLocation: fmi2String,
    functions: *const fmi2CallbackFunctions,
    visible: fmi2Boolean,
    loggingOn: fmi2Boolean,
) -> fmi2Component {
    let _ = visible; // not needed by this FMU
    if functions.is_null() {
        return std::ptr::null_mut();
    }
    // SAFETY: non-null and valid for the call (FMI contract); copied by value, as the
    // struct need not outlive the call.
    let functions = unsafe { *functions };
    // SAFETY: NUL-terminated or NULL (FMI contract); copied now.
    let name = unsafe { text_arg(instanceName) };
    // SAFETY: as above.
    let guid = unsafe { text_arg(fmuGUID) };
    // SAFETY: as above.
    let location = unsafe { text_arg(fmuResourceLocation) };
    let log = Log::new(
        &functions,
        name.as_deref().unwrap_or(""),
        loggingOn != fmi2False,
    );
    let result = catch_unwind(AssertUnwindSafe(|| -> Result<Box<Instance>, String> {
        if name.as_deref().is_none_or(str::is_empty) {
            return Err("instanceName is NULL or empty".into());
        }
        if fmuType != fmi2CoSimulation {
            return Err(format!(
                "fmuType {fmuType}: this FMU provides co-simulation (1) only"
            ));
        }
        let guid = guid.ok_or("fmuGUID is NULL")?;
        let location =
            location.ok_or("fmuResourceLocation is NULL: the FMU needs its resources folder")?;
        let dir = resource_path(&location)?;
        let model = Model::from_resources(&dir)?;
        if model.guid != guid {
            return Err(format!(
                "GUID mismatch: the caller passed {guid} but the FMU's resources ({}) give {}; \
                 the modelDescription.xml and the resources are from different packs",
                dir.display(),
                model.guid
            ));
        }
        Ok(Box::new(Instance {
            log: Log::new(
                &functions,
                name.as_deref().unwrap_or(""),
                loggingOn != fmi2False,
            ),
            state: FmiState::Instantiated,
            model,
        }))
    }));
    match result {
        Ok(Ok(inst)) => {
            if inst.log.on(LOG_SOLVER) {
                let m = &inst.model;
                inst.log.send(
                    fmi2OK,
                    LOG_SOLVER,
                    &format!(
                        "instantiated: {} variables, {} exposed nodes, {} local modes",
                        m.table.vars.len(),
                        m.scene().nodes.len(),
                        m.scene().body.nl()
                    ),
                );
            }
            Box::into_raw(inst).cast()
        }
        Ok(Err(msg)) => {
            log.send(fmi2Error, LOG_ERROR, &format!("fmi2Instantiate: {msg}"));
            std::ptr::null_mut()
        }
        Err(p) => {
            log.send(
                fmi2Fatal,
                LOG_ERROR,
                &format!(
                    "fmi2Instantiate: internal error (panic): {}",
                    panic_text(&*p)
                ),
            );
            std::ptr::null_mut()
        }
    }
}

/// Free an instance (NULL is ignored).
///
/// # Safety
/// `c` is NULL or an instance from fmi2Instantiate not yet freed.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    if c.is_null() {
        return;
    }
    // SAFETY: `c` came from Box::into_raw in fmi2Instantiate and is freed only here.
    let inst = unsafe { Box::from_raw(c.cast::<Instance>()) };
    let _ = catch_unwind(AssertUnwindSafe(move || drop(inst)));
}

/// Record start and stop time (tolerance is not used: every method is fixed-step).
///
/// # Safety
/// `c` is an instance from fmi2Instantiate.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    toleranceDefined: fmi2Boolean,
    tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    let _ = (toleranceDefined, tolerance); // not needed by this FMU
    enter(c, "fmi2SetupExperiment", state::SETUP_EXPERIMENT, |inst| {
        inst.model.setup(
            startTime,
            (stopTimeDefined != fmi2False).then_some(stopTime),
        )?;
        Ok(fmi2OK)
    })
}

fn build_solver(inst: &mut Instance) -> Result<(), String> {
    if let Some(msg) = inst.model.ensure_solver()? {
        inst.log.send(fmi2OK, LOG_SOLVER, &msg);
    }
    Ok(())
}

/// Enter initialisation mode: the solver is built with the parameters set so far.
///
/// # Safety
/// `c` is an instance from fmi2Instantiate.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    enter(
        c,
        "fmi2EnterInitializationMode",
        state::ENTER_INITIALIZATION_MODE,
        |inst| {
            build_solver(inst)?;
            inst.state = FmiState::InitializationMode;
            Ok(fmi2OK)
        },
    )
}

/// Leave initialisation mode (rebuilding the solver if a parameter changed).
///
/// # Safety
/// `c` is an instance from fmi2Instantiate.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    enter(
        c,
        "fmi2ExitInitializationMode",
        state::EXIT_INITIALIZATION_MODE,
        |inst| {
            build_solver(inst)?;
            inst.state = FmiState::StepComplete;
            Ok(fmi2OK)
        },
    )
}

/// End the simulation.
///
/// # Safety
/// `c` is an instance from fmi2Instantiate.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    enter(c, "fmi2Terminate", state::TERMINATE, |inst| {
        inst.state = FmiState::Terminated;
        Ok(fmi2OK)
    })
}

/// Back to the instantiated state with start values.
///
/// # Safety
/// `c` is an instance from fmi2Instantiate.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    enter(c, "fmi2Reset", state::RESET, |inst| {
        inst.model.reset();
        inst.state = FmiState::Instantiated;
        Ok(fmi2OK)
    })
}

fn phase(s: FmiState) -> Phase {
    match s {
        FmiState::Instantiated | FmiState::InitializationMode => Phase::Configuring,
        _ => Phase::Running,
    }
}

/// Get Real variables.
///
/// # Safety
/// `c` is an instance; `vr` and `value` hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    enter(c, "fmi2GetReal", state::GET, |inst| {
        // SAFETY: `vr` holds `nvr` value references (FMI contract).
        let vrs = unsafe { slice(vr, nvr, "vr") }?;
        // SAFETY: `value` holds `nvr` writable reals, distinct from `vr`.
        let out = unsafe { slice_mut(value, nvr, "value") }?;
        inst.model.get_reals(vrs, out)?;
        Ok(fmi2OK)
    })
}

/// Get Integer variables (the Enumeration `method`).
///
/// # Safety
/// `c` is an instance; `vr` and `value` hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    enter(c, "fmi2GetInteger", state::GET, |inst| {
        // SAFETY: `vr` holds `nvr` value references.
        let vrs = unsafe { slice(vr, nvr, "vr") }?;
        // SAFETY: `value` holds `nvr` writable integers.
        let out = unsafe { slice_mut(value, nvr, "value") }?;
        for (&r, o) in vrs.iter().zip(out.iter_mut()) {
            *o = inst.model.get_integer(r)?;
        }
        Ok(fmi2OK)
    })
}

fn no_variables(kind: &str, vrs: &[fmi2ValueReference]) -> Outcome {
    match vrs.first() {
        None => Ok(fmi2OK),
        Some(r) => Err(format!(
            "value reference {r}: this FMU has no {kind} variables"
        )),
    }
}

/// Get Boolean variables (there are none).
///
/// # Safety
/// `c` is an instance; `vr` holds `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    let _ = value; // not needed by this FMU
    enter(c, "fmi2GetBoolean", state::GET, |_| {
        // SAFETY: `vr` holds `nvr` value references.
        no_variables("Boolean", unsafe { slice(vr, nvr, "vr") }?)
    })
}

/// Get String variables (there are none).
///
/// # Safety
/// `c` is an instance; `vr` holds `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    let _ = value; // not needed by this FMU
    enter(c, "fmi2GetString", state::GET, |_| {
        // SAFETY: `vr` holds `nvr` value references.
        no_variables("String", unsafe { slice(vr, nvr, "vr") }?)
    })
}

/// Set Real variables (parameters before initialisation ends, inputs at any time).
///
/// # Safety
/// `c` is an instance; `vr` and `value` hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    enter(c, "fmi2SetReal", state::SET, |inst| {
        // SAFETY: `vr` holds `nvr` value references.
        let vrs = unsafe { slice(vr, nvr, "vr") }?;
        // SAFETY: `value` holds `nvr` reals.
        let vals = unsafe { slice(value, nvr, "value") }?;
        inst.model.set_reals(vrs, vals, phase(inst.state))?;
        Ok(fmi2OK)
    })
}

/// Set Integer variables (the Enumeration `method`).
///
/// # Safety
/// `c` is an instance; `vr` and `value` hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    enter(c, "fmi2SetInteger", state::SET, |inst| {
        // SAFETY: `vr` holds `nvr` value references.
        let vrs = unsafe { slice(vr, nvr, "vr") }?;
        // SAFETY: `value` holds `nvr` integers.
        let vals = unsafe { slice(value, nvr, "value") }?;
        inst.model.set_integers(vrs, vals, phase(inst.state))?;
        Ok(fmi2OK)
    })
}

/// Set Boolean variables (there are none).
///
/// # Safety
/// `c` is an instance; `vr` holds `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    let _ = value; // not needed by this FMU
    enter(c, "fmi2SetBoolean", state::SET, |_| {
        // SAFETY: `vr` holds `nvr` value references.
        no_variables("Boolean", unsafe { slice(vr, nvr, "vr") }?)
    })
}

/// Set String variables (there are none).
///
/// # Safety
/// `c` is an instance; `vr` holds `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    let _ = value; // not needed by this FMU
    enter(c, "fmi2SetString", state::SET, |_| {
        // SAFETY: `vr` holds `nvr` value references.
        no_variables("String", unsafe { slice(vr, nvr, "vr") }?)
    })
}

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

/// Not provided (providesDirectionalDerivative="false"): logs why, returns fmi2Error.
///
/// # Safety
/// `c` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    vUnknown_ref: *const fmi2ValueReference,
    nUnknown: usize,
    vKnown_ref: *const fmi2ValueReference,
    nKnown: usize,
    dvKnown: *const fmi2Real,
    dvUnknown: *mut fmi2Real,
) -> fmi2Status {
    let _ = (
        vUnknown_ref,
        nUnknown,
        vKnown_ref,
        nKnown,
        dvKnown,
        dvUnknown,
    ); // not needed by this FMU
    enter(
        c,
        "fmi2GetDirectionalDerivative",
        state::GET_DIRECTIONAL_DERIVATIVE,
        |_| Err("not provided by this FMU (providesDirectionalDerivative=\"false\")".into()),
    )
}

/// Input time derivatives (order 1): the load varies linearly over the next step.
///
/// # Safety
/// `c` is an instance; `vr`, `order`, `value` hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    enter(
        c,
        "fmi2SetRealInputDerivatives",
        state::SET_REAL_INPUT_DERIVATIVES,
        |inst| {
            // SAFETY: each array holds `nvr` elements (FMI contract).
            let (vrs, ords, vals) = unsafe {
                (
                    slice(vr, nvr, "vr")?,
                    slice(order, nvr, "order")?,
                    slice(value, nvr, "value")?,
                )
            };
            inst.model.set_input_rates(vrs, ords, vals)?;
            Ok(fmi2OK)
        },
    )
}

/// Output time derivatives: node positions (orders 1, 2), node velocities (order 1).
///
/// # Safety
/// `c` is an instance; `vr`, `order`, `value` hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *mut fmi2Real,
) -> fmi2Status {
    enter(
        c,
        "fmi2GetRealOutputDerivatives",
        state::GET_REAL_OUTPUT_DERIVATIVES,
        |inst| {
            // SAFETY: each array holds `nvr` elements; `value` is writable and distinct.
            let (vrs, ords, out) = unsafe {
                (
                    slice(vr, nvr, "vr")?,
                    slice(order, nvr, "order")?,
                    slice_mut(value, nvr, "value")?,
                )
            };
            for ((&r, &o), v) in vrs.iter().zip(ords).zip(out.iter_mut()) {
                *v = inst.model.get_output_derivative(r, o)?;
            }
            Ok(fmi2OK)
        },
    )
}

/// Advance from `currentCommunicationPoint` by `communicationStepSize` (synchronous).
///
/// # Safety
/// `c` is an instance from fmi2Instantiate.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    let _ = noSetFMUStatePriorToCurrentPoint; // not needed by this FMU
    enter(c, "fmi2DoStep", state::DO_STEP, |inst| {
        inst.model
            .do_step(currentCommunicationPoint, communicationStepSize)?;
        Ok(fmi2OK)
    })
}

/// Only legal while an asynchronous step runs, which never happens here.
///
/// # Safety
/// `c` is an instance from fmi2Instantiate.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    enter(c, "fmi2CancelStep", state::CANCEL_STEP, |_| Ok(fmi2OK))
}

fn discard(inst: &Instance, what: &str) -> Outcome {
    inst.log.send(fmi2Discard, LOG_WARNING, what);
    Ok(fmi2Discard)
}

/// Status of an asynchronous step: none ever runs, so fmi2Discard.
///
/// # Safety
/// `c` is an instance; `value` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Status,
) -> fmi2Status {
    let _ = (s, value); // not needed by this FMU
    enter(c, "fmi2GetStatus", state::GET_STATUS, |inst| {
        discard(
            inst,
            "fmi2GetStatus: steps are synchronous, no status to report",
        )
    })
}

/// fmi2LastSuccessfulTime: the current time; other kinds fmi2Discard.
///
/// # Safety
/// `c` is an instance; `value` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    enter(c, "fmi2GetRealStatus", state::GET_STATUS, |inst| {
        if s != fmi2LastSuccessfulTime {
            return discard(
                inst,
                &format!("fmi2GetRealStatus: status kind {s} has no Real value"),
            );
        }
        if value.is_null() {
            return Err("value pointer is NULL".into());
        }
        // SAFETY: non-null and writable (FMI contract).
        unsafe { *value = inst.model.time() };
        Ok(fmi2OK)
    })
}

/// No Integer status kinds: fmi2Discard.
///
/// # Safety
/// `c` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Integer,
) -> fmi2Status {
    let _ = value; // not needed by this FMU
    enter(c, "fmi2GetIntegerStatus", state::GET_STATUS, |inst| {
        discard(
            inst,
            &format!("fmi2GetIntegerStatus: status kind {s} has no Integer value"),
        )
    })
}

/// fmi2Terminated: false (the slave never asks to stop); other kinds fmi2Discard.
///
/// # Safety
/// `c` is an instance; `value` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    enter(c, "fmi2GetBooleanStatus", state::GET_STATUS, |inst| {
        if s != fmi2Terminated {
            return discard(
                inst,
                &format!("fmi2GetBooleanStatus: status kind {s} has no Boolean value"),
            );
        }
        if value.is_null() {
            return Err("value pointer is NULL".into());
        }
        // SAFETY: non-null and writable (FMI contract).
        unsafe { *value = fmi2False };
        Ok(fmi2OK)
    })
}

/// No pending step, so no text: fmi2Discard.
///
/// # Safety
/// `c` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2String,
) -> fmi2Status {
    let _ = value; // not needed by this FMU
    enter(c, "fmi2GetStringStatus", state::GET_STATUS, |inst| {
        discard(
            inst,
            &format!("fmi2GetStringStatus: status kind {s}: no pending step"),
        )
    })
}
