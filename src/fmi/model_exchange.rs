//! FMI 2.0 Model Exchange: the exports a master's integrator calls (time, continuous
//! states, derivatives, nominals, no event indicators, the event and continuous-time
//! modes, completed integrator steps) and their bodies, which FMI 3.0's exports
//! ([`super::fmi3::model_exchange`]) share. Every call goes through the same gate as
//! co-simulation (`super::instance::enter`): the state masks of `super::state`
//! refuse a call in a wrong state with a logged reason, and a Model Exchange function
//! on a co-simulation instance is refused likewise. The model behind is
//! [`crate::fmu::simulation::Simulation`]'s first-order form: outputs read in Model
//! Exchange come from the co-simulation output code.

#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::FmiError;
use super::instance::*;
use super::state::{self, FmiState};
use super::types::*;
use super::version::Interface;
use crate::solver::SolverError;

/// The event information fmi2NewDiscreteStates fills.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct fmi2EventInfo {
    /// Another event iteration is needed.
    pub newDiscreteStatesNeeded: fmi2Boolean,
    /// The FMU asks to stop.
    pub terminateSimulation: fmi2Boolean,
    /// The states' nominals changed.
    pub nominalsOfContinuousStatesChanged: fmi2Boolean,
    /// The states changed.
    pub valuesOfContinuousStatesChanged: fmi2Boolean,
    /// `nextEventTime` holds a time event.
    pub nextEventTimeDefined: fmi2Boolean,
    /// The next time event.
    pub nextEventTime: fmi2Real,
}

/// Refuse a Model Exchange function on a co-simulation instance.
pub(crate) fn model_exchange_only(inst: &Instance) -> Result<(), FmiError> {
    super::exports::only_for(inst, Interface::ModelExchange)
}

/// The body of fmi2SetTime and fmi3SetTime.
pub(crate) fn set_time(inst: &mut Instance, t: f64) -> Outcome {
    model_exchange_only(inst)?;
    inst.simulation.set_time(t)?;
    Ok(fmi2OK)
}

/// The body of fmi2SetContinuousStates and fmi3SetContinuousStates.
///
/// # Safety
/// `x` is NULL (refused for `n > 0`) or holds `n` values.
pub(crate) unsafe fn set_states(inst: &mut Instance, x: *const f64, n: usize) -> Outcome {
    model_exchange_only(inst)?;
    // SAFETY: the caller's contract.
    let x = unsafe { slice(x, n, "continuous states") }?;
    inst.simulation.set_states(x)?;
    Ok(fmi2OK)
}

/// What a per-state read fills: states, derivatives or nominals.
#[derive(Clone, Copy)]
pub(crate) enum Read {
    /// fmi2GetContinuousStates.
    States,
    /// fmi2GetDerivatives.
    Derivatives,
    /// fmi2GetNominalsOfContinuousStates.
    Nominals,
}

/// The body of the per-state reads of both versions.
///
/// # Safety
/// `out` is NULL (refused for `n > 0`) or holds `n` writable values.
pub(crate) unsafe fn read(inst: &mut Instance, what: Read, out: *mut f64, n: usize) -> Outcome {
    model_exchange_only(inst)?;
    // SAFETY: the caller's contract.
    let out = unsafe { slice_mut(out, n, "continuous-state array") }?;
    let m = &mut inst.simulation;
    match what {
        Read::States => m.states(out)?,
        Read::Derivatives => m.derivatives(out)?,
        Read::Nominals => m.nominals(out)?,
    }
    Ok(fmi2OK)
}

/// The body of fmi2GetEventIndicators and fmi3GetEventIndicators: the body has no
/// events, so no indicators (`n` must be 0).
pub(crate) fn event_indicators(inst: &mut Instance, n: usize) -> Outcome {
    model_exchange_only(inst)?;
    if n != 0 {
        return Err(
            crate::fmu::simulation::SimulationError::from(SolverError::BadLength {
                what: "event indicators (this FMU has none: numberOfEventIndicators 0)",
                expected: 0,
                found: n,
            })
            .into(),
        );
    }
    Ok(fmi2OK)
}

