//! The split method for free bodies (FORMULATION.md section 11): second order in the
//! frame, exact in the local modes between samples, not bound by dt_fx.
//!
//! The body's equations (section 3) are written on the constraint manifold itself: the
//! frame is a rigid body `(X, P)` (position of L0, rotation) moving with `(V, omega)`,
//! so the frame points move with `G(P) (V, omega)` and the constraint forces drop out
//! (`G^T C^T = 0`): `M6 a6 + B^T a_L = Q6`, `B a6 + m_L a_L + ... = S_L` with
//! `M6 = G^T M_R G`, `B = M_C^T G`, `Q6 = G^T (F_R + G_R - K_C alpha - M_R c)` and `c`
//! the centripetal accelerations of the frame points. The local modes are taken in the
//! modal basis of `(K_L, m_eff)`, `m_eff = diag(m_L) - B M6^-1 B^T` (the local mass with
//! the rigid motion they drag condensed out; `diag(m_L)` itself when the modes are
//! free-free, `B = 0`).
//!
//! One internal step of size `dt` is the symmetric (Strang) composition
//! `L(dt/2) R(dt) L(dt/2)`:
//! - `L`: the frame held; every mode advanced exactly (the blocked exact method's
//!   transition, `expm::mode_coefficients`) under the nodal loads held or linear over
//!   the sub-step, gravity, the frame's centrifugal load `-M_C^T c` and the inertial load
//!   of the rigid acceleration `-B M6^-1 Q6`; the frame's velocity takes the modes'
//!   recoil `-M6^-1 B^T dv_L` exactly. With `B != 0` the frame's spin in these loads is
//!   taken at the sub-step's middle (one predictor pass).
//! - `R`: the modes held; `M6 a6 = Q6` by the implicit midpoint on the rotation group
//!   (`P <- exp(dt [omega_mid]) P`: a rotation to round-off by construction).
//!
//! `L` is exact and `R` symmetric and second order, so the composition is symmetric and
//! second order. A communication step is cut into equal internal steps turning at most
//! [`ROT_STEP`] rad each.

pub(super) mod rigid;

use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, SMatrix, Vector3, Vector6};

use super::{
    FreeScene, Loads, MAX_FRAME_ERROR, SINGULAR_RATIO, checked_step, drag_warning, frame_error,
    frame_invalid, point_offset, singular_error, spin_warning,
};
use crate::scene::Scene;
use crate::solver::expm::mode_coefficients;
use crate::solver::nodes::check_state;
use crate::solver::rollback::{Restorable, Rollback};
use crate::solver::{
    Frame, MAX_INTERNAL_STEPS, Method, Options, Solver, SolverError, SolverWarning, State,
};

/// Largest rotation of the frame per internal step (rad): a communication step is cut
/// into equal internal steps of at most `ROT_STEP / |omega|`. The frame's error is
/// `(|omega| dt)^2` relative (second order) and the midpoint drift converges by a factor
/// of about `|omega| dt / 2` per pass, so 0.1 rad keeps both small; below it (every
/// scene of the study) a communication step is one internal step.
pub const ROT_STEP: f64 = 0.1;

