//! The study chart: one log-log panel per scene, error against CPU time per simulated
//! second, one polyline per method (points in order of communication step) and single
//! markers for the peers. Plain SVG written by hand.

use std::fmt::Write;

/// One curve or marker set of a panel.
pub struct Curve {
    /// Legend text.
    pub label: String,
    /// Stroke colour.
    pub color: String,
    /// (cpu s per simulated s, relative error) points, in drawing order.
    pub points: Vec<(f64, f64)>,
    /// Draw markers only (peers), not a line.
    pub markers_only: bool,
}

/// One panel.
pub struct Panel {
    /// Title.
    pub title: String,
    /// Curves.
    pub curves: Vec<Curve>,
}

const PW: f64 = 360.0;
const PH: f64 = 260.0;
const ML: f64 = 62.0;
const MT: f64 = 34.0;
const MB: f64 = 44.0;
const MR: f64 = 14.0;
const COLS: usize = 3;

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Decade bounds enclosing the positive finite values.
fn decades(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in v.filter(|x| x.is_finite() && *x > 0.0) {
        lo = lo.min(x.log10());
        hi = hi.max(x.log10());
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let (lo, hi) = (lo.floor(), hi.ceil());
    if hi <= lo { (lo, lo + 1.0) } else { (lo, hi) }
}

/// The whole chart as SVG text.
pub fn svg(panels: &[Panel], title: &str) -> String {
    let rows = panels.len().div_ceil(COLS);
    let cell_w = ML + PW + MR;
    let cell_h = MT + PH + MB;
    let legend_h = 30.0;
    let w = COLS as f64 * cell_w + 10.0;
    let h = rows as f64 * cell_h + 40.0 + legend_h;
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
    // Legend: every label once, in first-seen order.
    let mut seen: Vec<(String, String, bool)> = Vec::new();
    for c in panels.iter().flat_map(|p| &p.curves) {
        if !seen.iter().any(|(l, _, _)| *l == c.label) {
            seen.push((c.label.clone(), c.color.clone(), c.markers_only));
        }
    }
    let mut lx = 20.0;
    for (label, color, markers) in &seen {
        if *markers {
            let _ = writeln!(
                s,
                r#"<rect x="{:.1}" y="34" width="9" height="9" fill="{color}"/>"#,
                lx + 6.0
            );
        } else {
            let _ = writeln!(
                s,
                r#"<line x1="{lx:.1}" y1="38" x2="{:.1}" y2="38" stroke="{color}" stroke-width="2.5"/>"#,
                lx + 22.0
            );
        }
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="42">{}</text>"#,
            lx + 27.0,
            esc(label)
        );
        lx += 40.0 + 6.5 * label.len() as f64;
    }
    for (k, p) in panels.iter().enumerate() {
        let ox = 5.0 + (k % COLS) as f64 * cell_w + ML;
        let oy = 40.0 + legend_h + (k / COLS) as f64 * cell_h + MT;
        let all = || p.curves.iter().flat_map(|c| c.points.iter());
        let (x0, x1) = decades(all().map(|q| q.0));
        let (y0, y1) = decades(all().map(|q| q.1));
        let px = |x: f64| ox + (x.log10() - x0) / (x1 - x0) * PW;
        let py = |y: f64| oy + PH - (y.log10() - y0) / (y1 - y0) * PH;
        let _ = writeln!(
            s,
            r##"<rect x="{ox:.1}" y="{oy:.1}" width="{PW}" height="{PH}" fill="none" stroke="#444"/>"##
        );
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" font-size="13" text-anchor="middle">{}</text>"#,
            ox + PW / 2.0,
            oy - 10.0,
            esc(&p.title)
        );
        let mut d = x0;
        while d <= x1 + 1e-9 {
            let x = ox + (d - x0) / (x1 - x0) * PW;
            let _ = writeln!(
                s,
                r##"<line x1="{x:.1}" y1="{oy:.1}" x2="{x:.1}" y2="{:.1}" stroke="#ddd"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">1e{d:.0}</text>"##,
                oy + PH,
                oy + PH + 14.0
            );
            d += 1.0;
        }
        let mut d = y0;
        while d <= y1 + 1e-9 {
            let y = oy + PH - (d - y0) / (y1 - y0) * PH;
            let _ = writeln!(
                s,
                r##"<line x1="{ox:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#ddd"/><text x="{:.1}" y="{:.1}" text-anchor="end">1e{d:.0}</text>"##,
                ox + PW,
                ox - 4.0,
                y + 4.0
            );
            d += 1.0;
        }
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">CPU s per simulated s</text>"#,
            ox + PW / 2.0,
            oy + PH + 32.0
        );
        let _ = writeln!(
            s,
            r#"<text transform="translate({:.1},{:.1}) rotate(-90)" text-anchor="middle">max error / peak</text>"#,
            ox - 46.0,
            oy + PH / 2.0
        );
        for c in &p.curves {
            let pts: Vec<(f64, f64)> = c
                .points
                .iter()
                .filter(|q| q.0 > 0.0 && q.1 > 0.0 && q.0.is_finite() && q.1.is_finite())
                .map(|&(x, y)| (px(x), py(y)))
                .collect();
            if !c.markers_only && pts.len() > 1 {
                let path: Vec<String> = pts.iter().map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
                let _ = writeln!(
                    s,
                    r#"<polyline points="{}" fill="none" stroke="{}" stroke-width="2"/>"#,
                    path.join(" "),
                    c.color
                );
            }
            for (x, y) in pts {
                if c.markers_only {
                    let _ = writeln!(
                        s,
                        r#"<rect x="{:.1}" y="{:.1}" width="9" height="9" fill="{}"/>"#,
                        x - 4.5,
                        y - 4.5,
                        c.color
                    );
                } else {
                    let _ = writeln!(
                        s,
                        r#"<circle cx="{x:.1}" cy="{y:.1}" r="2.8" fill="{}"/>"#,
                        c.color
                    );
                }
            }
        }
    }
    s.push_str("</svg>\n");
    s
}
