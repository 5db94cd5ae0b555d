//! Why a solver could not be built or could not step: every refusal as data (the values,
//! indices and figures that made it), worded here and nowhere else, so that a caller can
//! match on the cause and read its numbers, and every message names the value refused.

use crate::num::num;

use super::{MAX_INTERNAL_STEPS, Method};

/// Why a solver could not be built or could not step.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolverError {
    /// A method was asked for a body, option or step it does not handle.
    #[error("method {method:?} does not handle this body: {why}")]
    Unsupported {
        /// The method asked for.
        method: Method,
        /// Why not.
        why: Unsupported,
    },
    /// A step size that is not finite and positive.
    #[error("step size must be finite and > 0, got {}", num(*.0))]
    BadStep(f64),
    /// A slice of the wrong length was passed.
    #[error("{what}: expected {expected} values, got {found}")]
    BadLength {
        /// Which argument.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Given length.
        found: usize,
    },
    /// A saved state that does not belong to this solver.
    #[error("state does not fit this solver: {0}")]
    BadState(BadState),
    /// An argument or scene value that is not usable.
    #[error("bad input: {0}")]
    BadInput(BadInput),
    /// A system the method solves is singular, or its iteration failed.
    #[error("body cannot be simulated: {0}")]
    Singular(Singular),
    /// A step would take more internal steps than [`MAX_INTERNAL_STEPS`]: refused before
    /// any work, so that no call runs for minutes or forever.
    #[error(
        "a step of {} s needs {} internal steps of at most {} s, more than the budget of {MAX_INTERNAL_STEPS} per call; {}",
        num(*h), step_count(*steps), num(*internal), budget_advice(*max_h)
    )]
    TooManySteps {
        /// The step asked for.
        h: f64,
        /// Internal steps it would take (a float: it may not fit an integer).
        steps: f64,
        /// The largest internal step the method may take.
        internal: f64,
        /// The largest communication step that fits the budget.
        max_h: f64,
    },
    /// The step would produce a non-finite value; the solver state is left as it was.
    #[error("the step would make {what} non-finite ({cause})")]
    NonFinite {
        /// Which variable or state part (an output's name, "the body frame", ...).
        what: String,
        /// Why, as far as known.
        cause: Overflow,
    },
    /// The body has left the model's validity (for example its frame is no longer a
    /// rotation); the step is refused with the figure and advice.
    #[error("{0}")]
    Invalid(Invalid),
}

/// Why a method does not handle a body, option or step ([`SolverError::Unsupported`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Unsupported {
    /// The exact method on a free body.
    #[error("exact modal stepping needs a blocked body (Iblo=1)")]
    NeedsBlocked,
    /// The split method on a blocked body.
    #[error(
        "the split method is for free bodies (Iblo=0); a blocked body is linear: use the exact method"
    )]
    NeedsFree,
    /// Model Exchange with a method whose equations are not a first-order system of the
    /// body alone.
    #[error(
        "Model Exchange integrates the {} method's equations only where they are a first-order system of the body alone: use method {} (exact) for a blocked body, {} (split) for a free one",
        crate::fmu::vars::method_name(*method), Method::Exact as i32, Method::Split as i32
    )]
    ModelExchange {
        /// The method asked for.
        method: Method,
    },
    /// A directional derivative asked of a first-order form without an exact Jacobian
    /// (the free body's).
    #[error(
        "no exact Jacobian for a free body: the description declares providesDirectionalDerivative false (the frame's equations are nonlinear in the attitude and the angular velocity)"
    )]
    NoJacobian,
    /// A spectral radius outside `[0, max]`; `free` when the bound is the free body's
    /// (the frame constraints need damping at infinite frequency).
    #[error("rho_inf must {} [0, {}]{}, got {}{}",
        if *free { "be in" } else { "lie in" },
        num(*max),
        if *free { " for a free body" } else { "" },
        num(*value),
        if *free { ": the frame constraints (index 3) need some damping at infinite frequency" } else { "" })]
    RhoInf {
        /// The value given.
        value: f64,
        /// The largest allowed.
        max: f64,
        /// The free body's bound.
        free: bool,
    },
    /// An explicit step fraction outside `(0, 1]`.
    #[error("dt_factor must lie in (0, 1], got {}", num(*.0))]
    DtFactor(f64),
    /// An added damping ratio under which the explicit stable step is unusably small.
    #[error(
        "its stable step with damping.ratio {} is {} s, below any usable step (the lagged damping shortens it as 2 / (damping coefficient)): use the exact or implicit method (blocked bodies) or split (free bodies), which take any step",
        num(*zeta), num(*step)
    )]
    DampedStep {
        /// The damping ratio.
        zeta: f64,
        /// The stable step it leaves (s).
        step: f64,
    },
    /// A step whose modal transition overflows (`omega h` not finite).
    #[error("a step of {} s overflows the modal transition (omega h is not finite)", num(*.0))]
    TransitionOverflow(f64),
    /// A step whose exact transition of an overdamped mode overflows.
    #[error(
        "a step of {} s overflows the exact transition of an overdamped mode (omega h is not finite)",
        num(*.0)
    )]
    OverdampedOverflow(f64),
    /// A step for which a mode's generalised-alpha effective mass is not finite.
    #[error(
        "the generalised-alpha effective mass of mode {} is not finite for a step of {} s",
        mode + 1, num(*h)
    )]
    EffectiveMass {
        /// The mode (0-based).
        mode: usize,
        /// The step (s).
        h: f64,
    },
}

