//! The Craig-Bampton basis of a whole model (`--reduction craig-bampton`): the
//! fixed-interface modes below fmax (the model with its connection DOFs held) and one
//! constraint mode per connection DOF (unit value there, zero at the other connection
//! DOFs, the interior at rest under no interior load: `x_i = -K_ii^-1 K_ic`).
//!
//! Unlike the default reduction, the body's frequencies are then the Craig-Bampton
//! model's, above the model's own by the dropped fixed-interface modes' share; statics at
//! the connections are still exact (the constraint modes hold the static response to a
//! connection load). A free model's rigid motions are in the constraint modes' span.

use faer::Mat;

use crate::sparse::eigen::{Modes, Options, Solver, Support};
use crate::sparse::{SolveError, SymCsc};

/// The basis `[constraint modes, fixed-interface modes]` over all the model's equations
/// (`connection`: the connection equations), and the fixed-interface modes.
pub fn basis(
    k: &SymCsc,
    m: &SymCsc,
    connection: &[usize],
    lambda_max: f64,
) -> Result<(Mat<f64>, Modes), SolveError> {
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
    Ok((b, modes))
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
