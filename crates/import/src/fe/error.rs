//! Errors of the FE readers. Each names the file and, when the cause sits on a line, the
//! 1-based line (and the columns of a fixed field), what was expected and what was found.

use std::fmt;

use super::Dof;
use fxbody::num::num;

/// Where in a file: `file:line`, or just `file` when the cause is not on one line
/// (line 0).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Loc {
    /// File name as given.
    pub file: String,
    /// 1-based line, 0 when not line-bound.
    pub line: usize,
}

impl Loc {
    /// A place in `file`.
    pub fn new(file: &str, line: usize) -> Loc {
        Loc {
            file: file.to_string(),
            line,
        }
    }
}

impl fmt::Display for Loc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            write!(f, "{}", self.file)
        } else {
            write!(f, "{}:{}", self.file, self.line)
        }
    }
}

/// The columns of a field (1-based, inclusive), shown as `cols 41-56: `, or nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Cols(pub Option<(usize, usize)>);

impl fmt::Display for Cols {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some((a, b)) => write!(f, "cols {a}-{b}: "),
            None => Ok(()),
        }
    }
}

/// Why an FE file could not be read. `Display` gives `file:line: message`.
#[derive(Debug, thiserror::Error)]
pub enum FeError {
    /// The file could not be read.
    #[error("{file}: cannot read the file: {source}")]
    Io {
        /// File name.
        file: String,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// A field or token that is not what its place requires.
    #[error("{at}: {cols}cannot read '{found}' as {what}: expected {expected}")]
    Syntax {
        /// File and line.
        at: Loc,
        /// Columns of the field, for fixed-column formats.
        cols: Cols,
        /// The text found (at most 40 characters).
        found: String,
        /// What the field holds (`a real`, `a grid ID`, ...).
        what: &'static str,
        /// What would have been accepted.
        expected: String,
    },
    /// Readable text that the format or this reader does not allow (unsupported matrix
    /// form, component out of range, local frames, negative labels, ...).
    #[error("{at}: {message}")]
    Invalid {
        /// File and line.
        at: Loc,
        /// The cause, naming the value or DOF.
        message: String,
    },
    /// The requested DMIG matrix is not in the file.
    #[error("{file}: no DMIG named {name} in {file} (found: {found})")]
    NoMatrix {
        /// File name.
        file: String,
        /// The name asked for.
        name: String,
        /// The DMIG names present, comma-separated, or `no DMIG card`.
        found: String,
    },
    /// The same matrix term given twice (neither summed nor overwritten: one is a
    /// mistake, and which one cannot be known).
    #[error("{at}: term ({a}, {b}) given twice: first on line {first_line}")]
    Duplicate {
        /// File and the line of the second occurrence.
        at: Loc,
        /// Row DOF.
        a: Dof,
        /// Column DOF.
        b: Dof,
        /// Line of the first occurrence.
        first_line: usize,
    },
    /// Both triangles given, and a term differs from its mirror (or the mirror is
    /// missing in full storage).
    #[error(
        "{at}: not symmetric: ({a}, {b}) = {} but ({b}, {a}) = {}, rel. diff {}: a mass or \
         stiffness matrix must be symmetric",
        num(*.ab), mirror(.ba), num(*.rel)
    )]
    NotSymmetric {
        /// File and the line of the (a, b) term.
        at: Loc,
        /// Row DOF of the term.
        a: Dof,
        /// Column DOF of the term.
        b: Dof,
        /// The (a, b) value.
        ab: f64,
        /// The (b, a) value and its line; `None` when not given although the file stores
        /// both triangles.
        ba: Option<(f64, usize)>,
        /// Relative difference |ab - ba| / max(|ab|, |ba|).
        rel: f64,
    },
    /// A Radioss `/NODE` deck or CSV file rejected by the `.fxb` tools' coordinate reader.
    #[error(transparent)]
    Coords(#[from] fxbody::fxb::coords::CoordsError),
}

impl FeError {
    /// An [`FeError::Invalid`] at `file:line`.
    pub fn invalid(file: &str, line: usize, message: impl Into<String>) -> FeError {
        FeError::Invalid {
            at: Loc::new(file, line),
            message: message.into(),
        }
    }

    /// An [`FeError::Syntax`] for `found` at `file:line`, columns `cols`.
    pub fn syntax(
        file: &str,
        line: usize,
        cols: Option<(usize, usize)>,
        found: &[u8],
        what: &'static str,
        expected: impl Into<String>,
    ) -> FeError {
        FeError::Syntax {
            at: Loc::new(file, line),
            cols: Cols(cols),
            found: fxbody::fxb::fields::shown(found).trim().to_string(),
            what,
            expected: expected.into(),
        }
    }

    /// A line of a matrix file that is not one term: `expected` says what one holds.
    pub fn matrix_line(
        file: &str,
        line: usize,
        text: &[u8],
        expected: impl Into<String>,
    ) -> FeError {
        FeError::syntax(file, line, None, text, "a matrix line", expected)
    }

    /// The line the error is on, 0 when none.
    pub fn line(&self) -> usize {
        match self {
            FeError::Syntax { at, .. }
            | FeError::Invalid { at, .. }
            | FeError::Duplicate { at, .. }
            | FeError::NotSymmetric { at, .. } => at.line,
            _ => 0,
        }
    }
}

/// The mirror term of a [`FeError::NotSymmetric`], as text.
fn mirror(ba: &Option<(f64, usize)>) -> String {
    match ba {
        Some((v, line)) => format!("{} (line {line})", num(*v)),
        None => "0 (not given, while the file stores both triangles)".into(),
    }
}
