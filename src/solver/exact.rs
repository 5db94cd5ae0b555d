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
//! A step is out of place: it reads the amplitudes and velocities from one of two buffers
//! and writes the other, so the state before the step is still there for
//! [`Solver::undo`] (the FMU's step guard takes a refused step back without having
//! copied anything).
//!
//! State layout (`State::data`): time, then the load part (`t_set`, 6m loads, 6m rates),
//! then the modal amplitudes y (nL) and modal velocities y' (nL).

use nalgebra::{DMatrix, DVector};

use super::damping::LocalDamping;
use super::expm::mode_coefficients;
use super::loads::Loads;
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
    /// Modal amplitudes, two buffers: `y[cur]` is the state, a step writes the other.
    y: [DVector<f64>; 2],
    /// Modal velocities, buffered like `y`.
    yd: [DVector<f64>; 2],
    cur: usize,
    /// The sum of squares of the time and the amplitudes and velocities the last step
    /// wrote ([`Solver::stepped_squares`]).
    squares: f64,
    undo: Undo,
    alpha: LocalCoords,
    /// Per slot, the 8 transition coefficients stored coefficient by coefficient
    /// (`8 nL`: `c[k]` of mode i at `k nL + i`), so that the step runs down contiguous
    /// arrays.
    coef: [Vec<f64>; 2],
    coef_h: [f64; 2],
    next_slot: usize,
}

/// What [`Solver::undo`] puts back besides the other buffer: the time and held load
/// from before the open step.
#[derive(Debug, Clone)]
struct Undo {
    /// A [`Solver::begin_undoable`] is open.
    open: bool,
    /// A step ran since it opened: its input is `y[1 - cur]`, `yd[1 - cur]`, `time`.
    stepped: bool,
    time: f64,
    /// `held` holds the load values and `t_set` from before their first change since it
    /// opened.
    kept_values: bool,
    /// `held` holds the rates from before their first change since it opened.
    kept_rates: bool,
    held: Loads,
}

impl Undo {
    /// Keep the held load's values and rates once, before they first change in an open
    /// step: `set_load_rates` changes both (`set_loads` moves the values itself).
    #[inline]
    fn keep(&mut self, held: &Loads) {
        if !self.open {
            return;
        }
        if !self.kept_values {
            self.held.values.copy_from_slice(&held.values);
            self.held.t_set = held.t_set;
            self.kept_values = true;
        }
        if !self.kept_rates {
            self.held.rates.copy_from_slice(&held.rates);
            self.kept_rates = true;
        }
    }
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
        let held = io.held.clone();
        Ok(Exact {
            time: 0.0,
            io,
            basis,
            omega,
            w2,
            damp,
            y: [DVector::zeros(nl), DVector::zeros(nl)],
            yd: [DVector::zeros(nl), DVector::zeros(nl)],
            cur: 0,
            squares: f64::INFINITY,
            undo: Undo {
                open: false,
                stepped: false,
                time: 0.0,
                kept_values: false,
                kept_rates: false,
                held,
            },
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
        1 + self.io.saved_len() + 2 * self.nl()
    }

    fn nl(&self) -> usize {
        self.omega.len()
    }

    /// The modal amplitudes (the current buffer).
    #[inline]
    fn y(&self) -> &DVector<f64> {
        &self.y[self.cur]
    }

    /// The modal velocities (the current buffer).
    #[inline]
    fn yd(&self) -> &DVector<f64> {
        &self.yd[self.cur]
    }

    /// Node accelerations through the rows at offset `off` (0 translations, 3
    /// rotations): modal accelerations from the equation of motion, recomputed for each
    /// output value so that no workspace is needed (outputs are few, and not on the step).
    fn node_accelerations(&self, off: usize, out: &mut [f64]) {
        let n = out.len().min(3 * self.io.nodes);
        for (i, o) in out[..n].iter_mut().enumerate() {
            let row = self.io.row(i / 3, off + i % 3);
            let (y, yd) = (self.y(), self.yd());
            *o = (0..y.len())
                .map(|j| {
                    let a = self.io.force(j, self.time) - self.damp[j] * yd[j] - self.w2[j] * y[j];
                    row[j] * a
                })
                .sum();
        }
    }
}

/// One exact step of every mode: `y', v' = c0..c3 (y, v, f0, fd)` and `c4..c7`, with the
/// load `f0 = f + fd dt0` reached at the start of the step, from `(y, v)` into the other
/// buffers `(y', v')`; returns the sum of squares of every `y'` and `v'` written (NaN or
/// infinite if one is not finite or the sum overflows), for the FMU's step guard, which
/// then reads nothing. A function of its own so that its slices are known not to overlap
/// (no run-time overlap checks, which cost more than the loop on 20 modes), and every
/// slice is cut to exactly `n` so that the loop runs without bounds checks. Modes go two
/// at a time with one sum per lane of the pair, so that the pair is one vector operation
/// and the sums need no reordering of additions.
// Eight arguments: each slice its own argument is what tells the compiler that none
// overlaps (a tuple of slices loses that).
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn advance(
    coef: &[f64],
    f: &[f64],
    fd: &[f64],
    dt0: f64,
    y: &[f64],
    v: &[f64],
    y_new: &mut [f64],
    v_new: &mut [f64],
) -> f64 {
    let n = y_new.len();
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
    let (f, fd, y, v) = (&f[..n], &fd[..n], &y[..n], &v[..n]);
    let v_new = &mut v_new[..n];
    // One mode, written out where it is used (a closure is not always inlined).
    macro_rules! mode {
        ($i:expr) => {{
            let i = $i;
            let f0 = f[i] + fd[i] * dt0;
            let (y0, v0) = (y[i], v[i]);
            (
                c0[i] * y0 + c1[i] * v0 + c2[i] * f0 + c3[i] * fd[i],
                c4[i] * y0 + c5[i] * v0 + c6[i] * f0 + c7[i] * fd[i],
            )
        }};
    }
    let mut acc = [0.0f64; 2];
    for p in 0..n / 2 {
        let i = 2 * p;
        let (a0, b0) = mode!(i);
        let (a1, b1) = mode!(i + 1);
        (y_new[i], v_new[i], y_new[i + 1], v_new[i + 1]) = (a0, b0, a1, b1);
        acc[0] += a0 * a0 + b0 * b0;
        acc[1] += a1 * a1 + b1 * b1;
    }
    let mut sum = acc[0] + acc[1];
    if n % 2 == 1 {
        let (a, b) = mode!(n - 1);
        (y_new[n - 1], v_new[n - 1]) = (a, b);
        sum += a * a + b * b;
    }
    sum
}

impl Solver for Exact {
    fn method(&self) -> Method {
        Method::Exact
    }