/// Why a saved state does not fit ([`SolverError::BadState`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BadState {
    /// Saved by another method.
    #[error("saved by method {saved:?}, this solver runs {runs:?}")]
    Method {
        /// The method that saved it.
        saved: Method,
        /// This solver's.
        runs: Method,
    },
    /// The wrong number of values.
    #[error("expected {expected} numbers for this scene and method, got {found}")]
    Length {
        /// This scene's and method's count.
        expected: usize,
        /// The state's.
        found: usize,
    },
    /// Too few values for a truncated solver's state.
    #[error("{found} values, a truncated solver's state has at least {min}")]
    TooShort {
        /// The state's count.
        found: usize,
        /// The least a truncated solver's state has.
        min: usize,
    },
    /// A value that is not finite.
    #[error("state holds a non-finite number")]
    NotFinite,
    /// A negative last step size.
    #[error("negative last step size")]
    NegativeStep,
    /// A rollback asked for without a checkpoint.
    #[error("no checkpoint to go back to: take one before the step")]
    NoCheckpoint,
}

/// Which argument or scene value is not usable ([`SolverError::BadInput`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BadInput {
    /// A continuous state value that is not finite.
    #[error("continuous state {index} is not finite ({value})")]
    ContinuousState {
        /// Its index.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// An exposed node index outside the body.
    #[error("exposed node index {index} is outside the body's {nodes} nodes")]
    Node {
        /// The index.
        index: usize,
        /// The body's node count.
        nodes: usize,
    },
    /// A free-body method given a blocked body.
    #[error("a blocked body (Iblo=1) is not a free body")]
    NotFree,
    /// An attitude quaternion state too short (or non-finite) to be a rotation's.
    #[error(
        "the attitude quaternion (continuous states 3..7) has norm {}: it must be a rotation's, of norm 1",
        num(*.0)
    )]
    Quaternion(f64),
    /// A damping ratio that is not finite and >= 0.
    #[error("damping ratio must be finite and >= 0, got {}", num(*.0))]
    DampingRatio(f64),
    /// Values that are not all finite.
    #[error("{0}: values must be finite")]
    NotFinite(&'static str),
    /// A residual flexibility of the wrong size.
    #[error(
        "residual flexibility is {rows}x{cols}, the scene exposes {nodes} nodes (expected {}x{})",
        6 * nodes, 6 * nodes
    )]
    ResidualShape {
        /// Its rows.
        rows: usize,
        /// Its columns.
        cols: usize,
        /// The exposed nodes.
        nodes: usize,
    },
    /// A residual flexibility with non-finite values.
    #[error("residual flexibility has non-finite values")]
    ResidualNotFinite,
}

/// Which system is singular or which iteration failed ([`SolverError::Singular`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Singular {
    /// The rigid-motion saddle-point system of a free body: with the step `dt` (0 at
    /// build) and the spin rate, worded by what can be at fault.
    #[error("{}", saddle_point(*ratio, *dt, *spin))]
    SaddlePoint {
        /// Smallest over largest pivot.
        ratio: f64,
        /// The internal step (0 before any step).
        dt: f64,
        /// The spin rate (rad/s).
        spin: f64,
    },
    /// The free implicit method's Newton iteration did not converge.
    #[error(
        "generalised-alpha Newton iteration did not converge in {iterations} iterations (step {} s)",
        num(*h)
    )]
    Newton {
        /// The iteration limit.
        iterations: usize,
        /// The step (s).
        h: f64,
    },
    /// The local (modal) iteration matrix is singular for the step.
    #[error(
        "the local (modal) iteration matrix is singular (pivot ratio {}) for the step {} s: the step is too large for the numbers to stay finite; use a smaller communication step",
        num(*ratio), num(*h)
    )]
    LocalIteration {
        /// Smallest over largest pivot.
        ratio: f64,
        /// The step (s).
        h: f64,
    },
    /// The condensed local mass is not positive definite.
    #[error(
        "the local mass with the rigid motion condensed out, diag(m_L) - B M6^-1 B^T, is not positive definite: M_C and M_R do not belong together"
    )]
    CondensedMass,
    /// The local mass is not invertible.
    #[error("the local mass is not invertible")]
    LocalMass,
}

