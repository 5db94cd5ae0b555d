//! The checks Radioss does not make (FORMULATION.md section 1, last paragraph): counts,
//! the frame, masses, definiteness of M_R on the rigid motions and of K_L, and the
//! stored Freq. Fatal findings are [`BodyError`]s; the Freq comparison is a warning.

use nalgebra::{DMatrix, Matrix3};

use super::Body;
use crate::fxb::{Block, FxbFile};
use crate::num::num;

/// Largest nL a body may have: K_L is dense and its eigenvalues are computed.
pub const MAX_LOCAL_MODES: usize = 5000;

/// Relative tolerance for "positive semi-definite" (round-off of 10 printed digits).
const PSD_TOL: f64 = 1e-8;

/// Ratio below which the rotational inertia about some axis counts as zero.
const SINGULAR_TOL: f64 = 1e-10;

/// Why a file's numbers do not make a valid body. Each variant names the source file and
/// the block holding the faulty numbers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BodyError {
    /// A block whose length does not match the header counts (hand-built files only).
    #[error(
        "{name}: {block}: inconsistent with the header: expected {expected} values, found {found}"
    )]
    Inconsistent {
        /// Source file.
        name: String,
        /// Block.
        block: Block,
        /// Values the header calls for.
        expected: usize,
        /// Values present.
        found: usize,
    },
    /// A NaN or infinite value (hand-built files only; the reader rejects them).
    #[error("{name}: {block}: value {index} is not finite: expected a number, found {}", num(*.value))]
    NotFinite {
        /// Source file.
        name: String,
        /// Block.
        block: Block,
        /// 1-based position in the block.
        index: usize,
        /// The value.
        value: f64,
    },
    /// Numbers so large that the matrix computations overflow.
    #[error("{name}: {block}: values too large: {what} is not finite")]
    Overflow {
        /// Source file.
        name: String,
        /// Block holding the matrix.
        block: Block,
        /// What overflowed.
        what: &'static str,
    },
    /// Nbnod = 0.
    #[error("{name}: block 1 (general data): expected at least one node, found Nbnod = 0")]
    NoNodes {
        /// Source file.
        name: String,
    },
    /// More local modes than the dense eigen analysis handles.
    #[error("{name}: block 1 (general data): expected Nbmod <= {max}, found {found}")]
    TooManyModes {
        /// Source file.
        name: String,
        /// Nbmod.
        found: usize,
        /// The limit.
        max: usize,
    },
    /// P0 is not orthonormal, or is a reflection.
    #[error(
        "{name}: block 3 (initial frame P0 and Freq): P0 must be a rotation (orthonormal within 1e-6, determinant +1): {found}"
    )]
    FrameNotRotation {
        /// Source file.
        name: String,
        /// What is wrong.
        found: String,
    },
    /// Freq <= 0 while there are local modes.
    #[error(
        "{name}: block 3 (initial frame P0 and Freq): Freq must be > 0 when Nbmod > 0, found {}", num(*.freq)
    )]
    FreqNotPositive {
        /// Source file.
        name: String,
        /// Stored Freq.
        freq: f64,
    },
    /// A local mass that is not positive.
    #[error("{name}: block 8 (local mass m_L): every m_L must be > 0, found m_L({mode}) = {}", num(*.value))]
    NonPositiveMass {
        /// Source file.
        name: String,
        /// 1-based mode.
        mode: usize,
        /// The value.
        value: f64,
    },
    /// A local mass so small (subnormal, or against its stiffness) that the frequencies
    /// cannot be computed as finite positive numbers.
    #[error("{name}: block 8 (local mass m_L): m_L({mode}) = {value} is too small: {why}")]
    MassTooSmall {
        /// Source file.
        name: String,
        /// 1-based mode.
        mode: usize,
        /// The value, in compact form.
        value: String,
        /// What cannot be computed.
        why: String,
    },
    /// Negative Rayleigh damping: it feeds energy in, and the explicit step formula
    /// takes the square root of a negative number.
    #[error("{name}: block 4 (Rayleigh damping): {which} must be >= 0, found {which} = {value}")]
    NegativeDamping {
        /// Source file.
        name: String,
        /// `alpha` or `beta`.
        which: &'static str,
        /// The value, in compact form.
        value: String,
    },
    /// An eigenfrequency of (K_L, m_L) that is not finite.
    #[error(
        "{name}: blocks 8-10 (m_L, K_L): eigenfrequency {index} of (K_L, m_L) is not finite ({}): the matrices overflow", num(*.value)
    )]
    FrequencyNotFinite {
        /// Source file.
        name: String,
        /// 1-based index in ascending order.
        index: usize,
        /// The value.
        value: f64,
    },
    /// K_L has a clearly negative eigenvalue.
    #[error(
        "{name}: blocks 9-10 (local stiffness K_L): K_L must be positive semi-definite, found eigenvalue {} (largest |entry| {})", num(*.min), num(*.scale)
    )]
    StiffnessNotPsd {
        /// Source file.
        name: String,
        /// Smallest eigenvalue.
        min: f64,
        /// Largest absolute entry.
        scale: f64,
    },
    /// M_R has a clearly negative eigenvalue.
    #[error(
        "{name}: block 11 (rigid mass M_R): M_R must be positive semi-definite, found eigenvalue {} (largest {})", num(*.min), num(*.max)
    )]
    RigidMassNotPsd {
        /// Source file.
        name: String,
        /// Smallest eigenvalue.
        min: f64,
        /// Largest eigenvalue.
        max: f64,
    },
    /// M_R gives no positive mass to translations.
    #[error(
        "{name}: block 11 (rigid mass M_R): expected a positive mass for rigid translations, found translation mass matrix with diagonal {found}"
    )]
    NoMass {
        /// Source file.
        name: String,
        /// Diagonal of the 3x3 translational mass.
        found: String,
    },
    /// No inertia about some axis: the rigid motions cannot be solved for.
    #[error(
        "{name}: block 11 (rigid mass M_R): M_R is singular on the rigid rotations (rotational inertia about the centre of mass has eigenvalues {found}); are all nodes on one line? A free body needs inertia about every axis"
    )]
    SingularRotation {
        /// Source file.
        name: String,
        /// Eigenvalues of the inertia about the centre of mass.
        found: String,
    },
}

