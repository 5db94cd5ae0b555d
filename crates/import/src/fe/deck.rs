//! A CalculiX (Abaqus-style) input deck, read for what a whole-model import needs beside
//! the matrices: node coordinates (`*NODE`), node sets (`*NSET`, `*NODE, NSET=`), the
//! spiders (`*RIGID BODY, NSET=S, REF NODE=r, ROT NODE=q`) and the connectivity of the
//! element types whose faces a distributing spider weighs (`*ELEMENT, TYPE=` one of
//! [`FACE_TYPES`]), following `*INCLUDE, INPUT=file` (relative to the including file).
//! Every other keyword and its data lines are passed over.
//!
//! Refused, naming the file and line: a keyword line this reader needs but cannot read
//! (a `*RIGID BODY` without REF NODE or ROT NODE, or with ELSET instead of NSET), a node
//! line that is not `id, x, y, z`, an unknown set name in a set's data, an included file
//! that includes itself.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use super::error::FeError;
use super::fields::{real, trim};
use fxbody::fxb::fields::parse_int;

/// A `*RIGID BODY` card: the node set it ties, its REF and ROT nodes, and where it was.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidBody {
    /// The tied node set's name (upper case).
    pub nset: String,
    /// REF node: its directions 1-3 are the spider's translations.
    pub reference: i64,
    /// ROT node: its directions 1-3 are the spider's rotations.
    pub rotation: i64,
    /// `file:line` of the card.
    pub at: String,
}

/// What a deck says about nodes.
#[derive(Debug, Clone, Default)]
pub struct Deck {
    /// Coordinates by node ID.
    pub nodes: BTreeMap<i64, [f64; 3]>,
    /// Node sets by upper-case name, IDs in the order given (repeats removed).
    pub nsets: HashMap<String, Vec<i64>>,
    /// The spiders, in deck order.
    pub spiders: Vec<RigidBody>,
    /// Elements of the types in [`FACE_TYPES`]: the type (upper case) and its nodes.
    pub elements: Vec<(String, Vec<i64>)>,
}

/// Element types whose connectivity is kept, with their node counts: the solids whose
/// faces are triangles or quadrilaterals, and the shells (one face each).
pub const FACE_TYPES: [(&str, usize); 14] = [
    ("C3D4", 4),
    ("C3D10", 10),
    ("C3D10T", 10),
    ("C3D8", 8),
    ("C3D8R", 8),
    ("C3D8I", 8),
    ("C3D20", 20),
    ("C3D20R", 20),
    ("S3", 3),
    ("S4", 4),
    ("S4R", 4),
    ("S6", 6),
    ("S8", 8),
    ("S8R", 8),
];

/// What the data lines under the current keyword are.
enum Block {
    Skip,
    Node(Option<String>),
    Nset {
        name: String,
        generate: bool,
    },
    /// Element lines of a kept type: its name, node count, and the cells read so far
    /// (an element may continue on the next line).
    Element {
        kind: String,
        nodes: usize,
        cells: Vec<i64>,
    },
}

/// Read `path` and the files it includes.
pub fn read_deck(path: &Path) -> Result<Deck, FeError> {
    let mut deck = Deck::default();
    let mut stack = Vec::new();
    read_into(path, &mut deck, &mut stack)?;
    Ok(deck)
}

/// The options of a keyword line, upper-cased: `NAME=VALUE` pairs (blanks removed).
fn options(line: &str) -> Vec<(String, String)> {
    line.split(',')
        .skip(1)
        .map(|o| {
            let o: String = o.chars().filter(|c| !c.is_whitespace()).collect();
            match o.split_once('=') {
                Some((k, v)) => (k.to_ascii_uppercase(), v.to_string()),
                None => (o.to_ascii_uppercase(), String::new()),
            }
        })
        .collect()
}

fn option<'a>(opts: &'a [(String, String)], name: &str) -> Option<&'a str> {
    opts.iter()
        .find(|(k, _)| k == name)
        .map(|(_, v)| v.as_str())
}