/// The split (Strang) solver for a free body.
#[derive(Debug, Clone)]
pub struct Split {
    pub(super) m: FreeScene,
    pub(super) t: f64,
    /// Displacement of L0 from its initial position.
    pub(super) d: Vector3<f64>,
    /// The frame (a rotation).
    pub(super) p: Matrix3<f64>,
    /// Rotational DOFs 13..15 (Irot = 1): the integral of omega.
    qrot: Vector3<f64>,
    /// Frame velocity `(V, omega)`: L0's velocity and the angular velocity (global).
    pub(super) v6: Vector6<f64>,
    /// Modal amplitudes and velocities in the basis of `(K_L, m_eff)`.
    pub(super) y: DVector<f64>,
    pub(super) yd: DVector<f64>,
    /// The accelerations of the current state ([`Split::accelerations`]): modal
    /// `y''`, and the frame's `(V', omega')`.
    pub(super) ydd: DVector<f64>,
    pub(super) a6: Vector6<f64>,
    /// Model Exchange's attitude quaternion and the frame it was read into
    /// ([`super::continuous`]).
    pub(super) attitude: super::continuous::Attitude,
    loads: Loads,
    pub(super) c: Consts,
    w: Work,
    /// Outputs at the current time: coordinates, velocities, accelerations (`nq` each).
    q: DVector<f64>,
    v: DVector<f64>,
    acc: DVector<f64>,
    coef: [Vec<f64>; 2],
    coef_h: [f64; 2],
    next_slot: usize,
    /// The state before the current step, restored when the step fails (sized at
    /// build).
    pub(super) rollback: Rollback,
    warned: bool,
    /// The load-time check's warning (modes that drag rigid motion: this method
    /// integrates the Radioss equations, FORMULATION.md section 3), given by the first
    /// step.
    drag_warning: Option<SolverWarning>,
}

/// What depends on the body only.
#[derive(Debug, Clone)]
pub(super) struct Consts {
    /// M_R row-major.
    m_r: Vec<f64>,
    /// Modal basis: `alpha = S y`, `S^T m_eff S = I`, `S^T K_L S = diag(w^2)`.
    pub(super) s: DMatrix<f64>,
    pub(super) omega: Vec<f64>,
    w2: Vec<f64>,
    damp: Vec<f64>,
    /// The modes drag rigid motion (`B != 0`): the predictor pass of `L` is needed.
    coupled: bool,
}

#[derive(Debug, Clone)]
struct Work {
    mc: DMatrix<f64>,
    kc: DMatrix<f64>,
    f_r: DVector<f64>,
    f_l: DVector<f64>,
    fa: DVector<f64>,
    fb: DVector<f64>,
    g0: DVector<f64>,
    g1: DVector<f64>,
    alpha: DVector<f64>,
    vl: DVector<f64>,
    sy: DVector<f64>,
    syd: DVector<f64>,
    /// `K_C,kl alpha` for the nine sub-blocks (`nr` each), for the frame's step.
    kca: Vec<DVector<f64>>,
    /// The frame `mc`, `kc` and `m6inv` belong to (NaN: none).
    key: Matrix3<f64>,
    m6inv: Matrix6<f64>,
}

