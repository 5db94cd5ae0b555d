//! Generalised-alpha (Chung and Hulbert) for a blocked body.
//!
//! With `alpha_m = (2 rho - 1)/(rho + 1)`, `alpha_f = rho/(rho + 1)`,
//! `gamma = 1/2 - alpha_m + alpha_f`, `beta = (1 - alpha_m + alpha_f)^2 / 4`, the step
//! solves `M a_(n+1-alpha_m) + C v_(n+1-alpha_f) + K q_(n+1-alpha_f) = F(t_(n+1-alpha_f))`
//! with Newmark's updates for q and v: second order, unconditionally stable, and the
//! spectral radius at infinite frequency is `rho_inf`.
//!
//! The scheme is linear and its matrices are combinations of M, K and the Rayleigh
//! damping `C = alpha M + beta K`, so it commutes with the change to the mass-normalised
//! modes `q = S y` (see [`modal_basis`]): applied to every mode separately it gives the
//! same numbers as applied to the coupled system, up to round-off. The step is then one
//! scalar recursion per mode (the effective matrix is diagonal, its inverse stored per
//! step size, two sizes kept), with loads and outputs going straight through the exposed
//! rows in the modal basis, like the exact method. The local coordinates `alpha = S y`
//! are formed only when `modal()` asks for them.
//!
//! The acceleration is the method's own variable, carried from step to step. Before the
//! first step it is set from the equation of motion whenever the loads change, so that
//! a start under load is consistent.
//!
//! State layout (`State::data`): time, the load part (`t_set`, 6m loads, 6m rates), a
//! started flag (0 or 1), then the modal y, y', y'' (nL each, in the order of the modal
//! basis).

use nalgebra::DVector;

use super::damping::LocalDamping;
use super::nodes::{Exposed, LocalCoords, check_state, modal_basis, modal_strain_energy};
use super::{Frame, Method, Options, Solver, SolverError, State};
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
    /// `S = m^-1/2 V`, physical from modal coordinates.
    basis: nalgebra::DMatrix<f64>,
    /// `omega^2` per mode.
    w2: Vec<f64>,
    /// Modal damping `alpha + beta omega^2 (+ 2 zeta omega)`.
    damp: Vec<f64>,
    p: AlphaParams,
    started: bool,
    y: DVector<f64>,
    v: DVector<f64>,
    a: DVector<f64>,
    alpha: LocalCoords,
    cache_h: [f64; 2],
    /// For the step sizes in `cache_h`: the inverse of each mode's effective mass
    /// `(1-alpha_m) + (1-alpha_f)(gamma h d + beta h^2 omega^2)`.
    inv: [Vec<f64>; 2],
    next_slot: usize,
}

impl Implicit {
    /// Build from a blocked scene; `opts.rho_inf` must lie in [0, 1]. The modal damping
    /// is [`LocalDamping::modal`] (Rayleigh plus the added ratio).
    pub fn new(scene: &Scene, opts: &Options) -> Result<Implicit, SolverError> {
        let rho_inf = opts.rho_inf;
        if !(0.0..=1.0).contains(&rho_inf) {
            return Err(SolverError::Unsupported {
                method: Method::Implicit,
                why: format!(
                    "rho_inf must lie in [0, 1], got {}",
                    crate::num::num(rho_inf)
                ),
            });
        }
        let body = &scene.body;
        let nl = body.nl();
        let (basis, omega) = modal_basis(body);
        let io = Exposed::new(scene, &basis)?;
        let damping = LocalDamping::new(body, opts.damping_ratio)?;
        let w2: Vec<f64> = omega.iter().map(|&w| w * w).collect();
        let damp = omega.iter().map(|&w| damping.modal(w)).collect();
        Ok(Implicit {
            time: 0.0,
            io,
            basis,
            w2,
            damp,
            p: AlphaParams::new(rho_inf),
            started: false,
            y: DVector::zeros(nl),
            v: DVector::zeros(nl),
            a: DVector::zeros(nl),
            alpha: LocalCoords::new(nl),
            cache_h: [f64::NAN; 2],
            inv: [vec![0.0; nl], vec![0.0; nl]],
            next_slot: 0,
        })
    }

    /// Acceleration from the equation of motion at the current time, mode by mode:
    /// `f - d y' - omega^2 y`.
    fn consistent_acceleration(&mut self) {
        for j in 0..self.y.len() {
            self.a[j] =
                self.io.force(j, self.time) - self.damp[j] * self.v[j] - self.w2[j] * self.y[j];
        }
    }

    /// The slot holding the inverse effective masses for step `h`, computing them if
    /// needed.
    fn factor(&mut self, h: f64) -> Result<usize, SolverError> {
        if let Some(slot) = self.cache_h.iter().position(|&c| c == h) {
            return Ok(slot);
        }
        let slot = self.next_slot;
        let p = self.p;
        let c = 1.0 - p.af;
        for (j, inv) in self.inv[slot].iter_mut().enumerate() {
            let s = (1.0 - p.am) + c * (p.gamma * h * self.damp[j] + p.beta * h * h * self.w2[j]);
            if !(s > 0.0 && s.is_finite()) {
                self.cache_h[slot] = f64::NAN;
                return Err(SolverError::Singular(format!(
                    "generalised-alpha effective mass of mode {j} is {} for step {} s",
                    crate::num::num(s),
                    crate::num::num(h)
                )));
            }
            *inv = 1.0 / s;
        }
        self.next_slot = 1 - slot;
        self.cache_h[slot] = h;
        Ok(slot)
    }

