//! modelDescription.xml from the variable table, the scene and the pack options. Element
//! order follows the FMI 2.0 schema (CoSimulation, UnitDefinitions, LogCategories,
//! DefaultExperiment, ModelVariables, ModelStructure); no time stamp, so the same input
//! gives the same bytes. The parts FMI 3.0's description shares ([`super::xml3`]) are
//! functions here.

use std::fmt::Write;

use super::options::{SceneOptions, UnitSystem};
use super::vars::{Causality, Kind, Quantity, VarTable, Variable, method_range};
use crate::num::count;
use crate::scene::Scene;
use crate::solver::free::continuous::RIGID_STATES;

/// Log categories the FMU declares, with descriptions; the FMI layer uses the same list.
pub const LOG_CATEGORIES: [(&str, &str); 4] = [
    (
        "logStatusError",
        "Errors: illegal calls, bad arguments, failed steps (always on)",
    ),
    ("logStatusWarning", "Warnings (always on)"),
    ("logCalls", "Each FMI call with its arguments"),
    ("logSolver", "Solver set-up: method, modes, step sizes"),
];

/// Escape text for an XML attribute value.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\n' => out.push_str("&#10;"),
            '\r' => out.push_str("&#13;"),
            '\t' => out.push_str("&#9;"),
            // Other control characters are not allowed in XML 1.0 at all.
            c if (c as u32) < 0x20 => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// A real as the shortest text that reads back to the same f64.
pub fn real(v: f64) -> String {
    format!("{v:?}")
}

/// Default experiment `(stop time, step size)`.
///
/// Step: at most 1 ms, and at least 20 samples per period of the lowest flexible mode, so
/// that its motion is resolved through sampled exchange (a master interpolating linearly
/// between samples then sees it within about 1%), rounded down to 1, 2 or 5 times a power
/// of ten. Any step is stable for every method (the explicit one sub-cycles internally at
/// 0.9 of its stable step), so the step is about what the exchange can resolve.
/// Stop: five periods of the lowest flexible mode (rounded up likewise), or 1 s when the
/// body has no flexible mode.
pub fn default_experiment(scene: &Scene) -> (f64, f64) {
    match lowest_frequency(scene) {
        Some(f1) => (
            nice(5.0 / f1, true),
            nice((1.0 / (20.0 * f1)).min(1e-3), false),
        ),
        None => (1.0, 1e-3),
    }
}

/// The lowest flexible eigenfrequency of the scene's kept modes (Hz; above 1e-6 Hz),
/// if it has one.
pub fn lowest_frequency(scene: &Scene) -> Option<f64> {
    scene
        .body
        .frequencies_hz
        .iter()
        .copied()
        .find(|&f| f > 1e-6)
}

/// Round to 1, 2 or 5 times a power of ten, up or down.
fn nice(v: f64, up: bool) -> f64 {
    let e = v.log10().floor();
    let base = 10f64.powf(e);
    let m = v / base;
    let steps = [1.0, 2.0, 5.0, 10.0];
    let pick = if up {
        steps
            .iter()
            .copied()
            .find(|&s| s >= m * (1.0 - 1e-12))
            .unwrap_or(10.0)
    } else {
        steps
            .iter()
            .rev()
            .copied()
            .find(|&s| s <= m * (1.0 + 1e-12))
            .unwrap_or(1.0)
    };
    // Format through text so that 0.001 is exactly the double nearest 1e-3.
    format!("{pick}e{e}").parse().unwrap_or(v)
}

/// Unit name of a quantity in a unit system, with its SI base-unit exponents
/// (kg, m, s) and factor to SI.
pub(crate) fn unit(q: Quantity, u: UnitSystem) -> Option<(String, [i32; 3], f64)> {
    use Quantity::*;
    let (l, t) = (u.length_name(), u.time_name());
    let (name, dims) = match q {
        None => return Option::None,
        Force => (u.force_name(), [1, 1, -2]),
        Moment => (format!("{}.{l}", u.force_name()), [1, 2, -2]),
        Length => (l.to_string(), [0, 1, 0]),
        Velocity => (format!("{l}/{t}"), [0, 1, -1]),
        Acceleration => (format!("{l}/{t}2"), [0, 1, -2]),
        AngularVelocity => (format!("rad/{t}"), [0, 0, -1]),
        Angle => ("rad".to_string(), [0, 0, 0]),
        Energy => (u.energy_name(), [1, 2, -2]),
    };
    Some((name, dims, u.factor(dims)))
}

