//! The variable table: names, value references, causality, start values and what each
//! variable maps to in the solver. Built by one function, [`VarTable::new`], from the scene
//! and the options; the XML generator and the running FMU both use it, so the description
//! and the library cannot disagree.

use crate::scene::Scene;
use crate::solver::{Method, Options};

mod states;

/// FMI causality.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    /// Set before initialisation, fixed afterwards.
    Parameter,
    /// Set by the master at communication points.
    Input,
    /// Computed by the FMU.
    Output,
    /// Inside the model, readable (Model Exchange's continuous states and derivatives).
    Local,
}

impl Causality {
    /// The FMI `causality` attribute.
    pub fn name(self) -> &'static str {
        match self {
            Causality::Parameter => "parameter",
            Causality::Input => "input",
            Causality::Output => "output",
            Causality::Local => "local",
        }
    }
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
    /// Angle (rotation vectors).
    Angle,
    /// Energy.
    Energy,
}

/// What a variable is bound to at run time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// The integration method (Integer, values from [`METHODS`]).
    Method,
    /// Generalised-alpha spectral radius at infinite frequency.
    RhoInf,
    /// Added modal damping ratio on every local mode.
    DampingRatio,
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
    /// Rotation vector of exposed node `node` from its initial orientation, component
    /// 0..3 (nodes with rotational DOFs only).
    Rotation {
        /// Exposed node.
        node: usize,
        /// Component 0..3.
        comp: usize,
    },
    /// Angular velocity of exposed node `node`, component 0..3 (nodes with rotational
    /// DOFs only).
    AngularVelocity {
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
    /// Velocity of the frame origin L0, component 0..3 (free bodies).
    FrameVelocity(usize),
    /// Angular velocity of the frame, component 0..3 (free bodies).
    FrameAngularVelocity(usize),
    /// Continuous state `i` (Model Exchange).
    State(usize),
    /// The time derivative of continuous state `i` (Model Exchange).
    Derivative(usize),
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
    /// Whether the variable is the Integer `method`.
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
    /// The methods this body offers, in value order (from [`METHODS`]).
    methods: Vec<Method>,
    /// The number of continuous states declared (Model Exchange; 0 otherwise).
    states: usize,
}

const AXES: [&str; 3] = ["x", "y", "z"];
const LOADS: [&str; 6] = ["fx", "fy", "fz", "mx", "my", "mz"];

impl VarTable {
    /// The value references of every output, in description order (what a master reads
    /// after each step).
    pub fn output_refs(&self) -> Vec<u32> {
        self.vars
            .iter()
            .filter(|v| v.causality == Causality::Output)
            .map(|v| v.vr)
            .collect()
    }

