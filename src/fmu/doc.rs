//! documentation/index.html: the body at a glance (nodes, modes and frequencies, stable
//! step, variables), so a user opening the FMU sees what it holds.

use std::fmt::Write;

pub mod picture;

use super::fmi_version::FmiVersion;
use super::options::SceneOptions;
use super::vars::{Causality, VarTable, default_method, method_name};
use super::xml::{feeds_through, modes_summary};
use crate::scene::Scene;

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The HTML page of an FMI 2.0 FMU.
pub fn index_html(scene: &Scene, table: &VarTable, opts: &SceneOptions, guid: &str) -> String {
    index_html_for(scene, table, opts, guid, FmiVersion::Fmi2, &opts.platforms)
}

/// The HTML page of an FMU packed for `fmi`, whose `binaries/` folders besides the
/// packing build's are `added`.
pub fn index_html_for(
    scene: &Scene,
    table: &VarTable,
    opts: &SceneOptions,
    guid: &str,
    fmi: FmiVersion,
    added: &[String],
) -> String {
    let b = &scene.body;
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{0}</title></head><body>\n<h1>{0}</h1>\n",
        esc(&opts.name)
    );
    let (stop, step) = opts.experiment(scene);
    let _ = write!(
        h,
        "<p>A Radioss flexible body (/FXBODY) as an FMI {} co-simulation unit, packed by fxbody {} \
         (GUID {}).</p>\n<ul>\n<li>{} body, {} nodes, {} ({} static), rotational DOFs: {}</li>\n\
         <li>Damping: {}</li>\n<li>Explicit stable step (from the largest computed eigenfrequency of the kept modes, {:.6e} Hz; the file's stored Freq is {:.6e} Hz): {:.6e} s</li>\n\
         <li>Default experiment: stop {} s, step {} s</li>\n<li>Methods: {}; default {}</li>\n<li>Units: {}</li>\n<li>Platforms: {}</li>\n</ul>\n",
        fmi.number(),
        env!("CARGO_PKG_VERSION"),
        esc(guid),
        if table.free { "Free" } else { "Blocked" },
        b.nnodes(),
        modes_summary(scene),
        b.nbstat,
        if b.irot { "yes" } else { "no" },
        b.damping.map_or("none".to_string(), |d| format!(
            "Rayleigh alpha {} 1/s, beta {} s",
            d.alpha, d.beta
        )),
        b.freq_max_hz(),
        b.freq_file,
        b.explicit_stable_step(),
        stop,
        step,
        table
            .methods()
            .iter()
            .map(|&m| method_name(m))
            .collect::<Vec<_>>()
            .join(", "),
        default_text(table),
        opts.units.map_or_else(
            || "none declared (the file's own consistent system)".to_string(),
            |u| u.name()
        ),
        std::iter::once(fmi.native_platform())
            .chain(added.iter().map(String::as_str))
            .collect::<Vec<_>>()
            .join(", "),
    );
    free_body(&mut h, scene, table);
    h.push_str("<h2>Eigenfrequencies of the kept local modes (Hz)</h2>\n<p>");
    let f: Vec<String> = b.frequencies_hz.iter().map(|f| format!("{f:.6}")).collect();
    h.push_str(&f.join(", "));
    h.push_str("</p>\n");
    h.push_str(&picture::section(scene, &b.frequencies_hz));
    h.push_str("<h2>Exposed nodes</h2>\n<table border=\"1\"><tr><th>ID</th><th>x</th><th>y</th><th>z</th><th>rotations</th></tr>\n");
    for (k, &n) in scene.nodes.iter().enumerate() {
        let [x, y, z] = scene.x0[k];
        let rot = scene.node_has_rotation(k);
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{x}</td><td>{y}</td><td>{z}</td><td>{}</td></tr>",
            b.node_ids[n],
            if rot { "yes" } else { "no" }
        );
    }
    h.push_str("</table>\n<h2>Variables</h2>\n<table border=\"1\"><tr><th>vr</th><th>name</th><th>causality</th><th>start</th><th>description</th></tr>\n");
    for v in &table.vars {
        let c = v.causality.name();
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{c}</td><td>{}</td><td>{}</td></tr>",
            v.vr,
            esc(&v.name),
            v.start.map_or(String::new(), |s| s.to_string()),
            esc(&v.description)
        );
    }
    h.push_str(match fmi {
        FmiVersion::Fmi2 => "</table>\n<p>Loads are in the global frame, held over a step or interpolated linearly when the master sets input derivatives.</p>\n",
        // FMI 3.0 has no input derivatives; `time`, its independent variable, is declared
        // at the value reference after the table's.
        FmiVersion::Fmi3 => "</table>\n<p>Loads are in the global frame, held over a step. The independent variable <code>time</code> follows the table's last value reference.</p>\n",
    });
    dependencies(&mut h, scene, table);
    h.push_str("</body></html>\n");
    h
}