/// A `<Unit>` element (FMI 2.0's, which the OSP model description shares) for a unit of
/// [`unit`], indented for `<UnitDefinitions>`.
pub(crate) fn unit_element(def: &(String, [i32; 3], f64)) -> String {
    let (name, [kg, m, s], factor) = (&def.0, def.1, def.2);
    let mut base = String::new();
    for (k, e) in [("kg", kg), ("m", m), ("s", s)] {
        if e != 0 {
            let _ = write!(base, " {k}=\"{e}\"");
        }
    }
    if name.starts_with("rad") {
        base.push_str(" rad=\"1\"");
    }
    if factor != 1.0 {
        let _ = write!(base, " factor=\"{}\"", real(factor));
    }
    format!(
        "    <Unit name=\"{}\">\n      <BaseUnit{base}/>\n    </Unit>\n",
        escape(name)
    )
}

/// Whether output `i` of the table depends on the inputs at the same instant (a direct
/// feedthrough; then on every load input). Without truncation none does: positions,
/// velocities, rotations, energies and the frame are states of the second-order system.
/// With a residual flexibility (pack --fmax), positions, rotations and the strain energy
/// carry `R f`. The model description and the documentation page both read this.
pub fn feeds_through(scene: &Scene, table: &VarTable, i: usize) -> bool {
    scene.residual.is_some()
        && matches!(
            table.vars[i].kind,
            Kind::Position { .. } | Kind::Rotation { .. } | Kind::StrainEnergy
        )
}

/// What the model keeps of the body, in one sentence shared by the model description
/// and the documentation page: the local modes, and the residual correction if any.
pub fn modes_summary(scene: &Scene) -> String {
    let nl = scene.body.nl();
    match &scene.residual {
        Some(r) => format!(
            "{} kept, residual correction of {}",
            count(nl, "local mode"),
            count(r.dropped, "dropped mode")
        ),
        None => format!("{}, no residual correction", count(nl, "local mode")),
    }
}

/// The model description's `description` attribute (both FMI versions): kind of body,
/// nodes, modes kept, exposed nodes.
pub(crate) fn body_description(scene: &Scene, table: &VarTable) -> String {
    let kind = if table.free { "free" } else { "blocked" };
    format!(
        "Radioss flexible body ({kind}, {}, {}, {}), by fxbody",
        count(scene.body.nnodes(), "node"),
        modes_summary(scene),
        count(scene.nodes.len(), "exposed node")
    )
}

/// The units the variables of `table` use in system `u`, each once, in variable order
/// (both FMI versions' `<UnitDefinitions>`).
pub(crate) fn units_used(table: &VarTable, u: UnitSystem) -> Vec<(String, [i32; 3], f64)> {
    let mut seen: Vec<(String, [i32; 3], f64)> = Vec::new();
    for v in &table.vars {
        if let Some(def) = unit(v.quantity, u)
            && !seen.iter().any(|d| d.0 == def.0)
        {
            seen.push(def);
        }
    }
    seen
}

/// `<LogCategories>` and `<DefaultExperiment>`, the same in both FMI versions.
pub(crate) fn categories_and_experiment(scene: &Scene, opts: &SceneOptions) -> String {
    let mut x = String::from("  <LogCategories>\n");
    for (name, desc) in LOG_CATEGORIES {
        let _ = writeln!(
            x,
            "    <Category name=\"{name}\" description=\"{}\"/>",
            escape(desc)
        );
    }
    x.push_str("  </LogCategories>\n");
    let (stop, step) = opts.experiment(scene);
    let _ = writeln!(
        x,
        "  <DefaultExperiment startTime=\"0.0\" stopTime=\"{}\" stepSize=\"{}\"/>",
        real(stop),
        real(step)
    );
    x
}

/// One output of the ModelStructure (both FMI versions), by position in the table: the
/// variables its value depends on at the same instant (the loads, when it feeds
/// through) and at the initial instant (also v0 and w0 for velocities of free bodies),
/// by position as well.
pub(crate) struct Unknown {
    /// The output.
    pub output: usize,
    /// Same-instant dependencies (`<Outputs>`, `<Output>`).
    pub outputs: Vec<usize>,
    /// Initial dependencies (`<InitialUnknowns>`, `<InitialUnknown>`).
    pub initial: Vec<usize>,
}

