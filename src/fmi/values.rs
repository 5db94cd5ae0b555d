//! The value exports: fmi2Get/Set{Real,Integer,Boolean,String}, the input and output
//! derivatives, and fmi2GetDirectionalDerivative (Model Exchange). Pointer arrays become
//! slices here; the model in [`crate::fmu::simulation`] checks what may be set or read. The
//! bodies are shared with FMI 3.0's exports ([`super::fmi3::values`]).

#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::FmiError;
use super::instance::*;
use super::state::{self, FmiState};
use super::types::*;
use crate::fmu::simulation::Phase;

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
        // SAFETY: the caller's contract, passed on.
        unsafe { real_values(inst, vr, nvr, value) }
    })
}

/// The body of fmi2GetReal and fmi3GetFloat64: the step loop's call, one position the
/// method gives alone, is read on comparisons alone; anything else takes the general
/// path with its messages.
///
/// # Safety
/// `vr` holds `nvr` elements, `value` `nvr` writable ones, distinct from `vr`.
#[inline(always)]
pub(crate) unsafe fn real_values(
    inst: &mut Instance,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> Outcome {
    if nvr == 1 && !vr.is_null() && !value.is_null() {
        // SAFETY: `vr` is non-null and holds `nvr` = 1 element.
        let r = unsafe { *vr };
        if let Some(x) = inst.simulation.get_position(r) {
            // SAFETY: `value` is non-null and holds 1 writable element.
            unsafe { *value = x };
            return Ok(fmi2OK);
        }
    }
    // SAFETY: the caller's contract, passed on.
    unsafe { get_reals(inst, vr, nvr, value) }
}

/// fmi2GetReal's general path, out of line so that the one-position path stays small.
///
/// # Safety
/// `vr` holds `nvr` elements, `value` `nvr` writable ones, distinct from `vr`.
#[inline(never)]
unsafe fn get_reals(
    inst: &mut Instance,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> Outcome {
    // SAFETY: `vr` holds `nvr` value references (FMI contract).
    let vrs = unsafe { slice(vr, nvr, "vr") }?;
    // SAFETY: `value` holds `nvr` writable reals, distinct from `vr`.
    let out = unsafe { slice_mut(value, nvr, "value") }?;
    inst.simulation.get_reals(vrs, out)?;
    Ok(fmi2OK)
}

/// Get Integer variables (the parameter `method`).
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
        // SAFETY: the caller's contract, passed on.
        unsafe { integer_values(inst, vr, nvr, value) }
    })
}

/// The body of fmi2GetInteger and fmi3GetInt32.
///
/// # Safety
/// `vr` holds `nvr` elements, `value` `nvr` writable ones.
pub(crate) unsafe fn integer_values(
    inst: &mut Instance,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> Outcome {
    // SAFETY: `vr` holds `nvr` value references.
    let vrs = unsafe { slice(vr, nvr, "vr") }?;
    // SAFETY: `value` holds `nvr` writable integers.
    let out = unsafe { slice_mut(value, nvr, "value") }?;
    for (&r, o) in vrs.iter().zip(out.iter_mut()) {
        *o = inst.simulation.get_integer(r)?;
    }
    Ok(fmi2OK)
}

/// A get or set of a type this FMU has no variables of: fine for no value references,
/// refused naming the first otherwise.
pub(crate) fn no_variables(kind: &'static str, vrs: &[fmi2ValueReference]) -> Outcome {
    match vrs.first() {
        None => Ok(fmi2OK),
        Some(&vr) => Err(FmiError::NoVariables { vr, kind }),
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
        // SAFETY: the caller's contract, passed on.
        unsafe { set_real_values(inst, vr, nvr, value) }
    })
}

