//! The directional derivative a Model Exchange master asks for
//! (fmi2GetDirectionalDerivative, fmi3GetDirectionalDerivative): `J s` of the state
//! derivatives (and the states) with respect to the states and the load inputs.
//!
//! A blocked body's system is linear: `J` is its exact state matrix
//! ([`crate::solver::continuous::Continuous::jacobian`]). A free body's accelerations are
//! nonlinear in the attitude, the angular velocity and the modes, and no closed-form
//! Jacobian is written: their rows are the central difference of the derivatives along
//! the seed direction, `(f(x + h s) - f(x - h s)) / 2h`, the step `h` chosen from the
//! state nominals so that the largest seeded state (or load) moves by
//! [`RELATIVE_STEP`] of its nominal (loads: of
//! [`crate::solver::continuous::NOMINAL_LOAD`]); the kinematic rows (`X' = V`, the
//! quaternion rate, `y' = y'`) are exact
//! ([`crate::solver::continuous::Continuous::exact_rows`]). The states and loads are set
//! back afterwards as fmi2SetContinuousStates would set the states read before the call
//! (so a call made before the master has set any states may move the frame in its last
//! bits: the frame is then rebuilt from the states, as after a set).
//! After the first call nothing allocates.

use super::me::check_len;
use super::{Simulation, SimulationError};
use crate::fmu::vars::Kind;
use crate::solver::continuous::NOMINAL_LOAD;

/// The central difference's step, relative to the seeded states' nominals: near the
/// cube root of the machine epsilon, where the difference's truncation error (`h^2`) and
/// its rounding (`eps / h`) balance. Measured on the tumbling free-free beam against a
/// Richardson-extrapolated difference (`free::me::free_directional_derivative_matches_richardson_differences`
/// in tests/all/free/me.rs).
pub const RELATIVE_STEP: f64 = 1e-5;

/// Work arrays, sized at the first call.
#[derive(Debug, Clone, Default)]
pub(super) struct Work {
    /// The seed over the states (`n`) and over the loads (`6 m`).
    sx: Vec<f64>,
    su: Vec<f64>,
    /// `J s` over every state derivative.
    js: Vec<f64>,
    /// The states and loads at the call, the perturbed ones, the derivatives either side,
    /// the nominals.
    x0: Vec<f64>,
    xh: Vec<f64>,
    uh: Vec<f64>,
    fp: Vec<f64>,
    fm: Vec<f64>,
    nom: Vec<f64>,
    /// The exact Jacobian `A` (`n x n`) and `B` (`n x 6m`) where the method has one.
    a: Vec<f64>,
    b: Vec<f64>,
}

impl Work {
    fn size(&mut self, n: usize, m: usize) {
        for (v, len) in [
            (&mut self.sx, n),
            (&mut self.su, m),
            (&mut self.js, n),
            (&mut self.x0, n),
            (&mut self.xh, n),
            (&mut self.uh, m),
            (&mut self.fp, n),
            (&mut self.fm, n),
            (&mut self.nom, n),
        ] {
            if v.len() != len {
                v.resize(len, 0.0);
            }
        }
    }
}