impl Split {
    /// Build the solver for a free-body scene at t = 0 with the scene's initial velocity;
    /// `opts.damping_ratio` adds `2 zeta w_i` to every mode of the split's own basis
    /// (`K_L`, `m_eff`), on top of Rayleigh ([`crate::solver::damping`]).
    pub fn new(scene: &Scene, opts: &Options) -> Result<Split, SolverError> {
        let m = FreeScene::new(scene, opts.damping_ratio)?;
        let zeta = opts.damping_ratio;
        let (nr, nl, nq) = (m.nr, m.nl, m.nq());
        // The file's P0 is a rotation to its printed digits only (1e-10 on the
        // fixtures); the frame starts at the nearest rotation (polar factor), which the
        // other methods' constraints reach after their first step.
        let svd = m.p0.svd(true, true);
        let p0 = match (svd.u, svd.v_t) {
            (Some(u), Some(v_t)) => u * v_t,
            _ => m.p0,
        };
        let m_r_rows: Vec<f64> = m.m_r.transpose().as_slice().to_vec();
        let m6 = rigid::rigid_mass(&m_r_rows, nr, &p0);
        let eig = m6.symmetric_eigen().eigenvalues;
        let (lo, hi) = (eig.min(), eig.max());
        let ratio = if hi > 0.0 { lo / hi } else { 0.0 };
        if ratio.is_nan() || ratio <= SINGULAR_RATIO {
            return Err(singular_error(ratio.max(0.0), 0.0, 0.0));
        }
        let m6inv = m6
            .try_inverse()
            .ok_or_else(|| singular_error(0.0, 0.0, 0.0))?;
        let mut mc = DMatrix::zeros(nr, nl);
        let mut kc = DMatrix::zeros(nr, nl);
        m.frame_matrices(&p0, &mut mc, &mut kc);
        let g = rigid::g_matrix(&p0, nr);
        let bmat: DMatrix<f64> =
            DMatrix::from_fn(nl, 6, |j, k| (0..nr).map(|i| mc[(i, j)] * g[(i, k)]).sum());
        let minv = DMatrix::from_iterator(6, 6, m6inv.iter().copied());
        let m_eff: DMatrix<f64> = DMatrix::from_diagonal(&m.m_l) - &bmat * minv * bmat.transpose();
        let m_eff = (&m_eff + m_eff.transpose()) * 0.5;
        let coupled = bmat.amax() > 1e-9 * m.m_l.amax().max(m6.amax());
        let (s, lam) = if nl == 0 {
            (DMatrix::zeros(0, 0), Vec::new())
        } else {
            modal_basis(m_eff, &m.k_l)?
        };
        let w2: Vec<f64> = lam.iter().map(|&x| x.max(0.0)).collect();
        let omega: Vec<f64> = w2.iter().map(|x| x.sqrt()).collect();
        // The modes of the split's own basis take the damping of their frequency (with
        // zeta = 0 bit for bit the Rayleigh coefficients).
        let damping = crate::solver::damping::LocalDamping::new(&scene.body, zeta)?;
        let damp = omega.iter().map(|&w| damping.modal(w)).collect();
        let c = Consts {
            m_r: m.m_r.transpose().as_slice().to_vec(),
            s,
            omega,
            w2,
            damp,
            coupled,
        };
        let v6 = Vector6::new(
            scene.v0[0],
            scene.v0[1],
            scene.v0[2],
            scene.w0[0],
            scene.w0[1],
            scene.w0[2],
        );
        let z = DVector::zeros(nl);
        let w = Work {
            mc,
            kc,
            f_r: DVector::zeros(nr),
            f_l: z.clone(),
            fa: z.clone(),
            fb: z.clone(),
            g0: z.clone(),
            g1: z.clone(),
            alpha: z.clone(),
            vl: z.clone(),
            sy: z.clone(),
            syd: z.clone(),
            kca: vec![DVector::zeros(nr); 9],
            key: Matrix3::from_element(f64::NAN),
            m6inv: Matrix6::zeros(),
        };
        let mut s = Split {
            loads: Loads::new(6 * m.nexp),
            t: 0.0,
            d: Vector3::zeros(),
            p: p0,
            qrot: Vector3::zeros(),
            v6,
            y: z.clone(),
            yd: z.clone(),
            ydd: z,
            a6: Vector6::zeros(),
            attitude: super::continuous::Attitude::of(&p0),
            c,
            w,
            q: DVector::zeros(nq),
            v: DVector::zeros(nq),
            acc: DVector::zeros(nq),
            coef: [vec![0.0; 8 * nl], vec![0.0; 8 * nl]],
            coef_h: [f64::NAN; 2],
            next_slot: 0,
            rollback: Rollback::new(Method::Split, 0),
            warned: false,
            drag_warning: drag_warning(&m, true),
            m,
        };
        s.rollback = Rollback::new(Method::Split, s.state_len());
        s.refresh()?;
        Ok(s)
    }

    /// Coordinate velocities (rigid then local) at the current time, as the other free
    /// methods give them: for momentum balances from the body's own matrices.
    pub fn velocity_coordinates(&self) -> &DVector<f64> {
        &self.v
    }

    fn state_len(&self) -> usize {
        1 + 3 + 9 + 3 + 6 + 2 * self.m.nl + self.loads.state_len()
    }

