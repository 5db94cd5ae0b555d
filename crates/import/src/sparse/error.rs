//! Errors of solving: each says which property of K and M failed and what to do about
//! it. (Reading errors are the readers' [`crate::fe::FeError`], one type for every
//! format.)

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
