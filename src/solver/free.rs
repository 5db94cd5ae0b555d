//! Free (floating) bodies, Iblo = 0: the kinematics shared by the explicit and implicit
//! methods (FORMULATION.md sections 2 and 3).
//!
//! Coordinates: `q = [q_R; alpha]` with `q_R` the displacements of the frame points L1,
//! L2, L3, L0 (3 each, global frame), then three rotational DOFs when Irot = 1, and
//! `alpha` the local modal amplitudes. The frame matrix is `P = P0 + [q_Lj - q_L0]_j`
//! (column j = edge L0->Lj); it stays orthonormal through six distance constraints on
//! the frame points, never by re-orthonormalisation.
//!
//! Methods: [`Explicit`], the reference central-difference scheme of FORMULATION.md
//! section 4 sub-cycled at `dt_factor x dt_fx` (its module documents the Irot = 1 rows
//! and the co-simulation restart), and [`Implicit`], generalised-alpha on the
//! index-3 constrained system, not bound by dt_fx. Both keep every per-step matrix in
//! preallocated storage and solve their saddle-point systems with an in-place LU.
//!
//! Outputs: node positions `x0 + u` and velocities (frame of the same instant), node
//! accelerations (without the `P_dot` terms the formulation leaves out), rotation rates
//! (frame or rotational-DOF rate plus the local modes' rotations), the frame (L0 position
//! and P; L0's initial position is found from the exposed nodes' coordinates and the
//! rigid modes, so it is the origin when no node is exposed) and the energies of
//! section 3.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use super::SolverError;
use super::dense::bilinear;
pub(crate) use super::loads::Loads;
use super::rollback::{Restorable, Rollback};
use crate::scene::Scene;

/// A free method's step of `h`, all or nothing ([`Rollback::step`], `partway` as there):
/// a step size that is no step is refused inside the rollback, so that a refusal after a
/// checkpoint goes back to it whatever refuses the step; then `run`.
pub(crate) fn checked_step<S: Restorable>(
    s: &mut S,
    h: f64,
    partway: bool,
    run: impl FnOnce(&mut S) -> Result<(), SolverError>,
) -> Result<(), SolverError> {
    Rollback::step(s, partway, |s| {
        if !(h.is_finite() && h > 0.0) {
            return Err(SolverError::BadStep(h));
        }
        run(s)
    })
}

/// The [`crate::solver::Solver`] items every free method answers the same way from its
/// coordinates `self.q`, its frame `self.p` and the shared [`FreeScene`] `self.m` (positions,
/// node rotations, modal coordinates, strain energy, the frame, the state items of
/// [`crate::solver::rollback`]), written once. Invoked inside each method's
/// `impl Solver`; the method writes `write_state`, `state_len`, `set_state` and the
/// velocity-dependent outputs itself. Also the time `self.t`, and the load rates, which
/// every free method holds in its `self.loads` alike.
macro_rules! free_solver_common {
    () => {
        fn time(&self) -> f64 {
            self.t
        }

        fn set_load_rates(&mut self, rates: &[f64]) -> Result<(), $crate::solver::SolverError> {
            self.m.check_loads("load rates", rates)?;
            self.rollback.touch();
            self.loads.set_rates(rates, self.t);
            Ok(())
        }

        fn positions(&self, out: &mut [f64]) {
            self.m.positions(&self.q, &self.p, out);
        }

        fn rotations(&self, out: &mut [f64]) {
            self.m.rotations(&self.q, &self.p, out);
        }

        fn modal(&self) -> &[f64] {
            &self.q.as_slice()[self.m.nr..]
        }

        fn strain_energy(&self) -> f64 {
            self.m.strain_energy(&self.q)
        }

        fn frame(&self) -> Option<Frame> {
            Some(self.m.frame(&self.q, &self.p))
        }

        $crate::solver::rollback::rollback_items!();
    };
}

