//! Exact modal stepping of a blocked body.
//!
//! A blocked body is linear: `diag(m_L) a + (beta K_L + alpha diag(m_L)) v + K_L q = F_L`.
//! With `m^-1/2 K_L m^-1/2 = V diag(w^2) V^T` and `q = S y`, `S = m^-1/2 V`, every mode
//! obeys `y'' + d y' + w^2 y = S^T F_L` with `d = alpha + beta w^2 = 2 zeta w`: Rayleigh
//! damping stays modal. Each mode is advanced exactly over a step for a load that is
//! held, or varies linearly when rates are set, so the only error left is the load model
//! between samples. The transition coefficients are computed once per distinct step size;
//! two sizes are kept, so a constant step with an odd last step does not recompute them.
//!
//! State layout (`State::data`): time, then the load part (`t_set`, 6m loads, 6m rates),
//! then the modal amplitudes y (nL) and modal velocities y' (nL).

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use super::expm::mode_coefficients;
use super::nodes::{Exposed, check_state};
use super::{Frame, Method, Solver, SolverError, State};
use crate::scene::Scene;

/// The exact modal solver.
#[derive(Debug, Clone)]
pub struct Exact {
    time: f64,
    io: Exposed,
    /// `S = m^-1/2 V`, physical from modal coordinates.
    basis: DMatrix<f64>,
    omega: Vec<f64>,
    damp: Vec<f64>,
    y: DVector<f64>,
    yd: DVector<f64>,
    ya: DVector<f64>,
    q: DVector<f64>,
    coef: [Vec<[f64; 8]>; 2],
    coef_h: [f64; 2],
    next_slot: usize,
}

impl Exact {
    /// Diagonalise the body and precompute the exposed-node rows in the modal basis.
    pub fn new(scene: &Scene) -> Result<Exact, SolverError> {
        let body = &scene.body;
        let nl = body.nl();
        let inv_sqrt = body.m_l.map(|m| 1.0 / m.sqrt());
        let scaled = DMatrix::from_fn(nl, nl, |i, j| body.k_l[(i, j)] * inv_sqrt[i] * inv_sqrt[j]);
        // nalgebra refuses an empty matrix: a body without local modes has nothing to
        // diagonalise.
        let (values, vectors) = if nl == 0 {
            (DVector::zeros(0), DMatrix::zeros(0, 0))
        } else {
            let eig = SymmetricEigen::new(scaled);
            (eig.eigenvalues, eig.eigenvectors)
        };
        let basis = DMatrix::from_fn(nl, nl, |i, j| inv_sqrt[i] * vectors[(i, j)]);
        let (a, b) = body.damping.map_or((0.0, 0.0), |r| (r.alpha, r.beta));
        let omega: Vec<f64> = values.iter().map(|&l| l.max(0.0).sqrt()).collect();
        let damp = omega.iter().map(|&w| a + b * w * w).collect();
        let io = Exposed::new(scene, &basis)?;
        Ok(Exact {
            time: 0.0,
            io,
            basis,
            omega,
            damp,
            y: DVector::zeros(nl),
            yd: DVector::zeros(nl),
            ya: DVector::zeros(nl),
            q: DVector::zeros(nl),
            coef: [vec![[0.0; 8]; nl], vec![[0.0; 8]; nl]],
            coef_h: [f64::NAN; 2],
            next_slot: 0,
        })
    }

    /// Modal circular frequencies (rad/s), in the order of the modal basis.
    pub fn omegas(&self) -> &[f64] {
        &self.omega
    }

    fn update_acceleration(&mut self) {
        for i in 0..self.y.len() {
            let w = self.omega[i];
            self.ya[i] =
                self.io.force(i, self.time) - self.damp[i] * self.yd[i] - w * w * self.y[i];
        }
    }

    fn state_len(&self) -> usize {
        1 + self.io.saved_len() + 2 * self.y.len()
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
        self.io.set_loads(loads, self.time)?;
        self.update_acceleration();
        Ok(())
    }

    fn set_load_rates(&mut self, rates: &[f64]) -> Result<(), SolverError> {
        self.io.set_rates(rates, self.time)?;
        self.update_acceleration();
        Ok(())
    }

    fn step(&mut self, h: f64) -> Result<(), SolverError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(SolverError::BadStep(h));
        }
        let slot = match self.coef_h.iter().position(|&c| c == h) {
            Some(slot) => slot,
            None => {
                let slot = self.next_slot;
                for (i, c) in self.coef[slot].iter_mut().enumerate() {
                    *c = mode_coefficients(self.omega[i], self.damp[i], h);
                }
                if self.coef[slot].iter().flatten().any(|c| !c.is_finite()) {
                    // w h overflows (h near f64::MAX): refuse before any state changes.
                    self.coef_h[slot] = f64::NAN;
                    return Err(SolverError::Unsupported {
                        method: Method::Exact,
                        why: format!("a step of {h} s overflows the modal transition"),
                    });
                }
                self.next_slot = 1 - slot;
                self.coef_h[slot] = h;
                slot
            }
        };
        let t0 = self.time;
        for i in 0..self.y.len() {
            let c = &self.coef[slot][i];
            let f0 = self.io.force(i, t0);
            let f1 = self.io.fd[i];
            let (y, v) = (self.y[i], self.yd[i]);
            self.y[i] = c[0] * y + c[1] * v + c[2] * f0 + c[3] * f1;
            self.yd[i] = c[4] * y + c[5] * v + c[6] * f0 + c[7] * f1;
        }
        self.time = t0 + h;
        self.update_acceleration();
        self.q.gemv(1.0, &self.basis, &self.y, 0.0);
        Ok(())
    }

    fn positions(&self, out: &mut [f64]) {
        self.io.positions(&self.y, out);
    }

    fn velocities(&self, out: &mut [f64]) {
        self.io.translations(&self.yd, out);
    }

    fn accelerations(&self, out: &mut [f64]) {
        self.io.translations(&self.ya, out);
    }

    fn rotation_rates(&self, out: &mut [f64]) {
        self.io.rotations(&self.yd, out);
    }

    fn modal(&self) -> &[f64] {
        self.q.as_slice()
    }

    fn strain_energy(&self) -> f64 {
        0.5 * self
            .y
            .iter()
            .zip(&self.omega)
            .map(|(y, w)| w * w * y * y)
            .sum::<f64>()
    }

    fn kinetic_energy(&self) -> f64 {
        0.5 * self.yd.norm_squared()
    }

    fn frame(&self) -> Option<Frame> {
        None
    }

    fn state(&self) -> State {
        let mut data = Vec::with_capacity(self.state_len());
        data.push(self.time);
        self.io.save(&mut data);
        data.extend(self.y.iter());
        data.extend(self.yd.iter());
        State {
            method: Method::Exact,
            data,
        }
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
        self.update_acceleration();
        self.q.gemv(1.0, &self.basis, &self.y, 0.0);
        Ok(())
    }
}
