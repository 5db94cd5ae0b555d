//! Time integration of a flexible body, independent of FMI. One trait, one file per
//! method. A solver is built from a [`Scene`] and only computes loads and outputs for the
//! scene's exposed nodes.
//!
//! Blocked bodies (Iblo=1) are linear,
//! `diag(m_L) a + (beta K_L + alpha diag(m_L)) v + K_L q = F_L` in the fixed frame P0:
//! - [`exact`]: modal stepping, exact for held or linearly varying loads, any step;
//! - [`implicit`]: generalised-alpha, second order, unconditionally stable;
//! - [`explicit`]: the Radioss central-difference scheme, sub-cycled below dt_fx.
//!
//! [`nodes`] holds what they share: the exposed-node rows of the modes in the global
//! frame, the caller's load model (value, rate, time) and the node outputs, all
//! preallocated so that `step` and the outputs never allocate. `dense` has the small
//! kernels (dot products, matrix-vector updates) and `expm` the per-mode transition of
//! the exact method.

use crate::scene::Scene;

pub mod continuous;
pub mod damping;
mod dense;
pub mod error;
pub mod exact;
pub mod explicit;
mod expm;
pub mod free;
pub mod implicit;
pub mod loads;
pub mod nodes;
pub mod residual;
pub(crate) mod rollback;

pub use error::{
    BadInput, BadState, FrameAdvice, Invalid, Overflow, Singular, SolverError, Unsupported,
};
pub use exact::Exact;
pub use explicit::Explicit;
pub use implicit::Implicit;

/// Integration method. The numbers are the FMI enumeration values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// The Radioss central-difference scheme, sub-cycled at 0.9 dt_fx.
    Explicit = 1,
    /// Generalised-alpha (Chung-Hulbert), not bound by dt_fx.
    Implicit = 2,
    /// Exact modal stepping (blocked bodies only).
    Exact = 3,
    /// Strang splitting (free bodies only): the local modes exact between samples, the
    /// frame second order on the rotation group (`free::Split`).
    Split = 4,
}

/// Settings shared by the methods.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Spectral radius at infinite frequency for the implicit method, in [0, 1].
    pub rho_inf: f64,
    /// Fraction of the stable step used by the explicit method's internal steps.
    pub dt_factor: f64,
    /// Sub-cycle the explicit method (tests switch it off to show the instability).
    pub subcycle: bool,
    /// Added modal damping ratio on every local mode, on top of Rayleigh (the FMU
    /// parameter `damping.ratio`; [`damping`] is its one definition).
    pub damping_ratio: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            rho_inf: 0.9,
            dt_factor: 0.9,
            subcycle: true,
            damping_ratio: 0.0,
        }
    }
}

/// The most internal steps (sub-cycles, Newton iterations summed over sub-steps) one call
/// to [`Solver::step`] may take. A step that needs more is refused at once with
/// [`SolverError::TooManySteps`]. 10^6 internal steps cost about 0.02 s on the 20-mode
/// blocked cantilever and about 2 s on a free body: a bound on the work of one call,
/// far above any communication step a master uses on purpose.
pub const MAX_INTERNAL_STEPS: f64 = 1e6;

/// A complete solver state, for FMU state get/set, serialisation and rollback.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// The method that saved it.
    pub method: Method,
    /// All numbers the method needs to continue bit for bit (layout private to it).
    pub data: Vec<f64>,
}

/// What one step can do to a solver's state, bounded before it is taken
/// ([`BoundedStep::growth`]): with `m` the [`BoundedStep::measure`] before the step and
/// every load at most `cap` in magnitude (held, no rate on), the measure after it is at
/// most `state m + load cap`, and every number of the state besides the time and the held
/// loads is at most `scale` times the measure. Rounding is included. The same for every
/// step of the same size on the same solver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Growth {
    /// Factor on the measure before the step.
    pub state: f64,
    /// Factor on the largest load magnitude.
    pub load: f64,
    /// Largest state entry per unit of the measure.
    pub scale: f64,
}

/// The frame of a free body: position of L0 and P (row-major).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Global position of L0.
    pub origin: [f64; 3],
    /// P, row-major (column j is local axis j).
    pub p: [f64; 9],
}

/// The rates of a free body's moving frame ([`Solver::frame_rates`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameRates {
    /// Global velocity of L0 (the point `v0` sets at the start).
    pub velocity: [f64; 3],
    /// Global angular velocity of the frame (what `w0` sets at the start).
    pub omega: [f64; 3],
}

