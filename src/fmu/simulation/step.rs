//! The step path of the model: one communication step (fmi2DoStep) under the step
//! guard, and the refusal that puts the state from before the step back.

use super::{Simulation, SimulationError, StepRefused, check_step_times};
use crate::fmu::guard::{any_nonzero, largest_input};
use crate::solver::{Solver, SolverError, SolverWarning};

impl Simulation {
    /// One communication step from `t` to `t + h`. `Ok(Some(text))` is a completed step
    /// with a warning for the master (fmi2Warning).
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<Option<String>, SimulationError> {
        let warned = self.step(t, h)?;
        Ok(if warned { self.take_warning() } else { None })
    }

    /// [`Simulation::do_step`] without moving the warning: `Ok(true)` is a completed step with
    /// a warning, which [`Simulation::take_warning`] gives. Inlined into fmi2DoStep, its one
    /// caller on the step path; refusing is out of line.
    #[inline(always)]
    pub fn step(&mut self, t: f64, h: f64) -> Result<bool, SimulationError> {
        check_step_times(t, h, self.time, self.start_time, self.stop_time)?;
        self.ensure_solver()?;
        let Some(s) = self.solver.as_mut() else {
            return Err(SimulationError::NoSolver);
        };
        // Either the step is bounded in advance and cannot make anything non-finite, or
        // the state before it is saved, to be put back if the step fails or leaves a
        // non-finite number anywhere (guard.rs): a refused step changes nothing. After
        // an accepted checked step the guard already holds that state, and this copies
        // nothing.
        let rates_on = self.rates_written && any_nonzero(&self.rates);
        self.guard.begin(s.as_mut(), h, &self.loads, rates_on);
        let stepped = step_solver(
            s.as_mut(),
            h,
            &self.loads,
            &self.rates,
            self.loads_dirty || self.rates_applied || rates_on,
            rates_on || self.rates_applied,
        );
        // Refusals are out of line: the step path builds no message.
        let warning = match stepped {
            Ok(w) => w,
            Err(e) => return Err(self.refuse_failed(t, h, e)),
        };
        if !self.guard.accept_bounded()
            && let Some(what) = self.guard.check(
                s.as_mut(),
                &self.table,
                (&self.loads, &self.rates, rates_on),
                h,
            )
        {
            return Err(self.refuse_non_finite(t, h, what));
        }
        self.loads_dirty = false;
        self.rates_applied = rates_on;
        if rates_on {
            self.rates.iter_mut().for_each(|r| *r = 0.0);
        }
        // Zero now, whether cleared here or all zero already.
        self.rates_written = false;
        let warned = warning.is_some();
        if warned {
            self.warning = warning;
        }
        // Adopt the master's time so that round-off does not accumulate against it.
        self.time = t + h;
        Ok(warned)
    }

    /// The warning of the last step that returned `Ok(true)` from [`Simulation::step`].
    pub fn take_warning(&mut self) -> Option<String> {
        self.warning.take().map(|w| w.to_string())
    }

    /// A step the solver refused (frame no longer a rotation, budget, singular system):
    /// under a load, that load is named too, being the usual cause.
    #[cold]
    #[inline(never)]
    fn refuse_failed(&mut self, t: f64, h: f64, e: SolverError) -> SimulationError {
        let loaded = self.loads.iter().chain(&self.rates).any(|&x| x != 0.0);
        let largest = loaded.then(|| largest_input(&self.table, &self.loads, &self.rates));
        // The solver's step is all or nothing: its state is as before the step.
        self.guard.forget();
        self.refuse(t, h, e, largest, Ok(()))
    }

    /// A step the guard refused: `what` would have become non-finite.
    #[cold]
    #[inline(never)]
    fn refuse_non_finite(&mut self, t: f64, h: f64, what: String) -> SimulationError {
        let cause = SolverError::NonFinite {
            what,
            cause: crate::solver::Overflow::LargestInput(largest_input(
                &self.table,
                &self.loads,
                &self.rates,
            )),
        };
        let restored = match self.solver.as_mut() {
            Some(s) => self.guard.rollback(s.as_mut()),
            None => Ok(()),
        };
        self.refuse(t, h, cause, None, restored)
    }

    /// Say why a step was refused (`restored`: whether the state from before it is back).
    #[cold]
    #[inline(never)]
    fn refuse(
        &mut self,
        t: f64,
        h: f64,
        cause: SolverError,
        largest_input: Option<String>,
        restored: Result<(), SolverError>,
    ) -> SimulationError {
        // The solver gets the loads and rates again at the next step.
        self.loads_dirty = true;
        self.rates_applied = true;
        SimulationError::StepRefused(Box::new(StepRefused {
            t,
            h,
            cause,
            largest_input,
            restored,
        }))
    }
}

/// Pass the loads when `pass_loads` (they changed, or rates are or were on: both make
/// the solver re-project the loads onto the modes), the rates when `pass_rates`, and
/// advance the solver by `h`.
#[inline]
fn step_solver(
    s: &mut dyn Solver,
    h: f64,
    loads: &[f64],
    rates: &[f64],
    pass_loads: bool,
    pass_rates: bool,
) -> Result<Option<SolverWarning>, SolverError> {
    if pass_loads {
        s.set_loads(loads)?;
    }
    if pass_rates {
        s.set_load_rates(rates)?;
    }
    s.step(h)
}
