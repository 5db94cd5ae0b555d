//! The checks Radioss does not make (FORMULATION.md section 1, last paragraph): counts,
//! the frame, masses, definiteness of M_R on the rigid motions and of K_L, the rigid
//! modes' affine form, and the stored Freq. Fatal findings are [`BodyError`]s; a Freq
//! that differs from the computed one by more than 1% is a warning, by more than
//! [`FREQ_RATIO`] a refusal.
//!
//! The physical checks run on the quantities, wherever they come from: a `.fxb` file at
//! load ([`check_body`], after the raw file's counts and values, [`check_raw`]) and the
//! FMU's scene file at instantiation ([`check_scene_body`]), which holds the same
//! quantities for the exposed nodes; [`Places`] names where each quantity is in either
//! file. The scene also holds the modes of (K_L, m_L), solved at `pack`: they are checked
//! against K_L and m_L instead of solved again (`physics::check_modal_solution`).

use super::Body;
use crate::fxb::{Block, FxbFile};
use crate::num::num;

mod physics;

pub use physics::{FREQ_RATIO, Places};

/// Largest nL a body may have: K_L is dense and its eigenvalues are computed.
pub const MAX_LOCAL_MODES: usize = 5000;

/// Why a file's numbers do not make a valid body. Each variant names the source file and
/// the block holding the faulty numbers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BodyError {
    /// Parts given to [`Body::from_parts`] whose sizes do not fit together.
    #[error(
        "{name}: {what} must be {} x {}, found {} x {}",
        expected.0, expected.1, found.0, found.1
    )]
    Shape {
        /// The body's source.
        name: String,
        /// Which matrix or list.
        what: &'static str,
        /// The size the other parts imply (rows, columns; a list is `n x 1`).
        expected: (usize, usize),
        /// Its size.
        found: (usize, usize),
    },
    /// Parts given to [`Body::from_parts`] holding a number that is not finite.
    #[error("{name}: the body's numbers must be finite, found {value}")]
    PartNotFinite {
        /// The body's source.
        name: String,
        /// The first such number.
        value: f64,
    },
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
    #[error("{name}: {place}: values too large: {what} is not finite")]
    Overflow {
        /// Source file.
        name: String,
        /// Where the matrix is ([`Places`]).
        place: &'static str,
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
        "{name}: {place}: P0 must be a rotation (orthonormal within 1e-6, determinant +1): {found}"
    )]
    FrameNotRotation {
        /// Source file.
        name: String,
        /// Where P0 is.
        place: &'static str,
        /// What is wrong.
        found: String,
    },
    /// Freq <= 0 while there are local modes.
    #[error("{name}: {place}: Freq must be > 0 when Nbmod > 0, found {}", num(*.freq))]
    FreqNotPositive {
        /// Source file.
        name: String,
        /// Where Freq is.
        place: &'static str,
        /// Stored Freq.
        freq: f64,
    },
    /// A local mode whose frequency is orders of magnitude above the stored Freq: a
    /// corrupt file (a mass or stiffness off by many orders), whose steps no method can
    /// take (the explicit step would be that many times shorter than the file says, and
    /// the other methods overflow).
    #[error(
        "{name}: {place}: mode {mode} has m_L({mode}) = {} and K_L({mode},{mode}) = {}, its own frequency sqrt(K_L / m_L) / (2 pi) is {} Hz, and the largest computed eigenfrequency of (K_L, m_L) is {} Hz, {} times the stored Freq = {} Hz (more than {}): the file is corrupt; check m_L and K_L of mode {mode}",
        figures[0], figures[1], figures[2], figures[3], figures[5], figures[4], figures[6]
    )]
    FrequencyAboveFreq {
        /// Source file.
        name: String,
        /// Where m_L and K_L are.
        place: &'static str,
        /// 1-based mode with the largest `K_L(j,j) / m_L(j)`.
        mode: usize,
        /// Its m_L and K_L, its own frequency and the largest computed one, the stored
        /// Freq, their ratio and [`FREQ_RATIO`], in compact form.
        figures: Box<[String; 7]>,
    },
    /// A local mass that is not positive.
    #[error("{name}: {place}: every m_L must be > 0, found m_L({mode}) = {}", num(*.value))]
    NonPositiveMass {
        /// Source file.
        name: String,
        /// Where m_L is.
        place: &'static str,
        /// 1-based mode.
        mode: usize,
        /// The value.
        value: f64,
    },
    /// A local mass so small (subnormal, or against its stiffness) that the frequencies
    /// cannot be computed as finite positive numbers.
    #[error("{name}: {place}: m_L({mode}) = {value} is too small: {why}")]
    MassTooSmall {
        /// Source file.
        name: String,
        /// Where m_L is.
        place: &'static str,
        /// 1-based mode.
        mode: usize,
        /// The value, in compact form.
        value: String,
        /// What cannot be computed.
        why: String,
    },
    /// Negative Rayleigh damping: it feeds energy in, and the explicit step formula
    /// takes the square root of a negative number.
    #[error("{name}: {place}: {which} must be >= 0, found {which} = {value}")]
    NegativeDamping {
        /// Source file.
        name: String,
        /// Where the damping is.
        place: &'static str,
        /// `alpha` or `beta`.
        which: &'static str,
        /// The value, in compact form.
        value: String,
    },
    /// An eigenfrequency of (K_L, m_L) that is not finite.
    #[error(
        "{name}: {place}: eigenfrequency {index} of (K_L, m_L) is not finite ({}): the matrices overflow", num(*.value)
    )]
    FrequencyNotFinite {
        /// Source file.
        name: String,
        /// Where the modes are.
        place: &'static str,
        /// 1-based index in ascending order.
        index: usize,
        /// The value.
        value: f64,
    },
    /// K_L has a clearly negative eigenvalue (relative to m_L: the eigenvalues of
    /// (K_L, m_L), which have K_L's signs).
    #[error(
        "{name}: {place}: K_L must be positive semi-definite, found the eigenvalue {min} of (K_L, m_L) (largest {max})"
    )]
    StiffnessNotPsd {
        /// Source file.
        name: String,
        /// Where K_L (or the stored modes) is.
        place: &'static str,
        /// Smallest eigenvalue, in compact form.
        min: String,
        /// Largest eigenvalue, in compact form.
        max: String,
    },
    /// A positive eigenvalue of (K_L, m_L) that is subnormal: a frequency below 1e-154
    /// Hz, whose static deflection `F / omega^2` overflows and whose steps lose every
    /// digit.
    #[error(
        "{name}: {place}: the eigenvalue {value} of (K_L, m_L) (mode {mode} in ascending order) is subnormal (below 2.2e-308): a stiffness or mass scaled beyond what double precision holds"
    )]
    EigenvalueSubnormal {
        /// Source file.
        name: String,
        /// Where the modes are.
        place: &'static str,
        /// 1-based index in ascending order.
        mode: usize,
        /// The value, in compact form.
        value: String,
    },
    /// Stored modes (the scene file's MODE section) that are not the modes of the
    /// stored K_L and m_L.
    #[error(
        "{name}: {place}: the stored modes are not the modes of (K_L, m_L): {what} is {value}, more than {tol} (relative); the file was changed after pack"
    )]
    ModesNotSolution {
        /// Source file.
        name: String,
        /// Where the modes are.
        place: &'static str,
        /// Which identity fails (`S^T diag(m_L) S - I`, `S^T K_L S - Lambda`).
        what: &'static str,
        /// Its relative residual, in compact form.
        value: String,
        /// The tolerance, in compact form.
        tol: String,
    },
    /// Rigid modes that are not the affine field of FORMULATION.md section 1 at a node.
    #[error(
        "{name}: {place}: node {node}: rigid mode {mode}, row {row}, is {value}, expected {expected}: the rigid modes must be the affine field (mode 3j+c moves the node by its local coordinate X_j along c, mode 10+c by 1 - X - Y - Z, modes 13-15 turn its rotations)"
    )]
    RigidModesNotAffine {
        /// Source file.
        name: String,
        /// Where the rigid modes are.
        place: &'static str,
        /// The node ID.
        node: i64,
        /// 1-based rigid mode.
        mode: usize,
        /// Row of the node, 1 to 6 (x y z xx yy zz).
        row: usize,
        /// The value, in compact form.
        value: String,
        /// The value the affine field gives, in compact form.
        expected: String,
    },
    /// M_R has a clearly negative eigenvalue.
    #[error(
        "{name}: {place}: M_R must be positive semi-definite, found eigenvalue {} (largest {})", num(*.min), num(*.max)
    )]
    RigidMassNotPsd {
        /// Source file.
        name: String,
        /// Where M_R is.
        place: &'static str,
        /// Smallest eigenvalue.
        min: f64,
        /// Largest eigenvalue.
        max: f64,
    },
    /// M_R gives no positive mass to translations.
    #[error(
        "{name}: {place}: expected a positive mass for rigid translations, found translation mass matrix with diagonal {found}"
    )]
    NoMass {
        /// Source file.
        name: String,
        /// Where M_R is.
        place: &'static str,
        /// Diagonal of the 3x3 translational mass.
        found: String,
    },
    /// No inertia about some axis: the rigid motions cannot be solved for.
    #[error(
        "{name}: {place}: M_R is singular on the rigid rotations (rotational inertia about the centre of mass has eigenvalues {found}); are all nodes on one line? A free body needs inertia about every axis"
    )]
    SingularRotation {
        /// Source file.
        name: String,
        /// Where M_R is.
        place: &'static str,
        /// Eigenvalues of the inertia about the centre of mass.
        found: String,
    },
}

