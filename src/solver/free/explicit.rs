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

use std::cell::RefCell;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use super::lu::Lu;
use super::{
    Loads, Model, PAIRS, SINGULAR_RATIO, edge, omega_matrix, point_offset, point_vec,
    singular_error,
};
use crate::scene::Scene;
use crate::solver::nodes::check_state;
use crate::solver::{Frame, Method, Options, Solver, SolverError, State};

/// Mid-step frame of the Irot = 1 rows, predicted with the old half-step velocities:
/// `R = P^n + dt2/2 [v_Lj - v_L0]^(n-1/2)`.
fn mid_frame(p: &Matrix3<f64>, v: &[f64], dt2: f64) -> Matrix3<f64> {
    let mut pm = *p;
    let v0 = point_vec(v, 0);
    for j in 0..3 {
        let de = (point_vec(v, j + 1) - v0) * (dt2 / 2.0);
        for c in 0..3 {
            pm[(c, j)] += de[c];
        }
    }
    pm
}

/// The explicit central-difference solver for a free body.
#[derive(Debug, Clone)]
pub struct Explicit {
    m: Model,
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
    key: Option<(f64, f64)>,
    /// `a` holds the accelerations of the state and steps of `key` with the loads
    /// `loads_at`.
    a_valid: bool,
    loads_at: Vec<f64>,
}

