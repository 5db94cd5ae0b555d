//! The simulation behind one FMU instance, in safe Rust: parameters, inputs, the
//! solver, outputs by value reference, and snapshots for FMU state get/set. The C ABI
//! in [`crate::fmi`] checks the call sequence and converts pointers; this file never
//! sees a pointer.

use std::path::Path;

use super::guard::StepGuard;
pub use super::simulation_error::{SimulationError, StepRefused, TimeError};
use super::snapshot::Snapshot;
pub use super::time::{check_step_times, time_tolerance};
use super::vars::{Causality, Kind, VarTable, method_name};
use crate::scene::Scene;
use crate::scene::io::{ResourceError, Resources, load_resources};
use crate::solver::{self, Method, Options, Solver, SolverWarning};

mod me;
mod me_directional;
mod outputs;
mod step;

/// When a value is set: before the end of initialisation parameters may change; after
/// it only inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Instantiated or initialisation mode.
    Configuring,
    /// Step complete.
    Running,
}

/// The simulation one FMU instance runs: what a co-simulation slave holds between the
/// calls of its master.
pub struct Simulation {
    /// The variable table (same as the description's).
    pub table: VarTable,
    /// The GUID of the resources this model was read from.
    pub guid: String,
    /// The interfaces the FMU declares (`pack --interface`, from the resources).
    pub interfaces: crate::fmu::interface::Interfaces,
    scene: Scene,
    method: Method,
    opts: Options,
    loads: Vec<f64>,
    rates: Vec<f64>,
    solver: Option<Box<dyn Solver>>,
    /// The last step's warning, until taken.
    warning: Option<SolverWarning>,
    /// Parameters changed since the solver was built.
    dirty: bool,
    /// Loads changed since they were last passed to the solver.
    loads_dirty: bool,
    /// An input rate was written since the rates were last cleared: only then can one
    /// be nonzero (read by [`any_nonzero`] before a step).
    rates_written: bool,
    /// The last step ran with nonzero input rates (the solver must be told they ended).
    rates_applied: bool,
    pos: Vec<f64>,
    vel: Vec<f64>,
    acc: Vec<f64>,
    /// Node rotation vectors and angular velocities (3 per exposed node), filled when
    /// one is asked for.
    rot: Vec<f64>,
    omega: Vec<f64>,
    /// Rollback buffer and finiteness check of each step.
    guard: StepGuard,
    start_time: f64,
    stop_time: Option<f64>,
    time: f64,
    /// Model Exchange: the master integrates the body's own equations, whatever
    /// `method` says ([`Simulation::solver_method`]).
    model_exchange: bool,
    /// Continuous states and derivatives read by value reference (Model Exchange's
    /// variables), sized when the first-order form is first asked for.
    xs: Vec<f64>,
    dxs: Vec<f64>,
    /// The directional derivative's work arrays, sized at its first call.
    directional: me_directional::Work,
}

impl Simulation {
    /// Read the resources folder and set up a model at its start values.
    pub fn from_resources(dir: &Path) -> Result<Simulation, ResourceError> {
        let Resources {
            scene,
            guid,
            options,
        } = load_resources(dir)?;
        let mut model = Simulation::new(scene, guid);
        // `pack --method` (the start value the description declares) and `pack
        // --interface` (Model Exchange's state variables): the description's table.
        model.table = VarTable::for_options(&model.scene, &options);
        model.interfaces = options.interface;
        model.method = model.table.default_method;
        Ok(model)
    }

