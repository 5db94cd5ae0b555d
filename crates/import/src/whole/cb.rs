//! The Craig-Bampton basis of a whole model (`--reduction craig-bampton`): the
//! fixed-interface modes below fmax (the model with its connection DOFs held) and one
//! constraint mode per connection DOF (unit value there, zero at the other connection
//! DOFs, the interior at rest under no interior load: `x_i = -K_ii^-1 K_ic`).
//!
//! Unlike the default reduction, the body's frequencies are then the Craig-Bampton
//! model's, above the model's own by the dropped fixed-interface modes' share; statics at
//! the connections are still exact (the constraint modes hold the static response to a
//! connection load). A free model's rigid motions are in the constraint modes' span.
//!
//! Each Craig-Bampton frequency's error against the full model is estimated from what
//! the basis leaves out: the interior's response to the inertia loads of the
//! Craig-Bampton modes. The basis is enlarged by [`ESTIMATE_DEPTH`] block steps of `x_i
//! <- K_ii^-1 (M x)_i` (boundary at rest, the factor the constraint modes already use:
//! each step brings in the dropped fixed-interface modes weighted by `lambda /
//! lambda_j`), and the Rayleigh-Ritz values of the enlarged basis in the full model
//! stand for the full model's. Both are upper bounds of the full model's eigenvalues
//! (Ritz values of nested subspaces), so an estimate never has the wrong sign; it falls
//! short of the true error by the share the enlarged basis still misses.

use faer::{Mat, MatRef};

use crate::sparse::dense::{ab, at_b, sub_ab, sym_eigen};
use crate::sparse::eigen::{Modes, Options, Solver, Support};
use crate::sparse::{SolveError, SymCsc};

/// Block steps of the error estimate's enlarged basis (see the module text).
pub const ESTIMATE_DEPTH: usize = 3;

/// A Craig-Bampton reduction of a whole model.
pub struct Cb {
    /// `[constraint modes, fixed-interface modes]` over all the model's equations.
    pub basis: Mat<f64>,
    /// The fixed-interface modes below the cut.
    pub modes: Modes,
    /// Per Craig-Bampton eigenvalue (ascending, rigid ones included), the estimated
    /// relative frequency error against the full model, `f_cb / f_full - 1` (0 for a
    /// zero eigenvalue).
    pub estimates: Vec<f64>,
}

/// The Craig-Bampton reduction (`connection`: the connection equations) with its error
/// estimates (see the module text).
pub fn reduce(
    k: &SymCsc,
    m: &SymCsc,
    connection: &[usize],
    lambda_max: f64,
) -> Result<Cb, SolveError> {
    let n = k.n();
    let mut interior = vec![usize::MAX; n];
    let mut ids = Vec::new();
    for (i, slot) in interior.iter_mut().enumerate() {
        if !connection.contains(&i) {
            *slot = ids.len();
            ids.push(i);
        }
    }
    let conn_col: std::collections::HashMap<usize, usize> = connection
        .iter()
        .enumerate()
        .map(|(c, &e)| (e, c))
        .collect();
    let (kii, kic) = split(k, &interior, &conn_col, ids.len())?;
    let (mii, _) = split(m, &interior, &conn_col, ids.len())?;
    let solver = Solver::new(&kii, &mii, &Support::Blocked, lambda_max).map_err(|e| {
        SolveError::Input(format!(
            "with the connection DOFs held, {e} (the connection DOFs must hold all six rigid \
             motions of a free body)"
        ))
    })?;
    let modes = solver.modes(&Options::default())?;
    let mut x = kic;
    solver.factor().solve_in_place(x.as_mut());
    let c = connection.len();
    let p = modes.vectors.ncols();
    let b = Mat::from_fn(n, c + p, |i, j| match (interior[i], j < c) {
        (usize::MAX, true) => f64::from(u8::from(connection[j] == i)),
        (usize::MAX, false) => 0.0,
        (r, true) => -x[(r, j)],
        (r, false) => modes.vectors[(r, j - c)],
    });
    let estimates = estimates(k, m, &b, &solver, &interior, ids.len())?;
    Ok(Cb {
        basis: b,
        modes,
        estimates,
    })
}

