//! Generalised-alpha for free bodies (Chung and Hulbert's parameters, in the form of
//! Arnold and Bruls for constrained systems), not bound by the stable step dt_fx.
//!
//! The equations are those of FORMULATION.md section 3 with the frame constraints kept
//! at position level (index 3): `|d_k(q)|^2 = c_k` for the six frame edges, so the frame
//! is orthonormal to the Newton tolerance at the end of every step. With Irot = 1 the
//! three rows that tie the rotational DOF rates to the frame angular velocity are
//! velocity constraints, `B(P) v_12 - v_rot = 0`, imposed at the end of the step.
//!
//! One step of size h from `(q_n, v_n, vdot_n, a_n)`: the unknowns are the true
//! accelerations `x = vdot_(n+1)` and the multipliers, with
//! `(1 - am) a_(n+1) + am a_n = (1 - af) x + af vdot_n`,
//! `v_(n+1) = v_n + h ((1 - g) a_n + g a_(n+1))`,
//! `q_(n+1) = q_n + h v_n + h^2 ((1/2 - b) a_n + b a_(n+1))`,
//! and the dynamic equations are satisfied at `t_(n+1)` with the loads of that time.
//! This is second order in q and v (Arnold and Bruls 2007). Before each step the two
//! accelerations take the jump of a held load and the lead a load rate calls for, so
//! that every step delivers exactly the impulse of the caller's held or linear load
//! (`held`). Newton on x and lambda: the
//! position constraints are divided by `h^2 b (1 - af)/(1 - am)` and the velocity
//! constraints by `h g (1 - af)/(1 - am)` so that all rows are acceleration-like, and
//! every constraint row is multiplied by the body's mass scale (conditioning of the
//! saddle-point matrix independent of h). The iteration matrix has the mass matrix with
//! the current M_C, the damping and stiffness K_L, K_C and the constraint Hessian; it
//! leaves out the derivatives of M_C(P), K_C(P) and of the load projection with respect
//! to the frame (small terms: the iteration converges linearly to the same solution).
//! The matrix is factored at the first iteration of a step and kept (modified Newton)
//! while each update is below a tenth of the previous one, rebuilt otherwise; on the
//! fixtures this needs the same number of iterations as a fresh matrix per iteration
//! and one factorisation per step instead of about three.
//! A step whose Newton iteration does not converge is split in two, recursively.
//! The iteration itself (residuals, iteration matrix, Schur solve) is in `newton`.

mod held;
mod newton;

use nalgebra::{DMatrix, DVector, Matrix3};

use super::lu::Lu;
use super::{
    FreeScene, Loads, MAX_FRAME_ERROR, PAIRS, checked_step, frame_error, frame_invalid,
    frame_omega, omega_rate_from_frame, point_vec, spin_warning,
};
use crate::scene::Scene;
use crate::solver::nodes::check_state;
use crate::solver::rollback::{Restorable, Rollback};
use crate::solver::{
    Frame, MAX_INTERNAL_STEPS, Method, Options, Solver, SolverError, SolverWarning, State,
};

/// Largest spectral radius accepted for free bodies. At exactly 1 (trapezoidal rule,
/// no damping at infinity) the position-level constraints make the multipliers
/// oscillate without decay; measured on a tumbling test body: energy error 1e-4 after
/// 1,000 steps, then growth and divergence, while 0.99 stays at 1e-6.
pub const MAX_RHO: f64 = 0.99;
/// Largest number of halvings of a communication step.
const MAX_SPLIT: u32 = 12;

/// Generalised-alpha parameters from the spectral radius at infinity.
#[derive(Debug, Clone, Copy)]
struct Params {
    am: f64,
    af: f64,
    gamma: f64,
    beta: f64,
}

impl Params {
    fn new(rho: f64) -> Params {
        let am = (2.0 * rho - 1.0) / (rho + 1.0);
        let af = rho / (rho + 1.0);
        Params {
            am,
            af,
            gamma: 0.5 - am + af,
            beta: (1.0 - am + af).powi(2) / 4.0,
        }
    }
}

