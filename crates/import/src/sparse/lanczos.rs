//! Block Lanczos on the shift-inverted pencil, in the M-inner product.
//!
//! The operator is `W = (K - sigma M)^-1 M`. It is self-adjoint in the M-inner product
//! `<x, y> = x^T M y`, and its eigenvalues are `theta = 1 / (lambda - sigma)`: the
//! eigenvalues of K x = lambda M x just above sigma become the largest, well separated
//! ones, which Lanczos finds first. With M only semi-definite (massless DOFs, spider
//! nodes) every vector the iteration makes is an image of W, so it stays in the space
//! where the M-inner product is one.
//!
//! One step takes the newest block `Q_j` (b vectors), solves with the factor for all b at
//! once, and M-orthogonalises the result against every earlier block, twice (full
//! reorthogonalisation: the basis stays M-orthonormal to rounding, so no spurious copies
//! of converged eigenvalues appear and none is missed for lack of orthogonality), and
//! against the locked vectors (rigid motions, eigenvectors found by an earlier run). What
//! remains, `Q_{j+1} B_j`, is normalised through the eigen-decomposition of its b x b
//! M-Gram matrix; a direction that vanished (an invariant subspace reached) is replaced by
//! a fresh random one. The projection `T = Q^T M W Q` is block tridiagonal: `A_j` on the
//! diagonal, `B_j` below it. An eigenpair `(theta, y)` of T gives the Ritz vector `Q y`,
//! whose residual `W x - theta x` has the M-norm `|B_j y_last|` (y's last block): no
//! product with K or M is needed to watch convergence.
//!
//! Memory: the basis and its M-image, `2 n m` doubles for m vectors.

use faer::{Mat, MatRef};

use crate::sparse::csc::SymCsc;
use crate::sparse::dense::{ab, at_b, random_block, sub_ab, sym_eigen};
use crate::sparse::error::SolveError;
use crate::sparse::factor::Factor;

/// How a run iterates.
#[derive(Debug, Clone, Copy)]
pub struct Params {
    /// Vectors per block (solves with this many right-hand sides at once).
    pub block: usize,
    /// Largest basis a run may build, in vectors.
    pub max_basis: usize,
    /// A Ritz pair has converged when its residual's M-norm is at most `tol * theta`.
    pub tol: f64,
    /// Seed of the random start block.
    pub seed: u64,
}

/// Where a run starts.
#[derive(Debug, Clone)]
pub enum Start {
    /// From random vectors put through the operator.
    Random,
    /// From these vectors (e.g. the best unconverged Ritz vectors of an earlier run, a
    /// restart that keeps most of what that run learnt).
    From(Mat<f64>),
}

/// Vectors the iteration keeps M-orthogonal to, with their M-images; M-orthonormal.
#[derive(Debug, Clone)]
pub struct Locked {
    /// The vectors, one column each (`n x d`).
    pub x: Mat<f64>,
    /// `M x`.
    pub mx: Mat<f64>,
}

impl Locked {
    /// No vectors, for an `n`-row problem.
    pub fn none(n: usize) -> Locked {
        Locked {
            x: Mat::zeros(n, 0),
            mx: Mat::zeros(n, 0),
        }
    }

    /// These vectors followed by `x` (with `mx = M x`).
    pub fn with(&self, x: MatRef<'_, f64>, mx: MatRef<'_, f64>) -> Locked {
        let n = self.x.nrows();
        let d = self.x.ncols();
        let join = |a: &Mat<f64>, b: MatRef<'_, f64>| {
            Mat::from_fn(n, d + b.ncols(), |i, j| {
                if j < d { a[(i, j)] } else { b[(i, j - d)] }
            })
        };
        Locked {
            x: join(&self.x, x),
            mx: join(&self.mx, mx),
        }
    }

    /// Remove from `w` its M-projection on these vectors.
    fn project_out(&self, w: &mut Mat<f64>) {
        if self.x.ncols() > 0 {
            let c = at_b(self.mx.as_ref(), w.as_ref());
            sub_ab(w.as_mut(), self.x.as_ref(), c.as_ref());
        }
    }
}

/// The converged Ritz pairs of a run: `theta` descending, the vectors M-orthonormal.
#[derive(Debug)]
pub struct Ritz {
    /// Eigenvalues of the operator, `1 / (lambda - sigma)`.
    pub theta: Vec<f64>,
    /// Ritz vectors, one column each.
    pub x: Mat<f64>,
    /// `M x`.
    pub mx: Mat<f64>,
    /// Residual M-norms relative to theta.
    pub residual: Vec<f64>,
    /// The unconverged Ritz vectors with the largest theta (at most a block): where a
    /// restart continues.
    pub restart: Mat<f64>,
    /// Block steps taken.
    pub steps: usize,
    /// Basis vectors built.
    pub basis: usize,
}