/// The velocity-dependent [`crate::solver::Solver`] items of a free method that keeps its
/// velocities `self.v` and accelerations `self.acc` at the sample (implicit, split; the
/// explicit method's velocities are staggered and computed on demand).
macro_rules! free_solver_sampled_velocity {
    () => {
        fn velocities(&self, out: &mut [f64]) {
            self.m.fields(&self.v, &self.p, out);
        }

        fn accelerations(&self, out: &mut [f64]) {
            self.m.fields(&self.acc, &self.p, out);
        }

        fn rotation_rates(&self, out: &mut [f64]) {
            self.m.rotation_rates(&self.v, &self.p, out);
        }

        fn kinetic_energy(&self) -> f64 {
            self.m.kinetic_energy(&self.v, &self.p)
        }

        fn frame_rates(&self) -> Option<$crate::solver::FrameRates> {
            Some($crate::solver::free::frame_rates(
                &self.p,
                self.v.as_slice(),
            ))
        }

        fn momentum(&self) -> Option<[f64; 3]> {
            Some(self.m.momentum(&self.v, &self.p))
        }
    };
}

pub mod continuous;
pub mod explicit;
pub mod implicit;
mod lu;
mod rotation;
pub mod split;
mod validity;

pub use explicit::Explicit;
pub use implicit::Implicit;
pub(crate) use rotation::rotation_vector;
pub use split::Split;
pub use validity::{
    DRAG_WARN, FRAME_RETRY_FRACTION, MAX_FRAME_ERROR, MAX_HALVINGS, SPIN_STEP, SPIN_WARN_RATIO,
    TRUSS_DRAGGED, TRUSS_GAIN_EXPLICIT, TRUSS_GAIN_SPLIT, TRUSS_IMPLICIT_400, TRUSS_SPLIT_300,
    drag_consequence, three_digits,
};
pub(crate) use validity::{
    SINGULAR_RATIO, drag_warning, frame_error, frame_invalid, overflow, singular_error,
    spin_warning,
};

/// The key of a factorisation that belongs to no step: NaN never compares equal, so
/// the first comparison with real step sizes asks for a new factorisation. A plain pair
/// rather than `Option<(f64, f64)>`: comparing an `Option` that is `None` with `Some(..)`
/// let the compiler read the uninitialised payload of `None`, which memcheck reported as
/// an uninitialised-value use once per free implicit step under an fmpy master (issue 13).
pub(crate) const NO_KEY: (f64, f64) = (f64::NAN, f64::NAN);

/// The six distance constraints: frame points (a, b) (0 = L0, j = Lj) and the target
/// squared distance.
pub(crate) const PAIRS: [(usize, usize, f64); 6] = [
    (1, 0, 1.0),
    (2, 0, 1.0),
    (3, 0, 1.0),
    (2, 1, 2.0),
    (3, 1, 2.0),
    (3, 2, 2.0),
];

/// Offset of frame point `p` (0 = L0, 1..3 = L1..L3) in `q_R`.
#[inline]
pub(crate) fn point_offset(p: usize) -> usize {
    if p == 0 { 9 } else { 3 * (p - 1) }
}

/// Edge vector of frame point `p` relative to L0: zero for L0, column j of P for Lj.
#[inline]
pub(crate) fn edge(p: &Matrix3<f64>, point: usize) -> Vector3<f64> {
    if point == 0 {
        Vector3::zeros()
    } else {
        p.column(point - 1).into_owned()
    }
}

/// Velocity (or acceleration) of frame point `p` read from the rigid part of a vector.
#[inline]
pub(crate) fn point_vec(v: &[f64], point: usize) -> Vector3<f64> {
    let o = point_offset(point);
    Vector3::new(v[o], v[o + 1], v[o + 2])
}

/// The 3 x 12 matrix B(P) with `omega = B v_R[0..12]`: the frame angular velocity
/// (global components) from the frame point velocities, FORMULATION.md section 2:
/// local `omega_l = (-e2.e3_dot, e1.e3_dot, -e1.e2_dot)` with `e_j_dot = v_Lj - v_L0`,
/// global `omega = P omega_l`, i.e.
/// `omega = -e1 e2^T (v3 - v0) + e2 e1^T (v3 - v0) - e3 e1^T (v2 - v0)`.
pub(crate) fn omega_matrix(p: &Matrix3<f64>) -> [[f64; 12]; 3] {
    let e1 = p.column(0);
    let e2 = p.column(1);
    let e3 = p.column(2);
    let mut b = [[0.0; 12]; 3];
    for (r, row) in b.iter_mut().enumerate() {
        for c in 0..3 {
            let on_v3 = -e1[r] * e2[c] + e2[r] * e1[c];
            let on_v2 = -e3[r] * e1[c];
            row[6 + c] = on_v3;
            row[3 + c] = on_v2;
            row[9 + c] = -on_v3 - on_v2;
        }
    }
    b
}

