//! CalculiX matrix storage, as `*FREQUENCY, SOLVER=MATRIXSTORAGE` writes it, read
//! streaming.
//!
//! - `JOB.dof`: line `i` names the DOF of equation `i`, `node.direction` (`12.3`): two
//!   integers joined by a point, never a real (`12.10` is direction 10, refused). DOFs
//!   fixed by `*BOUNDARY` and the dependent DOFs of `*RIGID BODY` and other MPCs have no
//!   equation. A spider's ROT node appears with directions 1-3, which are rotations.
//! - `JOB.sti` (stiffness) and `JOB.mas` (mass): one term per line, `row column value`,
//!   blank-separated, 1-based equation numbers, the upper triangle with the diagonal,
//!   column by column (`%d %d %20.13e`), explicit zeros included. Both triangles are
//!   accepted too (then every mirror must be given and agree, see [`crate::sparse::Coo`]).
//!
//! Errors name the file, the line, the columns of the token and what was expected.
//!
//! This is the one CalculiX reader: the sparse path keeps its result as it is
//! ([`read_job`]); the dense import of a reduced model reads through it too
//! ([`read_calculix`], the same matrix over sorted DOFs).

use std::path::{Path, PathBuf};

use super::{Dof, FeError, SymMatrix};
use crate::sparse::coo::Coo;
use crate::sparse::csc::SymCsc;
use crate::sparse::text::{Lines, cols, real, tokens, uint};

/// A whole model as CalculiX stores it: the DOF of each equation, and K and M over those
/// equations.
#[derive(Debug, Clone)]
pub struct MatrixStorage {
    /// The DOF of each equation, in equation order.
    pub dofs: Vec<Dof>,
    /// Stiffness.
    pub k: SymCsc,
    /// Mass.
    pub m: SymCsc,
}

/// Read `JOB.dof`, `JOB.sti` and `JOB.mas` given the job's path without extension
/// (`dir/JOB`).
pub fn read_job(job: &Path) -> Result<MatrixStorage, FeError> {
    let with = |ext: &str| -> PathBuf {
        let mut p = job.as_os_str().to_owned();
        p.push(ext);
        PathBuf::from(p)
    };
    let (dof_file, sti, mas) = (with(".dof"), with(".sti"), with(".mas"));
    let dofs = read_dofs(&dof_file)?;
    let k = read_matrix(&sti, &dofs, &dof_file)?;
    let m = read_matrix(&mas, &dofs, &dof_file)?;
    Ok(MatrixStorage { dofs, k, m })
}

/// `job.sti` or `job.mas` (`matrix`) with the DOF map `job.dof` (`dof_file`), as the
/// dense import takes it: over the DOFs its terms mention, sorted, zeros left out; named
/// after the matrix file's stem.
pub fn read_calculix(matrix: &Path, dof_file: &Path) -> Result<SymMatrix, FeError> {
    let dofs = read_dofs(dof_file)?;
    let a = read_matrix(matrix, &dofs, dof_file)?;
    Ok(SymMatrix::from_csc(super::stem(matrix), &dofs, &a))
}

/// The DOF of each equation, from a `.dof` file.
pub fn read_dofs(path: &Path) -> Result<Vec<Dof>, FeError> {
    let (f, _) = super::open(path)?;
    parse_dofs(f, &path.display().to_string())
}

/// [`read_dofs`] from any reader; `file` names it in errors.
pub fn parse_dofs(reader: impl std::io::Read, file: &str) -> Result<Vec<Dof>, FeError> {
    let mut out = Vec::new();
    let mut seen = std::collections::HashMap::new();
    let mut lines = Lines::new(reader, file);
    while let Some((ln, line)) = lines.next_line()? {
        let (tok, count) = tokens::<1>(line);
        if count == 0 {
            continue;
        }
        let t = tok[0].0;
        let parsed = t
            .iter()
            .position(|&c| c == b'.')
            .and_then(|p| Some((uint(&t[..p])?, uint(&t[p + 1..])?)));
        let Some((node, dir)) = parsed.filter(|_| count == 1) else {
            return Err(FeError::syntax(
                file,
                ln,
                cols(tok[0]),
                line,
                "a DOF",
                "node.direction, two integers joined by a point (12.3), alone on its line",
            ));
        };
        if node == 0 || node > i64::MAX as u64 {
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
                format!("DOF {node}.{dir} not supported (only directions 1..6){what}"),
            ));
        }
        let d = Dof::new(node as i64, dir as u8);
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
pub fn read_matrix(path: &Path, dofs: &[Dof], dof_file: &Path) -> Result<SymCsc, FeError> {
    let (f, size) = super::open(path)?;
    // CalculiX lines are 30-40 bytes: reserve for the terms the size promises.
    let hint = (size / 30) as usize;
    parse_matrix(
        f,
        &path.display().to_string(),
        dofs,
        &dof_file.display().to_string(),
        hint,
    )
}

