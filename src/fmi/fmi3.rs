//! The FMI 3.0 exports: all 75 functions fmi3Functions.h declares, unprefixed, beside
//! the FMI 2.0 ones in the same library. Co-simulation is provided (instantiation,
//! Float64 and Int32 variables, fmi3DoStep without early return, output derivatives,
//! FMU states); every other function logs why it is not provided and returns fmi3Error.
//! Each export is an adapter over the shared instance, gate and bodies of the FMI 2.0
//! layer (`super::instance::enter_as`, [`super::exports`], [`super::values`],
//! [`super::fmu_state`]): what differs is FMI 3.0's argument conventions (nValues, the
//! independent variable `time`, the resource path, fmi3DoStep's outputs), its state
//! table (`state`) and its logger ([`super::version`]).

pub mod clocks;
pub mod exports;
pub mod fmu_state;
pub mod model_exchange;
pub mod non_numeric;
pub mod other_types;
#[cfg(feature = "test-internals")]
#[doc(hidden)]
pub mod state;
#[cfg(not(feature = "test-internals"))]
mod state;
pub mod types;
pub mod values;

use super::FmiError;
use super::instance::Instance;
use super::version::FmiVersion;

/// The version every export here passes to the gate.
const V3: FmiVersion = FmiVersion::Fmi3;

/// An FMI 3.0 function this FMU does not provide: judged by `mask` (a call in a state
/// the standard forbids is refused as such), then refused for `why`, logged.
fn refuse(
    instance: types::fmi3Instance,
    func: &str,
    mask: u16,
    why: &'static str,
) -> types::fmi3Status {
    super::instance::enter_as(instance, V3, func, mask, |_| {
        Err(FmiError::NotProvided(why))
    })
}

/// Refuse `nValues` other than the number of value references: every variable of this
/// FMU is a scalar.
fn scalars(n_refs: usize, n_values: usize) -> Result<(), FmiError> {
    if n_values == n_refs {
        Ok(())
    } else {
        Err(FmiError::NValues { n_values, n_refs })
    }
}

/// Whether `vrs` names the independent variable `time` ([`crate::fmu::vars::VarTable::time_ref`]).
fn names_time(inst: &Instance, vrs: &[u32]) -> Option<u32> {
    let t = inst.simulation.table.time_ref();
    vrs.iter().copied().find(|&r| r == t)
}
