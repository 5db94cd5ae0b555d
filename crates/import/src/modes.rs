//! The local modes of an imported body: the eigenproblem `K phi = lambda M phi`, free or
//! blocked, and the cut at `--fmax` with static modes.
//!
//! The problem is made standard by a Cholesky factor of M (`M = L L^T`,
//! `A = L^-1 K L^-T`) and solved densely. For a free body the six rigid motions R are
//! first shifted out of the way, `A + sigma (L^T R) Rb^-1 (L^T R)^T`: that moves exactly
//! the rigid pairs to sigma and leaves the elastic ones, which are M-orthogonal to R,
//! untouched; each elastic mode is then re-projected to be M-orthogonal to R. Whether K
//! is singular, and where, is [`super::support`]'s question, decided before.
//!
//! `--fmax F` keeps the eigenmodes up to F and adds static modes for the unit loads on
//! the nodes' DOFs: the dropped modes' share of the static response, the flexibility's
//! response minus the kept modes' share (`static_modes`). They are M-orthonormal and M-
//! and K-orthogonal to the kept modes, so the static-dynamic block of K_L is zero, and the
//! static response at the nodes is that of the whole model (for a free body: the
//! inertia-relief response). With a cut, only the kept eigenvectors are computed
//! (tridiagonal bisection and inverse iteration, [`super::tridiag`]) when they are at most
//! a quarter of the modes.

use nalgebra::{DMatrix, DVector};

use super::ImportError;
use super::dense;
use super::dofs::Reduced;
use super::report::{Report, Resolution};
use super::rigid::MassProps;
use super::support::NEGATIVE;

/// Singular values of the dropped modes' static share below this fraction of the
/// largest add no static mode.
pub const STATIC_TOL: f64 = 1e-8;
/// Relative slack on `--fmax`, so that a printed frequency used as fmax keeps its mode.
const FMAX_SLACK: f64 = 1e-9;

/// The Cholesky factor of M and the standard-form matrix `A = L^-1 K L^-T`.
#[derive(Debug, Clone)]
pub struct StandardForm {
    /// Lower Cholesky factor of M.
    pub l: DMatrix<f64>,
    /// `L^-1 K L^-T`, symmetric.
    pub a: DMatrix<f64>,
}

impl StandardForm {
    /// Factor M (refusing a negative or singular one) and form A.
    pub fn factor(model: &Reduced) -> Result<StandardForm, ImportError> {
        let Some(l) = dense::cholesky(&model.m) else {
            let e = dense::sym_eigenvalues(&model.m).unwrap_or_default();
            let (lo, hi) = (
                e.first().copied().unwrap_or(f64::NAN),
                e.last().copied().unwrap_or(f64::NAN),
            );
            let out = |x: f64| model.scale.mass_out(x);
            return Err(if lo < -NEGATIVE * hi.abs() {
                ImportError::NegativeMass {
                    value: out(lo),
                    largest: out(hi),
                }
            } else {
                ImportError::SingularMass {
                    value: out(lo),
                    largest: out(hi),
                }
            });
        };
        let a = dense::congruence_inverse(&l, &model.k);
        Ok(StandardForm { l, a })
    }
}

/// The elastic modes an import keeps and the eigenvalues of those it drops.
#[derive(Debug, Clone)]
pub struct Elastic {
    /// Kept eigenvalues, ascending.
    pub lambda: Vec<f64>,
    /// Kept modes on the a-set, M-orthonormal (and for a free body M-orthogonal to the
    /// rigid motions), one column each.
    pub phi: DMatrix<f64>,
    /// Eigenvalues dropped by the cut, ascending.
    pub dropped: Vec<f64>,
    /// The largest eigenvalue magnitude of the matrix the eigen-solver took (a free
    /// body's with its rigid pairs shifted up): its absolute accuracy is round-off of
    /// this, so a mode of eigenvalue lambda is accurate to `eps solved_norm / lambda`.
    pub solved_norm: f64,
}

/// Above this worst-case relative accuracy of the lowest eigenvalue
/// (`eps |A| / lambda_min`) the import says how far double precision determines it: a
/// 500-element frame's lowest is at 3.6e-14 of the largest, 6e-3 (its frequency agrees
/// with LAPACK's to 1.7e-5: the bound is the worst case).
const RESOLUTION_WARN: f64 = 1e-3;

