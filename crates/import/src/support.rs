//! Free or blocked: whether K's null space is what the body's support says, decided by
//! tests that are relative and independent of the model's scale, size and conditioning.
//!
//! - **Held (blocked)**: K must be positive definite. Decided by a Cholesky factor of K
//!   scaled to a unit diagonal ([`dense::definiteness`]): its pivots do not depend on the
//!   rows' units and stay far from round-off for any realistic model (a 2,970-DOF frame
//!   whose lowest eigenvalue is 4e-14 of its largest: smallest pivot 1.6e-8), while a
//!   singular K fails or leaves a pivot at round-off. The eigenvalues alone cannot tell
//!   those apart: a real model's lowest reaches 4e-14 of the largest, where a rigid mode
//!   of the same model written to 10 digits lands (1.9e-14 measured).
//! - **Free**: the six rigid motions R of the coordinates must be in K's null space
//!   (`|K r| / (|K| |r|)` at most [`RIGID_TOL`]) and nothing else: K plus a stiffness on
//!   the rigid motions, `K + c (M R) (R^T M R)^-1 (M R)^T`, must be positive definite,
//!   else the body is a mechanism.
//! - **Detect**: free when the coordinates' rigid motions are zero-energy motions of K,
//!   blocked when K is positive definite. When K is singular but the coordinates' rigid
//!   motions are not its null space, that is said first, with the power of ten that makes
//!   them fit when there is one (coordinates in mm for matrices in m), before supports or
//!   `--free` are suggested.
//!
//! Counts of zero-energy modes (for messages) come from the eigenvalues: those below the
//! largest gap (on a log scale) among the eigenvalues under 1e-6 of the largest.

use nalgebra::DMatrix;

use super::dense;
use super::dofs::Reduced;
use super::modes::{StandardForm, shifted};
use super::report::Report;
use super::rigid::{MOTIONS, MassProps};
use super::{ImportError, SingularHint, Support};
use fxbody::num::num;

/// A rigid motion whose `|K r| / (|K|_F |r|)` exceeds this is not in K's null space.
pub const RIGID_TOL: f64 = 1e-6;

/// A unit-diagonal Cholesky pivot at or below `PIVOT_ROUND_OFF n eps` is round-off: the
/// matrix is singular in working precision. A singular stiffness leaves pivots near
/// `eps` or fails; definite ones of every model measured stay at 1e-8 and above at
/// 3,000 DOFs.
const PIVOT_ROUND_OFF: f64 = 100.0;

/// Eigenvalues below this fraction of the largest are candidates for zero-energy modes
/// in the counts of messages.
const CANDIDATE: f64 = 1e-6;

/// The largest eigenvalue, relative to the largest, that a zero-energy mode shows: the
/// round-off of the eigen-solve (1e-16 to 2e-14 measured) or of matrices written to 10
/// digits.
const ZERO_AT_MOST: f64 = 1e-9;

/// An eigenvalue below `-NEGATIVE` times the largest is a negative stiffness, not
/// round-off of a zero-energy mode.
pub const NEGATIVE: f64 = 1.5e-8;

/// Whether the symmetric stiffness-type `a` is positive definite in working precision;
/// `Err(row)` where its factorisation failed or left a round-off pivot.
pub fn definite(a: &DMatrix<f64>) -> Result<(), usize> {
    let d = dense::definiteness(a);
    let tol = PIVOT_ROUND_OFF * a.nrows() as f64 * f64::EPSILON;
    if d.min_pivot > tol { Ok(()) } else { Err(d.at) }
}

/// How many of the ascending eigenvalues `values` of a singular matrix are zero-energy
/// modes: those below the largest gap (ratio of neighbours, on absolute values) among
/// the ones under `CANDIDATE` of the largest, the gap's lower side at most
/// `ZERO_AT_MOST`; at least `at_least`. For messages: whether the matrix is singular
/// is decided by [`definite`].
pub fn zero_count(values: &[f64], at_least: usize) -> usize {
    let top = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let floor = f64::MIN_POSITIVE.max(top * f64::EPSILON * f64::EPSILON);
    let mut small: Vec<f64> = values
        .iter()
        .map(|v| v.abs())
        .filter(|&v| v <= CANDIDATE * top)
        .collect();
    small.sort_by(f64::total_cmp);
    let next = values
        .iter()
        .map(|v| v.abs())
        .filter(|&v| v > CANDIDATE * top)
        .fold(top, f64::min);
    let mut best = (0.0f64, 0);
    // a zero-energy mode is round-off, or the input's rounding at most (10 digits)
    for i in (0..small.len()).filter(|&i| small[i] <= ZERO_AT_MOST * top) {
        let above = small.get(i + 1).copied().unwrap_or(next);
        let gap = above / small[i].max(floor);
        if gap > best.0 {
            best = (gap, i + 1);
        }
    }
    best.1.max(at_least)
}

