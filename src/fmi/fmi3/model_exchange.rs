//! FMI 3.0's Model Exchange functions. This FMU provides co-simulation only (no
//! `<ModelExchange>` element, fmi3InstantiateModelExchange refuses), so each is an
//! illegal call outside the Model Exchange states a co-simulation instance never enters
//! (Event Mode, Continuous-Time Mode; `super::state` has their masks from the
//! standard) and, where the standard also allows it in a co-simulation state
//! (initialisation mode, Terminated, the counts), refused with a logged reason. Model
//! Exchange's bodies go here.

#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::types::*;
use super::{V3, state};
use crate::fmi::FmiError;
use crate::fmi::instance::enter_as;
use crate::fmi::version::Interface;

/// A Model Exchange function called on an instance: `func` judged by `mask`, then
/// refused, since every instance is a co-simulation one.
fn refused(instance: fmi3Instance, func: &str, mask: u16) -> fmi3Status {
    enter_as(instance, V3, func, mask, |inst| match inst.interface {
        Interface::CoSimulation => Err(FmiError::NotProvided(
            "a Model Exchange function, and this instance is a co-simulation one \
             (this FMU provides co-simulation only)",
        )),
    })
}

/// Model Exchange: not provided.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterContinuousTimeMode(instance: fmi3Instance) -> fmi3Status {
    refused(
        instance,
        "fmi3EnterContinuousTimeMode",
        state::ENTER_CONTINUOUS_TIME_MODE,
    )
}

/// Model Exchange: not provided.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3CompletedIntegratorStep(
    instance: fmi3Instance,
    noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
    enterEventMode: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
) -> fmi3Status {
    // Not needed: refused.
    let _ = (
        noSetFMUStatePriorToCurrentPoint,
        enterEventMode,
        terminateSimulation,
    );
    refused(
        instance,
        "fmi3CompletedIntegratorStep",
        state::COMPLETED_INTEGRATOR_STEP,
    )
}

/// Model Exchange: not provided.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetTime(instance: fmi3Instance, time: fmi3Float64) -> fmi3Status {
    let _ = time; // not needed: refused
    refused(instance, "fmi3SetTime", state::SET_TIME)
}

/// Model Exchange: not provided.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetContinuousStates(
    instance: fmi3Instance,
    continuousStates: *const fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    let _ = (continuousStates, nContinuousStates); // not needed: refused
    refused(
        instance,
        "fmi3SetContinuousStates",
        state::SET_CONTINUOUS_STATES,
    )
}

/// Model Exchange: not provided.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetContinuousStateDerivatives(
    instance: fmi3Instance,
    derivatives: *mut fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    let _ = (derivatives, nContinuousStates); // not needed: refused
    refused(
        instance,
        "fmi3GetContinuousStateDerivatives",
        state::GET_CONTINUOUS,
    )
}

/// Model Exchange: not provided.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetEventIndicators(
    instance: fmi3Instance,
    eventIndicators: *mut fmi3Float64,
    nEventIndicators: usize,
) -> fmi3Status {
    let _ = (eventIndicators, nEventIndicators); // not needed: refused
    refused(instance, "fmi3GetEventIndicators", state::GET_CONTINUOUS)
}

/// Model Exchange: not provided.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetContinuousStates(
    instance: fmi3Instance,
    continuousStates: *mut fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    let _ = (continuousStates, nContinuousStates); // not needed: refused
    refused(instance, "fmi3GetContinuousStates", state::GET_CONTINUOUS)
}

/// Model Exchange: not provided.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetNominalsOfContinuousStates(
    instance: fmi3Instance,
    nominals: *mut fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    let _ = (nominals, nContinuousStates); // not needed: refused
    refused(
        instance,
        "fmi3GetNominalsOfContinuousStates",
        state::GET_CONTINUOUS,
    )
}

/// Model Exchange: not provided.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetNumberOfEventIndicators(
    instance: fmi3Instance,
    nEventIndicators: *mut usize,
) -> fmi3Status {
    let _ = nEventIndicators; // not needed: refused
    refused(
        instance,
        "fmi3GetNumberOfEventIndicators",
        state::GET_NUMBER_OF,
    )
}

/// Model Exchange: not provided.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetNumberOfContinuousStates(
    instance: fmi3Instance,
    nContinuousStates: *mut usize,
) -> fmi3Status {
    let _ = nContinuousStates; // not needed: refused
    refused(
        instance,
        "fmi3GetNumberOfContinuousStates",
        state::GET_NUMBER_OF,
    )
}
