//! Abaqus `*MATRIX OUTPUT, FORMAT=MATRIX INPUT` files (`job_STIF1.mtx`, `job_MASS1.mtx`),
//! and CalculiX `*SUBSTRUCTURE MATRIX OUTPUT`, which writes the same lines: one term per
//! line, `row node, row dof, column node, column dof, value`, comma-separated. Storage may
//! be one triangle or both (then checked equal). `**` lines are comments.
//!
//! Refused: negative node labels (Abaqus's internal and Lagrange-multiplier nodes, which
//! no coordinates can place), DOFs other than 1..6 (warping, pressure, temperature), and
//! `FORMAT=COORDINATE` files (`row, column, value` by equation number: the node map is
//! lost).

use std::io::{BufRead, BufReader};
use std::path::Path;

use super::error::FeError;
use super::fields::{Lines, real, trim};
use super::terms::{Storage, Terms};
use super::{Dof, SymMatrix};
use fxbody::fxb::fields::parse_int;

/// Read an Abaqus matrix file; the matrix is named after the file stem.
pub fn read_abaqus(path: &Path) -> Result<SymMatrix, FeError> {
    let file = path.display().to_string();
    let reader = BufReader::with_capacity(1 << 20, super::open(path)?.0);
    parse_abaqus(reader, &file, super::stem(path))
}

/// Read Abaqus matrix lines from `reader` (file name `file` for messages).
pub fn parse_abaqus(reader: impl BufRead, file: &str, name: String) -> Result<SymMatrix, FeError> {
    let mut terms = Terms::new(file);
    let mut lines = Lines::new(reader, file);
    while let Some((ln, line)) = lines.next_line()? {
        let mut cells: [(&[u8], usize); 5] = [(&[], 0); 5];
        let t = trim(line);
        if t.is_empty() || t.starts_with(b"**") {
            continue;
        }
        if t.starts_with(b"*") {
            return Err(FeError::matrix_line(
                file,
                ln,
                t,
                "node, dof, node, dof, value (a keyword line has no place in a *MATRIX \
                 OUTPUT file)",
            ));
        }
        let mut count = 0;
        let mut col = 0;
        for cell in line.split(|&c| c == b',') {
            if count < 5 {
                cells[count] = (cell, col + 1);
            }
            col += cell.len() + 1;
            count += 1;
        }
        // A trailing comma leaves an empty last cell.
        if count == 6 && trim(line.rsplit(|&c| c == b',').next().unwrap_or(b"")).is_empty() {
            count = 5;
        }
        if count != 5 {
            let hint = if count == 3 {
                " (3 fields look like FORMAT=COORDINATE, which numbers equations instead \
                 of naming nodes: write the matrix with FORMAT=MATRIX INPUT)"
            } else {
                ""
            };
            return Err(FeError::matrix_line(
                file,
                ln,
                line,
                format!(
                    "5 comma-separated fields node, dof, node, dof, value, found {count}{hint}"
                ),
            ));
        }
        let cols = |k: usize| {
            let (c, start) = cells[k];
            Some((start, start + c.len().max(1) - 1))
        };
        let dof = |k: usize| -> Result<Dof, FeError> {
            let (node_text, dof_text) = (trim(cells[k].0), trim(cells[k + 1].0));
            let node = parse_int(node_text).ok_or_else(|| {
                FeError::syntax(file, ln, cols(k), node_text, "a node label", "an integer")
            })?;
            let d = parse_int(dof_text).ok_or_else(|| {
                FeError::syntax(
                    file,
                    ln,
                    cols(k + 1),
                    dof_text,
                    "a DOF number",
                    "an integer 1..6",
                )
            })?;
            if node <= 0 {
                return Err(FeError::invalid(
                    file,
                    ln,
                    format!(
                        "node label {node}: Abaqus writes negative labels for its internal \
                         and Lagrange-multiplier nodes, which have no coordinates and \
                         cannot be part of a body; output the matrix of a model without \
                         them (e.g. no hybrid or MPC/connector Lagrange DOFs)"
                    ),
                ));
            }
            if !(1..=6).contains(&d) {
                return Err(FeError::invalid(
                    file,
                    ln,
                    format!("DOF {node}.{d} not supported (only 1..6)"),
                ));
            }
            Ok(Dof {
                id: node,
                comp: d as u8,
            })
        };
        let row = dof(0)?;
        let col_dof = dof(2)?;
        let v = trim(cells[4].0);
        let value = real(v).ok_or_else(|| {
            FeError::syntax(
                file,
                ln,
                cols(4),
                v,
                "a real",
                "a finite number such as 2.5e+05",
            )
        })?;
        let r = terms.dof(row, ln)?;
        let c = terms.dof(col_dof, ln)?;
        terms.push(r, c, value, ln);
    }
    if terms.len() == 0 {
        return Err(FeError::invalid(
            file,
            0,
            "no matrix lines: expected node, dof, node, dof, value lines \
             (*MATRIX OUTPUT, FORMAT=MATRIX INPUT)",
        ));
    }
    terms.finish(name, Storage::Detect)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn g(id: i64, comp: u8) -> Dof {
        Dof { id, comp }
    }

    #[test]
    fn lower_triangle_lines() {
        let text = "** STIFFNESS\n1,1, 1,1,  2.352941176470588e+05\n1,2, 1,1,  1.102941176470588e+05\n\
                    7,3, 1,1, -4.411764705882353e+04\n1,2,1,2,1.0,\n";
        let m = parse_abaqus(text.as_bytes(), "j_STIF1.mtx", "j_STIF1".into()).unwrap();
        assert_eq!(m.dofs, vec![g(1, 1), g(1, 2), g(7, 3)]);
        assert_eq!(m.get(g(1, 1), g(7, 3)), -4.411764705882353e4);
        assert_eq!(m.get(g(1, 2), g(1, 1)), 1.102941176470588e5);
        assert_eq!(m.get(g(1, 2), g(1, 2)), 1.0);
    }

    #[test]
    fn refused_lines_name_line_and_value() {
        let cases = [
            (
                "1,1,-3,2,1.0\n",
                "m.mtx:1: node label -3: Abaqus writes negative labels",
            ),
            (
                "1,1,1,1,1.0\n1,7,1,1,1.0\n",
                "m.mtx:2: DOF 1.7 not supported (only 1..6)",
            ),
            (
                "1,1,1,1,1.2.3\n",
                "m.mtx:1: cols 9-13: cannot read '1.2.3' as a real",
            ),
            (
                "1,2,3.0\n",
                "m.mtx:1: cannot read '1,2,3.0' as a matrix line: expected 5",
            ),
        ];
        for (text, want) in cases {
            let e = parse_abaqus(text.as_bytes(), "m.mtx", "m".into()).unwrap_err();
            assert!(e.to_string().starts_with(want), "{e}");
        }
    }
}
