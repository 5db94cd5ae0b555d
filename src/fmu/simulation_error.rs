//! Why the running model ([`super::simulation::Simulation`]) refuses a call: a set or get it cannot
//! honour, a time argument, a solver that cannot be built, a refused step (with the
//! outcome of putting the state back), a saved state that does not fit. The FMI layer
//! logs each as `"{function}: {error}"`.

use super::snapshot::SnapshotError;
use crate::num::num;
use crate::solver::SolverError;

/// A time argument refused by fmi2SetupExperiment or fmi2DoStep ([`super::time::check_step_times`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TimeError {
    /// startTime NaN or infinite.
    #[error("startTime must be finite, got {}", num(*.0))]
    Start(f64),
    /// stopTime before startTime, or NaN.
    #[error("stopTime {} is before startTime {} (or NaN)", num(*.stop), num(*.start))]
    StopBeforeStart {
        /// stopTime.
        stop: f64,
        /// startTime.
        start: f64,
    },
    /// communicationStepSize not finite and > 0.
    #[error("communicationStepSize must be finite and > 0, got {}", num(*.0))]
    StepSize(f64),
    /// currentCommunicationPoint is not the FMU's time.
    #[error(
        "currentCommunicationPoint {} is not the FMU's current time {} (difference {}, tolerance {})",
        num(*.t), num(*.time), num(*.t - *.time), num(*.tol)
    )]
    NotCurrent {
        /// The master's time.
        t: f64,
        /// The FMU's time.
        time: f64,
        /// The tolerance allowed ([`super::time::time_tolerance`]).
        tol: f64,
    },
    /// The step would end after stopTime.
    #[error("the step to {} goes past stopTime {}", num(*.end), num(*.stop))]
    PastStop {
        /// t + h.
        end: f64,
        /// stopTime.
        stop: f64,
    },
}

/// A refused step: what refused it, and whether the state before the step was put back.
#[derive(Debug, thiserror::Error)]
#[error(
    "step from t = {} with h = {} refused: {cause}{}{}",
    num(*.t), num(*.h),
    .largest_input.as_ref().map_or(String::new(), |x| format!(" (largest input: {x})")),
    match .restored {
        Ok(()) => format!("; the FMU keeps its state at t = {}", num(*.t)),
        Err(b) => format!("; the state before the step could not be put back: {b}"),
    }
)]
pub struct StepRefused {
    /// currentCommunicationPoint.
    pub t: f64,
    /// communicationStepSize.
    pub h: f64,
    /// What the solver or the finiteness check refused.
    pub cause: SolverError,
    /// The largest input, named when a load was applied (usually the cause).
    pub largest_input: Option<String>,
    /// The rollback's outcome.
    pub restored: Result<(), SolverError>,
}

