//! FMI 3.0's life cycle: version, logging, the three instantiation functions (only
//! co-simulation is provided), free, initialisation, event and step modes,
//! configuration mode, terminate, reset and fmi3DoStep. The bodies are the FMI 2.0
//! layer's ([`crate::fmi::exports`]); what is FMI 3.0's own is here: the resource path,
//! the instantiation flags, the start and stop time given to
//! fmi3EnterInitializationMode, and fmi3DoStep's output arguments.

#![allow(non_snake_case, clippy::missing_safety_doc)]

use std::ffi::c_char;
use std::path::PathBuf;

use super::state;
use super::types::*;
use super::{V3, refuse};
use crate::fmi::FmiError;
use crate::fmi::exports::{
    do_step, enter_initialization, exit_initialization, reset, set_debug_logging,
};
use crate::fmi::instance::*;
use crate::fmi::instantiate::{free_instance, instantiate};
use crate::fmi::state::FmiState;
use crate::fmi::uri::resource_path;
use crate::fmi::version::Interface;

/// "3.0".
#[unsafe(no_mangle)]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

/// Switch log categories: all (nCategories = 0) or the named ones, on or off.
///
/// # Safety
/// `instance` is an instance from fmi3InstantiateCoSimulation; `categories` holds
/// `nCategories` strings.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    instance: fmi3Instance,
    loggingOn: fmi3Boolean,
    nCategories: usize,
    categories: *const fmi3String,
) -> fmi3Status {
    enter_as(
        instance,
        V3,
        "fmi3SetDebugLogging",
        state::SET_DEBUG_LOGGING,
        |inst| {
            // SAFETY: the caller's contract, passed on.
            unsafe { set_debug_logging(inst, loggingOn, nCategories, categories) }
        },
    )
}

/// The resources folder from FMI 3.0's `resourcePath`: an absolute path (with or
/// without the trailing separator FMI 3.0 prescribes); a `file:` URI, as FMI 2.0 and the
/// drafts of FMI 3.0 passed it, is decoded as such, since no absolute path starts so.
fn resource_dir(path: &str) -> Result<PathBuf, FmiError> {
    if path.starts_with("file:") {
        return Ok(resource_path(path)?);
    }
    let dir = PathBuf::from(path);
    if dir.is_absolute() {
        Ok(dir)
    } else {
        Err(FmiError::RelativeResourcePath(path.to_string()))
    }
}

/// Create a co-simulation instance: copy the arguments, read the body and scene from
/// the resources folder, check the instantiation token (the model description's GUID).
/// Event mode and intermediate variables are refused (hasEventMode and
/// providesIntermediateUpdate are "false"); earlyReturnAllowed is accepted, and
/// fmi3DoStep never returns early. NULL (with a logged reason, if loggingOn) on any
/// failure.
///
/// # Safety
/// String arguments are NULL or NUL-terminated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    resourcePath: fmi3String,
    visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    eventModeUsed: fmi3Boolean,
    earlyReturnAllowed: fmi3Boolean,
    requiredIntermediateVariables: *const fmi3ValueReference,
    nRequiredIntermediateVariables: usize,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
    intermediateUpdate: fmi3IntermediateUpdateCallback,
) -> fmi3Instance {
    // Not needed by this FMU: no window, never an early return, no intermediate update.
    let _ = (
        visible,
        earlyReturnAllowed,
        requiredIntermediateVariables,
        intermediateUpdate,
    );
    // SAFETY: NUL-terminated or NULL (FMI contract); copied now.
    let (name, token, path) = unsafe {
        (
            text_arg(instanceName),
            text_arg(instantiationToken),
            text_arg(resourcePath),
        )
    };
    instantiate(
        "fmi3InstantiateCoSimulation",
        V3,
        name,
        |n| Log::new3(instanceEnvironment, logMessage, n, loggingOn),
        || {
            if eventModeUsed {
                return Err(FmiError::NotProvided(
                    "eventModeUsed is true, but this FMU has no event mode \
                     (hasEventMode=\"false\"): instantiate with eventModeUsed = false",
                ));
            }
            if nRequiredIntermediateVariables > 0 {
                return Err(FmiError::NotProvided(
                    "requiredIntermediateVariables is not empty, but this FMU provides no \
                     intermediate update (providesIntermediateUpdate=\"false\")",
                ));
            }
            token_and_dir(Interface::CoSimulation, token, path)
        },
    )
}

