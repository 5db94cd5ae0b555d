//! The caller's load as the free implicit method integrates it: held over a step, or the
//! polynomial `F0 + F1 s` when input derivatives are set, each step's impulse exact.
//!
//! Generalised-alpha carries the load in its algorithmic acceleration `a` and in the
//! true acceleration `vdot` of the step's start. Both were computed with the load as it
//! was; a held input that jumps at a communication point must act from that point on,
//! so before the step the jump's acceleration, `dvdot = M^-1 dF` (the mass matrix with
//! the frame constraints, at the current state), is added to both: the body's momentum
//! then gains exactly `F h` over a step under a held `F` (`s^T M a` follows the held
//! total force, and `s^T (F_R - A^T lambda) = F` since the constraints do not resist a
//! translation). Sampling the load at the step's end instead gives, at each jump, half a
//! step of impulse too much or too little (h / (2 T) of a pulse of length T).
//!
//! With a rate `F1`, a free mass's algorithmic acceleration runs ahead of the load by
//! `(alpha_m - alpha_f) F1 h` when the impulse of every step is exact
//! (`(1 - alpha_m) a1 + alpha_m a0 = (1 - alpha_f) F(t1) + alpha_f F(t0)` and
//! `v1 - v0 = h ((1 - gamma) a0 + gamma a1)` give `int F = F0 h + F1 h^2 / 2` exactly
//! for this lead, with `gamma = 1/2 - alpha_m + alpha_f`). The lead held in `a` is kept
//! as a nodal load (`lag`); before each step it is moved to the lead the step's rate and
//! size call for, so that a derivative set for one step (FMI 2.0 clears it after the
//! step) integrates that step's polynomial, and the step after it the held value.

use crate::solver::SolverError;
use crate::solver::free::{PAIRS, edge, omega_matrix, point_offset};

use super::{FreeScene, Implicit, fill_mass};
use crate::solver::free::lu::Lu;

impl Implicit {
    /// New load values at the current time: their jump from the value the load has now
    /// is added to the accelerations before the next step.
    pub(super) fn note_jump(&mut self, loads: &[f64]) {
        let t = self.t;
        for (i, (j, &l)) in self.jump.iter_mut().zip(loads).enumerate() {
            *j += l - self.loads.at(i, t);
        }
    }

    /// Before a step of `dt`: add the acceleration of the load jump noted since the last
    /// step (when `with_jump`) to the true and the algorithmic acceleration, and move the
    /// algorithmic acceleration's lead to `(alpha_m - alpha_f) dt F1`. Nothing to do, and
    /// no work, under held loads that did not change.
    pub(super) fn hold(&mut self, dt: f64, with_jump: bool) -> Result<(), SolverError> {
        let lead = (self.par.am - self.par.af) * dt;
        let moves = (0..self.lag.len()).any(|i| lead * self.loads.rates[i] != self.lag[i]);
        let jumps = with_jump && self.jump.iter().any(|&j| j != 0.0);
        if !moves && !jumps {
            return Ok(());
        }
        // The algorithmic acceleration takes the jump and the lead's change.
        for i in 0..self.lag.len() {
            let jump = if with_jump { self.jump[i] } else { 0.0 };
            self.shift.values[i] = jump + lead * self.loads.rates[i] - self.lag[i];
        }
        let p = self.p;
        self.m.frame_matrices(&p, &mut self.w.mc, &mut self.w.kc);
        mass_matrix(&self.m, &mut self.w.kkt, &p);
        self.mass_solve(true)?;
        for i in 0..self.m.nq() {
            self.a[i] += self.w.res[i];
        }
        // The true acceleration takes the jump alone.
        if jumps {
            if moves {
                self.shift.values.copy_from_slice(&self.jump);
                self.mass_solve(false)?;
            }
            for i in 0..self.m.nq() {
                self.acc[i] += self.w.res[i];
            }
        }
        for i in 0..self.lag.len() {
            self.lag[i] = lead * self.loads.rates[i];
        }
        Ok(())
    }

    /// `M^-1` (with the frame constraints) of the generalised force of the nodal loads in
    /// `self.shift`, into `w.res[..nq]`; `refresh`: factor the matrix in `w.kkt` first.
    fn mass_solve(&mut self, refresh: bool) -> Result<(), SolverError> {
        let (nr, nq) = (self.m.nr, self.m.nq());
        let p = self.p;
        let w = &mut self.w;
        self.m
            .project_loads(&self.shift, self.shift.t_set, &p, &mut w.f_r, &mut w.f_l);
        w.res[..nr].copy_from_slice(w.f_r.as_slice());
        w.res[nr..nq].copy_from_slice(w.f_l.as_slice());
        w.res[nq..].fill(0.0);
        self.schur_solve(&p, 0.0, 0.0, refresh)
    }
}

/// The mass matrix with the frame constraints' rows and columns (their acceleration-level
/// Jacobian, scaled by the mass scale as the Newton matrix is) into `kkt`, for the frame
/// `p`: the matrix of the initial accelerations and of a load jump's.
pub(super) fn mass_matrix(m: &FreeScene, kkt: &mut Lu, p: &nalgebra::Matrix3<f64>) {
    let nr = m.nr;
    kkt.clear();
    fill_mass(m, kkt);
    let sc = m.mass_scale;
    for (r, &(a, b, _)) in PAIRS.iter().enumerate() {
        let d = edge(p, a) - edge(p, b);
        let kr = nr + r;
        for c in 0..3 {
            let (oa, ob) = (point_offset(a) + c, point_offset(b) + c);
            *kkt.at(kr, oa) -= sc * d[c];
            *kkt.at(kr, ob) += sc * d[c];
            *kkt.at(oa, kr) -= sc * d[c];
            *kkt.at(ob, kr) += sc * d[c];
        }
    }
    if m.irot {
        let bm = omega_matrix(p);
        for (r, row) in bm.iter().enumerate() {
            let kr = nr + 6 + r;
            for (i, &bri) in row.iter().enumerate() {
                *kkt.at(kr, i) -= sc * bri;
                *kkt.at(i, kr) -= sc * bri;
            }
            *kkt.at(kr, 12 + r) += sc;
            *kkt.at(12 + r, kr) += sc;
        }
    }
}
