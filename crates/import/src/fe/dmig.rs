//! Nastran `DMIG` matrices, in any field layout (see [`super::fields`]): the punch that
//! `EXTSEOUT(...,DMIGPCH)` writes (small-field header, large-field column cards, one `*`
//! line per entry), pyNastran's large-field output (one column card per entry, header in
//! large field too), small field with continuations, and free field.
//!
//! Card fields, after the name: header `NAME 0 IFO TIN TOUT POLAR (blank) NCOL`; column
//! card `NAME GJ CJ (blank)` followed by entries `G C A B`, four fields each. Only real
//! (TIN 1, 2) symmetric (IFO 6) or square (IFO 1, then both triangles) matrices are read.
//! Component 0 or blank is a scalar point, 1..6 a grid component. Cards may come in any
//! order (bulk data is unordered), so the header is checked once the file is read.

use std::collections::BTreeSet;
use std::path::Path;

use std::io::{BufRead, BufReader};

use super::cards::{Card, Deck};
use super::error::FeError;
use super::fields::{Field, trim};
use super::terms::{Storage, Terms};
use super::{Dof, SymMatrix};

/// Read the DMIG matrix `name` (case-insensitive) from a punch or bulk-data file.
pub fn read_dmig(path: &Path, name: &str) -> Result<SymMatrix, FeError> {
    let file = path.display().to_string();
    let reader = BufReader::with_capacity(1 << 20, super::open(path)?.0);
    parse_dmig(reader, &file, name)
}

/// The header of the matrix: where it is, and its form.
struct Header {
    line: usize,
    ifo: i64,
}

/// Read the DMIG matrix `name` from `reader` (file name `file` for messages).
pub fn parse_dmig(reader: impl BufRead, file: &str, name: &str) -> Result<SymMatrix, FeError> {
    let mut deck = Deck::new(reader, file);
    let mut names: BTreeSet<String> = BTreeSet::new();
    let mut header: Option<Header> = None;
    let mut first_column: Option<usize> = None;
    let mut terms = Terms::new(file);
    let mut includes: Option<usize> = None;
    let mut digits: Option<u32> = None;
    while let Some(card) =
        deck.next_card(|n| n.eq_ignore_ascii_case(b"DMIG") || n.eq_ignore_ascii_case(b"INCLUDE"))?
    {
        if card.is("INCLUDE") {
            includes.get_or_insert(card.line);
            continue;
        }
        let card_name = card.field(0).trimmed();
        names.insert(String::from_utf8_lossy(card_name).into_owned());
        if !card_name.eq_ignore_ascii_case(name.as_bytes()) {
            continue;
        }
        let second = card.field(1).trimmed();
        if second == b"0" {
            if let Some(h) = &header {
                return Err(FeError::invalid(
                    file,
                    card.line,
                    format!(
                        "a second DMIG header for {name} (the first is on line {}): \
                         expected one header card (0 in field 3) per matrix",
                        h.line
                    ),
                ));
            }
            header = Some(read_header(&card, file, name)?);
        } else {
            first_column.get_or_insert(card.line);
            read_column(&card, file, &mut terms, &mut digits)?;
        }
    }
    let Some(header) = header else {
        if let Some(line) = first_column {
            return Err(FeError::invalid(
                file,
                line,
                format!(
                    "DMIG {name} has column cards but no header card (DMIG {name} 0 IFO \
                     TIN ...): its form (symmetric, square, real) is unknown"
                ),
            ));
        }
        let mut found: Vec<String> = names.into_iter().collect();
        if found.is_empty() {
            found.push("no DMIG card".into());
        }
        let mut found = found.join(", ");
        if let Some(line) = includes {
            found.push_str(&format!(
                "; INCLUDE on line {line} is not followed: pass the included file"
            ));
        }
        return Err(FeError::NoMatrix {
            file: file.to_string(),
            name: name.to_string(),
            found,
        });
    };
    if terms.len() == 0 {
        return Err(FeError::invalid(
            file,
            header.line,
            format!("DMIG {name} has a header but no column cards: the matrix is empty"),
        ));
    }
    let storage = if header.ifo == 1 {
        Storage::Full
    } else {
        Storage::Either
    };
    let mut m = terms.finish(name.to_string(), storage)?;
    m.small_field_digits = digits;
    Ok(m)
}

/// The significant digits of a real's text (`1.2345-5`: 5), the mantissa's digits
/// after leading zeros.
fn significant_digits(text: &[u8]) -> u32 {
    let body = text
        .strip_prefix(b"-")
        .or(text.strip_prefix(b"+"))
        .unwrap_or(text);
    let end = (1..body.len())
        .find(|&k| matches!(body[k], b'e' | b'E' | b'd' | b'D' | b'+' | b'-'))
        .unwrap_or(body.len());
    let digits = body[..end].iter().filter(|c| c.is_ascii_digit());
    digits.skip_while(|&&c| c == b'0').count() as u32
}

