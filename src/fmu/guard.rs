//! The step guard of an FMU instance: a step that would leave a non-finite number in the
//! solver state or in an output a master can read is refused, and the instance keeps its
//! state from before the step ("right or loud").
//!
//! Before each step the solver state is saved into a reused buffer (no allocation once
//! it has held one state). After the step the guard checks the solver state (it holds
//! everything the future depends on) and the outputs: node positions, velocities and
//! both energies. The outputs are checked as well as the state because
//! a finite state does not make them finite: they are sums of products of the state
//! with the body's matrices (and, for a truncated body, with the loads themselves), which
//! can overflow. On failure the saved state is put back and the message names the first
//! non-finite variable and the input with the largest magnitude, the usual cause.

use super::vars::{Kind, VarTable};
use crate::num::num;
use crate::scene::Scene;
use crate::solver::{Method, Solver, SolverError, State};

/// The rollback buffer and output workspace of one instance.
pub struct StepGuard {
    saved: State,
    after: State,
    out: Vec<f64>,
    /// Below this magnitude of every state entry and input, every checked output is
    /// certainly finite ([`output_bound`]): the outputs need not be computed.
    bound: f64,
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
        StepGuard {
            bound: output_bound(scene),
            saved: State {
                method: Method::Exact,
                data: Vec::new(),
            },
            after: State {
                method: Method::Exact,
                data: Vec::new(),
            },
            out: vec![0.0; 3 * nodes],
        }
    }

    /// Save the solver's state before a step.
    pub fn save(&mut self, s: &dyn Solver) {
        s.state_into(&mut self.saved);
    }

    /// Put back the state saved by [`StepGuard::save`].
    pub fn rollback(&self, s: &mut dyn Solver) -> Result<(), SolverError> {
        s.set_state(&self.saved)
    }

    /// The first non-finite value after a step, named for the master; `None` when every
    /// checked value is finite. `inputs` is the largest magnitude the loads reach over the
    /// step (held value plus rate times step).
    pub fn first_non_finite(
        &mut self,
        s: &dyn Solver,
        table: &VarTable,
        inputs: f64,
    ) -> Option<String> {
        s.state_into(&mut self.after);
        // `NaN < bound` is false: a NaN anywhere takes the full check.
        let b = self.bound;
        if inputs < b && self.after.data.iter().all(|x| x.abs() < b) {
            return None;
        }
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
}
