//! The physical checks on a body's quantities, shared by the `.fxb` load and the scene
//! file's read ([`super`] holds the error type and the two entry points): the frame, the
//! masses and damping, the modes of (K_L, m_L) and their frequencies against the stored
//! Freq, the rigid modes' affine form and M_R on the rigid motions.

use nalgebra::{DMatrix, DVector, Matrix3};

use super::{Body, BodyError};
use crate::num::num;

/// Relative tolerance for "positive semi-definite" (round-off of 10 printed digits).
const PSD_TOL: f64 = 1e-8;

/// Ratio below which the rotational inertia about some axis counts as zero.
const SINGULAR_TOL: f64 = 1e-10;

/// Relative residual above which stored modes are not the modes of (K_L, m_L): the
/// eigen-solver leaves about `nL eps`, printed digits do not enter (the scene file holds
/// the bits `pack` computed).
const MODES_TOL: f64 = 1e-8;

/// Relative tolerance of the rigid modes' affine form, against the node's largest local
/// coordinate (at least 1): 10 printed digits leave 1e-10.
const AFFINE_TOL: f64 = 1e-8;

/// How far the largest computed eigenfrequency of (K_L, m_L) may lie above the stored
/// Freq before the file counts as corrupt. Every writer's Freq is at or above its modes'
/// frequencies, or within round-off of the largest: FORMULATION's rule and `fxbody
/// import` write the largest eigenfrequency (the shipped fixtures and test bodies agree
/// with it to 1e-10), OpenRadioss writes its cut-off, above every mode it keeps. Radioss
/// takes its stable step from Freq, so a mode even 10% above it already makes Radioss
/// unstable; three orders of magnitude is a mass or stiffness off by six (the cantilever
/// with m_L(1) = 1e-300: 1.7e149 times), never a writer's convention.
pub const FREQ_RATIO: f64 = 1e3;

/// Where each quantity is, in the file it was read from: block numbers of a `.fxb` file
/// ([`Places::FXB`]), sections of a scene file ([`Places::SCENE`]). The messages name it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Places {
    /// P0 and Freq.
    pub frame: &'static str,
    /// The Rayleigh coefficients.
    pub damping: &'static str,
    /// m_L.
    pub mass: &'static str,
    /// K_L.
    pub stiffness: &'static str,
    /// m_L and K_L together.
    pub mass_stiffness: &'static str,
    /// The modes of (K_L, m_L): computed from blocks 8-10 of a `.fxb` file, stored in a
    /// scene file.
    pub modes: &'static str,
    /// The rigid modes.
    pub rigid_modes: &'static str,
    /// M_R.
    pub rigid_mass: &'static str,
}

impl Places {
    /// The blocks of a `.fxb` file (FORMULATION.md section 1).
    pub const FXB: Places = Places {
        frame: "block 3 (initial frame P0 and Freq)",
        damping: "block 4 (Rayleigh damping)",
        mass: "block 8 (local mass m_L)",
        stiffness: "blocks 9-10 (local stiffness K_L)",
        mass_stiffness: "blocks 8-10 (m_L, K_L)",
        modes: "blocks 8-10 (m_L, K_L)",
        rigid_modes: "block 5 (rigid modes)",
        rigid_mass: "block 11 (rigid mass M_R)",
    };
    /// The sections of a scene file (docs/SCENE_FORMAT.md).
    pub const SCENE: Places = Places {
        frame: "section BODY (initial frame P0 and Freq)",
        damping: "section BODY (Rayleigh damping)",
        mass: "section MASS (local mass m_L)",
        stiffness: "section STIF (local stiffness K_L)",
        mass_stiffness: "sections MASS and STIF (m_L, K_L)",
        modes: "sections MASS, STIF and MODE (m_L, K_L and their modes)",
        rigid_modes: "section PHIR (rigid-mode rows of the exposed nodes)",
        rigid_mass: "section MRIG (rigid mass M_R)",
    };
    /// The parts of a body given to [`crate::body::Body::from_parts`].
    pub const PARTS: Places = Places {
        frame: "P0 and Freq",
        damping: "the Rayleigh damping",
        mass: "the local mass m_L",
        stiffness: "the local stiffness K_L",
        mass_stiffness: "m_L and K_L",
        modes: "m_L, K_L and their modes",
        rigid_modes: "the rigid modes",
        rigid_mass: "the rigid mass M_R",
    };
}