/// Frame angular velocity (global) from the rigid velocities and the frame.
pub(crate) fn frame_omega(p: &Matrix3<f64>, v: &[f64]) -> Vector3<f64> {
    let b = omega_matrix(p);
    let mut w = Vector3::zeros();
    for r in 0..3 {
        w[r] = (0..12).map(|i| b[r][i] * v[i]).sum();
    }
    w
}

/// The frame's rates from the coordinate velocities `v` (rigid part first) and the
/// frame P: L0's velocity and [`frame_omega`].
pub(crate) fn frame_rates(p: &Matrix3<f64>, v: &[f64]) -> crate::solver::FrameRates {
    crate::solver::FrameRates {
        velocity: point_vec(v, 0).into(),
        omega: frame_omega(p, v).into(),
    }
}

/// Time derivative of the frame angular velocity at fixed frame-point accelerations,
/// `dB/dt v_R[0..12]`: the part of `d omega / dt` that comes from the moving frame,
/// `-e1_dot (e2.e3_dot) - e1 (e2_dot.e3_dot) + e2_dot (e1.e3_dot) + e2 (e1_dot.e3_dot)
///  - e3_dot (e1.e2_dot) - e3 (e1_dot.e2_dot)`.
pub(crate) fn omega_rate_from_frame(p: &Matrix3<f64>, v: &[f64]) -> Vector3<f64> {
    let v0 = point_vec(v, 0);
    let d1 = point_vec(v, 1) - v0;
    let d2 = point_vec(v, 2) - v0;
    let d3 = point_vec(v, 3) - v0;
    let e1 = p.column(0).into_owned();
    let e2 = p.column(1).into_owned();
    let e3 = p.column(2).into_owned();
    -d1 * e2.dot(&d3) - e1 * d2.dot(&d3) + d2 * e1.dot(&d3) + e2 * d1.dot(&d3)
        - d3 * e1.dot(&d2)
        - e3 * d1.dot(&d2)
}

/// A free body as one scene sees it: the body's matrices with the mode rows of the
/// exposed nodes only, the scene's gravity and damping, and the kinematic maps every
/// free method shares (coordinates to node outputs, nodal loads to generalised forces,
/// energies). Each method holds one, as its field `m`.
#[derive(Debug, Clone)]
pub(crate) struct FreeScene {
    /// Number of rigid coordinates (12 or 15).
    pub nr: usize,
    /// Number of local modes.
    pub nl: usize,
    /// Rotational DOFs (Irot = 1).
    pub irot: bool,
    /// Number of exposed nodes.
    pub nexp: usize,
    /// Initial frame.
    pub p0: Matrix3<f64>,
    /// Initial global position of L0.
    pub origin0: Vector3<f64>,
    pub m_r: DMatrix<f64>,
    pub m_c_kl: Vec<DMatrix<f64>>,
    pub k_c_kl: Vec<DMatrix<f64>>,
    pub m_l: DVector<f64>,
    pub k_l: DMatrix<f64>,
    /// Rayleigh alpha (mass) and beta (stiffness).
    pub ray_a: f64,
    pub ray_b: f64,
    /// The added modal damping on the local coordinates, applied where `beta K_L` is
    /// ([`super::damping::LocalDamping::added_matrix`]); `None` without it.
    pub c_add: Option<DMatrix<f64>>,
    /// The explicit scheme's stable step with this damping.
    pub dt_fx: f64,
    /// Rigid modes at the exposed nodes (`6 m x nr`), row-major: row `r` is
    /// `phi_r_rows[r * nr..(r + 1) * nr]`, so that the per-node sums of the outputs and
    /// of the load projection read contiguous memory.
    pub phi_r_rows: Vec<f64>,
    /// Local modes at the exposed nodes (`6 m x nl`), row-major like `phi_r_rows`.
    pub phi_l_rows: Vec<f64>,
    /// `K_L` row-major (row `j` is `k_l_rows[j * nl..(j + 1) * nl]`).
    pub k_l_rows: Vec<f64>,
    /// Initial coordinates of the exposed nodes.
    pub x0: Vec<Vector3<f64>>,
    /// Uniform-translation pattern of gravity, `s` (nr).
    pub s_grav: DVector<f64>,
    /// `G_R = M_R s`.
    pub g_r: DVector<f64>,
    /// Circular frequency of the first (lowest non-zero) local mode, rad/s; infinite
    /// without local modes.
    pub omega1: f64,
    /// Mass scale used to scale constraint rows.
    pub mass_scale: f64,
}