impl Explicit {
    /// Build the solver for a free-body scene, at rest or with the scene's initial
    /// velocity, at t = 0.
    pub fn new(scene: &Scene, opts: &Options) -> Result<Explicit, SolverError> {
        let m = Model::new(scene)?;
        let (nr, nl, nq) = (m.nr, m.nl, m.nq());
        // The same function `fxbody info` reports (one definition of the stable step).
        let dt_fx = scene.body.explicit_stable_step();
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
            key: None,
            a_valid: false,
            loads_at: vec![0.0; 6 * m.nexp],
        };
        let mut s = Explicit {
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
        };
        s.evaluate_outputs()?;
        Ok(s)
    }

    /// Stable step `dt_fx` of the body (before the `dt_factor`).
    pub fn stable_step(&self) -> f64 {
        self.dt_fx
    }

    /// Internal step used for a communication step `h`: the equal split of h at or
    /// below `dt_factor x dt_fx` (h itself without sub-cycling).
    pub fn internal_step(&self, h: f64) -> (usize, f64) {
        let dmax = self.opts.dt_factor * self.dt_fx;
        let n = if self.opts.subcycle && dmax.is_finite() && dmax > 0.0 {
            ((h / dmax).ceil() as usize).max(1)
        } else {
            1
        };
        (n, h / n as f64)
    }

    /// Raw state for checks: positions `q^n`, half-step velocities `v^(n-1/2)` and the
    /// frame `P^n`.
    pub fn raw(&self) -> (&DVector<f64>, &DVector<f64>, &Matrix3<f64>) {
        (&self.q, &self.v, &self.p)
    }

    /// The accelerations of the current positions (steps 2 to 6 of the reference
    /// scheme), for a previous step `dt1` and a next step `dt2`; result in `self.w.a`.
    ///
    /// The saddle-point matrix, M_C, K_C and MVN depend on the state (q, v, P) and the
    /// steps only, not on the loads. They are kept with the key `(dt1, dt2)` until the
    /// state changes, so the evaluation for the synchronised outputs at the end of a
    /// communication step and the first internal step of the next one (same state, and
    /// the same steps when h does not change) share one factorisation; only the
    /// load-dependent right side is rebuilt. The numbers are those of a fresh
    /// evaluation, bit for bit.
    fn accelerations(&mut self, t: f64, dt1: f64, dt2: f64) -> Result<(), SolverError> {
        if self.w.key != Some((dt1, dt2)) {
            self.w.key = None;
            self.factor_matrix(dt1, dt2)?;
            self.w.key = Some((dt1, dt2));
        } else if self.w.a_valid
            && (0..self.w.loads_at.len()).all(|i| self.loads.at(i, t) == self.w.loads_at[i])
        {
            // Same state, steps and loads as the last evaluation: `w.a` is the answer.
            return Ok(());
        }
        self.w.a_valid = false;
        for (i, l) in self.w.loads_at.iter_mut().enumerate() {
            *l = self.loads.at(i, t);
        }
        let m = &self.m;
        let w = &mut self.w;
        let (nr, nl) = (m.nr, m.nl);
        let p = &self.p;
        // Step 2: loads with the current frame.
        m.project_loads(&self.loads, t, p, &mut w.f_r, &mut w.f_l);
        // Step 3: S_L, S_R.
        let alpha = self.q.rows(nr, nl);
        let vl = self.v.rows(nr, nl);
        w.s_l.copy_from(&w.f_l);
        m.add_gravity_local(&w.mc, &mut w.s_l);
        w.s_l.gemv(-1.0, &m.k_l, &alpha, 1.0);
        if m.ray_b != 0.0 {
            w.s_l.gemv(-m.ray_b, &m.k_l, &vl, 1.0);
        }
        for j in 0..nl {
            w.s_l[j] -= m.ray_a * m.m_l[j] * vl[j];
        }
        w.s_r.copy_from(&w.f_r);
        w.s_r += &m.g_r;
        w.s_r.gemv(-1.0, &w.kc, &alpha, 1.0);
        w.s_r.gemv(-1.0, &w.mvn, &w.s_l, 1.0);
        w.rhs[..nr].copy_from_slice(w.s_r.as_slice());
        // Step 4: right side of the constraint rows (scaled like the rows).
        let sc = m.mass_scale;
        let v = self.v.as_slice();
        for (r, &(a, b, c)) in PAIRS.iter().enumerate() {
            let d = edge(p, a) - edge(p, b);
            let wv = point_vec(v, a) - point_vec(v, b);
            let rhs = (c - d.norm_squared()) / (dt2 * (dt1 + dt2))
                - (2.0 * d + dt2 * wv).dot(&wv) / (dt1 + dt2);
            w.rhs[nr + r] = -sc * rhs;
        }
        if m.irot {
            let bm = omega_matrix(&mid_frame(p, v, dt2));
            let dt12 = (dt1 + dt2) / 2.0;
            for r in 0..3 {
                let mut bv = 0.0;
                for (i, &bri) in bm[r].iter().enumerate() {
                    bv += bri * v[i];
                }
                w.rhs[nr + 6 + r] = -sc * (bv - v[12 + r]) / dt12;
            }
        }
        // Step 5: solve the saddle-point system.
        let nc = m.nc();
        w.kkt.solve(&mut w.rhs[..nr + nc]);
        // Step 6: local accelerations.
        let f2 = 1.0 + m.ray_a * dt2 / 2.0;
        w.a.as_mut_slice()[..nr].copy_from_slice(&w.rhs[..nr]);
        {
            let a = w.a.as_mut_slice();
            let (ar, al) = a.split_at_mut(nr);
            let mvn = w.mvn.as_slice();
            for (j, x) in al.iter_mut().enumerate() {
                let mut s = w.s_l[j] / (m.m_l[j] * f2);
                for (&y, &ai) in mvn[j * nr..(j + 1) * nr].iter().zip(ar.iter()) {
                    s -= y * ai;
                }
                *x = s;
            }
        }
        if w.a.iter().any(|x| !x.is_finite()) {
            return Err(SolverError::Singular(
                "accelerations are not finite (loads or step too large?)".into(),
            ));
        }
        w.a_valid = true;
        Ok(())
    }

    /// The load-independent part of steps 2 to 5: M_C, K_C, MVN and the factored
    /// saddle-point matrix for the current state and the steps `dt1`, `dt2`.
    fn factor_matrix(&mut self, dt1: f64, dt2: f64) -> Result<(), SolverError> {
        let m = &self.m;
        let w = &mut self.w;
        let (nr, nl) = (m.nr, m.nl);
        let p = &self.p;
        // Step 2: M_C and K_C.
        m.frame_matrices(p, &mut w.mc, &mut w.kc);
        // Step 3: MVN.
        let f1 = 1.0 + m.ray_a * dt1 / 2.0;
        {
            let mc = w.mc.as_slice();
            let mvn = w.mvn.as_mut_slice();
            for j in 0..nl {
                let s = 1.0 / (m.m_l[j] * f1);
                for (x, &y) in mvn[j * nr..(j + 1) * nr]
                    .iter_mut()
                    .zip(&mc[j * nr..(j + 1) * nr])
                {
                    *x = y * s;
                }
            }
        }
        // Step 5 matrix, upper-left block: M* = M_R - MVN M_C^T. It is symmetric (MVN
        // is M_C scaled by column), so the upper triangle is formed row by row and
        // mirrored: half the work, and exactly symmetric.
        w.kkt.clear();
        {
            let (mvn, mc) = (w.mvn.as_slice(), w.mc.as_slice());
            for i in 0..nr {
                let row = &mut w.kkt.row_mut(i)[i..nr];
                for (k, x) in row.iter_mut().enumerate() {
                    *x = m.m_r[(i, i + k)];
                }
                for j in 0..nl {
                    let ai = mvn[j * nr + i];
                    for (x, &bk) in row.iter_mut().zip(&mc[j * nr + i..(j + 1) * nr]) {
                        *x -= ai * bk;
                    }
                }
            }
            for i in 1..nr {
                for k in 0..i {
                    *w.kkt.at(i, k) = *w.kkt.at(k, i);
                }
            }
        }
        // Step 4: constraint rows, scaled by the mass scale so that the saddle-point
        // matrix is well balanced (lambda is scaled alike and not needed).
        let sc = m.mass_scale;
        let v = self.v.as_slice();
        for (r, &(a, b, _)) in PAIRS.iter().enumerate() {
            let d = edge(p, a) - edge(p, b);
            let wv = point_vec(v, a) - point_vec(v, b);
            let g = d + dt2 * wv;
            let row = nr + r;
            for cc in 0..3 {
                let (oa, ob) = (point_offset(a) + cc, point_offset(b) + cc);
                *w.kkt.at(row, oa) -= sc * g[cc];
                *w.kkt.at(row, ob) += sc * g[cc];
                *w.kkt.at(oa, row) -= sc * g[cc];
                *w.kkt.at(ob, row) += sc * g[cc];
            }
        }
        if m.irot {
            let bm = omega_matrix(&mid_frame(p, v, dt2));
            for (r, bmr) in bm.iter().enumerate() {
                let row = nr + 6 + r;
                for (i, &bri) in bmr.iter().enumerate() {
                    *w.kkt.at(row, i) += sc * bri;
                    *w.kkt.at(i, row) += sc * bri;
                }
                *w.kkt.at(row, 12 + r) -= sc;
                *w.kkt.at(12 + r, row) -= sc;
            }
        }
        // Step 5: factor the saddle-point matrix.
        let ratio = w.kkt.factor();
        if ratio.is_nan() || ratio <= SINGULAR_RATIO {
            return Err(singular_error(ratio));
        }
        Ok(())
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
        self.w.key = None;
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
}

