//! The step guard of an FMU instance: a step that would leave a non-finite number in the
//! solver state or in an output a master can read is refused, and the instance keeps its
//! state from before the step ("right or loud").
//!
//! A method that steps out of place ([`Solver::begin_undoable`]: the exact method) keeps
//! the state before the step itself: the guard copies nothing, takes the sum of squares
//! the step computed as it wrote its state ([`Solver::stepped_squares`]) for its bound
//! test, and a refused step is the solver's [`Solver::undo`]. For the other methods the
//! guard holds two state buffers and copies the solver state once per step: after the
//! step, into the second buffer, which the check then reads. An accepted step swaps the
//! two (double buffering): the state after step k is the saved state before step k+1, so
//! no save runs before a step unless something else changed the solver in between
//! (building it, restoring an FMU state, passing loads to read a truncated scene's
//! outputs), which the model reports with [`StepGuard::forget`]. The buffers are reused:
//! no allocation once each has held one state. After the step the guard checks the solver
//! state (it holds everything the future depends on) and the outputs: node positions,
//! velocities and both energies. The outputs are checked as well as the state because a
//! finite state does not make them finite: they are sums of products of the state
//! with the body's matrices (and, for a truncated body, with the loads themselves), which
//! can overflow. On failure the saved state is put back and the message names the first
//! non-finite variable and the input with the largest magnitude, the usual cause.

use super::vars::{Kind, VarTable};
use crate::num::num;
use crate::scene::Scene;
use crate::solver::{Method, Solver, SolverError, State};

/// The rollback buffer and output workspace of one instance.
pub struct StepGuard {
    /// The solver state before the coming step (valid when `saved_is_current`).
    saved: State,
    /// The solver state after the last step, checked by [`StepGuard::check`].
    after: State,
    /// `saved` equals the solver's current state: the last step was accepted (or rolled
    /// back) and nothing has changed the solver since.
    saved_is_current: bool,
    /// The running step is undoable by the solver itself: nothing was saved.
    undoable: bool,
    out: Vec<f64>,
    /// Below this magnitude of every state entry and input, every checked output is
    /// certainly finite ([`output_bound`]): the outputs need not be computed.
    bound: f64,
    /// Below this magnitude of every load, their sum of squares is below `bound^2`.
    load_limit: f64,
}

/// The largest magnitude `s` of the state entries and inputs under which every output
/// the guard checks is certainly finite, so that a step whose state and inputs stay below
/// it needs no output evaluated. Each output is a sum of at most `n` terms, each a
/// product of at most three factors that are state entries or inputs (free bodies: the
/// frame P is built from the state) and one body-matrix entry of magnitude at most `a`,
/// plus a coordinate; with `s <= 1e90 / (n a)` and `n a >= 1` every such sum is below
/// `n a s^3 <= 1e270 / (n a)^2`, far from overflow. Realistic states (1e-6 .. 1e6) are far
/// below the bound, so the costly path only runs for a step that is already suspect.
fn output_bound(scene: &Scene) -> f64 {
    let b = &scene.body;
    let mut a: f64 = 1.0;
    let mut grow = |m: &[f64]| {
        for &x in m {
            a = a.max(x.abs());
        }
    };
    grow(b.phi_l.as_slice());
    grow(b.phi_r.as_slice());
    grow(b.k_l.as_slice());
    grow(b.m_l.as_slice());
    grow(b.m_r.as_slice());
    for m in b.m_c.iter().chain(&b.k_c) {
        grow(m.as_slice());
    }
    if let Some(r) = &scene.residual {
        grow(r.r.as_slice());
    }
    for x in &scene.x0 {
        grow(x);
    }
    let n = (6 * b.nnodes() + b.nr() + b.nl() + 12) as f64;
    // A non-finite matrix entry (refused by the body checks) would make every step take
    // the full check.
    let bound = 1e90 / (n * a);
    if bound.is_finite() { bound } else { 0.0 }
}

impl StepGuard {
    /// A guard for the scene's solver (one row of outputs per exposed node).
    pub fn new(scene: &Scene) -> StepGuard {
        let nodes = scene.nodes.len();
        let bound = output_bound(scene);
        StepGuard {
            bound,
            // 0.99: n limit^2 stays below bound^2 whatever the roundings.
            load_limit: 0.99 * bound / ((6 * nodes).max(1) as f64).sqrt(),
            saved: State {
                method: Method::Exact,
                data: Vec::new(),
            },
            after: State {
                method: Method::Exact,
                data: Vec::new(),
            },
            saved_is_current: false,
            undoable: false,
            out: vec![0.0; 3 * nodes],
        }
    }