fn read_header(card: &Card, file: &str, name: &str) -> Result<Header, FeError> {
    let line = card.line;
    let int = |k: usize, what: &'static str| card.field(k).int(file, what);
    let ifo = int(2, "IFO (field 4 of the DMIG header)")?;
    let tin = int(3, "TIN (field 5 of the DMIG header)")?;
    let at = |k: usize| card.field(k).line;
    match ifo {
        Some(6) | Some(1) => {}
        Some(9) => {
            return Err(FeError::invalid(
                file,
                at(2),
                format!(
                    "DMIG {name} has IFO=9 (rectangular): not supported; a mass or \
                     stiffness matrix is symmetric (IFO=6) or square (IFO=1)"
                ),
            ));
        }
        other => {
            return Err(FeError::invalid(
                file,
                at(2),
                format!(
                    "DMIG {name} has IFO={}: not supported; expected 6 (symmetric) or 1 \
                     (square)",
                    other.map_or("blank".to_string(), |v| v.to_string())
                ),
            ));
        }
    }
    match tin {
        Some(1) | Some(2) => {}
        Some(t @ (3 | 4)) => {
            return Err(FeError::invalid(
                file,
                at(3),
                format!(
                    "DMIG {name} has TIN={t} (complex): not supported; only real matrices \
                     (TIN=1 or 2) can be read"
                ),
            ));
        }
        other => {
            return Err(FeError::invalid(
                file,
                at(3),
                format!(
                    "DMIG {name} has TIN={}: expected 1 or 2 (real single or double \
                     precision)",
                    other.map_or("blank".to_string(), |v| v.to_string())
                ),
            ));
        }
    }
    Ok(Header {
        line,
        ifo: ifo.unwrap_or(0),
    })
}

/// A grid or point ID: a positive integer.
fn id(f: Field, file: &str, what: &'static str) -> Result<Option<i64>, FeError> {
    match f.int(file, what)? {
        Some(v) if v <= 0 => Err(FeError::syntax(
            file,
            f.line,
            f.cols(),
            f.trimmed(),
            what,
            "a positive grid or scalar-point ID",
        )),
        v => Ok(v),
    }
}

/// A component: blank or 0 (scalar point), 1..6 (grid); anything else is refused with
/// the DOF it would make.
fn comp(f: Field, g: i64, file: &str) -> Result<u8, FeError> {
    let t = f.trimmed();
    let c = f.int(file, "a component")?.unwrap_or(0);
    if (0..=6).contains(&c) {
        return Ok(c as u8);
    }
    Err(FeError::invalid(
        file,
        f.line,
        format!(
            "{}DOF {g}.{} not supported (only 1..6 for a grid point, 0 or blank for a \
             scalar point)",
            super::error::Cols(f.cols()),
            String::from_utf8_lossy(t)
        ),
    ))
}

