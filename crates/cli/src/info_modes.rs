//! `fxbody info --nodes ID,...`: what mode truncation costs at the nodes a scene couples
//! to. For each mode of (K_L, m_L): its frequency and, at each chosen node and direction,
//! the cumulative share of `sum_i phi_i^2 / omega_i^2` (the node's flexibility in the
//! local modes) carried by the modes up to it. For a blocked body that flexibility is
//! the static deflection under a unit load. A free body has no static deflection (a load
//! accelerates it); the same sum is then the deflection relative to the frame with the
//! load balanced by the body's rigid inertia (inertia relief), exactly so when the local
//! modes are mass-orthogonal to rigid motion; the report says which. A free body's
//! effective masses along X, Y, Z are printed only when a mode has one: local modes
//! mass-orthogonal to rigid motion (free-free modes) carry no net momentum, and the
//! report says so instead of printing a column of zeros. With `--json`, the JSON array
//! that `info` puts under its `modes` key (`cumulative_static_share` for a blocked body,
//! `cumulative_local_share` for a free one).
//!
//! An effective mass below [`ZERO_MASS`] times the total mass is printed as 0: it is
//! round-off of the projection (about 1e-22 kg on a 0.75 kg body), not mass.

use std::fmt::Write;

use fxbody::body::Body;
use fxbody::scene::reduce::{effective_mass, static_participation};

const DIRS: [&str; 6] = ["X", "Y", "Z", "XX", "YY", "ZZ"];

/// Effective masses below this fraction of the total mass are round-off and shown as 0.
pub const ZERO_MASS: f64 = 1e-12;

/// The report text (or JSON) for `nodes` (indices into the body's node list).
pub fn report(body: &Body, nodes: &[usize], json: bool) -> String {
    let p = static_participation(body, nodes);
    let floor = ZERO_MASS * body.total_mass().unwrap_or(0.0).abs();
    let eff = effective_mass(body).map(|e| e.map(|v| if v.abs() < floor { 0.0 } else { v }));
    let nl = body.nl();
    // Only the directions that deflect at all.
    let cols: Vec<usize> = (0..6 * nodes.len())
        .filter(|&c| p.deflection[c] > 0.0)
        .collect();
    let name = |c: usize| format!("{}:{}", body.node_ids()[nodes[c / 6]], DIRS[c % 6]);
    let mut cum = vec![0.0; 6 * nodes.len()];
    let mut o = String::new();
    let share_key = if body.is_blocked() {
        "cumulative_static_share"
    } else {
        "cumulative_local_share"
    };
    if json {
        o.push_str("[\n");
        for i in 0..nl {
            let shares: Vec<String> = cols
                .iter()
                .map(|&c| {
                    cum[c] += p.fraction[(i, c)];
                    format!("\"{}\": {:?}", name(c), cum[c])
                })
                .collect();
            let em = eff.as_ref().map_or("null".to_string(), |e| {
                format!("[{:?}, {:?}, {:?}]", e[(i, 0)], e[(i, 1)], e[(i, 2)])
            });
            let _ = write!(
                o,
                "    {{\"mode\": {}, \"frequency_hz\": {:?}, \"{share_key}\": {{{}}}, \"effective_mass\": {em}}}",
                i + 1,
                p.frequencies_hz[i],
                shares.join(", ")
            );
            o.push_str(if i + 1 < nl { ",\n" } else { "\n" });
        }
        o.push_str("  ]\n");
        return o;
    }
    // A free body's effective masses, printed only when some mode has one.
    let eff = eff.filter(|e| e.iter().any(|&v| v != 0.0));
    o.push_str(&heading(body, eff.is_some()));
    let _ = write!(o, "{:>5} {:>13}", "mode", "f (Hz)");
    for &c in &cols {
        let _ = write!(o, " {:>12}", name(c));
    }
    if eff.is_some() {
        let _ = write!(o, " {:>11} {:>11} {:>11}", "meff X", "meff Y", "meff Z");
    }
    o.push('\n');
    for i in 0..nl {
        let _ = write!(o, "{:>5} {:>13.6e}", i + 1, p.frequencies_hz[i]);
        for &c in &cols {
            cum[c] += p.fraction[(i, c)];
            let _ = write!(o, " {:>11.6}%", 100.0 * cum[c]);
        }
        if let Some(e) = &eff {
            let _ = write!(
                o,
                " {:>11.4e} {:>11.4e} {:>11.4e}",
                e[(i, 0)],
                e[(i, 1)],
                e[(i, 2)]
            );
        }
        o.push('\n');
    }
    if let (Some(e), Some(m)) = (&eff, body.total_mass()) {
        let _ = writeln!(
            o,
            "effective mass, sum over all modes (X Y Z): {:.4e} {:.4e} {:.4e} kg of total {m:.4e} kg \
             (values below {ZERO_MASS:e} of the total mass are round-off, shown as 0)",
            e.column(0).sum(),
            e.column(1).sum(),
            e.column(2).sum()
        );
    }
    o
}

/// What the table's shares mean for this body, and why a free body's table has no
/// static deflection (and, without effective masses, no such column).
fn heading(body: &Body, with_mass: bool) -> String {
    let tail = "; truncating after a mode without static correction loses 100% minus that \
                share\n";
    if body.is_blocked() {
        return format!(
            "\nper mode: cumulative share of the static deflection (unit load at the node \
             and direction, global frame at P0) carried by the modes up to this one{tail}"
        );
    }
    let mut o = format!(
        "\nper mode: each node's participation in the local modes: the cumulative share of \
         its flexibility relative to the frame, sum of phi_i^2 / omega_i^2 (unit load at the \
         node and direction, global frame at P0), carried by the modes up to this one{tail}\
         (a free body has no static deflection: a load accelerates the whole body; the \
         share is that of the deflection relative to the frame with the load balanced by \
         the rigid inertia, inertia relief{})\n",
        if with_mass {
            ", only approximately here: these local modes carry mass with the rigid motion"
        } else {
            ""
        }
    );
    if !with_mass {
        o.push_str(
            "effective masses: none (every local mode is mass-orthogonal to rigid motion and \
             carries no net momentum; the rigid-body mass, centre of gravity and inertia \
             are above)\n",
        );
    }
    o
}