impl FreeScene {
    /// Check the body and collect what the methods need (`damping_ratio`: the added
    /// modal damping ratio, [`super::damping`]).
    pub fn new(scene: &Scene, damping_ratio: f64) -> Result<FreeScene, SolverError> {
        let body = &scene.body;
        // The body's shape (nR = 12 or 15, M_R nR x nR, nine M_C,kl and K_C,kl of
        // nR x nL, m_L > 0) and its mass (M_R definite on the rigid motions) are what
        // every Body holds by construction (crate::body::Body); only the support is this
        // method's to check.
        if body.is_blocked() {
            return Err(SolverError::BadInput(crate::solver::BadInput::NotFree));
        }
        let nr = body.nr();
        let nl = body.nl();
        if scene.x0.len() != scene.nodes.len() {
            return Err(SolverError::BadLength {
                what: "scene x0",
                expected: scene.nodes.len(),
                found: scene.x0.len(),
            });
        }
        if let Some(&n) = scene.nodes.iter().find(|&&n| n >= body.nnodes()) {
            return Err(SolverError::BadInput(crate::solver::BadInput::Node {
                index: n,
                nodes: body.nnodes(),
            }));
        }
        let phi_r = scene.exposed_rows(&body.phi_r);
        let phi_l = scene.exposed_rows(&body.phi_l);
        let x0: Vec<Vector3<f64>> = scene.x0.iter().map(|x| Vector3::from(*x)).collect();
        // L0 from the exposed nodes: x0_n = x_L0 + P0 (X, Y, Z)_n.
        let mut origin0 = Vector3::zeros();
        for (k, x) in x0.iter().enumerate() {
            let local = Vector3::new(phi_r[(6 * k, 0)], phi_r[(6 * k, 3)], phi_r[(6 * k, 6)]);
            origin0 += x - body.p0 * local;
        }
        if !x0.is_empty() {
            origin0 /= x0.len() as f64;
        }
        let mut s_grav = DVector::zeros(nr);
        for c in 0..3 {
            for j in 0..4 {
                s_grav[3 * j + c] = scene.gravity[c];
            }
        }
        let g_r = &body.m_r * &s_grav;
        let omega1 = body
            .frequencies_hz
            .iter()
            .copied()
            .filter(|&f| f > 0.0)
            .fold(f64::INFINITY, f64::min)
            * 2.0
            * std::f64::consts::PI;
        let damping = super::damping::LocalDamping::new(body, damping_ratio)?;
        // Positive and finite: the body's translation mass is (checked at construction).
        let mass_scale = (0..12).map(|i| body.m_r[(i, i)].abs()).fold(0.0, f64::max);
        let row_major = |a: &DMatrix<f64>| -> Vec<f64> {
            (0..a.nrows())
                .flat_map(|r| (0..a.ncols()).map(move |c| a[(r, c)]))
                .collect()
        };
        Ok(FreeScene {
            phi_r_rows: row_major(&phi_r),
            phi_l_rows: row_major(&phi_l),
            k_l_rows: row_major(&body.k_l),
            nr,
            nl,
            irot: body.irot,
            nexp: scene.nodes.len(),
            p0: body.p0,
            origin0,
            m_r: body.m_r.clone(),
            m_c_kl: body.m_c.clone(),
            k_c_kl: body.k_c.clone(),
            m_l: body.m_l.clone(),
            k_l: body.k_l.clone(),
            ray_a: damping.alpha,
            ray_b: damping.beta,
            c_add: damping.added_matrix(body),
            dt_fx: damping.explicit_stable_step(body),
            x0,
            s_grav,
            g_r,
            omega1,
            mass_scale,
        })
    }