/// Every output's [`Unknown`], in table order. With Model Exchange's states in the
/// table, an output also depends on the states that move it (positions, rotations and
/// the strain energy on the amplitudes, velocities and the kinetic energy on the
/// velocities: a master sorting its equations needs them).
pub(crate) fn unknowns(scene: &Scene, table: &VarTable) -> Vec<Unknown> {
    let loads: Vec<usize> = (0..table.vars.len())
        .filter(|&j| matches!(table.vars[j].kind, Kind::Load { .. }))
        .collect();
    (0..table.vars.len())
        .filter(|&i| table.vars[i].causality == Causality::Output)
        .map(|i| {
            let feeds = feeds_through(scene, table, i);
            let states = states_moving(table, table.vars[i].kind);
            let mut outputs = states.clone();
            if feeds {
                outputs.extend(&loads);
            }
            outputs.sort_unstable();
            let mut initial: Vec<usize> = (0..table.vars.len())
                .filter(|&j| {
                    let p = &table.vars[j];
                    table.initial_dependency(&table.vars[i], p)
                        || (feeds && matches!(p.kind, Kind::Load { .. }))
                })
                .collect();
            initial.extend(initial_dependencies(table, &states));
            initial.sort_unstable();
            initial.dedup();
            Unknown {
                output: i,
                outputs,
                initial,
            }
        })
        .collect()
}

/// The positions in the table of the continuous states an output of kind `kind`
/// depends on (none without Model Exchange's states): amplitudes (the first half) or
/// velocities (the second).
fn states_moving(table: &VarTable, kind: Kind) -> Vec<usize> {
    let n = table.state_count();
    if table.free {
        // A free body's outputs move with the frame and the modes: every state.
        let moves = matches!(
            kind,
            Kind::Position { .. }
                | Kind::Rotation { .. }
                | Kind::StrainEnergy
                | Kind::Velocity { .. }
                | Kind::AngularVelocity { .. }
                | Kind::KineticEnergy
                | Kind::FrameOrigin(_)
                | Kind::FrameP(_)
                | Kind::FrameVelocity(_)
                | Kind::FrameAngularVelocity(_)
        );
        let all = if moves { 0..n } else { 0..0 };
        return all
            .filter_map(|i| table.state_ref(i).map(|vr| vr as usize))
            .collect();
    }
    let half = match kind {
        Kind::Position { .. } | Kind::Rotation { .. } | Kind::StrainEnergy => 0..n / 2,
        Kind::Velocity { .. } | Kind::AngularVelocity { .. } | Kind::KineticEnergy => n / 2..n,
        _ => 0..0,
    };
    half.filter_map(|i| table.state_ref(i).map(|vr| vr as usize))
        .collect()
}

/// Each state derivative's [`Unknown`] (Model Exchange's `<Derivatives>` and its initial
/// unknowns), in table order. A blocked body: `der(q_j)` is `qd_j`; `der(qd_j)` depends
/// on `q_j`, `qd_j` and the loads. A free body: `der(X)` is `V`, `der(quat)` depends on
/// `quat` and `omega`, `der(modal.q_j)` is `modal.qd_j`; the accelerations on every state
/// and the loads. Initially, a state the FMU calculates (a free body's frame) stands for
/// the parameters it is calculated from ([`initial_dependencies`]).
pub(crate) fn derivative_unknowns(table: &VarTable) -> Vec<Unknown> {
    let n = table.state_count();
    let loads: Vec<usize> = (0..table.vars.len())
        .filter(|&j| matches!(table.vars[j].kind, Kind::Load { .. }))
        .collect();
    let at = |i: usize| table.state_ref(i).map_or(0, |vr| vr as usize);
    let rigid = if table.free { RIGID_STATES } else { 0 };
    let nl = (n - rigid) / 2;
    (0..table.vars.len())
        .filter_map(|d| match table.vars[d].kind {
            Kind::Derivative(i) => {
                let mut deps = if table.free {
                    match i {
                        0..3 => vec![at(i + 7)],
                        3..7 => (3..7).chain(10..13).map(at).collect(),
                        _ if (rigid..rigid + nl).contains(&i) => vec![at(i + nl)],
                        // The accelerations: every state and the loads.
                        _ => loads.iter().copied().chain((0..n).map(at)).collect(),
                    }
                } else if i < n / 2 {
                    vec![at(i + n / 2)]
                } else {
                    let mut v = loads.clone();
                    v.extend([at(i - n / 2), at(i)]);
                    v
                };
                deps.sort_unstable();
                Some(Unknown {
                    output: d,
                    initial: initial_dependencies(table, &deps),
                    outputs: deps,
                })
            }
            _ => None,
        })
        .collect()
}

