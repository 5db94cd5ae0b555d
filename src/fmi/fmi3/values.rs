//! FMI 3.0's value exports for the types this FMU has: fmi3Get/SetFloat64 (every Real
//! variable, and the independent variable `time`, read-only) and fmi3Get/SetInt32 (the
//! `method` parameter), fmi3GetOutputDerivatives, and the derivative and dependency
//! queries it does not provide. The bodies are FMI 2.0's ([`crate::fmi::values`]); FMI
//! 3.0's own conventions are checked here first: `nValues` (every variable is a scalar,
//! so it must equal the number of value references) and `time`, which the FMI 3.0 model
//! description declares after the FMI 2.0 variables. The types without variables are in
//! [`super::other_types`].

#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::state;
use super::types::*;
use super::{V3, names_time, refuse, scalars};
use crate::fmi::FmiError;
use crate::fmi::instance::*;
use crate::fmi::values::{
    integer_values, output_derivatives, real_values, set_integer_values, set_real_values,
};

/// Refuse value references that name `time` where it cannot go (`what` says why).
fn refuse_time(inst: &Instance, vrs: &[u32], what: &'static str) -> Result<(), FmiError> {
    match names_time(inst, vrs) {
        Some(vr) => Err(FmiError::TimeVariable { vr, what }),
        None => Ok(()),
    }
}

/// FMI 3.0's checks of a typed get or set other than fmi3GetFloat64: `nValues`, and no
/// `time` among the value references (`what` says why it cannot go there).
///
/// # Safety
/// `vr` holds `n_refs` value references.
unsafe fn no_time(
    inst: &Instance,
    vr: *const u32,
    n_refs: usize,
    n_values: usize,
    what: &'static str,
) -> Result<(), FmiError> {
    scalars(n_refs, n_values)?;
    // SAFETY: `vr` holds `n_refs` value references (the caller's contract).
    let vrs = unsafe { slice(vr, n_refs, "valueReferences") }?;
    refuse_time(inst, vrs, what)
}

/// Float64 values by value reference: outputs, parameters, inputs and `time`.
///
/// # Safety
/// `instance` is an instance from fmi3InstantiateCoSimulation; `valueReferences` holds
/// `nValueReferences` elements and `values` `nValues` writable ones.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    enter_as(instance, V3, "fmi3GetFloat64", state::GET, |inst| {
        scalars(nValueReferences, nValues)?;
        // SAFETY: `valueReferences` holds `nValueReferences` elements.
        let vrs = unsafe { slice(valueReferences, nValueReferences, "valueReferences") }?;
        if names_time(inst, vrs).is_some() {
            // SAFETY: `values` holds `nValues` writable elements, distinct from `vrs`.
            let out = unsafe { slice_mut(values, nValues, "values") }?;
            let t = inst.simulation.table.time_ref();
            for (&r, o) in vrs.iter().zip(out.iter_mut()) {
                if r == t {
                    *o = inst.simulation.time();
                } else {
                    inst.simulation.get_reals(&[r], std::slice::from_mut(o))?;
                }
            }
            return Ok(fmi3OK);
        }
        // SAFETY: the caller's contract, passed on.
        unsafe { real_values(inst, valueReferences, nValueReferences, values) }
    })
}

/// Set Float64 variables (parameters before initialisation ends, inputs at any time).
///
/// # Safety
/// `instance` is an instance from fmi3InstantiateCoSimulation; `valueReferences` holds
/// `nValueReferences` elements and `values` `nValues`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    enter_as(instance, V3, "fmi3SetFloat64", state::SET, |inst| {
        // SAFETY: `valueReferences` holds `nValueReferences` elements.
        unsafe {
            no_time(
                inst,
                valueReferences,
                nValueReferences,
                nValues,
                "only fmi3DoStep advances it, it cannot be set",
            )
        }?;
        // SAFETY: the caller's contract, passed on.
        unsafe { set_real_values(inst, valueReferences, nValueReferences, values) }
    })
}

/// Get Int32 variables (the parameter `method`).
///
/// # Safety
/// `instance` is an instance from fmi3InstantiateCoSimulation; `valueReferences` holds
/// `nValueReferences` elements and `values` `nValues` writable ones.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int32,
    nValues: usize,
) -> fmi3Status {
    enter_as(instance, V3, "fmi3GetInt32", state::GET, |inst| {
        // SAFETY: `valueReferences` holds `nValueReferences` elements.
        unsafe {
            no_time(
                inst,
                valueReferences,
                nValueReferences,
                nValues,
                "a Float64, read it with fmi3GetFloat64",
            )
        }?;
        // SAFETY: the caller's contract, passed on.
        unsafe { integer_values(inst, valueReferences, nValueReferences, values) }
    })
}

/// Set Int32 variables (the parameter `method`).
///
/// # Safety
/// `instance` is an instance from fmi3InstantiateCoSimulation; `valueReferences` holds
/// `nValueReferences` elements and `values` `nValues`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int32,
    nValues: usize,
) -> fmi3Status {
    enter_as(instance, V3, "fmi3SetInt32", state::SET, |inst| {
        // SAFETY: `valueReferences` holds `nValueReferences` elements.
        unsafe {
            no_time(
                inst,
                valueReferences,
                nValueReferences,
                nValues,
                "a Float64 that only fmi3DoStep advances",
            )
        }?;
        // SAFETY: the caller's contract, passed on.
        unsafe { set_integer_values(inst, valueReferences, nValueReferences, values) }
    })
}

