//! Generalised-alpha (Chung and Hulbert) for a blocked body.
//!
//! With `alpha_m = (2 rho - 1)/(rho + 1)`, `alpha_f = rho/(rho + 1)`,
//! `gamma = 1/2 - alpha_m + alpha_f`, `beta = (1 - alpha_m + alpha_f)^2 / 4`, the step
//! solves `M a_(n+1-alpha_m) + C v_(n+1-alpha_f) + K q_(n+1-alpha_f) = 0` with Newmark's
//! updates for q and v: second order, unconditionally stable, and the spectral radius at
//! infinite frequency is `rho_inf`.
//!
//! The load is not sampled by the scheme: it is integrated exactly. Over a step the
//! caller's load is the polynomial `f0 + f1 s` (held value, and the rate when input
//! derivatives are set), and a free mass would gain exactly `I1 = f0 h + f1 h^2/2` of
//! velocity and `I2 = f0 h^2/2 + f1 h^3/6` of displacement; Newmark's updates add these
//! to the generalised-alpha increments of the internal forces (stiffness and damping), so
//! `a` is the algorithmic acceleration of the internal forces alone. A load held over a
//! step thus delivers exactly its impulse `F h` whatever it was before (sampling the load
//! at `t_(n+1-alpha_f)` and carrying it in `a` would move half a step of impulse at every
//! jump of a held input), and a load at rest on the static deflection keeps the body
//! there (the static state is a fixed point of the step). The internal forces are
//! integrated exactly as the plain scheme integrates them, so stability, dissipation and
//! order are those of generalised-alpha.
//!
//! The scheme is linear and its matrices are combinations of M, K and the Rayleigh
//! damping `C = alpha M + beta K`, so it commutes with the change to the mass-normalised
//! modes `q = S y` (see [`super::nodes::modal_basis`]): applied to every mode separately it gives the
//! same numbers as applied to the coupled system, up to round-off. The step is then one
//! scalar recursion per mode (the effective matrix is diagonal, its inverse stored per
//! step size, two sizes kept), with loads and outputs going straight through the exposed
//! rows in the modal basis, like the exact method. The local coordinates `alpha = S y`
//! are formed only when `modal()` asks for them.
//!
//! Modes that do not oscillate (damping `d >= 2 omega`, for example with
//! `damping.ratio >= 1`) are advanced exactly, with the exact method's transition
//! (`expm::mode_coefficients`): numerical dissipation of unresolved oscillation,
//! the reason for generalised-alpha, has nothing to act on there, and in its overdamped
//! limit (`d h >> 1`) generalised-alpha moves a mode against a step load by
//! `(gamma - 1/2)^2 / 4 F h^2` that never decays (a cantilever under a tip force with
//! `damping.ratio = 1e6` deflected the wrong way, -6.1e-8 m, where it barely moves).
//!
//! State layout (`State::data`): time, the load part (`t_set`, 6m loads, 6m rates), then
//! the modal y, y' and the internal forces' algorithmic acceleration (nL each, in the
//! order of the modal basis).

use nalgebra::DVector;

use super::expm::mode_coefficients;
use super::nodes::{Exposed, LocalCoords, Modes, modal_solver_items};
use super::rollback::{Restorable, Rollback};
use super::{Method, Options, Solver, SolverError, SolverWarning, State};
use crate::scene::Scene;

/// Generalised-alpha parameters from the spectral radius at infinity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlphaParams {
    /// alpha_m.
    pub am: f64,
    /// alpha_f.
    pub af: f64,
    /// Newmark gamma.
    pub gamma: f64,
    /// Newmark beta.
    pub beta: f64,
}

impl AlphaParams {
    /// Chung-Hulbert parameters for `rho_inf` in [0, 1].
    pub fn new(rho: f64) -> AlphaParams {
        let am = (2.0 * rho - 1.0) / (rho + 1.0);
        let af = rho / (rho + 1.0);
        let gamma = 0.5 - am + af;
        let beta = 0.25 * (1.0 - am + af) * (1.0 - am + af);
        AlphaParams {
            am,
            af,
            gamma,
            beta,
        }
    }
}

/// The generalised-alpha solver.
#[derive(Debug, Clone)]
pub struct Implicit {
    time: f64,
    io: Exposed,
    modes: Modes,
    /// The modes advanced exactly (they do not oscillate: `d >= 2 omega`, `d > 0`).
    exact: Vec<usize>,
    p: AlphaParams,
    y: DVector<f64>,
    v: DVector<f64>,
    /// Algorithmic acceleration of the internal forces (the load is integrated apart).
    a: DVector<f64>,
    /// The acceleration output: `a` plus the load at the current time.
    acc: DVector<f64>,
    alpha: LocalCoords,
    cache_h: [f64; 2],
    /// For the step sizes in `cache_h`: the inverse of each mode's effective mass
    /// `(1-alpha_m) + (1-alpha_f)(gamma h d + beta h^2 omega^2)` (generalised-alpha
    /// modes), or the exact transition's eight coefficients of each exact mode, one after
    /// the other in the order of `exact`.
    inv: [Vec<f64>; 2],
    coef: [Vec<f64>; 2],
    /// The exact modes' new `(y, y', a)` during a step.
    scratch: Vec<(f64, f64, f64)>,
    next_slot: usize,
    /// The state a refused step goes back to (used only after a checkpoint: the step
    /// itself cannot fail once it has begun).
    rollback: Rollback,
}