/// [`read_matrix`] from any reader: `file` and `dof_file` name the two files in errors,
/// `hint` is the expected number of terms (0 if unknown).
pub fn parse_matrix(
    reader: impl std::io::Read,
    file: &str,
    dofs: &[Dof],
    dof_file: &str,
    hint: usize,
) -> Result<SymCsc, FeError> {
    let n = dofs.len();
    let mut coo = Coo::new(n);
    coo.reserve(hint);
    let mut lines = Lines::new(reader, file);
    while let Some((ln, line)) = lines.next_line()? {
        let (tok, count) = tokens::<3>(line);
        if count == 0 {
            continue;
        }
        if count != 3 {
            return Err(FeError::matrix_line(
                file,
                ln,
                line,
                format!("3 blank-separated fields, row column value; found {count}"),
            ));
        }
        if ln >= 1 << 31 {
            return Err(FeError::invalid(
                file,
                ln,
                "more than 2^31 lines: not a matrix this reader takes",
            ));
        }
        let eq = |k: usize, what: &'static str| -> Result<usize, FeError> {
            let t = tok[k];
            let e = uint(t.0).filter(|&e| e >= 1).ok_or_else(|| {
                FeError::syntax(file, ln, cols(t), t.0, what, "a positive integer")
            })?;
            if e as usize > n {
                return Err(FeError::invalid(
                    file,
                    ln,
                    format!(
                        "equation {e} is not in {dof_file}, which lists {n} DOFs (equations 1 \
                         to {n}): the two files are not from the same run"
                    ),
                ));
            }
            Ok(e as usize - 1)
        };
        let r = eq(0, "a row number")?;
        let c = eq(1, "a column number")?;
        let value = real(tok[2].0).ok_or_else(|| {
            FeError::syntax(
                file,
                ln,
                cols(tok[2]),
                tok[2].0,
                "a real",
                "a finite number such as 2.5e+05",
            )
        })?;
        coo.push(r, c, value, ln);
    }
    if coo.is_empty() {
        return Err(FeError::invalid(
            file,
            0,
            "no matrix lines: expected row column value lines",
        ));
    }
    coo.finish(file, dofs)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dofs() -> Vec<Dof> {
        parse_dofs(b"12.1\n12.2\n3.1\n".as_slice(), "j.dof").unwrap()
    }

    fn parse(text: &str) -> Result<SymCsc, FeError> {
        parse_matrix(text.as_bytes(), "j.sti", &dofs(), "j.dof", 0)
    }

    #[test]
    fn equations_map_through_the_dof_file() {
        let m = parse("1 1  2.0000000000000e+00\n1 2 -5.0000000000000e-01\n2 2  4.0\n3 3 1.0\n")
            .unwrap();
        assert_eq!(
            dofs(),
            vec![Dof::new(12, 1), Dof::new(12, 2), Dof::new(3, 1)]
        );
        assert_eq!(m.get(1, 0), -0.5);
        assert_eq!(m.get(2, 2), 1.0);
        assert_eq!(m.nnz(), 4);
    }

    #[test]
    fn every_error_names_file_line_and_expectation() {
        let cases = [
            (
                "1 1 1.0\n1 4 1.0\n",
                "j.sti:2: equation 4 is not in j.dof, which lists 3 DOFs",
            ),
            (
                "1 1 1.0\n\n1 x 1.0\n",
                "j.sti:3: cols 3-3: cannot read 'x' as a column number",
            ),
            (
                "0 1 1.0\n",
                "j.sti:1: cols 1-1: cannot read '0' as a row number",
            ),
            (
                "1 1 1.0 2\n",
                "j.sti:1: cannot read '1 1 1.0 2' as a matrix line: expected 3",
            ),
            (
                "1 1 1.0\n1 2 1.0d0\n",
                "j.sti:2: cols 5-9: cannot read '1.0d0' as a real",
            ),
            (
                "1 1 nan\n",
                "j.sti:1: cols 5-7: cannot read 'nan' as a real",
            ),
            (
                "1 1 1.0\n1 1 1.0\n",
                "j.sti:2: term (12.1, 12.1) given twice: first on line 1",
            ),
            ("", "j.sti: no matrix lines"),
        ];
        for (text, want) in cases {
            let e = parse(text).unwrap_err().to_string();
            assert!(e.starts_with(want), "{text:?}: {e}");
        }
        let dof_cases = [
            (
                "1.1\n2.7\n",
                "j.dof:2: DOF 2.7 not supported (only directions 1..6)",
            ),
            (
                "1.1\n2.0\n",
                "j.dof:2: DOF 2.0 not supported (only directions 1..6) (0 is temp",
            ),
            (
                "1.1\n1.1\n",
                "j.dof:2: DOF 1.1 listed twice (first on line 1)",
            ),
            (
                "1.1\n1.5e0\n",
                "j.dof:2: cols 1-5: cannot read '1.5e0' as a DOF",
            ),
            (
                "0.1\n",
                "j.dof:1: DOF 0.1: node label 0 is not a positive node number",
            ),
            ("\n", "j.dof: no DOFs"),
        ];
        for (text, want) in dof_cases {
            let e = parse_dofs(text.as_bytes(), "j.dof")
                .unwrap_err()
                .to_string();
            assert!(e.starts_with(want), "{text:?}: {e}");
        }
    }
}