    /// The magnitude under which every load is small enough for the fast check: a model
    /// that knows all its loads are below it (and no rate is on) tells
    /// [`StepGuard::check`] so, which then does not read them.
    #[inline]
    pub fn load_limit(&self) -> f64 {
        self.load_limit
    }

    /// The solver was changed outside a step (built, restored, given loads): the next
    /// [`StepGuard::save`] copies its state again.
    #[inline]
    pub fn forget(&mut self) {
        self.saved_is_current = false;
    }

    /// Before a step (and before the loads it passes): open an undoable step in the
    /// solver, or where the method cannot, make sure its state is saved: a copy only when
    /// something changed the solver since the last accepted step (see the module notes).
    #[inline]
    pub fn begin(&mut self, s: &mut dyn Solver) {
        self.undoable = s.begin_undoable();
        if !self.undoable && !self.saved_is_current {
            s.state_into(&mut self.saved);
            self.saved_is_current = true;
        }
    }

    /// Put back the state from before the step begun by [`StepGuard::begin`].
    pub fn rollback(&mut self, s: &mut dyn Solver) -> Result<(), SolverError> {
        if self.undoable {
            s.undo();
            self.saved_is_current = false;
            return Ok(());
        }
        let restored = s.set_state(&self.saved);
        self.saved_is_current = restored.is_ok();
        restored
    }

    /// Check the step of `h` just taken under `loads` and `rates` (`rates_on`: some rate
    /// is nonzero; `loads_small`: every load is below [`StepGuard::load_limit`]): the
    /// first non-finite value, named for the master, or `None` when every checked value
    /// is finite, in which case the step is accepted and its state becomes the saved one
    /// for the next step. Inlined into the model's step; the full check is out of line.
    #[inline]
    pub fn check(
        &mut self,
        s: &dyn Solver,
        table: &VarTable,
        (loads, rates, rates_on): (&[f64], &[f64], bool),
        loads_small: bool,
        h: f64,
    ) -> Option<String> {
        let b = self.bound;
        let state_below = if self.undoable {
            // The rest of the state is the held load part: the inputs tested here.
            s.stepped_squares() < b * b
        } else {
            s.state_into(&mut self.after);
            squares_below(&self.after.data, b)
        };
        let inputs_ok = (loads_small && !rates_on) || inputs_below(loads, rates, rates_on, h, b);
        if state_below && inputs_ok {
            if !self.undoable {
                std::mem::swap(&mut self.saved, &mut self.after);
                self.saved_is_current = true;
            }
            return None;
        }
        if self.undoable {
            s.state_into(&mut self.after);
        }
        let bad = self.first_non_finite(s, table);
        if bad.is_none() && !self.undoable {
            std::mem::swap(&mut self.saved, &mut self.after);
            self.saved_is_current = true;
        }
        bad
    }

    /// The full check of the outputs and of the state in `self.after`, for a step whose
    /// state or inputs reach the bound.
    #[cold]
    #[inline(never)]
    fn first_non_finite(&mut self, s: &dyn Solver, table: &VarTable) -> Option<String> {
        let named = |kind: Kind| {
            table
                .vars
                .iter()
                .find(|v| v.kind == kind)
                .map_or_else(|| format!("{kind:?}"), |v| v.name.clone())
        };
        type Fill = fn(&dyn Solver, &mut [f64]);
        let outputs: [(Fill, &str); 4] = [
            (|s, o| s.positions(o), "position"),
            (|s, o| s.velocities(o), "velocity"),
            (|s, o| s.rotations(o), "rotation"),
            (|s, o| s.rotation_rates(o), "angular velocity"),
        ];
        for (fill, what) in outputs {
            fill(s, &mut self.out);
            if let Some(k) = self.out.iter().position(|x| !x.is_finite()) {
                let (node, comp) = (k / 3, k % 3);
                return Some(match what {
                    "position" => named(Kind::Position { node, comp }),
                    "velocity" => named(Kind::Velocity { node, comp }),
                    "rotation" => named(Kind::Rotation { node, comp }),
                    "angular velocity" => named(Kind::AngularVelocity { node, comp }),
                    _ => format!(
                        "the acceleration of {}",
                        named(Kind::Position { node, comp })
                    ),
                });
            }
        }
        if !s.kinetic_energy().is_finite() {
            return Some(named(Kind::KineticEnergy));
        }
        if !s.strain_energy().is_finite() {
            return Some(named(Kind::StrainEnergy));
        }
        if self.after.data.iter().all(|x| x.is_finite()) {
            return None;
        }
        // Error path only from here: naming may allocate.
        if let Some(j) = s.modal().iter().position(|x| !x.is_finite()) {
            return Some(format!("modal amplitude {}", j + 1));
        }
        let k = self.after.data.iter().position(|x| !x.is_finite());
        Some(format!("solver state entry {}", k.unwrap_or(0)))
    }
}

