//! `<modelName>_OspModelDescription.xml`, written by `pack` beside the `.fmu`: the
//! OSP Interface Specification's (OSP-IS 1.0) mechanical ports of the exposed nodes, so
//! that a libcosim user connects two bodies (or a body and another model) port to port in
//! OspSystemStructure.xml instead of variable by variable. libcosim looks for the file
//! under this name beside the FMU or beside the system structure.
//!
//! Per exposed node `ID`, generated from the variable table (so it names only variables
//! the model description declares):
//! - `node_ID.linear`, a LinearMechanicalPort: Force `node_ID.force` (inputs
//!   `node_ID.fx|fy|fz`) and LinearVelocity `node_ID.velocity` (outputs
//!   `node_ID.vx|vy|vz`);
//! - `node_ID.angular`, an AngularMechanicalPort, when the node has moment inputs and
//!   angular-velocity outputs: Torque `node_ID.torque` (`node_ID.mx|my|mz`) and
//!   AngularVelocity `node_ID.angular_velocity` (`node_ID.wx|wy|wz`).
//!
//! Every variable carries its axis, and its unit when the FMU declares units (`pack
//! --units`); the units are then also defined in the file, as the model description
//! defines them.

use std::collections::HashMap;
use std::fmt::Write;
use std::path::{Path, PathBuf};

use super::options::SceneOptions;
use super::vars::{Causality, Kind, VarTable, Variable};
use super::xml::{escape, unit, unit_element};

/// The OSP-IS namespace of the files written here.
pub const NAMESPACE: &str = "https://open-simulation-platform.com/OspModelDescription/1.0.0";

/// Where the OSP model description of the FMU at `fmu` with model name `name` goes: the
/// same folder, `<name>_OspModelDescription.xml`.
pub fn osp_path(fmu: &Path, name: &str) -> PathBuf {
    fmu.parent()
        .unwrap_or(Path::new(""))
        .join(format!("{name}_OspModelDescription.xml"))
}

/// One port: (port element, port name, [(group element, group name, variable suffixes)]).
type PortSpec = (
    &'static str,
    &'static str,
    [(&'static str, &'static str, [&'static str; 3]); 2],
);

const PORTS: [PortSpec; 2] = [
    (
        "LinearMechanicalPort",
        "linear",
        [
            ("Force", "force", ["fx", "fy", "fz"]),
            ("LinearVelocity", "velocity", ["vx", "vy", "vz"]),
        ],
    ),
    (
        "AngularMechanicalPort",
        "angular",
        [
            ("Torque", "torque", ["mx", "my", "mz"]),
            ("AngularVelocity", "angular_velocity", ["wx", "wy", "wz"]),
        ],
    ),
];

/// The file's text.
pub fn osp_model_description(table: &VarTable, opts: &SceneOptions) -> String {
    let by_name: HashMap<&str, &Variable> =
        table.vars.iter().map(|v| (v.name.as_str(), v)).collect();
    // Exposed nodes in table order, by the prefix of their first load input.
    let prefixes: Vec<&str> = table
        .vars
        .iter()
        .filter(|v| matches!(v.kind, Kind::Load { comp: 0, .. }))
        .filter_map(|v| v.name.rsplit_once('.').map(|(p, _)| p))
        .collect();
    let unit_of = |v: &Variable| opts.units.and_then(|u| unit(v.quantity, u));
    let mut groups = String::new();
    let mut used_units: Vec<(&str, [i32; 3], f64)> = Vec::new();
    for prefix in &prefixes {
        for (port, port_name, parts) in PORTS {
            // A port appears only when all six of its variables exist with the causality
            // it needs: efforts (force, torque) are inputs, flows (velocities) outputs.
            let vars: Option<Vec<Vec<&Variable>>> = parts
                .iter()
                .enumerate()
                .map(|(k, (_, _, sfx))| {
                    let want = if k == 0 {
                        Causality::Input
                    } else {
                        Causality::Output
                    };
                    sfx.iter()
                        .map(|s| {
                            by_name
                                .get(format!("{prefix}.{s}").as_str())
                                .copied()
                                .filter(|v| v.causality == want)
                        })
                        .collect()
                })
                .collect();
            let Some(vars) = vars else { continue };
            let _ = writeln!(
                groups,
                "    <{port} name=\"{}\">",
                escape(&format!("{prefix}.{port_name}"))
            );
            for ((group, group_name, _), vs) in parts.iter().zip(&vars) {
                let _ = writeln!(
                    groups,
                    "      <{group} name=\"{}\">",
                    escape(&format!("{prefix}.{group_name}"))
                );
                for (v, axis) in vs.iter().zip(["x", "y", "z"]) {
                    let mut attrs = String::new();
                    if let Some(u) = unit_of(v) {
                        let _ = write!(attrs, " unit=\"{}\"", escape(u.0));
                        if !used_units.iter().any(|w| w.0 == u.0) {
                            used_units.push((u.0, u.1, u.2));
                        }
                    }
                    let _ = writeln!(
                        groups,
                        "        <Variable ref=\"{}\"{attrs} axis=\"{axis}\"/>",
                        escape(&v.name)
                    );
                }
                let _ = writeln!(groups, "      </{group}>");
            }
            let _ = writeln!(groups, "    </{port}>");
        }
    }
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        "<!-- Mechanical ports of {} (written by fxbody pack): one LinearMechanicalPort per exposed node, \
         and an AngularMechanicalPort where the node has rotations. Forces and torques are inputs, \
         velocities outputs, global frame. -->",
        escape(&opts.name).replace("--", "- -")
    );
    let _ = writeln!(
        x,
        "<OspModelDescription xmlns=\"{NAMESPACE}\" version=\"1.0\">"
    );
    if !used_units.is_empty() {
        x.push_str("  <UnitDefinitions>\n");
        for def in &used_units {
            x.push_str(&unit_element(*def));
        }
        x.push_str("  </UnitDefinitions>\n");
    }
    x.push_str("  <VariableGroups>\n");
    x.push_str(&groups);
    x.push_str("  </VariableGroups>\n</OspModelDescription>\n");
    x
}