impl Implicit {
    /// Build from a blocked scene; `opts.rho_inf` must lie in [0, 1]. The modal damping
    /// is [`super::damping::LocalDamping::modal`] (Rayleigh plus the added ratio).
    pub fn new(scene: &Scene, opts: &Options) -> Result<Implicit, SolverError> {
        let rho_inf = opts.rho_inf;
        if !(0.0..=1.0).contains(&rho_inf) {
            return Err(SolverError::Unsupported {
                method: Method::Implicit,
                why: super::Unsupported::RhoInf {
                    value: rho_inf,
                    max: 1.0,
                    free: false,
                },
            });
        }
        let body = &scene.body;
        let nl = body.nl();
        let modes = Modes::new(body, opts.damping_ratio)?;
        let io = Exposed::new(scene, &modes.basis)?;
        let (damp, omega) = (&modes.damp, &modes.omega);
        let exact = (0..nl)
            .filter(|&j| damp[j] > 0.0 && damp[j] >= 2.0 * omega[j])
            .collect::<Vec<_>>();
        let ne = exact.len();
        let mut implicit = Implicit {
            time: 0.0,
            io,
            modes,
            exact,
            p: AlphaParams::new(rho_inf),
            y: DVector::zeros(nl),
            v: DVector::zeros(nl),
            a: DVector::zeros(nl),
            acc: DVector::zeros(nl),
            alpha: LocalCoords::new(nl),
            cache_h: [f64::NAN; 2],
            inv: [vec![0.0; nl], vec![0.0; nl]],
            coef: [vec![0.0; 8 * ne], vec![0.0; 8 * ne]],
            scratch: vec![(0.0, 0.0, 0.0); ne],
            next_slot: 0,
            rollback: Rollback::new(Method::Implicit, 0),
        };
        implicit.rollback = Rollback::new(Method::Implicit, implicit.state_len());
        Ok(implicit)
    }

    /// The acceleration output at the current time: the internal forces' algorithmic
    /// acceleration plus the load now.
    fn refresh(&mut self) {
        for j in 0..self.a.len() {
            self.acc[j] = self.a[j] + self.io.force(j, self.time);
        }
    }

    /// The slot holding the inverse effective masses (and the exact modes'
    /// coefficients) for step `h`, computing them if needed.
    fn factor(&mut self, h: f64) -> Result<usize, SolverError> {
        if let Some(slot) = self.cache_h.iter().position(|&c| c == h) {
            return Ok(slot);
        }
        let slot = self.next_slot;
        let p = self.p;
        let c = 1.0 - p.af;
        for (j, inv) in self.inv[slot].iter_mut().enumerate() {
            let s = (1.0 - p.am)
                + c * (p.gamma * h * self.modes.damp[j] + p.beta * h * h * self.modes.w2[j]);
            // The exact modes have no effective mass (it may overflow): unused.
            *inv = if s > 0.0 && s.is_finite() {
                1.0 / s
            } else {
                f64::NAN
            };
        }
        for (k, &j) in self.exact.iter().enumerate() {
            let cj = mode_coefficients(self.modes.omega[j], self.modes.damp[j], h);
            self.coef[slot][8 * k..8 * k + 8].copy_from_slice(&cj);
        }
        let bad_alpha = (0..self.y.len())
            .filter(|j| !self.exact.contains(j))
            .find(|&j| !self.inv[slot][j].is_finite());
        let bad_exact = self.coef[slot].iter().any(|c| !c.is_finite());
        if bad_alpha.is_some() || bad_exact {
            self.cache_h[slot] = f64::NAN;
            let why = match bad_alpha {
                Some(mode) => super::Unsupported::EffectiveMass { mode, h },
                None => super::Unsupported::OverdampedOverflow(h),
            };
            return Err(SolverError::Unsupported {
                method: Method::Implicit,
                why,
            });
        }
        self.next_slot = 1 - slot;
        self.cache_h[slot] = h;
        Ok(slot)
    }
}

impl Solver for Implicit {
    modal_solver_items!(Method::Implicit, v);