/// What a completed step has to say about the model's validity: the step was taken and
/// its numbers are finite, but the body has gone where the model's results may be wrong.
/// Raised once per solver; the FMU passes it on as fmi2Warning.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum SolverWarning {
    /// A free body spins at more than [`free::SPIN_WARN_RATIO`] of its first local
    /// mode's circular frequency: the model has no centrifugal stiffening or spin
    /// softening.
    #[error(
        "the body spins at {} rad/s, {} times the first local mode's circular frequency {} \
         rad/s (warning from {} times): the model has no centrifugal stiffening or spin \
         softening, so its deformation is no longer valid at this spin rate; results may \
         be wrong. Reduce the spin rate, or use a body whose modes were computed for it \
         (stiffer, or pre-stressed). Warned once per instance",
        crate::num::num(*spin), crate::num::num(*spin / *omega1), crate::num::num(*omega1),
        crate::num::num(free::SPIN_WARN_RATIO)
    )]
    SpinRate {
        /// The frame's spin rate `|omega|` (rad/s).
        spin: f64,
        /// The first local mode's circular frequency (rad/s).
        omega1: f64,
    },
    /// The explicit or split method on a free body whose local modes drag rigid motion:
    /// both integrate the Radioss equations, which leave out the `P_dot Phi_L alpha` part
    /// of the node velocities, so such a body gains energy when it spins
    /// (docs/FORMULATION.md section 3). Raised by the solver's first step.
    #[error(
        "the local modes drag rigid motion (up to {} of a mode's mass moves the frame with \
         it; modes computed on a support): the {} method integrates the Radioss equations, \
         which leave out the part of the node velocities that the turning frame gives the \
         deformation, so the body gains energy whenever it spins (measured on a truss tower \
         dragging {}, spun torque-free at 0.018 of its first frequency with 1 ms steps: {}). \
         Use the implicit method: its numerical damping holds that gain back (the same \
         truss: {} of its energy over 400 rad). Warned once per instance",
        crate::num::num(free::three_digits(*fraction)),
        if *split { "split" } else { "explicit" },
        crate::num::num(free::TRUSS_DRAGGED),
        free::drag_consequence(*split),
        crate::num::num(free::TRUSS_IMPLICIT_400)
    )]
    ModesDragRigidMotion {
        /// The largest fraction of a local mode's mass that moves the frame: the largest
        /// eigenvalue of `diag(m_L)^-1 B M6^-1 B^T`, `B = M_C^T G` (FORMULATION.md
        /// section 11).
        fraction: f64,
        /// The split method (else the explicit method).
        split: bool,
    },
}