    /// The table for a scene. Exposed node `k` has ID `body.node_ids[scene.nodes[k]]`;
    /// moment inputs exist only for nodes with rotational DOFs.
    pub fn new(scene: &Scene) -> VarTable {
        let body = &scene.body;
        let free = !body.is_blocked();
        let default_method = default_method(free).0;
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
            method_description(free),
        );
        push(
            "rho_inf".into(),
            Parameter,
            Some(Options::default().rho_inf),
            Kind::RhoInf,
            Quantity::None,
            "Implicit method: spectral radius at infinite frequency, 0..1".into(),
        );
        push(
            "damping.ratio".into(),
            Parameter,
            Some(Options::default().damping_ratio),
            Kind::DampingRatio,
            Quantity::None,
            "Added modal damping ratio on every local mode, on top of the file's Rayleigh damping, every method (>= 0; 0.02 is 2% of critical)".into(),
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
        for (k, id) in ids.iter().enumerate() {
            let ncomp = if scene.node_has_rotation(k) { 6 } else { 3 };
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
        // Rotations and angular velocities come last, so that adding them (issue 15) kept
        // the value references of every earlier variable.
        for (k, id) in ids.iter().enumerate() {
            if !scene.node_has_rotation(k) {
                continue;
            }
            let rot_desc = if free {
                "frame rotation then local small rotation; angle at most pi, so the vector \
                 jumps from about pi n to about -pi n each time the rotation passes pi (a \
                 steady spin: once a turn); integrate wx, wy, wz for a continuous angle"
            } else {
                "small rotation of the modes' rotation rows"
            };
            for (comp, axis) in AXES.iter().enumerate() {
                push(
                    format!("node_{id}.r{axis}"),
                    Output,
                    None,
                    Kind::Rotation { node: k, comp },
                    Quantity::Angle,
                    format!(
                        "Rotation of node {id} from its initial orientation as a rotation vector ({rot_desc}), global {axis}"
                    ),
                );
            }
            for (comp, axis) in AXES.iter().enumerate() {
                push(
                    format!("node_{id}.w{axis}"),
                    Output,
                    None,
                    Kind::AngularVelocity { node: k, comp },
                    Quantity::AngularVelocity,
                    format!("Angular velocity of node {id}, global {axis}"),
                );
            }
        }
        // The frame's rates (issue 25.5) after everything else, so that every earlier
        // variable keeps its value reference.
        if free {
            for (what, quantity, desc, mk) in [
                (
                    "v",
                    Quantity::Velocity,
                    "Velocity of the frame origin L0 (the point v0 sets)",
                    Kind::FrameVelocity as fn(usize) -> Kind,
                ),
                (
                    "w",
                    Quantity::AngularVelocity,
                    "Angular velocity of the frame (what w0 sets)",
                    Kind::FrameAngularVelocity,
                ),
            ] {
                for (c, axis) in AXES.iter().enumerate() {
                    push(
                        format!("frame.{what}{axis}"),
                        Output,
                        None,
                        mk(c),
                        quantity,
                        format!("{desc}, global {axis}"),
                    );
                }
            }
        }
        VarTable {
            vars,
            free,
            default_method,
            methods: METHODS
                .iter()
                .filter(|i| i.bodies.includes(free))
                .map(|i| i.method)
                .collect(),
            states: 0,
        }
    }

    /// The table with `m` as the `method` start value (`pack --method`, read back from
    /// scene.txt); `None` keeps the body's default. The scene check
    /// ([`crate::scene::io::make_scene`]) has refused a method the body does not offer.
    pub fn with_default_method(mut self, m: Option<Method>) -> VarTable {
        if let Some(m) = m {
            self.default_method = m;
            for v in &mut self.vars {
                if v.kind == Kind::Method {
                    v.start = Some(m as i32 as f64);
                }
            }
        }
        self
    }

    /// The value reference of FMI 3.0's independent variable `time`, which an FMI 3.0
    /// model description must declare (and the FMI 3.0 getter serves): the one after the
    /// table's, so that every variable keeps the value reference it has in the FMI 2.0
    /// FMU, whose description declares no independent variable.
    pub fn time_ref(&self) -> u32 {
        self.vars.len() as u32
    }

    /// The variable with value reference `vr`.
    pub fn get(&self, vr: u32) -> Option<&Variable> {
        self.vars.get(vr as usize)
    }

    /// Methods this body offers, in value order: the entries of [`METHODS`] whose
    /// [`Bodies`] include it (exact only for blocked bodies).
    pub fn methods(&self) -> &[Method] {
        &self.methods
    }

    /// The method with Integer value `v` if this body offers it; otherwise why not (no
    /// method has that value, or the method does not handle this kind of body).
    pub fn method_for(&self, v: i32) -> Result<Method, String> {
        let Some(info) = METHODS.iter().find(|i| i.method as i32 == v) else {
            let (lo, hi) = method_range();
            return Err(format!("no method has the value {v} (values {lo}..{hi})"));
        };
        if !info.bodies.includes(self.free) {
            return Err(format!(
                "{} ({v}) handles {} bodies only and this body is {}",
                info.name,
                info.bodies.name(),
                if self.free { "free" } else { "blocked" }
            ));
        }
        Ok(info.method)
    }

    /// Whether an output depends at the initial instant on `other` (a parameter):
    /// velocities, angular velocities and kinetic energy of a free body depend on v0
    /// and w0.
    pub fn initial_dependency(&self, output: &Variable, other: &Variable) -> bool {
        matches!(
            output.kind,
            Kind::Velocity { .. }
                | Kind::AngularVelocity { .. }
                | Kind::KineticEnergy
                | Kind::FrameVelocity(_)
                | Kind::FrameAngularVelocity(_)
        ) && matches!(other.kind, Kind::V0(_) | Kind::W0(_))
    }
}

/// Which bodies a method handles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bodies {
    /// Blocked (Iblo = 1) and free (Iblo = 0) bodies.
    Both,
    /// Blocked bodies only.
    Blocked,
    /// Free bodies only.
    Free,
}

