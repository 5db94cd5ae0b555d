//! [`Solver`]: every eigenpair of `K x = lambda M x` below a limit, none missed, for a
//! blocked body (K positive definite) or a free one (six rigid motions).
//!
//! 1. One ordering and symbolic analysis of the pattern of K and M together
//!    ([`Analysis`]), shared by every factorisation.
//! 2. The working factor of `K - sigma0 M`, positive definite: `sigma0 = 0` for a blocked
//!    body (the factor is K's own, which the static modes use too); for a free body a
//!    negative shift, `sigma0 = -FREE_SHIFT * lambda_max`, which keeps the factor definite
//!    while barely compressing the spectrum the Lanczos iteration sees.
//! 3. The count: the inertia of `K - lambda_max M` (a second numerical factorisation on
//!    the same analysis) is the number of eigenvalues below `lambda_max` (Sylvester).
//! 4. Block Lanczos on `(K - sigma0 M)^-1 M` ([`crate::sparse::lanczos`]) until that many Ritz
//!    pairs with `lambda <= lambda_max` have converged. For a free body whose rigid
//!    motions are given they are kept out of the iteration (locked), and the count less
//!    six is what is sought. If a run's basis fills first, its converged pairs are locked
//!    and a fresh run continues from new random vectors (this also finds the copies of an
//!    eigenvalue whose multiplicity exceeds the block size).
//! 5. Each pair's true residual is computed with K and M and checked.

use faer::Mat;

use crate::sparse::csc::SymCsc;
use crate::sparse::dense::{ab, at_b, sym_eigen};
use crate::sparse::error::SolveError;
use crate::sparse::factor::{Analysis, Factor, Inertia};
use crate::sparse::lanczos::{self, Locked, Params, Start};

/// A free body's working shift as a fraction of `lambda_max`: `sigma0 = -1e-4
/// lambda_max`. Small against the wanted eigenvalues, so the wanted part of the
/// operator's spectrum stays spread out and the static-mode iteration shrinks its error
/// 10^4-fold a step; `K - sigma0 M` stays positive definite (its smallest eigenvalue, on
/// the rigid motions, is the shift itself), and the rigid part of any solve with it is
/// removed afterwards.
pub const FREE_SHIFT: f64 = 1e-4;

/// Largest accepted backward error of an eigenpair,
/// `|K x - lambda M x|_inf / ((|K|_inf + |lambda| |M|_inf) |x|_inf)`. It is of the order
/// of the eigenvector's error, which is the Lanczos residual (1e-8 relative) over the
/// relative gap to the next eigenvalue: the bracket's pairs show 3e-11 blocked and 4e-10
/// free. The bound catches a pair that is not one (a wrong factor, a broken basis); the
/// eigenvalues themselves are far more accurate than the vectors (their error is below
/// the square of the residual over the gap).
pub const RESIDUAL_BOUND: f64 = 1e-6;

/// How the body is held.
#[derive(Debug, Clone)]
pub enum Support {
    /// Fixed: K is positive definite.
    Blocked,
    /// Unsupported: K has the rigid motions as its null space. `rigid` (`n x 6`, any
    /// basis, e.g. from [`crate::sparse::rigid::rigid_motions`]) keeps them out of the iteration
    /// and is required for static modes; without it the rigid modes are found as
    /// eigenpairs near zero.
    Free {
        /// The rigid motions over the DOFs, one column each.
        rigid: Option<Mat<f64>>,
    },
}

/// Tuning of the eigen-solve; the defaults suit models of 10^4 to 10^6 DOFs.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    /// Vectors per Lanczos block.
    pub block: usize,
    /// Ritz residual (relative to theta) at which a pair has converged.
    pub tol: f64,
    /// Seed of the start vectors.
    pub seed: u64,
    /// Memory the Lanczos basis may take, in bytes (it holds `16 n` bytes per vector).
    pub basis_bytes: usize,
    /// Fresh runs after the first, at most.
    pub restarts: usize,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            block: 16,
            tol: 1e-8,
            seed: 1,
            basis_bytes: 1 << 30,
            restarts: 6,
        }
    }
}

