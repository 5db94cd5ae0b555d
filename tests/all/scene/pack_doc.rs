//! The documentation page inside the FMU (documentation/index.html) tells what the model
//! description declares (issue 15 item 5): the kept modes and the residual correction
//! (the description attribute) and the outputs that depend on same-instant inputs (the
//! ModelStructure), parsed from both and compared; `--fmax` below the first mode warns
//! (no mode kept), above every mode keeps them all and declares no correction.

use std::collections::BTreeMap;

use crate::common::root;
use fxbody::body::load as load_body;
use fxbody::fmu::doc::index_html;
use fxbody::fmu::pack::{Fmax, PackNote, PackOptions, PackRequest, Prepared, prepare};

fn pack(fmax: Option<f64>) -> Prepared {
    let req = PackRequest {
        body: root().join("fixtures/cantilever.fxb"),
        coords: Some(root().join("fixtures/cantilever.nodes.rad")),
        nodes: Some(vec![121, 111]),
        ..PackRequest::default()
    };
    prepare(
        &req,
        &PackOptions {
            fmax: fmax.map(Fmax::Hz),
            ..PackOptions::default()
        },
        None,
    )
    .unwrap()
}

/// Text between `start` and the next `end` after it.
fn between<'a>(s: &'a str, start: &str, end: &str) -> &'a str {
    let a = s.find(start).unwrap_or_else(|| panic!("no {start}")) + start.len();
    &s[a..a + s[a..].find(end).unwrap()]
}

/// Output name -> input names it depends on at the same instant, from the XML's
/// ModelStructure/Outputs (indices are 1-based positions in ModelVariables).
fn xml_dependencies(xml: &str) -> BTreeMap<String, Vec<String>> {
    let names: Vec<&str> = xml
        .split("<ScalarVariable name=\"")
        .skip(1)
        .map(|s| s.split('"').next().unwrap())
        .collect();
    let outputs = between(xml, "<Outputs>", "</Outputs>");
    let mut map = BTreeMap::new();
    for u in outputs.split("<Unknown ").skip(1) {
        let index: usize = between(u, "index=\"", "\"").parse().unwrap();
        let deps: Vec<String> = between(u, "dependencies=\"", "\"")
            .split_whitespace()
            .map(|d| names[d.parse::<usize>().unwrap() - 1].to_string())
            .collect();
        if !deps.is_empty() {
            map.insert(names[index - 1].to_string(), deps);
        }
    }
    map
}

/// The same from the documentation page's table (empty when it says there is none).
fn doc_dependencies(html: &str) -> BTreeMap<String, Vec<String>> {
    let mut map = BTreeMap::new();
    if html.contains("Outputs do not depend on same-instant inputs.") {
        return map;
    }
    let table = between(
        html,
        "<h2>Outputs that depend on same-instant inputs</h2>",
        "</table>",
    );
    for row in table.split("<tr><td>").skip(1) {
        let out = row.split("</td>").next().unwrap();
        let deps = between(row, "<td>", "</td>");
        map.insert(
            out.to_string(),
            deps.split_whitespace().map(str::to_string).collect(),
        );
    }
    map
}

fn check_page_agrees(p: &Prepared) -> (String, BTreeMap<String, Vec<String>>) {
    let html = index_html(&p.scene, &p.table, &p.options, &p.guid);
    let summary = between(&p.xml, "(blocked, 21 nodes, ", ", 2 exposed nodes)").to_string();
    assert!(html.contains(&format!("{summary} (")), "{summary}\n{html}");
    let deps = xml_dependencies(&p.xml);
    assert_eq!(doc_dependencies(&html), deps);
    // The kept modes' frequencies: as many as the description says.
    let kept: usize = summary.split(' ').next().unwrap().parse().unwrap();
    let freqs = between(&html, "(Hz)</h2>\n<p>", "</p>");
    assert_eq!(freqs.split(", ").filter(|f| !f.is_empty()).count(), kept);
    // Issue 15: "fxbody 0.1.0.GUID" ran the version into the GUID.
    assert!(html.contains(&format!(
        "packed by fxbody {} (GUID {}).",
        env!("CARGO_PKG_VERSION"),
        p.guid
    )));
    (summary, deps)
}