fn read_into(path: &Path, deck: &mut Deck, stack: &mut Vec<PathBuf>) -> Result<(), FeError> {
    let file = path.display().to_string();
    let canonical = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
    if stack.contains(&canonical) {
        return Err(FeError::invalid(
            &file,
            0,
            "the file includes itself (through *INCLUDE)",
        ));
    }
    stack.push(canonical);
    let bytes = super::read_file(path)?;
    let text = String::from_utf8_lossy(&bytes);
    let mut block = Block::Skip;
    for (k, raw) in text.lines().enumerate() {
        let ln = k + 1;
        let line = raw.trim_end_matches('\r');
        if line.starts_with("**") || line.trim().is_empty() {
            continue;
        }
        if line.starts_with('*') {
            let key = line
                .split(',')
                .next()
                .unwrap_or("")
                .trim()
                .to_ascii_uppercase();
            let opts = options(line);
            block = Block::Skip;
            match key.as_str() {
                "*INCLUDE" => {
                    let Some(name) = option(&opts, "INPUT") else {
                        return Err(FeError::invalid(&file, ln, "*INCLUDE without INPUT=file"));
                    };
                    // The option's value keeps its case (a file name).
                    let name = line
                        .split(',')
                        .skip(1)
                        .find_map(|o| {
                            let (k, v) = o.split_once('=')?;
                            k.trim().eq_ignore_ascii_case("INPUT").then(|| v.trim())
                        })
                        .unwrap_or(name);
                    let inc = path.parent().unwrap_or(Path::new(".")).join(name);
                    read_into(&inc, deck, stack)?;
                }
                "*NODE" => block = Block::Node(option(&opts, "NSET").map(str::to_uppercase)),
                "*NSET" => {
                    let Some(name) = option(&opts, "NSET") else {
                        return Err(FeError::invalid(&file, ln, "*NSET without NSET=name"));
                    };
                    block = Block::Nset {
                        name: name.to_uppercase(),
                        generate: opts.iter().any(|(k, _)| k == "GENERATE"),
                    };
                }
                "*RIGID BODY" => deck.spiders.push(rigid_body(&opts, &file, ln)?),
                "*ELEMENT" => {
                    let kind = option(&opts, "TYPE").unwrap_or("").to_ascii_uppercase();
                    if let Some(&(_, nodes)) = FACE_TYPES.iter().find(|(t, _)| *t == kind) {
                        block = Block::Element {
                            kind,
                            nodes,
                            cells: Vec::new(),
                        };
                    }
                }
                _ => {}
            }
            continue;
        }
        match &mut block {
            Block::Skip => {}
            Block::Node(set) => {
                let (id, x) = node_line(line, &file, ln)?;
                deck.nodes.insert(id, x);
                if let Some(s) = set {
                    add(deck, s, &[id]);
                }
            }
            Block::Nset { name, generate } => {
                let ids = set_line(deck, line, *generate, &file, ln)?;
                add(deck, name, &ids);
            }
            Block::Element { kind, nodes, cells } => {
                for c in line.split(',').map(str::trim).filter(|c| !c.is_empty()) {
                    match parse_int(c.as_bytes()) {
                        Some(v) if v > 0 => cells.push(v),
                        _ => {
                            return Err(FeError::syntax(
                                &file,
                                ln,
                                None,
                                c.as_bytes(),
                                "an *ELEMENT line",
                                "id, then the element's node IDs (positive integers)",
                            ));
                        }
                    }
                }
                if cells.len() > *nodes + 1 {
                    return Err(FeError::invalid(
                        &file,
                        ln,
                        format!(
                            "element {} of type {kind} has more than {nodes} nodes",
                            cells[0]
                        ),
                    ));
                }
                if cells.len() == *nodes + 1 {
                    deck.elements.push((kind.clone(), cells[1..].to_vec()));
                    cells.clear();
                }
            }
        }
    }
    stack.pop();
    Ok(())
}

/// Append `ids` to set `name`, leaving out IDs it already holds.
fn add(deck: &mut Deck, name: &str, ids: &[i64]) {
    let set = deck.nsets.entry(name.to_string()).or_default();
    for &id in ids {
        if !set.contains(&id) {
            set.push(id);
        }
    }
}

fn rigid_body(opts: &[(String, String)], file: &str, ln: usize) -> Result<RigidBody, FeError> {
    let node = |name: &str, shown: &str| -> Result<i64, FeError> {
        let v = option(opts, name).ok_or_else(|| {
            FeError::invalid(
                file,
                ln,
                format!(
                    "*RIGID BODY without {shown}=node: the import reads a spider as its REF \
                     NODE (translations) and ROT NODE (rotations); give both"
                ),
            )
        })?;
        parse_int(v.as_bytes()).filter(|&id| id > 0).ok_or_else(|| {
            FeError::syntax(
                file,
                ln,
                None,
                v.as_bytes(),
                "a node ID",
                "a positive integer",
            )
        })
    };
    let Some(nset) = option(opts, "NSET") else {
        return Err(FeError::invalid(
            file,
            ln,
            "*RIGID BODY without NSET=: a spider tied to an element set (ELSET) is not read; \
             give the node set",
        ));
    };
    Ok(RigidBody {
        nset: nset.to_uppercase(),
        reference: node("REFNODE", "REF NODE")?,
        rotation: node("ROTNODE", "ROT NODE")?,
        at: format!("{file}:{ln}"),
    })
}

fn node_line(line: &str, file: &str, ln: usize) -> Result<(i64, [f64; 3]), FeError> {
    let cells: Vec<&[u8]> = line.as_bytes().split(|&c| c == b',').map(trim).collect();
    let cells = match cells.split_last() {
        Some(([], rest)) => rest,
        _ => &cells[..],
    };
    let parsed = (2..=4).contains(&cells.len()).then(|| {
        let id = parse_int(cells[0]).filter(|&id| id > 0)?;
        let mut x = [0.0; 3];
        for (v, c) in x.iter_mut().zip(&cells[1..]) {
            *v = real(c)?;
        }
        Some((id, x))
    });
    match parsed {
        Some(Some(n)) => Ok(n),
        _ => Err(FeError::syntax(
            file,
            ln,
            None,
            line.as_bytes(),
            "a *NODE line",
            "id, x, y, z (a positive integer and up to three reals)",
        )),
    }
}

