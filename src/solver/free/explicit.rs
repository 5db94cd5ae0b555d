//! The reference explicit scheme for free bodies (FORMULATION.md section 4), step by
//! step as OpenRadioss runs it, sub-cycled inside each communication step at
//! `dt_factor x dt_fx` with equal internal steps that land on the end of the step.
//!
//! Between calls the state holds positions `q^n`, the frame `P^n` and half-step
//! velocities `v^(n-1/2)` with the last step size `dt1` (0 before the first step, which
//! makes the first velocity update `v^(1/2) = v^0 + dt/2 a^0`). After each communication
//! step the accelerations `a^n` are evaluated once more with the loads at the end time,
//! so that the outputs are synchronised: velocity `v^n = v^(n-1/2) + dt1/2 a^n` mapped
//! with the frame `P^n` (the frame of the same instant, as step 8 maps `v^(n+1/2)` with
//! the mid-step frame).
//!
//! Co-simulation addition: when the master changes a held load at a communication point
//! (a jump in value; rates keep the load continuous and need nothing), the next step
//! restarts the scheme from these synchronised velocities (`dt1 = 0`, as at the very
//! first cycle): the old value acts up to that point and the new one from it, so a load
//! held over a step delivers exactly its impulse `F h` (the plain scheme would apply the
//! new value half a step early). Without a jump the internal steps simply continue the
//! reference scheme across communication points (variable steps through dt1, dt2), so
//! N steps of h and one step of N h give the same numbers.
//!
//! A property of the reference scheme worth knowing: the constraint rows act along the
//! predicted edges `d + dt2 w`, not along `d`, which removes rotational kinetic energy at
//! a relative rate of about `omega^2 dt` per unit time (measured 5.7 % over 20 s at
//! omega = 0.71 rad/s, dt = 5 ms, and four times less at dt/4). At real bodies' stable
//! steps (dt_fx of 1e-4 s and below) this is negligible.
//!
//! Irot = 1 adds three rows that tie the rates of rigid DOFs 13..15 to the frame angular
//! velocity (derivation). Section 2 gives local `omega_l = (-e2.e3_dot, e1.e3_dot,
//! -e1.e2_dot)` with `e_j_dot = v_Lj - v_L0` and global `omega = P omega_l`; for a given
//! frame this is linear in the frame-point velocities, `omega = B(P) v_R[0..12]` (see
//! `omega_matrix` (parent module) for B). The condition is imposed on the new half-step
//! velocities, `v_rot^(n+1/2) = B(R) v_12^(n+1/2)`, and with
//! `v^(n+1/2) = v^(n-1/2) + dt12 a` it becomes the acceleration row
//! `a_rot - B a_12 = (B v_12^(n-1/2) - v_rot^(n-1/2)) / dt12`, whose right side also
//! removes any drift of the velocity condition. The frame R is the mid-step frame of
//! step 8, predicted with the old velocities, `R = P^n + dt2/2 [v_Lj - v_L0]^(n-1/2)`,
//! which keeps the row linear. It matters: the section-2 formula uses one entry of each
//! antisymmetric pair, so with `P^n` it is only first-order accurate for a finite frame
//! increment (error about `omega dt / 2`, measured 2e-3 on a test tumble), while with the
//! mid-step frame the pair entries average out and the rate is second-order accurate.

mod accel;
mod halving;
mod stable;

use std::cell::RefCell;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use super::lu::Lu;
use super::{
    FreeScene, Loads, MAX_FRAME_ERROR, SPIN_STEP, checked_step, drag_warning, frame_omega,
    point_vec, spin_warning,
};
use crate::scene::Scene;
use crate::solver::nodes::check_state;
use crate::solver::rollback::{Restorable, Rollback};
use crate::solver::{
    Frame, MAX_INTERNAL_STEPS, Method, Options, Solver, SolverError, SolverWarning, State,
};

