//! The documentation page's pictures: the body's nodes (exposed ones marked and labelled)
//! and its first local modes' shapes, as small inline SVG drawings, so a user sees which
//! node is which. Written here rather than with the workspace's chart crate so that the
//! FMU library gains no dependency: a few lines of SVG text.
//!
//! The drawing plane is the pair of global axes along which the drawn points spread the
//! most (the undeformed nodes, and the mode shapes' displacements for a body whose
//! nodes all lie on one point).

use std::fmt::Write;

use crate::scene::Scene;

/// Drawing size in pixels, and the margin kept free for labels.
const SIZE: f64 = 260.0;
const MARGIN: f64 = 28.0;
/// How many modes are drawn.
pub const MODES_DRAWN: usize = 3;

/// The nodes drawn: every node for a free body (its rigid modes place them, L0 put where
/// the exposed nodes say), the exposed nodes only for a blocked body (the FMU knows no
/// other coordinates). Returns (node index, global position).
pub fn drawn_nodes(scene: &Scene) -> Vec<(usize, [f64; 3])> {
    let b = &scene.body;
    if let (Some(rel), Some(&n0)) = (b.rigid_mode_positions(), scene.nodes.first()) {
        let shift: [f64; 3] = std::array::from_fn(|c| scene.x0[0][c] - rel[n0][c]);
        return rel
            .iter()
            .enumerate()
            .map(|(n, p)| (n, std::array::from_fn(|c| p[c] + shift[c])))
            .collect();
    }
    scene
        .nodes
        .iter()
        .copied()
        .zip(scene.x0.iter().copied())
        .collect()
}

/// Global translation of node `n` in local mode `j` (mass-normalised mode of the kept
/// basis), `P0 Phi_L(n) psi_j`.
pub fn mode_translation(scene: &Scene, n: usize, j: usize) -> [f64; 3] {
    let b = &scene.body;
    let modal = &b.modal;
    let col = modal.ascending[j];
    let local: Vec<f64> = (0..3)
        .map(|c| {
            (0..b.nl())
                .map(|i| b.phi_l[(6 * n + c, i)] * modal.shapes[(i, col)])
                .sum()
        })
        .collect();
    std::array::from_fn(|r| (0..3).map(|c| b.p0[(r, c)] * local[c]).sum())
}

/// The two axes of largest spread among `points` (ties keep the lower axis).
fn plane(points: &[[f64; 3]]) -> (usize, usize) {
    let spread = |c: usize| {
        let (lo, hi) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[c]), hi.max(p[c]))
            });
        if hi > lo { hi - lo } else { 0.0 }
    };
    let mut axes = [0, 1, 2];
    axes.sort_by(|&a, &b| spread(b).total_cmp(&spread(a)).then(a.cmp(&b)));
    let (a, b) = (axes[0].min(axes[1]), axes[0].max(axes[1]));
    (a, b)
}

/// One drawing: `base` points (grey), `moved` points (the shape, drawn over them when
/// given), and labels on the `labelled` ones.
struct Drawing<'a> {
    title: String,
    base: &'a [[f64; 3]],
    moved: Option<Vec<[f64; 3]>>,
    labelled: &'a [(usize, String)],
}

