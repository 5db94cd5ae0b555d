//! The Newton iteration of one generalised-alpha step of a free body ([`super`] holds
//! the scheme, its state and the `Solver` interface): residual and iteration matrix of
//! the dynamic equations and frame constraints, and their solution by eliminating the
//! local unknowns (a Schur complement on the rigid and constraint rows).

use nalgebra::Matrix3;

use super::super::{
    PAIRS, SINGULAR_RATIO, edge, frame_omega, omega_matrix, point_offset, singular_error,
};
use super::{Implicit, Params, fill_mass};
use crate::solver::SolverError;

/// Newton tolerance on the frame constraints `|d|^2 - c` (dimensionless), per unit of the
/// largest frame-point displacement when that exceeds 1.
const TOL_CONSTRAINT: f64 = 1e-13;
/// Newton tolerance on the relative acceleration update.
const TOL_ACC: f64 = 1e-11;
/// Newton tolerance on the position update `|dx| h^2 beta'`, relative to the coordinates
/// (at least the unit frame edges). A slender body (tiny torsional inertia) has a
/// round-off floor near 1e-10 in the relative acceleration update, which this accepts.
const TOL_POS: f64 = 1e-14;
/// Largest number of Newton iterations before a step is split.
pub(super) const MAX_ITER: usize = 40;
/// Keep the iteration matrix across Newton iterations (modified Newton).
const MODIFIED_NEWTON: bool = true;
/// With modified Newton, rebuild the iteration matrix when an update is larger than this
/// fraction of the previous one (slow contraction).
const REFRESH_RATIO: f64 = 0.1;

