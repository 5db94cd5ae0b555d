//! `fxbody info --nodes ID,...`: what mode truncation costs at the nodes a scene couples
//! to. For each mode of (K_L, m_L): its frequency, the cumulative share of the static
//! deflection carried by the modes up to it at each chosen node and direction, and for
//! a free body its effective mass along X, Y, Z. With `--json`, the JSON array that
//! `info` puts under its `modes` key.
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
    let name = |c: usize| format!("{}:{}", body.node_ids[nodes[c / 6]], DIRS[c % 6]);
    let mut cum = vec![0.0; 6 * nodes.len()];
    let mut o = String::new();
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
                "    {{\"mode\": {}, \"frequency_hz\": {:?}, \"cumulative_static_share\": {{{}}}, \"effective_mass\": {em}}}",
                i + 1,
                p.frequencies_hz[i],
                shares.join(", ")
            );
            o.push_str(if i + 1 < nl { ",\n" } else { "\n" });
        }
        o.push_str("  ]\n");
        return o;
    }
    o.push_str(
        "\nper mode: cumulative share of the static deflection (unit load at the node and \
         direction, global frame at P0) carried by the modes up to this one; truncating \
         after a mode without static correction loses 100% minus that share\n",
    );
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