fn svg(d: &Drawing, (a, b): (usize, usize)) -> String {
    let all: Vec<&[f64; 3]> = d.base.iter().chain(d.moved.iter().flatten()).collect();
    let lo = |c: usize| all.iter().map(|p| p[c]).fold(f64::INFINITY, f64::min);
    let hi = |c: usize| all.iter().map(|p| p[c]).fold(f64::NEG_INFINITY, f64::max);
    let span = (hi(a) - lo(a)).max(hi(b) - lo(b));
    let scale = if span > 0.0 {
        (SIZE - 2.0 * MARGIN) / span
    } else {
        1.0
    };
    let (ca, cb) = ((lo(a) + hi(a)) / 2.0, (lo(b) + hi(b)) / 2.0);
    let xy = |p: &[f64; 3]| {
        (
            SIZE / 2.0 + (p[a] - ca) * scale,
            SIZE / 2.0 - (p[b] - cb) * scale,
        )
    };
    let axis = |c: usize| ["x", "y", "z"][c];
    let mut s = String::new();
    let _ = write!(
        s,
        "<figure style=\"display:inline-block;margin:4px\"><svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{SIZE}\" height=\"{SIZE}\" viewBox=\"0 0 {SIZE} {SIZE}\"><rect width=\"{SIZE}\" height=\"{SIZE}\" fill=\"white\" stroke=\"#ccc\"/>"
    );
    let dot = |s: &mut String, p: &[f64; 3], r: f64, fill: &str| {
        let (x, y) = xy(p);
        let _ = write!(
            s,
            "<circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"{r}\" fill=\"{fill}\"/>"
        );
    };
    let base_fill = if d.moved.is_some() { "#bbb" } else { "#36c" };
    for p in d.base {
        dot(&mut s, p, 2.0, base_fill);
    }
    if let Some(moved) = &d.moved {
        for (p, q) in d.base.iter().zip(moved) {
            let ((x0, y0), (x1, y1)) = (xy(p), xy(q));
            let _ = write!(
                s,
                "<line x1=\"{x0:.1}\" y1=\"{y0:.1}\" x2=\"{x1:.1}\" y2=\"{y1:.1}\" stroke=\"#e88\"/>"
            );
            dot(&mut s, q, 2.0, "#c33");
        }
    }
    let shown = d.moved.as_deref().unwrap_or(d.base);
    for (i, label) in d.labelled {
        let p = &shown[*i];
        let (x, y) = xy(p);
        let _ = write!(
            s,
            "<circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"4.5\" fill=\"none\" stroke=\"black\"/><text x=\"{:.1}\" y=\"{:.1}\" font-size=\"10\" font-family=\"sans-serif\">{label}</text>",
            x + 5.0,
            y - 5.0
        );
    }
    let _ = write!(
        s,
        "<text x=\"4\" y=\"{}\" font-size=\"10\" font-family=\"sans-serif\">{} right, {} up</text></svg><figcaption>{}</figcaption></figure>",
        SIZE - 4.0,
        axis(a),
        axis(b),
        d.title
    );
    s
}

/// The pictures section: the nodes, then the first [`MODES_DRAWN`] kept modes (each
/// scaled so that its largest drawn displacement is a fifth of the body's size).
pub fn section(scene: &Scene, frequencies_hz: &[f64]) -> String {
    let nodes = drawn_nodes(scene);
    let base: Vec<[f64; 3]> = nodes.iter().map(|(_, p)| *p).collect();
    let labelled: Vec<(usize, String)> = nodes
        .iter()
        .enumerate()
        .filter(|(_, (n, _))| scene.nodes.contains(n))
        .map(|(i, (n, _))| (i, format!("node {}", scene.body.node_ids[*n])))
        .collect();
    let modes = MODES_DRAWN.min(scene.body.nl());
    let shapes: Vec<Vec<[f64; 3]>> = (0..modes)
        .map(|j| {
            nodes
                .iter()
                .map(|(n, _)| mode_translation(scene, *n, j))
                .collect()
        })
        .collect();
    let extent = |pts: &[[f64; 3]]| {
        (0..3)
            .map(|c| {
                let v = pts.iter().map(|p| p[c]);
                v.clone().fold(f64::NEG_INFINITY, f64::max) - v.fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max)
    };
    let size = extent(&base);
    let mut points = base.clone();
    for u in &shapes {
        points.extend(u.iter().map(|d| {
            let m = d.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            if m > 0.0 { d.map(|x| x / m) } else { *d }
        }));
    }
    let axes = plane(&points);
    let mut h = String::from(
        "<h2>Nodes and mode shapes</h2>\n<p>Exposed nodes are circled and labelled; mode shapes in red over the undeformed nodes in grey, each scaled to a fifth of the body's size (of the drawn nodes' largest displacement, for one node).</p>\n<div>",
    );
    h.push_str(&svg(
        &Drawing {
            title: format!("{} nodes drawn, {} exposed", base.len(), labelled.len()),
            base: &base,
            moved: None,
            labelled: &labelled,
        },
        axes,
    ));
    for (j, u) in shapes.iter().enumerate() {
        let m = u.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
        let target = if size > 0.0 { size / 5.0 } else { 1.0 };
        let k = if m > 0.0 { target / m } else { 0.0 };
        let moved = base
            .iter()
            .zip(u)
            .map(|(p, d)| std::array::from_fn(|c| p[c] + k * d[c]))
            .collect();
        h.push_str(&svg(
            &Drawing {
                title: format!(
                    "mode {} ({:.6} Hz)",
                    j + 1,
                    frequencies_hz.get(j).copied().unwrap_or(f64::NAN)
                ),
                base: &base,
                moved: Some(moved),
                labelled: &labelled,
            },
            axes,
        ));
    }
    h.push_str("</div>\n");
    h
}