    fn time(&self) -> f64 {
        self.time
    }

    fn set_loads(&mut self, loads: &[f64]) -> Result<(), SolverError> {
        // `set_loads` writes every value: the held values move to the undo buffer
        // instead of being copied there, and come back if the loads are refused.
        let moved = self.undo.open && !self.undo.kept_values;
        if moved {
            std::mem::swap(&mut self.undo.held.values, &mut self.io.held.values);
            self.undo.held.t_set = self.io.held.t_set;
            self.undo.kept_values = true;
        }
        let set = self.io.set_loads(loads, self.time);
        if moved && set.is_err() {
            std::mem::swap(&mut self.undo.held.values, &mut self.io.held.values);
            self.undo.kept_values = false;
        }
        set
    }

    fn set_load_rates(&mut self, rates: &[f64]) -> Result<(), SolverError> {
        self.undo.keep(&self.io.held);
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
                let nl = self.nl();
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
        // Out of place: from the current buffers into the others.
        let (c, n) = (self.cur, 1 - self.cur);
        let ([y0, y1], [v0, v1]) = (&mut self.y, &mut self.yd);
        let (y, y_new, v, v_new) = if c == 0 {
            (&*y0, y1, &*v0, v1)
        } else {
            (&*y1, y0, &*v1, v0)
        };
        let squares = advance(
            &self.coef[slot],
            self.io.f.as_slice(),
            self.io.fd.as_slice(),
            dt0,
            y.as_slice(),
            v.as_slice(),
            y_new.as_mut_slice(),
            v_new.as_mut_slice(),
        );
        self.cur = n;
        if self.undo.open {
            self.undo.stepped = true;
            self.undo.time = t0;
        }
        self.time = t0 + h;
        self.squares = self.time * self.time + squares;
        self.alpha.invalidate();
        Ok(())
    }

    fn positions(&self, out: &mut [f64]) {
        self.io.positions(self.y(), out);
    }

    fn position(&self, k: usize) -> Option<f64> {
        self.io.position(k, self.y())
    }

    fn velocities(&self, out: &mut [f64]) {
        self.io.translations(self.yd(), out);
    }

    fn accelerations(&self, out: &mut [f64]) {
        self.node_accelerations(0, out);
    }

    fn rotation_rates(&self, out: &mut [f64]) {
        self.io.rotations(self.yd(), out);
    }

