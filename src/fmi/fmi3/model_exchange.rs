//! FMI 3.0's Model Exchange functions, over the FMI 2.0 layer's bodies
//! ([`crate::fmi::model_exchange`]): the same instance, gate and model; FMI 3.0's state
//! masks (`super::state`) and argument conventions. A Model Exchange function called on
//! a co-simulation instance is refused with a logged reason.

#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::types::*;
use super::{V3, state};
use crate::fmi::instance::{Outcome, enter_as};
use crate::fmi::model_exchange::{
    Read, completed_integrator_step, enter_mode, event_indicators, model_exchange_only, read,
    set_states, set_time,
};
use crate::fmi::state::FmiState;
use crate::fmi::types::fmi2OK;

/// One FMI 3.0 Model Exchange export: the gate with FMI 3.0's version and `mask`.
fn me3(
    instance: fmi3Instance,
    func: &str,
    mask: u16,
    body: impl FnOnce(&mut crate::fmi::instance::Instance) -> Outcome,
) -> fmi3Status {
    enter_as(instance, V3, func, mask, body)
}

/// Into Continuous-Time Mode.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterContinuousTimeMode(instance: fmi3Instance) -> fmi3Status {
    me3(
        instance,
        "fmi3EnterContinuousTimeMode",
        state::ENTER_CONTINUOUS_TIME_MODE,
        |inst| enter_mode(inst, FmiState::ContinuousTimeMode),
    )
}

/// A completed integrator step: an event asked for when a free body's quaternion must be
/// normalised (in the event update), never a termination.
///
/// # Safety
/// `instance` is an instance; the two flags are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3CompletedIntegratorStep(
    instance: fmi3Instance,
    noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
    enterEventMode: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
) -> fmi3Status {
    let _ = noSetFMUStatePriorToCurrentPoint; // not needed by this FMU
    me3(
        instance,
        "fmi3CompletedIntegratorStep",
        state::COMPLETED_INTEGRATOR_STEP,
        |inst| {
            // fmi3Boolean is a C bool: written as such, not as FMI 2.0's int.
            let (mut e, mut t) = (0i32, 0i32);
            // SAFETY: two local ints.
            unsafe { completed_integrator_step(inst, &mut e, &mut t) }?;
            for (p, v) in [(enterEventMode, e), (terminateSimulation, t)] {
                if !p.is_null() {
                    // SAFETY: non-null and writable (FMI contract).
                    unsafe { *p = v != 0 };
                }
            }
            Ok(fmi2OK)
        },
    )
}

/// Set the time.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetTime(instance: fmi3Instance, time: fmi3Float64) -> fmi3Status {
    me3(instance, "fmi3SetTime", state::SET_TIME, |inst| {
        set_time(inst, time)
    })
}

/// Set the continuous states.
///
/// # Safety
/// `instance` is an instance; `continuousStates` holds `nContinuousStates` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetContinuousStates(
    instance: fmi3Instance,
    continuousStates: *const fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    me3(
        instance,
        "fmi3SetContinuousStates",
        state::SET_CONTINUOUS_STATES,
        // SAFETY: the caller's contract, passed on.
        |inst| unsafe { set_states(inst, continuousStates, nContinuousStates) },
    )
}

/// The state derivatives.
///
/// # Safety
/// `instance` is an instance; `derivatives` holds `nContinuousStates` writable values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetContinuousStateDerivatives(
    instance: fmi3Instance,
    derivatives: *mut fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    me3(
        instance,
        "fmi3GetContinuousStateDerivatives",
        state::GET_CONTINUOUS,
        // SAFETY: the caller's contract, passed on.
        |inst| unsafe { read(inst, Read::Derivatives, derivatives, nContinuousStates) },
    )
}

/// No event indicators (`nEventIndicators` must be 0).
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetEventIndicators(
    instance: fmi3Instance,
    eventIndicators: *mut fmi3Float64,
    nEventIndicators: usize,
) -> fmi3Status {
    let _ = eventIndicators; // none to write
    me3(
        instance,
        "fmi3GetEventIndicators",
        state::GET_CONTINUOUS,
        |inst| event_indicators(inst, nEventIndicators),
    )
}

/// The continuous states.
///
/// # Safety
/// `instance` is an instance; `continuousStates` holds `nContinuousStates` writable
/// values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetContinuousStates(
    instance: fmi3Instance,
    continuousStates: *mut fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    me3(
        instance,
        "fmi3GetContinuousStates",
        state::GET_CONTINUOUS,
        // SAFETY: the caller's contract, passed on.
        |inst| unsafe { read(inst, Read::States, continuousStates, nContinuousStates) },
    )
}

/// The states' nominal magnitudes.
///
/// # Safety
/// `instance` is an instance; `nominals` holds `nContinuousStates` writable values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetNominalsOfContinuousStates(
    instance: fmi3Instance,
    nominals: *mut fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    me3(
        instance,
        "fmi3GetNominalsOfContinuousStates",
        state::GET_CONTINUOUS,
        // SAFETY: the caller's contract, passed on.
        |inst| unsafe { read(inst, Read::Nominals, nominals, nContinuousStates) },
    )
}

/// The number of event indicators: 0.
///
/// # Safety
/// `instance` is an instance; `nEventIndicators` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetNumberOfEventIndicators(
    instance: fmi3Instance,
    nEventIndicators: *mut usize,
) -> fmi3Status {
    me3(
        instance,
        "fmi3GetNumberOfEventIndicators",
        state::GET_NUMBER_OF,
        // SAFETY: the caller's contract, passed on.
        |inst| unsafe { write_count(inst, nEventIndicators, |_| Ok(0)) },
    )
}

/// The number of continuous states.
///
/// # Safety
/// `instance` is an instance; `nContinuousStates` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetNumberOfContinuousStates(
    instance: fmi3Instance,
    nContinuousStates: *mut usize,
) -> fmi3Status {
    me3(
        instance,
        "fmi3GetNumberOfContinuousStates",
        state::GET_NUMBER_OF,
        // SAFETY: the caller's contract, passed on.
        |inst| unsafe {
            write_count(inst, nContinuousStates, |i| {
                Ok(i.simulation.state_count()?)
            })
        },
    )
}

/// Write a count of a Model Exchange instance to `out`.
///
/// # Safety
/// `out` is NULL (refused) or writable.
unsafe fn write_count(
    inst: &mut crate::fmi::instance::Instance,
    out: *mut usize,
    count: impl FnOnce(&mut crate::fmi::instance::Instance) -> Result<usize, crate::fmi::FmiError>,
) -> Outcome {
    model_exchange_only(inst)?;
    if out.is_null() {
        return Err(crate::fmi::FmiError::Null("the count pointer"));
    }
    let n = count(inst)?;
    // SAFETY: non-null and writable (FMI contract).
    unsafe { *out = n };
    Ok(fmi2OK)
}