    /// Number of coordinates `nr + nl`.
    pub fn nq(&self) -> usize {
        self.nr + self.nl
    }

    /// Number of constraint rows (6, or 9 with Irot = 1).
    pub fn nc(&self) -> usize {
        if self.irot { 9 } else { 6 }
    }

    /// `M_C = sum_kl P_kl M_C,kl` and `K_C = sum_kl P_lk K_C,kl` (transposed P element).
    pub fn frame_matrices(&self, p: &Matrix3<f64>, mc: &mut DMatrix<f64>, kc: &mut DMatrix<f64>) {
        // One pass per output entry over the nine sub-blocks (terms added in the order
        // kl = 00, 01, ..., 22), instead of nine passes over the output.
        let len = mc.len();
        let mut pm = [0.0; 9];
        let mut pk = [0.0; 9];
        for k in 0..3 {
            for l in 0..3 {
                pm[3 * k + l] = p[(k, l)];
                pk[3 * k + l] = p[(l, k)];
            }
        }
        combine(&pm, &self.m_c_kl, &mut mc.as_mut_slice()[..len]);
        combine(&pk, &self.k_c_kl, &mut kc.as_mut_slice()[..len]);
    }

    /// Generalised forces of the nodal loads at time `t` with frame `p`
    /// (FORMULATION.md section 2); overwrites `f_r` and `f_l`.
    pub fn project_loads(
        &self,
        loads: &Loads,
        t: f64,
        p: &Matrix3<f64>,
        f_r: &mut DVector<f64>,
        f_l: &mut DVector<f64>,
    ) {
        f_r.fill(0.0);
        f_l.fill(0.0);
        for k in 0..self.nexp {
            let b = 6 * k;
            let f = Vector3::new(loads.at(b, t), loads.at(b + 1, t), loads.at(b + 2, t));
            let m = Vector3::new(loads.at(b + 3, t), loads.at(b + 4, t), loads.at(b + 5, t));
            if f == Vector3::zeros() && m == Vector3::zeros() {
                continue;
            }
            let (nr, nl) = (self.nr, self.nl);
            let pr = &self.phi_r_rows;
            for i in 0..nr {
                let rows = if i < 12 { b } else { b + 3 };
                let g = if i < 12 { &f } else { &m };
                f_r[i] += (0..3).map(|c| g[c] * pr[(rows + c) * nr + i]).sum::<f64>();
            }
            let fl = p.tr_mul(&f);
            let ml = p.tr_mul(&m);
            let pl = &self.phi_l_rows;
            for j in 0..nl {
                let mut s = 0.0;
                for c in 0..3 {
                    s += fl[c] * pl[(b + c) * nl + j] + ml[c] * pl[(b + 3 + c) * nl + j];
                }
                f_l[j] += s;
            }
        }
    }

    /// `G_L = M_C^T s` for the current M_C, added to `out`.
    pub fn add_gravity_local(&self, mc: &DMatrix<f64>, out: &mut DVector<f64>) {
        out.gemv_tr(1.0, mc, &self.s_grav, 1.0);
    }

    /// Initial velocities from a body velocity V and angular velocity w:
    /// `v_L0 = V`, `v_Lj = V + w x P0(:,j)`; with Irot = 1 the rotational DOF rates are w.
    pub fn initial_velocity(&self, vb: [f64; 3], wb: [f64; 3], v: &mut DVector<f64>) {
        v.fill(0.0);
        let vv = Vector3::from(vb);
        let w = Vector3::from(wb);
        for j in 1..4 {
            let vj = vv + w.cross(&self.p0.column(j - 1));
            let o = point_offset(j);
            v.rows_mut(o, 3).copy_from(&vj);
        }
        v.rows_mut(9, 3).copy_from(&vv);
        if self.irot {
            v.rows_mut(12, 3).copy_from(&w);
        }
    }

    /// Strain energy `1/2 alpha^T K_L alpha`.
    pub fn strain_energy(&self, q: &DVector<f64>) -> f64 {
        let a = &q.as_slice()[self.nr..self.nr + self.nl];
        0.5 * bilinear(&self.k_l, a, a)
    }

