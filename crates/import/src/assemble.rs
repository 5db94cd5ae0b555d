//! From the local modes to the file's blocks: m_L, K_L, the mode rows at the FXB nodes,
//! and for a free body the rigid modes, M_R, M_C,kl and K_C,kl (FORMULATION.md section 1,
//! with the mass formulas for a reduced mass that couples directions).
//!
//! With P0 = I the local frame is the global one. `K_C,kl(i,j) = Phi_L,j^T K (T_kl
//! Phi_R,i)`; `M_C,kl(i,j) = (T_lk Phi_R,i)^T M Phi_L,j`: the rotation goes on the rigid
//! mode, so that the engine's `sum P_kl M_C,kl` is the rotated body's coupling for any
//! mass. Both use the condensed K and the a-set M: for the massless DOFs' rebuilt rows
//! `E^T K_full = [K~ 0]` and M is zero there, so nothing is lost.

use std::ops::Range;

use nalgebra::DMatrix;

use super::dense;
use super::dofs::Reduced;
use super::modes::Basis;
use super::report::{Report, Warning};
use super::rigid::{MassProps, mode_value, modes_on};
use super::scale::Scale;
use super::{ImportError, Options};
use crate::fe::Dof;
use fxbody::body::eigenfrequencies_hz;
use fxbody::fxb::FxbFile;

/// Mode rows at the nodes in the file's layout: mode-major, then node, then component.
fn node_rows(model: &Reduced, full: &DMatrix<f64>, node_ids: &[i64]) -> Vec<f64> {
    let n = node_ids.len();
    let mut out = vec![0.0; full.ncols() * 6 * n];
    for (i, d) in model.all.iter().enumerate() {
        if d.is_scalar() {
            continue;
        }
        let Some(node) = node_ids.iter().position(|&id| id == d.id) else {
            continue;
        };
        for j in 0..full.ncols() {
            out[j * 6 * n + 6 * node + (d.comp - 1) as usize] = full[(i, j)];
        }
    }
    out
}

/// Probe vectors for [`departure`]: fixed signs (a seeded generator), so that a run
/// repeats.
const PROBES: usize = 4;

/// How far `Phi^T A Phi` is from the diagonal `d` that the file carries, per mode j in
/// `range` (zero outside it): the largest `|(D^-1/2 Phi^T A Phi D^-1/2 - I) x|_j` over
/// [`PROBES`] vectors x of random signs (zero outside `range`). Each row's value is a
/// random-sign sum of that row's departures, so it estimates the largest
/// `|a_ij| / sqrt(a_ii a_jj)` and the diagonal's error without the n x n-by-nl product
/// (`O(n^2)` per probe).
fn departure(phi: &DMatrix<f64>, a: &DMatrix<f64>, d: &[f64], range: Range<usize>) -> Vec<f64> {
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut x = DMatrix::zeros(phi.ncols(), PROBES);
    for j in range.clone() {
        for p in 0..PROBES {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let sign = if s >> 63 == 0 { 1.0 } else { -1.0 };
            x[(j, p)] = sign / d[j].abs().sqrt();
        }
    }
    let y = dense::tr_mul(phi, &dense::mul(a, &dense::mul(phi, &x)));
    let mut rows = vec![0.0f64; phi.ncols()];
    for j in range {
        for p in 0..PROBES {
            let r = y[(j, p)] / d[j].abs().sqrt() - x[(j, p)] * d[j].abs().sqrt();
            rows[j] = rows[j].max(r.abs());
        }
    }
    rows
}

/// Largest `departure` a written body may have, beyond the eigen-solve's own floor
/// (below). Round-off gives 5.9e-10 at 3,000 DOFs on a well-conditioned grillage;
/// faer 0.22's eigen-solver on an unscaled matrix of norm 1e12 gave 2.5e-2 (wrong modes,
/// written without a word before this check): that is a failed solve, never a body.
pub const MAX_DEPARTURE: f64 = 1e-6;

/// The eigen-solve's floor on `Phi^T K Phi` for a mode of eigenvalue lambda:
/// `FLOOR eps |A| / lambda`. The solver gives each eigenpair to round-off of the matrix's
/// norm `|A|` (the absolute accuracy of any backward-stable symmetric eigen-solver, and
/// of LAPACK's), and the modes are stored in double precision, so K seen through the
/// lowest modes of an ill-conditioned model cannot be diagonal to better than that.
/// Measured: frames of 180 and 360 elements, free (lowest eigenvalue 5.5e-11 and 3.5e-12
/// of the largest), depart by 0.1 and 1.35 times `eps |A| / lambda` at their lowest
/// modes, while their frequencies agree with LAPACK's and with the flexibility form's
/// to what double precision gives there (3e-7 and 2e-6).
const FLOOR: f64 = 8.0;