    /// The step cannot fail once it has begun (a bad step size, or one whose effective
    /// masses are not finite, is refused before anything changes), so it saves nothing.
    fn step(&mut self, h: f64) -> Result<Option<SolverWarning>, SolverError> {
        Rollback::step(self, false, |s| s.advance(h))?;
        Ok(None)
    }

    fn accelerations(&self, out: &mut [f64]) {
        self.io.translations(&self.acc, out);
    }

    fn rotation_accelerations(&self, out: &mut [f64]) -> bool {
        self.io.rotations(&self.acc, out);
        true
    }

    fn set_state(&mut self, state: &State) -> Result<(), SolverError> {
        let parts = &mut [
            self.y.as_mut_slice(),
            self.v.as_mut_slice(),
            self.a.as_mut_slice(),
        ];
        self.time = self.io.read_state(state, Method::Implicit, parts)?;
        self.refresh();
        self.alpha.invalidate();
        self.rollback.forget();
        Ok(())
    }
}

impl Restorable for Implicit {
    fn rollback(&mut self) -> &mut Rollback {
        &mut self.rollback
    }

    fn write_state(&self, data: &mut Vec<f64>) {
        let parts = [self.y.as_slice(), self.v.as_slice(), self.a.as_slice()];
        self.io.write_state(data, self.time, &parts);
    }

    fn state_len(&self) -> usize {
        self.io
            .state_len(&[self.y.as_slice(), self.v.as_slice(), self.a.as_slice()])
    }
}

impl Implicit {
    /// One generalised-alpha step of every mode; refused before any change when `h` is
    /// not a usable step.
    fn advance(&mut self, h: f64) -> Result<(), SolverError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(SolverError::BadStep(h));
        }
        let slot = self.factor(h)?;
        let p = self.p;
        let c = 1.0 - p.af;
        // The load over the step is f0 + f1 s: its exact velocity and displacement
        // increments on a free mass, per unit of f0 and of f1.
        let dt0 = self.time - self.io.held.t_set;
        let (h2, h3) = (h * h, h * h * h);
        let (i1_0, i1_1, i2_0, i2_1) = (h, 0.5 * h2, 0.5 * h2, h3 / 6.0);
        // Per mode, with u = v_(n+1-af) and w = q_(n+1-af) without their a_(n+1) parts:
        // s a1 = -am a - d u - omega^2 w, then Newmark's updates plus the load's.
        let (cq_v, cq_a) = (c * h, c * h2 * (0.5 - p.beta));
        let cv_a = c * h * (1.0 - p.gamma);
        let (bb, g, am) = (p.beta, p.gamma, p.am);
        let n = self.y.len();
        let (f, fd) = (&self.io.f.as_slice()[..n], &self.io.fd.as_slice()[..n]);
        // The modes that do not oscillate: exact, into `scratch` first (the loop below
        // runs over every mode), with the internal forces' acceleration taken from the
        // new state (so that a change of step size continues smoothly).
        for (k, &j) in self.exact.iter().enumerate() {
            let cj = &self.coef[slot][8 * k..8 * k + 8];
            let (y0, v0) = (self.y[j], self.v[j]);
            let f0 = f[j] + fd[j] * dt0;
            let y1 = cj[0] * y0 + cj[1] * v0 + cj[2] * f0 + cj[3] * fd[j];
            let v1 = cj[4] * y0 + cj[5] * v0 + cj[6] * f0 + cj[7] * fd[j];
            self.scratch[k] = (y1, v1, -self.modes.damp[j] * v1 - self.modes.w2[j] * y1);
        }
        let inv = &self.inv[slot][..n];
        let (w2, d) = (&self.modes.w2[..n], &self.modes.damp[..n]);
        let y = &mut self.y.as_mut_slice()[..n];
        let v = &mut self.v.as_mut_slice()[..n];
        let a = &mut self.a.as_mut_slice()[..n];
        for j in 0..n {
            let (y0, v0, a0) = (y[j], v[j], a[j]);
            let f0 = f[j] + fd[j] * dt0;
            let i1 = i1_0 * f0 + i1_1 * fd[j];
            let i2 = i2_0 * f0 + i2_1 * fd[j];
            let u = v0 + cv_a * a0 + c * i1;
            let w = y0 + cq_v * v0 + cq_a * a0 + c * i2;
            let a1 = (-am * a0 - d[j] * u - w2[j] * w) * inv[j];
            y[j] = y0 + h * v0 + h2 * ((0.5 - bb) * a0 + bb * a1) + i2;
            v[j] = v0 + h * ((1.0 - g) * a0 + g * a1) + i1;
            a[j] = a1;
        }
        for (k, &j) in self.exact.iter().enumerate() {
            (y[j], v[j], a[j]) = self.scratch[k];
        }
        self.time += h;
        self.refresh();
        self.alpha.invalidate();
        Ok(())
    }
}