    fn write_state(&self, d: &mut Vec<f64>) {
        d.clear();
        d.push(self.t);
        d.extend_from_slice(self.d.as_slice());
        d.extend_from_slice(self.p.as_slice());
        d.extend_from_slice(self.qrot.as_slice());
        d.extend_from_slice(self.v6.as_slice());
        d.extend_from_slice(self.y.as_slice());
        d.extend_from_slice(self.yd.as_slice());
        self.loads.save(d);
    }

    /// Spin rate `|omega|` (rad/s).
    fn spin_rate(&self) -> f64 {
        Vector3::new(self.v6[3], self.v6[4], self.v6[5]).norm()
    }

    /// `M6(P)^-1` for the current frame.
    fn m6_inverse(&self, p: &Matrix3<f64>) -> Result<Matrix6<f64>, SolverError> {
        rigid::rigid_mass(&self.c.m_r, self.m.nr, p)
            .try_inverse()
            .ok_or_else(|| singular_error(0.0, 0.0, self.spin_rate()))
    }

    /// `M_C`, `K_C` and `M6^-1` for the current frame, recomputed only when the frame
    /// moved since they were last formed.
    fn frame_terms(&mut self) -> Result<Matrix6<f64>, SolverError> {
        if self.w.key != self.p {
            self.m
                .frame_matrices(&self.p, &mut self.w.mc, &mut self.w.kc);
            self.w.m6inv = self.m6_inverse(&self.p)?;
            self.w.key = self.p;
        }
        Ok(self.w.m6inv)
    }

    /// Loads on the local modes at time `t` with the frame's velocity `v6`, into `out`
    /// (local coordinates): `F_L + G_L - M_C^T (c + G M6^-1 Q6)`, with
    /// `Q6 = G^T (F_R + G_R - K_C alpha - M_R c)` (returned). `w.mc`, `w.kc` must hold
    /// the current frame's matrices and `w.alpha` the local coordinates.
    fn local_loads(
        &mut self,
        t: f64,
        v6: &Vector6<f64>,
        m6inv: &Matrix6<f64>,
        out: Out,
    ) -> Vector6<f64> {
        let (m, w) = (&self.m, &mut self.w);
        let nr = m.nr;
        m.project_loads(&self.loads, t, &self.p, &mut w.f_r, &mut w.f_l);
        let cvec = centripetal(&self.p, v6);
        // Rigid generalised force F_R + G_R - K_C alpha - M_R c (in w.f_r).
        for i in 0..nr {
            let mr = &self.c.m_r[i * nr..(i + 1) * nr];
            let mut s = w.f_r[i] + m.g_r[i] - row_dot(&w.kc, i, &w.alpha);
            for (k, &ck) in cvec[..nr].iter().enumerate() {
                s -= mr[k] * ck;
            }
            w.f_r[i] = s;
        }
        let g = rigid::g_matrix(&self.p, nr);
        let mut q6 = Vector6::zeros();
        for k in 0..6 {
            q6[k] = (0..nr).map(|i| g[(i, k)] * w.f_r[i]).sum();
        }
        // Frame-point accelerations c + G a6 with a6 = M6^-1 Q6, the modes' inertial load.
        let ar = g * (m6inv * q6);
        let f = match out {
            Out::A => &mut w.fa,
            Out::B => &mut w.fb,
        };
        f.copy_from(&w.f_l);
        for j in 0..m.nl {
            let col = w.mc.column(j);
            let mut s = 0.0;
            for i in 0..nr {
                s += col[i] * (m.s_grav[i] - cvec[i] - ar[i]);
            }
            f[j] += s;
        }
        q6
    }

