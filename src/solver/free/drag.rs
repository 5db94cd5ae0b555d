//! The terms that make the free-body equations the Lagrange equations of a kinetic
//! energy (FORMULATION.md section 3, "the kinetic energy and its equations"): the one
//! place the free methods that take them read them from (implicit; split where the modes
//! do not drag rigid motion; the explicit method stays the Radioss scheme), written as
//! functions of the state so that a derivative evaluator can call them as well.
//!
//! The kinetic energy of section 3 leaves out the part `P_dot Phi_L alpha` of the node
//! velocities. Kept to first order in `alpha` (the order of the rest of the model) it adds
//!
//! ```text
//! T_drag = v_R^T M_C(P_dot) alpha = v_R^T Y(alpha) v_R,   Y(x)[:, i] = M_C(dP/dq_i) x
//! ```
//!
//! (`P_dot` is linear in `v_R`, `dP/dq_i` a constant pattern), and the Lagrange equations of
//! `T + T_drag` differ from the equations Radioss solves only in the rigid rows:
//!
//! ```text
//! (M_R + A(alpha)) a_R + M_C a_L + 2 M_C(P_dot) v_L = ...,   A(x) = Y(x) + Y(x)^T
//! ```
//!
//! The local rows are unchanged (their quadratic-velocity terms cancel exactly), so the
//! centrifugal load on the modes is the one Radioss applies. Without these terms the
//! equations are not the Lagrange equations of any energy: a body whose local modes drag
//! rigid motion (`M_C^T G != 0`, modes computed on a support) gains energy and loses its
//! angular momentum when it spins.
//!
//! Everything is formed from the nine products `M_C,kl x` (`nr` values each, on the
//! stack): O(9 nR nL) per vector `x`, the cost of forming `M_C` itself, no allocation.

use nalgebra::DMatrix;

/// The nine products `M_C,kl x` (`kl = 3k + l`), first `nr` entries used.
pub(crate) type Products = [[f64; 15]; 9];

/// `M_C,kl x` for the nine sub-blocks (`x`: `nl` values).
pub(crate) fn products(m_c_kl: &[DMatrix<f64>], x: &[f64]) -> Products {
    let mut z = [[0.0; 15]; 9];
    for (zk, blk) in z.iter_mut().zip(m_c_kl) {
        let nr = blk.nrows();
        for (j, col) in blk.as_slice().chunks_exact(nr).enumerate() {
            let xj = x[j];
            if xj != 0.0 {
                for (o, &mij) in zk[..nr].iter_mut().zip(col) {
                    *o += mij * xj;
                }
            }
        }
    }
    z
}

/// The frame's rate `P_dot = [v_Lj - v_L0]_j` from the rigid velocities, as the nine
/// weights `P_dot(k, l)` at index `3k + l`.
pub(crate) fn frame_rate(v_r: &[f64]) -> [f64; 9] {
    let mut pd = [0.0; 9];
    for k in 0..3 {
        for l in 0..3 {
            pd[3 * k + l] = v_r[3 * l + k] - v_r[9 + k];
        }
    }
    pd
}

/// `out += s Y(x) u` with `z = products(x)`: `M_C(P_dot(u)) x`.
fn add_y(z: &Products, u: &[f64], s: f64, out: &mut [f64]) {
    let pd = frame_rate(u);
    for (kl, zk) in z.iter().enumerate() {
        let w = s * pd[kl];
        if w != 0.0 {
            for (o, &zi) in out.iter_mut().zip(zk) {
                *o += w * zi;
            }
        }
    }
}

/// `out += s Y(x)^T u` with `z = products(x)`: entry i is `u . M_C(dP/dq_i) x`, i.e.
/// `u . z_(c,j)` for frame point Lj's component c and `-sum_l u . z_(c,l)` for L0's.
fn add_yt(z: &Products, u: &[f64], s: f64, out: &mut [f64]) {
    let nr = out.len();
    let dot = |kl: usize| -> f64 { z[kl][..nr].iter().zip(u).map(|(a, b)| a * b).sum() };
    for c in 0..3 {
        for l in 0..3 {
            let d = s * dot(3 * c + l);
            out[3 * l + c] += d;
            out[9 + c] -= d;
        }
    }
}

/// `out += s A(alpha) u`, `A = Y + Y^T`, with `z = products(alpha)` (`out`, `u`: `nr`).
pub(crate) fn add_mass(z: &Products, u: &[f64], s: f64, out: &mut [f64]) {
    add_y(z, u, s, out);
    add_yt(z, u, s, out);
}

/// `out += s 2 M_C(P_dot) v_L` with `zv = products(v_L)` and the rigid velocities `v_r`:
/// the quadratic-velocity force of the rigid rows.
pub(crate) fn add_force(zv: &Products, v_r: &[f64], s: f64, out: &mut [f64]) {
    add_y(zv, v_r, 2.0 * s, out);
}

/// `T_drag = v_R^T M_C(P_dot) alpha` with `z = products(alpha)`.
pub(crate) fn energy(z: &Products, v_r: &[f64]) -> f64 {
    let pd = frame_rate(v_r);
    let nr = v_r.len();
    z.iter()
        .zip(pd)
        .map(|(zk, w)| w * zk[..nr].iter().zip(v_r).map(|(a, b)| a * b).sum::<f64>())
        .sum()
}

