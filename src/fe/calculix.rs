//! CalculiX matrix storage (`*FREQUENCY, SOLVER=MATRIXSTORAGE`): `job.sti` (stiffness)
//! and `job.mas` (mass) hold `row column value` lines, blank-separated, by 1-based
//! equation number, one triangle (CalculiX writes the diagonal and one triangle of its
//! symmetric storage; both triangles are accepted and checked equal); `job.dof` names the
//! DOF of each equation, one `node.direction` per line (`12.3`), in equation order.
//!
//! A `.dof` entry is two integers joined by a point, not a real: `12.10` would be node
//! 12, direction 10 (refused), never 12.1. Directions other than 1..6 (0 is temperature)
//! are refused. CalculiX writes nodes under `*TRANSFORM` in their local directions when
//! there are no SPCs or MPCs; the files do not say so, and the reader cannot tell.

use std::collections::HashMap;
use std::io::{BufRead, BufReader};
use std::path::Path;

use super::error::FeError;
use super::fields::{Lines, real, trim};
use super::terms::{Storage, Terms};
use super::{Dof, SymMatrix};
use crate::fxb::fields::{is_blank, parse_int};

/// Read `job.sti` or `job.mas` (`matrix`) with the DOF map `job.dof` (`dof_file`); the
/// matrix is named after the matrix file's stem.
pub fn read_calculix(matrix: &Path, dof_file: &Path) -> Result<SymMatrix, FeError> {
    let dof_reader = BufReader::new(super::open(dof_file)?);
    let dofs = parse_dof_map(dof_reader, &dof_file.display().to_string())?;
    let reader = BufReader::with_capacity(1 << 20, super::open(matrix)?);
    parse_matrix(
        reader,
        &matrix.display().to_string(),
        &dofs,
        &dof_file.display().to_string(),
        super::stem(matrix),
    )
}

/// The DOF of each equation, from a `.dof` file.
pub fn parse_dof_map(reader: impl BufRead, file: &str) -> Result<Vec<Dof>, FeError> {
    let mut out = Vec::new();
    let mut seen: HashMap<Dof, usize> = HashMap::new();
    let mut lines = Lines::new(reader, file);
    while let Some((ln, line)) = lines.next_line()? {
        let t = trim(line);
        if t.is_empty() {
            continue;
        }
        let parsed = t
            .iter()
            .position(|&c| c == b'.')
            .and_then(|p| Some((parse_int(&t[..p])?, parse_int(&t[p + 1..])?)));
        let Some((node, dir)) = parsed else {
            return Err(FeError::syntax(
                file,
                ln,
                None,
                t,
                "a DOF",
                "node.direction, two integers joined by a point (12.3)",
            ));
        };
        if node <= 0 {
            return Err(FeError::invalid(
                file,
                ln,
                format!("DOF {node}.{dir}: node label {node} is not a positive node number"),
            ));
        }
        if !(1..=6).contains(&dir) {
            let what = if dir == 0 { " (0 is temperature)" } else { "" };
            return Err(FeError::invalid(
                file,
                ln,
                format!("DOF {node}.{dir} not supported (only 1..6){what}"),
            ));
        }
        let d = Dof {
            id: node,
            comp: dir as u8,
        };
        if let Some(first) = seen.insert(d, ln) {
            return Err(FeError::invalid(
                file,
                ln,
                format!(
                    "DOF {d} listed twice (first on line {first}): each equation has its own DOF"
                ),
            ));
        }
        out.push(d);
    }
    if out.is_empty() {
        return Err(FeError::invalid(
            file,
            0,
            "no DOFs: expected node.direction lines",
        ));
    }
    Ok(out)
}

/// Read `row column value` lines over the DOF map `dofs` (read from `dof_file`).
pub fn parse_matrix(
    reader: impl BufRead,
    file: &str,
    dofs: &[Dof],
    dof_file: &str,
    name: String,
) -> Result<SymMatrix, FeError> {
    let mut terms = Terms::new(file);
    let mut lines = Lines::new(reader, file);
    while let Some((ln, line)) = lines.next_line()? {
        let mut toks = [(&[][..], 0usize); 3];
        let mut count = 0;
        let mut k = 0;
        while k < line.len() {
            if is_blank(line[k]) {
                k += 1;
                continue;
            }
            let start = k;
            while k < line.len() && !is_blank(line[k]) {
                k += 1;
            }
            if count < 3 {
                toks[count] = (&line[start..k], start + 1);
            }
            count += 1;
        }
        if count == 0 {
            continue;
        }
        if count != 3 {
            return Err(FeError::syntax(
                file,
                ln,
                None,
                line,
                "a matrix line",
                format!("3 blank-separated fields row column value, found {count}"),
            ));
        }
        let cols = |k: usize| Some((toks[k].1, toks[k].1 + toks[k].0.len() - 1));
        let mut eq = |k: usize| -> Result<u32, FeError> {
            let t = toks[k].0;
            let what = if k == 0 {
                "a row number"
            } else {
                "a column number"
            };
            let n = parse_int(t)
                .ok_or_else(|| FeError::syntax(file, ln, cols(k), t, what, "a positive integer"))?;
            if n < 1 || n as usize > dofs.len() {
                return Err(FeError::invalid(
                    file,
                    ln,
                    format!(
                        "equation {n} is not in {dof_file}, which lists {} DOFs (equations 1 \
                         to {}): the two files are not from the same run",
                        dofs.len(),
                        dofs.len()
                    ),
                ));
            }
            terms.dof(dofs[n as usize - 1], ln)
        };
        let r = eq(0)?;
        let c = eq(1)?;
        let v = toks[2].0;
        let value = real(v).ok_or_else(|| {
            FeError::syntax(
                file,
                ln,
                cols(2),
                v,
                "a real",
                "a finite number such as 2.5e+05",
            )
        })?;
        terms.push(r, c, value, ln);
    }
    if terms.len() == 0 {
        return Err(FeError::invalid(
            file,
            0,
            "no matrix lines: expected row column value lines",
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
    fn equations_map_through_the_dof_file() {
        let dofs = parse_dof_map(b"12.1\n12.2\n3.10\n".as_slice(), "j.dof").unwrap_err();
        assert_eq!(
            dofs.to_string(),
            "j.dof:3: DOF 3.10 not supported (only 1..6)"
        );
        let dofs = parse_dof_map(b"12.1\n12.2\n3.1\n".as_slice(), "j.dof").unwrap();
        let text = b"1 1  2.0000000000000e+00\n2 1 -5.0000000000000e-01\n2 2  4.0\n3 3 1.0\n";
        let m = parse_matrix(&text[..], "j.sti", &dofs, "j.dof", "j".into()).unwrap();
        assert_eq!(m.dofs, vec![g(3, 1), g(12, 1), g(12, 2)]);
        assert_eq!(m.get(g(12, 2), g(12, 1)), -0.5);
        assert_eq!(m.get(g(3, 1), g(3, 1)), 1.0);
        let e =
            parse_matrix(b"1 4 1.0\n".as_slice(), "j.sti", &dofs, "j.dof", "j".into()).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("j.sti:1: equation 4 is not in j.dof, which lists 3 DOFs"),
            "{e}"
        );
    }
}
