//! The acceleration evaluation of the explicit free-body scheme (steps 2 to 6 of the
//! reference scheme; [`super`] holds the scheme's state, the stepping and the `Solver`
//! interface): the saddle-point matrix, kept while the state and steps do not change,
//! and the load-dependent right side.

use nalgebra::Matrix3;

use super::super::{
    PAIRS, SINGULAR_RATIO, edge, frame_omega, omega_matrix, overflow, point_offset, point_vec,
    singular_error,
};
use super::Explicit;
use crate::solver::SolverError;

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

impl Explicit {
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
    pub(super) fn accelerations(&mut self, t: f64, dt1: f64, dt2: f64) -> Result<(), SolverError> {
        if self.w.key != (dt1, dt2) {
            self.w.key = super::super::NO_KEY;
            self.factor_matrix(dt1, dt2)?;
            self.w.key = (dt1, dt2);
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
        if let Some(c) = &m.c_add {
            w.s_l.gemv(-1.0, c, &vl, 1.0);
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
            return Err(overflow("the accelerations"));
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
            // At build (no step yet) the matrix is the body's own.
            let at_build = self.t == 0.0 && self.dt_last == 0.0 && dt1 == 0.0;
            let spin = frame_omega(p, v).norm();
            return Err(singular_error(
                ratio,
                if at_build { 0.0 } else { dt2 },
                spin,
            ));
        }
        Ok(())
    }
}