#[test]
fn the_page_lists_modes_correction_and_dependencies_as_the_description() {
    let f1 = load_body(&root().join("fixtures/cantilever.fxb"), Default::default())
        .unwrap()
        .frequencies_hz()[0];
    // Untruncated: 20 modes, no correction, no dependency.
    let (summary, deps) = check_page_agrees(&pack(None));
    assert_eq!(summary, "20 local modes, no residual correction");
    assert!(deps.is_empty());
    // Truncated between modes 2 and 3 (the issue's case: the page said "Outputs do not
    // depend" while the description declared they do).
    let p = pack(Some(2.5 * f1));
    let (summary, deps) = check_page_agrees(&p);
    assert!(
        summary.contains("kept, residual correction of"),
        "{summary}"
    );
    // Positions, rotations of both nodes and the strain energy, each on all 12 loads.
    assert_eq!(deps.len(), 2 * 3 + 2 * 3 + 1, "{deps:?}");
    assert!(deps.contains_key("node_121.rz") && deps.contains_key("energy.strain"));
    assert!(deps.values().all(|d| d.len() == 12));
}

#[test]
fn fmax_below_the_first_mode_warns_and_above_every_mode_keeps_all() {
    let body = load_body(&root().join("fixtures/cantilever.fxb"), Default::default()).unwrap();
    let (f1, top) = (
        body.frequencies_hz()[0],
        *body.frequencies_hz().last().unwrap(),
    );
    let low = pack(Some(0.5 * f1));
    assert_eq!(low.scene.body.nl(), 0);
    assert!(
        low.notes.contains(&PackNote::FmaxBelowFirstMode {
            fmax: 0.5 * f1,
            first: f1
        }),
        "{:?}",
        low.notes
    );
    let (summary, _) = check_page_agrees(&low);
    assert_eq!(
        summary,
        "0 local modes kept, residual correction of 20 dropped modes"
    );
    let high = pack(Some(2.0 * top));
    assert_eq!(high.scene.body.nl(), 20);
    assert!(high.scene.residual.is_none());
    assert!(
        high.notes.contains(&PackNote::FmaxKeepsAll {
            fmax: 2.0 * top,
            kept: 20
        }) && !high.notes.iter().any(PackNote::is_warning),
        "{:?}",
        high.notes
    );
    let (summary, deps) = check_page_agrees(&high);
    assert_eq!(summary, "20 local modes, no residual correction");
    assert!(deps.is_empty());
}

/// The numbers after `key` up to the next `end`, split on non-number characters.
fn numbers_after(s: &str, key: &str, end: &str) -> Vec<f64> {
    between(s, key, end)
        .split(|c: char| !(c.is_ascii_digit() || "+-.e".contains(c)))
        .filter_map(|t| t.parse().ok())
        .collect()
}