    /// The transition coefficients for a sub-step `dt` (cached for two sizes).
    fn coefficients(&mut self, dt: f64) -> Result<usize, SolverError> {
        if let Some(slot) = self.coef_h.iter().position(|&c| c == dt) {
            return Ok(slot);
        }
        let slot = self.next_slot;
        let nl = self.m.nl;
        for i in 0..nl {
            let c = mode_coefficients(self.c.omega[i], self.c.damp[i], dt);
            for (k, &ck) in c.iter().enumerate() {
                self.coef[slot][k * nl + i] = ck;
            }
        }
        if self.coef[slot].iter().any(|c| !c.is_finite()) {
            self.coef_h[slot] = f64::NAN;
            return Err(SolverError::NonFinite {
                what: "the modal transition".into(),
                cause: crate::solver::Overflow::SubStep(dt),
            });
        }
        self.next_slot = 1 - slot;
        self.coef_h[slot] = dt;
        Ok(slot)
    }

    /// `L(dt)` from time `t`: the frame held, the modes exact, the frame's velocity
    /// taking their recoil.
    fn flow_local(&mut self, dt: f64, t: f64) -> Result<(), SolverError> {
        let (nr, nl) = (self.m.nr, self.m.nl);
        if nl == 0 {
            return Ok(());
        }
        let slot = self.coefficients(dt)?;
        let m6inv = self.frame_terms()?;
        self.w.alpha.gemv(1.0, &self.c.s, &self.y, 0.0);
        let g = rigid::g_matrix(&self.p, nr);
        let v_start = self.v6;
        let rates = self.loads.rates.iter().any(|&r| r != 0.0);
        self.w.sy.copy_from(&self.y);
        self.w.syd.copy_from(&self.yd);
        let passes = if self.c.coupled { 2 } else { 1 };
        let mut v_use = v_start;
        for pass in 0..passes {
            if pass == 1 {
                // The frame's spin in the loads at the middle of the sub-step.
                v_use = (v_start + self.v6) * 0.5;
                self.y.copy_from(&self.w.sy);
                self.yd.copy_from(&self.w.syd);
            }
            self.local_loads(t, &v_use, &m6inv, Out::A);
            let w = &mut self.w;
            w.g0.gemv_tr(1.0, &self.c.s, &w.fa, 0.0);
            if rates {
                self.local_loads(t + dt, &v_use, &m6inv, Out::B);
                let w = &mut self.w;
                w.fb -= &w.fa;
                w.g1.gemv_tr(1.0 / dt, &self.c.s, &w.fb, 0.0);
            } else {
                self.w.g1.fill(0.0);
            }
            advance(
                &self.coef[slot],
                self.w.g0.as_slice(),
                self.w.g1.as_slice(),
                self.y.as_mut_slice(),
                self.yd.as_mut_slice(),
            );
            if self.c.coupled {
                // Recoil: M6 dv6 = -G^T M_C dv_L.
                let w = &mut self.w;
                w.g0.copy_from(&self.yd);
                w.g0 -= &w.syd;
                w.vl.gemv(1.0, &self.c.s, &w.g0, 0.0);
                w.f_r.gemv(1.0, &w.mc, &w.vl, 0.0);
                let mut q = Vector6::zeros();
                for k in 0..6 {
                    q[k] = (0..nr).map(|i| g[(i, k)] * w.f_r[i]).sum();
                }
                self.v6 = v_start - m6inv * q;
            }
        }
        Ok(())
    }