/// The body of fmi2SetReal and fmi3SetFloat64: the step loop's call, one load, is
/// stored on comparisons alone; anything else (several values, a parameter, a value to
/// refuse) takes the general path with its messages.
///
/// # Safety
/// `vr` and `value` hold `nvr` elements.
#[inline(always)]
pub(crate) unsafe fn set_real_values(
    inst: &mut Instance,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> Outcome {
    if nvr == 1 && !vr.is_null() && !value.is_null() {
        // SAFETY: both are non-null and hold `nvr` = 1 element.
        let (r, v) = unsafe { (*vr, *value) };
        if inst.simulation.set_load(r, v) {
            return Ok(fmi2OK);
        }
    }
    // SAFETY: the caller's contract, passed on.
    unsafe { set_reals(inst, vr, nvr, value) }
}

/// fmi2SetReal's general path, out of line so that the one-load path stays small.
///
/// # Safety
/// `vr` and `value` hold `nvr` elements.
#[inline(never)]
unsafe fn set_reals(
    inst: &mut Instance,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> Outcome {
    // SAFETY: `vr` holds `nvr` value references.
    let vrs = unsafe { slice(vr, nvr, "vr") }?;
    // SAFETY: `value` holds `nvr` reals.
    let vals = unsafe { slice(value, nvr, "value") }?;
    inst.simulation.set_reals(vrs, vals, phase(inst.state))?;
    Ok(fmi2OK)
}

/// Set Integer variables (the parameter `method`).
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
        // SAFETY: the caller's contract, passed on.
        unsafe { set_integer_values(inst, vr, nvr, value) }
    })
}

/// The body of fmi2SetInteger and fmi3SetInt32.
///
/// # Safety
/// `vr` and `value` hold `nvr` elements.
pub(crate) unsafe fn set_integer_values(
    inst: &mut Instance,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> Outcome {
    // SAFETY: `vr` holds `nvr` value references.
    let vrs = unsafe { slice(vr, nvr, "vr") }?;
    // SAFETY: `value` holds `nvr` integers.
    let vals = unsafe { slice(value, nvr, "value") }?;
    inst.simulation.set_integers(vrs, vals, phase(inst.state))?;
    Ok(fmi2OK)
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

/// The directional derivative of state derivatives with respect to states and load
/// inputs: exact for a blocked body, a central difference of a free body's
/// accelerations with its kinematic rows exact (Model Exchange instances; co-simulation
/// declares
/// providesDirectionalDerivative="false" and is refused).
///
/// # Safety
/// `c` is an instance; the arrays hold `nUnknown` and `nKnown` elements.
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
    enter(
        c,
        "fmi2GetDirectionalDerivative",
        state::GET_DIRECTIONAL_DERIVATIVE,
        |inst| {
            // SAFETY: the caller's contract, passed on.
            unsafe {
                super::model_exchange::directional_derivative(
                    inst,
                    (vUnknown_ref, nUnknown),
                    (vKnown_ref, nKnown),
                    dvKnown,
                    dvUnknown,
                )
            }
        },
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
            super::exports::co_simulation_only(inst)?;
            // SAFETY: each array holds `nvr` elements (FMI contract).
            let (vrs, ords, vals) = unsafe {
                (
                    slice(vr, nvr, "vr")?,
                    slice(order, nvr, "order")?,
                    slice(value, nvr, "value")?,
                )
            };
            inst.simulation.set_input_rates(vrs, ords, vals)?;
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
        // SAFETY: the caller's contract, passed on.
        |inst| unsafe { output_derivatives(inst, vr, nvr, order, value) },
    )
}

/// The body of fmi2GetRealOutputDerivatives and fmi3GetOutputDerivatives.
///
/// # Safety
/// `vr`, `order` and `value` hold `nvr` elements; `value` is writable and distinct.
pub(crate) unsafe fn output_derivatives(
    inst: &mut Instance,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *mut fmi2Real,
) -> Outcome {
    super::exports::co_simulation_only(inst)?;
    // SAFETY: each array holds `nvr` elements; `value` is writable and distinct.
    let (vrs, ords, out) = unsafe {
        (
            slice(vr, nvr, "vr")?,
            slice(order, nvr, "order")?,
            slice_mut(value, nvr, "value")?,
        )
    };
    for ((&r, &o), v) in vrs.iter().zip(ords).zip(out.iter_mut()) {
        *v = inst.simulation.get_output_derivative(r, o)?;
    }
    Ok(fmi2OK)
}