/// The states the FMU calculates at initialisation (a free body's frame: no `start`)
/// as initial unknowns, in table order: the position and the attitude depend on nothing
/// a master sets, the velocities on the initial velocity parameters.
pub(crate) fn state_unknowns(table: &VarTable) -> Vec<Unknown> {
    (0..table.vars.len())
        .filter(|&s| matches!(table.vars[s].kind, Kind::State(_)) && table.vars[s].start.is_none())
        .map(|s| {
            let initial = initial_dependencies(table, &[s]);
            Unknown {
                output: s,
                outputs: initial.clone(),
                initial,
            }
        })
        .collect()
}

/// `deps` at the initial instant: a state the FMU calculates (no `start`) is replaced by
/// what it is calculated from (a free body's velocity states by `v0` and `w0`).
fn initial_dependencies(table: &VarTable, deps: &[usize]) -> Vec<usize> {
    let mut out = Vec::with_capacity(deps.len());
    for &d in deps {
        let v = &table.vars[d];
        match v.kind {
            Kind::State(i) if v.start.is_none() => {
                if (7..13).contains(&i) {
                    out.extend(
                        (0..table.vars.len())
                            .filter(|&j| matches!(table.vars[j].kind, Kind::V0(_) | Kind::W0(_))),
                    );
                }
            }
            _ => out.push(d),
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// A variable's causality, variability and `initial` attribute (the last empty or with
/// its leading blank), the same in both FMI versions: parameters fixed and exact,
/// inputs continuous without `initial`, outputs continuous and calculated.
fn causality_attributes(v: &Variable) -> (&'static str, &'static str, &'static str) {
    match v.causality {
        Causality::Parameter => ("parameter", "fixed", " initial=\"exact\""),
        Causality::Input => ("input", "continuous", ""),
        Causality::Output => ("output", "continuous", " initial=\"calculated\""),
        // Continuous states start at rest (exact); their derivatives are calculated.
        Causality::Local if v.start.is_some() => ("local", "continuous", " initial=\"exact\""),
        Causality::Local => ("local", "continuous", " initial=\"calculated\""),
    }
}

/// A variable's name, value reference, description, causality, variability and
/// `initial` attributes, the same in both FMI versions.
pub(crate) fn variable_attributes(v: &Variable) -> String {
    let (causality, variability, initial) = causality_attributes(v);
    format!(
        "name=\"{}\" valueReference=\"{}\" description=\"{}\" causality=\"{causality}\" \
         variability=\"{variability}\"{initial}",
        escape(&v.name),
        v.vr,
        escape(&v.description)
    )
}

/// A Real (FMI 3.0: Float64) variable's `unit` and `start` attributes, each with its
/// leading blank, when it has them.
pub(crate) fn real_attributes(v: &Variable, opts: &SceneOptions) -> String {
    let mut attrs = String::new();
    if let Some(u) = opts.units.and_then(|u| unit(v.quantity, u)) {
        let _ = write!(attrs, " unit=\"{}\"", escape(&u.0));
    }
    if let Some(s) = v.start {
        let _ = write!(attrs, " start=\"{}\"", real(s));
    }
    attrs
}

/// The complete modelDescription.xml text (FMI 2.0; FMI 3.0's is [`super::xml3`]).
pub fn model_description(
    scene: &Scene,
    table: &VarTable,
    opts: &SceneOptions,
    guid: &str,
) -> String {
    let mut x = String::new();
    let description = body_description(scene, table);
    x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"{}\" guid=\"{}\" description=\"{}\" \
         generationTool=\"fxbody {}\" variableNamingConvention=\"structured\" numberOfEventIndicators=\"0\">",
        escape(&opts.name),
        escape(guid),
        escape(&description),
        env!("CARGO_PKG_VERSION")
    );
    if opts.interface.model_exchange() {
        // No event indicators; fmi2CompletedIntegratorStep is called by the master (the
        // default): a free body asks there for the step event at which it normalises its
        // quaternion.
        let _ = writeln!(
            x,
            "  <ModelExchange modelIdentifier=\"{}\" canGetAndSetFMUstate=\"true\" \
             canSerializeFMUstate=\"true\" providesDirectionalDerivative=\"true\" \
             canNotUseMemoryManagementFunctions=\"true\"/>",
            // The directional derivative: exact for a blocked body, a central
            // difference of a free body's accelerations (crate::fmu::simulation).
            escape(&opts.model_identifier()),
        );
    }
    if opts.interface.co_simulation() {
        let _ = writeln!(
            x,
            "  <CoSimulation modelIdentifier=\"{}\" canHandleVariableCommunicationStepSize=\"true\" \
             canInterpolateInputs=\"true\" maxOutputDerivativeOrder=\"2\" canGetAndSetFMUstate=\"true\" \
             canSerializeFMUstate=\"true\" providesDirectionalDerivative=\"false\" \
             canNotUseMemoryManagementFunctions=\"true\"/>",
            escape(&opts.model_identifier())
        );
    }
    if let Some(u) = opts.units {
        x.push_str("  <UnitDefinitions>\n");
        for def in units_used(table, u) {
            x.push_str(&unit_element(&def));
        }
        x.push_str("  </UnitDefinitions>\n");
    }
    x.push_str(&categories_and_experiment(scene, opts));
    if !opts.platforms.is_empty() {
        // FMI 2.0 has no platform list; a tool annotation records what pack --binary added.
        let _ = writeln!(
            x,
            "  <VendorAnnotations>\n    <Tool name=\"fxbody\">\n      <Platforms native=\"{}\" added=\"{}\"/>\n    </Tool>\n  </VendorAnnotations>",
            super::platforms::NATIVE,
            escape(&opts.platforms.join(" "))
        );
    }
    x.push_str("  <ModelVariables>\n");
    for (i, v) in table.vars.iter().enumerate() {
        let _ = writeln!(
            x,
            "    <!-- Index {} -->\n    <ScalarVariable {}>",
            i + 1,
            variable_attributes(v)
        );
        if v.kind == Kind::Method {
            // An Integer, not an Enumeration: libcosim and ecos ignore Enumeration
            // variables, so their users could not choose the method.
            let (lo, hi) = method_range();
            let _ = writeln!(
                x,
                "      <Integer min=\"{lo}\" max=\"{hi}\" start=\"{}\"/>",
                table.default_method as i32
            );
        } else {
            let mut attrs = real_attributes(v, opts);
            if let Kind::Derivative(i) = v.kind
                && let Some(state) = table.state_ref(i)
            {
                // FMI 2.0 names the state by its 1-based index (= value reference + 1).
                let _ = write!(attrs, " derivative=\"{}\"", state + 1);
            }
            let _ = writeln!(x, "      <Real{attrs}/>");
        }
        x.push_str("    </ScalarVariable>\n");
    }
    x.push_str("  </ModelVariables>\n  <ModelStructure>\n");
    // FMI 2.0 names variables by their 1-based index in ModelVariables.
    let index = |deps: &[usize]| {
        let v: Vec<String> = deps.iter().map(|j| (j + 1).to_string()).collect();
        v.join(" ")
    };
    let outputs = unknowns(scene, table);
    let derivatives = derivative_unknowns(table);
    let states = state_unknowns(table);
    for (list, initial) in [
        ("Outputs", false),
        ("Derivatives", false),
        ("InitialUnknowns", true),
    ] {
        let listed: Vec<&Unknown> = match list {
            "Outputs" => outputs.iter().collect(),
            "Derivatives" => derivatives.iter().collect(),
            // Ascending index: the outputs, the calculated states, then the
            // derivatives after them.
            _ => outputs.iter().chain(&states).chain(&derivatives).collect(),
        };
        if listed.is_empty() {
            continue;
        }
        let _ = writeln!(x, "    <{list}>");
        for u in listed {
            let deps = if initial { &u.initial } else { &u.outputs };
            let _ = writeln!(
                x,
                "      <Unknown index=\"{}\" dependencies=\"{}\"/>",
                u.output + 1,
                index(deps)
            );
        }
        let _ = writeln!(x, "    </{list}>");
    }
    x.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escape_covers_markup_and_quotes() {
        assert_eq!(
            escape("a<b & \"c\" 'd'>\n"),
            "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;&#10;"
        );
    }

    #[test]
    fn nice_rounds_to_one_two_five() {
        assert_eq!(nice(0.0037, false), 0.002);
        assert_eq!(nice(0.0037, true), 0.005);
        assert_eq!(nice(0.001, false), 0.001);
        assert_eq!(nice(7.3, true), 10.0);
        assert_eq!(nice(0.25, false), 0.2);
    }
}