impl Implicit {
    /// One generalised-alpha step of size h; on failure the state is unchanged.
    pub(super) fn try_step(&mut self, h: f64) -> Result<(), SolverError> {
        let Params {
            am,
            af,
            gamma,
            beta,
        } = self.par;
        let (nr, nl, nq, nc) = (self.m.nr, self.m.nl, self.m.nq(), self.m.nc());
        let ca = (1.0 - af) / (1.0 - am);
        let bt = h * h * beta * ca;
        let gt = h * gamma * ca;
        let t1 = self.t + h;
        self.w.h_now = h;
        self.w.x.copy_from(&self.acc);
        self.w.lam.copy_from(&self.lam);
        let sc = self.m.mass_scale;
        let mut converged = false;
        // Modified Newton: the iteration matrix of the first iteration is kept while the
        // updates shrink fast; it is rebuilt when they stop doing so.
        let mut refresh = true;
        let mut dprev = f64::INFINITY;
        for _ in 0..MAX_ITER {
            let m = &self.m;
            let w = &mut self.w;
            // Kinematics of the end of the step for the current guess x.
            for i in 0..nq {
                let an = ((1.0 - af) * w.x[i] + af * self.acc[i] - am * self.a[i]) / (1.0 - am);
                w.an[i] = an;
                w.vn[i] = self.v[i] + h * ((1.0 - gamma) * self.a[i] + gamma * an);
                w.qn[i] =
                    self.q[i] + h * self.v[i] + h * h * ((0.5 - beta) * self.a[i] + beta * an);
            }
            let p = m.frame_of(w.qn.as_slice());
            m.frame_matrices(&p, &mut w.mc, &mut w.kc);
            m.project_loads(&self.loads, t1, &p, &mut w.f_r, &mut w.f_l);
            // Iteration matrix: M + gt D + bt K_t, constraint rows.
            if refresh {
                w.kkt.clear();
                fill_mass(m, &mut w.kkt);
            }
            // Residual of the dynamic equations, R1 = M x - F - A^T lambda (negated in res).
            let alpha = w.qn.rows(nr, nl);
            for i in 0..nr {
                let mut s = w.f_r[i] + m.g_r[i];
                for k in 0..nr {
                    s -= m.m_r[(i, k)] * w.x[k];
                }
                w.res[i] = s;
            }
            // Column by column (contiguous in M_C and K_C); each row still subtracts the
            // terms in the order j = 0, 1, ...
            for j in 0..nl {
                let (xj, aj) = (w.x[nr + j], alpha[j]);
                let mcj = &w.mc.as_slice()[j * nr..(j + 1) * nr];
                let kcj = &w.kc.as_slice()[j * nr..(j + 1) * nr];
                for ((r, &mij), &kij) in w.res[..nr].iter_mut().zip(mcj).zip(kcj) {
                    *r -= mij * xj + kij * aj;
                }
            }
            // Local rows; the per-row factors (s - x_R) and (alpha + beta v_L) are formed
            // once, in `small` and `z`, which are free until the solve.
            for i in 0..nr {
                w.small[i] = m.s_grav[i] - w.x[i];
            }
            for k in 0..nl {
                w.z[k] = alpha[k] + m.ray_b * w.vn[nr + k];
            }
            for j in 0..nl {
                let mut s = w.f_l[j] - m.m_l[j] * w.x[nr + j] - m.ray_a * m.m_l[j] * w.vn[nr + j];
                let mcj = &w.mc.as_slice()[j * nr..(j + 1) * nr];
                for (&mij, &gi) in mcj.iter().zip(&w.small[..nr]) {
                    s += mij * gi;
                }
                for (&kjk, &uk) in m.k_l_rows[j * nl..(j + 1) * nl].iter().zip(&w.z) {
                    s -= kjk * uk;
                }
                if let Some(c) = &m.c_add {
                    s -= (0..nl).map(|k| c[(j, k)] * w.vn[nr + k]).sum::<f64>();
                }
                w.res[nr + j] = s;
            }
            let vn = w.vn.as_slice();
            let mut cmax: f64 = 0.0;
            for (r, &(a, b, c)) in PAIRS.iter().enumerate() {
                let d = edge(&p, a) - edge(&p, b);
                let phi = d.norm_squared() - c;
                cmax = cmax.max(phi.abs());
                let lam = w.lam[r];
                let (row, kr) = (nq + r, nr + r);
                for cc in 0..3 {
                    let (oa, ob) = (point_offset(a) + cc, point_offset(b) + cc);
                    let g = 2.0 * d[cc];
                    // Force term A^T lambda and its derivative (constraint Hessian).
                    w.res[oa] += g * lam;
                    w.res[ob] -= g * lam;
                    if !refresh {
                        continue;
                    }
                    *w.kkt.at(oa, oa) -= bt * 2.0 * lam;
                    *w.kkt.at(ob, ob) -= bt * 2.0 * lam;
                    *w.kkt.at(oa, ob) += bt * 2.0 * lam;
                    *w.kkt.at(ob, oa) += bt * 2.0 * lam;
                    *w.kkt.at(kr, oa) -= sc * g;
                    *w.kkt.at(kr, ob) += sc * g;
                    *w.kkt.at(oa, kr) -= sc * g;
                    *w.kkt.at(ob, kr) += sc * g;
                }
                w.res[row] = sc * phi / bt;
            }
            if m.irot {
                let bm = omega_matrix(&p);
                for r in 0..3 {
                    let (row, kr) = (nq + 6 + r, nr + 6 + r);
                    let lam = w.lam[6 + r];
                    let mut g = -vn[12 + r];
                    for (i, &bri) in bm[r].iter().enumerate() {
                        g += bri * vn[i];
                        w.res[i] += bri * lam;
                        if refresh {
                            *w.kkt.at(kr, i) -= sc * bri;
                            *w.kkt.at(i, kr) -= sc * bri;
                        }
                    }
                    w.res[12 + r] -= lam;
                    if refresh {
                        *w.kkt.at(kr, 12 + r) += sc;
                        *w.kkt.at(12 + r, kr) += sc;
                    }
                    w.res[row] = sc * g / gt;
                }
            }
            self.schur_solve(&p, bt, gt, refresh)?;
            let w = &mut self.w;
            let mut dmax: f64 = 0.0;
            let mut xmax: f64 = 0.0;
            for i in 0..nq {
                w.x[i] += w.res[i];
                dmax = dmax.max(w.res[i].abs());
                xmax = xmax.max(w.x[i].abs());
            }
            for r in 0..nc {
                w.lam[r] += sc * w.res[nq + r];
            }
            if !dmax.is_finite() {
                break;
            }
            // Converged when the update is negligible (relative to the accelerations, or
            // as a position change: near round-off of the coordinates, whatever the
            // conditioning of the body) and the frame constraints hold.
            // The frame's edges are differences of frame-point coordinates: far from the
            // start (|q| of 1e3 and more) they carry |q| eps of round-off, which the
            // constraint tolerance must allow.
            let qscale = self.q.amax().max(1.0);
            let small = dmax <= TOL_ACC * xmax || dmax * bt <= TOL_POS * qscale;
            if small && cmax <= TOL_CONSTRAINT * qscale {
                converged = true;
                break;
            }
            refresh = !MODIFIED_NEWTON || dmax > REFRESH_RATIO * dprev;
            dprev = dmax;
        }
        if !converged {
            return Err(SolverError::Singular(crate::solver::Singular::Newton {
                iterations: MAX_ITER,
                h,
            }));
        }
        // Accept: the end-of-step kinematics of the converged x.
        let w = &mut self.w;
        for i in 0..nq {
            let an = ((1.0 - af) * w.x[i] + af * self.acc[i] - am * self.a[i]) / (1.0 - am);
            self.q[i] += h * self.v[i] + h * h * ((0.5 - beta) * self.a[i] + beta * an);
            self.v[i] += h * ((1.0 - gamma) * self.a[i] + gamma * an);
            self.a[i] = an;
            self.acc[i] = w.x[i];
        }
        self.lam.copy_from(&w.lam);
        self.p = self.m.frame_of(self.q.as_slice());
        self.t = t1;
        Ok(())
    }

