//! The reference central-difference scheme (FORMULATION.md section 4) for a blocked body,
//! sub-cycled inside each communication step.
//!
//! Velocities live at half steps. One internal step of size dt2 after a step dt1:
//! `S = F(t) - K q - (beta K + C_zeta + a_R diag m) v^(n-1/2)` (stiffness and added modal
//! damping lagged, [`super::damping`]),
//! `a = S / (m (1 + a_R dt2/2))` (mass damping semi-implicit),
//! `v^(n+1/2) = v^(n-1/2) + (dt1 + dt2)/2 a`, `q^(n+1) = q^n + dt2 v^(n+1/2)`. The first
//! cycle has dt1 = 0, so `v^(1/2) = v^0 + dt2/2 a^0`.
//!
//! Loads between communication points are the caller's model (held, or linear with
//! rates). A held load that jumps at a communication point t_k is integrated with its
//! exact impulse: the velocity update that straddles t_k covers `dt1/2` under the old
//! load (its value reached at t_k) and `dt2/2` under the new one, so the effective force
//! is `(F_old(t_k) dt1 + F_new(t_k) dt2) / (dt1 + dt2)`. For a continuous load this is
//! the usual `F(t_k)`; for a rectangular pulse it keeps the impulse right (otherwise half
//! an internal step of load is lost at each jump).
//!
//! A communication step h is cut into `n = ceil(h / (dt_factor dt_fx))` equal internal
//! steps that land exactly on its end, dt_fx being the stable step of the largest
//! eigenfrequency of (K_L, m_L) with the lagged damping (`LocalDamping::explicit_stable_step`:
//! `Body::explicit_stable_step`, which `fxbody info` reports, without an added ratio).
//! `Options::subcycle = false` takes one internal step of size h (a test switch: it is
//! unstable past dt_fx).
//!
//! Outputs at a communication point t^(n+1): positions are q^(n+1). The velocity output
//! is the full-step estimate `v^(n+1) = v^(n+1/2) + dt2/2 a^(n+1)`, with `a^(n+1)` the
//! acceleration the next cycle would compute from the loads held at t^(n+1) and the last
//! internal step size; it is second order, and it is also the acceleration output. The
//! product `K (q + beta v)` of the current state is kept, so the end-of-step estimate
//! costs no extra matrix product.
//!
//! State layout (`State::data`): time, the load part (`t_set`, 6m loads, 6m rates),
//! dt1, then q, v^(n-1/2) and the generalised load reached at the end of the last step
//! under the load model of that step (nL each).

use nalgebra::{DMatrix, DVector};

use super::damping::LocalDamping;
use super::dense::bilinear;
use super::nodes::{Exposed, check_state};
use super::rollback::{Restorable, Rollback, rollback_items};
use super::{
    Frame, MAX_INTERNAL_STEPS, Method, Options, Solver, SolverError, SolverWarning, State,
};
use crate::scene::Scene;

/// The sub-cycled central-difference solver.
#[derive(Debug, Clone)]
pub struct Explicit {
    time: f64,
    io: Exposed,
    m: DVector<f64>,
    k: DMatrix<f64>,
    ra: f64,
    rb: f64,
    dt_max: f64,
    subcycle: bool,
    dt1: f64,
    q: DVector<f64>,
    vh: DVector<f64>,
    /// `K (q + beta vh) + C_zeta vh` for the current q and vh.
    kq: DVector<f64>,
    /// The added modal damping in local coordinates ([`LocalDamping::added_matrix`]),
    /// lagged like the stiffness damping; `None` without it.
    c_add: Option<DMatrix<f64>>,
    w: DVector<f64>,
    acc: DVector<f64>,
    vout: DVector<f64>,
    /// Generalised load at the end of the last step under that step's load model.
    fend: DVector<f64>,
    /// The state a refused step goes back to (used only after a checkpoint: the step
    /// itself cannot fail once it has begun).
    rollback: Rollback,
}

