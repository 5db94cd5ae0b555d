//! Node coordinates for an imported body, from whichever file the FE model has:
//! Nastran `GRID` cards (any field layout), a Radioss `/NODE` deck, Abaqus `*NODE` data,
//! or CSV `id,x,y,z`. The format is told from the content (a `.csv` name is always CSV):
//! a `/NODE` line, a `*NODE` keyword line, a `GRID` card, else CSV.
//!
//! Radioss decks and CSV go through the `.fxb` tools' reader ([`fxbody::fxb::coords`]),
//! so `pack --coords` and `import --coords` accept the same files alike.
//!
//! Refused, because the matrices' DOFs would not be in the global frame or the position
//! would be wrong: a GRID with CP or CD other than 0 (local coordinate systems are not
//! read), an Abaqus file with `*TRANSFORM`, `*NODE, SYSTEM=C|S` or `*NODE, INPUT=`.

use std::collections::BTreeMap;
use std::path::Path;

use super::cards::Deck;
use super::error::FeError;
use super::fields::{real, trim};
use fxbody::fxb::coords::{self as radioss, Coords};
use fxbody::fxb::fields::parse_int;

/// Node coordinates by ID.
pub type NodeMap = BTreeMap<i64, [f64; 3]>;

/// Read the node coordinates of an FE model, detecting the format (see the module text):
/// the formats of the product's [`fxbody::fxb::coords::read_coords`] (a `/NODE` deck,
/// CSV), which reads them here too, and Nastran GRID cards and Abaqus `*NODE` data. The
/// same [`Coords`] as the product's reader, in order of node ID.
pub fn read_model_coords(path: &Path) -> Result<Coords, FeError> {
    let text = super::read_file(path)?;
    let file = path.display().to_string();
    let csv = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    let map: NodeMap = match detect(&text) {
        _ if csv => radioss::parse_csv(&text, &file)?.into_iter().collect(),
        Format::Radioss => radioss::parse_node_deck(&text, &file)?
            .into_iter()
            .collect(),
        Format::Abaqus => parse_abaqus_nodes(&text, &file)?,
        Format::Nastran => parse_grids(&text, &file)?,
        Format::Csv => radioss::parse_csv(&text, &file)?.into_iter().collect(),
    };
    Ok(map.into_iter().collect())
}

/// Lines of a small text held whole, numbered from 1, without line endings.
fn text_lines(text: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    text.split(|&c| c == b'\n')
        .enumerate()
        .map(|(k, l)| (k + 1, l.strip_suffix(b"\r").unwrap_or(l)))
}

#[derive(Debug, PartialEq, Eq)]
enum Format {
    Radioss,
    Abaqus,
    Nastran,
    Csv,
}

fn detect(text: &[u8]) -> Format {
    let mut grid = false;
    for (_, line) in text_lines(text) {
        if line.starts_with(b"/NODE") {
            return Format::Radioss;
        }
        if keyword(line).is_some_and(|k| k.eq_ignore_ascii_case(b"*NODE")) {
            return Format::Abaqus;
        }
        let f1 = trim(&line[..line.len().min(8)]);
        let f1 = f1.split(|&c| c == b',').next().unwrap_or(f1);
        let f1 = trim(f1.strip_suffix(b"*").unwrap_or(f1));
        grid |= f1.eq_ignore_ascii_case(b"GRID");
    }
    if grid { Format::Nastran } else { Format::Csv }
}

/// The keyword of an Abaqus keyword line (`*NODE` of `*Node, NSET=ALL`), `None` for data
/// and comment lines.
fn keyword(line: &[u8]) -> Option<&[u8]> {
    if !line.starts_with(b"*") || line.starts_with(b"**") {
        return None;
    }
    let k = line.split(|&c| c == b',').next().unwrap_or(line);
    Some(trim(k))
}

/// Remember a node, refusing a second definition.
fn insert(
    map: &mut NodeMap,
    lines: &mut BTreeMap<i64, usize>,
    file: &str,
    line: usize,
    what: &str,
    id: i64,
    x: [f64; 3],
) -> Result<(), FeError> {
    if let Some(&first) = lines.get(&id) {
        return Err(FeError::invalid(
            file,
            line,
            format!("{what} {id} defined twice (first on line {first}): expected each node once"),
        ));
    }
    lines.insert(id, line);
    map.insert(id, x);
    Ok(())
}

/// Nastran GRID cards: `GRID ID CP X1 X2 X3 CD PS SEID`.
pub fn parse_grids(text: &[u8], file: &str) -> Result<NodeMap, FeError> {
    let mut deck = Deck::new(text, file);
    let mut map = NodeMap::new();
    let mut first = BTreeMap::new();
    while let Some(card) = deck.next_card(|n| n.eq_ignore_ascii_case(b"GRID"))? {
        let f = |k: usize| card.field(k);
        let id_f = f(0);
        let id = match id_f.int(file, "a GRID ID")? {
            Some(v) if v > 0 => v,
            _ => {
                return Err(FeError::syntax(
                    file,
                    id_f.line,
                    id_f.cols(),
                    id_f.text,
                    "a GRID ID",
                    "a positive integer",
                ));
            }
        };
        for (k, what) in [(1, "CP"), (5, "CD")] {
            let v = f(k)
                .int(file, if k == 1 { "CP" } else { "CD" })?
                .unwrap_or(0);
            if v != 0 {
                let why = if k == 1 {
                    "its coordinates are in a local coordinate system"
                } else {
                    "its components (the matrices' DOFs) are in a local frame"
                };
                return Err(FeError::invalid(
                    file,
                    f(k).line,
                    format!(
                        "GRID {id} has {what}={v}: {why}, and CORD cards are not read; \
                         export the model with CP and CD 0 (basic system)"
                    ),
                ));
            }
        }
        let mut x = [0.0; 3];
        for (k, v) in x.iter_mut().enumerate() {
            // A blank coordinate is 0.0 in Nastran.
            *v = f(2 + k).real(file, "a coordinate")?.unwrap_or(0.0);
        }
        insert(&mut map, &mut first, file, card.line, "GRID", id, x)?;
    }
    if map.is_empty() {
        return Err(FeError::invalid(
            file,
            0,
            "no GRID cards: expected GRID ID CP X1 X2 X3",
        ));
    }
    Ok(map)
}

