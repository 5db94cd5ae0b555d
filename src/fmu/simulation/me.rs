//! The model as a Model Exchange master sees it: time and continuous states set from
//! outside, state derivatives, nominals and the exact Jacobian read back, all from the
//! method's own first-order form ([`crate::solver::continuous`]). The outputs of a state
//! set here are read by [`Simulation::get_reals`], the co-simulation output code, so the
//! residual correction's feed-through of the loads is the same. Nothing allocates once
//! the solver is built.
//!
//! An instance that serves Model Exchange ([`Simulation::serve_model_exchange`])
//! integrates the body's own equations whatever the `method` parameter says: for a
//! blocked body those of the exact method, the modal equations themselves.

use super::{Simulation, SimulationError};
use crate::fmu::vars::Kind;
use crate::solver::continuous::Continuous;
use crate::solver::{Method, SolverError};

impl Simulation {
    /// Serve Model Exchange: from now on the solver is the body's own first-order form
    /// (the exact method's equations for a blocked body), whatever `method` says.
    pub fn serve_model_exchange(&mut self) {
        if !self.model_exchange {
            self.model_exchange = true;
            self.dirty = true;
        }
    }

    /// Whether this model serves Model Exchange.
    pub fn serves_model_exchange(&self) -> bool {
        self.model_exchange
    }

    /// The method the solver is built with: `method`, except under Model Exchange,
    /// where the body's own equations are integrated: a blocked body's as the exact
    /// method states them, a free body's as the split method's first-order form (the
    /// other methods' are discretisations of the same equations, not first-order systems
    /// of the body alone).
    pub(super) fn solver_method(&self) -> Method {
        match (self.model_exchange, self.table.free) {
            (false, _) => self.method,
            (true, false) => Method::Exact,
            (true, true) => Method::Split,
        }
    }

    /// The method's first-order form, the solver built and the loads passed on first.
    pub(super) fn continuous(&mut self) -> Result<&mut dyn Continuous, SimulationError> {
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
        let c = s
            .continuous()
            .ok_or(SimulationError::Solver(SolverError::Unsupported {
                method,
                why: crate::solver::Unsupported::ModelExchange { method },
            }))?;
        let n = c.state_count();
        if self.xs.len() != n {
            // Once, when the form is first asked for: the reads below then allocate
            // nothing.
            self.xs.resize(n, 0.0);
            self.dxs.resize(n, 0.0);
        }
        Ok(c)
    }

    /// The number of continuous states (builds the solver). Under Model Exchange it is
    /// the number the description declares, checked.
    pub fn state_count(&mut self) -> Result<usize, SimulationError> {
        let declared = self.table.state_count();
        let n = self.continuous()?.state_count();
        if declared > 0 && n != declared {
            return Err(SolverError::BadLength {
                what: "continuous states of the description",
                expected: n,
                found: declared,
            }
            .into());
        }
        Ok(n)
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

    /// The master completed an integrator step (fmi2CompletedIntegratorStep): `true`
    /// when the method put its states back on their manifold (a free body's quaternion
    /// normalised) and the master must read them again.
    pub fn completed_step(&mut self) -> Result<bool, SimulationError> {
        Ok(self.continuous()?.completed_step())
    }

    /// Whether [`Simulation::completed_step`] would change the states now, the states
    /// left as they are: FMI lets a model change its continuous states in Event Mode
    /// only, so at fmi2CompletedIntegratorStep the model asks for an event with this and
    /// changes them in fmi2NewDiscreteStates. Allocates nothing.
    pub fn completed_step_due(&mut self) -> Result<bool, SimulationError> {
        Ok(self.continuous()?.off_manifold())
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

    /// Whether `vrs` names a continuous state or derivative variable.
    pub(super) fn asks_continuous(&self, vrs: &[u32]) -> bool {
        vrs.iter().any(|&r| {
            matches!(
                self.table.get(r).map(|v| v.kind),
                Some(Kind::State(_) | Kind::Derivative(_))
            )
        })
    }

    /// The states and derivatives into the buffers the state and derivative variables
    /// are read from.
    pub(super) fn fill_continuous(&mut self) -> Result<(), SimulationError> {
        // Built, loads passed, buffers sized.
        self.continuous()?;
        if let Some(c) = self.solver.as_mut().and_then(|s| s.continuous()) {
            c.states(&mut self.xs);
            c.derivatives(&mut self.dxs);
        }
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

pub(super) fn check_len(found: usize, expected: usize) -> Result<(), SimulationError> {
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