/// Eigenpairs below a limit.
#[derive(Debug, Clone)]
pub struct Modes {
    /// Eigenvalues, ascending (`(2 pi f)^2` in the model's units).
    pub lambda: Vec<f64>,
    /// Eigenvectors, one column each, M-orthonormal (and M-orthogonal to the rigid
    /// motions of a free body that gave them).
    pub vectors: Mat<f64>,
    /// Each pair's backward error (see [`RESIDUAL_BOUND`]).
    pub residual: Vec<f64>,
    /// Eigenvalues below the limit by the inertia count, rigid modes included.
    pub count: usize,
    /// Rigid modes in `count` that are not in `lambda` (6 when given, else 0).
    pub rigid_locked: usize,
    /// Lanczos block steps, over all runs.
    pub steps: usize,
    /// Lanczos runs (1 unless a basis filled up).
    pub runs: usize,
}

/// The frequency in cycles per time unit of the eigenvalue `lambda` (negative rounding
/// noise of a rigid mode gives 0).
pub fn hz(lambda: f64) -> f64 {
    lambda.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)
}

/// The eigenvalue `(2 pi f)^2` of the frequency `f`.
pub fn lambda(f: f64) -> f64 {
    (2.0 * std::f64::consts::PI * f).powi(2)
}

/// K, M, their analysis, the count below the limit and the working factor.
#[derive(Debug)]
pub struct Solver<'a> {
    k: &'a SymCsc,
    m: &'a SymCsc,
    analysis: Analysis,
    lambda_max: f64,
    count: usize,
    factor: Factor,
    /// The rigid motions M-orthonormalised, with their M-images (free bodies).
    rigid: Option<Locked>,
}