/// The rigid rows' extra terms at a state `(alpha, v)`: `A(alpha) a_R + 2 M_C(P_dot) v_L`
/// added to `out` times `s` (`out`: `nr`). The one evaluation the methods' residuals and
/// accelerations use.
pub(crate) fn add_rigid_terms(
    m_c_kl: &[DMatrix<f64>],
    alpha: &[f64],
    v_r: &[f64],
    v_l: &[f64],
    a_r: &[f64],
    s: f64,
    out: &mut [f64],
) {
    add_mass(&products(m_c_kl, alpha), a_r, s, out);
    add_force(&products(m_c_kl, v_l), v_r, s, out);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random body-like set of nine `nr x nl` blocks and a state.
    fn setup(nr: usize, nl: usize) -> (Vec<DMatrix<f64>>, Vec<f64>, Vec<f64>) {
        let mut seed = 7u64;
        let mut rnd = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let blocks = (0..9)
            .map(|_| DMatrix::from_fn(nr, nl, |_, _| rnd()))
            .collect();
        let q: Vec<f64> = (0..nr + nl).map(|_| rnd()).collect();
        let v: Vec<f64> = (0..nr + nl).map(|_| rnd()).collect();
        (blocks, q, v)
    }

    /// `T = v_R^T M_C(P(q)) v_L + v_R^T M_C(P_dot) alpha` (the parts of the kinetic
    /// energy that depend on the frame; `P = P0 + [q_Lj - q_L0]`, P0 = I), written out
    /// independently of the module.
    fn t(blocks: &[DMatrix<f64>], nr: usize, q: &[f64], v: &[f64]) -> f64 {
        let mut e = 0.0;
        for k in 0..3 {
            for l in 0..3 {
                let p = f64::from(u8::from(k == l)) + q[3 * l + k] - q[9 + k];
                let pd = v[3 * l + k] - v[9 + k];
                let b = &blocks[3 * k + l];
                for i in 0..nr {
                    for j in 0..b.ncols() {
                        e += b[(i, j)] * v[i] * (p * v[nr + j] + pd * q[nr + j]);
                    }
                }
            }
        }
        e
    }

    /// The rigid rows' terms against the Lagrange equations of `t` formed by central
    /// differences: `d/dt dT/dv_R - dT/dq_R` along `q' = v`, `v' = a`, and the local rows'
    /// `d/dt dT/dv_L - dT/dalpha` zero (no term there). Reference: numerical derivatives
    /// of the energy, exact to round-off for this polynomial.
    #[test]
    fn rigid_terms_are_the_lagrange_equations_of_the_energy() {
        for nr in [12, 15] {
            let nl = 4;
            let (blocks, q, v) = setup(nr, nl);
            let (_, a, _) = setup(nr, nl);
            let n = nr + nl;
            // `t` is cubic along the path and linear in q: central differences are exact
            // for it at any step, so a large one keeps round-off small.
            let e = 1e-2;
            let grad_v = |q: &[f64], v: &[f64], i: usize| {
                let (mut vp, mut vm) = (v.to_vec(), v.to_vec());
                vp[i] += e;
                vm[i] -= e;
                (t(&blocks, nr, q, &vp) - t(&blocks, nr, q, &vm)) / (2.0 * e)
            };
            let shift = |x: &[f64], d: &[f64], s: f64| -> Vec<f64> {
                x.iter().zip(d).map(|(x, d)| x + s * d).collect()
            };
            let mut worst: f64 = 0.0;
            let mut out = vec![0.0; nr];
            // The mass terms of the local block of the kinetic energy are not part of
            // `t`: compare the rigid rows' M_C a_L too, formed here.
            add_rigid_terms(
                &blocks,
                &q[nr..],
                &v[..nr],
                &v[nr..],
                &a[..nr],
                1.0,
                &mut out,
            );
            for i in 0..n {
                let ddt = (grad_v(&shift(&q, &v, e), &shift(&v, &a, e), i)
                    - grad_v(&shift(&q, &v, -e), &shift(&v, &a, -e), i))
                    / (2.0 * e);
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[i] += e;
                qm[i] -= e;
                let dq = (t(&blocks, nr, &qp, &v) - t(&blocks, nr, &qm, &v)) / (2.0 * e);
                let lagrange = ddt - dq;
                // Expected: rigid rows `M_C(P) a_L + A a_R + 2 M_C(P_dot) v_L`, local rows
                // `M_C(P)^T a_R` (no quadratic-velocity term).
                let mut want = 0.0;
                for k in 0..3 {
                    for l in 0..3 {
                        let p = f64::from(u8::from(k == l)) + q[3 * l + k] - q[9 + k];
                        let b = &blocks[3 * k + l];
                        if i < nr {
                            want += p * (0..nl).map(|j| b[(i, j)] * a[nr + j]).sum::<f64>();
                        } else {
                            want += p * (0..nr).map(|r| b[(r, i - nr)] * a[r]).sum::<f64>();
                        }
                    }
                }
                if i < nr {
                    want += out[i];
                }
                worst = worst.max((lagrange - want).abs());
            }
            assert!(
                worst < 1e-8,
                "nr {nr}: Lagrange equations off by {worst:.2e}"
            );
            // The energy term as the module forms it.
            let z = products(&blocks, &q[nr..]);
            let mut direct = t(&blocks, nr, &q, &v);
            let mut q0 = q.clone();
            q0[nr..].fill(0.0);
            direct -= t(&blocks, nr, &q0, &v);
            assert!((energy(&z, &v[..nr]) - direct).abs() < 1e-12 * direct.abs().max(1.0));
        }
    }
}
