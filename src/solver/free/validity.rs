//! When a free body has left what the methods or the model can answer for, and what the
//! product says then: a singular saddle-point system (with the step and spin rate that
//! made it so), a frame that is no longer a rotation (the step is refused), a spin rate
//! near the first local mode (a warning, once), the spin-rate bound of the explicit
//! method's internal step and the halving of an internal step the frame cannot follow.

use nalgebra::{DMatrix, Matrix3, Matrix6, Vector6};

use super::FreeScene;
use crate::num::num;
use crate::solver::{FrameAdvice, Invalid, Overflow, Singular, SolverError, SolverWarning};

/// Pivot ratio below which a saddle-point matrix counts as singular.
pub(crate) const SINGULAR_RATIO: f64 = 1e-13;

/// The error for a singular saddle-point system, with what was asked of it: the step
/// `dt` (0 for the evaluation at build, before any step: its matrix depends on the body
/// alone) and the frame's spin rate ([`Singular::SaddlePoint`] words it by what can be at
/// fault); NaN pivots or a non-finite spin are an overflow instead.
pub(crate) fn singular_error(ratio: f64, dt: f64, spin: f64) -> SolverError {
    if ratio.is_nan() || !spin.is_finite() {
        // Not a singular system: its numbers overflowed (NaN pivots), and neither the
        // ratio nor the spin is a figure worth printing.
        return overflow("the rigid-motion saddle-point system");
    }
    SolverError::Singular(Singular::SaddlePoint { ratio, dt, spin })
}

/// Largest `|P^T P - I|` (entry-wise) a step may leave: beyond it the frame is no longer
/// a rotation and the step is refused. The methods keep it near 1e-13 (implicit: Newton
/// tolerance on the constraints) and 1e-10 (explicit: the constraint rows act on the
/// predicted edges), so 1e-6 flags a broken frame long before positions go visibly wrong.
pub const MAX_FRAME_ERROR: f64 = 1e-6;

/// Spin rate, as a fraction of the first local mode's circular frequency, above which a
/// step warns once that the body has left the model's validity. The model leaves out the
/// centrifugal terms of the deformation (spin softening `-Omega^2` in the local stiffness,
/// geometric stiffening from the centrifugal pre-stress): both change the first mode's
/// `omega^2` by a fraction of order `(Omega / omega_1)^2`, 1 % at this ratio. It is also
/// where the model itself stops being trustworthy on a body whose local modes come from a
/// support (the truss tower reduced on a 3-2-1 support, tests/data/truss_supported.fxb,
/// the shipped truss until issue 28): spun about a tumbling axis it diverges with both
/// methods between 0.1 and 0.13 omega_1 (50 to 70 rad/s, omega_1 = 519 rad/s), so a
/// higher threshold would warn too late there (docs/STUDY.md, spin-rate stability).
pub const SPIN_WARN_RATIO: f64 = 0.1;

/// Largest rotation per internal step `|omega| dt` (rad) of the explicit method: its
/// internal step is at most `SPIN_STEP / |omega|` as well as `dt_factor x dt_fx`.
/// Measured by the study (docs/STUDY.md, spin-rate stability): the frame error the
/// scheme leaves is `|P^T P - I| ~ (|omega| dt)^4` (1e-8 at 0.01, 8e-7 at 0.03, 6e-6 at
/// 0.05 on the free-free beam), so 0.01 keeps it a factor 100 below the refusal at
/// `MAX_FRAME_ERROR`; the frame update itself stays bounded up to 0.5.
pub const SPIN_STEP: f64 = 0.01;

/// `|P^T P - I|`, largest entry: how far the frame is from a rotation.
pub(crate) fn frame_error(p: &Matrix3<f64>) -> f64 {
    let mut e: f64 = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            let d = p.column(i).dot(&p.column(j)) - if i == j { 1.0 } else { 0.0 };
            e = e.max(d.abs());
        }
    }
    if e.is_nan() { f64::INFINITY } else { e }
}

/// The refusal of a step whose numbers overflowed (`what` became non-finite): the cause
/// is a load or parameter too large for the body, not the step or the frame, whose
/// figures would read inf or NaN.
pub(crate) fn overflow(what: &str) -> SolverError {
    SolverError::NonFinite {
        what: what.into(),
        cause: Overflow::Inputs,
    }
}

/// The refusal of a step that would leave the frame no longer a rotation, with the
/// advice that fits the method (`advice`: what the user can change); a frame or spin rate
/// that overflowed is [`overflow`] instead.
pub(crate) fn frame_invalid(err: f64, h: f64, spin: f64, advice: FrameAdvice) -> SolverError {
    if !(err.is_finite() && spin.is_finite()) {
        return overflow("the body frame");
    }
    SolverError::Invalid(Invalid::Frame {
        h,
        error: err,
        spin,
        advice,
    })
}

/// Fraction of [`MAX_FRAME_ERROR`] above which the explicit method undoes an internal
/// step and redoes it in halves (1e-7). The frame error one internal step leaves is of
/// order `(dt^2 |b|)^2`, `b` the frame points' relative acceleration (`|omega|^2` from the
/// spin, `|alpha|` from an angular acceleration), so each halving divides it by about 16
/// (docs/STUDY.md, angular acceleration).
pub const FRAME_RETRY_FRACTION: f64 = 0.1;