/// A time integrator over one scene.
///
/// Loads are per exposed node, six values each (fx fy fz mx my mz, global frame), held
/// over a step, or varying linearly when rates are given. Outputs are per exposed node,
/// three values each. `step` never allocates.
///
/// # All or nothing
///
/// [`Solver::step`] either takes the whole step or none of it: when it returns an error
/// the state ([`Solver::state`], and with it every output) is bit for bit what it was
/// before the call, and the solver can go on (with a shorter step, smaller loads, or
/// from a saved state). After a [`Solver::checkpoint`] the step it refuses goes back to
/// the checkpoint instead, loads and rates set since then included. The free methods
/// also refuse a step that would leave a non-finite number in their state (their frame
/// and iterations need finite numbers to go on); a blocked method's step is a fixed
/// linear map of a finite state and the loads, which completes whatever the numbers: a
/// caller that wants every output finite checks them, as the FMU does
/// (`crate::fmu::guard`), and rewinds a step it refuses.
pub trait Solver: Send {
    /// The method this solver runs.
    fn method(&self) -> Method;
    /// Simulated time since the start.
    fn time(&self) -> f64;
    /// Set the loads at the current time (6 per exposed node). All or nothing: refused
    /// loads (a wrong count, a non-finite value) change nothing.
    fn set_loads(&mut self, loads: &[f64]) -> Result<(), SolverError>;
    /// Set load rates (6 per exposed node, per second): over the next steps the load is
    /// `loads + rate (t - t_set)`. Rates persist until set again; zeros mean held loads.
    /// All or nothing, like [`Solver::set_loads`].
    fn set_load_rates(&mut self, rates: &[f64]) -> Result<(), SolverError>;
    /// Advance by `h > 0`, all or nothing (see the trait notes). `Ok(Some(warning))` is
    /// a step taken whose result the model may no longer answer for
    /// ([`SolverWarning`]).
    fn step(&mut self, h: f64) -> Result<Option<SolverWarning>, SolverError>;
    /// Save the complete state as the one a refused step and [`Solver::rewind`] go back
    /// to, for the one step after it. A caller that sets a step's loads and may refuse
    /// the step once it ran takes it before setting them, so that the refusal takes the
    /// loads back too. No allocation once the solver has saved one state.
    fn checkpoint(&mut self);
    /// Go back to the state of the last [`Solver::checkpoint`], after the step that
    /// followed it (accepted or refused); an error, and no change, when no checkpoint
    /// was taken before that step or a state was set since.
    fn rewind(&mut self) -> Result<(), SolverError>;
    /// Whether every entry of the complete state (the numbers [`Solver::state`] saves)
    /// is certainly below `bound` in magnitude: the sum of their squares is below
    /// `bound^2` (false when an entry is not finite). One copy of the state into a
    /// buffer of the solver's own, no allocation once it has held one state: the FMU's
    /// step guard asks it after a step it could not bound in advance, and computes the
    /// outputs only when the state reaches its output bound (`crate::fmu::guard`).
    fn state_below(&mut self, bound: f64) -> bool;
    /// Global positions of the exposed nodes (3 per node).
    fn positions(&self, out: &mut [f64]);
    /// Position value `k` alone (node `k / 3`, component `k % 3`), bit for bit the entry
    /// `k` of [`Solver::positions`], for methods that can give it cheaper than all of
    /// them; `None` means "call `positions`".
    fn position(&self, _k: usize) -> Option<f64> {
        None
    }
    /// Global velocities of the exposed nodes (3 per node).
    fn velocities(&self, out: &mut [f64]);
    /// Global accelerations of the exposed nodes (3 per node).
    fn accelerations(&self, out: &mut [f64]);
    /// Global rotation rates of the exposed nodes (3 per node; zeros without rotational DOFs).
    fn rotation_rates(&self, out: &mut [f64]);
    /// Rotation of each exposed node from its initial orientation, as a rotation vector
    /// (axis times angle, global frame, angle at most pi; 3 per node, zeros without
    /// rotational DOFs). Blocked bodies: the small rotation of the rotational rows, whose
    /// rate is [`Solver::rotation_rates`]. Free bodies: the frame's rotation `P P0^T`
    /// followed by the local small rotation `P sum_j alpha_j Phi_L,j(n)_rot`.
    fn rotations(&self, out: &mut [f64]);
    /// Global angular accelerations of the exposed nodes (3 per node), the time
    /// derivative of [`Solver::rotation_rates`] where the method has it exactly (blocked
    /// bodies); `false` (and `out` untouched) where it does not.
    fn rotation_accelerations(&self, _out: &mut [f64]) -> bool {
        false
    }
    /// Local modal coordinates alpha.
    fn modal(&self) -> &[f64];
    /// Strain energy `1/2 alpha^T K_L alpha`.
    fn strain_energy(&self) -> f64;
    /// Kinetic energy (FORMULATION.md section 3).
    fn kinetic_energy(&self) -> f64;
    /// The moving frame, for free bodies; `None` for blocked ones.
    fn frame(&self) -> Option<Frame>;
    /// The moving frame's rates, for free bodies: the velocity of its origin L0 and its
    /// angular velocity (global components), both from the frame points' velocities
    /// (FORMULATION.md section 2); `None` for blocked bodies. Outputs `frame.vx..wz`.
    fn frame_rates(&self) -> Option<FrameRates> {
        None
    }
    /// Linear momentum of a free body (global components): `s_c^T M v` with `M` the
    /// mass matrix of section 3 for the current frame, `v` the coordinate velocities
    /// and `s_c` the uniform translation of the frame points along axis `c`. Its change
    /// over a step is the impulse of the applied forces (and of gravity), whatever the
    /// body does inside; `None` for blocked bodies, which have no momentum of their own.
    fn momentum(&self) -> Option<[f64; 3]> {
        None
    }
    /// Save the complete state.
    fn state(&self) -> State;
    /// Restore a state saved by a solver built from the same scene and method.
    fn set_state(&mut self, state: &State) -> Result<(), SolverError>;
    /// The method's bound on a step before it is taken, where it has one (the exact
    /// method); `None` for every other.
    fn bounded(&mut self) -> Option<&mut dyn BoundedStep> {
        None
    }
    /// The method as a first-order system its caller integrates (Model Exchange), where
    /// it has one; `None` for every other.
    fn continuous(&mut self) -> Option<&mut dyn continuous::Continuous> {
        None
    }
}

