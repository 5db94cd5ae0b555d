//! FMI 3.0's clock, interval, shift and discrete-state functions and Scheduled
//! Execution's fmi3ActivateModelPartition. This FMU has no clocks and no event mode:
//! each is refused with a logged reason, in the states where the standard allows it
//! (and as an illegal call elsewhere). The interval and shift functions take arrays of
//! clocks: with no value reference they are fine, as the typed getters of types
//! without variables are ([`super::other_types`]).

#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::types::*;
use super::{V3, refuse, state};
use crate::fmi::FmiError;
use crate::fmi::instance::*;
use crate::fmi::values::no_variables;
use crate::fmi::version::Interface;

/// A function over an array of clocks: fine for none, refused naming the first.
///
/// # Safety
/// `vr` holds `n` value references.
unsafe fn clocks(instance: fmi3Instance, func: &str, vr: *const u32, n: usize) -> fmi3Status {
    enter_as(instance, V3, func, state::CLOCKS, |_| {
        // SAFETY: `vr` holds `n` value references (the caller's contract).
        no_variables("Clock", unsafe { slice(vr, n, "valueReferences") }?)
    })
}

/// The reason the discrete-state functions give.
const NO_EVENT_MODE: &str = "this FMU has no clocks and no event mode (hasEventMode=\"false\")";

/// No clocks: fmi3OK for no value reference, refused otherwise.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetIntervalDecimal(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    intervals: *mut fmi3Float64,
    qualifiers: *mut fmi3IntervalQualifier,
) -> fmi3Status {
    let _ = (intervals, qualifiers); // no clocks
    // SAFETY: the caller's contract, passed on.
    unsafe {
        clocks(
            instance,
            "fmi3GetIntervalDecimal",
            valueReferences,
            nValueReferences,
        )
    }
}

/// No clocks: fmi3OK for no value reference, refused otherwise.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetIntervalFraction(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    counters: *mut fmi3UInt64,
    resolutions: *mut fmi3UInt64,
    qualifiers: *mut fmi3IntervalQualifier,
) -> fmi3Status {
    let _ = (counters, resolutions, qualifiers); // no clocks
    // SAFETY: the caller's contract, passed on.
    unsafe {
        clocks(
            instance,
            "fmi3GetIntervalFraction",
            valueReferences,
            nValueReferences,
        )
    }
}

/// No clocks: fmi3OK for no value reference, refused otherwise.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetShiftDecimal(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    shifts: *mut fmi3Float64,
) -> fmi3Status {
    let _ = shifts; // no clocks
    // SAFETY: the caller's contract, passed on.
    unsafe {
        clocks(
            instance,
            "fmi3GetShiftDecimal",
            valueReferences,
            nValueReferences,
        )
    }
}

/// No clocks: fmi3OK for no value reference, refused otherwise.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetShiftFraction(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    counters: *mut fmi3UInt64,
    resolutions: *mut fmi3UInt64,
) -> fmi3Status {
    let _ = (counters, resolutions); // no clocks
    // SAFETY: the caller's contract, passed on.
    unsafe {
        clocks(
            instance,
            "fmi3GetShiftFraction",
            valueReferences,
            nValueReferences,
        )
    }
}

/// No clocks: fmi3OK for no value reference, refused otherwise.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetIntervalDecimal(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    intervals: *const fmi3Float64,
) -> fmi3Status {
    let _ = intervals; // no clocks
    // SAFETY: the caller's contract, passed on.
    unsafe {
        clocks(
            instance,
            "fmi3SetIntervalDecimal",
            valueReferences,
            nValueReferences,
        )
    }
}

/// No clocks: fmi3OK for no value reference, refused otherwise.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetIntervalFraction(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    counters: *const fmi3UInt64,
    resolutions: *const fmi3UInt64,
) -> fmi3Status {
    let _ = (counters, resolutions); // no clocks
    // SAFETY: the caller's contract, passed on.
    unsafe {
        clocks(
            instance,
            "fmi3SetIntervalFraction",
            valueReferences,
            nValueReferences,
        )
    }
}

/// No clocks: fmi3OK for no value reference, refused otherwise.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetShiftDecimal(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    shifts: *const fmi3Float64,
) -> fmi3Status {
    let _ = shifts; // no clocks
    // SAFETY: the caller's contract, passed on.
    unsafe {
        clocks(
            instance,
            "fmi3SetShiftDecimal",
            valueReferences,
            nValueReferences,
        )
    }
}

/// No clocks: fmi3OK for no value reference, refused otherwise.
///
/// # Safety
/// `instance` is an instance; `valueReferences` holds `nValueReferences` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetShiftFraction(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    counters: *const fmi3UInt64,
    resolutions: *const fmi3UInt64,
) -> fmi3Status {
    let _ = (counters, resolutions); // no clocks
    // SAFETY: the caller's contract, passed on.
    unsafe {
        clocks(
            instance,
            "fmi3SetShiftFraction",
            valueReferences,
            nValueReferences,
        )
    }
}

/// Not provided (no clocks, no event mode): logs why, returns fmi3Error.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EvaluateDiscreteStates(instance: fmi3Instance) -> fmi3Status {
    refuse(
        instance,
        "fmi3EvaluateDiscreteStates",
        state::DISCRETE_STATES,
        NO_EVENT_MODE,
    )
}

/// An event iteration of a Model Exchange instance: no discrete states and no time
/// event; a free body's drifted quaternion is normalised (the continuous states'
/// values changed). A co-simulation instance has no event mode.
///
/// # Safety
/// `instance` is an instance; the output arguments are NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3UpdateDiscreteStates(
    instance: fmi3Instance,
    discreteStatesNeedUpdate: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
    nominalsOfContinuousStatesChanged: *mut fmi3Boolean,
    valuesOfContinuousStatesChanged: *mut fmi3Boolean,
    nextEventTimeDefined: *mut fmi3Boolean,
    nextEventTime: *mut fmi3Float64,
) -> fmi3Status {
    enter_as(
        instance,
        V3,
        "fmi3UpdateDiscreteStates",
        state::DISCRETE_STATES,
        |inst| {
            if inst.interface != Interface::ModelExchange {
                return Err(FmiError::NotProvided(NO_EVENT_MODE));
            }
            // A free body's quaternion normalised here (Event Mode), if it drifted.
            let changed = crate::fmi::model_exchange::discrete_update(inst)?;
            for (p, v) in [
                (discreteStatesNeedUpdate, false),
                (terminateSimulation, false),
                (nominalsOfContinuousStatesChanged, false),
                (valuesOfContinuousStatesChanged, changed),
                (nextEventTimeDefined, false),
            ] {
                if !p.is_null() {
                    // SAFETY: non-null and writable (FMI contract).
                    unsafe { *p = v };
                }
            }
            if !nextEventTime.is_null() {
                // SAFETY: as above.
                unsafe { *nextEventTime = 0.0 };
            }
            Ok(crate::fmi::types::fmi2OK)
        },
    )
}

/// Not provided (no Scheduled Execution): refused in every state.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3ActivateModelPartition(
    instance: fmi3Instance,
    clockReference: fmi3ValueReference,
    activationTime: fmi3Float64,
) -> fmi3Status {
    let _ = (clockReference, activationTime); // not needed: refused
    refuse(
        instance,
        "fmi3ActivateModelPartition",
        state::ACTIVATE_MODEL_PARTITION,
        "this FMU provides no Scheduled Execution",
    )
}