/// Check a raw file's counts and values before assembly (so assembly cannot index out of
/// bounds).
pub(super) fn check_raw(f: &FxbFile, name: &str) -> Result<(), BodyError> {
    let (n, nl, ns, nr) = (f.nbnod, f.nbmod, f.nbstat, f.nr());
    if n == 0 {
        return Err(BodyError::NoNodes { name: name.into() });
    }
    if nl > MAX_LOCAL_MODES {
        return Err(BodyError::TooManyModes {
            name: name.into(),
            found: nl,
            max: MAX_LOCAL_MODES,
        });
    }
    let big = |v: Option<usize>| v.unwrap_or(usize::MAX);
    let k_full = if ns <= nl {
        ns * (2 * nl - ns + 1) / 2
    } else {
        usize::MAX
    };
    let sizes: [(u8, &[f64], usize); 8] = [
        (
            5,
            &f.rigid_modes,
            big(nr.checked_mul(n).and_then(|v| v.checked_mul(6))),
        ),
        (
            7,
            &f.local_modes,
            big(nl.checked_mul(n).and_then(|v| v.checked_mul(6))),
        ),
        (8, &f.m_l, nl),
        (9, &f.k_full, k_full),
        (10, &f.k_diag, nl.saturating_sub(ns)),
        (11, &f.m_r, nr * (nr + 1) / 2),
        (
            12,
            &f.m_c,
            if nl > 0 {
                big(nr.checked_mul(nl).and_then(|v| v.checked_mul(9)))
            } else {
                0
            },
        ),
        (
            13,
            &f.k_c,
            if nl > 0 {
                big(nr.checked_mul(nl).and_then(|v| v.checked_mul(9)))
            } else {
                0
            },
        ),
    ];
    if f.node_ids.len() != n {
        return Err(BodyError::Inconsistent {
            name: name.into(),
            block: Block::new(2),
            expected: n,
            found: f.node_ids.len(),
        });
    }
    for (b, data, expected) in sizes {
        if data.len() != expected {
            return Err(BodyError::Inconsistent {
                name: name.into(),
                block: Block::new(b),
                expected,
                found: data.len(),
            });
        }
        if let Some(index) = data.iter().position(|v| !v.is_finite()) {
            return Err(BodyError::NotFinite {
                name: name.into(),
                block: Block::new(b),
                index: index + 1,
                value: data[index],
            });
        }
    }
    let mut frame = f.p0.to_vec();
    frame.push(f.freq);
    if let Some((a, b)) = f.damping {
        frame.extend([a, b]);
    }
    if let Some(index) = frame.iter().position(|v| !v.is_finite()) {
        return Err(BodyError::NotFinite {
            name: name.into(),
            block: Block::new(if index < 10 { 3 } else { 4 }),
            index: if index < 10 { index + 1 } else { index - 9 },
            value: frame[index],
        });
    }
    if let Some((a, b)) = f.damping {
        for (which, v) in [("alpha", a), ("beta", b)] {
            if v < 0.0 {
                return Err(BodyError::NegativeDamping {
                    name: name.into(),
                    which,
                    value: num(v),
                });
            }
        }
    }
    // Before assembly: the eigen analysis divides by sqrt(m_L).
    if let Some((j, &value)) = f.m_l.iter().enumerate().find(|(_, v)| **v <= 0.0) {
        return Err(BodyError::NonPositiveMass {
            name: name.into(),
            mode: j + 1,
            value,
        });
    }
    if let Some((j, &value)) = f.m_l.iter().enumerate().find(|(_, v)| !v.is_normal()) {
        return Err(BodyError::MassTooSmall {
            name: name.into(),
            mode: j + 1,
            value: num(value),
            why: "a subnormal number (below 2.2e-308), 1/sqrt(m_L) overflows".into(),
        });
    }
    Ok(())
}

