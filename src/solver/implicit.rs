//! Generalised-alpha (Chung and Hulbert) for a blocked body.
//!
//! With `alpha_m = (2 rho - 1)/(rho + 1)`, `alpha_f = rho/(rho + 1)`,
//! `gamma = 1/2 - alpha_m + alpha_f`, `beta = (1 - alpha_m + alpha_f)^2 / 4`, the step
//! solves `M a_(n+1-alpha_m) + C v_(n+1-alpha_f) + K q_(n+1-alpha_f) = F(t_(n+1-alpha_f))`
//! with Newmark's updates for q and v: second order, unconditionally stable, and the
//! spectral radius at infinite frequency is `rho_inf`. One linear solve per step with
//! the SPD matrix `(1-alpha_m) M + (1-alpha_f)(gamma h C + beta h^2 K)`, factorised once
//! per distinct step size into storage allocated at build time (two sizes are kept, so a
//! constant step with an odd last step does not refactorise).
//!
//! The acceleration is the method's own variable, carried from step to step. Before the
//! first step it is set from the equation of motion whenever the loads change, so that
//! a start under load is consistent.
//!
//! State layout (`State::data`): time, the load part (`t_set`, 6m loads, 6m rates), a
//! started flag (0 or 1), then q, v, a (nL each).

use nalgebra::{DMatrix, DVector};

use super::dense::{cholesky_in_place, cholesky_solve, quadratic};
use super::nodes::{Exposed, check_state};
use super::{Frame, Method, Solver, SolverError, State};
use crate::scene::Scene;

/// Largest number of modes for which the inverse of the effective matrix is stored
/// instead of its Cholesky factor (measured: the inverse is faster at 20 and 100 modes,
/// the factor at 200).
pub const INVERSE_MAX_MODES: usize = 128;

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
    m: DVector<f64>,
    k: DMatrix<f64>,
    ra: f64,
    rb: f64,
    p: AlphaParams,
    started: bool,
    q: DVector<f64>,
    v: DVector<f64>,
    a: DVector<f64>,
    rhs: DVector<f64>,
    w: DVector<f64>,
    cache_h: [f64; 2],
    /// For the step sizes in `cache_h`: `S^-1` when `use_inverse`, else the Cholesky
    /// factor of S.
    slots: [DMatrix<f64>; 2],
    /// Factorisation workspace (used only with `use_inverse`).
    chol: DMatrix<f64>,
    use_inverse: bool,
    /// Solution workspace (the new acceleration).
    a1: DVector<f64>,
    next_slot: usize,
}

impl Implicit {
    /// Build from a blocked scene; `rho_inf` must lie in [0, 1].
    pub fn new(scene: &Scene, rho_inf: f64) -> Result<Implicit, SolverError> {
        if !(0.0..=1.0).contains(&rho_inf) {
            return Err(SolverError::Unsupported {
                method: Method::Implicit,
                why: format!("rho_inf must lie in [0, 1], got {rho_inf}"),
            });
        }
        let body = &scene.body;
        let nl = body.nl();
        let io = Exposed::new(scene, &DMatrix::identity(nl, nl))?;
        let (ra, rb) = body.damping.map_or((0.0, 0.0), |r| (r.alpha, r.beta));
        Ok(Implicit {
            time: 0.0,
            io,
            m: body.m_l.clone(),
            k: body.k_l.clone(),
            ra,
            rb,
            p: AlphaParams::new(rho_inf),
            started: false,
            q: DVector::zeros(nl),
            v: DVector::zeros(nl),
            a: DVector::zeros(nl),
            rhs: DVector::zeros(nl),
            w: DVector::zeros(nl),
            cache_h: [f64::NAN; 2],
            slots: [DMatrix::zeros(nl, nl), DMatrix::zeros(nl, nl)],
            chol: DMatrix::zeros(if nl <= INVERSE_MAX_MODES { nl } else { 0 }, nl),
            use_inverse: nl <= INVERSE_MAX_MODES,
            a1: DVector::zeros(nl),
            next_slot: 0,
        })
    }

    /// Acceleration from the equation of motion at the current time:
    /// `M^-1 (F - C v - K q)`.
    fn consistent_acceleration(&mut self) {
        self.io.force_into(self.time, &mut self.rhs);
        self.w.copy_from(&self.q);
        self.w.axpy(self.rb, &self.v, 1.0);
        self.rhs.gemv(-1.0, &self.k, &self.w, 1.0);
        for i in 0..self.a.len() {
            self.a[i] = (self.rhs[i] - self.ra * self.m[i] * self.v[i]) / self.m[i];
        }
    }

