//! Exact modal stepping of a blocked body.
//!
//! A blocked body is linear: `diag(m_L) a + (beta K_L + alpha diag(m_L)) v + K_L q = F_L`.
//! With `m^-1/2 K_L m^-1/2 = V diag(w^2) V^T` and `q = S y`, `S = m^-1/2 V`, every mode
//! obeys `y'' + d y' + w^2 y = S^T F_L` with `d = alpha + beta w^2` (plus `2 zeta w`
//! with an added damping ratio, [`super::damping`]): the damping stays modal. Each mode
//! is advanced exactly over a step for a load that is held, or varies linearly when rates
//! are set, so the only error left is the load model between samples. The transition
//! coefficients are computed once per distinct step size; two sizes are kept, so a
//! constant step with an odd last step does not recompute them.
//!
//! A step touches only the modal amplitudes: the loads are projected straight onto the
//! modes and the node outputs are read from them through rows that already hold the
//! modal basis. The local coordinates `alpha = S y` (`modal()`) and the accelerations are
//! computed only when asked for.
//!
//! With the coefficients of a step size comes its [`Growth`]: how far one step can carry
//! the energy norm `sqrt(sum w^2 y^2 + y'^2)` ([`BoundedStep::measure`]) under held loads. A
//! damped mode's energy does not grow without load, so the transition's norm in the
//! scaled coordinates `(w y, y')` is at most 1 (plus rounding, which the bound includes),
//! and a load adds at most its projection times the forcing column's norm. The FMU's step
//! guard uses it to know before a step that the step cannot overflow.
//!
//! State layout (`State::data`): time, then the load part (`t_set`, 6m loads, 6m rates),
//! then the modal amplitudes y (nL) and modal velocities y' (nL).

use nalgebra::DVector;

use super::continuous::{Continuous, NOMINAL_LOAD, check_states, modal_acceleration};
use super::expm::mode_coefficients;
use super::nodes::{Exposed, LocalCoords, Modes, modal_solver_items};
use super::rollback::{Restorable, Rollback};
use super::{BoundedStep, Growth, Method, Options, Solver, SolverError, SolverWarning, State};
use crate::scene::Scene;

/// The exact modal solver.
#[derive(Debug, Clone)]
pub struct Exact {
    time: f64,
    io: Exposed,
    modes: Modes,
    y: DVector<f64>,
    yd: DVector<f64>,
    alpha: LocalCoords,
    /// Per slot, the 8 transition coefficients stored coefficient by coefficient
    /// (`8 nL`: `c[k]` of mode i at `k nL + i`), so that the step runs down contiguous
    /// arrays.
    coef: [Vec<f64>; 2],
    coef_h: [f64; 2],
    /// Per slot, the growth of a step of `coef_h` ([`Exact::growth_of`]).
    growth: [Growth; 2],
    next_slot: usize,
    /// `||gt||_F sqrt(6m)`: the modal load's 2-norm per unit of the largest load.
    load_gain: f64,
    /// `max(1, 1 / w_min)`: every amplitude and velocity is at most this times the
    /// energy norm (infinite with a zero frequency).
    scale: f64,
    /// The state a refused step goes back to (used only after a checkpoint: the step
    /// itself cannot fail once it has begun).
    rollback: Rollback,
}

/// Rounding allowance of the growth bound: relative, far above the few ulps a step and
/// the norms themselves can be off by, far below anything that matters to the guard.
const SLACK: f64 = 1e-12;

/// The 2-norm of the 2x2 matrix `[[a, b], [c, d]]` (its largest singular value).
fn norm2(a: f64, b: f64, c: f64, d: f64) -> f64 {
    0.5 * ((a + d).hypot(b - c) + (a - d).hypot(b + c))
}

impl Exact {
    /// Diagonalise the body and precompute the exposed-node rows in the modal basis;
    /// the modal damping is [`super::damping::LocalDamping::modal`] (Rayleigh plus the added ratio).
    pub fn new(scene: &Scene, opts: &Options) -> Result<Exact, SolverError> {
        let body = &scene.body;
        let nl = body.nl();
        let modes = Modes::new(body, opts.damping_ratio)?;
        let io = Exposed::new(scene, &modes.basis)?;
        let load_gain = io.gt.norm() * ((6 * io.nodes) as f64).sqrt() * (1.0 + SLACK);
        let w_min = modes.omega.iter().copied().fold(f64::INFINITY, f64::min);
        let scale = if w_min > 0.0 {
            (1.0 / w_min).max(1.0) * (1.0 + SLACK)
        } else {
            f64::INFINITY
        };
        let none = Growth {
            state: f64::INFINITY,
            load: f64::INFINITY,
            scale,
        };
        let mut exact = Exact {
            time: 0.0,
            io,
            modes,
            y: DVector::zeros(nl),
            yd: DVector::zeros(nl),
            alpha: LocalCoords::new(nl),
            coef: [vec![0.0; 8 * nl], vec![0.0; 8 * nl]],
            coef_h: [f64::NAN; 2],
            growth: [none; 2],
            next_slot: 0,
            load_gain,
            scale,
            rollback: Rollback::new(Method::Exact, 0),
        };
        exact.rollback = Rollback::new(Method::Exact, exact.state_len());
        Ok(exact)
    }

