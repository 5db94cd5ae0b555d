//! The FMI 2.0 co-simulation exports for the instance life cycle and stepping:
//! platform and version, logging, instantiate and free, setup, initialisation,
//! terminate, reset, doStep, cancel and the status queries. The value exports are in
//! [`super::values`], the FMU-state ones in [`super::fmu_state`]: 34 in all, exported
//! unprefixed. Each converts its pointer arguments and hands over to `enter` (state
//! mask, panic barrier, logging) and the safe model in [`crate::fmu::simulation`].

#![allow(non_snake_case, clippy::missing_safety_doc)]

use std::ffi::c_char;

use super::FmiError;
use super::instance::*;
use super::instantiate::{free_instance, instantiate};
use super::state::{self, FmiState};
use super::types::*;
use super::uri::resource_path;
use super::version::{FmiVersion, Interface};

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
        // SAFETY: the caller's contract, passed on.
        unsafe { set_debug_logging(inst, loggingOn != fmi2False, nCategories, categories) }
    })
}

/// The body of fmi2SetDebugLogging and fmi3SetDebugLogging: all categories (n = 0) or
/// the named ones, on or off; an unknown name refuses the call, naming the declared
/// ones.
///
/// # Safety
/// `categories` holds `n` NUL-terminated strings (unread for n = 0).
pub(crate) unsafe fn set_debug_logging(
    inst: &mut Instance,
    on: bool,
    n: usize,
    categories: *const *const c_char,
) -> Outcome {
    // SAFETY: `categories` holds `n` pointers (FMI contract).
    let names = unsafe { slice(categories, n, "categories") }?;
    if names.is_empty() {
        inst.log.enabled = [on; CATEGORIES.len()];
        return Ok(fmi2OK);
    }
    for &p in names {
        // SAFETY: each entry is a NUL-terminated string (FMI contract).
        let name = unsafe { text_arg(p) }.ok_or(FmiError::Null("a category name"))?;
        let k = CATEGORIES
            .iter()
            .position(|c| c.to_bytes() == name.as_bytes())
            .ok_or_else(|| {
                let known: Vec<_> = CATEGORIES.iter().map(|c| c.to_string_lossy()).collect();
                FmiError::UnknownCategory {
                    name: name.clone(),
                    declared: known.join(", "),
                }
            })?;
        inst.log.enabled[k] = on;
    }
    Ok(fmi2OK)
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
    instantiate(
        "fmi2Instantiate",
        FmiVersion::Fmi2,
        name,
        |n| Log::new(&functions, n, loggingOn != fmi2False),
        || {
            let interface = if fmuType == fmi2CoSimulation {
                Interface::CoSimulation
            } else if fmuType == fmi2ModelExchange {
                Interface::ModelExchange
            } else {
                return Err(FmiError::FmuType(fmuType));
            };
            let guid = guid.ok_or(FmiError::Null("fmuGUID"))?;
            let location = location.ok_or(FmiError::NoResourceLocation)?;
            Ok((interface, guid, resource_path(&location)?))
        },
    )
}

/// Free an instance (NULL is ignored).
///
/// # Safety
/// `c` is NULL or an instance from fmi2Instantiate not yet freed.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    // SAFETY: the caller's contract, passed on.
    unsafe { free_instance(c) }
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
        inst.simulation.setup(
            startTime,
            (stopTimeDefined != fmi2False).then_some(stopTime),
        )?;
        Ok(fmi2OK)
    })
}

fn build_solver(inst: &mut Instance) -> Result<(), FmiError> {
    if let Some(msg) = inst.simulation.ensure_solver()? {
        inst.log.send(fmi2OK, LOG_SOLVER, &msg);
    }
    Ok(())
}

/// Into initialisation mode, the solver built with the parameters set so far (both
/// versions).
pub(crate) fn enter_initialization(inst: &mut Instance) -> Outcome {
    build_solver(inst)?;
    inst.state = FmiState::InitializationMode;
    Ok(fmi2OK)
}

/// Out of initialisation mode (the solver rebuilt if a parameter changed; both
/// versions): ready to step (co-simulation), or in Event Mode (Model Exchange).
pub(crate) fn exit_initialization(inst: &mut Instance) -> Outcome {
    build_solver(inst)?;
    inst.state = match inst.interface {
        Interface::CoSimulation => FmiState::StepComplete,
        Interface::ModelExchange => FmiState::EventMode,
    };
    Ok(fmi2OK)
}

/// Refuse a function of `interface` on an instance serving the other one (a
/// co-simulation function on a Model Exchange instance, in a state the co-simulation
/// table allows it, or the reverse).
pub(crate) fn only_for(inst: &Instance, interface: Interface) -> Result<(), FmiError> {
    if inst.interface == interface {
        Ok(())
    } else {
        Err(FmiError::WrongInterface {
            function_of: interface.name(),
            instance: inst.interface.name(),
        })
    }
}

/// [`only_for`] co-simulation (input and output derivatives, the status queries).
pub(crate) fn co_simulation_only(inst: &Instance) -> Result<(), FmiError> {
    only_for(inst, Interface::CoSimulation)
}

/// Back to the instantiated state with start values (both versions).
pub(crate) fn reset(inst: &mut Instance) -> Outcome {
    inst.simulation.reset();
    inst.state = FmiState::Instantiated;
    Ok(fmi2OK)
}

/// One communication step of `func` (both versions): a warning the step raised is
/// logged and returned as Warning.
#[inline(always)]
pub(crate) fn do_step(inst: &mut Instance, func: &str, t: f64, h: f64) -> Outcome {
    let warned = inst.simulation.step(t, h)?;
    Ok(if warned {
        step_warning(inst, func)
    } else {
        fmi2OK
    })
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
        enter_initialization,
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
        exit_initialization,
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
    enter(c, "fmi2Reset", state::RESET, reset)
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
        do_step(
            inst,
            "fmi2DoStep",
            currentCommunicationPoint,
            communicationStepSize,
        )
    })
}

/// A completed step with a warning: logged, Warning. Out of the step path.
#[cold]
#[inline(never)]
fn step_warning(inst: &mut Instance, func: &str) -> fmi2Status {
    let warning = inst.simulation.take_warning().unwrap_or_default();
    inst.log
        .send(fmi2Warning, LOG_WARNING, &format!("{func}: {warning}"));
    fmi2Warning
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
        co_simulation_only(inst)?;
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
        co_simulation_only(inst)?;
        if s != fmi2LastSuccessfulTime {
            return discard(
                inst,
                &format!("fmi2GetRealStatus: status kind {s} has no Real value"),
            );
        }
        if value.is_null() {
            return Err(FmiError::Null("value pointer"));
        }
        // SAFETY: non-null and writable (FMI contract).
        unsafe { *value = inst.simulation.time() };
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
        co_simulation_only(inst)?;
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
        co_simulation_only(inst)?;
        if s != fmi2Terminated {
            return discard(
                inst,
                &format!("fmi2GetBooleanStatus: status kind {s} has no Boolean value"),
            );
        }
        if value.is_null() {
            return Err(FmiError::Null("value pointer"));
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
        co_simulation_only(inst)?;
        discard(
            inst,
            &format!("fmi2GetStringStatus: status kind {s}: no pending step"),
        )
    })
}