/// The explicit central-difference solver for a free body.
#[derive(Debug, Clone)]
pub struct Explicit {
    m: FreeScene,
    opts: Options,
    dt_fx: f64,
    t: f64,
    dt1: f64,
    /// Last internal step size used (for the output evaluation).
    dt_last: f64,
    q: DVector<f64>,
    v: DVector<f64>,
    p: Matrix3<f64>,
    /// Accelerations `a^n` at the current time (synchronised outputs).
    a_out: DVector<f64>,
    /// The loads jumped at the current time: restart the scheme at the next step.
    jump: bool,
    loads: Loads,
    w: Work,
    /// Synchronised coordinate velocities, filled on demand by the output getters
    /// (which take `&self` and must not allocate).
    v_out: RefCell<DVector<f64>>,
    /// The state before the current step, restored when the step fails (sized at
    /// build).
    rollback: Rollback,
    /// The spin-rate warning was raised (once per solver).
    warned: bool,
    /// The load-time check's warning (modes that drag rigid motion: this scheme solves
    /// the Radioss equations, FORMULATION.md section 3), given by the first step.
    drag_warning: Option<SolverWarning>,
    /// Largest rotation per internal step (`SPIN_STEP` unless changed).
    spin_step: f64,
    /// Largest `|P^T P - I|` a step may leave (`MAX_FRAME_ERROR` unless changed).
    frame_tol: f64,
    /// The state before the current internal step, restored when its frame error asks
    /// for halving (preallocated): positions, half-step velocities, frame, `dt1`.
    sub_q: DVector<f64>,
    sub_v: DVector<f64>,
    sub_p: Matrix3<f64>,
    sub_dt1: f64,
    /// Internal steps redone in halves since the solver was built (for checks).
    halved: u64,
}

/// Preallocated storage for one acceleration evaluation.
#[derive(Debug, Clone)]
struct Work {
    mc: DMatrix<f64>,
    kc: DMatrix<f64>,
    mvn: DMatrix<f64>,
    f_r: DVector<f64>,
    f_l: DVector<f64>,
    s_l: DVector<f64>,
    s_r: DVector<f64>,
    a: DVector<f64>,
    kkt: Lu,
    rhs: Vec<f64>,
    /// `(dt1, dt2)` of the matrices above when they belong to the current state.
    key: (f64, f64),
    /// `a` holds the accelerations of the state and steps of `key` with the loads
    /// `loads_at`.
    a_valid: bool,
    loads_at: Vec<f64>,
}

impl Explicit {
    /// Build the solver for a free-body scene, at rest or with the scene's initial
    /// velocity, at t = 0.
    pub fn new(scene: &Scene, opts: &Options) -> Result<Explicit, SolverError> {
        let m = FreeScene::new(scene, opts.damping_ratio)?;
        let (nr, nl, nq) = (m.nr, m.nl, m.nq());
        // The local modes' stable step (the one `fxbody info` reports, shortened by an
        // added damping ratio); shortened below for the modes coupled to the rigid motion.
        let dt_fx = m.dt_fx;
        let mut v = DVector::zeros(nq);
        m.initial_velocity(scene.v0, scene.w0, &mut v);
        let w = Work {
            mc: DMatrix::zeros(nr, nl),
            kc: DMatrix::zeros(nr, nl),
            mvn: DMatrix::zeros(nr, nl),
            f_r: DVector::zeros(nr),
            f_l: DVector::zeros(nl),
            s_l: DVector::zeros(nl),
            s_r: DVector::zeros(nr),
            a: DVector::zeros(nq),
            kkt: Lu::new(nr + m.nc()),
            rhs: vec![0.0; nr + m.nc()],
            key: super::NO_KEY,
            a_valid: false,
            loads_at: vec![0.0; 6 * m.nexp],
        };
        // A body whose modes drag rigid motion is warned about at load (returned by the
        // first step): this scheme stays Radioss's (FORMULATION.md section 3).
        let drag_warning = drag_warning(&m, false);
        let mut s = Explicit {
            drag_warning,
            p: m.p0,
            loads: Loads::new(6 * m.nexp),
            m,
            opts: *opts,
            dt_fx,
            t: 0.0,
            dt1: 0.0,
            dt_last: 0.0,
            q: DVector::zeros(nq),
            v,
            a_out: DVector::zeros(nq),
            jump: false,
            w,
            v_out: RefCell::new(DVector::zeros(nq)),
            rollback: Rollback::new(Method::Explicit, 0),
            warned: false,
            spin_step: SPIN_STEP,
            frame_tol: MAX_FRAME_ERROR,
            sub_q: DVector::zeros(nq),
            sub_v: DVector::zeros(nq),
            sub_p: Matrix3::zeros(),
            sub_dt1: 0.0,
            halved: 0,
        };
        // The stable step of the coupled modes (`stable`), when above the local ones'.
        let coupled = s.coupled_frequency_hz()?;
        if coupled > scene.body.freq_max_hz() {
            s.dt_fx = super::super::damping::LocalDamping::new(&scene.body, opts.damping_ratio)?
                .explicit_stable_step_at(&scene.body, coupled);
            s.m.dt_fx = s.dt_fx;
        }
        crate::solver::damping::check_explicit_step(s.dt_fx, opts.damping_ratio)?;
        s.evaluate_outputs()?;
        s.rollback = Rollback::new(Method::Explicit, s.state_len());
        Ok(s)
    }