/// Relative residuals `|K r| / (|K|_F |r|)` of the six rigid motions, and for each the
/// a-set row with the largest `|K r|`.
pub fn rigid_residuals(model: &Reduced, props: &MassProps) -> Vec<(f64, usize)> {
    let kn = model.k.norm();
    let kr = &model.k * &props.r;
    (0..6)
        .map(|i| {
            let col = kr.column(i);
            let rel = col.norm() / (kn * props.r.column(i).norm());
            (if rel.is_nan() { f64::INFINITY } else { rel }, col.iamax())
        })
        .collect()
}

/// The power of ten `p` such that the coordinates divided by `p` make the three rigid
/// rotations zero-energy motions of K (coordinates in mm for matrices in m: 1000), when
/// there is one other than 1. A rotation about the centre of mass moves the nodes by
/// `w x (x - c)`, which scales with the coordinates, and turns the rotational DOFs by
/// `w`, which does not: `K (s t + q) = 0` is solved for s by least squares, per axis.
fn units_ratio(model: &Reduced, props: &MassProps) -> Option<f64> {
    let dofs = model.a_dofs();
    let mut estimates = Vec::new();
    for axis in 3..6 {
        let r = props.r.column(axis);
        let (mut t, mut q) = (r.into_owned(), r.into_owned());
        for (row, d) in dofs.iter().enumerate() {
            if (1..=3).contains(&d.comp) {
                q[row] = 0.0;
            } else {
                t[row] = 0.0;
            }
        }
        let (kt, kq) = (&model.k * &t, &model.k * &q);
        let s = -kt.dot(&kq) / kt.dot(&kt);
        if !(s.is_finite() && s > 0.0) {
            return None;
        }
        let fit = (&kt * s + &kq).norm() / (model.k.norm() * (&t * s + &q).norm());
        if fit.is_nan() || fit > RIGID_TOL {
            return None;
        }
        estimates.push(s);
    }
    let s = estimates.iter().sum::<f64>() / 3.0;
    let e = s.log10().round();
    let p = 10f64.powf(e);
    (e != 0.0 && estimates.iter().all(|&x| (x / p - 1.0).abs() < 1e-2)).then_some(1.0 / p)
}

/// What a units ratio means, as pack says it.
fn units_text(p: f64) -> String {
    format!(
        "units? the coordinates are {} times what fits K's zero-energy modes (ratio 1e{}: \
         e.g. coordinates in mm for matrices in m): give them in the matrices' length unit",
        num(p),
        p.log10().round()
    )
}

/// Zero-energy modes of K (eigenvalues of `form.a`), at least one: for a K that is not
/// definite.
fn k_zero_count(form: &StandardForm) -> Result<usize, ImportError> {
    let values = dense::sym_eigenvalues(&form.a)
        .ok_or_else(|| ImportError::Invalid("the eigen-solver did not converge".into()))?;
    negative_check(&values)?;
    Ok(zero_count(&values, 1))
}

/// Refuses a clearly negative eigenvalue (below [`NEGATIVE`] of the largest).
fn negative_check(values: &[f64]) -> Result<(), ImportError> {
    let top = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    match values.first() {
        Some(&lo) if lo < -NEGATIVE * top => Err(ImportError::NegativeStiffness {
            value: lo,
            largest: top,
        }),
        _ => Ok(()),
    }
}

/// The refusal of coordinates whose rigid motions are not K's zero-energy motions, with
/// what K's null space says (module text).
fn not_rigid(
    model: &Reduced,
    props: &MassProps,
    res: &[(f64, usize)],
    form: &StandardForm,
    definite_k: bool,
) -> ImportError {
    let (i, &(rel, row)) = res
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.0.total_cmp(&b.1.0))
        .expect("six motions");
    let units = units_ratio(model, props);
    let held = definite_k && units.is_none();
    let diagnosis = if let Some(p) = units {
        format!("; {}", units_text(p))
    } else if held {
        "; K has no zero-energy mode: the matrices are of a held body".to_string()
    } else {
        match k_zero_count(form) {
            Err(e) => return e,
            Ok(6) => "; K has 6 zero-energy modes, as a free body has, but not these: the \
                      coordinates do not belong to the matrices (rounded, in other units, or \
                      of other node IDs)"
                .to_string(),
            Ok(z) => format!(
                "; K has {z} zero-energy modes (a free body has 6): the matrices are partly \
                 constrained, or the coordinates, units or IDs do not belong to them"
            ),
        }
    };
    ImportError::NotRigid {
        motion: MOTIONS[i].to_string(),
        rel,
        dof: model.all[model.a[row]],
        diagnosis,
        held,
    }
}