/// Into `to` (Event or Continuous-Time Mode), for a Model Exchange instance.
pub(crate) fn enter_mode(inst: &mut Instance, to: FmiState) -> Outcome {
    model_exchange_only(inst)?;
    inst.state = to;
    Ok(fmi2OK)
}

/// The body of fmi2CompletedIntegratorStep and fmi3CompletedIntegratorStep: when the
/// method would put its states back on their manifold (a free body's quaternion drifted
/// from norm 1; never for a blocked body) it asks for an event, leaving the states as
/// they are: FMI lets the model change continuous states in Event Mode only, so it
/// normalises them in fmi2NewDiscreteStates / fmi3UpdateDiscreteStates
/// ([`discrete_update`]), which reports `valuesOfContinuousStatesChanged`. Never a
/// termination.
///
/// # Safety
/// `enter_event_mode` and `terminate` are NULL (then not written) or writable.
pub(crate) unsafe fn completed_integrator_step(
    inst: &mut Instance,
    enter_event_mode: *mut i32,
    terminate: *mut i32,
) -> Outcome {
    model_exchange_only(inst)?;
    let due = inst.simulation.completed_step_due()?;
    for (p, v) in [(enter_event_mode, due), (terminate, false)] {
        if !p.is_null() {
            // SAFETY: non-null and writable (FMI contract).
            unsafe { *p = i32::from(v) };
        }
    }
    Ok(fmi2OK)
}

/// The event update of fmi2NewDiscreteStates and fmi3UpdateDiscreteStates: the body has
/// no discrete states; the method puts its continuous states back on their manifold (a
/// free body's quaternion normalised once it has drifted). `true` when it changed them
/// (`valuesOfContinuousStatesChanged`).
pub(crate) fn discrete_update(inst: &mut Instance) -> Result<bool, FmiError> {
    Ok(inst.simulation.completed_step()?)
}

/// The body of fmi2GetDirectionalDerivative and fmi3GetDirectionalDerivative (Model
/// Exchange instances: `J seed` of the state derivatives, exact for a blocked body, a
/// central difference of a free body's accelerations).
///
/// # Safety
/// The arrays are NULL (refused for a nonzero length) or hold their lengths' values.
pub(crate) unsafe fn directional_derivative(
    inst: &mut Instance,
    unknowns: (*const u32, usize),
    knowns: (*const u32, usize),
    seed: *const f64,
    sensitivity: *mut f64,
) -> Outcome {
    if inst.interface == Interface::CoSimulation {
        return Err(FmiError::NoDirectionalDerivative);
    }
    // SAFETY: the caller's contract, for each array.
    let (u, k, s, out) = unsafe {
        (
            slice(unknowns.0, unknowns.1, "unknowns")?,
            slice(knowns.0, knowns.1, "knowns")?,
            slice(seed, knowns.1, "seed")?,
            slice_mut(sensitivity, unknowns.1, "sensitivity")?,
        )
    };
    inst.simulation.directional_derivative(u, k, s, out)?;
    Ok(fmi2OK)
}

/// Into Event Mode.
///
/// # Safety
/// `c` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status {
    enter(c, "fmi2EnterEventMode", state::ENTER_EVENT_MODE, |inst| {
        enter_mode(inst, FmiState::EventMode)
    })
}

/// An event iteration: the body has no discrete states and no events, so none is
/// needed.
///
/// # Safety
/// `c` is an instance; `eventInfo` is writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2NewDiscreteStates(
    c: fmi2Component,
    eventInfo: *mut fmi2EventInfo,
) -> fmi2Status {
    enter(
        c,
        "fmi2NewDiscreteStates",
        state::NEW_DISCRETE_STATES,
        |inst| {
            model_exchange_only(inst)?;
            if eventInfo.is_null() {
                return Err(FmiError::Null("eventInfo"));
            }
            let changed = discrete_update(inst)?;
            // SAFETY: non-null and writable (FMI contract).
            unsafe {
                *eventInfo = fmi2EventInfo {
                    newDiscreteStatesNeeded: fmi2False,
                    terminateSimulation: fmi2False,
                    nominalsOfContinuousStatesChanged: fmi2False,
                    valuesOfContinuousStatesChanged: i32::from(changed),
                    nextEventTimeDefined: fmi2False,
                    nextEventTime: 0.0,
                }
            };
            Ok(fmi2OK)
        },
    )
}