    /// `R(dt)` from time `t`: the modes held, `M6 a6 = Q6` by the implicit midpoint on
    /// the rotation group with the loads of the middle of the step.
    fn flow_rigid(&mut self, dt: f64, t: f64) -> Result<(), SolverError> {
        let v0 = self.v6;
        let (m, w) = (&self.m, &mut self.w);
        let nr = m.nr;
        m.project_loads(&self.loads, t + 0.5 * dt, &self.p, &mut w.f_r, &mut w.f_l);
        for i in 0..nr {
            w.f_r[i] += m.g_r[i];
        }
        w.alpha.gemv(1.0, &self.c.s, &self.y, 0.0);
        for (kca, kc) in w.kca.iter_mut().zip(&m.k_c_kl) {
            kca.gemv(1.0, kc, &w.alpha, 0.0);
        }
        let (f_r, kca, m_r) = (&w.f_r, &w.kca, &self.c.m_r);
        // M6^-1 is re-formed only when the midpoint frame moved by more than 1e-14 since
        // it was last formed (the passes after the first move it by round-off).
        let mut cache: Option<(Matrix3<f64>, Matrix6<f64>)> = None;
        let accel = |p: &Matrix3<f64>, v: &Vector6<f64>| -> Option<Vector6<f64>> {
            let c = centripetal(p, v);
            let g = rigid::g_matrix(p, nr);
            let mut rhs = [0.0; 15];
            for (i, r) in rhs[..nr].iter_mut().enumerate() {
                // K_C(P) alpha = sum_kl P_lk K_C,kl alpha.
                let mut s = f_r[i];
                for k in 0..3 {
                    for l in 0..3 {
                        s -= p[(l, k)] * kca[3 * k + l][i];
                    }
                }
                let mr = &m_r[i * nr..(i + 1) * nr];
                for (j, &cj) in c[..nr].iter().enumerate() {
                    s -= mr[j] * cj;
                }
                *r = s;
            }
            let mut q6 = Vector6::zeros();
            for k in 0..6 {
                q6[k] = (0..nr).map(|i| g[(i, k)] * rhs[i]).sum();
            }
            let inv = match cache {
                Some((key, inv)) if (key - p).amax() <= 1e-14 => inv,
                _ => {
                    let inv = rigid::rigid_mass(m_r, nr, p).try_inverse()?;
                    cache = Some((*p, inv));
                    inv
                }
            };
            Some(inv * q6)
        };
        let mut x = m.origin0 + self.d;
        let spin = Vector3::new(v0[3], v0[4], v0[5]).norm();
        if rigid::midpoint(dt, &mut x, &mut self.p, &mut self.v6, accel).is_none() {
            return Err(SolverError::Invalid(crate::solver::Invalid::Midpoint {
                passes: rigid::MAX_FIXED_POINT,
                dt,
                spin,
            }));
        }
        self.d = x - self.m.origin0;
        if self.m.irot {
            let vm = (v0 + self.v6) * 0.5;
            self.qrot += Vector3::new(vm[3], vm[4], vm[5]) * dt;
        }
        Ok(())
    }

    /// One communication step (no restore on failure: [`Solver::step`] does it).
    fn run_step(&mut self, h: f64) -> Result<(), SolverError> {
        let spin = self.spin_rate();
        let n = (h * spin / ROT_STEP).ceil().max(1.0);
        if n > MAX_INTERNAL_STEPS {
            return Err(SolverError::TooManySteps {
                h,
                steps: n,
                internal: ROT_STEP / spin,
                max_h: MAX_INTERNAL_STEPS * ROT_STEP / spin,
            });
        }
        let n = n as usize;
        let dt = h / n as f64;
        let t0 = self.t;
        for k in 0..n {
            let t = t0 + k as f64 * dt;
            self.flow_local(0.5 * dt, t)?;
            self.flow_rigid(dt, t)?;
            self.flow_local(0.5 * dt, t + 0.5 * dt)?;
        }
        self.t = t0 + h;
        let finite = self
            .v6
            .iter()
            .chain(self.d.iter())
            .chain(self.p.iter())
            .all(|x| x.is_finite())
            && self.y.iter().chain(self.yd.iter()).all(|x| x.is_finite());
        if !finite {
            return Err(SolverError::NonFinite {
                what: "the body state".into(),
                cause: crate::solver::Overflow::Step { h, spin },
            });
        }
        let err = frame_error(&self.p);
        if err > MAX_FRAME_ERROR {
            return Err(frame_invalid(
                err,
                h,
                spin,
                crate::solver::FrameAdvice::SmallerSteps,
            ));
        }
        self.refresh()
    }