/// A basis being built: `q` and `mq` column-major, `n` rows.
struct Basis {
    n: usize,
    q: Vec<f64>,
    mq: Vec<f64>,
}

impl Basis {
    fn cols(&self) -> usize {
        self.q.len() / self.n.max(1)
    }
    fn q(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.q, self.n, self.cols())
    }
    fn mq(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.mq, self.n, self.cols())
    }
    fn push(&mut self, q: &Mat<f64>, mq: &Mat<f64>) {
        for j in 0..q.ncols() {
            self.q.extend((0..self.n).map(|i| q[(i, j)]));
            self.mq.extend((0..self.n).map(|i| mq[(i, j)]));
        }
    }
    /// Remove from `w` its M-projection on the basis (one pass); the coefficients.
    fn project_out(&self, w: &mut Mat<f64>) -> Mat<f64> {
        let c = at_b(self.mq(), w.as_ref());
        sub_ab(w.as_mut(), self.q(), c.as_ref());
        c
    }
}

/// `(K - sigma M)^-1 M x` for the columns of `mx = M x`.
fn apply(factor: &Factor, mx: MatRef<'_, f64>) -> Mat<f64> {
    let mut w = mx.to_owned();
    factor.solve_in_place(w.as_mut());
    w
}

/// Run block Lanczos until `need` Ritz values at or above `theta_cut` have converged,
/// or the basis reaches `params.max_basis`; returns the converged pairs at or above
/// `theta_cut` (more than `need` if they converged too). The caller checks the count.
pub fn run(
    factor: &Factor,
    m: &SymCsc,
    locked: &Locked,
    theta_cut: f64,
    need: usize,
    params: Params,
    start: &Start,
) -> Result<Ritz, SolveError> {
    let n = m.n();
    let b = params
        .block
        .max(1)
        .min(n.saturating_sub(locked.x.ncols()).max(1));
    let mut basis = Basis {
        n,
        q: Vec::new(),
        mq: Vec::new(),
    };
    // Diagonal blocks A_j and the blocks B_j below them.
    let mut diag: Vec<Mat<f64>> = Vec::new();
    let mut below: Vec<Mat<f64>> = Vec::new();
    let mut seed = params.seed;
    let first = match start {
        Start::Random => next_block(factor, m, locked, &basis, b, &mut seed)?,
        Start::From(x) => from_vectors(m, locked, x, b)
            .map_or_else(|| next_block(factor, m, locked, &basis, b, &mut seed), Ok)?,
    };
    basis.push(&first.0, &first.1);
    let mut steps = 0;
    loop {
        steps += 1;
        let j0 = basis.cols() - b;
        let mq_j = basis.mq().subcols(j0, b).to_owned();
        let mut w = apply(factor, mq_j.as_ref());
        locked.project_out(&mut w);
        let c1 = basis.project_out(&mut w);
        locked.project_out(&mut w);
        let c2 = basis.project_out(&mut w);
        let a = Mat::from_fn(b, b, |i, k| {
            let v = |i: usize, k: usize| c1[(j0 + i, k)] + c2[(j0 + i, k)];
            0.5 * (v(i, k) + v(k, i))
        });
        diag.push(a);
        let (q, mq, beta) = normalise(factor, m, locked, &basis, w, b, &mut seed)?;
        below.push(beta);
        // Ritz pairs of T.
        let t = tridiagonal(&diag, &below, b);
        let (theta, y) = sym_eigen(t.as_ref())
            .ok_or_else(|| SolveError::Input("the Lanczos projection is not finite".to_string()))?;
        let mm = t.nrows();
        let last = below.last().expect("one block at least");
        let mut done = Vec::new();
        for k in (0..mm).rev() {
            if theta[k] < theta_cut {
                break;
            }
            let ylast = y.as_ref().submatrix(mm - b, k, b, 1);
            let r = ab(last.as_ref(), ylast).norm_l2() / theta[k].abs();
            if r <= params.tol {
                done.push((k, r));
            }
        }
        let full = basis.cols() + b > params.max_basis || basis.cols() + b > n;
        if done.len() >= need || full {
            let cols: Vec<usize> = done.iter().map(|&(k, _)| k).collect();
            let ysel = Mat::from_fn(mm, cols.len(), |i, c| y[(i, cols[c])]);
            let rest: Vec<usize> = (0..mm)
                .rev()
                .filter(|k| !cols.contains(k))
                .take(b)
                .collect();
            let yrest = Mat::from_fn(mm, rest.len(), |i, c| y[(i, rest[c])]);
            return Ok(Ritz {
                restart: ab(basis.q(), yrest.as_ref()),
                theta: cols.iter().map(|&k| theta[k]).collect(),
                x: ab(basis.q(), ysel.as_ref()),
                mx: ab(basis.mq(), ysel.as_ref()),
                residual: done.iter().map(|&(_, r)| r).collect(),
                steps,
                basis: basis.cols(),
            });
        }
        basis.push(&q, &mq);
    }
}