impl Solver for Explicit {
    fn method(&self) -> Method {
        Method::Explicit
    }

    fn time(&self) -> f64 {
        self.t
    }

    fn set_loads(&mut self, loads: &[f64]) -> Result<(), SolverError> {
        self.m.check_loads("loads", loads)?;
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

    fn set_load_rates(&mut self, rates: &[f64]) -> Result<(), SolverError> {
        self.m.check_loads("load rates", rates)?;
        self.loads.set_rates(rates, self.t);
        Ok(())
    }

    fn step(&mut self, h: f64) -> Result<(), SolverError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(SolverError::BadStep(h));
        }
        let (n, dt) = self.internal_step(h);
        let t0 = self.t;
        // After a load jump, restart from the synchronised velocities: the old loads act
        // over the half step before this communication point, the new ones from it on.
        if self.jump && self.dt1 > 0.0 {
            self.v.axpy(0.5 * self.dt1, &self.a_out, 1.0);
            self.dt1 = 0.0;
            self.w.key = None;
        }
        self.jump = false;
        for k in 0..n {
            self.substep(dt)?;
            self.t = if k + 1 == n {
                t0 + h
            } else {
                t0 + (k + 1) as f64 * dt
            };
        }
        self.dt_last = dt;
        self.evaluate_outputs()
    }

    fn positions(&self, out: &mut [f64]) {
        self.m.positions(&self.q, &self.p, out);
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

    fn modal(&self) -> &[f64] {
        &self.q.as_slice()[self.m.nr..]
    }

    fn strain_energy(&self) -> f64 {
        self.m.strain_energy(&self.q)
    }

    fn kinetic_energy(&self) -> f64 {
        self.with_velocity(|v| self.m.kinetic_energy(v, &self.p))
    }

    fn frame(&self) -> Option<Frame> {
        Some(self.m.frame(&self.q, &self.p))
    }

    fn state(&self) -> State {
        let mut d = Vec::with_capacity(self.state_len());
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
        self.loads.save(&mut d);
        State {
            method: Method::Explicit,
            data: d,
        }
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
        self.w.key = None;
        Ok(())
    }
}