impl<'a> Solver<'a> {
    /// Analyse K and M, count the eigenvalues below `lambda_max` and factor
    /// `K - sigma0 M` (see the module text; the count's factor is dropped before the
    /// working one is made, so one factor is in memory at a time). Fails if K and M
    /// differ in size or hold non-finite values, if the working matrix is not positive
    /// definite (a blocked body that can still move, a mechanism), or if the rigid motions
    /// have no mass.
    pub fn new(
        k: &'a SymCsc,
        m: &'a SymCsc,
        support: &Support,
        lambda_max: f64,
    ) -> Result<Solver<'a>, SolveError> {
        if k.n() != m.n() {
            return Err(SolveError::Size(format!(
                "K has {} rows, M {}",
                k.n(),
                m.n()
            )));
        }
        for (a, name) in [(k, "K"), (m, "M")] {
            if let Some((row, col)) = a.first_non_finite() {
                return Err(SolveError::NotFinite {
                    matrix: name,
                    row,
                    col,
                });
            }
        }
        if !(lambda_max > 0.0 && lambda_max.is_finite()) {
            return Err(SolveError::Input(format!(
                "the eigenvalue limit must be positive and finite, not {lambda_max:e}"
            )));
        }
        let (sigma, hint) = match support {
            Support::Blocked => (
                0.0,
                "K is singular or indefinite, so the body is not blocked: a rigid motion or a \
                 mechanism is left (check the supports, or treat the body as free)",
            ),
            Support::Free { .. } => (
                -FREE_SHIFT * lambda_max,
                "K + s M is not positive definite: K has a negative eigenvalue, or a \
                 zero-energy mode without mass (a mechanism, or a DOF with neither stiffness \
                 nor mass)",
            ),
        };
        let analysis = Analysis::new(&k.add_scaled(-lambda_max, m)?)?;
        let count = count_below(k, m, &analysis, lambda_max)?;
        let a = k.add_scaled(-sigma, m)?;
        let factor = Factor::new(&analysis, &a, sigma)?;
        // Blocked: a pivot at rounding level (1e-13 of its diagonal term) is a singular K.
        // Free: the rigid motions' pivots are the shift's size, which may be that small
        // for a low limit; only the sign is checked.
        let rel = if sigma == 0.0 { 1e-13 } else { 0.0 };
        if let Some(index) = factor.first_non_positive_relative(&a, rel) {
            return Err(SolveError::NotDefinite { sigma, index, hint });
        }
        let rigid = match support {
            Support::Free { rigid: Some(r) } => Some(m_orthonormal(m, r)?),
            _ => None,
        };
        Ok(Solver {
            k,
            m,
            analysis,
            lambda_max,
            count,
            factor,
            rigid,
        })
    }

    /// The working shift sigma0.
    pub fn shift(&self) -> f64 {
        self.factor.sigma()
    }

    /// The analysis (ordering, size of the factor).
    pub fn analysis(&self) -> &Analysis {
        &self.analysis
    }

    /// The working factor of `K - sigma0 M`.
    pub fn factor(&self) -> &Factor {
        &self.factor
    }

    /// The rigid motions, M-orthonormal, with their M-images (free bodies given them).
    pub fn rigid(&self) -> Option<&Locked> {
        self.rigid.as_ref()
    }

    /// K.
    pub fn k(&self) -> &SymCsc {
        self.k
    }

    /// M.
    pub fn m(&self) -> &SymCsc {
        self.m
    }

    /// Sylvester's inertia of `K - sigma M`: `negative` eigenvalues lie below sigma (a
    /// numerical factorisation on the shared analysis).
    pub fn inertia(&self, sigma: f64) -> Result<Inertia, SolveError> {
        inertia(self.k, self.m, &self.analysis, sigma)
    }

    /// The eigenvalue limit.
    pub fn lambda_max(&self) -> f64 {
        self.lambda_max
    }

    /// Eigenvalues below the limit, by inertia (rigid modes included).
    pub fn count(&self) -> usize {
        self.count
    }

    /// Every eigenpair with `lambda < lambda_max` (the limit given to [`Solver::new`]),
    /// as many as the inertia count says, each checked by its residual.
    pub fn modes(&self, opt: &Options) -> Result<Modes, SolveError> {
        let n = self.k.n();
        let (count, lambda_max) = (self.count, self.lambda_max);
        let rigid_locked = if self.rigid.is_some() { 6 } else { 0 };
        if count < rigid_locked {
            return Err(SolveError::Input(format!(
                "only {count} eigenvalues below {lambda_max:e}, fewer than the 6 rigid modes \
                 of a free body: the rigid motions are not in K's null space"
            )));
        }
        let need = count - rigid_locked;
        let mut locked = self.rigid.clone().unwrap_or_else(|| Locked::none(n));
        let base = locked.x.ncols();
        let theta_cut = 1.0 / (lambda_max - self.shift());
        let (mut theta, mut steps, mut runs) = (Vec::new(), 0, 0);
        let mut start = Start::Random;
        while theta.len() < need && runs <= opt.restarts {
            let left = need - theta.len();
            let cap = (opt.basis_bytes / (16 * n.max(1))).max(2 * opt.block);
            let params = Params {
                block: opt.block,
                max_basis: (8 * left + 4 * opt.block).max(16 * opt.block).min(cap),
                tol: opt.tol,
                seed: opt.seed.wrapping_add(runs as u64),
            };
            let ritz = lanczos::run(
                &self.factor,
                self.m,
                &locked,
                theta_cut,
                left,
                params,
                &start,
            )?;
            start = Start::From(ritz.restart);
            steps += ritz.steps;
            runs += 1;
            theta.extend_from_slice(&ritz.theta);
            locked = locked.with(ritz.x.as_ref(), ritz.mx.as_ref());
        }
        if theta.len() != need {
            return Err(SolveError::NotConverged {
                found: theta.len() + rigid_locked,
                expected: count,
                limit: lambda_max,
                steps,
                basis: locked.x.ncols(),
                hint: if theta.len() > need {
                    "an eigenvalue lies within rounding of the limit: move the limit slightly"
                } else {
                    "raise the block size or the basis memory"
                },
            });
        }
        // Ascending lambda = descending theta.
        let mut order: Vec<usize> = (0..need).collect();
        order.sort_by(|&a, &b| theta[b].total_cmp(&theta[a]));
        let vectors = Mat::from_fn(n, need, |i, c| locked.x[(i, base + order[c])]);
        let mx = Mat::from_fn(n, need, |i, c| locked.mx[(i, base + order[c])]);
        let lambda: Vec<f64> = order
            .iter()
            .map(|&k| self.shift() + 1.0 / theta[k])
            .collect();
        let residual = backward_errors(self.k, self.m, &vectors, &mx, &lambda);
        if let Some((index, &r)) = residual
            .iter()
            .enumerate()
            .find(|&(_, &r)| r.is_nan() || r > RESIDUAL_BOUND)
        {
            return Err(SolveError::Residual {
                index,
                lambda: lambda[index],
                residual: r,
                bound: RESIDUAL_BOUND,
            });
        }
        Ok(Modes {
            lambda,
            vectors,
            residual,
            count,
            rigid_locked,
            steps,
            runs,
        })
    }
}

/// Relative moves of the count's shift tried when `K - lambda_max M` has a zero or
/// tiny pivot (LDL^T without pivoting can meet one even when `lambda_max` is no
/// eigenvalue): an eigenvalue that close to the limit is on it, to the precision of any
/// frequency.
const COUNT_NUDGE: [f64; 3] = [0.0, -1e-9, 1e-9];