/// The block tridiagonal T from its diagonal blocks and the blocks below them (the last
/// block below, which couples to the next, unbuilt block, is left out).
fn tridiagonal(diag: &[Mat<f64>], below: &[Mat<f64>], b: usize) -> Mat<f64> {
    let m = diag.len() * b;
    let mut t = Mat::zeros(m, m);
    for (j, a) in diag.iter().enumerate() {
        for r in 0..b {
            for c in 0..b {
                t[(j * b + r, j * b + c)] = a[(r, c)];
            }
        }
        if j + 1 < diag.len() {
            let beta = &below[j];
            for r in 0..b {
                for c in 0..b {
                    t[((j + 1) * b + r, j * b + c)] = beta[(r, c)];
                    t[(j * b + c, (j + 1) * b + r)] = beta[(r, c)];
                }
            }
        }
    }
    t
}

/// A fresh block: random vectors put through the operator (so that they lie in its
/// range), M-orthogonal to the locked vectors and the basis, M-orthonormal.
fn next_block(
    factor: &Factor,
    m: &SymCsc,
    locked: &Locked,
    basis: &Basis,
    b: usize,
    seed: &mut u64,
) -> Result<(Mat<f64>, Mat<f64>), SolveError> {
    for _ in 0..4 {
        let x = random_block(m.n(), b, *seed);
        *seed = seed.wrapping_add(0x632b_e59b_d9b4_e019);
        let mut mx = Mat::zeros(m.n(), b);
        m.mul(x.as_ref(), mx.as_mut());
        let mut w = apply(factor, mx.as_ref());
        for _ in 0..2 {
            locked.project_out(&mut w);
            if basis.cols() > 0 {
                basis.project_out(&mut w);
            }
        }
        let mut mw = Mat::zeros(m.n(), b);
        m.mul(w.as_ref(), mw.as_mut());
        let g = at_b(w.as_ref(), mw.as_ref());
        let (s, u) = sym_eigen(g.as_ref()).ok_or_else(not_finite)?;
        let top = s.last().copied().unwrap_or(0.0);
        if top > 0.0 && s[0] > 1e-20 * top {
            let scale = Mat::from_fn(b, b, |i, k| u[(i, k)] / s[k].sqrt());
            return Ok((
                ab(w.as_ref(), scale.as_ref()),
                ab(mw.as_ref(), scale.as_ref()),
            ));
        }
    }
    Err(SolveError::Input(
        "no start vectors with mass outside the locked space: M has too few DOFs with mass \
         for the modes asked for"
            .into(),
    ))
}

/// `x` made M-orthogonal to the locked vectors and M-orthonormal, if it has `b`
/// independent columns left (else `None`: start at random).
fn from_vectors(
    m: &SymCsc,
    locked: &Locked,
    x: &Mat<f64>,
    b: usize,
) -> Option<(Mat<f64>, Mat<f64>)> {
    if x.ncols() != b || x.nrows() != m.n() {
        return None;
    }
    let mut w = x.clone();
    locked.project_out(&mut w);
    locked.project_out(&mut w);
    let mut mw = Mat::zeros(m.n(), b);
    m.mul(w.as_ref(), mw.as_mut());
    let g = at_b(w.as_ref(), mw.as_ref());
    let (s, u) = sym_eigen(g.as_ref())?;
    let top = s.last().copied().unwrap_or(0.0);
    if !(top > 0.0 && s[0] > 1e-12 * top) {
        return None;
    }
    let scale = Mat::from_fn(b, b, |i, k| u[(i, k)] / s[k].sqrt());
    Some((
        ab(w.as_ref(), scale.as_ref()),
        ab(mw.as_ref(), scale.as_ref()),
    ))
}