/// A warning when double precision guarantees the lowest eigenvalue only to
/// `eps |A| / lambda_min` above `RESOLUTION_WARN`, which is also what a free body's
/// rigid modes look like when the matrices' rounding left them slightly stiff (a 10-digit
/// punch: 5.7e-15 of the largest) and the body was imported as held without coordinates
/// (its rigid motions unknown: [`Resolution::maybe_free`]); `None` else.
pub fn resolution_warning(el: &Elastic, free: bool, coords: bool) -> Option<Resolution> {
    let lowest = *el.lambda.first()?;
    let ratio = lowest / el.solved_norm;
    let accuracy = f64::EPSILON / ratio;
    if accuracy <= RESOLUTION_WARN {
        return None;
    }
    let two = |x: f64| format!("{x:.1e}").parse().unwrap_or(x);
    Some(Resolution {
        ratio: two(ratio),
        accuracy: two(accuracy),
        maybe_free: !(free || coords),
    })
}

/// With a cut keeping at most this share of the modes, only the kept eigenvectors are
/// computed ([`super::tridiag`]); above it faer's full eigen-solver is cheaper.
const PARTIAL_SHARE: usize = 4;

/// The elastic eigenpairs, ascending, up to the eigenvalue `cut` when given: eigenvalues
/// and M-orthonormal modes on the a-set. For a free body (`props` given) the rigid pairs
/// are removed and every mode is M-orthogonal to the rigid motions. K must have passed
/// [`super::support::classify`]; a lowest eigenvalue at round-off is refused as a spread
/// beyond double precision. `stage` is told when each step ends (the import's profile).
pub fn elastic(
    model: &Reduced,
    form: &StandardForm,
    props: Option<&MassProps>,
    cut: Option<f64>,
    stage: &mut dyn FnMut(&str),
) -> Result<Elastic, ImportError> {
    let n = form.a.nrows();
    let a = match props {
        Some(p) => shifted(&form.a, &form.l, p)?,
        None => form.a.clone(),
    };
    stage("rigid shift");
    let nel = if props.is_some() {
        n.saturating_sub(6)
    } else {
        n
    };
    let failed = || ImportError::Invalid("the eigen-solver did not converge".into());
    // With a cut: the eigenvalues first, then the kept eigenvectors only, unless most are
    // kept. Without: every pair.
    let reduction = match cut {
        Some(_) if n >= 2 => Some(dense::tridiagonalize(&a).ok_or_else(failed)?),
        _ => None,
    };
    let (values, vectors) = match &reduction {
        Some(r) => {
            let mut values = r.eigenvalues().ok_or_else(failed)?;
            let kept = kept_count(&values[..nel], cut);
            if kept * PARTIAL_SHARE <= n {
                for (k, v) in values.iter_mut().enumerate().take(kept) {
                    *v = r.eigenvalue(k);
                }
                let v = r.eigenvectors(&values[..kept]);
                (values, v)
            } else {
                dense::sym_eigen(&a).ok_or_else(failed)?
            }
        }
        None => dense::sym_eigen(&a).ok_or_else(failed)?,
    };
    stage("eigen-solve");
    // Ascending: the elastic pairs first (a free body's rigid pairs were shifted up).
    // K (or K with the rigid motions stiffened) is definite (support::classify): a
    // lowest eigenvalue at or below zero is the eigen-solve's round-off of the largest.
    let lambda: Vec<f64> = values[..nel].to_vec();
    let top = lambda.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if let Some(&lo) = lambda.first()
        && (lo <= 0.0 || lo.is_nan())
    {
        return Err(ImportError::Unresolved {
            lowest: model.scale.eigenvalue_out(lo),
            largest: model.scale.eigenvalue_out(top),
        });
    }
    let kept = kept_count(&lambda, cut);
    let v = vectors.columns(0, kept).into_owned();
    let mut phi = dense::solve_lower_transposed(&form.l, &v);
    if let Some(p) = props {
        // Re-project: phi -= R Rb^-1 (M R)^T phi (M R is n x 6: no n x n product).
        let rb_inv = p.rb.clone().try_inverse().expect("checked above");
        let c = rb_inv * dense::tr_mul(&(&model.m * &p.r), &phi);
        phi -= &p.r * c;
    }
    stage("back-solve L^-T, projection");
    Ok(Elastic {
        dropped: lambda[kept..].to_vec(),
        lambda: lambda[..kept].to_vec(),
        phi,
        solved_norm: values.iter().fold(0.0f64, |m, v| m.max(v.abs())),
    })
}