/// The implicit (generalised-alpha) solver for a free body.
#[derive(Debug, Clone)]
pub struct Implicit {
    m: FreeScene,
    par: Params,
    t: f64,
    q: DVector<f64>,
    v: DVector<f64>,
    /// True accelerations vdot_n.
    acc: DVector<f64>,
    /// Algorithmic accelerations a_n.
    a: DVector<f64>,
    /// Multipliers of the last step (initial guess of the next).
    lam: DVector<f64>,
    /// The jump of the held loads since the last step (nodal, 6 per exposed node), not
    /// yet added to the accelerations (`held`).
    jump: Vec<f64>,
    /// The lead of the algorithmic acceleration over a load with a rate, as nodal loads
    /// (`held`): `(alpha_m - alpha_f) h F1` of the last step.
    lag: Vec<f64>,
    /// The nodal loads whose acceleration `held` solves for (preallocated).
    shift: Loads,
    /// The checkpoint a refused step goes back to, when one was taken (sized at build); a
    /// step without one puts itself back from `Work::save`.
    rollback: Rollback,
    /// The spin-rate warning was raised (once per solver).
    warned: bool,
    loads: Loads,
    p: Matrix3<f64>,
    w: Work,
}

#[derive(Debug, Clone)]
struct Work {
    mc: DMatrix<f64>,
    kc: DMatrix<f64>,
    f_r: DVector<f64>,
    f_l: DVector<f64>,
    x: DVector<f64>,
    lam: DVector<f64>,
    qn: DVector<f64>,
    vn: DVector<f64>,
    an: DVector<f64>,
    res: Vec<f64>,
    /// Rigid + constraint block after eliminating the local unknowns.
    kkt: Lu,
    small: Vec<f64>,
    /// Local iteration matrix, factored, for the step-size key `lkey`.
    lfac: Lu,
    lkey: (f64, f64),
    ykl: Vec<DMatrix<f64>>,
    y: DMatrix<f64>,
    /// `M_C + bt K_C` of the factored matrix, row-major `nr x nl`.
    arl: Vec<f64>,
    z: Vec<f64>,
    /// What a step changes, saved before it: a step that has to be split starts again
    /// from it, a refused one goes back to it.
    save: [DVector<f64>; 5],
    /// The lead `lag` before the step, for the same.
    save_lag: Vec<f64>,
    /// Size of the step being iterated (0 for the initial accelerations), for messages.
    h_now: f64,
}

impl Implicit {
    /// Build the solver for a free-body scene at t = 0 with the scene's initial velocity
    /// and consistent initial accelerations.
    pub fn new(scene: &Scene, opts: &Options) -> Result<Implicit, SolverError> {
        if !(0.0..=MAX_RHO).contains(&opts.rho_inf) {
            return Err(SolverError::Unsupported {
                method: Method::Implicit,
                why: crate::solver::Unsupported::RhoInf {
                    value: opts.rho_inf,
                    max: MAX_RHO,
                    free: true,
                },
            });
        }
        let m = FreeScene::new(scene, opts.damping_ratio)?;
        let (nr, nl, nq, nc) = (m.nr, m.nl, m.nq(), m.nc());
        let mut v = DVector::zeros(nq);
        m.initial_velocity(scene.v0, scene.w0, &mut v);
        let z = DVector::zeros(nq);
        let w = Work {
            mc: DMatrix::zeros(nr, nl),
            kc: DMatrix::zeros(nr, nl),
            f_r: DVector::zeros(nr),
            f_l: DVector::zeros(nl),
            x: z.clone(),
            lam: DVector::zeros(nc),
            qn: z.clone(),
            vn: z.clone(),
            an: z.clone(),
            res: vec![0.0; nq + nc],
            kkt: Lu::new(nr + nc),
            small: vec![0.0; nr + nc],
            lfac: Lu::new(nl),
            lkey: super::NO_KEY,
            ykl: vec![DMatrix::zeros(nl, nr); 9],
            y: DMatrix::zeros(nl, nr),
            arl: vec![0.0; nr * nl],
            z: vec![0.0; nl],
            save: [
                z.clone(),
                z.clone(),
                z.clone(),
                z.clone(),
                DVector::zeros(nc),
            ],
            save_lag: vec![0.0; 6 * m.nexp],
            h_now: 0.0,
        };
        let mut s = Implicit {
            p: m.p0,
            loads: Loads::new(6 * m.nexp),
            par: Params::new(opts.rho_inf),
            t: 0.0,
            q: z.clone(),
            v,
            acc: z.clone(),
            a: z,
            lam: DVector::zeros(nc),
            jump: vec![0.0; 6 * m.nexp],
            lag: vec![0.0; 6 * m.nexp],
            shift: Loads::new(6 * m.nexp),
            rollback: Rollback::new(Method::Implicit, 0),
            warned: false,
            m,
            w,
        };
        s.initial_accelerations()?;
        s.rollback = Rollback::new(Method::Implicit, s.state_len());
        Ok(s)
    }