    fn state_len(&self) -> usize {
        2 + self.io.saved_len() + 3 * self.y.len()
    }
}

impl Solver for Implicit {
    fn method(&self) -> Method {
        Method::Implicit
    }

    fn time(&self) -> f64 {
        self.time
    }

    fn set_loads(&mut self, loads: &[f64]) -> Result<(), SolverError> {
        self.io.set_loads(loads, self.time)?;
        if !self.started {
            self.consistent_acceleration();
        }
        Ok(())
    }

    fn set_load_rates(&mut self, rates: &[f64]) -> Result<(), SolverError> {
        self.io.set_rates(rates, self.time)?;
        if !self.started {
            self.consistent_acceleration();
        }
        Ok(())
    }

    fn step(&mut self, h: f64) -> Result<(), SolverError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(SolverError::BadStep(h));
        }
        let slot = self.factor(h)?;
        let p = self.p;
        let c = 1.0 - p.af;
        // Load at t_(n+1-alpha_f).
        let dtf = self.time + c * h - self.io.held.t_set;
        // Per mode, with u = v_(n+1-af) and w = q_(n+1-af) without their a_(n+1) parts:
        // s a1 = f - am a - d u - omega^2 w, then Newmark's updates.
        let (cq_v, cq_a) = (c * h, c * h * h * (0.5 - p.beta));
        let cv_a = c * h * (1.0 - p.gamma);
        let (h2, bb, g, am) = (h * h, p.beta, p.gamma, p.am);
        let n = self.y.len();
        let inv = &self.inv[slot][..n];
        let (w2, d) = (&self.w2[..n], &self.damp[..n]);
        let (f, fd) = (&self.io.f.as_slice()[..n], &self.io.fd.as_slice()[..n]);
        let y = &mut self.y.as_mut_slice()[..n];
        let v = &mut self.v.as_mut_slice()[..n];
        let a = &mut self.a.as_mut_slice()[..n];
        for j in 0..n {
            let (y0, v0, a0) = (y[j], v[j], a[j]);
            let u = v0 + cv_a * a0;
            let w = y0 + cq_v * v0 + cq_a * a0;
            let r = (f[j] + fd[j] * dtf) - am * a0 - d[j] * u - w2[j] * w;
            let a1 = r * inv[j];
            y[j] = y0 + h * v0 + h2 * ((0.5 - bb) * a0 + bb * a1);
            v[j] = v0 + h * ((1.0 - g) * a0 + g * a1);
            a[j] = a1;
        }
        self.time += h;
        self.started = true;
        self.alpha.invalidate();
        Ok(())
    }

    fn positions(&self, out: &mut [f64]) {
        self.io.positions(&self.y, out);
    }

    fn position(&self, k: usize) -> Option<f64> {
        self.io.position(k, &self.y)
    }

    fn velocities(&self, out: &mut [f64]) {
        self.io.translations(&self.v, out);
    }

    fn accelerations(&self, out: &mut [f64]) {
        self.io.translations(&self.a, out);
    }

    fn rotation_rates(&self, out: &mut [f64]) {
        self.io.rotations(&self.v, out);
    }

    fn rotations(&self, out: &mut [f64]) {
        self.io.rotations(&self.y, out);
    }

    fn rotation_accelerations(&self, out: &mut [f64]) -> bool {
        self.io.rotations(&self.a, out);
        true
    }

    fn modal(&self) -> &[f64] {
        self.alpha.get(&self.basis, &self.y)
    }

    fn strain_energy(&self) -> f64 {
        modal_strain_energy(&self.y, &self.w2)
    }

    fn kinetic_energy(&self) -> f64 {
        0.5 * self.v.norm_squared()
    }

    fn frame(&self) -> Option<Frame> {
        None
    }

    fn state(&self) -> State {
        let mut s = State {
            method: Method::Implicit,
            data: Vec::with_capacity(self.state_len()),
        };
        self.state_into(&mut s);
        s
    }

    fn state_into(&self, out: &mut State) {
        out.method = Method::Implicit;
        let data = &mut out.data;
        data.clear();
        data.push(self.time);
        self.io.save(data);
        data.push(if self.started { 1.0 } else { 0.0 });
        data.extend_from_slice(self.y.as_slice());
        data.extend_from_slice(self.v.as_slice());
        data.extend_from_slice(self.a.as_slice());
    }

    fn set_state(&mut self, state: &State) -> Result<(), SolverError> {
        check_state(state, Method::Implicit, self.state_len())?;
        let d = &state.data;
        let nl = self.y.len();
        let k = 1 + self.io.saved_len();
        self.time = d[0];
        self.io.restore(&d[1..k]);
        self.started = d[k] != 0.0;
        let k = k + 1;
        self.y.copy_from_slice(&d[k..k + nl]);
        self.v.copy_from_slice(&d[k + nl..k + 2 * nl]);
        self.a.copy_from_slice(&d[k + 2 * nl..k + 3 * nl]);
        self.alpha.invalidate();
        Ok(())
    }
}