/// A method whose step can be bounded before it is taken: only the exact method, whose
/// step is a fixed linear map per mode. The FMU's step guard uses it to know, before a
/// step under held loads, that the step cannot make any state entry or output
/// non-finite, and then neither saves the state nor checks the outputs.
pub trait BoundedStep: Solver {
    /// How far a step of `h` under held loads (no rate on) can carry
    /// [`BoundedStep::measure`], known before the step. It also holds the coefficients
    /// of that step, so that the step cannot fail, and keeps them until a step of
    /// another size. `None` where the step of `h` cannot be taken at all.
    fn growth(&mut self, h: f64) -> Option<Growth>;
    /// The norm [`BoundedStep::growth`] bounds (for the exact method the energy norm of
    /// the modal state), rounded up.
    fn measure(&self) -> f64;
}

/// Build a solver for a scene with the chosen method.
///
/// Blocked bodies (Iblo=1) are linear and every method handles them. Free bodies
/// (Iblo=0) run the free explicit or implicit method ([`free`]); the exact method needs a
/// blocked body and is refused for them. A truncated scene (one with a residual
/// flexibility) gets the chosen method wrapped in [`residual::Residual`].
///
/// A tip force on the cantilever: the implicit method with full numerical damping
/// (`rho_inf = 0`) and steps far longer than every period settles on the static
/// deflection, which Euler-Bernoulli theory gives as `F L^3 / (3 E I)` =
/// 1 N x 1 m^3 / (3 x 210e9 Pa x 1.152e-9 m^4) = 1.377866e-3 m, as does the full
/// finite-element model in fixtures/cantilever.ref.json.
///
/// ```
/// use std::{path::Path, sync::Arc};
///
/// use fxbody::body::load as load_body;
/// use fxbody::scene::Scene;
/// use fxbody::solver::{Method, Options, build};
///
/// let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/cantilever.fxb");
/// let body = load_body(&path, Default::default())?;
/// let tip = body.node_index(121).ok_or("no tip node")?;
/// let scene = Scene::new(Arc::new(body), vec![tip], vec![[1.0, 0.0, 0.0]]);
/// let opts = Options { rho_inf: 0.0, ..Options::default() };
/// let mut solver = build(&scene, Method::Implicit, &opts)?;
/// solver.set_loads(&[0.0, 1.0, 0.0, 0.0, 0.0, 0.0])?; // fx fy fz mx my mz at the tip
/// for _ in 0..20 {
///     solver.step(1.0)?;
/// }
/// let mut x = [0.0; 3];
/// solver.positions(&mut x);
/// assert!((x[1] - 1.377866e-3).abs() < 1e-6 * 1.377866e-3, "tip y = {} m", x[1]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn build(
    scene: &Scene,
    method: Method,
    opts: &Options,
) -> Result<Box<dyn Solver>, SolverError> {
    let s = build_method(scene, method, opts)?;
    // A start no step could leave (gravity, initial velocity or spin, or damping so large
    // that the initial accelerations overflow) is refused here, once, rather than as a
    // step that fails and a state that cannot be put back.
    let state = s.state();
    if state.data.iter().any(|x| !x.is_finite()) {
        return Err(SolverError::Invalid(Invalid::InitialState));
    }
    Ok(s)
}

/// [`build`] before the check of the initial state.
fn build_method(
    scene: &Scene,
    method: Method,
    opts: &Options,
) -> Result<Box<dyn Solver>, SolverError> {
    // A truncated scene: the kept modes by the chosen method, plus the dropped modes'
    // quasi-static displacement (residual.rs).
    if scene.residual.is_some() {
        let mut bare = scene.clone();
        bare.residual = None;
        let inner = build_method(&bare, method, opts)?;
        return Ok(Box::new(residual::Residual::new(scene, inner)?));
    }
    if !scene.body.is_blocked() {
        return match method {
            Method::Explicit => Ok(Box::new(free::Explicit::new(scene, opts)?)),
            Method::Implicit => Ok(Box::new(free::Implicit::new(scene, opts)?)),
            Method::Split => Ok(Box::new(free::Split::new(scene, opts)?)),
            Method::Exact => Err(SolverError::Unsupported {
                method,
                why: Unsupported::NeedsBlocked,
            }),
        };
    }
    match method {
        Method::Split => Err(SolverError::Unsupported {
            method,
            why: Unsupported::NeedsFree,
        }),
        Method::Exact => Ok(Box::new(Exact::new(scene, opts)?)),
        Method::Implicit => Ok(Box::new(Implicit::new(scene, opts)?)),
        Method::Explicit => Ok(Box::new(Explicit::new(scene, opts)?)),
    }
}
