//! The variable table: names, value references, causality, start values and what each
//! variable maps to in the solver. Built by one function, [`VarTable::new`], from the scene
//! and the options; the XML generator and the running FMU both use it, so the description
//! and the library cannot disagree.

use crate::scene::Scene;
use crate::solver::{Method, Options};

/// FMI causality.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    /// Set before initialisation, fixed afterwards.
    Parameter,
    /// Set by the master at communication points.
    Input,
    /// Computed by the FMU.
    Output,
}

/// The physical quantity of a variable (for declared units).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Dimensionless or an enumeration.
    None,
    /// Force.
    Force,
    /// Moment.
    Moment,
    /// Length (positions).
    Length,
    /// Velocity.
    Velocity,
    /// Acceleration (gravity).
    Acceleration,
    /// Angular velocity.
    AngularVelocity,
    /// Energy.
    Energy,
}

/// What a variable is bound to at run time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// The integration method (Enumeration `Method`).
    Method,
    /// Generalised-alpha spectral radius at infinite frequency.
    RhoInf,
    /// Gravity component (free bodies).
    Gravity(usize),
    /// Initial body velocity component (free bodies).
    V0(usize),
    /// Initial body angular velocity component (free bodies).
    W0(usize),
    /// Load on exposed node `node`, component `comp` (0..6: fx fy fz mx my mz).
    Load {
        /// Exposed node (position in `Scene::nodes`).
        node: usize,
        /// Component 0..6.
        comp: usize,
    },
    /// Position of exposed node `node`, component 0..3.
    Position {
        /// Exposed node.
        node: usize,
        /// Component 0..3.
        comp: usize,
    },
    /// Velocity of exposed node `node`, component 0..3.
    Velocity {
        /// Exposed node.
        node: usize,
        /// Component 0..3.
        comp: usize,
    },
    /// Kinetic energy.
    KineticEnergy,
    /// Strain energy.
    StrainEnergy,
    /// Frame origin (L0) component 0..3 (free bodies).
    FrameOrigin(usize),
    /// Frame matrix P entry, row-major index 0..9 (free bodies).
    FrameP(usize),
}

/// One scalar variable.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    /// Name (part of the interface: keep stable).
    pub name: String,
    /// Value reference (unique in the table; equals the 0-based index).
    pub vr: u32,
    /// Causality.
    pub causality: Causality,
    /// Start value for parameters and inputs; `None` for calculated outputs.
    pub start: Option<f64>,
    /// The binding.
    pub kind: Kind,
    /// Quantity for units.
    pub quantity: Quantity,
    /// Human-readable description.
    pub description: String,
}

impl Variable {
    /// Whether the variable is the Enumeration `method` (an Integer at the C ABI).
    pub fn is_integer(&self) -> bool {
        self.kind == Kind::Method
    }
}

/// All variables of one scene, in description order.
#[derive(Debug, Clone, PartialEq)]
pub struct VarTable {
    /// The variables; `vars[i].vr == i`.
    pub vars: Vec<Variable>,
    /// Free body (has rigid modes).
    pub free: bool,
    /// Default method (the `method` start value).
    pub default_method: Method,
}

const AXES: [&str; 3] = ["x", "y", "z"];
const LOADS: [&str; 6] = ["fx", "fy", "fz", "mx", "my", "mz"];