/// Issue 25.5: with `--fmax` the page shows the file's stored Freq (read here from the
/// file by the reader, 4137 Hz) beside the kept modes' highest (the first mode's, 10.03
/// Hz, from the eigenvalues of the full body); the picture circles and labels every
/// exposed node and draws the first kept modes, captioned with their frequencies.
#[test]
fn the_page_shows_the_stored_freq_and_draws_the_nodes_and_modes() {
    let full = load_body(&root().join("fixtures/cantilever.fxb"), Default::default()).unwrap();
    let first = full.frequencies_hz()[0];
    let p = pack(Some(1.5 * first));
    let html = index_html(&p.scene, &p.table, &p.options, &p.guid);
    let figures = numbers_after(
        &html,
        "largest computed eigenfrequency of the kept modes, ",
        " s</li>",
    );
    println!(
        "stable-step line: {figures:?}, file Freq {}, first mode {first}",
        full.freq_file()
    );
    assert!((figures[0] / first - 1.0).abs() < 1e-6, "{figures:?}");
    assert!(
        (figures[1] / full.freq_file() - 1.0).abs() < 1e-6,
        "{figures:?}"
    );
    assert!(full.freq_file() > 4000.0);
    // The picture: one drawing of the nodes and one per kept mode (one here), both
    // exposed nodes circled and labelled in each.
    let svgs = html.matches("<svg ").count();
    assert_eq!(svgs, 2, "{html}");
    assert_eq!(html.matches("r=\"4.5\"").count(), 2 * 2);
    for id in [111, 121] {
        assert_eq!(html.matches(&format!(">node {id}</text>")).count(), svgs);
    }
    let caption = numbers_after(&html, "<figcaption>mode 1 (", " Hz)");
    assert!((caption[0] / first - 1.0).abs() < 1e-6);
    // Untruncated: the first three of the ten modes drawn.
    let untruncated = pack(None);
    let page = index_html(
        &untruncated.scene,
        &untruncated.table,
        &untruncated.options,
        &untruncated.guid,
    );
    assert_eq!(
        page.matches("<svg ").count(),
        1 + fxbody::fmu::doc::picture::MODES_DRAWN
    );
}

/// Issue 25.5: a free body's page gives its mass, centre of mass and inertia, checked
/// against the fixture's own reference (fixtures/freefree.ref.json: mass 0.7536 kg, L0
/// at the centre of mass) and beam theory (a 1 m beam along the local X axis: m L^2/12
/// about the transverse axes within 1%, the lumped end nodes' share; next to nothing about
/// the axis), names the point v0 and w0 refer to, and draws every node of the body.
#[test]
fn a_free_body_page_gives_mass_centre_inertia_and_the_reference_point() {
    let req = PackRequest {
        body: root().join("fixtures/freefree.fxb"),
        nodes: Some(vec![521, 511]),
        ..PackRequest::default()
    };
    let p = prepare(&req, &PackOptions::default(), None).unwrap();
    let html = index_html(&p.scene, &p.table, &p.options, &p.guid);
    let text = std::fs::read_to_string(root().join("fixtures/freefree.ref.json")).unwrap();
    let reference: serde_json::Value = serde_json::from_str(&text).unwrap();
    let mass = reference["total_mass"].as_f64().unwrap();
    let m = numbers_after(&html, "<li>Mass: ", "</li>");
    assert!((m[0] / mass - 1.0).abs() < 1e-6, "{m:?} vs {mass}");
    let c = numbers_after(
        &html,
        "Centre of mass, from the frame origin L0 (global axes at the start): ",
        "</li>",
    );
    assert_eq!(c.len(), 3);
    assert!(c.iter().all(|x| x.abs() < 1e-9), "{c:?}");
    let i = numbers_after(
        &html,
        "Inertia at the centre of mass (global axes at the start): ",
        "</li>",
    );
    assert_eq!(i.len(), 9);
    let inertia = nalgebra::Matrix3::from_row_slice(&i);
    let p0 = &reference["frame"]["P0"];
    let axis = nalgebra::Vector3::from_fn(|r, _| p0[r][0].as_f64().unwrap());
    let across = nalgebra::Vector3::from_fn(|r, _| p0[r][1].as_f64().unwrap());
    let beam = mass * 1.0 / 12.0;
    let i_across = across.dot(&(inertia * across));
    let i_axis = axis.dot(&(inertia * axis));
    println!("inertia across {i_across:e} (m L^2/12 {beam:e}), about the axis {i_axis:e}");
    assert!((i_across / beam - 1.0).abs() < 0.01);
    assert!(i_axis < 1e-3 * beam);
    assert!(html.contains("v0 is the initial velocity of the frame origin L0"));
    assert!(html.contains("frame.vx, frame.vy, frame.vz its velocity"));
    assert!(html.contains("21 nodes drawn, 2 exposed"), "{html}");
}