/// Whether every entry of `data` is certainly below `bound` in magnitude: the sum of
/// their squares is below `bound^2` (NaN or overflow to infinity compare false). Stricter
/// than testing each entry by at most a factor `sqrt(data.len())`, which only sends a
/// step that is already near the bound to the full check.
#[inline]
fn squares_below(data: &[f64], bound: f64) -> bool {
    sum_squares(data) < bound * bound
}

/// The sum of squares behind [`squares_below`] (NaN if an entry is NaN, infinite if an
/// entry or the sum overflows). Four accumulators, read four entries at a time, so that
/// the loop vectorises into independent sums (no long chain of dependent additions) and
/// the short vectors of a step (20 modes, 12 loads) leave no remainder.
#[inline]
fn sum_squares(data: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let mut chunks = data.chunks_exact(4);
    for c in &mut chunks {
        for k in 0..4 {
            acc[k] += c[k] * c[k];
        }
    }
    // Neighbours first: lanes (0, 1) and (2, 3) stay two vector registers.
    let mut sum = (acc[0] + acc[2]) + (acc[1] + acc[3]);
    for x in chunks.remainder() {
        sum += x * x;
    }
    sum
}

/// Whether any rate is nonzero (`-0.0` counts as zero, as `r != 0.0` does): an OR of the
/// bit patterns without the sign bit, which vectorises.
#[inline]
pub fn any_nonzero(rates: &[f64]) -> bool {
    rates.iter().fold(0u64, |bits, r| bits | (r.to_bits() << 1)) != 0
}

/// Whether the loads stay certainly below `bound` in magnitude over a step of `h`: held
/// value plus rate times step, as a sum of squares like [`squares_below`]; the held
/// values alone when no rate is on. Loads and rates are finite (checked when set).
#[inline]
fn inputs_below(loads: &[f64], rates: &[f64], rates_on: bool, h: f64, bound: f64) -> bool {
    if !rates_on {
        return squares_below(loads, bound);
    }
    let sum: f64 = loads
        .iter()
        .zip(rates)
        .map(|(l, r)| {
            let x = l.abs() + r.abs() * h;
            x * x
        })
        .sum();
    sum < bound * bound
}

/// The input with the largest magnitude, loads and input rates, as `name = value`: the
/// likely cause of a non-finite step.
pub fn largest_input(table: &VarTable, loads: &[f64], rates: &[f64]) -> String {
    let big = |v: &[f64]| {
        v.iter().enumerate().fold(
            (0, 0.0f64),
            |b, (k, &x)| if x.abs() > b.1.abs() { (k, x) } else { b },
        )
    };
    let name = |k: usize| {
        let kind = Kind::Load {
            node: k / 6,
            comp: k % 6,
        };
        table
            .vars
            .iter()
            .find(|v| v.kind == kind)
            .map_or_else(|| format!("load {k}"), |v| v.name.clone())
    };
    let (kl, l) = big(loads);
    let (kr, r) = big(rates);
    if loads.is_empty() && rates.is_empty() {
        return "no input".into();
    }
    // Compare as magnitudes over a second for rates: a rate of 1e308 /s reaches a huge
    // load within the step, so the larger figure is reported.
    if r.abs() > l.abs() {
        format!("input derivative d/dt {} = {} /s", name(kr), num(r))
    } else {
        format!("{} = {}", name(kl), num(l))
    }
}

#[cfg(test)]
mod tests {
    use super::super::model::{Model, Phase};
    use super::super::vars::Causality;