/// Decide free or blocked (see [`Support`] and the module text) and check K against it.
/// Returns `true` for a free body.
pub fn classify(
    model: &Reduced,
    props: Option<&MassProps>,
    support: Support,
    form: &StandardForm,
    report: &mut Report,
) -> Result<bool, ImportError> {
    let res = props.map(|p| rigid_residuals(model, p));
    let all_rigid = res
        .as_ref()
        .is_some_and(|r| r.iter().all(|&(rel, _)| rel <= RIGID_TOL));
    if let Some(r) = &res {
        report.rigid_residuals = r.iter().map(|&(rel, _)| rel).collect();
    }
    let free = match (support, props) {
        (Support::Free, None) => return Err(ImportError::CoordinatesNeeded),
        (Support::Free, Some(p)) => {
            if !all_rigid {
                let definite_k = definite(&model.k).is_ok();
                return Err(not_rigid(
                    model,
                    p,
                    res.as_deref().unwrap_or(&[]),
                    form,
                    definite_k,
                ));
            }
            true
        }
        (Support::Detect, _) if all_rigid => true,
        // K does not resist the coordinates' rigid motions (to 1e-6): a free body, even
        // when the matrices' rounding (a punch's 10 digits) leaves K definite
        (Support::Blocked, _) if all_rigid => {
            return Err(ImportError::SingularBlocked {
                zero: 6,
                first: String::new(),
                hint: Some(SingularHint::RigidMotions),
            });
        }
        (Support::Blocked | Support::Detect, _) => {
            if definite(&model.k).is_ok() {
                false
            } else if let (Support::Detect, Some(p)) = (support, props) {
                return Err(not_rigid(
                    model,
                    p,
                    res.as_deref().unwrap_or(&[]),
                    form,
                    false,
                ));
            } else {
                let first = props
                    .and_then(|p| units_ratio(model, p))
                    .map(|p| {
                        format!(
                            "units? the coordinates divided by {} (ratio 1e{}: e.g. \
                             coordinates in mm for matrices in m) make K's zero-energy modes \
                             exactly their rigid motions, as for a free body; ",
                            num(p),
                            p.log10().round()
                        )
                    })
                    .unwrap_or_default();
                let hint = (props.is_none() && matches!(support, Support::Detect))
                    .then_some(SingularHint::GiveCoords);
                return Err(ImportError::SingularBlocked {
                    zero: k_zero_count(form)?,
                    first,
                    hint,
                });
            }
        }
    };
    if free {
        // nothing but the rigid motions in K's null space
        let p = props.expect("free bodies have mass properties");
        let c = dense::inf_norm(&form.a);
        let mr = &model.m * &p.r;
        let rb_inv =
            p.rb.clone()
                .try_inverse()
                .ok_or_else(|| ImportError::NoModes("the rigid mass R^T M R is singular".into()))?;
        let w = &mr * rb_inv;
        let mut k_s = &model.k + (&w * mr.transpose()) * c;
        k_s = (&k_s + k_s.transpose()) * 0.5;
        if definite(&k_s).is_err() {
            let a = shifted(&form.a, &form.l, p)?;
            let values = dense::sym_eigenvalues(&a)
                .ok_or_else(|| ImportError::Invalid("the eigen-solver did not converge".into()))?;
            negative_check(&values)?;
            return Err(ImportError::Mechanism(zero_count(&values, 1) + 6));
        }
    }
    report.free = free;
    Ok(free)
}

#[cfg(test)]
mod tests {
    use super::zero_count;

    /// The count takes the largest gap among the small eigenvalues: six round-off ones
    /// (some negative) under a first elastic one at 1e-12 of the largest, or at 4e-14 (a
    /// 500-element frame) when the zeros are at 1e-17.
    #[test]
    fn zero_count_takes_the_largest_gap() {
        let zeros = [-3e-17, -1e-18, 2e-19, 4e-18, 1e-17, 6e-17];
        let elastic = [
            1e-12, 3e-12, 8e-12, 2e-11, 6e-11, 2e-10, 6e-10, 2e-9, 1e-8, 1.0,
        ];
        let mut v: Vec<f64> = zeros.iter().chain(&elastic).copied().collect();
        assert_eq!(zero_count(&v, 0), 6);
        v[6] = 4e-14;
        v[7] = 8e-14;
        assert_eq!(zero_count(&v, 0), 6);
        // punched input: the sixth rigid mode at 1.9e-14, the first elastic at 8e-6
        let w = [
            -7e-17, -5e-18, 3e-17, 4e-16, 1e-15, 1.9e-14, 8.35e-6, 2.8e-5, 1e-4, 1.0,
        ];
        assert_eq!(zero_count(&w, 0), 6);
        // two zeros of different round-off
        let m = [1e-17, 2e-15, 2e-7, 3e-7, 8e-7, 2e-6, 1.0];
        assert_eq!(zero_count(&m, 0), 2);
        // nothing small: the count a failed factorisation asks for
        assert_eq!(zero_count(&[1e-3, 1.0], 1), 1);
    }
}