/// The interface, the instantiation token and the resources folder of an FMI 3.0
/// instantiation's arguments.
fn token_and_dir(
    interface: Interface,
    token: Option<String>,
    path: Option<String>,
) -> Result<(Interface, String, PathBuf), FmiError> {
    let token = token.ok_or(FmiError::Null("instantiationToken"))?;
    let path = path.ok_or(FmiError::NoResourcePath)?;
    Ok((interface, token, resource_dir(&path)?))
}

/// Create a Model Exchange instance (an FMU packed with `--interface me` or `both`):
/// the arguments copied, the body and scene read from the resources folder, the
/// instantiation token checked. NULL (with a logged reason, if loggingOn) on any
/// failure, an FMU packed for co-simulation only among them.
///
/// # Safety
/// String arguments are NULL or NUL-terminated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    resourcePath: fmi3String,
    visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
) -> fmi3Instance {
    let _ = visible; // not needed by this FMU
    // SAFETY: NUL-terminated or NULL (FMI contract); copied now.
    let (name, token, path) = unsafe {
        (
            text_arg(instanceName),
            text_arg(instantiationToken),
            text_arg(resourcePath),
        )
    };
    instantiate(
        "fmi3InstantiateModelExchange",
        V3,
        name,
        |n| Log::new3(instanceEnvironment, logMessage, n, loggingOn),
        || token_and_dir(Interface::ModelExchange, token, path),
    )
}

/// An instantiation function of an interface this FMU does not provide: NULL after
/// logging `why` through `log` (environment, logMessage, loggingOn).
///
/// # Safety
/// `instance_name` is NULL or NUL-terminated.
unsafe fn not_provided(
    func: &str,
    instance_name: fmi3String,
    log: (fmi3InstanceEnvironment, fmi3LogMessageCallback, bool),
    why: &'static str,
) -> fmi3Instance {
    // SAFETY: NUL-terminated or NULL (FMI contract).
    let name = unsafe { text_arg(instance_name) };
    instantiate(
        func,
        V3,
        name,
        |n| Log::new3(log.0, log.1, n, log.2),
        || Err(FmiError::NotProvided(why)),
    )
}

/// Not provided (no `<ScheduledExecution>` element): NULL with a logged reason.
///
/// # Safety
/// String arguments are NULL or NUL-terminated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    resourcePath: fmi3String,
    visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
    clockUpdate: fmi3ClockUpdateCallback,
    lockPreemption: fmi3LockPreemptionCallback,
    unlockPreemption: fmi3UnlockPreemptionCallback,
) -> fmi3Instance {
    // Not needed: refused.
    let _ = (
        instantiationToken,
        resourcePath,
        visible,
        clockUpdate,
        lockPreemption,
        unlockPreemption,
    );
    // SAFETY: the caller's contract, passed on.
    unsafe {
        not_provided(
            "fmi3InstantiateScheduledExecution",
            instanceName,
            (instanceEnvironment, logMessage, loggingOn),
            "this FMU provides co-simulation only (its model description has no \
             <ScheduledExecution> element): use fmi3InstantiateCoSimulation",
        )
    }
}

/// Free an instance (NULL is ignored).
///
/// # Safety
/// `instance` is NULL or an instance not yet freed.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeInstance(instance: fmi3Instance) {
    // SAFETY: the caller's contract, passed on.
    unsafe { free_instance(instance) }
}

/// Record start and stop time (tolerance is not used: every method is fixed-step) and
/// enter initialisation mode: the solver is built with the parameters set so far.
///
/// # Safety
/// `instance` is an instance from fmi3InstantiateCoSimulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    instance: fmi3Instance,
    toleranceDefined: fmi3Boolean,
    tolerance: fmi3Float64,
    startTime: fmi3Float64,
    stopTimeDefined: fmi3Boolean,
    stopTime: fmi3Float64,
) -> fmi3Status {
    let _ = (toleranceDefined, tolerance); // not needed by this FMU
    enter_as(
        instance,
        V3,
        "fmi3EnterInitializationMode",
        state::ENTER_INITIALIZATION_MODE,
        |inst| {
            inst.simulation
                .setup(startTime, stopTimeDefined.then_some(stopTime))?;
            enter_initialization(inst)
        },
    )
}

/// Leave initialisation mode into Step Mode (rebuilding the solver if a parameter
/// changed).
///
/// # Safety
/// `instance` is an instance from fmi3InstantiateCoSimulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: fmi3Instance) -> fmi3Status {
    enter_as(
        instance,
        V3,
        "fmi3ExitInitializationMode",
        state::EXIT_INITIALIZATION_MODE,
        exit_initialization,
    )
}