/// The message of [`Singular::SaddlePoint`]: at build with the body at rest only the
/// body can be at fault; during a run the step, spin rate or load is.
fn saddle_point(ratio: f64, dt: f64, spin: f64) -> String {
    let what = format!(
        "the rigid-motion saddle-point system is singular (pivot ratio {}, condition above {})",
        num(ratio),
        num(1.0 / ratio)
    );
    if dt == 0.0 && spin == 0.0 {
        format!(
            "{what} before any step: a body whose nodes all lie on one line has no inertia \
             about that line"
        )
    } else if dt == 0.0 {
        format!(
            "{what} before any step, at the initial spin rate {} rad/s: the spin is too \
             large for the frame constraints; start the body with a smaller w0",
            num(spin)
        )
    } else {
        format!(
            "{what} with the internal step {} s at spin rate {} rad/s (rotation per step {} \
             rad): the step, spin rate or load is too large for the frame constraints; use a \
             smaller communication step or smaller loads",
            num(dt),
            num(spin),
            num(spin * dt)
        )
    }
}

/// Why a step's numbers would not be finite ([`SolverError::NonFinite`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Overflow {
    /// The body's numbers overflow under what was set on it.
    #[error(
        "its numbers overflow: the loads, gravity, initial velocity or spin rate are too large for this body"
    )]
    Inputs,
    /// The input of largest magnitude, as `name = value`.
    #[error("largest input: {0}")]
    LargestInput(String),
    /// The modal transition of a sub-step.
    #[error("omega h is not finite for the sub-step {} s", num(*.0))]
    SubStep(f64),
    /// A step with loads or a spin rate too large for it.
    #[error(
        "a step of {} s with loads or a spin rate ({} rad/s) too large for it",
        num(*h), num(*spin)
    )]
    Step {
        /// The step (s).
        h: f64,
        /// The spin rate (rad/s).
        spin: f64,
    },
}

/// How the body left the model's validity ([`SolverError::Invalid`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Invalid {
    /// The initial state is not finite.
    #[error(
        "the initial state is not finite: gravity, the initial velocity or spin, or the damping is too large for this body"
    )]
    InitialState,
    /// A step would leave the frame no longer a rotation.
    #[error(
        "the step of {} s would leave the body frame no longer a rotation (|P^T P - I| = {}, more than {}) at spin rate {} rad/s; the step was refused and the state is as before it: {advice}",
        num(*h), num(*error), num(crate::solver::free::MAX_FRAME_ERROR), num(*spin)
    )]
    Frame {
        /// The step (s).
        h: f64,
        /// `|P^T P - I|` after it.
        error: f64,
        /// The spin rate (rad/s).
        spin: f64,
        /// What the user can change.
        advice: FrameAdvice,
    },
    /// The split method's midpoint iteration for the frame did not converge.
    #[error(
        "the frame's midpoint step did not converge in {passes} passes over an internal step of {} s at spin rate {} rad/s; the step was refused and the state is as before it: use smaller communication steps or smaller loads",
        num(*dt), num(*spin)
    )]
    Midpoint {
        /// The pass limit.
        passes: usize,
        /// The internal step (s).
        dt: f64,
        /// The spin rate (rad/s).
        spin: f64,
    },
}

/// The advice of [`Invalid::Frame`], by what the method can change.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum FrameAdvice {
    /// Smaller communication steps.
    #[error("use smaller communication steps")]
    SmallerSteps,
    /// An angular acceleration the halved explicit step cannot follow.
    #[error(
        "the frame's angular acceleration is beyond what internal steps of {} s (the explicit step halved {halvings} times) can follow; reduce the torque or the loads' rate of change, or use the implicit method",
        num(*internal)
    )]
    AngularAcceleration {
        /// The smallest internal step (s).
        internal: f64,
        /// How many times it was halved.
        halvings: u32,
    },
}

/// The advice of [`SolverError::TooManySteps`]: the largest communication step that fits
/// the budget when it is a usable number (positive, a normal `f64`); otherwise no step
/// of any usable size fits (the method's internal step underflows, for example under an
/// added damping ratio near `f64::MAX`), and another method is the remedy.
fn budget_advice(max_h: f64) -> String {
    if max_h.is_normal() && max_h > 0.0 {
        format!("use steps of at most {} s", num(max_h))
    } else {
        format!(
            "no step of a usable size fits the budget (the largest is {} s): use another \
             method",
            num(max_h)
        )
    }
}

