//! Model Exchange + CVode on the study's panels (issue 26.3): the points `study/me.py`
//! writes to `me.csv` before the study runs (the Model Exchange FMU through fmpy's
//! CVode over a range of relative tolerances, the error measured as the study measures
//! it, CPU per simulated second), read into one curve per scene and a table of
//! study_results.md.

use std::fmt::Write as _;
use std::path::Path;

use fxbody_chart::{Curve, Style};

/// The curve's legend entry.
pub const LABEL: &str = "Model Exchange + CVode (fmpy)";
/// The curve's colour: black, apart from the methods' and the peers' colours.
const COLOR: &str = "#000000";

/// One point of `me.csv`: a scene run at one CVode tolerance.
#[derive(Debug, Clone, PartialEq)]
pub struct MePoint {
    /// The study's scene name (`cantilever step`, ...).
    pub scene: String,
    /// CVode's relative tolerance.
    pub rtol: f64,
    /// Largest error over the reference samples, relative to the reference's peak
    /// (NaN when CVode gave up).
    pub error: f64,
    /// CPU seconds per simulated second (NaN when CVode gave up).
    pub cpu_per_s: f64,
    /// Why there is no result, if there is none.
    pub note: String,
}

/// The points of `me.csv` (`scene,rtol,error_rel_peak,cpu_s_per_sim_s,outputs,
/// compared_samples,note`), none when the text is `None` (the file is missing: the
/// study was run without `study/me.py`). A row that does not read is refused, naming
/// the file and line.
pub fn parse(text: Option<&str>, path: &Path) -> Result<Vec<MePoint>, String> {
    let Some(text) = text else {
        return Ok(Vec::new());
    };
    let mut out = Vec::new();
    for (no, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() || line.starts_with('#') {
            continue;
        }
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        let bad = |what: &str| {
            format!(
                "{}: line {}: {what} (expected scene,rtol,error_rel_peak,cpu_s_per_sim_s,outputs,compared_samples,note)",
                path.display(),
                no + 1
            )
        };
        if f.len() < 4 {
            return Err(bad(&format!("{} fields", f.len())));
        }
        let num = |i: usize, name: &str| {
            f[i].parse::<f64>()
                .map_err(|_| bad(&format!("{name} `{}` is not a number", f[i])))
        };
        out.push(MePoint {
            scene: f[0].to_string(),
            rtol: num(1, "rtol")?,
            error: num(2, "error_rel_peak")?,
            cpu_per_s: num(3, "cpu_s_per_sim_s")?,
            note: f.get(6).map_or(String::new(), |s| s.to_string()),
        });
    }
    Ok(out)
}

/// Above this error (relative to the peak) a run has diverged: the chart leaves it out,
/// so that one diverged point (CVode at a loose tolerance on an undamped body reaches
/// 6e9) does not stretch its panel's error axis; the table lists it.
pub const DIVERGED: f64 = 1.0;

/// The scene's curve (CPU per simulated second, error), tolerances loosest first, the
/// diverged runs left out; `None` when `me.csv` has no point for it.
pub fn curve(points: &[MePoint], scene: &str) -> Option<Curve> {
    let mut pts: Vec<&MePoint> = points
        .iter()
        .filter(|p| p.scene == scene && (p.error <= DIVERGED || p.error.is_nan()))
        .collect();
    if pts.is_empty() {
        return None;
    }
    pts.sort_by(|a, b| b.rtol.total_cmp(&a.rtol));
    Some(Curve {
        label: LABEL.to_string(),
        color: COLOR.to_string(),
        points: pts.iter().map(|p| (p.cpu_per_s, p.error)).collect(),
        style: Style::LinePoints,
    })
}

/// The table of study_results.md: every point as read.
pub fn table(points: &[MePoint]) -> String {
    let mut md = String::from(
        "| scene | CVode rtol | error / peak | CPU s / sim. s | note |\n|---|---|---|---|---|\n",
    );
    for p in points {
        let note = if p.error > DIVERGED {
            "diverged (not drawn)"
        } else {
            p.note.as_str()
        };
        let _ = writeln!(
            md,
            "| {} | {:.0e} | {:.2e} | {:.2e} | {note} |",
            p.scene, p.rtol, p.error, p.cpu_per_s
        );
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    const CSV: &str = "scene,rtol,error_rel_peak,cpu_s_per_sim_s,outputs,compared_samples,note\n\
        cantilever step,1e-07,6.854e-04,1.55,2245,2245,\n\
        cantilever step,1e-04,2.338,1.5,2245,2245,\n\
        cantilever step,1e-03,0.5,1.4,2245,2245,\n\
        truss pulse,1e-10,NaN,NaN,0,0,CVode gave up\n";

    /// Rows read as written; a scene's curve runs from the loosest tolerance to the
    /// tightest, a diverged run (error 2.338 of the peak) left out of it and marked in the
    /// table; a failed run keeps its note.
    #[test]
    fn reads_points_into_one_curve_per_scene() {
        let p = parse(Some(CSV), Path::new("me.csv")).unwrap();
        assert_eq!(p.len(), 4);
        assert_eq!(p[0].rtol, 1e-7);
        assert_eq!(p[0].error, 6.854e-4);
        assert!(p[3].error.is_nan() && p[3].note == "CVode gave up");
        let c = curve(&p, "cantilever step").unwrap();
        assert_eq!(c.points, vec![(1.4, 0.5), (1.55, 6.854e-4)]);
        let t = table(&p);
        assert!(
            t.contains("| cantilever step | 1e-4 | 2.34e0 | 1.50e0 | diverged (not drawn) |"),
            "{t}"
        );
        assert!(
            t.contains("| truss pulse | 1e-10 | NaN | NaN | CVode gave up |"),
            "{t}"
        );
        assert_eq!(c.label, LABEL);
        assert!(curve(&p, "free tumble").is_none());
        assert!(parse(None, Path::new("me.csv")).unwrap().is_empty());
    }

    /// A row that does not read is refused with the file, the line and the field.
    #[test]
    fn a_bad_row_is_refused_naming_file_and_line() {
        let bad = "scene,rtol,error_rel_peak,cpu_s_per_sim_s\ncantilever step,1e-7,x,1.0\n";
        let e = parse(Some(bad), Path::new("out/me.csv")).unwrap_err();
        assert!(
            e.contains("out/me.csv: line 2: error_rel_peak `x` is not a number"),
            "{e}"
        );
        let e = parse(Some("h\ncantilever step,1e-7\n"), Path::new("me.csv")).unwrap_err();
        assert!(e.contains("line 2: 2 fields"), "{e}");
    }
}
