//! `pack --header FILE.h`: a C header for one packed FMU, so a C master names the
//! variables instead of reading value references out of modelDescription.xml by hand.
//! It holds the GUID and model identifier as strings, the value reference of every
//! variable as a named constant (`<PREFIX>_VR_<NAME>`, with its causality, unit and
//! description in a comment), the method values, and the variable count. It needs no
//! other header; the FMI types come from the FMI headers or include/fxbody.h.
//!
//! The macros are named after the header's own file name (`tip.h`: `TIP_GUID`,
//! `TIP_VR_NODE_121_FY`), not after the model: two packs of one body (one model name)
//! with headers `tip.h` and `root.h` can be included in one program without their
//! macros colliding.

use std::fmt::Write;
use std::path::Path;

use super::options::SceneOptions;
use super::vars::{VarTable, method_name};
use super::xml::unit;

/// A name as the upper-case C identifier part it becomes: every character outside
/// `[A-Za-z0-9]` becomes `_` (`node_121.fy` -> `NODE_121_FY`).
pub fn c_name(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_uppercase()
            } else {
                '_'
            }
        })
        .collect()
}

/// The prefix of the macros of the header written to `path`: its file name without
/// extension as an upper-case C identifier part ([`c_name`]: `out/tip-a.h` gives
/// `TIP_A`). Refused when that is no identifier a program may define: empty, starting
/// with a digit, or with `_` (reserved in C when an upper-case letter follows).
pub fn macro_prefix(path: &Path) -> Result<String, String> {
    let stem = path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let p = c_name(&stem);
    if p.starts_with(|c: char| c.is_ascii_alphabetic()) {
        Ok(p)
    } else {
        Err(format!(
            "{}: the header's macros are named after its file name ('{p}_GUID', ...), which must start with a letter",
            path.display()
        ))
    }
}

/// The header text for the FMU with variables `table`, options `opts` and `guid`, its
/// macros prefixed with `p` ([`macro_prefix`]).
pub fn c_header(p: &str, table: &VarTable, opts: &SceneOptions, guid: &str) -> String {
    let id = opts.model_identifier();
    let mut h = String::new();
    let _ = writeln!(
        h,
        "/* {p}_*: value references of the FMU '{}' (modelIdentifier {id}), written by fxbody pack {}.\n \
         * Valid for the FMU of this GUID only: pack again, write the header again. */",
        opts.name.replace("*/", "* /"),
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(
        h,
        "#ifndef FXBODY_HEADER_{p}_H\n#define FXBODY_HEADER_{p}_H\n"
    );
    let _ = writeln!(h, "#define {p}_GUID \"{guid}\"");
    let _ = writeln!(h, "#define {p}_MODEL_IDENTIFIER \"{id}\"");
    let _ = writeln!(h, "#define {p}_NUMBER_OF_VARIABLES {}u\n", table.vars.len());
    h.push_str("/* Values of the Integer parameter `method`. */\n");
    for &m in table.methods() {
        let _ = writeln!(
            h,
            "#define {p}_METHOD_{} {}",
            method_name(m).to_ascii_uppercase(),
            m as i32
        );
    }
    h.push_str("\n/* Value references (fmi2ValueReference). */\n");
    for v in &table.vars {
        let causality = v.causality.name();
        let u = opts
            .units
            .and_then(|u| unit(v.quantity, u))
            .map_or(String::new(), |u| format!(" [{}]", u.0));
        let _ = writeln!(
            h,
            "#define {p}_VR_{} {}u /* {} {causality}{u}: {} */",
            c_name(&v.name),
            v.vr,
            v.name,
            v.description.replace("*/", "* /")
        );
    }
    let _ = writeln!(h, "\n#endif /* FXBODY_HEADER_{p}_H */");
    h
}