    /// Recompute the outputs (coordinates, velocities, accelerations) of the current
    /// state: section 2's coordinates from the frame, the modes and the momenta.
    pub(super) fn refresh(&mut self) -> Result<(), SolverError> {
        let (nr, nl) = (self.m.nr, self.m.nl);
        let v6 = self.v6;
        let m6inv = self.frame_terms()?;
        self.w.alpha.gemv(1.0, &self.c.s, &self.y, 0.0);
        self.w.vl.gemv(1.0, &self.c.s, &self.yd, 0.0);
        // Coordinates: q_L0 = d, q_Lj = d + e_j - e_j0, rotational DOFs.
        for j in 0..4 {
            let o = point_offset(j);
            for c in 0..3 {
                let e = if j == 0 {
                    0.0
                } else {
                    self.p[(c, j - 1)] - self.m.p0[(c, j - 1)]
                };
                self.q[o + c] = self.d[c] + e;
            }
        }
        if self.m.irot {
            self.q.rows_mut(12, 3).copy_from(&self.qrot);
        }
        self.q.rows_mut(nr, nl).copy_from(&self.w.alpha);
        let g: SMatrix<f64, 15, 6> = rigid::g_matrix(&self.p, nr);
        let vr = g * v6;
        self.v.rows_mut(0, nr).copy_from(&vr.rows(0, nr));
        self.v.rows_mut(nr, nl).copy_from(&self.w.vl);
        // Accelerations from the equations of motion at this instant.
        self.accelerations(&m6inv);
        let ar = g * self.a6;
        let c = centripetal(&self.p, &v6);
        for i in 0..nr {
            self.acc[i] = ar[i] + c[i];
        }
        self.acc.rows_mut(nr, nl).copy_from(&self.w.g1);
        Ok(())
    }

    /// The body's accelerations at the current state, time and loads: the one
    /// acceleration function of section 11's equations as a first-order system. The
    /// modal accelerations `y''` go to `self.ydd`, their local coordinates `S y''` to
    /// `w.g1`, and the frame's `a6 = (V', omega') = M6^-1 (Q6 - G^T M_C a_L)` to
    /// `self.a6`. The co-simulation outputs ([`Split::refresh`]) and Model Exchange's
    /// derivatives (`free::continuous`) both read it. `w.alpha` must hold `S y`, `w.mc`
    /// and `w.kc` the current frame's matrices, `m6inv` its `M6^-1`.
    fn accelerations(&mut self, m6inv: &Matrix6<f64>) {
        let nr = self.m.nr;
        let (t, v6) = (self.t, self.v6);
        let q6 = self.local_loads(t, &v6, m6inv, Out::A);
        let w = &mut self.w;
        w.g0.gemv_tr(1.0, &self.c.s, &w.fa, 0.0);
        for (i, a) in self.ydd.iter_mut().enumerate() {
            *a = w.g0[i] - (self.c.damp[i] * self.yd[i] + self.c.w2[i] * self.y[i]);
        }
        w.g1.gemv(1.0, &self.c.s, &self.ydd, 0.0);
        w.f_r.gemv(1.0, &w.mc, &w.g1, 0.0);
        let g = rigid::g_matrix(&self.p, nr);
        let mut ba = Vector6::zeros();
        for k in 0..6 {
            ba[k] = (0..nr).map(|i| g[(i, k)] * w.f_r[i]).sum();
        }
        self.a6 = m6inv * (q6 - ba);
    }
}

/// Centripetal accelerations `omega x (omega x e_j)` of the frame points L1..L3 (zero
/// for L0 and the rotational DOFs) for the velocity `v6` and frame `p`.
fn centripetal(p: &Matrix3<f64>, v6: &Vector6<f64>) -> [f64; 15] {
    let om = Vector3::new(v6[3], v6[4], v6[5]);
    let mut c = [0.0; 15];
    for j in 1..4 {
        let e = p.column(j - 1).into_owned();
        let cj = om.cross(&om.cross(&e));
        let o = point_offset(j);
        c[o..o + 3].copy_from_slice(cj.as_slice());
    }
    c
}