impl Explicit {
    /// Build from a blocked scene.
    pub fn new(scene: &Scene, opts: &Options) -> Result<Explicit, SolverError> {
        if !(opts.dt_factor > 0.0 && opts.dt_factor <= 1.0) {
            return Err(SolverError::Unsupported {
                method: Method::Explicit,
                why: super::Unsupported::DtFactor(opts.dt_factor),
            });
        }
        let body = &scene.body;
        let nl = body.nl();
        let io = Exposed::new(scene, &DMatrix::identity(nl, nl))?;
        let damping = LocalDamping::new(body, opts.damping_ratio)?;
        let (ra, rb) = (damping.alpha, damping.beta);
        let dt_fx = damping.explicit_stable_step(body);
        super::damping::check_explicit_step(dt_fx, opts.damping_ratio)?;
        let mut explicit = Explicit {
            time: 0.0,
            io,
            m: body.m_l.clone(),
            k: body.k_l.clone(),
            ra,
            rb,
            dt_max: opts.dt_factor * dt_fx,
            c_add: damping.added_matrix(body),
            subcycle: opts.subcycle,
            dt1: 0.0,
            q: DVector::zeros(nl),
            vh: DVector::zeros(nl),
            kq: DVector::zeros(nl),
            w: DVector::zeros(nl),
            acc: DVector::zeros(nl),
            vout: DVector::zeros(nl),
            fend: DVector::zeros(nl),
            rollback: Rollback::new(Method::Explicit, 0),
        };
        explicit.rollback = Rollback::new(Method::Explicit, explicit.state_len());
        Ok(explicit)
    }

    /// The largest internal step, `dt_factor dt_fx` (infinite without stiffness).
    pub fn max_internal_step(&self) -> f64 {
        self.dt_max
    }

    /// `acc = S / (m (1 + a_R dt/2))` at time t from the kept `K (q + beta vh)`. With
    /// `straddle`, the force is the impulse-weighted mean of the previous step's end
    /// load (over dt1/2) and the current load (over dt/2).
    fn acceleration(&mut self, t: f64, dt: f64, straddle: bool) {
        let f = 1.0 + 0.5 * self.ra * dt;
        let dts = t - self.io.held.t_set;
        let (wold, wnew) = if straddle && self.dt1 > 0.0 {
            let sum = self.dt1 + dt;
            (self.dt1 / sum, dt / sum)
        } else {
            (0.0, 1.0)
        };
        for i in 0..self.q.len() {
            let now = self.io.f[i] + self.io.fd[i] * dts;
            let force = if wold > 0.0 {
                wold * self.fend[i] + wnew * now
            } else {
                now
            };
            let s = force - self.kq[i] - self.ra * self.m[i] * self.vh[i];
            self.acc[i] = s / (self.m[i] * f);
        }
    }

    fn refresh_products(&mut self) {
        self.w.copy_from(&self.q);
        self.w.axpy(self.rb, &self.vh, 1.0);
        self.kq.gemv(1.0, &self.k, &self.w, 0.0);
        if let Some(c) = &self.c_add {
            self.kq.gemv(1.0, c, &self.vh, 1.0);
        }
    }

    /// Acceleration and full-step velocity estimate at the current time.
    fn update_outputs(&mut self) {
        self.acceleration(self.time, self.dt1, false);
        self.vout.copy_from(&self.vh);
        self.vout.axpy(0.5 * self.dt1, &self.acc, 1.0);
    }

    /// The sub-cycled step; refused before any change when `h` is not a usable step or
    /// needs more internal steps than the budget.
    fn advance(&mut self, h: f64) -> Result<(), SolverError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(SolverError::BadStep(h));
        }
        let n = if self.subcycle {
            (h / self.dt_max).ceil().max(1.0)
        } else {
            1.0
        };
        // Refused before any work: a step that long is a caller error, not a simulation
        // (h = 1e300 would otherwise loop for ever).
        if n > MAX_INTERNAL_STEPS {
            return Err(SolverError::TooManySteps {
                h,
                steps: n,
                internal: self.dt_max,
                max_h: MAX_INTERNAL_STEPS * self.dt_max,
            });
        }
        let n = n as usize;
        let dt2 = h / n as f64;
        let t0 = self.time;
        for i in 0..n {
            let t = t0 + i as f64 * dt2;
            self.acceleration(t, dt2, i == 0);
            let dt12 = 0.5 * (self.dt1 + dt2);
            self.vh.axpy(dt12, &self.acc, 1.0);
            self.q.axpy(dt2, &self.vh, 1.0);
            self.dt1 = dt2;
            self.refresh_products();
        }
        self.time = t0 + h;
        self.io.force_into(self.time, &mut self.fend);
        self.update_outputs();
        Ok(())
    }
}

