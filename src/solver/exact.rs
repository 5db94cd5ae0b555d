//! Exact modal stepping of a blocked body.
//!
//! A blocked body is linear: `diag(m_L) a + (beta K_L + alpha diag(m_L)) v + K_L q = F_L`.
//! With `m^-1/2 K_L m^-1/2 = V diag(w^2) V^T` and `q = S y`, `S = m^-1/2 V`, every mode
//! obeys `y'' + d y' + w^2 y = S^T F_L` with `d = alpha + beta w^2` (plus `2 zeta w`
//! with an added damping ratio, [`super::damping`]): the damping stays modal. Each mode is advanced exactly over a step for a load that is
//! held, or varies linearly when rates are set, so the only error left is the load model
//! between samples. The transition coefficients are computed once per distinct step size;
//! two sizes are kept, so a constant step with an odd last step does not recompute them.
//!
//! A step touches only the modal amplitudes: the loads are projected straight onto the
//! modes and the node outputs are read from them through rows that already hold the
//! modal basis. The local coordinates `alpha = S y` (`modal()`) and the accelerations are
//! computed only when asked for.
//!
//! State layout (`State::data`): time, then the load part (`t_set`, 6m loads, 6m rates),
//! then the modal amplitudes y (nL) and modal velocities y' (nL).

use nalgebra::{DMatrix, DVector};

use super::damping::LocalDamping;
use super::expm::mode_coefficients;
use super::nodes::{Exposed, LocalCoords, check_state, modal_basis, modal_strain_energy};
use super::{Frame, Method, Options, Solver, SolverError, State};
use crate::scene::Scene;

/// The exact modal solver.
#[derive(Debug, Clone)]
pub struct Exact {
    time: f64,
    io: Exposed,
    /// `S = m^-1/2 V`, physical from modal coordinates.
    basis: DMatrix<f64>,
    omega: Vec<f64>,
    /// `omega^2`.
    w2: Vec<f64>,
    damp: Vec<f64>,
    y: DVector<f64>,
    yd: DVector<f64>,
    alpha: LocalCoords,
    /// Per slot, the 8 transition coefficients stored coefficient by coefficient
    /// (`8 nL`: `c[k]` of mode i at `k nL + i`), so that the step runs down contiguous
    /// arrays.
    coef: [Vec<f64>; 2],
    coef_h: [f64; 2],
    next_slot: usize,
}

impl Exact {
    /// Diagonalise the body and precompute the exposed-node rows in the modal basis;
    /// the modal damping is [`LocalDamping::modal`] (Rayleigh plus the added ratio).
    pub fn new(scene: &Scene, opts: &Options) -> Result<Exact, SolverError> {
        let body = &scene.body;
        let nl = body.nl();
        let (basis, omega) = modal_basis(body);
        let damping = LocalDamping::new(body, opts.damping_ratio)?;
        let w2: Vec<f64> = omega.iter().map(|&w| w * w).collect();
        let damp = omega.iter().map(|&w| damping.modal(w)).collect();
        let io = Exposed::new(scene, &basis)?;
        Ok(Exact {
            time: 0.0,
            io,
            basis,
            omega,
            w2,
            damp,
            y: DVector::zeros(nl),
            yd: DVector::zeros(nl),
            alpha: LocalCoords::new(nl),
            coef: [vec![0.0; 8 * nl], vec![0.0; 8 * nl]],
            coef_h: [f64::NAN; 2],
            next_slot: 0,
        })
    }

    /// Modal circular frequencies (rad/s), in the order of the modal basis.
    pub fn omegas(&self) -> &[f64] {
        &self.omega
    }

    fn state_len(&self) -> usize {
        1 + self.io.saved_len() + 2 * self.y.len()
    }

    /// Node accelerations through the rows at offset `off` (0 translations, 3
    /// rotations): modal accelerations from the equation of motion, recomputed for each
    /// output value so that no workspace is needed (outputs are few, and not on the step).
    fn node_accelerations(&self, off: usize, out: &mut [f64]) {
        let n = out.len().min(3 * self.io.nodes);
        for (i, o) in out[..n].iter_mut().enumerate() {
            let row = self.io.row(i / 3, off + i % 3);
            *o = (0..self.y.len())
                .map(|j| {
                    let a = self.io.force(j, self.time)
                        - self.damp[j] * self.yd[j]
                        - self.w2[j] * self.y[j];
                    row[j] * a
                })
                .sum();
        }
    }
}