fn set_line(
    deck: &Deck,
    line: &str,
    generate: bool,
    file: &str,
    ln: usize,
) -> Result<Vec<i64>, FeError> {
    let cells: Vec<&str> = line
        .split(',')
        .map(str::trim)
        .filter(|c| !c.is_empty())
        .collect();
    if generate {
        let v: Vec<i64> = cells
            .iter()
            .filter_map(|c| parse_int(c.as_bytes()))
            .collect();
        let ok = v.len() == cells.len() && (2..=3).contains(&v.len()) && v[0] <= v[1];
        let step = v.get(2).copied().unwrap_or(1);
        if !ok || step <= 0 {
            return Err(FeError::syntax(
                file,
                ln,
                None,
                line.as_bytes(),
                "a *NSET, GENERATE line",
                "first, last[, increment] with first <= last and increment > 0",
            ));
        }
        return Ok((v[0]..=v[1]).step_by(step as usize).collect());
    }
    let mut ids = Vec::new();
    for c in cells {
        match parse_int(c.as_bytes()) {
            Some(id) if id > 0 => ids.push(id),
            Some(_) => {
                return Err(FeError::syntax(
                    file,
                    ln,
                    None,
                    c.as_bytes(),
                    "a node ID",
                    "a positive integer or a node set's name",
                ));
            }
            None => match deck.nsets.get(&c.to_uppercase()) {
                Some(s) => ids.extend_from_slice(s),
                None => {
                    return Err(FeError::invalid(
                        file,
                        ln,
                        format!("'{c}' is neither a node ID nor a node set defined above"),
                    ));
                }
            },
        }
    }
    Ok(ids)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn reads_nodes_sets_spiders_through_includes() {
        let dir = std::env::temp_dir().join(format!("fxbody-deck-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write(
            &dir,
            "mesh.inp",
            "** a comment\n*NODE, NSET=ALL\n1, 0., 0., 0.\n2, 1.5, 0, 0\n3, 0, 2e1\n\
             *ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 3\n*ELEMENT, TYPE=S8R\n2, 1, 2, 3,\n4, 5, 6, 7, 8\n\
             *ELEMENT, TYPE=B31\n3, 1, 2\n*NSET, NSET=Hole\n1, 2,\n\
             *NSET, NSET=MORE, GENERATE\n10, 14, 2\n*NSET, NSET=BOTH\nHOLE, 3\n\
             *RIGID BODY, NSET=HOLE, REF NODE=100, ROT NODE = 101\n",
        );
        let job = write(
            &dir,
            "job.inp",
            "*INCLUDE, INPUT=mesh.inp\n*STEP\n*END STEP\n",
        );
        let deck = read_deck(&job).unwrap();
        assert_eq!(deck.nodes.len(), 3);
        assert_eq!(deck.nodes[&3], [0.0, 20.0, 0.0]);
        assert_eq!(deck.nsets["HOLE"], vec![1, 2]);
        assert_eq!(deck.nsets["MORE"], vec![10, 12, 14]);
        assert_eq!(deck.nsets["BOTH"], vec![1, 2, 3]);
        assert_eq!(deck.nsets["ALL"], vec![1, 2, 3]);
        let s = &deck.spiders[0];
        assert_eq!(
            (s.nset.as_str(), s.reference, s.rotation),
            ("HOLE", 100, 101)
        );
        assert!(s.at.ends_with("mesh.inp:19"), "{}", s.at);
        // Element types with faces are kept (one continued over two lines), beams not.
        assert_eq!(deck.elements.len(), 2);
        assert_eq!(deck.elements[0], ("C3D4".to_string(), vec![1, 2, 3, 3]));
        assert_eq!(deck.elements[1].1, (1..=8).collect::<Vec<i64>>());

        let bad = write(&dir, "bad.inp", "*RIGID BODY, NSET=HOLE, REF NODE=4\n");
        let e = read_deck(&bad).unwrap_err().to_string();
        assert!(e.contains("bad.inp:1: *RIGID BODY without ROT NODE"), "{e}");
        let bad = write(&dir, "bad2.inp", "*NODE\n1, 0.0, x, 0\n");
        let e = read_deck(&bad).unwrap_err().to_string();
        assert!(e.contains("bad2.inp:2: cannot read"), "{e}");
        let bad = write(&dir, "bad3.inp", "*NSET, NSET=A\n1, NOPE\n");
        let e = read_deck(&bad).unwrap_err().to_string();
        assert!(e.contains("bad3.inp:2: 'NOPE' is neither"), "{e}");
        let bad = write(&dir, "bad4.inp", "*ELEMENT, TYPE=S3\n1, 1, 2, 3, 4\n");
        let e = read_deck(&bad).unwrap_err().to_string();
        assert!(
            e.contains("bad4.inp:2: element 1 of type S3 has more than 3"),
            "{e}"
        );
        let bad = write(&dir, "loop.inp", "*INCLUDE, INPUT=loop.inp\n");
        let e = read_deck(&bad).unwrap_err().to_string();
        assert!(e.contains("includes itself"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