fn not_finite() -> SolveError {
    SolveError::Input("a Lanczos block is not finite (a non-finite K or M?)".into())
}

/// A new block, its M-image and the block B that maps it back to the remainder.
type Step = (Mat<f64>, Mat<f64>, Mat<f64>);

/// M-orthonormalise the remainder `w` of a step: `w = Q_new B`. Directions that vanished
/// are replaced by fresh ones (their rows of B are zero); a block that came out less than
/// orthogonal (a remainder much smaller than its image) is orthogonalised once more.
fn normalise(
    factor: &Factor,
    m: &SymCsc,
    locked: &Locked,
    basis: &Basis,
    w: Mat<f64>,
    b: usize,
    seed: &mut u64,
) -> Result<Step, SolveError> {
    let n = m.n();
    let mut mw = Mat::zeros(n, b);
    m.mul(w.as_ref(), mw.as_mut());
    let g = at_b(w.as_ref(), mw.as_ref());
    let (s, u) = sym_eigen(g.as_ref()).ok_or_else(not_finite)?;
    // The image's size before orthogonalisation is at least the largest of the block's
    // own sizes; a direction below 1e-10 of it is numerically gone.
    let top = s.last().copied().unwrap_or(0.0).max(0.0);
    let kept: Vec<usize> = (0..b)
        .filter(|&k| s[k] > 1e-20 * top && top > 0.0)
        .collect();
    let scale = Mat::from_fn(b, b, |l, c| {
        kept.get(c).map_or(0.0, |&k| u[(l, k)] / s[k].sqrt())
    });
    let mut q = ab(w.as_ref(), scale.as_ref());
    let mut mq = ab(mw.as_ref(), scale.as_ref());
    let beta = Mat::from_fn(b, b, |c, l| {
        kept.get(c).map_or(0.0, |&k| s[k].sqrt() * u[(l, k)])
    });
    if kept.len() < b {
        // Continue in a fresh direction: orthogonal to the basis, the kept part and the
        // locked vectors.
        let kq = Mat::from_fn(n, kept.len(), |i, c| q[(i, c)]);
        let kmq = Mat::from_fn(n, kept.len(), |i, c| mq[(i, c)]);
        let wider = locked.with(kq.as_ref(), kmq.as_ref());
        let (fq, fmq) = next_block(factor, m, &wider, basis, b - kept.len(), seed)?;
        for c in 0..b - kept.len() {
            for i in 0..n {
                q[(i, kept.len() + c)] = fq[(i, c)];
                mq[(i, kept.len() + c)] = fmq[(i, c)];
            }
        }
    }
    // Normalising a small remainder magnifies what the orthogonalisation left of the
    // basis in it by sqrt(top / s): check the block against the basis and itself when
    // that could matter (a remainder below 1e-4 of the block's largest direction, or a
    // replaced one), and orthogonalise once more if it drifted.
    let small = kept.len() < b || kept.first().is_some_and(|&k| s[k] < 1e-8 * top);
    let drift = if small {
        let against = at_b(basis.mq(), q.as_ref()).norm_max();
        let own = at_b(mq.as_ref(), q.as_ref());
        (0..b)
            .flat_map(|i| (0..b).map(move |k| (i, k)))
            .map(|(i, k)| (own[(i, k)] - if i == k { 1.0 } else { 0.0 }).abs())
            .fold(against, f64::max)
    } else {
        0.0
    };
    if drift > 1e-12 {
        locked.project_out(&mut q);
        basis.project_out(&mut q);
        let mut mq2 = Mat::zeros(n, b);
        m.mul(q.as_ref(), mq2.as_mut());
        let g = at_b(q.as_ref(), mq2.as_ref());
        let (s, u) = sym_eigen(g.as_ref()).ok_or_else(not_finite)?;
        if s[0] <= 0.0 {
            return Err(not_finite());
        }
        // q_old = q_new R with R = S^(1/2) U^T: fold R into B.
        let inv = Mat::from_fn(b, b, |i, k| u[(i, k)] / s[k].sqrt());
        let r = Mat::from_fn(b, b, |i, k| s[i].sqrt() * u[(k, i)]);
        return Ok((
            ab(q.as_ref(), inv.as_ref()),
            ab(mq2.as_ref(), inv.as_ref()),
            ab(r.as_ref(), beta.as_ref()),
        ));
    }
    Ok((q, mq, beta))
}