    /// Change the two spin-related limits: the largest rotation per internal step and
    /// the largest `|P^T P - I|` a step may leave (infinite: no limit, no check, and no
    /// halving, which starts at `FRAME_RETRY_FRACTION` of it). For
    /// the spin-rate study, which measures the scheme beyond them, and for checks of the
    /// raw scheme's arithmetic at deliberately large steps; the product never calls it.
    pub fn set_spin_limits(&mut self, spin_step: f64, frame_tol: f64) {
        self.spin_step = spin_step;
        self.frame_tol = frame_tol;
    }

    /// How many internal steps were redone in halves because their frame error passed
    /// `FRAME_RETRY_FRACTION x MAX_FRAME_ERROR` (counted over the solver's life, not
    /// saved in the state): 0 means the results are those of the plain scheme.
    pub fn halved_steps(&self) -> u64 {
        self.halved
    }

    /// Stable step `dt_fx` of the body (before the `dt_factor`).
    pub fn stable_step(&self) -> f64 {
        self.dt_fx
    }

    /// Internal step used for a communication step `h` from the current state: the
    /// equal split of h at or below [`Explicit::step_limit`] (h itself without
    /// sub-cycling). The count is a float: for an absurd h it does not fit an integer.
    pub fn internal_step(&self, h: f64) -> (f64, f64) {
        let dmax = self.step_limit();
        let n = if self.opts.subcycle && dmax.is_finite() && dmax > 0.0 {
            (h / dmax).ceil().max(1.0)
        } else {
            1.0
        };
        (n, h / n)
    }

    /// Largest internal step at the current state: `dt_factor x dt_fx`, and
    /// `SPIN_STEP / |omega|` with the frame's spin rate `omega` (from the half-step
    /// velocities): the frame update turns the edges by `|omega| dt` per step, and its
    /// error grows with that angle (docs/STUDY.md, spin-rate stability).
    pub fn step_limit(&self) -> f64 {
        let dmax = self.opts.dt_factor * self.dt_fx;
        let spin = self.spin_rate();
        if spin > 0.0 {
            dmax.min(self.spin_step / spin)
        } else {
            dmax
        }
    }

    /// Spin rate `|omega|` of the frame from the half-step velocities (rad/s).
    fn spin_rate(&self) -> f64 {
        frame_omega(&self.p, self.v.as_slice()).norm()
    }

    /// Raw state for checks: positions `q^n`, half-step velocities `v^(n-1/2)` and the
    /// frame `P^n`.
    pub fn raw(&self) -> (&DVector<f64>, &DVector<f64>, &Matrix3<f64>) {
        (&self.q, &self.v, &self.p)
    }

    /// One internal step of size `dt2` from the current time: accelerations (steps 2-6),
    /// half-step velocities (step 7), then the next positions and frame columns (step 1
    /// of the following cycle).
    fn substep(&mut self, dt2: f64) -> Result<(), SolverError> {
        self.accelerations(self.t, self.dt1, dt2)?;
        let dt12 = (self.dt1 + dt2) / 2.0;
        self.v.axpy(dt12, &self.w.a, 1.0);
        self.q.axpy(dt2, &self.v, 1.0);
        let v = self.v.as_slice();
        let v0 = point_vec(v, 0);
        for j in 0..3 {
            let de = (point_vec(v, j + 1) - v0) * dt2;
            for c in 0..3 {
                self.p[(c, j)] += de[c];
            }
        }
        self.dt1 = dt2;
        self.w.key = super::NO_KEY;
        Ok(())
    }

    /// Accelerations at the current time for the outputs.
    fn evaluate_outputs(&mut self) -> Result<(), SolverError> {
        let dt2 = if self.dt_last > 0.0 {
            self.dt_last
        } else {
            let d = self.opts.dt_factor * self.dt_fx;
            if d.is_finite() && d > 0.0 { d } else { 1e-3 }
        };
        self.accelerations(self.t, self.dt1, dt2)?;
        self.a_out.copy_from(&self.w.a);
        Ok(())
    }