/// `A + sigma U Rb^-1 U^T` with `U = L^T R`: the standard-form matrix `a` with the six
/// rigid pairs of `props` moved to sigma, above every elastic eigenvalue (`|A|_inf`
/// bounds them), and the elastic pairs, M-orthogonal to R, untouched. No larger: the
/// solver's absolute error grows with the shifted matrix's norm (with 2 |A|_F, 13 times
/// the largest eigenvalue of a 2040-DOF grillage, it was that much larger). Symmetric
/// (Rb is); only the lower triangle is formed, which is all the solvers read.
pub fn shifted(
    a: &DMatrix<f64>,
    l: &DMatrix<f64>,
    props: &MassProps,
) -> Result<DMatrix<f64>, ImportError> {
    let n = a.nrows();
    let mut out = a.clone();
    let sigma = 2.0 * dense::inf_norm(a) + f64::MIN_POSITIVE;
    let u = l.transpose() * &props.r;
    let rb_inv = props
        .rb
        .clone()
        .try_inverse()
        .ok_or_else(|| ImportError::NoModes("the rigid mass R^T M R is singular".into()))?;
    let w = (&u * rb_inv) * sigma;
    for j in 0..n {
        for i in j..n {
            out[(i, j)] += (0..6).map(|c| w[(i, c)] * u[(j, c)]).sum::<f64>();
        }
    }
    Ok(out)
}

/// How many of the ascending eigenvalues `lambda` are at or below `cut` (all without).
fn kept_count(lambda: &[f64], cut: Option<f64>) -> usize {
    cut.map_or(lambda.len(), |c| lambda.iter().filter(|&&l| l <= c).count())
}

/// The eigenvalue of the frequency `fmax` (Hz), with the relative slack that keeps a
/// printed frequency's mode.
pub fn cut_eigenvalue(fmax: f64) -> f64 {
    let w = 2.0 * std::f64::consts::PI * fmax * (1.0 + FMAX_SLACK);
    w * w
}

/// The local modes on the a-set, static modes first, how many are static, and their
/// generalised mass and stiffness.
///
/// `m_l` and `k_l` come from the eigen relations, not from `Phi^T M Phi` and
/// `Phi^T K Phi` (two n x n-by-nl products, a third of a 3000-DOF import): before scaling
/// the columns are M-orthonormal (`Phi^T M Phi = I`, `Phi^T K Phi = Lambda`), the static
/// modes are M- and K-orthogonal to the kept ones, and a column scaled by `f` has its row
/// and column of both scaled by `f`.
#[derive(Debug, Clone)]
pub struct Basis {
    /// Modes on the a-set, one per column, each scaled so that its largest nodal
    /// translation at the FXB nodes is +1.
    pub phi: DMatrix<f64>,
    /// The first `nbstat` columns are static modes.
    pub nbstat: usize,
    /// Generalised masses `phi_j^T M phi_j` (the scale factors squared).
    pub m_l: Vec<f64>,
    /// `Phi^T K Phi`: a full static block, the eigenvalues (scaled) on the rest of the
    /// diagonal, zero elsewhere.
    pub k_l: DMatrix<f64>,
    /// [`Elastic::solved_norm`].
    pub solved_norm: f64,
}

/// Add static modes for the nodes `node_ids` to the kept modes `el` (see the module
/// text), then scale every mode. `l` is M's Cholesky factor; `props` is given for a free
/// body.
pub fn local_basis(
    model: &Reduced,
    el: &Elastic,
    l: &DMatrix<f64>,
    props: Option<&MassProps>,
    node_ids: &[i64],
    report: &mut Report,
) -> Result<Basis, ImportError> {
    let hz = |l: f64| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI);
    let kept = el.lambda.len();
    let (statics, k_s) = if el.dropped.is_empty() {
        (DMatrix::zeros(model.a.len(), 0), DMatrix::zeros(0, 0))
    } else {
        report.dropped_hz = el
            .dropped
            .iter()
            .map(|&l| model.scale.hz_out(hz(l)))
            .collect();
        static_modes(model, el, l, props, node_ids)?
    };
    let nbstat = statics.ncols();
    let mut cols: Vec<DVector<f64>> = statics.column_iter().map(|c| c.into_owned()).collect();
    for j in 0..kept {
        cols.push(el.phi.column(j).into_owned());
    }
    if cols.is_empty() {
        return Err(ImportError::NoModes(
            "the body has no elastic mode to keep".into(),
        ));
    }
    let mut phi_l = DMatrix::from_columns(&cols);
    let f = scale(model, &mut phi_l, node_ids);
    let nl = phi_l.ncols();
    let mut k_l = DMatrix::zeros(nl, nl);
    for i in 0..nbstat {
        for j in 0..nbstat {
            k_l[(i, j)] = f[i] * f[j] * k_s[(i, j)];
        }
    }
    for j in nbstat..nl {
        k_l[(j, j)] = f[j] * f[j] * el.lambda[j - nbstat];
    }
    let m_l = f.iter().map(|f| f * f).collect();
    report.kept_modes = kept;
    report.static_modes = nbstat;
    Ok(Basis {
        phi: phi_l,
        nbstat,
        m_l,
        k_l,
        solved_norm: el.solved_norm,
    })
}

