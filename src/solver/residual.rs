//! The static (residual-flexibility) correction of a truncated body, as a decorator over
//! any solver: the dropped modes follow the load quasi-statically, so the exposed nodes
//! move by `R f` on top of what the kept modes do ([`crate::scene::reduce`]).
//!
//! With `f(t) = f0 + fdot (t - t_set)` (held or linearly varying load, the solvers' load
//! model), the correction adds `P R P^T f` to the positions, `P R P^T fdot` to the
//! velocities and the rotational rows to the rotations and rotation rates; it adds nothing to the
//! accelerations (the second derivative of a piecewise-linear load is zero between
//! samples; the impulses at the samples are not represented). `P` is P0 for a blocked
//! body and the current frame of a free one (node-wise, on forces and on moments). The
//! strain energy gains `1/2 f^T R f`; the kinetic energy of the dropped modes is not
//! represented (quasi-static). Positions thus depend on the same-instant loads (a direct
//! feedthrough, which the FMI model structure must declare).
//!
//! State layout: the inner solver's data, then `t_set`, 6m loads and 6m rates.

use nalgebra::{DMatrix, Matrix3};

use super::loads::Loads;
use super::rollback::{Mark, no_checkpoint};
use super::{Frame, Method, Solver, SolverError, SolverWarning, State};
use crate::scene::Scene;

/// A solver plus the quasi-static displacement of the dropped modes at the exposed nodes.
pub struct Residual {
    inner: Box<dyn Solver>,
    /// Local-frame residual flexibility, `6m x 6m`.
    r: DMatrix<f64>,
    /// Fixed frame of a blocked body; `None` for a free body (frame from the solver).
    p_fixed: Option<Matrix3<f64>>,
    /// The caller's loads, held alongside the inner solver's copy.
    held: Loads,
    /// `held` at the last checkpoint (the inner solver keeps the rest of the state), and
    /// whether it still serves.
    checkpoint_held: Loads,
    mark: Mark,
}

impl Residual {
    /// Wrap `inner`, built for `scene`, with the scene's residual flexibility.
    pub fn new(scene: &Scene, inner: Box<dyn Solver>) -> Result<Residual, SolverError> {
        let m = scene.nodes.len();
        let r = scene
            .residual
            .as_ref()
            .map_or_else(|| DMatrix::zeros(6 * m, 6 * m), |res| res.r.clone());
        if r.nrows() != 6 * m || r.ncols() != 6 * m {
            return Err(SolverError::BadInput(super::BadInput::ResidualShape {
                rows: r.nrows(),
                cols: r.ncols(),
                nodes: m,
            }));
        }
        if r.iter().any(|v| !v.is_finite()) {
            return Err(SolverError::BadInput(super::BadInput::ResidualNotFinite));
        }
        Ok(Residual {
            inner,
            r,
            p_fixed: scene.body.is_blocked().then_some(scene.body.p0),
            held: Loads::new(6 * m),
            checkpoint_held: Loads::new(6 * m),
            mark: Mark::default(),
        })
    }

    fn frame_p(&self) -> Matrix3<f64> {
        match (self.p_fixed, self.inner.frame()) {
            (Some(p), _) => p,
            (None, Some(Frame { p, .. })) => Matrix3::from_row_slice(&p),
            (None, None) => Matrix3::identity(),
        }
    }

    /// Add `P R_(rows) P^T v` to `out` (3 per node): `rows` 0 for translations, 3 for
    /// rotations; `v` is a global load-like vector given by `value(i)` for entry i.
    fn add(&self, rows: usize, value: impl Fn(usize) -> f64, out: &mut [f64]) {
        let p = self.frame_p();
        let m = self.held.len() / 6;
        for i in 0..m.min(out.len() / 3) {
            let mut acc = [0.0; 3];
            for j in 0..m {
                let mut g = [0.0; 6];
                for half in 0..2 {
                    for b in 0..3 {
                        g[3 * half + b] = (0..3)
                            .map(|a| p[(a, b)] * value(6 * j + 3 * half + a))
                            .sum();
                    }
                }
                for (b, acc_b) in acc.iter_mut().enumerate() {
                    *acc_b += (0..6)
                        .map(|c| self.r[(6 * i + rows + b, 6 * j + c)] * g[c])
                        .sum::<f64>();
                }
            }
            for a in 0..3 {
                out[3 * i + a] += (0..3).map(|b| p[(a, b)] * acc[b]).sum::<f64>();
            }
        }
    }

    fn load(&self, k: usize) -> f64 {
        self.held.at(k, self.inner.time())
    }
}

