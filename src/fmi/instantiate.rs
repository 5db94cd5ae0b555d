//! Creating an instance, shared by fmi2Instantiate and fmi3InstantiateCoSimulation: the
//! instance name checked, the version's own argument checks (fmuType, event mode,
//! resource location or path), the resources read, the GUID (FMI 3.0's
//! instantiationToken) compared, the body's warnings logged once the instance exists.
//! NULL with a logged reason on any failure; a panic is caught and reported the same way.

use std::ffi::c_void;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;

use super::FmiError;
use super::instance::{Instance, LOG_ERROR, LOG_SOLVER, LOG_WARNING, Log, panic_text};
use super::state::FmiState;
use super::types::*;
use super::version::{FmiVersion, Interface};

/// Instantiate for `func` of FMI `version`: `log` makes the instance's log for a name,
/// `args` checks the version's own arguments and gives the interface asked for, the
/// GUID the caller passed and the resources folder. Returns the new instance, or NULL
/// after logging why (an interface the FMU was not packed for among the reasons).
pub(crate) fn instantiate(
    func: &str,
    version: FmiVersion,
    name: Option<String>,
    log: impl Fn(&str) -> Log,
    args: impl FnOnce() -> Result<(Interface, String, PathBuf), FmiError>,
) -> *mut c_void {
    let shown = name.as_deref().unwrap_or("");
    // A body whose rigid part does not turn with it (body::invariance): logged as a
    // warning once the instance exists.
    let mut warning = None;
    let result = catch_unwind(AssertUnwindSafe(|| -> Result<Box<Instance>, FmiError> {
        if name.as_deref().is_none_or(|n| n.trim().is_empty()) {
            return Err(FmiError::NoInstanceName);
        }
        let (interface, guid, dir) = args()?;
        let mut model = crate::fmu::simulation::Simulation::from_resources(&dir)?;
        let scene_file = dir.join(crate::scene::io::SCENE_FILE).display().to_string();
        warning = crate::body::invariance::check(&model.scene().body, &scene_file);
        if model.guid != guid {
            return Err(FmiError::GuidMismatch {
                given: guid,
                dir,
                found: model.guid,
            });
        }
        let declared = match interface {
            Interface::CoSimulation => model.interfaces.co_simulation(),
            Interface::ModelExchange => model.interfaces.model_exchange(),
        };
        if !declared {
            return Err(FmiError::InterfaceNotDeclared {
                asked: interface.name(),
                declared: model.interfaces.name(),
            });
        }
        if interface == Interface::ModelExchange {
            model.serve_model_exchange();
        }
        Ok(Box::new(Instance {
            log: log(shown),
            version,
            interface,
            state: FmiState::Instantiated,
            before_error: FmiState::Instantiated,
            simulation: model,
        }))
    }));
    match result {
        Ok(Ok(inst)) => {
            if let Some(w) = &warning {
                inst.log
                    .send(fmi2Warning, LOG_WARNING, &format!("{func}: {w}"));
            }
            if inst.log.on(LOG_SOLVER) {
                let m = &inst.simulation;
                inst.log.send(
                    fmi2OK,
                    LOG_SOLVER,
                    &format!(
                        "instantiated: {}, {}, {}",
                        crate::num::count(m.table.vars.len(), "variable"),
                        crate::num::count(m.scene().nodes.len(), "exposed node"),
                        crate::num::count(m.scene().body.nl(), "local mode")
                    ),
                );
            }
            Box::into_raw(inst).cast()
        }
        Ok(Err(msg)) => {
            log(shown).send(fmi2Error, LOG_ERROR, &format!("{func}: {msg}"));
            std::ptr::null_mut()
        }
        Err(p) => {
            log(shown).send(
                fmi2Fatal,
                LOG_ERROR,
                &format!("{func}: internal error (panic): {}", panic_text(&*p)),
            );
            std::ptr::null_mut()
        }
    }
}

/// Free an instance of either version (NULL is ignored); a panic while dropping is
/// caught.
///
/// # Safety
/// `c` is NULL or an instance from an instantiation function not yet freed.
pub(crate) unsafe fn free_instance(c: *mut c_void) {
    if c.is_null() {
        return;
    }
    // SAFETY: `c` came from Box::into_raw in `instantiate` and is freed only here.
    let inst = unsafe { Box::from_raw(c.cast::<Instance>()) };
    let _ = catch_unwind(AssertUnwindSafe(move || drop(inst)));
}