/// Most halvings of one explicit internal step (down to `dt / 1024`) before the step is
/// refused: a frame acceleration that 1024 times smaller steps cannot follow is
/// `~1e6` times beyond what a normal internal step follows, a load the body cannot take.
pub const MAX_HALVINGS: u32 = 10;

/// Spin-rate check at the end of a step: when `|omega|` passes `SPIN_WARN_RATIO x
/// omega_1` for the first time in this solver's life, the warning (else `None`).
pub(crate) fn spin_warning(m: &FreeScene, spin: f64, warned: &mut bool) -> Option<SolverWarning> {
    if *warned || spin.is_nan() || spin <= SPIN_WARN_RATIO * m.omega1 {
        return None;
    }
    *warned = true;
    Some(SolverWarning::SpinRate {
        spin,
        omega1: m.omega1,
    })
}

/// Fraction of a local mode's mass dragged with the frame above which the explicit and
/// split methods warn at their first step (`SolverWarning::ModesDragRigidMotion`):
/// free-free modes drag nothing but round-off (below 1e-12 on the shipped beams); modes
/// computed on a support drag a sizeable fraction.
pub const DRAG_WARN: f64 = 1e-6;

/// The dragged fraction of the truss tower reduced on a 3-2-1 support
/// (tests/data/truss_supported.fxb), quoted by the warning. The shipped truss
/// (fixtures/truss.fxb, free-free modes) drags 1.2e-21 and is not warned about.
pub const TRUSS_DRAGGED: f64 = 0.9989;

/// The explicit method's relative energy gain per radian on that truss spun
/// torque-free at 0.018 of its first frequency with 1 ms communication steps (+3.4e-3
/// after 27 rad; `free::drag_warning::drag_gain_figures`).
pub const TRUSS_GAIN_EXPLICIT: f64 = 1.26e-4;

/// The split method's relative energy gain per radian on the same spin over its first
/// 100 rad (+1.87e-5 in all; `free::drag_warning::drag_gain_figures`).
pub const TRUSS_GAIN_SPLIT: f64 = 1.87e-7;

/// The split method's relative energy gain after 300 rad of the same spin: the gain
/// grows ever faster (+7.7e-5 after 200 rad, +1.8e-3 after 350, +1.1e-2 after 400).
pub const TRUSS_SPLIT_300: f64 = 4.0e-4;

/// The implicit method's relative energy change over 400 rad of the same spin, quoted
/// by the warning's remedy.
pub const TRUSS_IMPLICIT_400: f64 = 8.5e-6;

/// What the warning says the method does to the truss's energy (the measured figures).
pub fn drag_consequence(split: bool) -> String {
    if split {
        format!(
            "{} of its energy per radian turned over the first 100 rad, {} in all after \
             300 rad, the gain growing until the run diverges after about 400 rad",
            num(TRUSS_GAIN_SPLIT),
            num(TRUSS_SPLIT_300)
        )
    } else {
        format!(
            "{} of its energy per radian turned, its stable step collapsing after about \
             40 rad",
            num(TRUSS_GAIN_EXPLICIT)
        )
    }
}

/// The load-time check of the explicit (`split` false) and split methods: the warning
/// for a body whose modes drag rigid motion at P0 by more than [`DRAG_WARN`] (else
/// `None`).
pub(crate) fn drag_warning(m: &FreeScene, split: bool) -> Option<SolverWarning> {
    dragged_fraction(m, &m.p0)
        .filter(|&f| f > DRAG_WARN)
        .map(|fraction| SolverWarning::ModesDragRigidMotion { fraction, split })
}

/// How much the local modes drag rigid motion at the frame `p`: the largest eigenvalue
/// of `diag(m_L)^-1 B M6^-1 B^T` (`B = M_C^T G`, `M6 = G^T M_R G`), the largest fraction of
/// a mode's mass that moves the frame with it, in [0, 1) (0: free-free modes; along that
/// mode `m_eff` of the module text is `diag(m_L)` times one minus it). `None` when `M6` is
/// not positive definite (the builds refuse such a body). Read by [`drag_warning`].
fn dragged_fraction(m: &FreeScene, p: &Matrix3<f64>) -> Option<f64> {
    let (nr, nl) = (m.nr, m.nl);
    let m_r_rows: Vec<f64> = m.m_r.transpose().as_slice().to_vec();
    let chol = nalgebra::Cholesky::new(super::split::rigid::rigid_mass(&m_r_rows, nr, p))?;
    let mut mc = DMatrix::zeros(nr, nl);
    let mut kc = DMatrix::zeros(nr, nl);
    m.frame_matrices(p, &mut mc, &mut kc);
    let g = super::split::rigid::g_matrix(p, nr);
    // C = B^T diag(m_L)^-1 B (6 x 6), then the eigenvalues of L^-1 C L^-T, M6 = L L^T.
    let mut c = Matrix6::zeros();
    for j in 0..nl {
        let b = Vector6::from_fn(|k, _| (0..nr).map(|i| mc[(i, j)] * g[(i, k)]).sum());
        c += b * b.transpose() / m.m_l[j];
    }
    let linv = chol.l().try_inverse()?;
    let x = linv * c * linv.transpose();
    Some(
        ((x + x.transpose()) * 0.5)
            .symmetric_eigen()
            .eigenvalues
            .max(),
    )
}

/// `x` rounded to three significant digits, for a figure a message quotes.
pub fn three_digits(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let scale = 10f64.powi(2 - x.abs().log10().floor() as i32);
    (x * scale).round() / scale
}