/// Check a raw file's counts and values before assembly (so assembly cannot index out of
/// bounds).
pub(super) fn check_raw(f: &FxbFile, name: &str) -> Result<(), BodyError> {
    check_counts(f, name)?;
    let places = &Places::FXB;
    if let Some((a, b)) = f.damping {
        physics::check_damping(a, b, places, name)?;
    }
    // Before assembly: the eigen analysis divides by sqrt(m_L).
    physics::check_local_masses(&f.m_l, places, name)
}

/// Check a raw file's block lengths against its header and that its numbers are
/// finite: what assembly needs to index in bounds.
pub(super) fn check_counts(f: &FxbFile, name: &str) -> Result<(), BodyError> {
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
    Ok(())
}

/// Check the assembled body of a `.fxb` file; returns the warnings.
pub(super) fn check_body(b: &Body, name: &str) -> Result<Vec<String>, BodyError> {
    physics::check_physics(b, &Places::FXB, name)
}

/// The physical checks of a body built from parts ([`Body::from_parts`], the scene-file
/// reader): [`check_scene_body`], with the places named by `places`.
pub(super) fn check_parts(b: &Body, places: &Places, name: &str) -> Result<Vec<String>, BodyError> {
    physics::check_local_masses(b.m_l.as_slice(), places, name)?;
    if let Some(d) = b.damping {
        physics::check_damping(d.alpha, d.beta, places, name)?;
    }
    physics::check_modal_solution(b, places, name)?;
    physics::check_physics(b, places, name)
}