    /// The fast path's claim, checked against the outputs themselves (an independent
    /// evaluation): over load magnitudes from 1 to 1e301, every method, on the whole and on
    /// a truncated cantilever, a step the guard accepts leaves every Real output finite,
    /// and both paths run (steps accepted below the bound, accepted above it after the
    /// full check, and refused).
    #[test]
    fn an_accepted_step_has_every_output_finite() {
        let full = crate::fmu::scene_io::cantilever_tip_scene();
        let (cut, _) = full.truncated(40.0).unwrap();
        let (mut fast, mut slow, mut refused) = (0, 0, 0);
        for scene in [full, cut] {
            for method in [1, 2, 3] {
                for k in (0..=301).step_by(7) {
                    let bound = super::output_bound(&scene);
                    let mut m = Model::new(scene.clone(), "{g}".into());
                    let vr = |name: &str| m.table.vars.iter().find(|v| v.name == name).unwrap().vr;
                    let (fy, meth) = (vr("node_121.fy"), vr("method"));
                    m.set_integer(meth, method, Phase::Configuring).unwrap();
                    m.setup(0.0, None).unwrap();
                    let load = 10f64.powi(k);
                    m.set_reals(&[fy], &[load], Phase::Running).unwrap();
                    match m.do_step(0.0, 1e-3) {
                        Err(e) => {
                            assert!(e.to_string().contains("non-finite"), "{e}");
                            refused += 1;
                        }
                        Ok(_) => {
                            let outs: Vec<u32> = m
                                .table
                                .vars
                                .iter()
                                .filter(|v| v.causality == Causality::Output)
                                .map(|v| v.vr)
                                .collect();
                            let mut vals = vec![0.0; outs.len()];
                            m.get_reals(&outs, &mut vals).unwrap();
                            assert!(
                                vals.iter().all(|x| x.is_finite()),
                                "method {method}, load 1e{k}: {vals:?}"
                            );
                            if load < bound {
                                fast += 1;
                            } else {
                                slow += 1;
                            }
                        }
                    }
                }
            }
        }
        assert!(
            fast > 0 && slow > 0 && refused > 0,
            "{fast} {slow} {refused}"
        );
    }

    /// Double buffering keeps its promise: wherever the solver changed between steps
    /// (loads passed to read a truncated scene's outputs, an FMU state restored, a
    /// method changed), a refused step still leaves the model exactly as before it, and
    /// accepted steps equal a twin's whose guard saved the state before every step.
    #[test]
    fn a_refused_step_restores_after_any_change_between_steps() {
        let full = crate::fmu::scene_io::cantilever_tip_scene();
        let (cut, _) = full.truncated(40.0).unwrap();
        for scene in [full, cut] {
            let mut m = Model::new(scene.clone(), "{g}".into());
            let mut twin = Model::new(scene, "{g}".into());
            let vr = |name: &str| m.table.vars.iter().find(|v| v.name == name).unwrap().vr;
            let (fy, y) = (vr("node_121.fy"), vr("node_121.y"));
            for x in [&mut m, &mut twin] {
                x.setup(0.0, None).unwrap();
                x.ensure_solver().unwrap();
            }
            let h = 1e-3;
            let mut out = [0.0];
            let mut older = m.snapshot(0);
            for k in 0..12 {
                let f = (k as f64).sin();
                match k % 4 {
                    // Reading a truncated scene's position passes the loads to the solver.
                    1 => {
                        m.set_reals(&[fy], &[f], Phase::Running).unwrap();
                        m.get_reals(&[y], &mut out).unwrap();
                    }
                    // Back to a state of two steps ago, in both.
                    2 => {
                        m.restore(&older).unwrap();
                        twin.restore(&older).unwrap();
                    }
                    _ => older = m.snapshot(0),
                }
                for x in [&mut m, &mut twin] {
                    x.set_reals(&[fy], &[f], Phase::Running).unwrap();
                }
                let t = m.time();
                // A huge load is refused and leaves everything as it was.
                let before = m.snapshot(0);
                m.set_reals(&[fy], &[f64::MAX], Phase::Running).unwrap();
                assert!(m.do_step(t, h).is_err());
                m.set_reals(&[fy], &[f], Phase::Running).unwrap();
                assert_eq!(m.snapshot(0), before, "step {k}");
                // The twin never saw a refused step or a read, and its guard copies the
                // state before every step (a restore makes it forget the buffer).
                let s = twin.snapshot(0);
                twin.restore(&s).unwrap();
                m.do_step(t, h).unwrap();
                twin.do_step(t, h).unwrap();
                let (a, b) = (m.snapshot(0), twin.snapshot(0));
                assert_eq!(a.solver, b.solver, "step {k}");
            }
        }
    }
}