/// Rayleigh coefficients: >= 0 (a negative one feeds energy in).
pub(super) fn check_damping(
    alpha: f64,
    beta: f64,
    places: &Places,
    name: &str,
) -> Result<(), BodyError> {
    for (which, v) in [("alpha", alpha), ("beta", beta)] {
        if v < 0.0 {
            return Err(BodyError::NegativeDamping {
                name: name.into(),
                place: places.damping,
                which,
                value: num(v),
            });
        }
    }
    Ok(())
}

/// Local masses: > 0 and normal numbers (the eigen analysis divides by sqrt(m_L)).
pub(super) fn check_local_masses(
    m_l: &[f64],
    places: &Places,
    name: &str,
) -> Result<(), BodyError> {
    if let Some((j, &value)) = m_l
        .iter()
        .enumerate()
        .find(|(_, v)| v.is_nan() || **v <= 0.0)
    {
        return Err(BodyError::NonPositiveMass {
            name: name.into(),
            place: places.mass,
            mode: j + 1,
            value,
        });
    }
    if let Some((j, &value)) = m_l.iter().enumerate().find(|(_, v)| !v.is_normal()) {
        return Err(BodyError::MassTooSmall {
            name: name.into(),
            place: places.mass,
            mode: j + 1,
            value: num(value),
            why: "a subnormal number (below 2.2e-308), 1/sqrt(m_L) overflows".into(),
        });
    }
    Ok(())
}

/// The checks on an assembled body, wherever its numbers came from; returns the warnings.
pub(super) fn check_physics(
    b: &Body,
    places: &Places,
    name: &str,
) -> Result<Vec<String>, BodyError> {
    let mut warnings = Vec::new();
    check_frame(&b.p0, places, name)?;
    check_mass_scale(b, places, name)?;
    if let Some((k, &value)) = b
        .frequencies_hz
        .iter()
        .enumerate()
        .find(|(_, f)| !f.is_finite())
    {
        return Err(BodyError::FrequencyNotFinite {
            name: name.into(),
            place: places.modes,
            index: k + 1,
            value,
        });
    }
    if b.nl() > 0 {
        if b.freq_file.is_nan() || b.freq_file <= 0.0 {
            return Err(BodyError::FreqNotPositive {
                name: name.into(),
                place: places.frame,
                freq: b.freq_file,
            });
        }
        check_eigenvalues(b, places, name)?;
        check_freq(b, places, name)?;
        let fmax = b.freq_max_hz();
        if (b.freq_file - fmax).abs() > 0.01 * fmax {
            warnings.push(format!(
                "{name}: {}: stored Freq = {} Hz differs from the largest eigenfrequency \
                 of (K_L, m_L) = {} Hz by more than 1%; the stable step uses the computed one",
                places.frame,
                num(b.freq_file),
                num(fmax)
            ));
        }
    }
    if b.nr() > 0 {
        check_rigid_modes(b, places, name)?;
        check_rigid_mass(b, places, name)?;
    }
    Ok(warnings)
}

/// The eigenvalues of (K_L, m_L), which have K_L's signs (Sylvester): none clearly
/// negative (K_L positive semi-definite), none positive but subnormal.
fn check_eigenvalues(b: &Body, places: &Places, name: &str) -> Result<(), BodyError> {
    let lam = &b.modal.lambda;
    let (min, max) = (lam.min(), lam.amax());
    if min < -PSD_TOL * max * (b.nl() as f64) {
        return Err(BodyError::StiffnessNotPsd {
            name: name.into(),
            place: places.stiffness,
            min: num(min),
            max: num(max),
        });
    }
    if let Some(k) = (0..b.nl()).find(|&k| {
        let l = lam[b.modal.ascending[k]];
        l > 0.0 && !l.is_normal()
    }) {
        return Err(BodyError::EigenvalueSubnormal {
            name: name.into(),
            place: places.modes,
            mode: k + 1,
            value: num(lam[b.modal.ascending[k]]),
        });
    }
    Ok(())
}

