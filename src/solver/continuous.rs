//! A method's equations as a first-order system `x' = f(t, x, u)`, for masters that
//! integrate the body themselves (FMI Model Exchange). The states are the method's own
//! (blocked bodies: the modal amplitudes `y` then the modal velocities `y'`), so the
//! derivatives come from the very equations the method's step solves, and the node
//! outputs of a state set here are read through the method's output code.
//!
//! A blocked mode obeys `y'' + d y' + w^2 y = g` ([`super::exact`]): [`modal_acceleration`]
//! is that equation, evaluated by the exact method's node accelerations and by its
//! [`Continuous::derivatives`] alike. The system is linear, `x' = A x + B u`, and
//! [`Continuous::jacobian`] gives `A` and `B` exactly.
//!
//! A free body's form is the split method's, with the attitude as a quaternion
//! ([`super::free::continuous`]).

use super::SolverError;

/// The load, in units of the body's force, whose static response sets a mode's nominal
/// amplitude ([`Continuous::nominals`]): per mode, `NOMINAL_LOAD max_c |g_jc| / w^2`,
/// the static amplitude under this load on the exposed node and component that moves the
/// mode most, and `w` times it for the modal velocity. A master's absolute tolerance is
/// its relative tolerance times the nominal (fmpy's CVode: `atol = rtol x nominal`), so
/// the relative tolerance governs a mode while it moves more than the nominal. A tenth
/// of a unit load, not a whole one: loads a coupled body sees are transient, and a load
/// held for a time `tau` short against a mode's period moves it by only
/// `2 sin(w tau / 2)` of its static amplitude (the cantilever's tip pulse of 2 ms: 1/11
/// of it on the mode that carries the tip). Measured on that pulse through fmpy's CVode
/// at rtol 1e-8: 5.8e-6 of the peak with a unit load's nominals, 2.8e-7 with a tenth's,
/// for 1.8 times the right-hand-side evaluations; nominals of 1 give 5.4e-4.
pub const NOMINAL_LOAD: f64 = 0.1;

/// The modal acceleration `y'' = g - d y' - w^2 y` of one blocked mode under the modal
/// load `g`, with damping `d` and squared frequency `w2`.
#[inline]
pub fn modal_acceleration(g: f64, d: f64, w2: f64, y: f64, yd: f64) -> f64 {
    g - d * yd - w2 * y
}

/// A method that can be integrated by its caller. Nothing here allocates.
pub trait Continuous {
    /// The number of continuous states.
    fn state_count(&self) -> usize;
    /// The states into `out` (length [`Continuous::state_count`]).
    fn states(&self, out: &mut [f64]);
    /// Set time and states (all or nothing: a wrong length or a non-finite value changes
    /// nothing).
    fn set_states(&mut self, time: f64, x: &[f64]) -> Result<(), SolverError>;
    /// Set the time alone (the loads' rates make the load a function of time).
    fn set_time(&mut self, time: f64);
    /// The state derivatives at the current time, states and loads, into `out`.
    fn derivatives(&self, out: &mut [f64]);
    /// A typical magnitude of each state (for the master's error control).
    fn nominals(&self, out: &mut [f64]);
    /// `dx'/dx` (`n x n`) and `dx'/du` (`n x 6m`, loads in the caller's order), column
    /// major, into `a` and `b`; `false` where the method has no exact Jacobian.
    fn jacobian(&self, a: &mut [f64], b: &mut [f64]) -> bool;
    /// Where [`Continuous::jacobian`] answers `false` and the caller differentiates the
    /// derivatives numerically: overwrite the rows of `js = J s` (over every state
    /// derivative) the method knows exactly, for the states `x` and the state direction
    /// `s` (the loads' direction moves none of them). None by default.
    fn exact_rows(&self, x: &[f64], s: &[f64], js: &mut [f64]) {
        let _ = (x, s, js);
    }
    /// The master completed an integrator step at the current states (FMI
    /// `CompletedIntegratorStep`): the method may put its states back on their manifold
    /// (a free body's attitude quaternion to norm 1). `true` when it changed the states:
    /// the master must read them again before it goes on (FMI: a step event, then
    /// `valuesOfContinuousStatesChanged`). Nothing to do by default.
    fn completed_step(&mut self) -> bool {
        false
    }
    /// Whether [`Continuous::completed_step`] would change the states now, nothing
    /// changed: FMI lets a model change its states in Event Mode only, so the model asks
    /// for an event with this first. Never by default.
    fn off_manifold(&self) -> bool {
        false
    }
}

/// Check a state vector for [`Continuous::set_states`].
pub fn check_states(x: &[f64], n: usize) -> Result<(), SolverError> {
    if x.len() != n {
        return Err(SolverError::BadLength {
            what: "continuous states",
            expected: n,
            found: x.len(),
        });
    }
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(SolverError::BadInput(super::BadInput::ContinuousState {
            index: i,
            value: x[i],
        }));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modal_acceleration_is_the_damped_oscillator() {
        // y'' + 0.2 y' + 4 y = 1 at y = 0.5, y' = -1: y'' = 1 + 0.2 - 2 = -0.8.
        assert!((modal_acceleration(1.0, 0.2, 4.0, 0.5, -1.0) + 0.8).abs() < 1e-15);
    }

    #[test]
    fn states_are_checked() {
        assert!(check_states(&[1.0, 2.0], 2).is_ok());
        assert!(check_states(&[1.0], 2).is_err());
        assert!(check_states(&[1.0, f64::NAN], 2).is_err());
    }
}