/// Into Event Mode: Model Exchange instances (from Continuous-Time Mode); a
/// co-simulation instance has no event mode (hasEventMode="false") and is refused.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterEventMode(instance: fmi3Instance) -> fmi3Status {
    enter_as(
        instance,
        V3,
        "fmi3EnterEventMode",
        state::ENTER_EVENT_MODE,
        |inst| match inst.interface {
            Interface::ModelExchange => {
                crate::fmi::model_exchange::enter_mode(inst, FmiState::EventMode)
            }
            Interface::CoSimulation => Err(FmiError::NotProvided(
                "this FMU has no event mode in co-simulation (hasEventMode=\"false\")",
            )),
        },
    )
}

/// Event Mode is never entered (hasEventMode="false"), so there is no Step Mode to
/// enter from it: refused in every state.
///
/// # Safety
/// `instance` is an instance from fmi3InstantiateCoSimulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterStepMode(instance: fmi3Instance) -> fmi3Status {
    refuse(
        instance,
        "fmi3EnterStepMode",
        state::ENTER_STEP_MODE,
        "this FMU has no event mode (hasEventMode=\"false\")",
    )
}

/// Not provided (no structural parameters): logs why, returns fmi3Error.
///
/// # Safety
/// `instance` is an instance from fmi3InstantiateCoSimulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterConfigurationMode(instance: fmi3Instance) -> fmi3Status {
    refuse(
        instance,
        "fmi3EnterConfigurationMode",
        state::ENTER_CONFIGURATION_MODE,
        "this FMU has no structural parameters",
    )
}

/// Configuration Mode is never entered: refused in every state.
///
/// # Safety
/// `instance` is an instance from fmi3InstantiateCoSimulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3ExitConfigurationMode(instance: fmi3Instance) -> fmi3Status {
    refuse(
        instance,
        "fmi3ExitConfigurationMode",
        state::EXIT_CONFIGURATION_MODE,
        "this FMU has no structural parameters",
    )
}

/// End the simulation.
///
/// # Safety
/// `instance` is an instance from fmi3InstantiateCoSimulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Terminate(instance: fmi3Instance) -> fmi3Status {
    enter_as(instance, V3, "fmi3Terminate", state::TERMINATE, |inst| {
        inst.state = FmiState::Terminated;
        Ok(fmi3OK)
    })
}

/// Back to the instantiated state with start values.
///
/// # Safety
/// `instance` is an instance from fmi3InstantiateCoSimulation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Reset(instance: fmi3Instance) -> fmi3Status {
    enter_as(instance, V3, "fmi3Reset", state::RESET, reset)
}

/// Advance from `currentCommunicationPoint` by `communicationStepSize`, always to the
/// end (no early return, no events): `eventHandlingNeeded`, `terminateSimulation` and
/// `earlyReturn` are false, `lastSuccessfulTime` the end of the step. The output
/// arguments are checked before the step; a NULL one refuses the call.
///
/// # Safety
/// `instance` is an instance from fmi3InstantiateCoSimulation; the four output
/// arguments are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3DoStep(
    instance: fmi3Instance,
    currentCommunicationPoint: fmi3Float64,
    communicationStepSize: fmi3Float64,
    noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
    eventHandlingNeeded: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
    earlyReturn: *mut fmi3Boolean,
    lastSuccessfulTime: *mut fmi3Float64,
) -> fmi3Status {
    let _ = noSetFMUStatePriorToCurrentPoint; // not needed by this FMU
    enter_as(instance, V3, "fmi3DoStep", state::DO_STEP, |inst| {
        for (null, what) in [
            (eventHandlingNeeded.is_null(), "eventHandlingNeeded"),
            (terminateSimulation.is_null(), "terminateSimulation"),
            (earlyReturn.is_null(), "earlyReturn"),
            (lastSuccessfulTime.is_null(), "lastSuccessfulTime"),
        ] {
            if null {
                return Err(FmiError::Null(what));
            }
        }
        let status = do_step(
            inst,
            "fmi3DoStep",
            currentCommunicationPoint,
            communicationStepSize,
        )?;
        // SAFETY: all four are non-null (checked above) and writable (FMI contract).
        unsafe {
            *eventHandlingNeeded = false;
            *terminateSimulation = false;
            *earlyReturn = false;
            *lastSuccessfulTime = inst.simulation.time();
        }
        Ok(status)
    })
}