/// The mode with the largest `K_L(j,j) / m_L(j)` (the Rayleigh quotient that bounds the
/// top eigenvalue from below) and that quotient; `None` without local modes.
fn stiffest_mode(b: &Body) -> Option<(usize, f64)> {
    let mut top: Option<(usize, f64)> = None;
    for j in 0..b.nl() {
        let q = b.k_l[(j, j)] / b.m_l[j];
        if top.is_none_or(|(_, t)| q > t || t.is_nan()) {
            top = Some((j, q));
        }
    }
    top
}

/// A largest computed eigenfrequency more than [`FREQ_RATIO`] times the stored Freq is
/// a corrupt file; the message names the stiffest mode (largest `K_L(j,j) / m_L(j)`), its
/// m_L and K_L and the frequencies.
fn check_freq(b: &Body, places: &Places, name: &str) -> Result<(), BodyError> {
    let computed = b.freq_max_hz();
    if computed <= FREQ_RATIO * b.freq_file {
        return Ok(());
    }
    let (j, q) = stiffest_mode(b).unwrap_or((0, f64::NAN));
    Err(BodyError::FrequencyAboveFreq {
        name: name.into(),
        place: places.mass_stiffness,
        mode: j + 1,
        figures: Box::new([
            num(b.m_l[j]),
            num(b.k_l[(j, j)]),
            num(q.sqrt() / (2.0 * std::f64::consts::PI)),
            num(computed),
            num(b.freq_file),
            num(computed / b.freq_file),
            num(FREQ_RATIO),
        ]),
    })
}

/// Each `k_jj / m_j` must be finite, and the largest computed `omega^2` at least the
/// largest of them (a Rayleigh quotient bounds the top eigenvalue from below): an m_L
/// tiny against the others makes the mass-scaled matrix overflow or lose every digit,
/// and the frequencies would read as 0 Hz or NaN.
fn check_mass_scale(b: &Body, places: &Places, name: &str) -> Result<(), BodyError> {
    let two_pi = 2.0 * std::f64::consts::PI;
    let too_small = |j: usize, why: String| BodyError::MassTooSmall {
        name: name.into(),
        place: places.mass,
        mode: j + 1,
        value: num(b.m_l[j]),
        why,
    };
    for j in 0..b.nl() {
        let q = b.k_l[(j, j)] / b.m_l[j];
        if !q.is_finite() {
            return Err(too_small(
                j,
                format!(
                    "K_L({0},{0}) / m_L({0}) = {1} / {2} is not finite",
                    j + 1,
                    num(b.k_l[(j, j)]),
                    num(b.m_l[j])
                ),
            ));
        }
    }
    let Some((j, q)) = stiffest_mode(b) else {
        return Ok(());
    };
    let w2 = (two_pi * b.freq_max_hz()).powi(2);
    if q > 0.0 && (w2.is_nan() || w2 < q * (1.0 - 1e-6)) {
        return Err(too_small(
            j,
            format!(
                "the largest computed eigenfrequency {f} Hz is below the lower bound sqrt(K_L({j},{j}) / m_L({j}))/(2 pi) = {lb} Hz: \
                 the masses span too many orders of magnitude for the eigen analysis",
                f = num(b.freq_max_hz()),
                lb = num(q.sqrt() / two_pi),
                j = j + 1
            ),
        ));
    }
    Ok(())
}