/// One exact step of every mode: `y, v <- c0..c3 (y, v, f0, fd)` and `c4..c7`, with the
/// load `f0 = f + fd dt0` reached at the start of the step. A function of its own so that
/// its slices are known not to overlap (no run-time overlap checks, which cost more than
/// the loop on 20 modes), and every slice is cut to exactly `n` so that the loop runs
/// without bounds checks and vectorises.
#[inline(never)]
fn advance(coef: &[f64], f: &[f64], fd: &[f64], dt0: f64, y: &mut [f64], v: &mut [f64]) {
    let n = y.len();
    let cs = &coef[..8 * n];
    let (c0, c1, c2, c3) = (
        &cs[..n],
        &cs[n..2 * n],
        &cs[2 * n..3 * n],
        &cs[3 * n..4 * n],
    );
    let (c4, c5, c6, c7) = (
        &cs[4 * n..5 * n],
        &cs[5 * n..6 * n],
        &cs[6 * n..7 * n],
        &cs[7 * n..8 * n],
    );
    let (f, fd, v) = (&f[..n], &fd[..n], &mut v[..n]);
    for i in 0..n {
        let f0 = f[i] + fd[i] * dt0;
        let (y0, v0) = (y[i], v[i]);
        y[i] = c0[i] * y0 + c1[i] * v0 + c2[i] * f0 + c3[i] * fd[i];
        v[i] = c4[i] * y0 + c5[i] * v0 + c6[i] * f0 + c7[i] * fd[i];
    }
}

impl Solver for Exact {
    fn method(&self) -> Method {
        Method::Exact
    }

    fn time(&self) -> f64 {
        self.time
    }

    fn set_loads(&mut self, loads: &[f64]) -> Result<(), SolverError> {
        self.io.set_loads(loads, self.time)
    }

    fn set_load_rates(&mut self, rates: &[f64]) -> Result<(), SolverError> {
        self.io.set_rates(rates, self.time)
    }

    fn step(&mut self, h: f64) -> Result<(), SolverError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(SolverError::BadStep(h));
        }
        let slot = match self.coef_h.iter().position(|&c| c == h) {
            Some(slot) => slot,
            None => {
                let slot = self.next_slot;
                let nl = self.y.len();
                for i in 0..nl {
                    let c = mode_coefficients(self.omega[i], self.damp[i], h);
                    for (k, &ck) in c.iter().enumerate() {
                        self.coef[slot][k * nl + i] = ck;
                    }
                }
                if self.coef[slot].iter().any(|c| !c.is_finite()) {
                    // w h overflows (h near f64::MAX): refuse before any state changes.
                    self.coef_h[slot] = f64::NAN;
                    return Err(SolverError::Unsupported {
                        method: Method::Exact,
                        why: format!(
                            "a step of {} s overflows the modal transition (omega h is not finite)",
                            crate::num::num(h)
                        ),
                    });
                }
                self.next_slot = 1 - slot;
                self.coef_h[slot] = h;
                slot
            }
        };
        let t0 = self.time;
        // Load over the step: f0 + fd s, f0 the value reached at t0.
        let dt0 = t0 - self.io.held.t_set;
        advance(
            &self.coef[slot],
            self.io.f.as_slice(),
            self.io.fd.as_slice(),
            dt0,
            self.y.as_mut_slice(),
            self.yd.as_mut_slice(),
        );
        self.time = t0 + h;
        self.alpha.invalidate();
        Ok(())
    }

    fn positions(&self, out: &mut [f64]) {
        self.io.positions(&self.y, out);
    }

    fn position(&self, k: usize) -> Option<f64> {
        self.io.position(k, &self.y)
    }

    fn velocities(&self, out: &mut [f64]) {
        self.io.translations(&self.yd, out);
    }

    fn accelerations(&self, out: &mut [f64]) {
        self.node_accelerations(0, out);
    }

    fn rotation_rates(&self, out: &mut [f64]) {
        self.io.rotations(&self.yd, out);
    }

    fn rotations(&self, out: &mut [f64]) {
        self.io.rotations(&self.y, out);
    }

    fn rotation_accelerations(&self, out: &mut [f64]) -> bool {
        self.node_accelerations(3, out);
        true
    }

    fn modal(&self) -> &[f64] {
        self.alpha.get(&self.basis, &self.y)
    }

    fn strain_energy(&self) -> f64 {
        modal_strain_energy(&self.y, &self.w2)
    }

    fn kinetic_energy(&self) -> f64 {
        0.5 * self.yd.norm_squared()
    }

    fn frame(&self) -> Option<Frame> {
        None
    }

    fn state(&self) -> State {
        let mut s = State {
            method: Method::Exact,
            data: Vec::with_capacity(self.state_len()),
        };
        self.state_into(&mut s);
        s
    }

    fn state_into(&self, out: &mut State) {
        out.method = Method::Exact;
        let data = &mut out.data;
        data.clear();
        data.push(self.time);
        self.io.save(data);
        data.extend(self.y.iter());
        data.extend(self.yd.iter());
    }

    fn set_state(&mut self, state: &State) -> Result<(), SolverError> {
        check_state(state, Method::Exact, self.state_len())?;
        let d = &state.data;
        let nl = self.y.len();
        let k = 1 + self.io.saved_len();
        self.time = d[0];
        self.io.restore(&d[1..k]);
        self.y.copy_from_slice(&d[k..k + nl]);
        self.yd.copy_from_slice(&d[k + nl..k + 2 * nl]);
        self.alpha.invalidate();
        Ok(())
    }
}