/// The static modes of a cut and their stiffness block `Q^T K Q`.
///
/// The dropped modes' share of the static response to the unit loads F on the nodes is
/// `S = G F - Phi_k Lambda_k^-1 Phi_k^T F`, with G the flexibility on the elastic modes:
/// `K^-1` for a blocked body; for a free one `P K_s^-1 P^T` with the M-orthogonal
/// projector `P = I - R Rb^-1 (M R)^T` off the rigid motions and `K_s = K + c (M R) Rb^-1
/// (M R)^T`, which is positive definite and equal to K on the elastic modes. S lies in
/// the dropped modes' span; the static modes are its M-orthonormal left singular vectors
/// (`L^-T` of those of `L^T S`), singular values below [`STATIC_TOL`] of the largest
/// left out, largest first. This needs neither the dropped eigenvectors nor their
/// eigenvalues.
fn static_modes(
    model: &Reduced,
    el: &Elastic,
    l: &DMatrix<f64>,
    props: Option<&MassProps>,
    node_ids: &[i64],
) -> Result<(DMatrix<f64>, DMatrix<f64>), ImportError> {
    let loads = model.grid_loads(node_ids);
    let not_pd = || {
        ImportError::Invalid(
            "K is not positive definite on the elastic modes (its Cholesky factor failed)".into(),
        )
    };
    let mut g_f = match props {
        None => {
            let lk = dense::cholesky(&model.k).ok_or_else(not_pd)?;
            dense::solve_lower_transposed(&lk, &dense::solve_lower(&lk, &loads))
        }
        Some(p) => {
            let rb_inv = p.rb.clone().try_inverse().expect("checked by elastic");
            let mr = &model.m * &p.r;
            // c: the largest elastic eigenvalue, so that K_s is as well scaled as K
            let c = el.dropped.last().copied().unwrap_or(1.0);
            let w = &mr * &rb_inv;
            let mut k_s = &model.k + (&w * mr.transpose()) * c;
            k_s = (&k_s + k_s.transpose()) * 0.5;
            let lk = dense::cholesky(&k_s).ok_or_else(not_pd)?;
            let relieved = &loads - &w * (p.r.transpose() * &loads);
            let x = dense::solve_lower_transposed(&lk, &dense::solve_lower(&lk, &relieved));
            let proj = rb_inv * dense::tr_mul(&mr, &x);
            x - &p.r * proj
        }
    };
    let pk = &el.phi;
    let inv = DMatrix::from_diagonal(&DVector::from_iterator(
        el.lambda.len(),
        el.lambda.iter().map(|l| 1.0 / l),
    ));
    g_f -= pk * (inv * dense::tr_mul(pk, &loads));
    // Round-off off the kept modes' span: S -= Phi_k (Phi_k^T M S).
    let ms = dense::mul(&model.m, &g_f);
    g_f -= pk * dense::tr_mul(pk, &ms);
    let w = l.transpose() * &g_f;
    let svd = w.svd(true, false);
    let u = svd.u.expect("requested");
    let smax = svd.singular_values.max();
    let mut idx: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&i| svd.singular_values[i] > STATIC_TOL * smax)
        .collect();
    idx.sort_by(|&i, &j| svd.singular_values[j].total_cmp(&svd.singular_values[i]));
    let picked = DMatrix::from_columns(&idx.iter().map(|&i| u.column(i)).collect::<Vec<_>>());
    if picked.ncols() == 0 {
        return Ok((DMatrix::zeros(model.a.len(), 0), DMatrix::zeros(0, 0)));
    }
    let q = dense::solve_lower_transposed(l, &picked);
    let kq = dense::tr_mul(&q, &dense::mul(&model.k, &q));
    Ok((q, (&kq + kq.transpose()) * 0.5))
}

/// Scale each mode so that its largest translation at the FXB nodes is +1 (else its
/// largest rotation there; a mode with neither keeps its unit M-norm). Returns the
/// factors.
fn scale(model: &Reduced, phi: &mut DMatrix<f64>, node_ids: &[i64]) -> Vec<f64> {
    let full = model.expand(phi);
    let mut factors = vec![1.0; phi.ncols()];
    let on_node: Vec<bool> = model
        .all
        .iter()
        .map(|d| !d.is_scalar() && node_ids.contains(&d.id))
        .collect();
    for j in 0..phi.ncols() {
        let mut best = [(0.0f64, 0.0f64); 2];
        for (i, d) in model.all.iter().enumerate() {
            if !on_node[i] {
                continue;
            }
            let v = full[(i, j)];
            let slot = usize::from(d.comp >= 4);
            if v.abs() > best[slot].0 {
                best[slot] = (v.abs(), v);
            }
        }
        let pick = if best[0].0 > 0.0 {
            best[0].1
        } else {
            best[1].1
        };
        if pick != 0.0 {
            factors[j] = 1.0 / pick;
            phi.column_mut(j).scale_mut(factors[j]);
        }
    }
    factors
}