/// Into Continuous-Time Mode.
///
/// # Safety
/// `c` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status {
    enter(
        c,
        "fmi2EnterContinuousTimeMode",
        state::ENTER_CONTINUOUS_TIME_MODE,
        |inst| enter_mode(inst, FmiState::ContinuousTimeMode),
    )
}

/// A completed integrator step: an event asked for when a free body's quaternion must be
/// normalised (in the event update), never a termination.
///
/// # Safety
/// `c` is an instance; the two flags are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CompletedIntegratorStep(
    c: fmi2Component,
    noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
    enterEventMode: *mut fmi2Boolean,
    terminateSimulation: *mut fmi2Boolean,
) -> fmi2Status {
    let _ = noSetFMUStatePriorToCurrentPoint; // not needed by this FMU
    enter(
        c,
        "fmi2CompletedIntegratorStep",
        state::COMPLETED_INTEGRATOR_STEP,
        // SAFETY: the caller's contract, passed on.
        |inst| unsafe { completed_integrator_step(inst, enterEventMode, terminateSimulation) },
    )
}

/// Set the time.
///
/// # Safety
/// `c` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetTime(c: fmi2Component, time: fmi2Real) -> fmi2Status {
    enter(c, "fmi2SetTime", state::SET_TIME, |inst| {
        set_time(inst, time)
    })
}

/// Set the continuous states.
///
/// # Safety
/// `c` is an instance; `x` holds `nx` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetContinuousStates(
    c: fmi2Component,
    x: *const fmi2Real,
    nx: usize,
) -> fmi2Status {
    enter(
        c,
        "fmi2SetContinuousStates",
        state::SET_CONTINUOUS_STATES,
        // SAFETY: the caller's contract, passed on.
        |inst| unsafe { set_states(inst, x, nx) },
    )
}

/// The state derivatives.
///
/// # Safety
/// `c` is an instance; `derivatives` holds `nx` writable values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetDerivatives(
    c: fmi2Component,
    derivatives: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    enter(c, "fmi2GetDerivatives", state::GET_CONTINUOUS, |inst| {
        // SAFETY: the caller's contract, passed on.
        unsafe { read(inst, Read::Derivatives, derivatives, nx) }
    })
}

/// No event indicators (`ni` must be 0).
///
/// # Safety
/// `c` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetEventIndicators(
    c: fmi2Component,
    eventIndicators: *mut fmi2Real,
    ni: usize,
) -> fmi2Status {
    let _ = eventIndicators; // none to write
    enter(c, "fmi2GetEventIndicators", state::GET_CONTINUOUS, |inst| {
        event_indicators(inst, ni)
    })
}

/// The continuous states.
///
/// # Safety
/// `c` is an instance; `x` holds `nx` writable values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetContinuousStates(
    c: fmi2Component,
    x: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    enter(
        c,
        "fmi2GetContinuousStates",
        state::GET_CONTINUOUS,
        |inst| {
            // SAFETY: the caller's contract, passed on.
            unsafe { read(inst, Read::States, x, nx) }
        },
    )
}

/// The states' nominal magnitudes.
///
/// # Safety
/// `c` is an instance; `x_nominal` holds `nx` writable values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetNominalsOfContinuousStates(
    c: fmi2Component,
    x_nominal: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    enter(
        c,
        "fmi2GetNominalsOfContinuousStates",
        state::GET_NOMINALS,
        // SAFETY: the caller's contract, passed on.
        |inst| unsafe { read(inst, Read::Nominals, x_nominal, nx) },
    )
}