/// The physical checks of a body read from an FMU's scene file (the exposed nodes'
/// rows, the whole mode-space matrices and the modes solved at `pack`), the same as a
/// `.fxb` file's at load where the quantities are the same: P0 a rotation, m_L positive
/// and normal, Rayleigh coefficients >= 0, the stored modes the modes of (K_L, m_L) and
/// their eigenvalues neither negative nor subnormal, the masses against the stiffness,
/// Freq against the computed frequencies, the rigid modes the affine field at every
/// exposed node, M_R definite on the rigid motions. Errors name the scene file and the
/// section. Cheap at scene size: the modes are checked, not solved (O(nL^2)).
pub fn check_scene_body(b: &Body, name: &str) -> Result<(), BodyError> {
    check_parts(b, &Places::SCENE, name).map(|_| ())
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::{BodyError, FREQ_RATIO};
    use crate::body::Body;

    fn fixture(name: &str) -> crate::fxb::FxbFile {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        crate::fxb::read_path(&root.join(name)).unwrap()
    }

    /// Issue 28, point 8: the cantilever with m_L(1) = 1e-300 in block 8 (which `info`
    /// and `pack` accepted, and then no method could step: explicit needed 3.67e149
    /// internal steps, implicit went non-finite) is refused at load, naming the mode,
    /// its m_L and K_L and both frequencies.
    #[test]
    fn a_mode_far_above_the_stored_freq_is_refused_at_load() {
        let mut f = fixture("fixtures/cantilever.fxb");
        f.m_l[0] = 1e-300;
        let e = Body::from_fxb(&f, "c.fxb").unwrap_err();
        let msg = e.to_string();
        println!("{msg}");
        assert!(
            matches!(e, BodyError::FrequencyAboveFreq { mode: 1, .. }),
            "{msg}"
        );
        for want in [
            "c.fxb: blocks 8-10 (m_L, K_L): mode 1 has m_L(1) = 1e-300 and K_L(1,1) = ",
            "the largest computed eigenfrequency of (K_L, m_L) is 7.146039221536518e152 Hz",
            "times the stored Freq = 4137.359299 Hz (more than 1000)",
        ] {
            assert!(msg.contains(want), "{msg}");
        }
        // The same file with its m_L as written loads.
        assert!(Body::from_fxb(&fixture("fixtures/cantilever.fxb"), "c.fxb").is_ok());
    }

    /// The threshold refuses no legitimate body: every shipped fixture and test body
    /// (those not refused for another reason) has its largest computed frequency within
    /// 1e-6 of its stored Freq, three orders below the limit; a Freq at a cut-off far
    /// above every mode (OpenRadioss writes its cut-off) and a Freq 100 times below the
    /// modes (within the limit) load, with the 1% warning; 1.01e3 times below is refused.
    #[test]
    fn the_freq_limit_refuses_no_legitimate_body() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut seen = 0;
        for dir in ["fixtures", "tests/data"] {
            for e in std::fs::read_dir(root.join(dir)).unwrap().flatten() {
                let p = e.path();
                let small = std::fs::metadata(&p).is_ok_and(|m| m.len() < 5 << 20);
                if !(small && p.extension().is_some_and(|x| x == "fxb")) {
                    continue;
                }
                let Ok(b) = crate::body::load(&p, Default::default()) else {
                    continue;
                };
                if b.nl() == 0 {
                    continue;
                }
                let ratio = b.freq_max_hz() / b.freq_file;
                assert!((ratio - 1.0).abs() < 1e-6, "{}: {ratio}", p.display());
                seen += 1;
            }
        }
        assert!(seen >= 10, "{seen}");
        let f = fixture("fixtures/cantilever.fxb");
        let top = Body::from_fxb(&f, "c").unwrap().freq_max_hz();
        for (stored, ok) in [
            (top * 1e6, true),
            (top / 100.0, true),
            (top / (FREQ_RATIO * 1.01), false),
        ] {
            let mut g = f.clone();
            g.freq = stored;
            match Body::from_fxb(&g, "c") {
                Ok(b) => {
                    assert!(ok, "Freq {stored}: accepted");
                    assert_eq!(b.warnings.len(), 1, "{:?}", b.warnings);
                }
                Err(e) => assert!(!ok, "Freq {stored}: {e}"),
            }
        }
    }
}