/// The number of eigenvalues below `lambda_max` (Sylvester's inertia of
/// `K - lambda_max M`), the shift nudged by [`COUNT_NUDGE`] if a pivot is zero or below
/// 1e-12 of its row's diagonal term.
fn count_below(
    k: &SymCsc,
    m: &SymCsc,
    analysis: &Analysis,
    lambda_max: f64,
) -> Result<usize, SolveError> {
    let mut last = None;
    for nudge in COUNT_NUDGE {
        let sigma = lambda_max * (1.0 + nudge);
        let a = k.add_scaled(-sigma, m)?;
        match Factor::new(analysis, &a, sigma) {
            Ok(f) if f.smallest_relative_pivot(&a) >= 1e-12 => return Ok(f.inertia().negative),
            Ok(f) => last = Some(f.inertia().negative),
            Err(e @ SolveError::Singular { .. }) => {
                if last.is_none() && nudge == COUNT_NUDGE[COUNT_NUDGE.len() - 1] {
                    return Err(e);
                }
            }
            Err(e) => return Err(e),
        }
    }
    last.ok_or_else(|| SolveError::Input("no inertia count".into()))
}

/// Sylvester's inertia of `K - sigma M`, factored on `analysis`.
fn inertia(k: &SymCsc, m: &SymCsc, analysis: &Analysis, sigma: f64) -> Result<Inertia, SolveError> {
    Ok(Factor::new(analysis, &k.add_scaled(-sigma, m)?, sigma)?.inertia())
}

/// `r` (`n x d`) made M-orthonormal (`r U S^-1/2` from `r^T M r = U S U^T`), with its
/// M-image; refused if some rigid motion has (nearly) no mass.
fn m_orthonormal(m: &SymCsc, r: &Mat<f64>) -> Result<Locked, SolveError> {
    if r.nrows() != m.n() {
        return Err(SolveError::Size(format!(
            "rigid motions have {} rows, M {}",
            r.nrows(),
            m.n()
        )));
    }
    let mut mr = Mat::zeros(m.n(), r.ncols());
    m.mul(r.as_ref(), mr.as_mut());
    let g = at_b(r.as_ref(), mr.as_ref());
    let (s, u) = sym_eigen(g.as_ref())
        .ok_or_else(|| SolveError::Input("the rigid motions are not finite".into()))?;
    let top = s.last().copied().unwrap_or(0.0);
    if s.first().is_none_or(|&s0| s0.is_nan() || s0 <= 1e-12 * top) {
        return Err(SolveError::Input(
            "the rigid motions' mass matrix R^T M R is singular: a rigid motion carries no \
             mass (too few nodes with mass, or the motions are not independent)"
                .into(),
        ));
    }
    let scale = Mat::from_fn(r.ncols(), r.ncols(), |i, k| u[(i, k)] / s[k].sqrt());
    Ok(Locked {
        x: ab(r.as_ref(), scale.as_ref()),
        mx: ab(mr.as_ref(), scale.as_ref()),
    })
}

/// The infinity norm (largest absolute row sum) of a symmetric matrix stored by its
/// upper triangle.
pub fn inf_norm(a: &SymCsc) -> f64 {
    let mut row = vec![0.0; a.n()];
    for j in 0..a.n() {
        for k in a.col_ptr()[j]..a.col_ptr()[j + 1] {
            let (i, v) = (a.row_idx()[k], a.values()[k].abs());
            row[i] += v;
            if i != j {
                row[j] += v;
            }
        }
    }
    row.into_iter().fold(0.0, f64::max)
}

/// Each pair's normwise backward error (see [`RESIDUAL_BOUND`]).
pub fn backward_errors(
    k: &SymCsc,
    m: &SymCsc,
    x: &Mat<f64>,
    mx: &Mat<f64>,
    lambda: &[f64],
) -> Vec<f64> {
    let mut kx = Mat::zeros(x.nrows(), x.ncols());
    k.mul(x.as_ref(), kx.as_mut());
    let (nk, nm) = (inf_norm(k), inf_norm(m));
    (0..x.ncols())
        .map(|c| {
            let r = (0..x.nrows())
                .map(|i| (kx[(i, c)] - lambda[c] * mx[(i, c)]).abs())
                .fold(0.0, f64::max);
            let xn = (0..x.nrows()).map(|i| x[(i, c)].abs()).fold(0.0, f64::max);
            r / ((nk + lambda[c].abs() * nm) * xn)
        })
        .collect()
}
