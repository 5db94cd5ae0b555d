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
use crate::solver::{Method, Solver, SolverError, State};

/// The rollback buffer and output workspace of one instance.
pub struct StepGuard {
    saved: State,
    after: State,
    out: Vec<f64>,
}

impl StepGuard {
    /// A guard for a body with `nodes` exposed nodes.
    pub fn new(nodes: usize) -> StepGuard {
        StepGuard {
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
    /// checked value is finite.
    pub fn first_non_finite(&mut self, s: &dyn Solver, table: &VarTable) -> Option<String> {
        let named = |kind: Kind| {
            table
                .vars
                .iter()
                .find(|v| v.kind == kind)
                .map_or_else(|| format!("{kind:?}"), |v| v.name.clone())
        };
        type Fill = fn(&dyn Solver, &mut [f64]);
        let outputs: [(Fill, &str); 2] = [
            (|s, o| s.positions(o), "position"),
            (|s, o| s.velocities(o), "velocity"),
        ];
        for (fill, what) in outputs {
            fill(s, &mut self.out);
            if let Some(k) = self.out.iter().position(|x| !x.is_finite()) {
                let (node, comp) = (k / 3, k % 3);
                return Some(match what {
                    "position" => named(Kind::Position { node, comp }),
                    "velocity" => named(Kind::Velocity { node, comp }),
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
        s.state_into(&mut self.after);
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
