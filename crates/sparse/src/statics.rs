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
//! (`s = -sigma0 > 0`). `K u = f` is `A u = f + s M u`, solved by the fixed-point
//! iteration `u <- A^-1 (f + s M u)` with the rigid part removed at each step. The part of
//! the solution along the kept eigenvectors Phi (all modes below the limit) is known in
//! closed form, `Phi Lambda^-1 Phi^T f`, and is removed from the iteration too; what is
//! left has only eigen-components above the limit, each of which shrinks by
//! `s / (lambda + s) < s / lambda_max` per step (0.001 with the default shift), so a few
//! solves with all connection DOFs as right-hand sides give the mode to rounding.

use faer::Mat;

use crate::dense::{ab, at_b, sub_ab};
use crate::eigen::{Modes, Solver};
use crate::error::SolveError;

/// Largest relative change of the last fixed-point step accepted as converged.
pub const STATIC_TOL: f64 = 1e-13;

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
    // The kept modes' part, in closed form, and the load that is left.
    let phi = &modes.vectors;
    if phi.nrows() != n {
        return Err(SolveError::Size(format!(
            "modes have {} rows, the model {n}",
            phi.nrows()
        )));
    }
    let mut mphi = Mat::zeros(n, phi.ncols());
    solver.m().mul(phi.as_ref(), mphi.as_mut());
    let g = at_b(phi.as_ref(), f.as_ref());
    let scaled = Mat::from_fn(g.nrows(), c, |i, col| g[(i, col)] / modes.lambda[i]);
    let kept = ab(phi.as_ref(), scaled.as_ref());
    sub_ab(f.as_mut(), mphi.as_ref(), g.as_ref());
    // Fixed point u <- A^-1 (f + s M u), rigid and kept parts removed.
    let s = -solver.shift();
    let mut u = Mat::<f64>::zeros(n, c);
    let mut mu = Mat::<f64>::zeros(n, c);
    let mut last = f64::INFINITY;
    for _ in 0..MAX_STEPS {
        let mut next = Mat::from_fn(n, c, |i, col| f[(i, col)] + s * mu[(i, col)]);
        solver.factor().solve_in_place(next.as_mut());
        for _ in 0..2 {
            let a = at_b(rigid.mx.as_ref(), next.as_ref());
            sub_ab(next.as_mut(), rigid.x.as_ref(), a.as_ref());
            let b = at_b(mphi.as_ref(), next.as_ref());
            sub_ab(next.as_mut(), phi.as_ref(), b.as_ref());
        }
        let change = (0..c)
            .map(|col| {
                let d = (0..n)
                    .map(|i| (next[(i, col)] - u[(i, col)]).abs())
                    .fold(0.0, f64::max);
                let size = (0..n).map(|i| next[(i, col)].abs()).fold(0.0, f64::max);
                d / size
            })
            .fold(0.0, f64::max);
        u = next;
        if change <= STATIC_TOL {
            return Ok(Mat::from_fn(n, c, |i, col| u[(i, col)] + kept[(i, col)]));
        }
        last = change;
        solver.m().mul(u.as_ref(), mu.as_mut());
    }
    Err(SolveError::StaticNotConverged {
        steps: MAX_STEPS,
        change: last,
        hint: "the modes given are not this solver's, or K has a zero-energy mode besides the \
               rigid motions",
    })
}