impl Solver for Residual {
    fn method(&self) -> Method {
        self.inner.method()
    }
    fn time(&self) -> f64 {
        self.inner.time()
    }
    fn set_loads(&mut self, loads: &[f64]) -> Result<(), SolverError> {
        self.inner.set_loads(loads)?;
        self.held.set(loads, self.inner.time());
        Ok(())
    }
    fn set_load_rates(&mut self, rates: &[f64]) -> Result<(), SolverError> {
        self.inner.set_load_rates(rates)?;
        self.held.set_rates(rates, self.inner.time());
        Ok(())
    }
    fn step(&mut self, h: f64) -> Result<Option<SolverWarning>, SolverError> {
        let held = self.mark.step();
        let stepped = self.inner.step(h);
        if stepped.is_err() && held {
            self.held.copy_from(&self.checkpoint_held);
        }
        stepped
    }
    fn checkpoint(&mut self) {
        self.inner.checkpoint();
        self.checkpoint_held.copy_from(&self.held);
        self.mark.set();
    }
    fn rewind(&mut self) -> Result<(), SolverError> {
        let mut mark = self.mark;
        if !mark.rewind() {
            return Err(no_checkpoint());
        }
        self.inner.rewind()?;
        self.held.copy_from(&self.checkpoint_held);
        self.mark = mark;
        Ok(())
    }
    /// The inner solver's state: the held loads and rates beside it are the caller's
    /// inputs, which the caller bounds itself (`crate::fmu::guard`).
    fn state_below(&mut self, bound: f64) -> bool {
        self.inner.state_below(bound)
    }
    fn positions(&self, out: &mut [f64]) {
        self.inner.positions(out);
        self.add(0, |k| self.load(k), out);
    }
    fn velocities(&self, out: &mut [f64]) {
        self.inner.velocities(out);
        self.add(0, |k| self.held.rates[k], out);
    }
    fn accelerations(&self, out: &mut [f64]) {
        self.inner.accelerations(out);
    }
    fn rotation_rates(&self, out: &mut [f64]) {
        self.inner.rotation_rates(out);
        self.add(3, |k| self.held.rates[k], out);
    }
    /// The inner rotation plus the rotational rows of `P R P^T f` (exact for a blocked
    /// body, whose rotations are linear; for a free body the small correction is added
    /// to the rotation vector, right to first order in it).
    fn rotations(&self, out: &mut [f64]) {
        self.inner.rotations(out);
        self.add(3, |k| self.load(k), out);
    }
    fn rotation_accelerations(&self, out: &mut [f64]) -> bool {
        self.inner.rotation_accelerations(out)
    }
    fn modal(&self) -> &[f64] {
        self.inner.modal()
    }
    fn strain_energy(&self) -> f64 {
        // 1/2 g^T R g with g = P^T f node-wise (R is symmetric, positive semi-definite).
        let p = self.frame_p();
        let n = self.held.len();
        let g = |k: usize| -> f64 {
            let (node, c) = (k / 6, k % 6);
            let base = 6 * node + 3 * (c / 3);
            (0..3).map(|a| p[(a, c % 3)] * self.load(base + a)).sum()
        };
        let mut e = 0.0;
        for i in 0..n {
            let gi = g(i);
            if gi != 0.0 {
                e += gi * (0..n).map(|j| self.r[(i, j)] * g(j)).sum::<f64>();
            }
        }
        self.inner.strain_energy() + 0.5 * e
    }
    fn kinetic_energy(&self) -> f64 {
        self.inner.kinetic_energy()
    }
    fn momentum(&self) -> Option<[f64; 3]> {
        self.inner.momentum()
    }

    fn frame(&self) -> Option<Frame> {
        self.inner.frame()
    }
    fn frame_rates(&self) -> Option<super::FrameRates> {
        self.inner.frame_rates()
    }
    fn state(&self) -> State {
        let mut s = self.inner.state();
        self.held.save_time_first(&mut s.data);
        s
    }
    fn set_state(&mut self, state: &State) -> Result<(), SolverError> {
        let tail = self.held.state_len();
        if state.data.len() < tail {
            return Err(SolverError::BadState(super::BadState::TooShort {
                found: state.data.len(),
                min: tail,
            }));
        }
        let (head, rest) = state.data.split_at(state.data.len() - tail);
        let inner = State {
            method: state.method,
            data: head.to_vec(),
        };
        self.inner.set_state(&inner)?;
        self.held.load_time_first(rest);
        self.mark.forget();
        Ok(())
    }
    /// The kept modes' system: the dropped modes follow the loads and have no state.
    fn continuous(&mut self) -> Option<&mut dyn super::continuous::Continuous> {
        self.mark.forget();
        self.inner.continuous()
    }
}
