//! The continuous states and their derivatives as variables, for FMUs that declare Model
//! Exchange ([`super::super::interface::Interfaces`]): appended after every other
//! variable, so that each earlier variable keeps its value reference, and only in those
//! FMUs, so that a co-simulation FMU's table is what it was. A blocked body's states are
//! the method's own ([`crate::solver::continuous`]): the modal amplitudes `q` of the kept
//! local modes, then their velocities `qd`; `der(x)` is each one's time derivative.

use super::{Causality, Kind, Quantity, VarTable, Variable};
use crate::fmu::options::SceneOptions;
use crate::scene::Scene;
use crate::solver::free::continuous::RIGID_STATES;

impl VarTable {
    /// The table of an FMU packed with `opts`: the scene's variables, the packed method
    /// as `method`'s start value, and the continuous states with their derivatives when
    /// the FMU declares Model Exchange. The description and the running library both
    /// build their table here.
    pub fn for_options(scene: &Scene, opts: &SceneOptions) -> VarTable {
        let table = VarTable::new(scene).with_default_method(opts.method);
        if opts.interface.model_exchange() {
            table.with_states(scene)
        } else {
            table
        }
    }

    /// The table with the continuous states and their derivatives appended, in the
    /// method's order ([`crate::solver::continuous`]), then `der(...)` of each, in the
    /// same order. A blocked body: `modal.q[j]` and `modal.qd[j]` for each kept local
    /// mode `j` (1-based, in the body's order). A free body (the split method's first-order
    /// form, [`crate::solver::free::continuous`]): first `state.X[1..3]` (the frame point
    /// L0, global), `state.quat[1..4]` (the attitude quaternion `(w, x, y, z)`),
    /// `state.V[1..3]` (L0's velocity, global), `state.omega[1..3]` (the frame's angular
    /// velocity, global components), then `modal.q[j]` and `modal.qd[j]` in the split
    /// method's modal basis.
    pub fn with_states(mut self, scene: &Scene) -> VarTable {
        let nl = scene.body.nl();
        let free = self.free;
        let hz = |j: usize| {
            if free {
                // The split basis mixes the body's local modes.
                return String::new();
            }
            scene
                .body
                .frequencies_hz
                .get(j)
                .map_or(String::new(), |f| format!(", {} Hz", crate::num::num(*f)))
        };
        let mode = if free {
            "mode of the split basis"
        } else {
            "local mode"
        };
        let mut states = Vec::with_capacity(RIGID_STATES + 2 * nl);
        if free {
            let rigid: [(&str, &str, usize); 4] = [
                ("X", "Position of the frame point L0, global component", 3),
                (
                    "quat",
                    "Attitude quaternion of the frame, component (w, x, y, z)",
                    4,
                ),
                ("V", "Velocity of the frame point L0, global component", 3),
                (
                    "omega",
                    "Angular velocity of the frame, global component",
                    3,
                ),
            ];
            for (name, description, len) in rigid {
                for c in 1..=len {
                    states.push((format!("state.{name}[{c}]"), format!("{description} {c}")));
                }
            }
        }
        for j in 0..nl {
            states.push((
                format!("modal.q[{}]", j + 1),
                format!("Modal amplitude of {mode} {}{}", j + 1, hz(j)),
            ));
        }
        for j in 0..nl {
            states.push((
                format!("modal.qd[{}]", j + 1),
                format!("Modal velocity of {mode} {}{}", j + 1, hz(j)),
            ));
        }
        let n = states.len();
        let rigid = if free { RIGID_STATES } else { 0 };
        for (i, (name, description)) in states.iter().enumerate() {
            let vr = self.vars.len() as u32;
            self.vars.push(Variable {
                name: name.clone(),
                vr,
                causality: Causality::Local,
                // A free body's frame states are calculated at initialisation (the
                // body's placement, v0 and w0); the modes start at rest.
                start: (i >= rigid).then_some(0.0),
                kind: Kind::State(i),
                quantity: Quantity::None,
                description: format!(
                    "{description}: continuous state {} of {n} (Model Exchange), {}",
                    i + 1,
                    if i >= rigid {
                        "at rest at the start"
                    } else {
                        "calculated at initialisation"
                    }
                ),
            });
        }
        for (i, (name, description)) in states.iter().enumerate() {
            let vr = self.vars.len() as u32;
            self.vars.push(Variable {
                name: format!("der({name})"),
                vr,
                causality: Causality::Local,
                start: None,
                kind: Kind::Derivative(i),
                quantity: Quantity::None,
                description: format!("Time derivative of the {}", lower_first(description)),
            });
        }
        // The method integrates its own equations; a Model Exchange master integrates the
        // body's, whatever `method` says.
        for v in &mut self.vars {
            if v.kind == Kind::Method {
                v.description.push_str(
                    ". Model Exchange: no meaning (the master's integrator integrates the \
                     body's own equations; the value is accepted and ignored)",
                );
            }
        }
        self.states = n;
        self
    }

    /// The number of continuous states the table declares (0 without Model Exchange).
    pub fn state_count(&self) -> usize {
        self.states
    }

    /// The value reference of continuous state `i` (the derivative's `derivative`
    /// attribute names it).
    pub fn state_ref(&self, i: usize) -> Option<u32> {
        self.vars
            .iter()
            .find(|v| v.kind == Kind::State(i))
            .map(|v| v.vr)
    }
}

fn lower_first(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_lowercase().chain(c).collect(),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmu::interface::Interfaces;

    #[test]
    fn states_follow_every_other_variable_only_with_model_exchange() {
        let scene = crate::scene::io::cantilever_tip_scene();
        let cs = VarTable::for_options(&scene, &SceneOptions::default());
        assert_eq!(cs, VarTable::new(&scene));
        assert_eq!(cs.state_count(), 0);
        let me = VarTable::for_options(
            &scene,
            &SceneOptions {
                interface: Interfaces::ModelExchange,
                ..SceneOptions::default()
            },
        );
        let nl = scene.body.nl();
        assert_eq!(me.state_count(), 2 * nl);
        assert_eq!(me.vars.len(), cs.vars.len() + 4 * nl);
        // Every earlier variable keeps its value reference and name.
        for (a, b) in cs.vars.iter().zip(&me.vars) {
            assert_eq!((a.vr, &a.name), (b.vr, &b.name));
        }
        let first = &me.vars[cs.vars.len()];
        assert_eq!(
            (first.name.as_str(), first.kind),
            ("modal.q[1]", Kind::State(0))
        );
        let der = &me.vars[cs.vars.len() + 2 * nl + nl];
        assert_eq!(der.name, "der(modal.qd[1])");
        assert_eq!(der.kind, Kind::Derivative(nl));
        assert_eq!(me.state_ref(nl), Some(cs.vars.len() as u32 + nl as u32));
        for v in &me.vars {
            assert_eq!(v.vr as usize, me.vars.iter().position(|w| w == v).unwrap());
        }
    }
}
