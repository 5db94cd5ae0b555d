//! A small SVG line chart: axes with labelled ticks and one polyline per series.

use std::fmt::Write;

/// One curve.
pub struct Series<'a> {
    /// Legend text.
    pub label: &'a str,
    /// x values.
    pub x: &'a [f64],
    /// y values.
    pub y: &'a [f64],
    /// Stroke colour.
    pub color: &'a str,
    /// Dashed line.
    pub dashed: bool,
}

fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = (hi - lo).max(1e-300);
    let raw = span / 5.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let mut t = (lo / step).ceil() * step;
    let mut out = Vec::new();
    while t <= hi + 1e-9 * span {
        out.push(if t.abs() < 1e-12 * span { 0.0 } else { t });
        t += step;
    }
    out
}

/// The SVG text of a chart.
pub fn chart(title: &str, xlabel: &str, ylabel: &str, series: &[Series]) -> String {
    let (w, h, ml, mr, mt, mb) = (800.0, 450.0, 90.0, 20.0, 40.0, 60.0);
    let range = |vals: Vec<f64>| {
        vals.into_iter()
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            })
    };
    let (x0, x1) = range(series.iter().flat_map(|s| s.x.iter().copied()).collect());
    let (mut y0, mut y1) = range(series.iter().flat_map(|s| s.y.iter().copied()).collect());
    let pad = 0.05 * (y1 - y0).max(1e-300);
    y0 -= pad;
    y1 += pad;
    let px = |x: f64| ml + (x - x0) / (x1 - x0).max(1e-300) * (w - ml - mr);
    let py = |y: f64| h - mb - (y - y0) / (y1 - y0) * (h - mt - mb);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\">"
    );
    let _ = writeln!(s, "<rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>");
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">{title}</text>",
        w / 2.0
    );
    for t in ticks(x0, x1) {
        let x = px(t);
        let _ = writeln!(
            s,
            "<line x1=\"{x:.1}\" y1=\"{}\" x2=\"{x:.1}\" y2=\"{mt}\" stroke=\"#ddd\"/><text x=\"{x:.1}\" y=\"{}\" text-anchor=\"middle\">{t}</text>",
            h - mb,
            h - mb + 16.0
        );
    }
    for t in ticks(y0, y1) {
        let y = py(t);
        let _ = writeln!(
            s,
            "<line x1=\"{ml}\" y1=\"{y:.1}\" x2=\"{}\" y2=\"{y:.1}\" stroke=\"#ddd\"/><text x=\"{}\" y=\"{:.1}\" text-anchor=\"end\">{t:.3e}</text>",
            w - mr,
            ml - 6.0,
            y + 4.0
        );
    }
    let _ = writeln!(
        s,
        "<rect x=\"{ml}\" y=\"{mt}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"black\"/>",
        w - ml - mr,
        h - mt - mb
    );
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{xlabel}</text>",
        (ml + w - mr) / 2.0,
        h - 15.0
    );
    let _ = writeln!(
        s,
        "<text x=\"18\" y=\"{}\" text-anchor=\"middle\" transform=\"rotate(-90 18 {})\">{ylabel}</text>",
        (mt + h - mb) / 2.0,
        (mt + h - mb) / 2.0
    );
    for (k, ser) in series.iter().enumerate() {
        let mut pts = String::new();
        for (&x, &y) in ser.x.iter().zip(ser.y) {
            if x.is_finite() && y.is_finite() {
                let _ = write!(pts, "{:.2},{:.2} ", px(x), py(y));
            }
        }
        let dash = if ser.dashed {
            " stroke-dasharray=\"6 4\""
        } else {
            ""
        };
        let _ = writeln!(
            s,
            "<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"1.5\"{dash} points=\"{}\"/>",
            ser.color,
            pts.trim_end()
        );
        let ly = mt + 18.0 + 18.0 * k as f64;
        let _ = writeln!(
            s,
            "<line x1=\"{}\" y1=\"{ly}\" x2=\"{}\" y2=\"{ly}\" stroke=\"{}\" stroke-width=\"2\"{dash}/><text x=\"{}\" y=\"{}\">{}</text>",
            w - mr - 230.0,
            w - mr - 200.0,
            ser.color,
            w - mr - 195.0,
            ly + 4.0,
            ser.label
        );
    }
    s.push_str("</svg>\n");
    s
}