impl Solver for Explicit {
    fn method(&self) -> Method {
        Method::Explicit
    }

    fn time(&self) -> f64 {
        self.time
    }

    fn set_loads(&mut self, loads: &[f64]) -> Result<(), SolverError> {
        self.io.set_loads(loads, self.time)?;
        self.rollback.touch();
        self.update_outputs();
        Ok(())
    }

    fn set_load_rates(&mut self, rates: &[f64]) -> Result<(), SolverError> {
        self.io.set_rates(rates, self.time)?;
        self.rollback.touch();
        self.update_outputs();
        Ok(())
    }

    /// The step cannot fail once it has begun (a bad step size, or one beyond the budget
    /// of internal steps, is refused before anything changes), so it saves nothing.
    fn step(&mut self, h: f64) -> Result<Option<SolverWarning>, SolverError> {
        Rollback::step(self, false, |s| s.advance(h))?;
        Ok(None)
    }

    rollback_items!();

    fn positions(&self, out: &mut [f64]) {
        self.io.positions(&self.q, out);
    }

    fn position(&self, k: usize) -> Option<f64> {
        self.io.position(k, &self.q)
    }

    fn velocities(&self, out: &mut [f64]) {
        self.io.translations(&self.vout, out);
    }

    fn accelerations(&self, out: &mut [f64]) {
        self.io.translations(&self.acc, out);
    }

    fn rotation_rates(&self, out: &mut [f64]) {
        self.io.rotations(&self.vout, out);
    }

    fn rotations(&self, out: &mut [f64]) {
        self.io.rotations(&self.q, out);
    }

    fn rotation_accelerations(&self, out: &mut [f64]) -> bool {
        self.io.rotations(&self.acc, out);
        true
    }

    fn modal(&self) -> &[f64] {
        self.q.as_slice()
    }

    fn strain_energy(&self) -> f64 {
        0.5 * bilinear(&self.k, self.q.as_slice(), self.q.as_slice())
    }

    /// `1/2 sum m_L v^2` with the full-step velocity estimate.
    fn kinetic_energy(&self) -> f64 {
        0.5 * self
            .m
            .iter()
            .zip(self.vout.iter())
            .map(|(m, v)| m * v * v)
            .sum::<f64>()
    }

    fn frame(&self) -> Option<Frame> {
        None
    }

    fn set_state(&mut self, state: &State) -> Result<(), SolverError> {
        check_state(state, Method::Explicit, self.state_len())?;
        if state.data[1 + self.io.saved_len()] < 0.0 {
            return Err(SolverError::BadState(super::BadState::NegativeStep));
        }
        let parts = &mut [
            std::slice::from_mut(&mut self.dt1),
            self.q.as_mut_slice(),
            self.vh.as_mut_slice(),
            self.fend.as_mut_slice(),
        ];
        self.time = self.io.read_state(state, Method::Explicit, parts)?;
        self.refresh_products();
        self.update_outputs();
        self.rollback.forget();
        Ok(())
    }
}

impl Explicit {
    /// The state after the time and the load part: the last step size, then `q`,
    /// `v^(n-1/2)` and the generalised load at the end of the last step.
    fn parts(&self) -> [&[f64]; 4] {
        [
            std::slice::from_ref(&self.dt1),
            self.q.as_slice(),
            self.vh.as_slice(),
            self.fend.as_slice(),
        ]
    }
}

impl Restorable for Explicit {
    fn rollback(&mut self) -> &mut Rollback {
        &mut self.rollback
    }

    fn write_state(&self, data: &mut Vec<f64>) {
        self.io.write_state(data, self.time, &self.parts());
    }

    fn state_len(&self) -> usize {
        self.io.state_len(&self.parts())
    }
}