    /// The slot holding the factorised matrix for step `h`, factorising if needed.
    fn factor(&mut self, h: f64) -> Result<usize, SolverError> {
        if let Some(slot) = self.cache_h.iter().position(|&c| c == h) {
            return Ok(slot);
        }
        let slot = self.next_slot;
        self.next_slot = 1 - slot;
        let p = self.p;
        let cm = (1.0 - p.am) + (1.0 - p.af) * p.gamma * h * self.ra;
        let ck = (1.0 - p.af) * (p.gamma * h * self.rb + p.beta * h * h);
        let s = if self.use_inverse {
            &mut self.chol
        } else {
            &mut self.slots[slot]
        };
        s.copy_from(&self.k);
        s.scale_mut(ck);
        for i in 0..self.m.len() {
            s[(i, i)] += cm * self.m[i];
        }
        self.cache_h[slot] = f64::NAN;
        cholesky_in_place(s).map_err(|col| {
            SolverError::Singular(format!(
                "generalised-alpha matrix not positive definite at column {col} for step {h}"
            ))
        })?;
        if self.use_inverse {
            // Columns of S^-1: solve for the unit vectors, in the preallocated a1.
            for j in 0..self.m.len() {
                self.a1.fill(0.0);
                self.a1[j] = 1.0;
                cholesky_solve(&self.chol, &mut self.a1);
                self.slots[slot].set_column(j, &self.a1);
            }
        }
        self.cache_h[slot] = h;
        Ok(slot)
    }

    fn state_len(&self) -> usize {
        2 + self.io.saved_len() + 3 * self.q.len()
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
        self.io.force_into(self.time + c * h, &mut self.rhs);
        // w = q_(n+1-af) without the a_(n+1) part, plus beta_R times the same for v.
        let (cq_v, cq_a) = (c * h, c * h * h * (0.5 - p.beta));
        let cv_a = c * h * (1.0 - p.gamma);
        let (rb, ra, am) = (self.rb, self.ra, p.am);
        for ((((w, r), &q), &v), (&a, &m)) in self
            .w
            .iter_mut()
            .zip(self.rhs.iter_mut())
            .zip(self.q.iter())
            .zip(self.v.iter())
            .zip(self.a.iter().zip(self.m.iter()))
        {
            let u = v + cv_a * a;
            *w = q + cq_v * v + cq_a * a + rb * u;
            *r -= m * (am * a + ra * u);
        }
        self.rhs.gemv(-1.0, &self.k, &self.w, 1.0);
        if self.use_inverse {
            self.a1.gemv(1.0, &self.slots[slot], &self.rhs, 0.0);
        } else {
            self.a1.copy_from(&self.rhs);
            cholesky_solve(&self.slots[slot], &mut self.a1);
        }
        let (h2, bb, g) = (h * h, p.beta, p.gamma);
        for (((q, v), a), &a1) in self
            .q
            .iter_mut()
            .zip(self.v.iter_mut())
            .zip(self.a.iter_mut())
            .zip(self.a1.iter())
        {
            let a0 = *a;
            *q += h * *v + h2 * ((0.5 - bb) * a0 + bb * a1);
            *v += h * ((1.0 - g) * a0 + g * a1);
            *a = a1;
        }
        self.time += h;
        self.started = true;
        Ok(())
    }

    fn positions(&self, out: &mut [f64]) {
        self.io.positions(&self.q, out);
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

    fn modal(&self) -> &[f64] {
        self.q.as_slice()
    }

    fn strain_energy(&self) -> f64 {
        0.5 * quadratic(&self.k, &self.q)
    }

    fn kinetic_energy(&self) -> f64 {
        0.5 * self
            .m
            .iter()
            .zip(self.v.iter())
            .map(|(m, v)| m * v * v)
            .sum::<f64>()
    }

    fn frame(&self) -> Option<Frame> {
        None
    }

    fn state(&self) -> State {
        let mut data = Vec::with_capacity(self.state_len());
        data.push(self.time);
        self.io.save(&mut data);
        data.push(if self.started { 1.0 } else { 0.0 });
        data.extend(self.q.iter());
        data.extend(self.v.iter());
        data.extend(self.a.iter());
        State {
            method: Method::Implicit,
            data,
        }
    }

    fn set_state(&mut self, state: &State) -> Result<(), SolverError> {
        check_state(state, Method::Implicit, self.state_len())?;
        let d = &state.data;
        let nl = self.q.len();
        let k = 1 + self.io.saved_len();
        self.time = d[0];
        self.io.restore(&d[1..k]);
        self.started = d[k] != 0.0;
        let k = k + 1;
        self.q.copy_from_slice(&d[k..k + nl]);
        self.v.copy_from_slice(&d[k + nl..k + 2 * nl]);
        self.a.copy_from_slice(&d[k + 2 * nl..k + 3 * nl]);
        Ok(())
    }
}