/// A free body's rigid properties (mass, centre of mass, inertia), the point `v0` and `w0`
/// refer to, the frame outputs, and which method to choose when.
fn free_body(h: &mut String, scene: &Scene, table: &VarTable) {
    if !table.free {
        return;
    }
    let Some(mp) = crate::body::mass_props::mass_properties(&scene.body) else {
        return;
    };
    let c = mp.cog_from_l0;
    let i = mp.inertia;
    let _ = write!(
        h,
        "<h2>Free body</h2>\n<ul>\n<li>Mass: {:.6e}</li>\n\
         <li>Centre of mass, from the frame origin L0 (global axes at the start): ({:.6e}, {:.6e}, {:.6e})</li>\n\
         <li>Inertia at the centre of mass (global axes at the start): [[{:.6e}, {:.6e}, {:.6e}], [{:.6e}, {:.6e}, {:.6e}], [{:.6e}, {:.6e}, {:.6e}]]</li>\n\
         <li>v0 is the initial velocity of the frame origin L0 and w0 the body's initial angular velocity; every point of the body starts at v0 + w0 x r, r its position from L0. L0 is the origin of the file's rigid modes; the outputs frame.x, frame.y, frame.z give its position, frame.vx, frame.vy, frame.vz its velocity and frame.wx, frame.wy, frame.wz the frame's angular velocity.</li>\n\
         <li>Which method (the measured comparison in docs/STUDY.md): split, the default, at a master's step: the most accurate at every step on the study's free bodies, second order on a tumble, and cheaper than the explicit method at equal error; explicit to compare with Radioss (its own scheme, sub-cycled at 0.9 of the stable step, first order on a fast tumble); implicit only to reproduce an implicit reference tool (it damps the highest modes, by rho_inf)</li>\n</ul>\n",
        mp.mass,
        c[0],
        c[1],
        c[2],
        i[(0, 0)],
        i[(0, 1)],
        i[(0, 2)],
        i[(1, 0)],
        i[(1, 1)],
        i[(1, 2)],
        i[(2, 0)],
        i[(2, 1)],
        i[(2, 2)],
    );
}

/// The default method and why: the body's default with its reason, or the method
/// `pack --method` chose.
fn default_text(table: &VarTable) -> String {
    let (body_default, why) = default_method(table.free);
    if table.default_method == body_default {
        esc(&format!("{} ({why})", method_name(body_default)))
    } else {
        esc(&format!(
            "{} (chosen by pack --method; this body's own default is {}: {why})",
            method_name(table.default_method),
            method_name(body_default)
        ))
    }
}

/// The outputs that depend on same-instant inputs, from the function the model
/// description's ModelStructure is written from ([`feeds_through`]).
fn dependencies(h: &mut String, scene: &Scene, table: &VarTable) {
    let name = |i: usize| esc(&table.vars[i].name);
    let outputs: Vec<usize> = (0..table.vars.len())
        .filter(|&i| table.vars[i].causality == Causality::Output && feeds_through(scene, table, i))
        .collect();
    if outputs.is_empty() {
        h.push_str("<p>Outputs do not depend on same-instant inputs.</p>\n");
        return;
    }
    let inputs: Vec<String> = (0..table.vars.len())
        .filter(|&j| table.vars[j].causality == Causality::Input)
        .map(name)
        .collect();
    h.push_str("<h2>Outputs that depend on same-instant inputs</h2>\n<p>The residual correction makes these outputs depend on every input at the same instant:</p>\n<table border=\"1\"><tr><th>output</th><th>depends on</th></tr>\n");
    for i in outputs {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td></tr>",
            name(i),
            inputs.join(" ")
        );
    }
    h.push_str("</table>\n");
}

#[cfg(test)]
mod tests {
    use super::index_html;
    use crate::fmu::options::SceneOptions;
    use crate::fmu::vars::VarTable;
    use crate::solver::Method;

    /// The page says which method runs unless chosen, and why: exact for a blocked body,
    /// split for a free one (issue 28), and the method `pack --method` chose beside the
    /// body's own default.
    #[test]
    fn the_page_names_the_default_method_and_why() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let blocked = crate::scene::io::cantilever_tip_scene();
        let body =
            crate::body::load(&root.join("fixtures/freefree.fxb"), Default::default()).unwrap();
        let x = body.rigid_mode_positions().unwrap();
        let free = crate::scene::Scene::new(std::sync::Arc::new(body), vec![20], vec![x[20]]);
        let opts = SceneOptions {
            name: "t".into(),
            ..SceneOptions::default()
        };
        let page = |s: &crate::scene::Scene, t: &VarTable| index_html(s, t, &opts, "{g}");
        let b = page(&blocked, &VarTable::new(&blocked));
        assert!(
            b.contains("default exact (no time-discretisation error"),
            "{b}"
        );
        let f = page(&free, &VarTable::new(&free));
        assert!(
            f.contains("default split (local modes exact between samples")
                && f.contains("each step's impulse exact"),
            "{f}"
        );
        let chosen = VarTable::new(&free).with_default_method(Some(Method::Implicit));
        let c = page(&free, &chosen);
        assert!(
            c.contains(
                "default implicit (chosen by pack --method; this body's own default is split"
            ),
            "{c}"
        );
    }
}