    /// A model for a scene at its start values.
    pub fn new(scene: Scene, guid: String) -> Simulation {
        let table = VarTable::new(&scene);
        let m = scene.nodes.len();
        Simulation {
            method: table.default_method,
            table,
            guid,
            interfaces: Default::default(),
            opts: Options::default(),
            loads: vec![0.0; 6 * m],
            rates: vec![0.0; 6 * m],
            solver: None,
            warning: None,
            dirty: true,
            loads_dirty: true,
            rates_applied: false,
            rates_written: false,
            pos: vec![0.0; 3 * m],
            vel: vec![0.0; 3 * m],
            acc: vec![0.0; 3 * m],
            rot: vec![0.0; 3 * m],
            omega: vec![0.0; 3 * m],
            guard: StepGuard::new(&scene),
            start_time: 0.0,
            stop_time: None,
            time: 0.0,
            model_exchange: false,
            xs: Vec::new(),
            dxs: Vec::new(),
            directional: Default::default(),
            scene,
        }
    }

    /// The step guard (tests).
    #[cfg(test)]
    pub(crate) fn guard_mut(&mut self) -> &mut StepGuard {
        &mut self.guard
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Current time.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The method in use.
    pub fn method(&self) -> Method {
        self.method
    }

    /// Record the experiment's start and stop time (fmi2SetupExperiment).
    pub fn setup(&mut self, start: f64, stop: Option<f64>) -> Result<(), SimulationError> {
        if !start.is_finite() {
            return Err(TimeError::Start(start).into());
        }
        if let Some(s) = stop
            && (s.is_nan() || s < start)
        {
            return Err(TimeError::StopBeforeStart { stop: s, start }.into());
        }
        self.start_time = start;
        self.stop_time = stop;
        self.time = start;
        Ok(())
    }

    /// Build the solver if none exists or a parameter changed. Returns a description
    /// of what was built, for the solver log category.
    #[inline]
    pub fn ensure_solver(&mut self) -> Result<Option<String>, SimulationError> {
        if self.solver.is_some() && !self.dirty {
            return Ok(None);
        }
        self.build_solver()
    }

    /// The build behind [`Simulation::ensure_solver`], out of the step's way.
    #[cold]
    #[inline(never)]
    fn build_solver(&mut self) -> Result<Option<String>, SimulationError> {
        let method = self.solver_method();
        let s = solver::build(&self.scene, method, &self.opts).map_err(|source| {
            SimulationError::Build {
                method: method_name(method),
                source,
            }
        })?;
        self.guard.adopt(&self.scene, &self.opts);
        self.solver = Some(s);
        self.dirty = false;
        self.loads_dirty = true;
        self.rates_applied = true;
        Ok(Some(format!(
            "built the {} solver: {}, {}, rho_inf {}, damping.ratio {}",
            method_name(method),
            crate::num::count(self.scene.body.nl(), "local mode"),
            crate::num::count(self.scene.nodes.len(), "exposed node"),
            crate::num::num(self.opts.rho_inf),
            crate::num::num(self.opts.damping_ratio)
        )))
    }

    #[inline]
    fn var(&self, vr: u32) -> Result<&super::vars::Variable, SimulationError> {
        match self.table.get(vr) {
            Some(var) => Ok(var),
            None => Err(SimulationError::UnknownReference {
                vr,
                count: self.table.vars.len(),
            }),
        }
    }

    /// Whether [`Simulation::set_real`] would accept `v` for `vr`, without changing anything.
    pub fn check_real(&self, vr: u32, v: f64, phase: Phase) -> Result<(), SimulationError> {
        self.checked_real(vr, v, phase).map(|_| ())
    }

    /// [`Simulation::check_real`], giving the variable's binding for [`Simulation::apply_real`] so
    /// that the table is read once per value.
    #[inline(always)]
    fn checked_real(&self, vr: u32, v: f64, phase: Phase) -> Result<Kind, SimulationError> {
        // No clone of the variable: this runs on every fmi2SetReal and must not allocate.
        let var = self.var(vr)?;
        if var.is_integer() {
            return Err(SimulationError::WrongType {
                name: var.name.clone(),
                vr,
                is: "an Integer",
                use_instead: "set it with fmi2SetInteger",
            });
        }
        check_settable(var, phase)?;
        if !v.is_finite() {
            return Err(SimulationError::NonFinite {
                name: var.name.clone(),
                value: v,
            });
        }
        if var.kind == Kind::RhoInf && !(0.0..=1.0).contains(&v) {
            return Err(SimulationError::RhoInf(v));
        }
        if var.kind == Kind::DampingRatio && v < 0.0 {
            return Err(SimulationError::DampingRatio(v));
        }
        Ok(var.kind)
    }

    /// Set Real variables: all or none (a refused value leaves every variable as it
    /// was, so a master's error does not half-apply a set of loads).
    #[inline]
    pub fn set_reals(
        &mut self,
        vrs: &[u32],
        vals: &[f64],
        phase: Phase,
    ) -> Result<(), SimulationError> {
        // One value (a master setting one input): all or none holds already.
        if let ([r], [v]) = (vrs, vals) {
            return self.set_real(*r, *v, phase);
        }
        self.set_several(vrs, vals, phase)
    }

    /// [`Simulation::set_reals`] for any number of values: all checked, then all stored.
    #[inline(never)]
    fn set_several(
        &mut self,
        vrs: &[u32],
        vals: &[f64],
        phase: Phase,
    ) -> Result<(), SimulationError> {
        for (&r, &v) in vrs.iter().zip(vals) {
            self.check_real(r, v, phase)?;
        }
        // Every value passed the check: each is checked once per call, not again here.
        for (&r, &v) in vrs.iter().zip(vals) {
            if let Some(var) = self.table.get(r) {
                self.apply_real(var.kind, v);
            }
        }
        Ok(())
    }

    /// Set a Real variable.
    #[inline]
    pub fn set_real(&mut self, vr: u32, v: f64, phase: Phase) -> Result<(), SimulationError> {
        let kind = self.checked_real(vr, v, phase)?;
        self.apply_real(kind, v);
        Ok(())
    }

    /// Store `v` in the Real variable bound to `kind`, which [`Simulation::check_real`]
    /// accepted.
    #[inline(always)]
    fn apply_real(&mut self, kind: Kind, v: f64) {
        match kind {
            Kind::RhoInf => {
                self.opts.rho_inf = v;
                self.dirty = true;
            }
            Kind::DampingRatio => {
                self.opts.damping_ratio = v;
                self.dirty = true;
            }
            Kind::Gravity(c) => {
                self.scene.gravity[c] = v;
                self.dirty = true;
            }
            Kind::V0(c) => {
                self.scene.v0[c] = v;
                self.dirty = true;
            }
            Kind::W0(c) => {
                self.scene.w0[c] = v;
                self.dirty = true;
            }
            Kind::Load { node, comp } => self.store_load(6 * node + comp, v),
            _ => unreachable!("check_settable refuses outputs"),
        }
    }

    /// Store load `k` (finite), noting a change for the solver and the step guard.
    #[inline(always)]
    fn store_load(&mut self, k: usize, v: f64) {
        let slot = &mut self.loads[k];
        if slot.to_bits() != v.to_bits() {
            *slot = v;
            self.loads_dirty = true;
            self.guard.note_load(v);
        }
    }

    /// The common fmi2SetReal in a step loop: `vr` is a load (an input, settable in
    /// every phase) and `v` finite, stored as [`Simulation::set_real`] would. `false`, with
    /// nothing changed, for anything else, which then takes [`Simulation::set_reals`] and its
    /// messages.
    #[inline(always)]
    pub fn set_load(&mut self, vr: u32, v: f64) -> bool {
        let Some(Kind::Load { node, comp }) = self.table.get(vr).map(|var| var.kind) else {
            return false;
        };
        // Finite: `<= MAX` fails for infinities and NaN alike (`is_finite` compiles to a
        // bit-pattern classification).
        let finite = v.abs() <= f64::MAX;
        if finite {
            self.store_load(6 * node + comp, v);
        }
        finite
    }

    /// Set Integer variables: all or none, like [`Simulation::set_reals`].
    pub fn set_integers(
        &mut self,
        vrs: &[u32],
        vals: &[i32],
        phase: Phase,
    ) -> Result<(), SimulationError> {
        let (method, dirty) = (self.method, self.dirty);
        for (&r, &v) in vrs.iter().zip(vals) {
            if let Err(e) = self.set_integer(r, v, phase) {
                (self.method, self.dirty) = (method, dirty);
                return Err(e);
            }
        }
        Ok(())
    }

    /// Set the Integer variable `method`.
    pub fn set_integer(&mut self, vr: u32, v: i32, phase: Phase) -> Result<(), SimulationError> {
        let var = self.var(vr)?;
        if !var.is_integer() {
            return Err(SimulationError::WrongType {
                name: var.name.clone(),
                vr,
                is: "a Real",
                use_instead: "set it with fmi2SetReal",
            });
        }
        check_settable(var, phase)?;
        let m = self.table.method_for(v).map_err(|why| {
            let offered: Vec<String> = self
                .table
                .methods()
                .iter()
                .map(|&m| format!("{}={}", method_name(m), m as i32))
                .collect();
            SimulationError::MethodNotOffered {
                value: v,
                why,
                offered: offered.join(", "),
            }
        })?;
        if m != self.method {
            self.method = m;
            self.dirty = true;
        }
        Ok(())
    }

    /// Get the Integer `method`.
    pub fn get_integer(&self, vr: u32) -> Result<i32, SimulationError> {
        let var = self.var(vr)?;
        if !var.is_integer() {
            return Err(SimulationError::WrongType {
                name: var.name.clone(),
                vr,
                is: "a Real",
                use_instead: "get it with fmi2GetReal",
            });
        }
        Ok(self.method as i32)
    }

    /// Set input derivatives: all or none, like [`Simulation::set_reals`].
    pub fn set_input_rates(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        vals: &[f64],
    ) -> Result<(), SimulationError> {
        for pass in 0..2 {
            for ((&r, &o), &v) in vrs.iter().zip(orders).zip(vals) {
                let slot = self.input_rate_slot(r, o, v)?;
                if pass == 1 {
                    self.rates[slot] = v;
                    self.rates_written = true;
                }
            }
        }
        Ok(())
    }

    /// Where the input rate for `vr` goes, if `order` and `v` are acceptable.
    fn input_rate_slot(&self, vr: u32, order: i32, v: f64) -> Result<usize, SimulationError> {
        let var = self.var(vr)?;
        let Kind::Load { node, comp } = var.kind else {
            return Err(SimulationError::NotAnInput(var.name.clone()));
        };
        if order != 1 {
            return Err(SimulationError::InputOrder {
                name: var.name.clone(),
                order,
            });
        }
        if !v.is_finite() {
            return Err(SimulationError::NonFiniteRate {
                name: var.name.clone(),
                value: v,
            });
        }
        Ok(6 * node + comp)
    }

    /// Set the time derivative of order 1 of an input (fmi2SetRealInputDerivatives).
    /// It applies to the next step only: each doStep clears the rates.
    pub fn set_input_rate(&mut self, vr: u32, order: i32, v: f64) -> Result<(), SimulationError> {
        let slot = self.input_rate_slot(vr, order, v)?;
        self.rates[slot] = v;
        self.rates_written = true;
        Ok(())
    }

    /// Back to the state after instantiation (fmi2Reset).
    pub fn reset(&mut self) {
        let scene = {
            let mut s = self.scene.clone();
            s.gravity = [0.0; 3];
            s.v0 = [0.0; 3];
            s.w0 = [0.0; 3];
            s
        };
        let guid = std::mem::take(&mut self.guid);
        // The start values are the description's: the packed method (`pack --method`)
        // among them, not the body's default.
        let method = self.table.default_method;
        let mut fresh = Simulation::new(scene, guid);
        // The description's table (the packed method, Model Exchange's states) and the
        // interface the instance serves are kept.
        fresh.table = std::mem::replace(&mut self.table, fresh.table);
        fresh.method = method;
        fresh.model_exchange = self.model_exchange;
        fresh.interfaces = self.interfaces;
        *self = fresh;
    }

    /// A snapshot of everything that defines the future (FMU state).
    pub fn snapshot(&self, phase: u8) -> Snapshot {
        Snapshot {
            phase,
            method: self.method as i32,
            rho_inf: self.opts.rho_inf,
            damping_ratio: self.opts.damping_ratio,
            gravity: self.scene.gravity,
            v0: self.scene.v0,
            w0: self.scene.w0,
            start_time: self.start_time,
            stop_time: self.stop_time,
            time: self.time,
            loads: self.loads.clone(),
            rates: self.rates.clone(),
            solver: if self.dirty {
                None
            } else {
                self.solver.as_ref().map(|s| s.state())
            },
        }
    }

    /// Restore a snapshot taken from a model of the same scene: all or nothing. A
    /// snapshot with non-finite or out-of-range values is refused before anything
    /// changes; one the solver refuses (wrong size) leaves the model as it was.
    pub fn restore(&mut self, snap: &Snapshot) -> Result<(), SimulationError> {
        snap.check()?;
        let backup = self.snapshot(0);
        self.restore_unchecked(snap).inspect_err(|_| {
            // The backup came from this model, so it restores; if not, the caller
            // reports the Error state anyway.
            let _ = self.restore_unchecked(&backup);
        })
    }

    fn restore_unchecked(&mut self, snap: &Snapshot) -> Result<(), SimulationError> {
        // The solver's state changes below: the guard saves it again before the next step.
        self.guard.forget();
        if snap.loads.len() != self.loads.len() || snap.rates.len() != self.rates.len() {
            return Err(SimulationError::StateLoads {
                held: snap.loads.len(),
                have: self.loads.len(),
            });
        }
        let method = self
            .table
            .method_for(snap.method)
            .map_err(|_| SimulationError::StateMethod(snap.method))?;
        let params_differ = method != self.method
            || snap.rho_inf != self.opts.rho_inf
            || snap.damping_ratio != self.opts.damping_ratio
            || snap.gravity != self.scene.gravity
            || snap.v0 != self.scene.v0
            || snap.w0 != self.scene.w0;
        self.method = method;
        self.opts.rho_inf = snap.rho_inf;
        self.opts.damping_ratio = snap.damping_ratio;
        self.scene.gravity = snap.gravity;
        self.scene.v0 = snap.v0;
        self.scene.w0 = snap.w0;
        if params_differ {
            self.dirty = true;
        }
        self.start_time = snap.start_time;
        self.stop_time = snap.stop_time;
        self.time = snap.time;
        self.loads.copy_from_slice(&snap.loads);
        self.guard.set_loads(&self.loads);
        self.rates.copy_from_slice(&snap.rates);
        self.rates_written = true;
        self.loads_dirty = true;
        self.rates_applied = true;
        match &snap.solver {
            Some(st) => {
                self.ensure_solver()?;
                if let Some(s) = self.solver.as_mut() {
                    s.set_state(st)?;
                }
            }
            None => {
                self.solver = None;
                self.dirty = true;
            }
        }
        Ok(())
    }
}

/// Whether `var` may be set in `phase`: never an output, parameters only before the end
/// of initialisation.
fn check_settable(var: &super::vars::Variable, phase: Phase) -> Result<(), SimulationError> {
    match (var.causality, phase) {
        (Causality::Output, _) => Err(SimulationError::Output(var.name.clone())),
        (Causality::Local, _) => Err(SimulationError::ContinuousState(var.name.clone())),
        (Causality::Parameter, Phase::Running) => {
            Err(SimulationError::FixedParameter(var.name.clone()))
        }
        _ => Ok(()),
    }
}