/// An internal step count for [`SolverError::TooManySteps`]: beyond `f64::MAX` (an
/// internal step that underflows) it is "more than 1.8e308", never "inf".
fn step_count(steps: f64) -> String {
    if steps.is_finite() {
        num(steps)
    } else {
        format!("more than {}", num(f64::MAX))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The structured errors keep the wording the String variants had, and each message
    /// names the value that was refused: the wording lives here only, so a change of a
    /// message shows in this table.
    #[test]
    fn every_refusal_is_worded_with_its_values() {
        let cases: Vec<(SolverError, &str)> = vec![
            (
                SolverError::Unsupported {
                    method: Method::Implicit,
                    why: Unsupported::RhoInf {
                        value: 1.5,
                        max: 1.0,
                        free: false,
                    },
                },
                "method Implicit does not handle this body: rho_inf must lie in [0, 1], got 1.5",
            ),
            (
                SolverError::Unsupported {
                    method: Method::Implicit,
                    why: Unsupported::RhoInf {
                        value: 0.995,
                        max: 0.99,
                        free: true,
                    },
                },
                "method Implicit does not handle this body: rho_inf must be in [0, 0.99] for a \
                 free body, got 0.995: the frame constraints (index 3) need some damping at \
                 infinite frequency",
            ),
            (
                SolverError::Unsupported {
                    method: Method::Explicit,
                    why: Unsupported::DtFactor(1.25),
                },
                "method Explicit does not handle this body: dt_factor must lie in (0, 1], got 1.25",
            ),
            (
                SolverError::Unsupported {
                    method: Method::Implicit,
                    why: Unsupported::EffectiveMass { mode: 2, h: 0.5 },
                },
                "method Implicit does not handle this body: the generalised-alpha effective mass \
                 of mode 3 is not finite for a step of 0.5 s",
            ),
            (
                SolverError::BadState(BadState::Length {
                    expected: 7,
                    found: 5,
                }),
                "state does not fit this solver: expected 7 numbers for this scene and method, got 5",
            ),
            (
                SolverError::BadState(BadState::Method {
                    saved: Method::Exact,
                    runs: Method::Implicit,
                }),
                "state does not fit this solver: saved by method Exact, this solver runs Implicit",
            ),
            (
                SolverError::BadInput(BadInput::Node {
                    index: 42,
                    nodes: 21,
                }),
                "bad input: exposed node index 42 is outside the body's 21 nodes",
            ),
            (
                SolverError::BadInput(BadInput::DampingRatio(-0.25)),
                "bad input: damping ratio must be finite and >= 0, got -0.25",
            ),
            (
                SolverError::BadInput(BadInput::ResidualShape {
                    rows: 6,
                    cols: 5,
                    nodes: 2,
                }),
                "bad input: residual flexibility is 6x5, the scene exposes 2 nodes (expected 12x12)",
            ),
            (
                SolverError::Singular(Singular::Newton {
                    iterations: 40,
                    h: 0.125,
                }),
                "body cannot be simulated: generalised-alpha Newton iteration did not converge \
                 in 40 iterations (step 0.125 s)",
            ),
            (
                SolverError::Singular(Singular::SaddlePoint {
                    ratio: 0.25,
                    dt: 0.0,
                    spin: 0.0,
                }),
                "body cannot be simulated: the rigid-motion saddle-point system is singular \
                 (pivot ratio 0.25, condition above 4) before any step: a body whose nodes all \
                 lie on one line has no inertia about that line",
            ),
            (
                SolverError::NonFinite {
                    what: "the modal transition".into(),
                    cause: Overflow::SubStep(0.75),
                },
                "the step would make the modal transition non-finite (omega h is not finite for \
                 the sub-step 0.75 s)",
            ),
            (
                SolverError::Invalid(Invalid::Frame {
                    h: 0.01,
                    error: 3e-6,
                    spin: 12.5,
                    advice: FrameAdvice::SmallerSteps,
                }),
                "the step of 0.01 s would leave the body frame no longer a rotation (|P^T P - I| \
                 = 3e-6, more than 1e-6) at spin rate 12.5 rad/s; the step was refused and the \
                 state is as before it: use smaller communication steps",
            ),
            (
                SolverError::Invalid(Invalid::Midpoint {
                    passes: 60,
                    dt: 0.002,
                    spin: 7.0,
                }),
                "the frame's midpoint step did not converge in 60 passes over an internal step of \
                 0.002 s at spin rate 7 rad/s; the step was refused and the state is as before \
                 it: use smaller communication steps or smaller loads",
            ),
        ];
        for (e, want) in cases {
            assert_eq!(e.to_string(), want, "{e:?}");
        }
    }
}