/// Refuses a basis whose `Phi^T M Phi` or `Phi^T K Phi` departs from the diagonal the
/// file would carry by more than [`MAX_DEPARTURE`] beyond round-off (for K, plus the
/// [`FLOOR`] of each mode of eigenvalue `lambda[j]`, `solved_norm` the norm of the
/// matrix solved): the modes are not the eigenmodes the file claims, and the FMU would
/// integrate the wrong body. `m_rows`, `k_rows` are [`departure`]'s.
fn check_departure(
    m_rows: &[f64],
    k_rows: &[f64],
    lambda: &[f64],
    solved_norm: f64,
) -> Result<(), ImportError> {
    for (j, (&dm, &dk)) in m_rows.iter().zip(k_rows).enumerate() {
        let floor = FLOOR * f64::EPSILON * solved_norm / lambda[j];
        let allowed = MAX_DEPARTURE + if floor.is_finite() { floor } else { 0.0 };
        if dm > MAX_DEPARTURE {
            return Err(ImportError::Inaccurate {
                departure: dm,
                allowed: MAX_DEPARTURE,
            });
        }
        if dk > allowed {
            return Err(ImportError::Inaccurate {
                departure: dk,
                allowed,
            });
        }
    }
    Ok(())
}

/// The file (see the module text). `props` is given for a free body only. Refuses modes
/// that are not M- and K-orthogonal to round-off (`check_departure`).
pub fn fxb(
    model: &Reduced,
    basis: &Basis,
    props: Option<&MassProps>,
    node_ids: &[i64],
    opts: &Options,
    report: &mut Report,
) -> Result<FxbFile, ImportError> {
    let phi = &basis.phi;
    let nl = phi.ncols();
    let ns = basis.nbstat;
    let k_l = &basis.k_l;
    let m_l = basis.m_l.clone();
    let k_dyn: Vec<f64> = (0..nl).map(|j| k_l[(j, j)]).collect();
    let m_rows = departure(phi, &model.m, &m_l, 0..nl);
    let k_rows = departure(phi, &model.k, &k_dyn, ns..nl);
    report.offdiag = m_rows.iter().chain(&k_rows).fold(0.0f64, |a, &b| a.max(b));
    let lambda: Vec<f64> = (0..nl).map(|j| k_dyn[j] / m_l[j]).collect();
    check_departure(&m_rows, &k_rows, &lambda, basis.solved_norm)?;
    let k_full = (0..ns)
        .flat_map(|r| (r..nl).map(move |c| (r, c)))
        .map(|rc| k_l[rc])
        .collect();
    let k_diag = (ns..nl).map(|r| k_l[(r, r)]).collect();
    // With no static mode K_L is diagonal in the file: its frequencies need no solver.
    let freqs = if ns == 0 {
        let mut f: Vec<f64> = (0..nl)
            .map(|j| (k_l[(j, j)] / m_l[j]).max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect();
        f.sort_by(f64::total_cmp);
        f
    } else {
        eigenfrequencies_hz(k_l, &nalgebra::DVector::from_column_slice(&m_l))
    };
    let freqs: Vec<f64> = freqs.iter().map(|&f| model.scale.hz_out(f)).collect();
    let freq = freqs.last().copied().unwrap_or(0.0);
    report.frequencies_hz = freqs;
    report.freq = freq;
    report.nodes = node_ids.len();
    report.dofs = model.all.len();
    report.dofs_with_mass = model.a.len();
    let irot = model.all.iter().any(|d| d.comp >= 4);
    report.irot = irot;
    let local_modes = node_rows(model, &model.expand(phi), node_ids);
    let mut file = FxbFile {
        nbmod: nl,
        nbstat: ns,
        nbnod: node_ids.len(),
        irot,
        idamp: opts.damping.is_some(),
        iblo: props.is_none(),
        ifile: false,
        node_ids: node_ids.to_vec(),
        p0: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        freq,
        damping: opts.damping,
        rigid_modes: Vec::new(),
        local_modes,
        m_l,
        k_full,
        k_diag,
        m_r: Vec::new(),
        m_c: Vec::new(),
        k_c: Vec::new(),
    };
    let Some(p) = props else {
        to_true_units(&mut file, model.scale);
        return Ok(file);
    };
    let nr = if irot { 15 } else { 12 };
    let has = |d: Dof| {
        model
            .all
            .binary_search_by_key(&d.order_key(), Dof::order_key)
            .is_ok()
    };
    // Rigid modes at the nodes, global frame.
    let n = node_ids.len();
    let mut rigid = vec![0.0; nr * 6 * n];
    for (node, id) in node_ids.iter().enumerate() {
        for comp in 1..=6u8 {
            let present = has(Dof { id: *id, comp });
            for mode in 0..nr {
                rigid[mode * 6 * n + 6 * node + (comp - 1) as usize] =
                    mode_value(p.local[id], comp, mode, comp >= 4 && present);
            }
        }
    }
    file.rigid_modes = rigid;
    let dofs = model.a_dofs();
    let on_a = modes_on(&dofs, &p.local, nr, None, &has);
    let naive = {
        let m = on_a.transpose() * &model.m * &on_a;
        (&m + m.transpose()) * 0.5
    };
    let (exact, d) = p.m_r(irot);
    report.naive_m_r_diff = Some((&naive - &exact).norm() / exact.norm());
    if report.naive_m_r_diff.is_some_and(|v| v > 0.01) {
        report.warnings.push(Warning::Text(format!(
            "the naive M_R = Phi_R^T M Phi_R (what OpenRadioss builds from a reduced mass) \
             differs from the rotation-invariant one by {:.1}%: written is the invariant one",
            100.0 * report.naive_m_r_diff.unwrap_or(0.0)
        )));
    }
    report.rotary = irot.then_some(model.scale.mass_out(d));
    let m_r = if opts.naive_mass_r { naive } else { exact };
    file.m_r = (0..nr)
        .flat_map(|i| (i..nr).map(move |j| (i, j)))
        .map(|ij| m_r[ij])
        .collect();
    // All nine rotated rigid sets side by side, so that M_C and K_C are two products:
    // `(M T)^T Phi` is `T^T (M Phi)` without an n x n-by-nl product.
    let mut t_lk = DMatrix::zeros(dofs.len(), 9 * nr);
    let mut t_kl = DMatrix::zeros(dofs.len(), 9 * nr);
    for k in 0..3 {
        for l in 0..3 {
            let blk = 3 * k + l;
            t_lk.columns_mut(blk * nr, nr).copy_from(&modes_on(
                &dofs,
                &p.local,
                nr,
                Some((l, k)),
                &has,
            ));
            t_kl.columns_mut(blk * nr, nr).copy_from(&modes_on(
                &dofs,
                &p.local,
                nr,
                Some((k, l)),
                &has,
            ));
        }
    }
    let mc = dense::tr_mul(&dense::mul(&model.m, &t_lk), phi);
    let kc = dense::tr_mul(&dense::mul(&model.k, &t_kl), phi);
    let mut m_c = vec![0.0; 9 * nr * nl];
    let mut k_c = vec![0.0; 9 * nr * nl];
    for row in 0..9 * nr {
        for j in 0..nl {
            m_c[row * nl + j] = mc[(row, j)];
            k_c[row * nl + j] = kc[(row, j)];
        }
    }
    file.m_c = m_c;
    file.k_c = k_c;
    to_true_units(&mut file, model.scale);
    Ok(file)
}

/// The file's matrices back in the matrices' own units (the import works on K and M
/// scaled by powers of two, [`super::scale`]): exact.
fn to_true_units(file: &mut FxbFile, s: Scale) {
    for v in file
        .m_l
        .iter_mut()
        .chain(&mut file.m_r)
        .chain(&mut file.m_c)
    {
        *v = s.mass_out(*v);
    }
    for v in file
        .k_full
        .iter_mut()
        .chain(&mut file.k_diag)
        .chain(&mut file.k_c)
    {
        *v = s.stiffness_out(*v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eigenvectors of a diagonal K turned by a small angle in one plane: the departure
    /// estimate equals the closed-form off-diagonal `sin t cos t (k2 - k1) / sqrt(k1 k2)`,
    /// and the check refuses it while the exact eigenvectors pass.
    #[test]
    fn turned_modes_are_measured_and_refused() {
        let k = [1e6, 4e6, 9e6, 16e6];
        let a = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&k));
        let exact = DMatrix::identity(4, 4);
        let worst = |v: &[f64]| v.iter().fold(0.0f64, |m, &x| m.max(x));
        let d0 = departure(&exact, &a, &k, 0..4);
        assert!(worst(&d0) < 1e-15, "exact modes depart by {d0:?}");
        let ones = [1.0; 4];
        assert!(check_departure(&[0.0; 4], &d0, &k, 16e6).is_ok());

        let t: f64 = 1e-3;
        let mut turned = exact.clone();
        turned[(0, 0)] = t.cos();
        turned[(1, 0)] = t.sin();
        turned[(0, 1)] = -t.sin();
        turned[(1, 1)] = t.cos();
        let closed = t.sin() * t.cos() * (k[1] - k[0]) / (k[0] * k[1]).sqrt();
        let d = departure(&turned, &a, &k, 0..4);
        assert!(
            (worst(&d) - closed).abs() < 0.01 * closed,
            "estimate {d:?} vs closed form {closed}"
        );
        let msg = check_departure(&[0.0; 4], &d, &k, 16e6)
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("0.00150") && msg.contains("at most 1.0000000"),
            "{msg}"
        );
        // the floor: a mode 1e-12 of the solved matrix's norm may depart by FLOOR eps/1e-12
        let tiny = [1e-12, 1.0, 1.0, 1.0];
        let floor = FLOOR * f64::EPSILON / 1e-12;
        assert!(check_departure(&[0.0; 4], &[0.5 * floor, 0.0, 0.0, 0.0], &tiny, 1.0).is_ok());
        assert!(check_departure(&[0.0; 4], &[2.0 * floor, 0.0, 0.0, 0.0], &tiny, 1.0).is_err());
        assert!(check_departure(&[2e-6, 0.0, 0.0, 0.0], &[0.0; 4], &ones, 1.0).is_err());
    }
}
