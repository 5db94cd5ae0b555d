//! fxbody-chart: the SVG charts of the demo (`cantilever_tip.svg`, one linear panel) and
//! of the study (`study.svg`, a log-log panel per scene), written by one writer: a grid of
//! panels, each with its own axes (linear with 1-2-5 ticks, or logarithmic by decades),
//! and one legend above them naming every curve once. Plain SVG text, no dependency.
//!
//! ```
//! use fxbody_chart::{Curve, Panel, Scale, Style, svg};
//!
//! let panel = Panel {
//!     title: "tip".into(),
//!     x_label: "time (ms)".into(),
//!     y_label: "uy (m)".into(),
//!     x: Scale::Linear,
//!     y: Scale::Linear,
//!     curves: vec![Curve {
//!         label: "FMU".into(),
//!         color: "#1f77b4".into(),
//!         points: vec![(0.0, 0.0), (1.0, 2.0e-3), (2.0, 1.0e-3)],
//!         style: Style::Line,
//!     }],
//! };
//! let text = svg("Cantilever", &[panel], 1, (600.0, 300.0));
//! assert!(text.starts_with("<svg") && text.ends_with("</svg>\n"));
//! assert_eq!(text.matches("<polyline").count(), 1);
//! ```

use std::fmt::Write;

/// How an axis maps values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Linear, ticks at 1, 2 or 5 times a power of ten.
    Linear,
    /// Logarithmic, a tick per decade; values <= 0 are left out.
    Log,
}

/// How a curve is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// A line through the points.
    Line,
    /// A dashed line.
    Dashed,
    /// A line with a dot at each point.
    LinePoints,
    /// Square markers only (single measurements, no order between them).
    Markers,
}

/// One curve of a panel.
#[derive(Debug, Clone)]
pub struct Curve {
    /// Legend text (a label met again in another panel is listed once).
    pub label: String,
    /// Stroke or fill colour, as SVG takes it.
    pub color: String,
    /// (x, y) points in drawing order; non-finite points (and on a log axis, points <= 0)
    /// are left out.
    pub points: Vec<(f64, f64)>,
    /// How it is drawn.
    pub style: Style,
}

/// One panel: a title, two axes and its curves.
#[derive(Debug, Clone)]
pub struct Panel {
    /// Title above the panel.
    pub title: String,
    /// Label under the x axis.
    pub x_label: String,
    /// Label beside the y axis.
    pub y_label: String,
    /// The x axis' scale.
    pub x: Scale,
    /// The y axis' scale.
    pub y: Scale,
    /// The curves.
    pub curves: Vec<Curve>,
}

const ML: f64 = 72.0;
const MR: f64 = 16.0;
const MT: f64 = 34.0;
const MB: f64 = 46.0;
const TOP: f64 = 70.0;

/// `&`, `<` and `>` escaped for SVG text.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Whether `v` can be drawn on an axis of `scale`.
fn drawable(v: f64, scale: Scale) -> bool {
    v.is_finite() && (scale == Scale::Linear || v > 0.0)
}

/// An axis' range in axis units (values, or log10 of values) and its ticks (axis unit,
/// label).
struct Axis {
    scale: Scale,
    lo: f64,
    hi: f64,
    ticks: Vec<(f64, String)>,
}

impl Axis {
    /// The axis over `values`; `pad` widens a linear range by that share on each side.
    fn over(values: impl Iterator<Item = f64>, scale: Scale, pad: f64) -> Axis {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values.filter(|&v| drawable(v, scale)) {
            let u = if scale == Scale::Log { v.log10() } else { v };
            lo = lo.min(u);
            hi = hi.max(u);
        }
        if !lo.is_finite() {
            (lo, hi) = (0.0, 1.0);
        }
        match scale {
            Scale::Log => {
                let (lo, hi) = (lo.floor(), hi.ceil().max(lo.floor() + 1.0));
                let ticks = (0..=(hi - lo) as i64)
                    .map(|k| (lo + k as f64, format!("1e{:.0}", lo + k as f64)))
                    .collect();
                Axis {
                    scale,
                    lo,
                    hi,
                    ticks,
                }
            }
            Scale::Linear => {
                let span = (hi - lo).max(1e-300);
                let (lo, hi) = (lo - pad * span, hi + pad * span);
                Axis {
                    scale,
                    lo,
                    hi,
                    ticks: linear_ticks(lo, hi),
                }
            }
        }
    }