fn read_column(
    card: &Card,
    file: &str,
    terms: &mut Terms,
    digits: &mut Option<u32>,
) -> Result<(), FeError> {
    let line = card.line;
    let gj_f = card.field(1);
    let Some(gj) = id(gj_f, file, "GJ (the column's grid or point ID)")? else {
        return Err(FeError::syntax(
            file,
            line,
            gj_f.cols(),
            gj_f.text,
            "GJ (the column's grid or point ID)",
            "a positive grid or scalar-point ID, found a blank field",
        ));
    };
    let cj = comp(card.field(2), gj, file)?;
    let col = terms.dof(Dof { id: gj, comp: cj }, line)?;
    for k in (4..card.len()).step_by(4) {
        let [g, c, a, b] = [0, 1, 2, 3].map(|o| card.field(k + o));
        let Some(gi) = id(g, file, "G (an entry's grid or point ID)")? else {
            // Padding after the last entry; an entry with no ID is an error.
            if let Some(f) = [c, a, b].into_iter().find(|f| !f.is_blank()) {
                return Err(FeError::syntax(
                    file,
                    f.line,
                    f.cols(),
                    f.trimmed(),
                    "an entry field",
                    format!(
                        "blank, since the entry's G field (cols {}-{}) is blank",
                        g.col,
                        g.col + g.width.max(1) - 1
                    ),
                ));
            }
            continue;
        };
        let ci = comp(c, gi, file)?;
        let Some(value) = a.real(file, "a real")? else {
            return Err(FeError::syntax(
                file,
                a.line,
                a.cols(),
                a.text,
                "a real",
                format!("the value of the term ({gi}.{ci}, {gj}.{cj}), found a blank field"),
            ));
        };
        if let Some(im) = b.real(file, "a real")?
            && im != 0.0
        {
            return Err(FeError::invalid(
                file,
                b.line,
                format!(
                    "{}an imaginary part {} for the term ({gi}.{ci}, {gj}.{cj}) of a real \
                         matrix: expected a blank field",
                    super::error::Cols(b.cols()),
                    String::from_utf8_lossy(trim(b.text))
                ),
            ));
        }
        if a.width == 8 && trim(a.text).len() == 8 && value != 0.0 {
            let d = significant_digits(trim(a.text));
            *digits = Some(digits.map_or(d, |v| v.min(d)));
        }
        let row = terms.dof(Dof { id: gi, comp: ci }, a.line)?;
        terms.push(row, col, value, a.line);
    }
    // A column card with no entries is legal Nastran (an empty column); its DOF stays
    // mentioned, so the builder sees every DOF the file names.
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits_of_a_field() {
        for (t, d) in [
            ("1.2345-5", 5),
            ("-1.234+4", 4),
            (".1234567", 7),
            ("0.001234", 4),
            ("12345678", 8),
            ("1.23E-04", 3),
            ("-.12D+03", 2),
        ] {
            assert_eq!(significant_digits(t.as_bytes()), d, "{t}");
        }
    }

    fn g(id: i64, comp: u8) -> Dof {
        Dof { id, comp }
    }

    /// The real punch layout, as pyNastran's EXTDB comments and the ANSYS help quote it.
    const PUNCH: &str = "\
$ punched by hand in the layout of EXTSEOUT DMIGPCH
DMIG    KAAX           0       6       2       0                     243
DMIG*   KAAX                          21               1
*                     21               1 2.261491337E+08
*                     22               3-1.000000000D+03
DMIG*   KAAX                          22               3
*                     22               3      1.0+3
*                 900001               0             .5
DMIG    MAAX           0       6       2       0                       1
DMIG*   MAAX                          21               1
*                     21               1 1.000000000E+00
";

    #[test]
    fn punch_layout_reads_values_touching_their_field() {
        let m = parse_dmig(PUNCH.as_bytes(), "model.pch", "KAAX").unwrap();
        assert_eq!(m.name, "KAAX");
        assert_eq!(m.dofs, vec![g(21, 1), g(22, 3), g(900001, 0)]);
        assert_eq!(m.get(g(21, 1), g(21, 1)), 2.261491337e8);
        assert_eq!(m.get(g(22, 3), g(21, 1)), -1e3);
        assert_eq!(m.get(g(22, 3), g(22, 3)), 1e3);
        assert_eq!(m.get(g(900001, 0), g(22, 3)), 0.5);
        let m = parse_dmig(PUNCH.as_bytes(), "model.pch", "maax").unwrap();
        assert_eq!(m.terms, vec![(0, 0, 1.0)]);
    }

    #[test]
    fn missing_matrix_lists_the_names_found() {
        let e = parse_dmig(PUNCH.as_bytes(), "model.pch", "K2GG").unwrap_err();
        assert_eq!(
            e.to_string(),
            "model.pch: no DMIG named K2GG in model.pch (found: KAAX, MAAX)"
        );
    }

    #[test]
    fn small_field_with_continuations() {
        let text = "\
DMIG    KAAX    0       6       1       0
DMIG    KAAX    12      2               12      2       4.5             +A
+A      13      1       -1.5-2          14      0       .25
";
        let m = parse_dmig(text.as_bytes(), "s.bdf", "KAAX").unwrap();
        assert_eq!(m.dofs, vec![g(12, 2), g(13, 1), g(14, 0)]);
        assert_eq!(m.terms, vec![(0, 0, 4.5), (0, 1, -0.015), (0, 2, 0.25)]);
    }

    #[test]
    fn square_form_needs_both_triangles_and_a_header_once() {
        let col = |gj: i64, gi: i64, v: &str| {
            format!(
                "DMIG*   KAAX            {gj:>16}{:>16}\n*       {gi:>16}{:>16}{v:>16}\n",
                1, 1
            )
        };
        let head = "DMIG    KAAX           0       1       2       0\n";
        let full = format!(
            "{head}{}{}{}",
            col(1, 1, "2.0"),
            col(1, 2, "-1.0"),
            col(2, 1, "-1.0")
        );
        let m = parse_dmig(full.as_bytes(), "q.pch", "KAAX").unwrap();
        assert_eq!(m.terms, vec![(0, 0, 2.0), (0, 1, -1.0)]);
        let one = format!("{head}{}{}", col(1, 1, "2.0"), col(1, 2, "-1.0"));
        let e = parse_dmig(one.as_bytes(), "q.pch", "KAAX")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("q.pch:5: not symmetric: (2.1, 1.1) = -1 but (1.1, 2.1) = 0"),
            "{e}"
        );
        let twice = format!("{head}{head}{}", col(1, 1, "2.0"));
        let e = parse_dmig(twice.as_bytes(), "q.pch", "KAAX")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("q.pch:2: a second DMIG header for KAAX (the first is on line 1)"),
            "{e}"
        );
        let none = col(1, 1, "2.0");
        let e = parse_dmig(none.as_bytes(), "q.pch", "KAAX")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("q.pch:1: DMIG KAAX has column cards but no header card"),
            "{e}"
        );
        let tab = format!("{head}DMIG*   KAAX\t1\n");
        let e = parse_dmig(tab.as_bytes(), "q.pch", "KAAX")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("q.pch:2: cols 13-13: cannot read '<tab>'"),
            "{e}"
        );
    }
}