    /// Nothing to do after the loads changed: every output is read from the modal state.
    fn refresh(&mut self) {}

    /// Modal circular frequencies (rad/s), in the order of the modal basis.
    pub fn omegas(&self) -> &[f64] {
        &self.modes.omega
    }

    /// The coefficient slot of a step of `h`, computed if neither slot holds it.
    #[inline]
    fn slot(&mut self, h: f64) -> Result<usize, SolverError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(SolverError::BadStep(h));
        }
        match self.coef_h.iter().position(|&c| c == h) {
            Some(slot) => Ok(slot),
            None => self.new_slot(h),
        }
    }

    /// Compute the coefficients of a step of `h` into the older slot, and their growth.
    #[cold]
    #[inline(never)]
    fn new_slot(&mut self, h: f64) -> Result<usize, SolverError> {
        let slot = self.next_slot;
        let nl = self.y.len();
        for i in 0..nl {
            let c = mode_coefficients(self.modes.omega[i], self.modes.damp[i], h);
            for (k, &ck) in c.iter().enumerate() {
                self.coef[slot][k * nl + i] = ck;
            }
        }
        if self.coef[slot].iter().any(|c| !c.is_finite()) {
            // w h overflows (h near f64::MAX): refuse before any state changes.
            self.coef_h[slot] = f64::NAN;
            return Err(SolverError::Unsupported {
                method: Method::Exact,
                why: super::Unsupported::TransitionOverflow(h),
            });
        }
        self.growth[slot] = self.growth_of(slot);
        self.next_slot = 1 - slot;
        self.coef_h[slot] = h;
        Ok(slot)
    }

    /// The growth of the step whose coefficients are in `slot` (held loads: the rate
    /// columns `c3`, `c7` do not enter). Per mode, in the scaled coordinates `(w y, y')`,
    /// the transition is `[[c0, w c1], [c4 / w, c5]]` and a unit modal load adds
    /// `(w c2, c6)`; the state factor is the largest transition norm, the load factor the
    /// largest forcing norm times [`Exact::load_gain`]. Each term carries [`SLACK`] for
    /// the rounding of the step and of these norms: the rounding error of a step is at
    /// most a few ulps of `|M| |u|`, whose norm is at most the Frobenius norm of `M`
    /// times that of `u`. Infinite factors (a zero frequency) make every guard test fail,
    /// which sends each step to the full check.
    fn growth_of(&self, slot: usize) -> Growth {
        let nl = self.y.len();
        let c = |k: usize, i: usize| self.coef[slot][k * nl + i];
        let (mut state, mut force) = (0.0f64, 0.0f64);
        for (i, &w) in self.modes.omega.iter().enumerate() {
            let (a, b, cc, d) = (c(0, i), w * c(1, i), c(4, i) / w, c(5, i));
            let frobenius = (a * a + b * b + cc * cc + d * d).sqrt();
            let g = norm2(a, b, cc, d) * (1.0 + SLACK) + SLACK * frobenius;
            // `max` would drop a NaN: a zero frequency must give an infinite factor.
            state = if g.is_nan() || g > state { g } else { state };
            let k = (w * c(2, i)).hypot(c(6, i)) * (1.0 + SLACK);
            force = if k.is_nan() || k > force { k } else { force };
        }
        let fix = |x: f64| if x.is_nan() { f64::INFINITY } else { x };
        Growth {
            state: fix(state),
            load: fix(force * self.load_gain),
            scale: self.scale,
        }
    }

    /// Node accelerations through the rows at offset `off` (0 translations, 3
    /// rotations): modal accelerations from the equation of motion, recomputed for each
    /// output value so that no workspace is needed (outputs are few, and not on the step).
    fn node_accelerations(&self, off: usize, out: &mut [f64]) {
        let n = out.len().min(3 * self.io.nodes);
        for (i, o) in out[..n].iter_mut().enumerate() {
            let row = self.io.row(i / 3, off + i % 3);
            *o = (0..self.y.len())
                .map(|j| row[j] * self.acceleration(j))
                .sum();
        }
    }
}

