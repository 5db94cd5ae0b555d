//! Errors: of reading (each names the file, the 1-based line and what was expected) and
//! of solving (each says which matrix property failed and what to do about it).

use std::fmt;

use crate::Dof;

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

/// The columns of a field (1-based, inclusive), shown as `cols 3-5: `, or nothing.
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

/// Why a matrix or DOF file could not be read. `Display` gives `file:line: message`.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be opened or read.
    #[error("{file}: cannot read the file: {source}")]
    Io {
        /// File name.
        file: String,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// A token that is not what its place requires.
    #[error("{at}: {cols}cannot read '{found}' as {what}: expected {expected}")]
    Syntax {
        /// File and line.
        at: Loc,
        /// Columns of the token.
        cols: Cols,
        /// The text found (at most 40 characters).
        found: String,
        /// What the token holds (`a row number`, `a real`, ...).
        what: &'static str,
        /// What would have been accepted.
        expected: String,
    },
    /// Readable text that the format does not allow (an equation outside the DOF map, a
    /// direction other than 1..6, a DOF listed twice, an empty file, ...).
    #[error("{at}: {message}")]
    Invalid {
        /// File and line.
        at: Loc,
        /// The cause, naming the value or DOF.
        message: String,
    },
    /// The same matrix term given twice (neither summed nor overwritten: one of them is a
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
    /// Both triangles given, and a term differs from its mirror, or its mirror is missing
    /// while the file stores both triangles.
    #[error(
        "{at}: not symmetric: ({a}, {b}) = {ab:e} but ({b}, {a}) = {}: a mass or stiffness \
         matrix must be symmetric",
        mirror(.ba)
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
    },
}

impl ReadError {
    /// A [`ReadError::Invalid`] at `file:line`.
    pub fn invalid(file: &str, line: usize, message: impl Into<String>) -> ReadError {
        ReadError::Invalid {
            at: Loc::new(file, line),
            message: message.into(),
        }
    }

    /// A [`ReadError::Syntax`] for `found` at `file:line`, columns `cols`.
    pub fn syntax(
        file: &str,
        line: usize,
        cols: Option<(usize, usize)>,
        found: &[u8],
        what: &'static str,
        expected: impl Into<String>,
    ) -> ReadError {
        ReadError::Syntax {
            at: Loc::new(file, line),
            cols: Cols(cols),
            found: shown(found),
            what,
            expected: expected.into(),
        }
    }

    /// The line the error is on, 0 when none.
    pub fn line(&self) -> usize {
        match self {
            ReadError::Syntax { at, .. }
            | ReadError::Invalid { at, .. }
            | ReadError::Duplicate { at, .. }
            | ReadError::NotSymmetric { at, .. } => at.line,
            ReadError::Io { .. } => 0,
        }
    }
}

/// At most 40 characters of `bytes`, invalid UTF-8 replaced, trimmed.
fn shown(bytes: &[u8]) -> String {
    let s = String::from_utf8_lossy(bytes);
    let t = s.trim();
    match t.char_indices().nth(40) {
        Some((k, _)) => format!("{}...", &t[..k]),
        None => t.to_string(),
    }
}

/// The mirror term of a [`ReadError::NotSymmetric`], as text.
fn mirror(ba: &Option<(f64, usize)>) -> String {
    match ba {
        Some((v, line)) => format!("{v:e} (line {line})"),
        None => "0 (not given, while the file stores both triangles)".into(),
    }
}

/// Why an eigen-solve or a static-mode solve could not give its result. Each says which
/// property of K and M failed and what it usually means in an FE model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    /// K and M (or a DOF list) do not have the same size.
    #[error("size mismatch: {0}")]
    Size(String),
    /// A matrix holds a value that is not finite.
    #[error("{matrix} holds a non-finite value at ({row}, {col})")]
    NotFinite {
        /// `K` or `M`.
        matrix: &'static str,
        /// 0-based row.
        row: usize,
        /// 0-based column.
        col: usize,
    },
    /// The shifted matrix `K - sigma M` that must be positive definite is not (a zero or
    /// negative pivot at `index`, 0-based in the fill-reducing order).
    #[error(
        "K - ({sigma:e}) M is not positive definite (pivot {index} of the factorisation is \
         not positive): {hint}"
    )]
    NotDefinite {
        /// The shift.
        sigma: f64,
        /// The failed pivot, in factorisation order.
        index: usize,
        /// What this usually means for the model at hand.
        hint: &'static str,
    },
    /// The factorisation of `K - sigma M` hit an exactly zero pivot (sigma is an
    /// eigenvalue, or the matrix is singular).
    #[error("K - ({sigma:e}) M is singular (zero pivot {index}): {hint}")]
    Singular {
        /// The shift.
        sigma: f64,
        /// The zero pivot, in factorisation order.
        index: usize,
        /// What to do.
        hint: &'static str,
    },
    /// The Lanczos iteration did not find every eigenvalue the inertia count promised.
    #[error(
        "found {found} of the {expected} eigenvalues below {limit:e} after {steps} Lanczos \
         steps (basis of {basis} vectors): {hint}"
    )]
    NotConverged {
        /// Eigenpairs found below the limit.
        found: usize,
        /// Eigenvalues below the limit, by inertia.
        expected: usize,
        /// The eigenvalue limit.
        limit: f64,
        /// Block steps taken.
        steps: usize,
        /// Size of the basis at the end.
        basis: usize,
        /// What to try.
        hint: &'static str,
    },
    /// The fixed-point iteration of free-body static modes did not settle.
    #[error(
        "the free-body static modes did not settle after {steps} steps (last relative change \
         {change:e}): {hint}"
    )]
    StaticNotConverged {
        /// Steps taken.
        steps: usize,
        /// The last step's largest relative change.
        change: f64,
        /// What it usually means.
        hint: &'static str,
    },
    /// An eigenpair's true residual is larger than the accepted bound.
    #[error(
        "eigenpair {index} (lambda = {lambda:e}) has a residual |K x - lambda M x| / \
         (|K x| + |lambda| |M x|) of {residual:e}, above {bound:e}"
    )]
    Residual {
        /// 0-based index of the pair.
        index: usize,
        /// Its eigenvalue.
        lambda: f64,
        /// Its relative residual.
        residual: f64,
        /// The bound.
        bound: f64,
    },
    /// An input the method needs is missing or inconsistent (rigid motions, DOFs).
    #[error("{0}")]
    Input(String),
}
