//! The model as a Model Exchange master sees it: time and continuous states set from
//! outside, state derivatives, nominals and the exact Jacobian read back, all from the
//! method's own first-order form ([`crate::solver::continuous`]). The outputs of a state
//! set here are read by [`Simulation::get_reals`], the co-simulation output code, so the
//! residual correction's feed-through of the loads is the same. Nothing allocates once
//! the solver is built.

use super::{Simulation, SimulationError};
use crate::solver::SolverError;
use crate::solver::continuous::Continuous;

impl Simulation {
    /// The method's first-order form, the solver built and the loads passed on first.
    fn continuous(&mut self) -> Result<&mut dyn Continuous, SimulationError> {
        self.ensure_solver()?;
        let method = self.method;
        let Some(s) = self.solver.as_mut() else {
            return Err(SimulationError::NoSolver);
        };
        if self.loads_dirty {
            s.set_loads(&self.loads)?;
            self.guard.forget();
            self.loads_dirty = false;
        }
        s.continuous()
            .ok_or(SimulationError::Solver(SolverError::Unsupported {
                method,
                why: crate::solver::Unsupported::ModelExchange { method },
            }))
    }

    /// The number of continuous states (builds the solver).
    pub fn state_count(&mut self) -> Result<usize, SimulationError> {
        Ok(self.continuous()?.state_count())
    }

    /// Set the time (fmi2SetTime).
    pub fn set_time(&mut self, t: f64) -> Result<(), SimulationError> {
        if !t.is_finite() {
            return Err(super::TimeError::Start(t).into());
        }
        self.continuous()?.set_time(t);
        self.time = t;
        Ok(())
    }

    /// Set the continuous states (fmi2SetContinuousStates), at the current time.
    pub fn set_states(&mut self, x: &[f64]) -> Result<(), SimulationError> {
        let t = self.time;
        self.continuous()?.set_states(t, x)?;
        Ok(())
    }

    /// The continuous states (fmi2GetContinuousStates).
    pub fn states(&mut self, out: &mut [f64]) -> Result<(), SimulationError> {
        self.fill(out, |c, o| c.states(o))
    }

    /// The state derivatives (fmi2GetDerivatives).
    pub fn derivatives(&mut self, out: &mut [f64]) -> Result<(), SimulationError> {
        self.fill(out, |c, o| c.derivatives(o))
    }

    /// The states' nominal magnitudes (fmi2GetNominalsOfContinuousStates).
    pub fn nominals(&mut self, out: &mut [f64]) -> Result<(), SimulationError> {
        self.fill(out, |c, o| c.nominals(o))
    }

    /// One value per state into `out` by `read`, its length checked first.
    fn fill(
        &mut self,
        out: &mut [f64],
        read: impl Fn(&dyn Continuous, &mut [f64]),
    ) -> Result<(), SimulationError> {
        let c = self.continuous()?;
        check_len(out.len(), c.state_count())?;
        read(c, out);
        Ok(())
    }

    /// `A = dx'/dx` (`n x n`) and `B = dx'/du` (`n x 6m`, loads in value-reference
    /// order), column major; `false` where the method has no exact Jacobian.
    pub fn jacobian(&mut self, a: &mut [f64], b: &mut [f64]) -> Result<bool, SimulationError> {
        let loads = self.loads.len();
        let c = self.continuous()?;
        let n = c.state_count();
        check_len(a.len(), n * n)?;
        check_len(b.len(), n * loads)?;
        Ok(c.jacobian(a, b))
    }
}

fn check_len(found: usize, expected: usize) -> Result<(), SimulationError> {
    if found == expected {
        Ok(())
    } else {
        Err(SolverError::BadLength {
            what: "continuous-state array",
            expected,
            found,
        }
        .into())
    }
}