/// The Craig-Bampton eigenvalues' estimated relative frequency errors (see the module
/// text): `interior` maps an equation to its interior index (`usize::MAX` on the
/// boundary), `solver` holds the factor of `K_ii`.
fn estimates(
    k: &SymCsc,
    m: &SymCsc,
    b: &Mat<f64>,
    solver: &Solver<'_>,
    interior: &[usize],
    ni: usize,
) -> Result<Vec<f64>, SolveError> {
    let n = k.n();
    let fail = || SolveError::Input("the Craig-Bampton error estimate did not converge".into());
    let mut v = Mat::zeros(n, 0);
    extend(m, &mut v, b.as_ref(), &fail)?;
    let ritz = |v: &Mat<f64>| sym_eigen(k.project(v.as_ref()).as_ref()).ok_or_else(fail);
    let (lambda_cb, _) = ritz(&v)?;
    let mut last = b.clone();
    for _ in 0..ESTIMATE_DEPTH {
        let mut mx = Mat::zeros(n, last.ncols());
        m.mul(last.as_ref(), mx.as_mut());
        let mut xi = Mat::zeros(ni, last.ncols());
        for (i, &r) in interior.iter().enumerate() {
            if r != usize::MAX {
                for j in 0..last.ncols() {
                    xi[(r, j)] = mx[(i, j)];
                }
            }
        }
        solver.factor().solve_in_place(xi.as_mut());
        last = Mat::from_fn(n, last.ncols(), |i, j| match interior[i] {
            usize::MAX => 0.0,
            r => xi[(r, j)],
        });
        extend(m, &mut v, last.as_ref(), &fail)?;
    }
    let (lambda_ref, _) = ritz(&v)?;
    let top = lambda_cb.iter().fold(0.0f64, |a, &l| a.max(l.abs()));
    Ok(lambda_cb
        .iter()
        .zip(&lambda_ref)
        .map(|(&l, &r)| {
            if l <= 1e-10 * top || r <= 0.0 {
                0.0
            } else {
                (l / r).sqrt() - 1.0
            }
        })
        .collect())
}

/// Append to the M-orthonormal columns of `v` those of `z` M-orthogonalised against them
/// (two passes) and against each other; a direction left with less than 1e-10 of its
/// M-norm is dependent and dropped.
fn extend(
    m: &SymCsc,
    v: &mut Mat<f64>,
    z: MatRef<'_, f64>,
    fail: &dyn Fn() -> SolveError,
) -> Result<(), SolveError> {
    let (n, q) = (z.nrows(), z.ncols());
    let mut mz = Mat::zeros(n, q);
    m.mul(z, mz.as_mut());
    let scale: Vec<f64> = (0..q)
        .map(|j| {
            let d = (0..n).map(|r| z[(r, j)] * mz[(r, j)]).sum::<f64>();
            if d > 0.0 { 1.0 / d.sqrt() } else { 0.0 }
        })
        .collect();
    let mut z = Mat::from_fn(n, q, |i, j| z[(i, j)] * scale[j]);
    for _ in 0..2 {
        if v.ncols() == 0 {
            break;
        }
        m.mul(z.as_ref(), mz.as_mut());
        let c = at_b(v.as_ref(), mz.as_ref());
        sub_ab(z.as_mut(), v.as_ref(), c.as_ref());
    }
    let g = m.project(z.as_ref());
    let (d, u) = sym_eigen(g.as_ref()).ok_or_else(fail)?;
    let keep: Vec<usize> = (0..q).filter(|&j| d[j] > 1e-10).collect();
    let w = Mat::from_fn(q, keep.len(), |i, j| u[(i, keep[j])] / d[keep[j]].sqrt());
    let add = ab(z.as_ref(), w.as_ref());
    let r = v.ncols();
    let mut out = Mat::zeros(n, r + add.ncols());
    out.as_mut().subcols_mut(0, r).copy_from(v.as_ref());
    out.as_mut()
        .subcols_mut(r, add.ncols())
        .copy_from(add.as_ref());
    *v = out;
    Ok(())
}

/// A's interior block (upper triangle, interior numbering) and its interior-connection
/// block `A_ic` (dense, `ni x c`).
fn split(
    a: &SymCsc,
    interior: &[usize],
    conn_col: &std::collections::HashMap<usize, usize>,
    ni: usize,
) -> Result<(SymCsc, Mat<f64>), SolveError> {
    let (ptr, rows, values) = (a.col_ptr(), a.row_idx(), a.values());
    let mut col_ptr = vec![0usize; ni + 1];
    let mut row_idx = Vec::with_capacity(values.len());
    let mut vals = Vec::with_capacity(values.len());
    let mut aic = Mat::zeros(ni, conn_col.len());
    for j in 0..a.n() {
        for q in ptr[j]..ptr[j + 1] {
            let (i, v) = (rows[q], values[q]);
            match (interior[i], interior[j]) {
                (usize::MAX, usize::MAX) => {}
                (usize::MAX, cj) => aic[(cj, conn_col[&i])] += v,
                (ri, usize::MAX) => aic[(ri, conn_col[&j])] += v,
                (ri, _) => {
                    row_idx.push(ri);
                    vals.push(v);
                }
            }
        }
        if interior[j] != usize::MAX {
            col_ptr[interior[j] + 1] = row_idx.len();
        }
    }
    // Interior columns keep their order, so the pointers are the running counts.
    Ok((SymCsc::from_parts(ni, col_ptr, row_idx, vals)?, aic))
}