impl Simulation {
    /// The directional derivative `out = J seed` of the `unknowns` (state derivative or
    /// state variables) with respect to the `knowns` (state variables and load inputs)
    /// (fmi2GetDirectionalDerivative): exact for a blocked body, a central difference
    /// for a free body's accelerations (the module notes). Outputs as unknowns are
    /// refused: their derivatives are not provided.
    pub fn directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        seed: &[f64],
        out: &mut [f64],
    ) -> Result<(), SimulationError> {
        check_len(seed.len(), knowns.len())?;
        check_len(out.len(), unknowns.len())?;
        let n = self.state_count()?;
        let m = self.loads.len();
        // The work arrays out of `self` for the call (a move: no allocation).
        let mut w = std::mem::take(&mut self.directional);
        w.size(n, m);
        let r = self.seed_into(&mut w, knowns, seed).and_then(|()| {
            self.jacobian_times_seed(&mut w)?;
            self.pick_rows(&w, unknowns, out)
        });
        self.directional = w;
        r
    }

    /// The seed spread over the states and loads (a known named twice adds up); a
    /// non-finite seed is refused.
    fn seed_into(&self, w: &mut Work, knowns: &[u32], seed: &[f64]) -> Result<(), SimulationError> {
        w.sx.fill(0.0);
        w.su.fill(0.0);
        for (&k, &s) in knowns.iter().zip(seed) {
            let var = self.var(k)?;
            if !s.is_finite() {
                return Err(SimulationError::NonFinite {
                    name: format!("the seed of {}", var.name),
                    value: s,
                });
            }
            match var.kind {
                Kind::State(j) => w.sx[j] += s,
                Kind::Load { node, comp } => w.su[6 * node + comp] += s,
                _ => {
                    return Err(SimulationError::NotAKnown {
                        name: var.name.clone(),
                    });
                }
            }
        }
        Ok(())
    }

    /// `out` for each unknown: a state derivative's row of `J s`, a state's own seed.
    fn pick_rows(
        &self,
        w: &Work,
        unknowns: &[u32],
        out: &mut [f64],
    ) -> Result<(), SimulationError> {
        for (o, &u) in out.iter_mut().zip(unknowns) {
            let var = self.var(u)?;
            *o = match var.kind {
                Kind::Derivative(i) => w.js[i],
                // d x_i / d x: the identity; no state depends on an input.
                Kind::State(i) => w.sx[i],
                _ => {
                    return Err(SimulationError::NotAnUnknown {
                        name: var.name.clone(),
                    });
                }
            };
        }
        Ok(())
    }

    /// `w.js = J [sx; su]`: from the exact Jacobian where the method has one, else by
    /// the central difference with exact kinematic rows.
    fn jacobian_times_seed(&mut self, w: &mut Work) -> Result<(), SimulationError> {
        let (n, m) = (w.sx.len(), w.su.len());
        let exact = {
            let c = self.continuous()?;
            if w.a.len() != n * n || w.b.len() != n * m {
                // Once, at the first call.
                w.a.resize(n * n, 0.0);
                w.b.resize(n * m, 0.0);
            }
            c.jacobian(&mut w.a, &mut w.b)
        };
        if exact {
            for (i, o) in w.js.iter_mut().enumerate() {
                let ax: f64 = (0..n).map(|c| w.a[c * n + i] * w.sx[c]).sum();
                let bu: f64 = (0..m).map(|c| w.b[c * n + i] * w.su[c]).sum();
                *o = ax + bu;
            }
            return Ok(());
        }
        self.central_difference(w)
    }

    /// `w.js` by the central difference along the seed, then the rows the method knows
    /// exactly; states and loads set back.
    fn central_difference(&mut self, w: &mut Work) -> Result<(), SimulationError> {
        let t = self.time;
        {
            let c = self.continuous()?;
            c.states(&mut w.x0);
            c.nominals(&mut w.nom);
        }
        let scale =
            w.sx.iter()
                .zip(&w.nom)
                .map(|(s, v)| s.abs() / v)
                .chain(w.su.iter().map(|s| s.abs() / NOMINAL_LOAD))
                .fold(0.0f64, f64::max);
        if scale == 0.0 {
            // A zero seed: J 0 = 0.
            w.js.fill(0.0);
            return Ok(());
        }
        let h = RELATIVE_STEP / scale;
        let loads_seeded = w.su.iter().any(|&s| s != 0.0);
        let r = self.derivatives_at(w, h, loads_seeded, t).map(|()| {
            for (i, o) in w.js.iter_mut().enumerate() {
                *o = (w.fp[i] - w.fm[i]) / (2.0 * h);
            }
        });
        // Back to the states and loads of the call, whatever happened.
        let Some(s) = self.solver.as_mut() else {
            return Err(SimulationError::NoSolver);
        };
        if loads_seeded {
            s.set_loads(&self.loads)?;
        }
        let c = s.continuous().ok_or(SimulationError::NoSolver)?;
        c.set_states(t, &w.x0)?;
        r?;
        c.exact_rows(&w.x0, &w.sx, &mut w.js);
        Ok(())
    }

    /// `w.fp` and `w.fm`: the derivatives at `x0 + h sx` (loads `+ h su`) and at
    /// `x0 - h sx` (loads `- h su`). Model Exchange sets no load rates, so the loads
    /// are values at the current time, as `Simulation::continuous` passes them.
    fn derivatives_at(
        &mut self,
        w: &mut Work,
        h: f64,
        loads_seeded: bool,
        t: f64,
    ) -> Result<(), SimulationError> {
        let Some(s) = self.solver.as_mut() else {
            return Err(SimulationError::NoSolver);
        };
        for sign in [1.0, -1.0] {
            if loads_seeded {
                for ((u, &u0), &su) in w.uh.iter_mut().zip(&self.loads).zip(&w.su) {
                    *u = u0 + sign * h * su;
                }
                s.set_loads(&w.uh)?;
            }
            for ((x, &x0), &sx) in w.xh.iter_mut().zip(&w.x0).zip(&w.sx) {
                *x = x0 + sign * h * sx;
            }
            let c = s.continuous().ok_or(SimulationError::NoSolver)?;
            c.set_states(t, &w.xh)?;
            c.derivatives(if sign > 0.0 { &mut w.fp } else { &mut w.fm });
        }
        Ok(())
    }
}
