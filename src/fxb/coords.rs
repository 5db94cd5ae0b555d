//! Node coordinates, which a `.fxb` file does not hold: from a Radioss starter-deck
//! `/NODE` block or from a CSV file `id,x,y,z`. Blocked bodies need them to report node
//! positions, and the FMU packer needs them to place nodes.
//!
//! `/NODE` lines are read like `.fxb` lines: fixed columns (ID in columns 1-10, then X, Y,
//! Z in 20-column fields, first 100 columns) and blank-separated, and a line the two
//! readings see differently is an error. Several `/NODE` blocks are concatenated; a block
//! ends at the next line starting with `/`. Comments start with `#` or `$` in column 1.

use std::collections::HashMap;
use std::path::Path;

use super::fields::{LINE_COLUMNS, is_blank, parse_int, parse_real, shown};

/// Why coordinates could not be read.
#[derive(Debug, thiserror::Error)]
pub enum CoordsError {
    /// The file could not be read.
    #[error("{file}: cannot read the coordinate file: {}", super::input::describe(.source))]
    Io {
        /// File name.
        file: String,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// A line that is not `ID X Y Z`.
    #[error(
        "{file}:{line}: {section}: cannot read a node line: expected {expected}, found {found}"
    )]
    Unparsable {
        /// File name.
        file: String,
        /// 1-based line.
        line: usize,
        /// `/NODE block` or `CSV`.
        section: &'static str,
        /// What a line must hold.
        expected: String,
        /// What was there.
        found: String,
    },
    /// A line read differently in fixed columns and blank-separated.
    #[error(
        "{file}:{line}: /NODE block: ambiguous line: the fixed-column reading (ID in 10 \
         columns, X Y Z in 20) gives {fixed} but the blank-separated reading gives {free}"
    )]
    Ambiguous {
        /// File name.
        file: String,
        /// 1-based line.
        line: usize,
        /// Fixed-column reading.
        fixed: String,
        /// Blank-separated reading.
        free: String,
    },
    /// A node given twice.
    #[error(
        "{file}:{line}: {section}: duplicate node ID {id}: expected each node once, found it already on line {first_line}"
    )]
    Duplicate {
        /// File name.
        file: String,
        /// 1-based line of the second occurrence.
        line: usize,
        /// `/NODE block` or `CSV`.
        section: &'static str,
        /// Node ID.
        id: i64,
        /// Line of the first occurrence.
        first_line: usize,
    },
    /// No node found.
    #[error("{file}: no nodes: expected {expected}, found none")]
    Empty {
        /// File name.
        file: String,
        /// What the file should hold.
        expected: &'static str,
    },
}

/// Node coordinates in file order.
pub type Coords = Vec<(i64, [f64; 3])>;

/// Read node coordinates: CSV when the name ends in `.csv`, a `/NODE` deck otherwise.
pub fn read_coords(path: &Path) -> Result<Coords, CoordsError> {
    let name = path.display().to_string();
    let bytes =
        super::input::read_bounded(path, super::input::Limit::Coordinates).map_err(|source| {
            CoordsError::Io {
                file: name.clone(),
                source,
            }
        })?;
    let csv = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    if csv {
        parse_csv(&bytes, &name)
    } else {
        parse_node_deck(&bytes, &name)
    }
}

/// The coordinates as a map from node ID.
pub fn to_map(coords: &Coords) -> HashMap<i64, [f64; 3]> {
    coords.iter().copied().collect()
}

fn lines(text: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    text.split(|&c| c == b'\n')
        .enumerate()
        .map(|(k, l)| (k + 1, l.strip_suffix(b"\r").unwrap_or(l)))
}

fn is_skipped(line: &[u8]) -> bool {
    matches!(line.first(), Some(b'#' | b'$')) || line.iter().all(|&c| is_blank(c))
}

struct Seen<'a> {
    file: &'a str,
    section: &'static str,
    first: HashMap<i64, usize>,
    out: Coords,
}

impl Seen<'_> {
    fn push(&mut self, line: usize, id: i64, x: [f64; 3]) -> Result<(), CoordsError> {
        if let Some(&first_line) = self.first.get(&id) {
            return Err(CoordsError::Duplicate {
                file: self.file.to_string(),
                line,
                section: self.section,
                id,
                first_line,
            });
        }
        self.first.insert(id, line);
        self.out.push((id, x));
        Ok(())
    }
}