    fn rotations(&self, out: &mut [f64]) {
        self.io.rotations(self.y(), out);
    }

    fn rotation_accelerations(&self, out: &mut [f64]) -> bool {
        self.node_accelerations(3, out);
        true
    }

    fn modal(&self) -> &[f64] {
        self.alpha.get(&self.basis, &self.y[self.cur])
    }

    fn strain_energy(&self) -> f64 {
        modal_strain_energy(self.y(), &self.w2)
    }

    fn kinetic_energy(&self) -> f64 {
        0.5 * self.yd().norm_squared()
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
        data.extend_from_slice(self.y().as_slice());
        data.extend_from_slice(self.yd().as_slice());
    }

    fn set_state(&mut self, state: &State) -> Result<(), SolverError> {
        check_state(state, Method::Exact, self.state_len())?;
        let d = &state.data;
        let nl = self.nl();
        let k = 1 + self.io.saved_len();
        self.time = d[0];
        self.io.restore(&d[1..k]);
        self.y[self.cur].copy_from_slice(&d[k..k + nl]);
        self.yd[self.cur].copy_from_slice(&d[k + nl..k + 2 * nl]);
        self.alpha.invalidate();
        self.undo.open = false;
        Ok(())
    }

    fn begin_undoable(&mut self) -> bool {
        self.undo.open = true;
        self.undo.stepped = false;
        self.undo.kept_values = false;
        self.undo.kept_rates = false;
        true
    }

    fn undo(&mut self) {
        if !self.undo.open {
            return;
        }
        self.undo.open = false;
        if self.undo.stepped {
            // The step wrote the other buffers: its input is still in them.
            self.cur = 1 - self.cur;
            self.time = self.undo.time;
            self.alpha.invalidate();
        }
        if self.undo.kept_values {
            if !self.undo.kept_rates {
                // Unchanged since: the current rates are the ones to keep.
                self.undo.held.rates.copy_from_slice(&self.io.held.rates);
            }
            self.io.set_held(&self.undo.held);
        }
    }

    fn stepped_squares(&self) -> f64 {
        self.squares
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Method, Options, build};

    /// Out-of-place stepping keeps its promise against a twin that never undoes: after
    /// loads, rates and a step (an ordinary one, and one under a huge load), `undo` puts
    /// the saved state back bit for bit, and the run continued from there equals the
    /// twin's bit for bit. The step's own sum of squares equals the one computed from the
    /// saved state (time, amplitudes, velocities) to rounding.
    #[test]
    fn undo_puts_back_every_bit_and_the_step_measures_its_state() {
        let scene = crate::fmu::scene_io::cantilever_tip_scene();
        let opts = Options::default();
        let mut s = build(&scene, Method::Exact, &opts).unwrap();
        let mut twin = build(&scene, Method::Exact, &opts).unwrap();
        let h = 1e-3;
        for k in 0..40 {
            let f = [0.0, (k as f64).sin(), 0.3, 0.0, 0.0, 0.1];
            let r = [0.0, 0.0, (k as f64).cos(), 0.0, 0.0, 0.0];
            let before = s.state();
            assert!(s.begin_undoable());
            if k % 3 == 0 {
                s.set_load_rates(&r).unwrap();
            }
            // A refused load changes nothing, kept or not.
            assert!(s.set_loads(&[f64::NAN; 6]).is_err());
            if k % 3 != 0 {
                assert_eq!(s.state(), before, "step {k}");
            }
            s.set_loads(&[0.0, 1e300, 0.0, 0.0, 0.0, 0.0]).unwrap();
            s.step(h).unwrap();
            assert!(s.state() != before);
            s.undo();
            assert_eq!(s.state(), before, "step {k}");
            // An undo with nothing open changes nothing.
            s.undo();
            assert_eq!(s.state(), before, "step {k}");
            for x in [&mut s, &mut twin] {
                if k % 3 == 0 {
                    x.set_load_rates(&r).unwrap();
                }
                x.set_loads(&f).unwrap();
                x.step(h).unwrap();
            }
            assert_eq!(s.state(), twin.state(), "step {k}");
            // State layout: time, t_set, 6 loads, 6 rates, then y and y' (20 modes each).
            let st = s.state();
            let reference: f64 = std::iter::once(st.data[0])
                .chain(st.data[14..].iter().copied())
                .map(|x| x * x)
                .sum();
            let got = s.stepped_squares();
            assert!(
                (got - reference).abs() <= 1e-14 * reference,
                "step {k}: {got} against {reference}"
            );
        }
    }
}