/// Check the assembled body; returns the warnings.
pub(super) fn check_body(b: &Body, name: &str) -> Result<Vec<String>, BodyError> {
    let mut warnings = Vec::new();
    check_frame(&b.p0, name)?;
    let overflow = |block: u8, what: &'static str| BodyError::Overflow {
        name: name.into(),
        block: Block::new(block),
        what,
    };
    check_mass_scale(b, name)?;
    if let Some((k, &value)) = b
        .frequencies_hz
        .iter()
        .enumerate()
        .find(|(_, f)| !f.is_finite())
    {
        return Err(BodyError::FrequencyNotFinite {
            name: name.into(),
            index: k + 1,
            value,
        });
    }
    if b.nl() > 0 {
        if b.freq_file <= 0.0 {
            return Err(BodyError::FreqNotPositive {
                name: name.into(),
                freq: b.freq_file,
            });
        }
        let scale = b.k_l.amax();
        let eig = b.k_l.clone().symmetric_eigenvalues();
        if !scale.is_finite() || !eig.iter().all(|v| v.is_finite()) {
            return Err(overflow(9, "an eigenvalue of K_L"));
        }
        let min = eig.min();
        if min < -PSD_TOL * scale * (b.nl() as f64) {
            return Err(BodyError::StiffnessNotPsd {
                name: name.into(),
                min,
                scale,
            });
        }
        let fmax = b.frequencies_hz.last().copied().unwrap_or(0.0);
        if (b.freq_file - fmax).abs() > 0.01 * fmax {
            warnings.push(format!(
                "{name}: block 3: stored Freq = {} Hz differs from the largest eigenfrequency \
                 of (K_L, m_L) = {} Hz by more than 1%; the stable step uses the computed one",
                crate::num::num(b.freq_file),
                crate::num::num(fmax)
            ));
        }
    }
    if b.nr() > 0 {
        check_rigid_mass(b, name)?;
    }
    Ok(warnings)
}

/// Each `k_jj / m_j` must be finite, and the largest computed `omega^2` at least the
/// largest of them (a Rayleigh quotient bounds the top eigenvalue from below): an m_L
/// tiny against the others makes the mass-scaled matrix overflow or lose every digit,
/// and the frequencies would read as 0 Hz or NaN.
fn check_mass_scale(b: &Body, name: &str) -> Result<(), BodyError> {
    let two_pi = 2.0 * std::f64::consts::PI;
    let mut top: Option<(usize, f64)> = None;
    for j in 0..b.nl() {
        let q = b.k_l[(j, j)] / b.m_l[j];
        if !q.is_finite() {
            return Err(BodyError::MassTooSmall {
                name: name.into(),
                mode: j + 1,
                value: num(b.m_l[j]),
                why: format!(
                    "K_L({0},{0}) / m_L({0}) = {1} / {2} is not finite",
                    j + 1,
                    num(b.k_l[(j, j)]),
                    num(b.m_l[j])
                ),
            });
        }
        if top.is_none_or(|(_, t)| q > t) {
            top = Some((j, q));
        }
    }
    let Some((j, q)) = top else { return Ok(()) };
    let w2 = (two_pi * b.freq_max_hz()).powi(2);
    if q > 0.0 && (w2.is_nan() || w2 < q * (1.0 - 1e-6)) {
        return Err(BodyError::MassTooSmall {
            name: name.into(),
            mode: j + 1,
            value: num(b.m_l[j]),
            why: format!(
                "the largest computed eigenfrequency {f} Hz is below the lower bound sqrt(K_L({j},{j}) / m_L({j}))/(2 pi) = {lb} Hz: \
                 the masses span too many orders of magnitude for the eigen analysis",
                f = num(b.freq_max_hz()),
                lb = num(q.sqrt() / two_pi),
                j = j + 1
            ),
        });
    }
    Ok(())
}

fn check_frame(p: &Matrix3<f64>, name: &str) -> Result<(), BodyError> {
    let dev = (p.transpose() * p - Matrix3::identity()).amax();
    if dev > 1e-6 {
        return Err(BodyError::FrameNotRotation {
            name: name.into(),
            found: format!("max |P0^T P0 - I| = {}", num(dev)),
        });
    }
    let det = p.determinant();
    if det < 0.0 {
        return Err(BodyError::FrameNotRotation {
            name: name.into(),
            found: format!("determinant {} (a reflection)", num(det)),
        });
    }
    Ok(())
}

/// The rigid motions in rigid-mode coordinates (nR x 6): columns 0-2 unit translations
/// along the global axes, columns 3-5 unit rotations about them (about L0). A translation
/// moves L0..L3 alike; a rotation w moves L_j by w x P0(:,j) and turns DOFs 13-15.
pub(super) fn rigid_motions(p0: &Matrix3<f64>, nr: usize) -> DMatrix<f64> {
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

fn check_rigid_mass(b: &Body, name: &str) -> Result<(), BodyError> {
    let overflow = |what: &'static str| BodyError::Overflow {
        name: name.into(),
        block: Block::new(11),
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
            found: format!("[{}, {}, {}]", num(e[0]), num(e[1]), num(e[2])),
        });
    }
    Ok(())
}