    /// Kinetic energy `1/2 v_R^T M_R v_R + v_R^T M_C v_L + 1/2 sum m_L v_L^2` with
    /// `M_C` for the frame `p`.
    pub fn kinetic_energy(&self, v: &DVector<f64>, p: &Matrix3<f64>) -> f64 {
        let vr = &v.as_slice()[..self.nr];
        let vl = &v.as_slice()[self.nr..self.nr + self.nl];
        let mut e = 0.5 * bilinear(&self.m_r, vr, vr);
        for k in 0..3 {
            for l in 0..3 {
                let pk = p[(k, l)];
                if pk != 0.0 {
                    e += pk * bilinear(&self.m_c_kl[3 * k + l], vr, vl);
                }
            }
        }
        e + 0.5
            * (0..self.nl)
                .map(|j| self.m_l[j] * vl[j] * vl[j])
                .sum::<f64>()
    }

    /// Linear momentum `s_c^T (M_R v_R + M_C(P) v_L)` for the three global axes c
    /// ([`crate::solver::Solver::momentum`]); `s_c` moves the four frame points by
    /// `e_c` and the rotational DOFs and modes not at all.
    pub fn momentum(&self, v: &DVector<f64>, p: &Matrix3<f64>) -> [f64; 3] {
        let (nr, nl) = (self.nr, self.nl);
        let vr = &v.as_slice()[..nr];
        let vl = &v.as_slice()[nr..nr + nl];
        let mut out = [0.0; 3];
        for (c, o) in out.iter_mut().enumerate() {
            let rows = [c, 3 + c, 6 + c, 9 + c];
            let mut s = 0.0;
            for &i in &rows {
                s += (0..nr).map(|k| self.m_r[(i, k)] * vr[k]).sum::<f64>();
                for k in 0..3 {
                    for l in 0..3 {
                        let pkl = p[(k, l)];
                        if pkl != 0.0 {
                            let mc = &self.m_c_kl[3 * k + l];
                            s += pkl * (0..nl).map(|j| mc[(i, j)] * vl[j]).sum::<f64>();
                        }
                    }
                }
            }
            *o = s;
        }
        out
    }

    /// Node vector field `sum_{i<12} r_i Phi_R,i(n)_trans + P sum_j l_j Phi_L,j(n)_trans`
    /// of exposed node `k` for a coordinate-like vector `x = [r; l]` (displacement,
    /// velocity or acceleration).
    pub fn node_field(&self, k: usize, x: &DVector<f64>, p: &Matrix3<f64>) -> Vector3<f64> {
        let b = 6 * k;
        let (nr, nl) = (self.nr, self.nl);
        let x = x.as_slice();
        let mut rig = Vector3::zeros();
        let mut loc = Vector3::zeros();
        for c in 0..3 {
            let pr = &self.phi_r_rows[(b + c) * nr..(b + c) * nr + 12];
            rig[c] = pr.iter().zip(&x[..12]).map(|(f, y)| y * f).sum::<f64>();
            let pl = &self.phi_l_rows[(b + c) * nl..(b + c + 1) * nl];
            loc[c] = pl.iter().zip(&x[nr..]).map(|(f, y)| y * f).sum::<f64>();
        }
        rig + p * loc
    }

    /// Positions `x0 + u` of the exposed nodes.
    pub fn positions(&self, q: &DVector<f64>, p: &Matrix3<f64>, out: &mut [f64]) {
        for k in 0..self.nexp.min(out.len() / 3) {
            let x = self.x0[k] + self.node_field(k, q, p);
            out[3 * k..3 * k + 3].copy_from_slice(x.as_slice());
        }
    }

    /// Node vector field of every exposed node (velocities or accelerations).
    pub fn fields(&self, x: &DVector<f64>, p: &Matrix3<f64>, out: &mut [f64]) {
        for k in 0..self.nexp.min(out.len() / 3) {
            let f = self.node_field(k, x, p);
            out[3 * k..3 * k + 3].copy_from_slice(f.as_slice());
        }
    }