/// Why the model refused a call (set, get, step, state restore). The FMI layer logs it
/// as `"{function}: {error}"` and returns fmi2Error; nothing changed in the model.
#[derive(Debug, thiserror::Error)]
pub enum SimulationError {
    /// A value reference this FMU does not have.
    #[error("unknown value reference {vr} (this FMU has 0..{count})")]
    UnknownReference {
        /// The value reference.
        vr: u32,
        /// How many variables there are.
        count: usize,
    },
    /// A variable accessed with the other type's function.
    #[error("{name} (vr {vr}) is {is}: {use_instead}")]
    WrongType {
        /// The variable's name.
        name: String,
        /// Its value reference.
        vr: u32,
        /// What it is ("a Real", "an Integer").
        is: &'static str,
        /// The call to use ("set it with fmi2SetInteger", ...).
        use_instead: &'static str,
    },
    /// An output cannot be set.
    #[error("{0} is an output: it cannot be set")]
    Output(String),
    /// A continuous state or derivative variable (Model Exchange) set by value.
    #[error(
        "{0} is a continuous state or its derivative: set the states with \
         fmi2SetContinuousStates (they start at rest)"
    )]
    ContinuousState(String),
    /// A directional derivative with respect to a variable that is neither a
    /// continuous state nor a load input.
    #[error(
        "{name} is not a known of the directional derivative: the knowns are the \
         continuous states and the load inputs"
    )]
    NotAKnown {
        /// The variable.
        name: String,
    },
    /// A directional derivative of a variable that is neither a state derivative nor
    /// a continuous state.
    #[error(
        "{name}: directional derivatives are provided for the state derivatives (and \
         the states) only, not for outputs"
    )]
    NotAnUnknown {
        /// The variable.
        name: String,
    },
    /// A fixed parameter after initialisation.
    #[error("{0} is a fixed parameter: set it before fmi2ExitInitializationMode")]
    FixedParameter(String),
    /// A non-finite value for a Real variable.
    #[error("{name}: value must be finite, got {}", crate::num::num(*.value))]
    NonFinite {
        /// The variable.
        name: String,
        /// The value.
        value: f64,
    },
    /// rho_inf outside [0, 1].
    #[error("rho_inf must be in [0, 1], got {}", num(*.0))]
    RhoInf(f64),
    /// A negative added damping ratio (it would feed energy in).
    #[error("damping.ratio must be >= 0 (a negative ratio feeds energy in), got {}", num(*.0))]
    DampingRatio(f64),
    /// A method value not offered for this body.
    #[error("method: {value} is not offered for this body: {why} (offered: {offered})")]
    MethodNotOffered {
        /// The value given.
        value: i32,
        /// Why not (no such value, or a method for another kind of body).
        why: String,
        /// The offered `name=value` pairs.
        offered: String,
    },
    /// An input derivative for a variable that is not an input.
    #[error("{0} is not an input: input derivatives apply to inputs only")]
    NotAnInput(String),
    /// An input derivative of an order other than 1.
    #[error(
        "{name}: derivative order {order} is not supported (inputs are interpolated linearly: order 1 only)"
    )]
    InputOrder {
        /// The input.
        name: String,
        /// The order given.
        order: i32,
    },
    /// A non-finite input derivative.
    #[error("{name}: derivative must be finite, got {}", crate::num::num(*.value))]
    NonFiniteRate {
        /// The input.
        name: String,
        /// The value.
        value: f64,
    },
    /// An output derivative this FMU does not give.
    #[error(
        "{name}: no derivative of order {order} (available: node positions orders 1 and 2, node velocities order 1)"
    )]
    NoOutputDerivative {
        /// The variable.
        name: String,
        /// The order asked for.
        order: i32,
    },
    /// No solver was built yet (a derivative asked before any value or step).
    #[error("no solver")]
    NoSolver,
    /// A time argument refused.
    #[error(transparent)]
    Time(#[from] TimeError),
    /// The solver could not be built for the current parameters.
    #[error("cannot build the {method} solver: {source}")]
    Build {
        /// The method's name.
        method: &'static str,
        /// Why.
        source: SolverError,
    },
    /// The solver refused loads or a state.
    #[error(transparent)]
    Solver(#[from] SolverError),
    /// A step refused (boxed: it carries two solver errors).
    #[error(transparent)]
    StepRefused(Box<StepRefused>),
    /// A saved state that holds another number of loads.
    #[error("state holds {held} loads, this FMU has {have}")]
    StateLoads {
        /// Loads in the state.
        held: usize,
        /// Loads in this FMU.
        have: usize,
    },
    /// A saved state whose method this FMU does not offer.
    #[error("state holds method {0}, not offered here")]
    StateMethod(i32),
    /// A saved state refused by its own checks.
    #[error(transparent)]
    Snapshot(#[from] SnapshotError),
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A refused step says when, what refused it, the input named, and whether the state
    /// before the step was put back (the second outcome only happens if the solver
    /// refuses its own saved state, which no test can provoke through the FMU).
    #[test]
    fn a_refused_step_says_what_and_whether_the_state_was_put_back() {
        let cause = SolverError::Invalid(crate::solver::Invalid::Frame {
            h: 1e-3,
            error: 1e-3,
            spin: 2.0,
            advice: crate::solver::FrameAdvice::SmallerSteps,
        });
        let kept = SimulationError::StepRefused(Box::new(StepRefused {
            t: 0.5,
            h: 1e-3,
            cause: cause.clone(),
            largest_input: Some("F_x_12 = 1e300".into()),
            restored: Ok(()),
        }));
        assert_eq!(
            kept.to_string(),
            format!(
                "step from t = 0.5 with h = 0.001 refused: {cause} (largest input: F_x_12 = 1e300); \
                 the FMU keeps its state at t = 0.5"
            )
        );
        let lost = SimulationError::StepRefused(Box::new(StepRefused {
            t: 0.5,
            h: 1e-3,
            cause: cause.clone(),
            largest_input: None,
            restored: Err(SolverError::BadState(crate::solver::BadState::Length {
                expected: 4,
                found: 3,
            })),
        }));
        assert_eq!(
            lost.to_string(),
            format!(
                "step from t = 0.5 with h = 0.001 refused: {cause}; the state before the step \
                 could not be put back: {}",
                "state does not fit this solver: expected 4 numbers for this scene and \
                 method, got 3"
            )
        );
    }

    /// Numbers in time refusals are compact ([`num`]), whatever their size.
    #[test]
    fn time_refusals_print_compact_numbers() {
        let e = TimeError::PastStop {
            end: 1e300,
            stop: 2.0,
        };
        assert_eq!(e.to_string(), "the step to 1e300 goes past stopTime 2");
        let e = SimulationError::from(TimeError::StepSize(-0.25));
        assert_eq!(
            e.to_string(),
            "communicationStepSize must be finite and > 0, got -0.25"
        );
    }
}