/// Abaqus `*NODE` data lines `id, x[, y[, z]]` (missing coordinates are 0).
pub fn parse_abaqus_nodes(text: &[u8], file: &str) -> Result<NodeMap, FeError> {
    let mut map = NodeMap::new();
    let mut first = BTreeMap::new();
    let mut inside = false;
    for (ln, line) in text_lines(text) {
        if line.starts_with(b"**") || trim(line).is_empty() {
            continue;
        }
        if let Some(k) = keyword(line) {
            let upper = line.to_ascii_uppercase();
            let opts: Vec<Vec<u8>> = upper
                .split(|&c| c == b',')
                .skip(1)
                .map(|o| {
                    o.iter()
                        .copied()
                        .filter(|c| !c.is_ascii_whitespace())
                        .collect()
                })
                .collect();
            if k.eq_ignore_ascii_case(b"*TRANSFORM") {
                return Err(FeError::invalid(
                    file,
                    ln,
                    "*TRANSFORM: the DOFs of the nodes it names are in a local frame, which \
                     the import does not support; output the matrices without *TRANSFORM",
                ));
            }
            inside = k.eq_ignore_ascii_case(b"*NODE");
            if inside {
                for o in &opts {
                    let bad = o.starts_with(b"INPUT=")
                        || (o.starts_with(b"SYSTEM=") && o.as_slice() != b"SYSTEM=R");
                    if bad {
                        return Err(FeError::invalid(
                            file,
                            ln,
                            format!(
                                "*NODE option {}: not supported (only rectangular \
                                 coordinates given in this file)",
                                String::from_utf8_lossy(o)
                            ),
                        ));
                    }
                }
            }
            continue;
        }
        if !inside {
            continue;
        }
        let cells: Vec<&[u8]> = line.split(|&c| c == b',').map(trim).collect();
        let cells = match cells.split_last() {
            Some(([], rest)) => rest,
            _ => &cells[..],
        };
        let parsed = (2..=4).contains(&cells.len()).then(|| {
            let id = parse_int(cells[0])?;
            let mut x = [0.0; 3];
            for (v, c) in x.iter_mut().zip(&cells[1..]) {
                *v = real(c)?;
            }
            Some((id, x))
        });
        let Some(Some((id, x))) = parsed else {
            return Err(FeError::syntax(
                file,
                ln,
                None,
                line,
                "a *NODE line",
                "id, x, y, z (an integer and up to three reals)",
            ));
        };
        if id <= 0 {
            return Err(FeError::invalid(
                file,
                ln,
                format!("node label {id}: expected a positive node number"),
            ));
        }
        insert(&mut map, &mut first, file, ln, "node", id, x)?;
    }
    if map.is_empty() {
        return Err(FeError::invalid(
            file,
            0,
            "no *NODE data lines: expected id, x, y, z",
        ));
    }
    Ok(map)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_in_three_layouts_and_refused_frames() {
        let text = "GRID          12       01.0000002.0000003.000000       0\n\
                    GRID*                 13                        4.              .5\n\
                    *                  1.0+3\n\
                    GRID,14,,-1.,,2.5\n";
        let m = parse_grids(text.as_bytes(), "m.bdf").unwrap();
        assert_eq!(m[&12], [1.0, 2.0, 3.0]);
        assert_eq!(m[&13], [4.0, 0.5, 1000.0]);
        assert_eq!(m[&14], [-1.0, 0.0, 2.5]);
        let e = parse_grids(
            b"GRID          12       0      1.      2.      3.       5\n",
            "m.bdf",
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .starts_with("m.bdf:1: GRID 12 has CD=5: its components"),
            "{e}"
        );
        let e = parse_grids(b"GRID,7,2,1.,2.,3.\n", "m.bdf").unwrap_err();
        assert!(e.to_string().starts_with("m.bdf:1: GRID 7 has CP=2"), "{e}");
    }

    #[test]
    fn abaqus_node_blocks() {
        let text = "*Heading\n*NODE, NSET=ALL\n 1, 0., 0., 0.\n 2, 1.5, 0\n*ELEMENT, TYPE=B31\n1, 1, 2\n\
                    *Node\n3,1,2,3,\n";
        let m = parse_abaqus_nodes(text.as_bytes(), "m.inp").unwrap();
        assert_eq!(m.len(), 3);
        assert_eq!(m[&2], [1.5, 0.0, 0.0]);
        assert_eq!(m[&3], [1.0, 2.0, 3.0]);
        let e = parse_abaqus_nodes(b"*NODE\n1,0,0,0\n*Transform, nset=A\n", "m.inp").unwrap_err();
        assert!(e.to_string().starts_with("m.inp:3: *TRANSFORM"), "{e}");
        assert_eq!(detect(text.as_bytes()), Format::Abaqus);
        assert_eq!(detect(b"/NODE\n1 0 0 0\n"), Format::Radioss);
        assert_eq!(detect(b"$x\nGRID*   1\n"), Format::Nastran);
        assert_eq!(detect(b"1,0,0,0\n"), Format::Csv);
    }
}