impl VarTable {
    /// The table for a scene. Exposed node `k` has ID `body.node_ids[scene.nodes[k]]`;
    /// moment inputs exist only for nodes with rotational DOFs.
    pub fn new(scene: &Scene) -> VarTable {
        let body = &scene.body;
        let free = !body.iblo;
        let default_method = if free {
            Method::Implicit
        } else {
            Method::Exact
        };
        let mut vars = Vec::new();
        let mut push = |name: String, causality, start, kind, quantity, description: String| {
            let vr = vars.len() as u32;
            vars.push(Variable {
                name,
                vr,
                causality,
                start,
                kind,
                quantity,
                description,
            });
        };
        use Causality::*;
        push(
            "method".into(),
            Parameter,
            Some(default_method as i32 as f64),
            Kind::Method,
            Quantity::None,
            if free {
                "Integration method: explicit (Radioss central difference, sub-cycled) or implicit (generalised-alpha)".into()
            } else {
                "Integration method: explicit (Radioss central difference, sub-cycled), implicit (generalised-alpha) or exact (modal)".into()
            },
        );
        push(
            "rho_inf".into(),
            Parameter,
            Some(Options::default().rho_inf),
            Kind::RhoInf,
            Quantity::None,
            "Implicit method: spectral radius at infinite frequency, 0..1".into(),
        );
        if free {
            for (what, quantity, desc, mk) in [
                (
                    "gravity",
                    Quantity::Acceleration,
                    "Gravity acceleration",
                    Kind::Gravity as fn(usize) -> Kind,
                ),
                ("v0", Quantity::Velocity, "Initial body velocity", Kind::V0),
                (
                    "w0",
                    Quantity::AngularVelocity,
                    "Initial body angular velocity",
                    Kind::W0,
                ),
            ] {
                for (c, axis) in AXES.iter().enumerate() {
                    push(
                        format!("{what}.{axis}"),
                        Parameter,
                        Some(0.0),
                        mk(c),
                        quantity,
                        format!("{desc}, global {axis}"),
                    );
                }
            }
        }
        let ids: Vec<i64> = scene.nodes.iter().map(|&n| body.node_ids[n]).collect();
        for (k, (&n, id)) in scene.nodes.iter().zip(&ids).enumerate() {
            let ncomp = if body.node_has_rotation(n) { 6 } else { 3 };
            for (comp, l) in LOADS.iter().enumerate().take(ncomp) {
                let (quantity, what) = if comp < 3 {
                    (Quantity::Force, "Force")
                } else {
                    (Quantity::Moment, "Moment")
                };
                push(
                    format!("node_{id}.{l}"),
                    Input,
                    Some(0.0),
                    Kind::Load { node: k, comp },
                    quantity,
                    format!("{what} on node {id}, global {}", AXES[comp % 3]),
                );
            }
        }
        for (k, id) in ids.iter().enumerate() {
            for (comp, axis) in AXES.iter().enumerate() {
                push(
                    format!("node_{id}.{axis}"),
                    Output,
                    None,
                    Kind::Position { node: k, comp },
                    Quantity::Length,
                    format!("Position of node {id}, global {axis}"),
                );
            }
            for (comp, axis) in AXES.iter().enumerate() {
                push(
                    format!("node_{id}.v{axis}"),
                    Output,
                    None,
                    Kind::Velocity { node: k, comp },
                    Quantity::Velocity,
                    format!("Velocity of node {id}, global {axis}"),
                );
            }
        }
        push(
            "energy.kinetic".into(),
            Output,
            None,
            Kind::KineticEnergy,
            Quantity::Energy,
            "Kinetic energy of the body".into(),
        );
        push(
            "energy.strain".into(),
            Output,
            None,
            Kind::StrainEnergy,
            Quantity::Energy,
            "Strain energy of the body".into(),
        );
        if free {
            for (c, axis) in AXES.iter().enumerate() {
                push(
                    format!("frame.{axis}"),
                    Output,
                    None,
                    Kind::FrameOrigin(c),
                    Quantity::Length,
                    format!("Frame origin L0, global {axis}"),
                );
            }
            for (r, row_axis) in AXES.iter().enumerate() {
                for c in 0..3 {
                    push(
                        format!("frame.P{}{}", r + 1, c + 1),
                        Output,
                        None,
                        Kind::FrameP(3 * r + c),
                        Quantity::None,
                        format!(
                            "Frame matrix P({}, {}): global {} component of local axis {}",
                            r + 1,
                            c + 1,
                            row_axis,
                            c + 1
                        ),
                    );
                }
            }
        }
        VarTable {
            vars,
            free,
            default_method,
        }
    }

    /// The variable with value reference `vr`.
    pub fn get(&self, vr: u32) -> Option<&Variable> {
        self.vars.get(vr as usize)
    }

    /// Methods a scene offers: exact only for blocked bodies.
    pub fn methods(&self) -> &'static [Method] {
        if self.free {
            &[Method::Explicit, Method::Implicit, Method::Split]
        } else {
            &[Method::Explicit, Method::Implicit, Method::Exact]
        }
    }

    /// Whether an output depends at the initial instant on `other` (a parameter):
    /// velocities and kinetic energy of a free body depend on v0 and w0.
    pub fn initial_dependency(&self, output: &Variable, other: &Variable) -> bool {
        matches!(output.kind, Kind::Velocity { .. } | Kind::KineticEnergy)
            && matches!(other.kind, Kind::V0(_) | Kind::W0(_))
    }
}

/// The name of a method's enumeration item.
pub fn method_name(m: Method) -> &'static str {
    match m {
        Method::Explicit => "explicit",
        Method::Implicit => "implicit",
        Method::Exact => "exact",
        Method::Split => "split",
    }
}

/// The method with enumeration value `v`, if any.
pub fn method_from_value(v: i32) -> Option<Method> {
    match v {
        1 => Some(Method::Explicit),
        2 => Some(Method::Implicit),
        3 => Some(Method::Exact),
        4 => Some(Method::Split),
        _ => None,
    }
}