    /// Coordinate velocities (rigid then local).
    pub fn velocity_coordinates(&self) -> &DVector<f64> {
        &self.v
    }

    /// Consistent accelerations at the current state: the saddle-point system with the
    /// second time derivative of the constraints, `d.b = -|w|^2` per edge and
    /// `B a_12 - a_rot = -dB/dt v_12` for Irot = 1. Sets vdot = a = the solution.
    fn initial_accelerations(&mut self) -> Result<(), SolverError> {
        let m = &self.m;
        let w = &mut self.w;
        let (nr, nl, nq) = (m.nr, m.nl, m.nq());
        let p = m.frame_of(self.q.as_slice());
        m.frame_matrices(&p, &mut w.mc, &mut w.kc);
        m.project_loads(&self.loads, self.t, &p, &mut w.f_r, &mut w.f_l);
        held::mass_matrix(m, &mut w.kkt, &p);
        // Right side: the forces.
        let alpha = self.q.rows(nr, nl);
        let vl = self.v.rows(nr, nl);
        for i in 0..nr {
            let mut s = w.f_r[i] + m.g_r[i];
            for j in 0..nl {
                s -= w.kc[(i, j)] * alpha[j];
            }
            w.res[i] = s;
        }
        for j in 0..nl {
            let mut s = w.f_l[j] - m.ray_a * m.m_l[j] * vl[j];
            for i in 0..nr {
                s += w.mc[(i, j)] * m.s_grav[i];
            }
            for (k, &kjk) in m.k_l_rows[j * nl..(j + 1) * nl].iter().enumerate() {
                s -= kjk * (alpha[k] + m.ray_b * vl[k]);
            }
            if let Some(c) = &m.c_add {
                s -= (0..nl).map(|k| c[(j, k)] * vl[k]).sum::<f64>();
            }
            w.res[nr + j] = s;
        }
        // Constraint rows: the second time derivative of the constraints,
        // `d.b = -|w|^2` per edge and `B a_12 - a_rot = -dB/dt v_12`.
        let sc = m.mass_scale;
        let v = self.v.as_slice();
        for (r, &(a, b, _)) in PAIRS.iter().enumerate() {
            let wv = point_vec(v, a) - point_vec(v, b);
            w.res[nq + r] = sc * wv.norm_squared();
        }
        if m.irot {
            let bd = omega_rate_from_frame(&p, v);
            for r in 0..3 {
                w.res[nq + 6 + r] = sc * bd[r];
            }
        }
        self.schur_solve(&p, 0.0, 0.0, true)?;
        let w = &mut self.w;
        for i in 0..nq {
            self.acc[i] = w.res[i];
            self.a[i] = w.res[i];
        }
        self.p = p;
        Ok(())
    }

    fn save(&mut self) {
        let w = &mut self.w;
        w.save[0].copy_from(&self.q);
        w.save[1].copy_from(&self.v);
        w.save[2].copy_from(&self.acc);
        w.save[3].copy_from(&self.a);
        w.save[4].copy_from(&self.lam);
        w.save_lag.copy_from_slice(&self.lag);
    }

    fn restore(&mut self, t: f64) {
        let w = &self.w;
        self.q.copy_from(&w.save[0]);
        self.v.copy_from(&w.save[1]);
        self.acc.copy_from(&w.save[2]);
        self.a.copy_from(&w.save[3]);
        self.lam.copy_from(&w.save[4]);
        self.lag.copy_from_slice(&w.save_lag);
        self.p = self.m.frame_of(self.q.as_slice());
        self.t = t;
    }

    fn state_len(&self) -> usize {
        1 + 4 * self.m.nq() + self.m.nc() + self.loads.state_len() + 2 * self.jump.len()
    }

    /// The state into `d` (cleared first; no allocation once `d` has the capacity).
    fn write_state(&self, d: &mut Vec<f64>) {
        d.clear();
        d.push(self.t);
        d.extend_from_slice(self.q.as_slice());
        d.extend_from_slice(self.v.as_slice());
        d.extend_from_slice(self.acc.as_slice());
        d.extend_from_slice(self.a.as_slice());
        d.extend_from_slice(self.lam.as_slice());
        self.loads.save(d);
        d.extend_from_slice(&self.jump);
        d.extend_from_slice(&self.lag);
    }

