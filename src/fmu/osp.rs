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
/// same folder, `<name>_OspModelDescription.xml`, the name libcosim looks for (it finds
/// an FMU's description by the model name of its modelDescription.xml, not by the
/// `.fmu` file's name).
pub fn osp_path(fmu: &Path, name: &str) -> PathBuf {
    fmu.parent()
        .unwrap_or(Path::new(""))
        .join(format!("{name}_OspModelDescription.xml"))
}

/// The comment that records which `.fmu` file (by name, in the same folder) an OSP
/// model description was written for, so that a second pack of the same model name
/// into the folder is refused instead of silently describing the other FMU.
const DESCRIBES: &str = "<!-- fxbody: describes ";

/// `fmu`'s file name as recorded in the [`DESCRIBES`] comment (no `--` inside a comment).
fn recorded_name(fmu: &Path) -> String {
    fmu.file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
        .replace("--", "- -")
}

/// Why the OSP model description of a pack cannot be written where libcosim looks for it.
/// The messages name the files; the way out (another model name, another folder) is the
/// command's to word with its options.
#[derive(Debug, thiserror::Error)]
pub enum OspClash {
    /// It describes another `.fmu` of the same model name, still in the folder.
    #[error(
        "{}: {} describes {other}, another FMU of the model name '{name}' in this folder, \
         and libcosim finds an FMU's OSP description by its model name: writing this pack's \
         would make it describe the wrong FMU",
        .fmu.display(), .osp.display()
    )]
    OtherFmu {
        /// The FMU being packed.
        fmu: PathBuf,
        /// The OSP description in the way.
        osp: PathBuf,
        /// The `.fmu` file it describes.
        other: String,
        /// The model name.
        name: String,
    },
    /// It was not written by `fxbody pack` (or is unreadable): never overwritten.
    #[error(
        "{}: {} exists and was not written by fxbody pack ({why}): refusing to overwrite it",
        .fmu.display(), .osp.display()
    )]
    NotOurs {
        /// The FMU being packed.
        fmu: PathBuf,
        /// The OSP description in the way.
        osp: PathBuf,
        /// What was found instead of the record.
        why: String,
    },
}

/// Check that the OSP model description of `fmu` (model name `name`) can be written: no
/// such file yet, or one `pack` wrote for this same `.fmu` file name, or for a `.fmu` no
/// longer in the folder.
pub fn check_osp_target(fmu: &Path, name: &str) -> Result<(), OspClash> {
    let osp = osp_path(fmu, name);
    if std::fs::symlink_metadata(&osp).is_err() {
        return Ok(());
    }
    let not_ours = |why: String| OspClash::NotOurs {
        fmu: fmu.to_path_buf(),
        osp: osp.clone(),
        why,
    };
    let bytes = crate::fxb::input::read_bounded(&osp, crate::fxb::input::Limit::Reference)
        .map_err(|e| not_ours(crate::fxb::input::describe(&e)))?;
    let text = String::from_utf8_lossy(&bytes);
    let Some(other) = text
        .lines()
        .find_map(|l| l.trim().strip_prefix(DESCRIBES)?.strip_suffix(" -->"))
    else {
        return Err(not_ours("no record of the FMU it describes".into()));
    };
    let this = recorded_name(fmu);
    let dir = fmu.parent().unwrap_or(Path::new(""));
    if other == this || !dir.join(other).exists() {
        return Ok(());
    }
    Err(OspClash::OtherFmu {
        fmu: fmu.to_path_buf(),
        osp,
        other: other.to_string(),
        name: name.to_string(),
    })
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

/// The file's text, for the FMU written to `fmu` (recorded in it, see [`check_osp_target`]).
pub fn osp_model_description(table: &VarTable, opts: &SceneOptions, fmu: &Path) -> String {
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
    let mut used_units: Vec<(String, [i32; 3], f64)> = Vec::new();
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
                        let _ = write!(attrs, " unit=\"{}\"", escape(&u.0));
                        if !used_units.iter().any(|w| w.0 == u.0) {
                            used_units.push(u);
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
    let _ = writeln!(x, "{DESCRIBES}{} -->", recorded_name(fmu));
    let _ = writeln!(
        x,
        "<OspModelDescription xmlns=\"{NAMESPACE}\" version=\"1.0\">"
    );
    if !used_units.is_empty() {
        x.push_str("  <UnitDefinitions>\n");
        for def in &used_units {
            x.push_str(&unit_element(def));
        }
        x.push_str("  </UnitDefinitions>\n");
    }
    x.push_str("  <VariableGroups>\n");
    x.push_str(&groups);
    x.push_str("  </VariableGroups>\n</OspModelDescription>\n");
    x
}
