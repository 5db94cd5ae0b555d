//! Static modes at connection DOFs: with them in a reduced basis, statics at the
//! connections are exact.
//!
//! - **Blocked** body: the connection columns of K^-1, `U = K^-1 E` (E: unit columns at
//!   the connection DOFs), one solve with the working factor, which is K's own.
//! - **Free** body: inertia-relief attachment modes. With `R` the rigid motions made
//!   M-orthonormal, `P = I - M R R^T` turns a unit load `e_j` into a self-equilibrated
//!   one (`R^T P e_j = 0`: the rigid body's inertia balances it). The mode is the
//!   solution of `K u = P e_j` with no rigid part (`R^T M u = 0`), which exists because
//!   the load is balanced and is unique because the rigid part is fixed.
//!
//! K is singular for a free body, so the working factor is of `A = K + s M`
//! (`s = -sigma0 > 0`). `K u = f` is solved by a two-level iteration, all connection DOFs
//! at once:
//! - smoothing, `u += A^-1 (f - K u)` with the rigid part removed: the error's
//!   eigen-component at lambda shrinks by `s / (lambda + s)`, which is below
//!   `s / lambda_max` (1e-4 with the default shift) for every mode above the limit but
//!   only 0.2 for a low mode;
//! - a coarse correction in the kept eigenvectors Phi (every mode below the limit),
//!   `u += Phi Lambda^-1 Phi^T (f - K u)`, which removes the low modes' error (a Galerkin
//!   step: it needs Phi to be good, not exact).
//!
//! Each step costs one solve with the factor and two products with K; a few steps give
//! the mode to rounding.

use faer::Mat;

use crate::sparse::dense::{ab, at_b, sub_ab};
use crate::sparse::eigen::{Modes, Solver};
use crate::sparse::error::SolveError;

/// Largest relative change of the last step accepted as converged (the rounding floor of
/// `f - K u` is near 1e-12 on a 10^4-DOF solid).
pub const STATIC_TOL: f64 = 1e-10;

/// Fixed-point steps at most.
const MAX_STEPS: usize = 80;

/// One static mode per connection DOF (equation indices into K), one column each:
/// blocked, the columns of K^-1; free, the inertia-relief attachment modes (which need
/// the rigid motions given to [`Solver::new`]). `modes` are the eigenpairs below the
/// limit found by the same solver (any subset of them is correct, all of them is fast).
pub fn static_modes(
    solver: &Solver<'_>,
    connection: &[usize],
    modes: &Modes,
) -> Result<Mat<f64>, SolveError> {
    let n = solver.k().n();
    if let Some(&bad) = connection.iter().find(|&&j| j >= n) {
        return Err(SolveError::Size(format!(
            "connection DOF {bad} is outside the model's {n} equations"
        )));
    }
    let c = connection.len();
    let mut f = Mat::zeros(n, c);
    for (col, &j) in connection.iter().enumerate() {
        f[(j, col)] = 1.0;
    }
    if solver.shift() == 0.0 && solver.rigid().is_none() {
        solver.factor().solve_in_place(f.as_mut());
        return Ok(f);
    }
    let rigid = solver.rigid().ok_or_else(|| {
        SolveError::Input(
            "free-body static modes need the rigid motions (give them to Solver::new)".into(),
        )
    })?;
    // f = P E = E - M R (R^T E): R^T E is R's rows at the connection DOFs.
    let rt_e = Mat::from_fn(rigid.x.ncols(), c, |k, col| rigid.x[(connection[col], k)]);
    sub_ab(f.as_mut(), rigid.mx.as_ref(), rt_e.as_ref());
    let phi = &modes.vectors;
    if phi.nrows() != n || phi.ncols() != modes.lambda.len() {
        return Err(SolveError::Size(format!(
            "modes have {} rows and {} eigenvalues for {} vectors, the model {n} rows",
            phi.nrows(),
            modes.lambda.len(),
            phi.ncols()
        )));
    }
    // Start from the coarse solution.
    let g = at_b(phi.as_ref(), f.as_ref());
    let scaled = Mat::from_fn(g.nrows(), c, |i, col| g[(i, col)] / modes.lambda[i]);
    let mut u = ab(phi.as_ref(), scaled.as_ref());
    let mut r = Mat::zeros(n, c);
    residual(solver, &f, &u, &mut r);
    let mut last = f64::INFINITY;
    for _ in 0..MAX_STEPS {
        // Smoothing: u += A^-1 r, rigid part removed.
        let mut du = r.clone();
        solver.factor().solve_in_place(du.as_mut());
        project_out(&mut du, &rigid.x, &rigid.mx);
        add(&mut u, &du);
        // Coarse correction in the kept modes: u += Phi Lambda^-1 Phi^T (f - K u).
        residual(solver, &f, &u, &mut r);
        let g = at_b(phi.as_ref(), r.as_ref());
        let scaled = Mat::from_fn(g.nrows(), c, |i, col| g[(i, col)] / modes.lambda[i]);
        let dc = ab(phi.as_ref(), scaled.as_ref());
        add(&mut u, &dc);
        residual(solver, &f, &u, &mut r);
        let change = (0..c)
            .map(|col| {
                let d = (0..n)
                    .map(|i| (du[(i, col)] + dc[(i, col)]).abs())
                    .fold(0.0, f64::max);
                let size = (0..n).map(|i| u[(i, col)].abs()).fold(0.0, f64::max);
                d / size
            })
            .fold(0.0, f64::max);
        // Converged, or the next step would change less than the tolerance (the error
        // shrinks by the same factor each step).
        if change <= STATIC_TOL || (last < 1.0 && change * (change / last) <= STATIC_TOL) {
            return Ok(u);
        }
        last = change;
    }
    Err(SolveError::StaticNotConverged {
        steps: MAX_STEPS,
        change: last,
        hint: "the modes given are not this solver's, or K has a zero-energy mode besides the \
               rigid motions",
    })
}

/// `x -= R (R^T M x)` for M-orthonormal `R` with `MR = M R`.
fn project_out(x: &mut Mat<f64>, r: &Mat<f64>, mr: &Mat<f64>) {
    let c = at_b(mr.as_ref(), x.as_ref());
    sub_ab(x.as_mut(), r.as_ref(), c.as_ref());
}

/// `u += d`.
fn add(u: &mut Mat<f64>, d: &Mat<f64>) {
    *u += d;
}

/// `r = f - K u`.
fn residual(solver: &Solver<'_>, f: &Mat<f64>, u: &Mat<f64>, r: &mut Mat<f64>) {
    solver.k().mul(u.as_ref(), r.as_mut());
    *r = f - &*r;
}