    /// Solve the Newton (or initial-acceleration) system whose rigid block and
    /// constraint rows are in `w.kkt` and whose right side is `w.res` (layout rigid,
    /// local, constraints), by eliminating the local unknowns: the local block
    /// `L = diag(m_L)(1 + gt a_R) + (bt + gt beta) K_L` depends on the step size only, so
    /// it is factored once per step size together with `L^-1 M_C,kl^T` for the nine
    /// sub-blocks; each iteration then costs O(nL (nR + nL)) plus the small
    /// (nR + constraints) solve, instead of a dense solve of the whole system.
    /// On return `w.res` holds `[dx_R; dx_L; dlambda / mass_scale]`.
    ///
    /// With `refresh` false the matrix factored by the last call is used again (modified
    /// Newton: only the right side is new) and `w.kkt` is not read.
    pub(super) fn schur_solve(
        &mut self,
        p: &Matrix3<f64>,
        bt: f64,
        gt: f64,
        refresh: bool,
    ) -> Result<(), SolverError> {
        let m = &self.m;
        let w = &mut self.w;
        let (nr, nl, nq, nc) = (m.nr, m.nl, m.nq(), m.nc());
        // The mass matrix alone (initial accelerations, the jump of a held load): its
        // local block is diag(m_L), eliminated by division, and the factorisation kept
        // for the step size is left alone.
        let mass_only = bt == 0.0 && gt == 0.0;
        if refresh && !mass_only && w.lkey != (bt, gt) {
            // Invalidate first: a factorisation that fails below must not be taken for
            // the matrix of the old key by a later call.
            w.lkey = super::super::NO_KEY;
            w.lfac.clear();
            for j in 0..nl {
                for k in 0..nl {
                    *w.lfac.at(j, k) = (bt + gt * m.ray_b) * m.k_l[(j, k)];
                    if let Some(c) = &m.c_add {
                        *w.lfac.at(j, k) += gt * c[(j, k)];
                    }
                }
                *w.lfac.at(j, j) += m.m_l[j] * (1.0 + gt * m.ray_a);
            }
            let ratio = w.lfac.factor();
            if ratio.is_nan() || ratio <= SINGULAR_RATIO {
                return Err(SolverError::Singular(
                    crate::solver::Singular::LocalIteration { ratio, h: w.h_now },
                ));
            }
            for (idx, y) in w.ykl.iter_mut().enumerate() {
                for i in 0..nr {
                    for j in 0..nl {
                        w.z[j] = m.m_c_kl[idx][(i, j)];
                    }
                    w.lfac.solve(&mut w.z);
                    for j in 0..nl {
                        y[(j, i)] = w.z[j];
                    }
                }
            }
            w.lkey = (bt, gt);
        }
        if refresh && mass_only {
            // Y = diag(m_L)^-1 M_C^T for the current M_C.
            for i in 0..nr {
                for j in 0..nl {
                    w.y[(j, i)] = w.mc[(i, j)] / m.m_l[j];
                }
            }
        } else if refresh {
            // Y = L^-1 M_C^T with M_C = sum P_kl M_C,kl.
            w.y.fill(0.0);
            for k in 0..3 {
                for l in 0..3 {
                    let pk = p[(k, l)];
                    for (a, b) in
                        w.y.as_mut_slice()
                            .iter_mut()
                            .zip(w.ykl[3 * k + l].as_slice())
                    {
                        *a += pk * b;
                    }
                }
            }
        }
        if refresh {
            // A_RL = M_C + bt K_C, row-major.
            for i in 0..nr {
                for j in 0..nl {
                    w.arl[i * nl + j] = w.mc[(i, j)] + bt * w.kc[(i, j)];
                }
            }
            // Reduced matrix: A_RR - A_RL Y.
            for k in 0..nr {
                let yk = &w.y.as_slice()[k * nl..(k + 1) * nl];
                for i in 0..nr {
                    let mut s = 0.0;
                    for (&a, &yjk) in w.arl[i * nl..(i + 1) * nl].iter().zip(yk) {
                        s += a * yjk;
                    }
                    *w.kkt.at(i, k) -= s;
                }
            }
            let ratio = w.kkt.factor();
            if ratio.is_nan() || ratio <= SINGULAR_RATIO {
                let spin = frame_omega(&self.p, self.v.as_slice()).norm();
                return Err(singular_error(ratio, w.h_now, spin));
            }
        }
        // z = L^-1 r_L.
        w.z.copy_from_slice(&w.res[nr..nq]);
        if mass_only {
            for (z, &mj) in w.z.iter_mut().zip(m.m_l.iter()) {
                *z /= mj;
            }
        } else {
            w.lfac.solve(&mut w.z);
        }
        // Reduced system: (A_RR - A_RL Y) dx_R - A^T dl = r_R - A_RL z.
        for i in 0..nr {
            let mut r = w.res[i];
            for (&a, &zj) in w.arl[i * nl..(i + 1) * nl].iter().zip(&w.z) {
                r -= a * zj;
            }
            w.small[i] = r;
        }
        for r in 0..nc {
            w.small[nr + r] = w.res[nq + r];
        }
        w.kkt.solve(&mut w.small);
        // Back substitution: dx_L = z - Y dx_R.
        for i in 0..nr {
            w.res[i] = w.small[i];
        }
        // Column by column of Y (contiguous); each row subtracts in the order i = 0, 1, ...
        w.res[nr..nq].copy_from_slice(&w.z);
        for i in 0..nr {
            let si = w.small[i];
            let yi = &w.y.as_slice()[i * nl..(i + 1) * nl];
            for (r, &yji) in w.res[nr..nq].iter_mut().zip(yi) {
                *r -= yji * si;
            }
        }
        for r in 0..nc {
            w.res[nq + r] = w.small[nr + r];
        }
        Ok(())
    }
}
