//! Mode-count sweep (issue 8): the cantilever scenes with the local modes truncated at
//! `fmax = k f1` (the dropped modes' residual flexibility kept, `Scene::truncated`), run
//! by the exact and the implicit method at one communication step, against the full-FE
//! reference. Shows how much accuracy each kept mode buys and what it costs.

use std::fmt::Write as _;

use super::run;
use super::scenes::{Case, Variant};

/// Cut-offs as multiples of the loaded plane's first frequency; `None` keeps every mode.
pub const FACTORS: [Option<f64>; 6] = [
    Some(1.5),
    Some(2.0),
    Some(5.0),
    Some(10.0),
    Some(30.0),
    None,
];

/// One row of the sweep.
pub struct ModeRow {
    scene: String,
    cutoff: String,
    fmax_hz: f64,
    kept: usize,
    method: String,
    h: f64,
    point: run::Point,
}

/// Run the sweep on `cases` (FE references) with `variants` at step `h`; `f1` is the
/// loaded plane's first frequency (Hz).
pub fn sweep(
    cases: &[&Case],
    variants: &[&Variant],
    f1: f64,
    h: f64,
    min_time: f64,
) -> Result<Vec<ModeRow>, String> {
    let mut rows = Vec::new();
    for case in cases {
        for k in FACTORS {
            let mut c = Case {
                name: case.name.clone(),
                scene: case.scene.clone(),
                load: case.load,
                duration: case.duration,
                components: case.components,
                steps: vec![h],
                reference: case.reference.clone(),
            };
            let (cutoff, fmax) = match k {
                Some(k) => {
                    let fmax = k * f1;
                    let (s, _) = case
                        .scene
                        .truncated(fmax)
                        .map_err(|e| format!("{}: truncation at {fmax:.1} Hz: {e}", case.name))?;
                    c.scene = s;
                    (format!("{k} f1"), fmax)
                }
                None => ("all".to_string(), f64::INFINITY),
            };
            let kept = c.scene.body.frequencies_hz().len();
            for v in variants {
                let p = run::measure(&c, v, h, min_time);
                eprintln!(
                    "  modes {:<16} {cutoff:<7} kept {kept:>2} {:<17} error {:.3e}  cpu/s {:.3e}",
                    case.name, v.label, p.error, p.cpu_per_s
                );
                rows.push(ModeRow {
                    scene: case.name.clone(),
                    cutoff: cutoff.clone(),
                    fmax_hz: fmax,
                    kept,
                    method: v.label.to_string(),
                    h,
                    point: p,
                });
            }
        }
    }
    Ok(rows)
}

/// `modes.csv` text and the Markdown table.
pub fn report(rows: &[ModeRow]) -> (String, String) {
    let mut csv = String::from(
        "scene,cutoff,fmax_hz,modes_kept,method,h_s,error_rel_peak,cpu_s_per_sim_s,ns_per_step,outcome\n",
    );
    let mut md = String::from(
        "| scene | cutoff | fmax (Hz) | modes kept | method | error / peak | CPU s per sim. s |\n|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            csv,
            "{},{},{:.4e},{},{},{:.6e},{:.6e},{:.6e},{:.1},{}",
            r.scene,
            r.cutoff,
            r.fmax_hz,
            r.kept,
            r.method,
            r.h,
            r.point.error,
            r.point.cpu_per_s,
            r.point.ns_per_step,
            r.point
                .outcome
                .as_ref()
                .map_or(String::new(), |f| f.to_string().replace(',', ";"))
        );
        let fmax = if r.fmax_hz.is_finite() {
            format!("{:.1}", r.fmax_hz)
        } else {
            "-".into()
        };
        let _ = writeln!(
            md,
            "| {} | {} | {fmax} | {} | {} | {:.2e} | {:.2e} |",
            r.scene, r.cutoff, r.kept, r.method, r.point.error, r.point.cpu_per_s
        );
    }
    (csv, md)
}