/// Stored modes (a scene file's MODE section) are the modes of the stored (K_L, m_L):
/// `S^T diag(m_L) S = I` and `S^T K_L S = Lambda`, checked on two fixed vectors `z`
/// (Freivalds: `S^T (m (S z)) = z` and `S^T (K_L (S z)) = Lambda z`), O(nL^2) instead of
/// the O(nL^3) products or a new eigen-solution. Both are compared component by
/// component, each against the largest `|z|` (and `|Lambda|`), which is the resolution
/// of the eigen-solver itself: a changed eigenvalue, however low its mode, moves its own
/// component by the change times `z_j` (the cantilever's first eigenvalue is 2.6e-6 of
/// its largest, the tolerance 1e-8), while a sum over all modes would drown it. A change
/// to K_L, m_L, the shapes or the eigenvalues that the identities do not survive is seen
/// on any vector but a measure-zero set, and these vectors have no structure a body's
/// modes share. The mode order must sort the eigenvalues.
pub(super) fn check_modal_solution(b: &Body, places: &Places, name: &str) -> Result<(), BodyError> {
    let nl = b.nl();
    let (s, lam, m) = (&b.modal.shapes, &b.modal.lambda, &b.m_l);
    let bad = |what: &'static str, value: f64| BodyError::ModesNotSolution {
        name: name.into(),
        place: places.modes,
        what,
        value: num(value),
        tol: num(MODES_TOL),
    };
    let lam_max = lam.amax();
    for seed in [0.37, 1.91] {
        let z = DVector::from_fn(nl, |j, _| (seed + 1.7 * j as f64).sin() + 1.3);
        let z_max = z.amax();
        let u = s * &z;
        let back = s.tr_mul(&u.component_mul(m)) - &z;
        let r1 = back.amax() / z_max;
        if r1.is_nan() || r1 > MODES_TOL {
            return Err(bad("S^T diag(m_L) S - I", r1));
        }
        let y = s.tr_mul(&(&b.k_l * &u)) - z.component_mul(lam);
        let r2 = if lam_max > 0.0 {
            y.amax() / (lam_max * z_max)
        } else {
            y.amax()
        };
        if r2.is_nan() || r2 > MODES_TOL {
            return Err(bad("S^T K_L S - Lambda", r2));
        }
    }
    let order = &b.modal.ascending;
    if let Some(k) =
        (1..nl).find(|&k| lam[order[k - 1]].is_nan() || lam[order[k - 1]] > lam[order[k]])
    {
        return Err(bad(
            "the mode order (eigenvalues out of ascending order at position)",
            k as f64,
        ));
    }
    Ok(())
}

/// The rigid modes are the affine field of FORMULATION.md section 1 at every node: on
/// its translation rows, mode `3j + c` is its local coordinate `X_j` along `c` and mode
/// `9 + c` is `1 - X - Y - Z` along `c` (nothing else); on its rotation rows, modes
/// 13-15 turn its rotations (1, or 0 for a node without rotational DOFs) and nothing
/// else. Rows that are zero (or scaled) move the node with no rigid motion, and the
/// coordinates the modes give contradict the node's position.
fn check_rigid_modes(b: &Body, places: &Places, name: &str) -> Result<(), BodyError> {
    let phi = &b.phi_r;
    let nr = b.nr();
    for n in 0..b.nnodes() {
        let r = 6 * n;
        let x = [phi[(r, 0)], phi[(r, 3)], phi[(r, 6)]];
        let w = 1.0 - x[0] - x[1] - x[2];
        let tol = AFFINE_TOL * x.iter().fold(1.0f64, |a, v| a.max(v.abs()));
        for row in 0..6 {
            for col in 0..nr {
                let v = phi[(r + row, col)];
                let expected = if row < 3 {
                    match col {
                        _ if col < 9 && col % 3 == row => x[col / 3],
                        _ if col == 9 + row => w,
                        _ => 0.0,
                    }
                } else if col == 12 + row - 3 {
                    // 1 on a node with rotational DOFs, 0 on one without.
                    if (v - 1.0).abs() <= tol { 1.0 } else { 0.0 }
                } else {
                    0.0
                };
                let off = (v - expected).abs();
                if off.is_nan() || off > tol {
                    return Err(BodyError::RigidModesNotAffine {
                        name: name.into(),
                        place: places.rigid_modes,
                        node: b.node_ids[n],
                        mode: col + 1,
                        row: row + 1,
                        value: num(v),
                        expected: num(expected),
                    });
                }
            }
        }
    }
    Ok(())
}