    /// Synchronised velocity `v^n = v^(n-1/2) + dt1/2 a^n`, coordinate `i`.
    #[inline]
    fn v_sync(&self, i: usize) -> f64 {
        self.v[i] + 0.5 * self.dt1 * self.a_out[i]
    }

    /// Synchronised coordinate velocities (allocates; for outputs and tests only).
    pub fn velocity_coordinates(&self) -> DVector<f64> {
        self.with_velocity(|v| v.clone())
    }

    /// Frame angular velocity (global) at the current time.
    pub fn frame_angular_velocity(&self) -> Vector3<f64> {
        self.with_velocity(|v| super::frame_omega(&self.p, v.as_slice()))
    }

    /// Run `f` on the synchronised coordinate velocities, held in the preallocated
    /// `v_out` (no allocation).
    fn with_velocity<R>(&self, f: impl FnOnce(&DVector<f64>) -> R) -> R {
        let mut v = self.v_out.borrow_mut();
        for (i, x) in v.iter_mut().enumerate() {
            *x = self.v_sync(i);
        }
        f(&v)
    }

    fn state_len(&self) -> usize {
        let nq = self.m.nq();
        4 + 3 * nq + 9 + self.loads.state_len()
    }

    /// The state into `d` (cleared first; no allocation once `d` has the capacity).
    fn write_state(&self, d: &mut Vec<f64>) {
        d.clear();
        d.extend_from_slice(&[
            self.t,
            self.dt1,
            self.dt_last,
            f64::from(u8::from(self.jump)),
        ]);
        d.extend_from_slice(self.q.as_slice());
        d.extend_from_slice(self.v.as_slice());
        d.extend_from_slice(self.a_out.as_slice());
        d.extend_from_slice(self.p.as_slice());
        self.loads.save(d);
    }

    /// The sub-cycles of one communication step `h` (after the budget check): equal
    /// internal steps at or below the step limit, the limit re-evaluated before each one
    /// (the spin rate grows under a torque), the rest of the step split again when it
    /// falls below the current step. Every internal step's frame is checked, and an
    /// internal step the frame cannot follow is redone in halves (`checked_substep`).
    fn run_step(&mut self, h: f64) -> Result<(), SolverError> {
        let t0 = self.t;
        let t_end = t0 + h;
        // After a load jump, restart from the synchronised velocities: the old loads act
        // over the half step before this communication point, the new ones from it on.
        if self.jump && self.dt1 > 0.0 {
            self.v.axpy(0.5 * self.dt1, &self.a_out, 1.0);
            self.dt1 = 0.0;
            self.w.key = super::NO_KEY;
        }
        self.jump = false;
        let (n0, dt0) = self.internal_step(h);
        let (mut seg_t0, mut seg_n, mut dt) = (t0, n0, dt0);
        let mut k = 0.0;
        let mut taken = 0.0;
        while k < seg_n {
            if self.opts.subcycle {
                let lim = self.step_limit();
                if dt > lim * (1.0 + 1e-12) {
                    // The spin rate grew: split what is left at the new limit.
                    let rest = t_end - self.t;
                    seg_t0 = self.t;
                    seg_n = (rest / lim).ceil().max(1.0);
                    dt = rest / seg_n;
                    k = 0.0;
                    if taken + seg_n > MAX_INTERNAL_STEPS {
                        return Err(SolverError::TooManySteps {
                            h,
                            steps: taken + seg_n,
                            internal: lim,
                            max_h: MAX_INTERNAL_STEPS * lim,
                        });
                    }
                }
            }
            taken += self.checked_substep(dt, h, taken)?;
            k += 1.0;
            self.t = if k == seg_n { t_end } else { seg_t0 + k * dt };
        }
        self.dt_last = dt;
        self.evaluate_outputs()
    }
}

impl Solver for Explicit {
    free_solver_common!();

    fn method(&self) -> Method {
        Method::Explicit
    }