    /// Where `v` lies on the axis, 0 at its low end and 1 at its high end.
    fn at(&self, v: f64) -> f64 {
        let u = if self.scale == Scale::Log {
            v.log10()
        } else {
            v
        };
        (u - self.lo) / (self.hi - self.lo).max(1e-300)
    }
}

/// Ticks at 1, 2 or 5 times a power of ten, about five over `lo..hi`, labelled with the
/// digits the step needs.
fn linear_ticks(lo: f64, hi: f64) -> Vec<(f64, String)> {
    let span = (hi - lo).max(1e-300);
    let raw = span / 5.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    let mut out = Vec::new();
    let mut k = (lo / step).ceil();
    while k * step <= hi + 1e-9 * span {
        let t = if (k * step).abs() < 1e-12 * span {
            0.0
        } else {
            k * step
        };
        let label = if decimals > 6 {
            format!("{t:.1e}")
        } else {
            format!("{t:.decimals$}")
        };
        out.push((t, label));
        k += 1.0;
    }
    out
}

/// The chart as SVG text: `title` on top, the legend under it, then the panels in rows
/// of `columns`, each panel's plotting area `size` (width, height) in pixels.
pub fn svg(title: &str, panels: &[Panel], columns: usize, size: (f64, f64)) -> String {
    let columns = columns.max(1);
    let (pw, ph) = size;
    let (cell_w, cell_h) = (ML + pw + MR, MT + ph + MB);
    let rows = panels.len().div_ceil(columns);
    let w = columns.min(panels.len().max(1)) as f64 * cell_w + 10.0;
    let h = rows as f64 * cell_h + TOP;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" font-family="sans-serif" font-size="11">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{:.0}" y="22" font-size="15" text-anchor="middle">{}</text>"#,
        w / 2.0,
        esc(title)
    );
    legend(&mut s, panels);
    for (k, p) in panels.iter().enumerate() {
        let ox = 5.0 + (k % columns) as f64 * cell_w + ML;
        let oy = TOP + (k / columns) as f64 * cell_h + MT;
        panel(&mut s, p, ox, oy, pw, ph);
    }
    s.push_str("</svg>\n");
    s
}

/// Every curve label once, in first-seen order, in one row under the title.
fn legend(s: &mut String, panels: &[Panel]) {
    let mut seen: Vec<&Curve> = Vec::new();
    for c in panels.iter().flat_map(|p| &p.curves) {
        if !seen.iter().any(|d| d.label == c.label) {
            seen.push(c);
        }
    }
    let mut lx = 20.0;
    for c in seen {
        let color = &c.color;
        if c.style == Style::Markers {
            let _ = writeln!(
                s,
                r#"<rect x="{:.1}" y="36" width="9" height="9" fill="{color}"/>"#,
                lx + 6.0
            );
        } else {
            let _ = writeln!(
                s,
                r#"<line x1="{lx:.1}" y1="40" x2="{:.1}" y2="40" stroke="{color}" stroke-width="2.5"{}/>"#,
                lx + 22.0,
                dash(c.style)
            );
        }
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="44">{}</text>"#,
            lx + 27.0,
            esc(&c.label)
        );
        lx += 40.0 + 6.5 * c.label.len() as f64;
    }
}

/// The dash attribute of a style.
fn dash(style: Style) -> &'static str {
    if style == Style::Dashed {
        r#" stroke-dasharray="6 4""#
    } else {
        ""
    }
}

