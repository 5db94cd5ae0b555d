//! The documentation page inside the FMU (documentation/index.html) tells what the model
//! description declares (issue 15 item 5): the kept modes and the residual correction
//! (the description attribute) and the outputs that depend on same-instant inputs (the
//! ModelStructure), parsed from both and compared; `--fmax` below the first mode warns
//! (no mode kept), above every mode keeps them all and declares no correction.

use std::collections::BTreeMap;

use crate::common::root;
use fxbody::body::load as load_body;
use fxbody::fmu::doc::index_html;
use fxbody::fmu::pack::{Fmax, PackRequest, Prepared, prepare_with};

fn pack(fmax: Option<f64>) -> Prepared {
    let req = PackRequest {
        body: root().join("fixtures/cantilever.fxb"),
        coords: Some(root().join("fixtures/cantilever.nodes.rad")),
        nodes: Some(vec![121, 111]),
        ..PackRequest::default()
    };
    prepare_with(&req, fmax.map(Fmax::Hz)).unwrap()
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
    let f1 = load_body(&root().join("fixtures/cantilever.fxb"))
        .unwrap()
        .frequencies_hz[0];
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
    let body = load_body(&root().join("fixtures/cantilever.fxb")).unwrap();
    let (f1, top) = (body.frequencies_hz[0], *body.frequencies_hz.last().unwrap());
    let low = pack(Some(0.5 * f1));
    assert_eq!(low.scene.body.nl(), 0);
    assert!(
        low.notes
            .iter()
            .any(|n| n.starts_with("warning: --fmax") && n.contains("below the first mode")),
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
        high.notes.iter().any(|n| n.contains("all 20 modes kept"))
            && !high.notes.iter().any(|n| n.starts_with("warning")),
        "{:?}",
        high.notes
    );
    let (summary, deps) = check_page_agrees(&high);
    assert_eq!(summary, "20 local modes, no residual correction");
    assert!(deps.is_empty());
}