/// Output time derivatives at the current time: node positions (orders 1, 2), node
/// velocities (order 1), and on blocked bodies rotations and angular velocities
/// likewise (maxOutputDerivativeOrder="2").
///
/// # Safety
/// `instance` is an instance; `valueReferences` and `orders` hold `nValueReferences`
/// elements, `values` `nValues` writable ones.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetOutputDerivatives(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    orders: *const fmi3Int32,
    values: *mut fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    enter_as(
        instance,
        V3,
        "fmi3GetOutputDerivatives",
        state::GET_OUTPUT_DERIVATIVES,
        |inst| {
            scalars(nValueReferences, nValues)?;
            // SAFETY: `valueReferences` holds `nValueReferences` elements.
            let vrs = unsafe { slice(valueReferences, nValueReferences, "valueReferences") }?;
            refuse_time(inst, vrs, "it is no output and has no output derivatives")?;
            // SAFETY: the caller's contract, passed on.
            unsafe { output_derivatives(inst, valueReferences, nValueReferences, orders, values) }
        },
    )
}

/// The directional derivative of state derivatives with respect to states and load
/// inputs: exact for a blocked body, a central difference of a free body's
/// accelerations with its kinematic rows exact (Model Exchange instances; co-simulation
/// declares
/// providesDirectionalDerivatives="false" and is refused). Every variable is a scalar:
/// nSeed is nKnowns and nSensitivity nUnknowns.
///
/// # Safety
/// `instance` is an instance; the arrays hold their lengths' elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetDirectionalDerivative(
    instance: fmi3Instance,
    unknowns: *const fmi3ValueReference,
    nUnknowns: usize,
    knowns: *const fmi3ValueReference,
    nKnowns: usize,
    seed: *const fmi3Float64,
    nSeed: usize,
    sensitivity: *mut fmi3Float64,
    nSensitivity: usize,
) -> fmi3Status {
    enter_as(
        instance,
        V3,
        "fmi3GetDirectionalDerivative",
        state::GET_DERIVATIVES,
        |inst| {
            scalars(nKnowns, nSeed)?;
            scalars(nUnknowns, nSensitivity)?;
            // SAFETY: the caller's contract, passed on.
            unsafe {
                crate::fmi::model_exchange::directional_derivative(
                    inst,
                    (unknowns, nUnknowns),
                    (knowns, nKnowns),
                    seed,
                    sensitivity,
                )
            }
        },
    )
}

/// Not provided (providesAdjointDerivatives="false"): logs why, returns fmi3Error.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetAdjointDerivative(
    instance: fmi3Instance,
    unknowns: *const fmi3ValueReference,
    nUnknowns: usize,
    knowns: *const fmi3ValueReference,
    nKnowns: usize,
    seed: *const fmi3Float64,
    nSeed: usize,
    sensitivity: *mut fmi3Float64,
    nSensitivity: usize,
) -> fmi3Status {
    // Not needed: refused.
    let _ = (
        unknowns,
        nUnknowns,
        knowns,
        nKnowns,
        seed,
        nSeed,
        sensitivity,
        nSensitivity,
    );
    refuse(
        instance,
        "fmi3GetAdjointDerivative",
        state::GET_DERIVATIVES,
        "not provided by this FMU (providesAdjointDerivatives=\"false\")",
    )
}

/// The reason both dependency queries give.
const NO_ELEMENT_DEPENDENCIES: &str = "not provided by this FMU \
    (providesPerElementDependencies=\"false\"): every variable is a scalar, and the \
    model description's ModelStructure lists the dependencies";

/// Not provided (providesPerElementDependencies="false"): logs why, returns fmi3Error.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetNumberOfVariableDependencies(
    instance: fmi3Instance,
    valueReference: fmi3ValueReference,
    nDependencies: *mut usize,
) -> fmi3Status {
    let _ = (valueReference, nDependencies); // not needed: refused
    refuse(
        instance,
        "fmi3GetNumberOfVariableDependencies",
        state::DEPENDENCIES,
        NO_ELEMENT_DEPENDENCIES,
    )
}

/// Not provided (providesPerElementDependencies="false"): logs why, returns fmi3Error.
///
/// # Safety
/// `instance` is an instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetVariableDependencies(
    instance: fmi3Instance,
    dependent: fmi3ValueReference,
    elementIndicesOfDependent: *mut usize,
    independents: *mut fmi3ValueReference,
    elementIndicesOfIndependents: *mut usize,
    dependencyKinds: *mut fmi3DependencyKind,
    nDependencies: usize,
) -> fmi3Status {
    // Not needed: refused.
    let _ = (
        dependent,
        elementIndicesOfDependent,
        independents,
        elementIndicesOfIndependents,
        dependencyKinds,
        nDependencies,
    );
    refuse(
        instance,
        "fmi3GetVariableDependencies",
        state::DEPENDENCIES,
        NO_ELEMENT_DEPENDENCIES,
    )
}