    /// One communication step, all or nothing: the copy a step that has to be split
    /// starts again from (`save`, what the step changes) also puts a refused step back,
    /// so the step copies its state once.
    fn run_step(&mut self, h: f64) -> Result<(), SolverError> {
        let t0 = self.t;
        let t_end = t0 + h;
        self.save();
        // Try the whole step; on failure restart with 2, 4, ... equal pieces.
        let mut last = None;
        for split in 0..=MAX_SPLIT {
            let n = 1usize << split;
            let dt = h / n as f64;
            let mut ok = true;
            for k in 0..n {
                // The held load's jump before the first piece, the rate's lead before
                // each (held.rs).
                if let Err(e) = self.hold(dt, k == 0).and_then(|()| self.try_step(dt)) {
                    last = Some(e);
                    ok = false;
                    break;
                }
            }
            if ok {
                let err = frame_error(&self.p);
                if err > MAX_FRAME_ERROR {
                    let e = frame_invalid(
                        err,
                        h,
                        self.spin_rate(),
                        crate::solver::FrameAdvice::SmallerSteps,
                    );
                    self.restore(t0);
                    return Err(e);
                }
                self.jump.fill(0.0);
                self.t = t_end;
                return Ok(());
            }
            self.restore(t0);
        }
        Err(last.unwrap_or(SolverError::BadStep(h)))
    }

    /// Spin rate `|omega|` of the frame (rad/s).
    fn spin_rate(&self) -> f64 {
        frame_omega(&self.p, self.v.as_slice()).norm()
    }
}

/// The most Newton iterations one step can take: `newton::MAX_ITER` per piece over
/// 1 + 2 + 4 + ... + 2^MAX_SPLIT pieces. It is within [`MAX_INTERNAL_STEPS`] (checked at
/// compile time), so the implicit method needs no step-size refusal: its work per call
/// is bounded whatever h.
pub const MAX_NEWTON_PER_STEP: usize = newton::MAX_ITER * ((2 << MAX_SPLIT) - 1);
const _: () = assert!(MAX_NEWTON_PER_STEP as f64 <= MAX_INTERNAL_STEPS);

/// The rigid mass M_R into the top-left of the reduced (rigid + constraint) matrix.
fn fill_mass(m: &FreeScene, kkt: &mut Lu) {
    for i in 0..m.nr {
        for k in 0..m.nr {
            *kkt.at(i, k) = m.m_r[(i, k)];
        }
    }
}

impl Solver for Implicit {
    free_solver_common!();
    free_solver_sampled_velocity!();

    fn method(&self) -> Method {
        Method::Implicit
    }

    fn set_loads(&mut self, loads: &[f64]) -> Result<(), SolverError> {
        self.m.check_loads("loads", loads)?;
        self.rollback.touch();
        self.note_jump(loads);
        self.loads.set(loads, self.t);
        Ok(())
    }

    /// Advance by `h`. The work is bounded ([`MAX_NEWTON_PER_STEP`]); on any error the
    /// state is as before the call (the step puts itself back: `run_step`).
    fn step(&mut self, h: f64) -> Result<Option<SolverWarning>, SolverError> {
        checked_step(self, h, false, |s| s.run_step(h))?;
        Ok(spin_warning(&self.m, self.spin_rate(), &mut self.warned))
    }

    fn set_state(&mut self, state: &State) -> Result<(), SolverError> {
        check_state(state, Method::Implicit, self.state_len())?;
        let (nq, nc) = (self.m.nq(), self.m.nc());
        let d = &state.data;
        self.t = d[0];
        let mut o = 1;
        for x in [&mut self.q, &mut self.v, &mut self.acc, &mut self.a] {
            x.copy_from_slice(&d[o..o + nq]);
            o += nq;
        }
        self.lam.copy_from_slice(&d[o..o + nc]);
        o += nc;
        let nl = self.loads.state_len();
        self.loads.load(&d[o..o + nl]);
        o += nl;
        let n = self.jump.len();
        self.jump.copy_from_slice(&d[o..o + n]);
        self.lag.copy_from_slice(&d[o + n..o + 2 * n]);
        self.p = self.m.frame_of(self.q.as_slice());
        self.rollback.forget();
        Ok(())
    }
}

impl Restorable for Implicit {
    fn rollback(&mut self) -> &mut Rollback {
        &mut self.rollback
    }

    fn write_state(&self, out: &mut Vec<f64>) {
        Implicit::write_state(self, out);
    }

    fn state_len(&self) -> usize {
        Implicit::state_len(self)
    }
}