impl Exact {
    /// The modal acceleration of mode `j` now: the equation every step solves exactly
    /// ([`modal_acceleration`]).
    #[inline]
    fn acceleration(&self, j: usize) -> f64 {
        let g = self.io.force(j, self.time);
        modal_acceleration(
            g,
            self.modes.damp[j],
            self.modes.w2[j],
            self.y[j],
            self.yd[j],
        )
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
    modal_solver_items!(Method::Exact, yd);

    /// The exact step cannot fail once it has begun (a bad step size, or one whose
    /// transition overflows, is refused before anything changes), so it saves nothing.
    #[inline]
    fn step(&mut self, h: f64) -> Result<Option<SolverWarning>, SolverError> {
        Rollback::step(self, false, |s| s.advance(h))?;
        Ok(None)
    }

    fn accelerations(&self, out: &mut [f64]) {
        self.node_accelerations(0, out);
    }

    fn rotation_accelerations(&self, out: &mut [f64]) -> bool {
        self.node_accelerations(3, out);
        true
    }

    fn set_state(&mut self, state: &State) -> Result<(), SolverError> {
        let parts = &mut [self.y.as_mut_slice(), self.yd.as_mut_slice()];
        self.time = self.io.read_state(state, Method::Exact, parts)?;
        self.alpha.invalidate();
        self.rollback.forget();
        Ok(())
    }

    fn bounded(&mut self) -> Option<&mut dyn BoundedStep> {
        Some(self)
    }

    /// The caller may change the continuous states through it: the state measured last
    /// is stale.
    fn continuous(&mut self) -> Option<&mut dyn Continuous> {
        self.rollback.touch();
        Some(self)
    }
}

impl Restorable for Exact {
    fn rollback(&mut self) -> &mut Rollback {
        &mut self.rollback
    }

    fn write_state(&self, data: &mut Vec<f64>) {
        let parts = [self.y.as_slice(), self.yd.as_slice()];
        self.io.write_state(data, self.time, &parts);
    }

    fn state_len(&self) -> usize {
        self.io.state_len(&[self.y.as_slice(), self.yd.as_slice()])
    }
}

impl BoundedStep for Exact {
    #[inline]
    fn growth(&mut self, h: f64) -> Option<Growth> {
        let slot = self.slot(h).ok()?;
        Some(self.growth[slot])
    }

    /// `sqrt(sum w^2 y^2 + y'^2)`, twice the strain plus kinetic energy under the root.
    fn measure(&self) -> f64 {
        (2.0 * (self.strain_energy() + self.kinetic_energy())).sqrt() * (1.0 + SLACK)
    }
}

impl Exact {
    /// One exact step of every mode ([`advance`]); refused before any change when `h`
    /// is not a usable step.
    #[inline]
    fn advance(&mut self, h: f64) -> Result<(), SolverError> {
        let slot = self.slot(h)?;
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
}

/// The states are `y` then `y'` (the modal amplitudes and velocities of [`Exact`]).
impl Continuous for Exact {
    fn state_count(&self) -> usize {
        2 * self.y.len()
    }

    fn states(&self, out: &mut [f64]) {
        let nl = self.y.len();
        out[..nl].copy_from_slice(self.y.as_slice());
        out[nl..2 * nl].copy_from_slice(self.yd.as_slice());
    }

    fn set_states(&mut self, time: f64, x: &[f64]) -> Result<(), SolverError> {
        let nl = self.y.len();
        check_states(x, 2 * nl)?;
        self.y.as_mut_slice().copy_from_slice(&x[..nl]);
        self.yd.as_mut_slice().copy_from_slice(&x[nl..]);
        self.time = time;
        self.alpha.invalidate();
        self.rollback.forget();
        Ok(())
    }

    fn set_time(&mut self, time: f64) {
        self.time = time;
    }

    fn derivatives(&self, out: &mut [f64]) {
        let nl = self.y.len();
        out[..nl].copy_from_slice(self.yd.as_slice());
        for (j, o) in out[nl..2 * nl].iter_mut().enumerate() {
            *o = self.acceleration(j);
        }
    }

    /// Per mode, the static amplitude under a load of [`NOMINAL_LOAD`] on the exposed
    /// node and component that moves it most (`NOMINAL_LOAD max_c |g_jc| / w^2`), and
    /// `w` times it for the velocity; a mode no exposed load reaches gets the largest
    /// amplitude of the others (1 if none has one).
    fn nominals(&self, out: &mut [f64]) {
        let nl = self.y.len();
        let gt = &self.io.gt;
        let amp = |j: usize| {
            let g = gt.row(j).iter().fold(0.0f64, |m, v| m.max(v.abs()));
            NOMINAL_LOAD * g / self.modes.w2[j]
        };
        let fallback = (0..nl)
            .map(amp)
            .filter(|a| a.is_finite() && *a > 0.0)
            .fold(0.0f64, f64::max);
        let fallback = if fallback > 0.0 { fallback } else { 1.0 };
        for j in 0..nl {
            let a = amp(j);
            let a = if a.is_finite() && a > 0.0 {
                a
            } else {
                fallback
            };
            out[j] = a;
            out[nl + j] = if self.modes.omega[j] > 0.0 {
                a * self.modes.omega[j]
            } else {
                a
            };
        }
    }