impl Bodies {
    /// Whether a body (free or blocked) is handled.
    pub fn includes(self, free: bool) -> bool {
        match self {
            Bodies::Both => true,
            Bodies::Blocked => !free,
            Bodies::Free => free,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Bodies::Both => "blocked and free",
            Bodies::Blocked => "blocked (Iblo=1)",
            Bodies::Free => "free (Iblo=0)",
        }
    }
}

/// One integration method as the FMU offers it: its Integer value is `method as i32`.
#[derive(Debug, Clone, Copy)]
pub struct MethodInfo {
    /// The solver's method.
    pub method: Method,
    /// Its name (`fxbody pack --method`, messages, the documentation page).
    pub name: &'static str,
    /// What it does, for the `method` parameter's description.
    pub what: &'static str,
    /// The bodies it handles.
    pub bodies: Bodies,
}

/// Every method, in value order, values contiguous from 1. The `method` parameter's
/// min, max and description, the methods a body offers and the check of a value set by
/// a master all read this table: a new method is one more line here.
pub const METHODS: &[MethodInfo] = &[
    MethodInfo {
        method: Method::Explicit,
        name: "explicit",
        what: "Radioss central difference, sub-cycled at 0.9 of the stable step",
        bodies: Bodies::Both,
    },
    MethodInfo {
        method: Method::Implicit,
        name: "implicit",
        what: "generalised-alpha (Chung-Hulbert), any step",
        bodies: Bodies::Both,
    },
    MethodInfo {
        method: Method::Exact,
        name: "exact",
        what: "exact modal stepping",
        bodies: Bodies::Blocked,
    },
    MethodInfo {
        method: Method::Split,
        name: "split",
        what: "Strang splitting: local modes exact, frame second order on the rotation group, any step",
        bodies: Bodies::Free,
    },
];

/// The Integer range of `method`: the first and last values of [`METHODS`] (declared as
/// min and max, so that every master, including those without enumerations, can set it).
pub fn method_range() -> (i32, i32) {
    (
        METHODS.first().map_or(0, |i| i.method as i32),
        METHODS.last().map_or(0, |i| i.method as i32),
    )
}

/// The `method` parameter's description: every value with its meaning, those this body
/// refuses marked as such.
fn method_description(free: bool) -> String {
    let items: Vec<String> = METHODS
        .iter()
        .map(|i| {
            let refused = if i.bodies.includes(free) {
                String::new()
            } else {
                format!("; {} bodies only, refused here", i.bodies.name())
            };
            format!("{} = {} ({}{refused})", i.method as i32, i.name, i.what)
        })
        .collect();
    format!("Integration method: {}", items.join(", "))
}

/// The method a body runs unless `pack --method` or the master chooses another, and
/// why, in words for the FMU's documentation page. Blocked bodies: exact modal stepping,
/// which has no time-discretisation error at any step and is the cheapest per step. Free
/// bodies: split, which keeps the local modes exact between samples and the frame second
/// order on the rotation group at any step and delivers each step's impulse exactly; on
/// the free bodies of docs/STUDY.md it is the most accurate per unit of cost, where the
/// implicit method damps the highest modes and the explicit one is bound by the stable
/// step.
pub fn default_method(free: bool) -> (Method, &'static str) {
    if free {
        (
            Method::Split,
            "local modes exact between samples, the frame second order on the rotation \
             group, any step, each step's impulse exact; the implicit method damps the \
             highest modes and the explicit one is bound by the stable step",
        )
    } else {
        (
            Method::Exact,
            "no time-discretisation error at any step, and the cheapest step",
        )
    }
}

/// The name of a method (from [`METHODS`]).
pub fn method_name(m: Method) -> &'static str {
    METHODS
        .iter()
        .find(|i| i.method == m)
        .map_or("unknown", |i| i.name)
}

/// The method with Integer value `v`, if any (whatever the body).
pub fn method_from_value(v: i32) -> Option<Method> {
    METHODS
        .iter()
        .find(|i| i.method as i32 == v)
        .map(|i| i.method)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_values_are_contiguous_from_one_and_round_trip() {
        for (k, i) in METHODS.iter().enumerate() {
            assert_eq!(i.method as i32, k as i32 + 1, "{}", i.name);
            assert_eq!(method_from_value(i.method as i32), Some(i.method));
            assert_eq!(method_name(i.method), i.name);
        }
        assert_eq!(method_range(), (1, METHODS.len() as i32));
        assert_eq!(method_from_value(0), None);
        assert_eq!(method_from_value(METHODS.len() as i32 + 1), None);
    }
}