    fn set_loads(&mut self, loads: &[f64]) -> Result<(), SolverError> {
        self.m.check_loads("loads", loads)?;
        self.rollback.touch();
        let t = self.t;
        // A jump is a change beyond round-off of the value the load function has now (a
        // master re-sending a continuous load computes it in its own way).
        let jumped = loads.iter().enumerate().any(|(i, &l)| {
            let old = self.loads.at(i, t);
            (l - old).abs() > 1e-12 * l.abs().max(old.abs())
        });
        if jumped {
            self.jump = true;
        }
        self.loads.values.copy_from_slice(loads);
        self.loads.t_set = self.t;
        Ok(())
    }

    /// Advance by `h`. Refused before any work when the sub-cycles at the current step
    /// limit exceed [`MAX_INTERNAL_STEPS`] (the limit shrinks as the spin rate grows, so
    /// a spin-up within the step that pushes the count past the budget is refused when
    /// it happens). On any error the state is as before the call.
    fn step(&mut self, h: f64) -> Result<Option<SolverWarning>, SolverError> {
        checked_step(self, h, true, |s| {
            let (n, dt) = s.internal_step(h);
            if n > MAX_INTERNAL_STEPS {
                let internal = s.step_limit();
                return Err(SolverError::TooManySteps {
                    h,
                    steps: n,
                    internal: dt.min(internal),
                    max_h: MAX_INTERNAL_STEPS * internal,
                });
            }
            s.run_step(h)
        })?;
        if let Some(w) = self.drag_warning.take() {
            return Ok(Some(w));
        }
        Ok(spin_warning(
            &self.m,
            self.frame_angular_velocity().norm(),
            &mut self.warned,
        ))
    }

    fn velocities(&self, out: &mut [f64]) {
        // Without allocation: map coordinate by coordinate.
        for k in 0..self.m.nexp.min(out.len() / 3) {
            let mut vn = Vector3::zeros();
            let mut loc = Vector3::zeros();
            let b = 6 * k;
            let (nr, nl) = (self.m.nr, self.m.nl);
            for c in 0..3 {
                let pr = &self.m.phi_r_rows[(b + c) * nr..(b + c) * nr + 12];
                vn[c] = pr
                    .iter()
                    .enumerate()
                    .map(|(i, f)| self.v_sync(i) * f)
                    .sum::<f64>();
                let pl = &self.m.phi_l_rows[(b + c) * nl..(b + c + 1) * nl];
                loc[c] = pl
                    .iter()
                    .enumerate()
                    .map(|(j, f)| self.v_sync(nr + j) * f)
                    .sum::<f64>();
            }
            let x = vn + self.p * loc;
            out[3 * k..3 * k + 3].copy_from_slice(x.as_slice());
        }
    }

    fn accelerations(&self, out: &mut [f64]) {
        self.m.fields(&self.a_out, &self.p, out);
    }

    fn rotation_rates(&self, out: &mut [f64]) {
        self.with_velocity(|v| self.m.rotation_rates(v, &self.p, out));
    }

    fn kinetic_energy(&self) -> f64 {
        self.with_velocity(|v| self.m.kinetic_energy(v, &self.p))
    }

    fn momentum(&self) -> Option<[f64; 3]> {
        Some(self.with_velocity(|v| self.m.momentum(v, &self.p)))
    }

    fn frame_rates(&self) -> Option<crate::solver::FrameRates> {
        Some(self.with_velocity(|v| super::frame_rates(&self.p, v.as_slice())))
    }

    fn set_state(&mut self, state: &State) -> Result<(), SolverError> {
        check_state(state, Method::Explicit, self.state_len())?;
        let nq = self.m.nq();
        let d = &state.data;
        self.t = d[0];
        self.dt1 = d[1];
        self.dt_last = d[2];
        self.jump = d[3] != 0.0;
        let mut o = 4;
        self.q.copy_from_slice(&d[o..o + nq]);
        o += nq;
        self.v.copy_from_slice(&d[o..o + nq]);
        o += nq;
        self.a_out.copy_from_slice(&d[o..o + nq]);
        o += nq;
        self.p.copy_from_slice(&d[o..o + 9]);
        o += 9;
        self.loads.load(&d[o..]);
        self.w.key = super::NO_KEY;
        self.rollback.forget();
        Ok(())
    }
}

impl Restorable for Explicit {
    fn rollback(&mut self) -> &mut Rollback {
        &mut self.rollback
    }

    fn write_state(&self, out: &mut Vec<f64>) {
        Explicit::write_state(self, out);
    }

    fn state_len(&self) -> usize {
        Explicit::state_len(self)
    }
}