    /// `A = [[0, I], [-diag(w^2), -diag(d)]]`, `B = [[0], [gt]]`.
    fn jacobian(&self, a: &mut [f64], b: &mut [f64]) -> bool {
        let nl = self.y.len();
        let n = 2 * nl;
        a[..n * n].fill(0.0);
        for j in 0..nl {
            a[(nl + j) * n + j] = 1.0;
            a[j * n + nl + j] = -self.modes.w2[j];
            a[(nl + j) * n + nl + j] = -self.modes.damp[j];
        }
        let loads = self.io.gt.ncols();
        b[..n * loads].fill(0.0);
        for c in 0..loads {
            for j in 0..nl {
                b[c * n + nl + j] = self.io.gt[(j, c)];
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::{Exact, Growth};
    use crate::solver::{BoundedStep, Options, Solver};
    use fxbody_testkit::Rng;

    fn cantilever(zeta: f64) -> Exact {
        let scene = crate::scene::io::cantilever_tip_scene();
        let opts = Options {
            damping_ratio: zeta,
            ..Options::default()
        };
        Exact::new(&scene, &opts).unwrap()
    }

    /// Without damping each mode's step is a rotation in `(w y, y')`, of norm 1, and a
    /// unit modal load moves it by `((1 - cos wh) / w, sin(wh) / w)`, of norm
    /// `2 |sin(wh / 2)| / w`: the growth equals those closed forms to 1e-9 (so the bound
    /// is as tight as the physics allows), for steps from far below to far above the
    /// modes' periods.
    #[test]
    fn an_undamped_step_grows_as_the_closed_form_says() {
        let mut s = cantilever(0.0);
        s.modes.damp.iter_mut().for_each(|d| *d = 0.0);
        for h in [1e-6, 2e-4, 1e-3, 0.1, 3.7] {
            let g: Growth = s.growth(h).unwrap();
            assert!(
                (g.state - 1.0).abs() < 1e-9,
                "h {h}: state factor {}",
                g.state
            );
            let force = s
                .modes
                .omega
                .iter()
                .map(|&w| 2.0 * (0.5 * w * h).sin().abs() / w)
                .fold(0.0, f64::max);
            let expected = force * s.load_gain;
            assert!(
                (g.load / expected - 1.0).abs() < 1e-9,
                "h {h}: load factor {} against {expected}",
                g.load
            );
        }
    }

    /// The bound holds step by step against the measure computed from the state the
    /// step wrote: undamped, under- and over-damped modes, loads from 1e-3 to 1e6 and step sizes
    /// that change; a damped step never has a state factor above 1 (a damped mode's
    /// energy does not grow without load); every amplitude and velocity is within
    /// `scale` times the measure.
    #[test]
    fn the_growth_bounds_every_step() {
        let mut rng = Rng::new(0x9e37_79b9_7f4a_7c15);
        let mut unif = move || rng.uniform();
        let mut checked = 0;
        for zeta in [0.0, 0.02, 0.5, 3.0] {
            let mut s = cantilever(zeta);
            if zeta == 0.0 {
                // Undamped, the body's Rayleigh damping included.
                s.modes.damp.iter_mut().for_each(|d| *d = 0.0);
            }
            // One exposed node (the tip): six loads.
            let mut loads = [0.0; 6];
            for k in 0..300 {
                let h = [2e-4, 1e-3, 3e-2][k % 3];
                let scale = 10f64.powf(-3.0 + 9.0 * unif());
                for l in loads.iter_mut() {
                    *l = if k % 10 == 0 {
                        0.0
                    } else {
                        scale * (2.0 * unif() - 1.0)
                    };
                }
                let cap = loads.iter().fold(0.0f64, |m, l| m.max(l.abs()));
                let before = s.measure();
                let g = s.growth(h).unwrap();
                assert!(g.state <= 1.0 + 1e-9, "zeta {zeta}: {}", g.state);
                s.set_loads(&loads).unwrap();
                s.step(h).unwrap();
                let after = s.measure();
                let bound = g.state * before + g.load * cap;
                assert!(after <= bound, "zeta {zeta}, step {k}: {after} > {bound}");
                if zeta == 0.0 && cap == 0.0 && after > 0.0 {
                    // No load, no damping: the energy is kept, and the bound says so.
                    assert!(bound / after - 1.0 < 1e-9, "step {k}: {bound} vs {after}");
                }
                let largest =
                    s.y.iter()
                        .chain(s.yd.iter())
                        .fold(0.0f64, |m, x| m.max(x.abs()));
                assert!(largest <= g.scale * after, "step {k}");
                checked += 1;
            }
        }
        assert_eq!(checked, 1200);
    }
}