/// One panel with its plotting area at (ox, oy), `pw` x `ph` pixels.
fn panel(s: &mut String, p: &Panel, ox: f64, oy: f64, pw: f64, ph: f64) {
    // The axes span the points that can be drawn on both.
    let all = || {
        p.curves
            .iter()
            .flat_map(|c| c.points.iter())
            .filter(|q| drawable(q.0, p.x) && drawable(q.1, p.y))
    };
    let ax = Axis::over(all().map(|q| q.0), p.x, 0.0);
    let ay = Axis::over(all().map(|q| q.1), p.y, 0.05);
    let px = |x: f64| ox + ax.at(x) * pw;
    let py = |y: f64| oy + ph - ay.at(y) * ph;
    let _ = writeln!(
        s,
        r##"<rect x="{ox:.1}" y="{oy:.1}" width="{pw}" height="{ph}" fill="none" stroke="#444"/>"##
    );
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" font-size="13" text-anchor="middle">{}</text>"#,
        ox + pw / 2.0,
        oy - 10.0,
        esc(&p.title)
    );
    for (t, label) in &ax.ticks {
        let x = ox + (t - ax.lo) / (ax.hi - ax.lo) * pw;
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{oy:.1}" x2="{x:.1}" y2="{:.1}" stroke="#ddd"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{label}</text>"##,
            oy + ph,
            oy + ph + 14.0
        );
    }
    for (t, label) in &ay.ticks {
        let y = oy + ph - (t - ay.lo) / (ay.hi - ay.lo) * ph;
        let _ = writeln!(
            s,
            r##"<line x1="{ox:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#ddd"/><text x="{:.1}" y="{:.1}" text-anchor="end">{label}</text>"##,
            ox + pw,
            ox - 4.0,
            y + 4.0
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
        ox + pw / 2.0,
        oy + ph + 32.0,
        esc(&p.x_label)
    );
    let _ = writeln!(
        s,
        r#"<text transform="translate({:.1},{:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
        ox - 56.0,
        oy + ph / 2.0,
        esc(&p.y_label)
    );
    for c in &p.curves {
        let pts: Vec<(f64, f64)> = c
            .points
            .iter()
            .filter(|q| drawable(q.0, p.x) && drawable(q.1, p.y))
            .map(|&(x, y)| (px(x), py(y)))
            .collect();
        if c.style != Style::Markers && pts.len() > 1 {
            let path: Vec<String> = pts.iter().map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
            let _ = writeln!(
                s,
                r#"<polyline points="{}" fill="none" stroke="{}" stroke-width="1.8"{}/>"#,
                path.join(" "),
                c.color,
                dash(c.style)
            );
        }
        for (x, y) in pts {
            match c.style {
                Style::Markers => {
                    let _ = writeln!(
                        s,
                        r#"<rect x="{:.1}" y="{:.1}" width="9" height="9" fill="{}"/>"#,
                        x - 4.5,
                        y - 4.5,
                        c.color
                    );
                }
                Style::LinePoints => {
                    let _ = writeln!(
                        s,
                        r#"<circle cx="{x:.1}" cy="{y:.1}" r="2.8" fill="{}"/>"#,
                        c.color
                    );
                }
                Style::Line | Style::Dashed => {}
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(points: Vec<(f64, f64)>, style: Style) -> Curve {
        Curve {
            label: "c".into(),
            color: "red".into(),
            points,
            style,
        }
    }

    /// Linear ticks: 1-2-5 steps inside the range, exact multiples, labelled with the
    /// step's digits.
    #[test]
    fn linear_ticks_are_round_multiples_inside_the_range() {
        let t = linear_ticks(-0.3e-3, 2.9e-3);
        let labels: Vec<&str> = t.iter().map(|(_, l)| l.as_str()).collect();
        assert_eq!(labels, ["0.000", "0.001", "0.002"]);
        let t = linear_ticks(0.0, 400.0);
        assert_eq!(t.first().unwrap().0, 0.0);
        assert_eq!(t.last().unwrap().0, 400.0);
        assert_eq!(t[1].1, "100");
    }

    /// A point at the low end of an axis lands on the panel's left or bottom edge, one
    /// at the high end of a log axis on the decade that bounds it.
    #[test]
    fn points_map_to_the_panel_edges() {
        let p = Panel {
            title: "p".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            x: Scale::Log,
            y: Scale::Log,
            curves: vec![curve(
                vec![(1e-3, 1e-6), (1e1, 1e-2), (-1.0, 1.0)],
                Style::LinePoints,
            )],
        };
        let text = svg("t", &[p.clone(), p], 2, (200.0, 100.0));
        // Two panels side by side: the first plotting area starts at 5 + ML.
        let x0 = 5.0 + ML;
        assert!(text.contains(&format!(
            r#"<circle cx="{x0:.1}" cy="{:.1}""#,
            TOP + MT + 100.0
        )));
        // 1e1 is the top decade of x: the right edge; 1e-2 the top decade of y.
        assert!(text.contains(&format!(
            r#"<circle cx="{:.1}" cy="{:.1}""#,
            x0 + 200.0,
            TOP + MT
        )));
        // The point at x = -1 cannot be drawn on a log axis: two circles per panel.
        assert_eq!(text.matches("<circle").count(), 4);
        // The decades 1e1 (x only) and 1e-6 (y only) are labelled once per panel.
        assert_eq!(text.matches(">1e1</text>").count(), 2);
        assert_eq!(text.matches(">1e-6</text>").count(), 2);
    }
}