    /// Node rotation rates: the frame's angular velocity (Irot = 0) or the rotational
    /// DOF rates `sum_{13..15} v_R,i Phi_R,i(n)_rot` (Irot = 1), plus
    /// `P sum_j alpha_dot_j Phi_L,j(n)_rot`.
    pub fn rotation_rates(&self, v: &DVector<f64>, p: &Matrix3<f64>, out: &mut [f64]) {
        let w = frame_omega(p, v.as_slice());
        for k in 0..self.nexp.min(out.len() / 3) {
            let b = 6 * k + 3;
            let mut rig = Vector3::zeros();
            let mut loc = Vector3::zeros();
            let (nr, nl) = (self.nr, self.nl);
            for c in 0..3 {
                rig[c] = if self.irot {
                    (12..15)
                        .map(|i| v[i] * self.phi_r_rows[(b + c) * nr + i])
                        .sum::<f64>()
                } else {
                    w[c]
                };
                let pl = &self.phi_l_rows[(b + c) * nl..(b + c + 1) * nl];
                loc[c] = pl
                    .iter()
                    .zip(&v.as_slice()[nr..])
                    .map(|(f, y)| y * f)
                    .sum::<f64>();
            }
            let r = rig + p * loc;
            out[3 * k..3 * k + 3].copy_from_slice(r.as_slice());
        }
    }

    /// Node rotation vectors (FORMULATION.md section 9): the frame's rotation
    /// `P P0^T` followed by the local small rotation `P theta_l`,
    /// `theta_l = sum_j alpha_j Phi_L,j(n)_rot`, i.e. `log(exp([P theta_l]) P P0^T)`.
    /// P satisfies its constraints only to their tolerance: the rotation is read
    /// through a unit quaternion, which absorbs that drift. Zeros for nodes without
    /// rotational DOFs (Irot = 0).
    pub fn rotations(&self, q: &DVector<f64>, p: &Matrix3<f64>, out: &mut [f64]) {
        let rf = p * self.p0.transpose();
        let (nr, nl) = (self.nr, self.nl);
        for k in 0..self.nexp.min(out.len() / 3) {
            if !self.irot {
                out[3 * k..3 * k + 3].fill(0.0);
                continue;
            }
            let b = 6 * k + 3;
            let mut loc = Vector3::zeros();
            for c in 0..3 {
                let pl = &self.phi_l_rows[(b + c) * nl..(b + c + 1) * nl];
                loc[c] = pl
                    .iter()
                    .zip(&q.as_slice()[nr..])
                    .map(|(f, a)| a * f)
                    .sum::<f64>();
            }
            let theta = p * loc;
            let r = nalgebra::Rotation3::from_scaled_axis(theta).matrix() * rf;
            let v = rotation_vector(&r);
            out[3 * k..3 * k + 3].copy_from_slice(v.as_slice());
        }
    }

    /// The frame output: origin of L0 and P row-major.
    pub fn frame(&self, q: &DVector<f64>, p: &Matrix3<f64>) -> super::Frame {
        let o = self.origin0 + Vector3::new(q[9], q[10], q[11]);
        let mut pr = [0.0; 9];
        for r in 0..3 {
            for c in 0..3 {
                pr[3 * r + c] = p[(r, c)];
            }
        }
        super::Frame {
            origin: [o[0], o[1], o[2]],
            p: pr,
        }
    }

    /// Frame from coordinates: `P = P0 + [q_Lj - q_L0]_j`.
    pub fn frame_of(&self, q: &[f64]) -> Matrix3<f64> {
        let mut p = self.p0;
        for j in 0..3 {
            for c in 0..3 {
                p[(c, j)] += q[3 * j + c] - q[9 + c];
            }
        }
        p
    }

    /// Check loads or rates for this scene's exposed nodes ([`super::loads::check`]).
    pub fn check_loads(&self, what: &'static str, x: &[f64]) -> Result<(), SolverError> {
        super::loads::check(what, x, 6 * self.nexp)
    }
}

/// `out = sum_i w_i blocks_i` entry by entry, the terms added in the order i = 0..9
/// (from zero, so the sums equal nine accumulating passes bit for bit).
fn combine(w: &[f64; 9], blocks: &[DMatrix<f64>], out: &mut [f64]) {
    let n = out.len();
    let b: [&[f64]; 9] = std::array::from_fn(|i| &blocks[i].as_slice()[..n]);
    for (e, x) in out.iter_mut().enumerate() {
        let mut s = 0.0;
        for i in 0..9 {
            s += w[i] * b[i][e];
        }
        *x = s;
    }
}