/// Parse the `/NODE` blocks of a starter deck.
pub fn parse_node_deck(text: &[u8], file: &str) -> Result<Coords, CoordsError> {
    let mut seen = Seen {
        file,
        section: "/NODE block",
        first: HashMap::new(),
        out: Vec::new(),
    };
    let mut inside = false;
    for (ln, line) in lines(text) {
        if line.first() == Some(&b'/') {
            let key = line.split(|&c| is_blank(c)).next().unwrap_or(line);
            inside = key == b"/NODE";
            continue;
        }
        if !inside || is_skipped(line) {
            continue;
        }
        let (id, x) = node_line(line).map_err(|e| match e {
            NodeIssue::Bad(found) => CoordsError::Unparsable {
                file: file.to_string(),
                line: ln,
                section: "/NODE block",
                expected: "a node ID (columns 1-10) and X, Y, Z (20 columns each), or \
                           four blank-separated values"
                    .into(),
                found,
            },
            NodeIssue::Ambiguous(fixed, free) => CoordsError::Ambiguous {
                file: file.to_string(),
                line: ln,
                fixed,
                free,
            },
        })?;
        seen.push(ln, id, x)?;
    }
    if seen.out.is_empty() {
        return Err(CoordsError::Empty {
            file: file.to_string(),
            expected: "a /NODE line followed by node lines",
        });
    }
    Ok(seen.out)
}

enum NodeIssue {
    Bad(String),
    Ambiguous(String, String),
}

type NodeLine = (i64, [f64; 3]);

fn node_line(line: &[u8]) -> Result<NodeLine, NodeIssue> {
    let fixed = fixed_node(line);
    let free = free_node(line);
    match (fixed, free) {
        (Some(a), Some(b)) if a == b => Ok(a),
        (Some(a), Some(b)) => Err(NodeIssue::Ambiguous(show(a), show(b))),
        (Some(a), None) | (None, Some(a)) => Ok(a),
        (None, None) => Err(NodeIssue::Bad(format!("'{}'", shown(line)))),
    }
}

fn show((id, x): NodeLine) -> String {
    use crate::num::num;
    format!("[{id}, {}, {}, {}]", num(x[0]), num(x[1]), num(x[2]))
}

fn squeeze(field: &[u8]) -> Vec<u8> {
    field.iter().copied().filter(|&c| !is_blank(c)).collect()
}

fn fixed_node(line: &[u8]) -> Option<NodeLine> {
    let line = &line[..line.len().min(LINE_COLUMNS)];
    let field = |a: usize, b: usize| squeeze(line.get(a..b.min(line.len())).unwrap_or(&[]));
    // Nothing may follow the Z field within the 100 columns.
    if line.len() > 70 && line[70..].iter().any(|&c| !is_blank(c)) {
        return None;
    }
    let id = parse_int(&field(0, 10))?;
    let mut x = [0.0; 3];
    for (k, v) in x.iter_mut().enumerate() {
        let f = field(10 + 20 * k, 30 + 20 * k);
        // A blank coordinate field reads as zero, as Fortran does.
        *v = if f.is_empty() { 0.0 } else { parse_real(&f)? };
    }
    Some((id, x))
}

fn free_node(line: &[u8]) -> Option<NodeLine> {
    let toks: Vec<&[u8]> = line
        .split(|&c| is_blank(c))
        .filter(|t| !t.is_empty())
        .collect();
    let [id, a, b, c] = toks.as_slice() else {
        return None;
    };
    Some((
        parse_int(id)?,
        [parse_real(a)?, parse_real(b)?, parse_real(c)?],
    ))
}

/// Parse CSV `id,x,y,z`, with an optional header line first (a first line whose ID
/// field is not an integer). Comments and blank lines are skipped.
pub fn parse_csv(text: &[u8], file: &str) -> Result<Coords, CoordsError> {
    let mut seen = Seen {
        file,
        section: "CSV",
        first: HashMap::new(),
        out: Vec::new(),
    };
    let mut first_data = true;
    for (ln, line) in lines(text) {
        if is_skipped(line) {
            continue;
        }
        let cells: Vec<Vec<u8>> = line.split(|&c| c == b',').map(squeeze).collect();
        let header = first_data && cells.first().is_some_and(|c| parse_int(c).is_none());
        first_data = false;
        if header {
            continue;
        }
        let parsed = match cells.as_slice() {
            [id, a, b, c] => (|| {
                Some((
                    parse_int(id)?,
                    [parse_real(a)?, parse_real(b)?, parse_real(c)?],
                ))
            })(),
            _ => None,
        };
        let Some((id, x)) = parsed else {
            return Err(CoordsError::Unparsable {
                file: file.to_string(),
                line: ln,
                section: "CSV",
                expected: "id,x,y,z (an integer and three reals)".into(),
                found: format!("'{}'", shown(line)),
            });
        };
        seen.push(ln, id, x)?;
    }
    if seen.out.is_empty() {
        return Err(CoordsError::Empty {
            file: file.to_string(),
            expected: "lines id,x,y,z",
        });
    }
    Ok(seen.out)
}
