//! FMI 3.0's modelDescription.xml, from the same variable table, scene and options as
//! FMI 2.0's ([`super::xml`], whose shared parts it uses): the same names, value
//! references, descriptions, units, start values and dependencies; the types Float64
//! (Real variables) and Int32 (`method`); the independent variable `time`, which FMI 3.0
//! requires, at the value reference after the table's ([`VarTable::time_ref`]);
//! `instantiationToken` the FMU's GUID; ModelStructure naming variables by value
//! reference. Element order follows the FMI 3.0 schema (CoSimulation, UnitDefinitions,
//! LogCategories, DefaultExperiment, ModelVariables, ModelStructure, Annotations), with
//! `<ModelExchange>` before `<CoSimulation>` when the FMU declares it.

use std::fmt::Write;

use super::fmi_version::FmiVersion;
use super::options::SceneOptions;
use super::vars::{Kind, VarTable, method_range};
use super::xml::{
    body_description, categories_and_experiment, derivative_unknowns, escape, real_attributes,
    state_unknowns, unit_element, units_used, unknowns, variable_attributes,
};
use crate::scene::Scene;

/// The time unit of a system (`s`, `ms`, ...), declared with the others when the FMU
/// declares units: `time` is in it.
fn time_unit(u: crate::units::UnitSystem) -> (String, [i32; 3], f64) {
    (u.time_name().to_string(), [0, 0, 1], u.factor([0, 0, 1]))
}

/// The complete FMI 3.0 modelDescription.xml text; `platforms` are the `binaries/`
/// folders of the libraries `pack --binary` added (recorded in an annotation).
pub fn model_description(
    scene: &Scene,
    table: &VarTable,
    opts: &SceneOptions,
    guid: &str,
    platforms: &[String],
) -> String {
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        "<fmiModelDescription fmiVersion=\"3.0\" modelName=\"{}\" instantiationToken=\"{}\" \
         description=\"{}\" generationTool=\"fxbody {}\" variableNamingConvention=\"structured\">",
        escape(&opts.name),
        escape(guid),
        escape(&body_description(scene, table)),
        env!("CARGO_PKG_VERSION")
    );
    if opts.interface.model_exchange() {
        // No events; the master calls fmi3CompletedIntegratorStep.
        let _ = writeln!(
            x,
            "  <ModelExchange modelIdentifier=\"{}\" needsExecutionTool=\"false\" \
             canBeInstantiatedOnlyOncePerProcess=\"false\" canGetAndSetFMUState=\"true\" \
             canSerializeFMUState=\"true\" providesDirectionalDerivatives=\"true\" \
             providesAdjointDerivatives=\"false\" providesPerElementDependencies=\"false\" \
             needsCompletedIntegratorStep=\"true\" providesEvaluateDiscreteStates=\"false\"/>",
            // The directional derivative: exact for a blocked body, a central
            // difference of a free body's accelerations (crate::fmu::simulation).
            escape(&opts.model_identifier()),
        );
    }
    if opts.interface.co_simulation() {
        let _ = writeln!(
            x,
            "  <CoSimulation modelIdentifier=\"{}\" needsExecutionTool=\"false\" \
             canBeInstantiatedOnlyOncePerProcess=\"false\" canGetAndSetFMUState=\"true\" \
             canSerializeFMUState=\"true\" providesDirectionalDerivatives=\"false\" \
             providesAdjointDerivatives=\"false\" providesPerElementDependencies=\"false\" \
             canHandleVariableCommunicationStepSize=\"true\" maxOutputDerivativeOrder=\"2\" \
             providesIntermediateUpdate=\"false\" mightReturnEarlyFromDoStep=\"false\" \
             canReturnEarlyAfterIntermediateUpdate=\"false\" hasEventMode=\"false\" \
             providesEvaluateDiscreteStates=\"false\"/>",
            escape(&opts.model_identifier())
        );
    }
    if let Some(u) = opts.units {
        x.push_str("  <UnitDefinitions>\n");
        let mut used = units_used(table, u);
        let time = time_unit(u);
        if !used.iter().any(|d| d.0 == time.0) {
            used.push(time);
        }
        for def in &used {
            x.push_str(&unit_element(def));
        }
        x.push_str("  </UnitDefinitions>\n");
    }
    // FMI 3.0 calls logMessage only when loggingOn or fmi3SetDebugLogging asks, errors
    // and warnings included.
    x.push_str(&categories_and_experiment(scene, opts).replace(
        " (always on)",
        " (when loggingOn or fmi3SetDebugLogging switches logging on)",
    ));
    x.push_str("  <ModelVariables>\n");
    let time_unit = opts
        .units
        .map_or_else(String::new, |u| format!(" unit=\"{}\"", time_unit(u).0));
    let _ = writeln!(
        x,
        "    <Float64 name=\"time\" valueReference=\"{}\" description=\"Simulation time \
         (the independent variable)\" causality=\"independent\" variability=\"continuous\"{time_unit}/>",
        table.time_ref()
    );
    for v in &table.vars {
        let common = variable_attributes(v);
        if v.kind == Kind::Method {
            // An Int32 with min and max, as FMI 2.0's Integer (see super::xml).
            let (lo, hi) = method_range();
            let _ = writeln!(
                x,
                "    <Int32 {common} min=\"{lo}\" max=\"{hi}\" start=\"{}\"/>",
                table.default_method as i32
            );
        } else {
            let mut attrs = real_attributes(v, opts);
            if let Kind::Derivative(i) = v.kind
                && let Some(state) = table.state_ref(i)
            {
                // FMI 3.0 names the state by value reference.
                let _ = write!(attrs, " derivative=\"{state}\"");
            }
            let _ = writeln!(x, "    <Float64 {common}{attrs}/>");
        }
    }
    x.push_str("  </ModelVariables>\n  <ModelStructure>\n");
    // FMI 3.0 names variables by value reference (here the table position too).
    let vrs = |deps: &[usize]| {
        let v: Vec<String> = deps.iter().map(|&j| table.vars[j].vr.to_string()).collect();
        v.join(" ")
    };
    let outputs = unknowns(scene, table);
    let derivatives = derivative_unknowns(table);
    let states = state_unknowns(table);
    // Schema order: Output, ContinuousStateDerivative, InitialUnknown (the outputs',
    // the calculated states', then the derivatives': ascending value references).
    for (element, initial, list) in [
        ("Output", false, &outputs),
        ("ContinuousStateDerivative", false, &derivatives),
        ("InitialUnknown", true, &outputs),
        ("InitialUnknown", true, &states),
        ("InitialUnknown", true, &derivatives),
    ] {
        for u in list {
            let deps = if initial { &u.initial } else { &u.outputs };
            let _ = writeln!(
                x,
                "    <{element} valueReference=\"{}\" dependencies=\"{}\"/>",
                table.vars[u.output].vr,
                vrs(deps)
            );
        }
    }
    x.push_str("  </ModelStructure>\n");
    if !platforms.is_empty() {
        // What pack --binary added, as FMI 2.0's description records it in a vendor
        // annotation.
        let _ = writeln!(
            x,
            "  <Annotations>\n    <Annotation type=\"fxbody\">\n      <Platforms native=\"{}\" added=\"{}\"/>\n    </Annotation>\n  </Annotations>",
            FmiVersion::Fmi3.native_platform(),
            escape(&platforms.join(" "))
        );
    }
    x.push_str("</fmiModelDescription>\n");
    x
}