/// P0 orthonormal within 1e-6 and not a reflection.
fn check_frame(p: &Matrix3<f64>, places: &Places, name: &str) -> Result<(), BodyError> {
    let dev = (p.transpose() * p - Matrix3::identity()).amax();
    if dev.is_nan() || dev > 1e-6 {
        return Err(BodyError::FrameNotRotation {
            name: name.into(),
            place: places.frame,
            found: format!("max |P0^T P0 - I| = {}", num(dev)),
        });
    }
    let det = p.determinant();
    if det < 0.0 {
        return Err(BodyError::FrameNotRotation {
            name: name.into(),
            place: places.frame,
            found: format!("determinant {} (a reflection)", num(det)),
        });
    }
    Ok(())
}

/// The rigid motions in rigid-mode coordinates (nR x 6): columns 0-2 unit translations
/// along the global axes, columns 3-5 unit rotations about them (about L0). A translation
/// moves L0..L3 alike; a rotation w moves L_j by w x P0(:,j) and turns DOFs 13-15.
fn rigid_motions(p0: &Matrix3<f64>, nr: usize) -> DMatrix<f64> {
    let mut r = DMatrix::zeros(nr, 6);
    for c in 0..3 {
        for point in 0..4 {
            r[(3 * point + c, c)] = 1.0;
        }
        let w = nalgebra::Vector3::ith(c, 1.0);
        for j in 0..3 {
            let d = w.cross(&p0.column(j).into_owned());
            for k in 0..3 {
                r[(3 * j + k, 3 + c)] = d[k];
            }
        }
        if nr == 15 {
            r[(12 + c, 3 + c)] = 1.0;
        }
    }
    r
}

/// M_R positive semi-definite, with a positive mass for translations and inertia about
/// every axis through the centre of mass.
fn check_rigid_mass(b: &Body, places: &Places, name: &str) -> Result<(), BodyError> {
    let overflow = |what: &'static str| BodyError::Overflow {
        name: name.into(),
        place: places.rigid_mass,
        what,
    };
    let eig = b.m_r.clone().symmetric_eigenvalues();
    if !eig.iter().all(|v| v.is_finite()) {
        return Err(overflow("an eigenvalue of M_R"));
    }
    let (min, max) = (eig.min(), eig.max());
    if max <= 0.0 || min < -PSD_TOL * max * (b.nr() as f64) {
        return Err(BodyError::RigidMassNotPsd {
            name: name.into(),
            place: places.rigid_mass,
            min,
            max,
        });
    }
    let r = rigid_motions(&b.p0, b.nr());
    let g = r.transpose() * &b.m_r * &r;
    let gtt = g.view((0, 0), (3, 3)).into_owned();
    let diag = format!(
        "[{}, {}, {}]",
        num(gtt[(0, 0)]),
        num(gtt[(1, 1)]),
        num(gtt[(2, 2)])
    );
    let Some(chol) = gtt.clone().cholesky() else {
        return Err(BodyError::NoMass {
            name: name.into(),
            place: places.rigid_mass,
            found: diag,
        });
    };
    let gtr = g.view((0, 3), (3, 3)).into_owned();
    let grr = g.view((3, 3), (3, 3)).into_owned();
    let jc = &grr - gtr.transpose() * chol.solve(&gtr);
    let jc = (&jc + jc.transpose()) * 0.5;
    if !jc.iter().all(|v| v.is_finite()) {
        return Err(overflow("the rigid-body inertia R^T M_R R"));
    }
    let e = jc.symmetric_eigenvalues();
    if e.max() <= 0.0 || e.min() <= SINGULAR_TOL * e.max() {
        return Err(BodyError::SingularRotation {
            name: name.into(),
            place: places.rigid_mass,
            found: format!("[{}, {}, {}]", num(e[0]), num(e[1]), num(e[2])),
        });
    }
    Ok(())
}