/// The basis `S` with `S^T m_eff S = I` and `S^T K_L S = diag(lambda)`, and lambda.
fn modal_basis(
    m_eff: DMatrix<f64>,
    k_l: &DMatrix<f64>,
) -> Result<(DMatrix<f64>, Vec<f64>), SolverError> {
    let chol = nalgebra::Cholesky::new(m_eff).ok_or(SolverError::Singular(
        crate::solver::Singular::CondensedMass,
    ))?;
    let linv = chol
        .l()
        .try_inverse()
        .ok_or(SolverError::Singular(crate::solver::Singular::LocalMass))?;
    let a = &linv * k_l * linv.transpose();
    let a = (&a + a.transpose()) * 0.5;
    let se = a.symmetric_eigen();
    let s = linv.transpose() * se.eigenvectors;
    Ok((s, se.eigenvalues.iter().copied().collect()))
}

/// `a[i, :] . x` without a temporary.
fn row_dot(a: &DMatrix<f64>, i: usize, x: &DVector<f64>) -> f64 {
    (0..a.ncols()).map(|j| a[(i, j)] * x[j]).sum()
}

/// Which load buffer [`Split::local_loads`] writes.
#[derive(Clone, Copy)]
enum Out {
    A,
    B,
}

/// One exact step of every mode under the modal load `f0 + f1 s` (the blocked exact
/// method's transition with the load taken from the start of the sub-step).
fn advance(coef: &[f64], f0: &[f64], f1: &[f64], y: &mut [f64], v: &mut [f64]) {
    let n = y.len();
    for i in 0..n {
        let (y0, v0) = (y[i], v[i]);
        let c = |k: usize| coef[k * n + i];
        y[i] = c(0) * y0 + c(1) * v0 + c(2) * f0[i] + c(3) * f1[i];
        v[i] = c(4) * y0 + c(5) * v0 + c(6) * f0[i] + c(7) * f1[i];
    }
}

impl Solver for Split {
    free_solver_common!();
    free_solver_sampled_velocity!();

    fn method(&self) -> Method {
        Method::Split
    }

    fn set_loads(&mut self, loads: &[f64]) -> Result<(), SolverError> {
        self.m.check_loads("loads", loads)?;
        self.rollback.touch();
        self.loads.set(loads, self.t);
        self.refresh()
    }

    /// Advance by `h`; on any error the state is as before the call.
    fn step(&mut self, h: f64) -> Result<Option<SolverWarning>, SolverError> {
        checked_step(self, h, true, |s| s.run_step(h))?;
        if let Some(w) = self.drag_warning.take() {
            return Ok(Some(w));
        }
        let spin = self.spin_rate();
        Ok(spin_warning(&self.m, spin, &mut self.warned))
    }

    /// The caller may change the continuous states through it: the state measured last
    /// is stale.
    fn continuous(&mut self) -> Option<&mut dyn crate::solver::continuous::Continuous> {
        self.rollback.touch();
        Some(self)
    }

    fn set_state(&mut self, state: &State) -> Result<(), SolverError> {
        check_state(state, Method::Split, self.state_len())?;
        let nl = self.m.nl;
        let d = &state.data;
        self.t = d[0];
        self.d.copy_from_slice(&d[1..4]);
        self.p.copy_from_slice(&d[4..13]);
        self.qrot.copy_from_slice(&d[13..16]);
        self.v6.copy_from_slice(&d[16..22]);
        self.y.copy_from_slice(&d[22..22 + nl]);
        self.yd.copy_from_slice(&d[22 + nl..22 + 2 * nl]);
        self.loads.load(&d[22 + 2 * nl..]);
        self.rollback.forget();
        self.refresh()
    }
}

impl Restorable for Split {
    fn rollback(&mut self) -> &mut Rollback {
        &mut self.rollback
    }

    fn write_state(&self, out: &mut Vec<f64>) {
        Split::write_state(self, out);
    }

    fn state_len(&self) -> usize {
        Split::state_len(self)
    }
}
