//! Body validation: each check of Body::from_fxb on a file broken in one known way, and
//! small free bodies of point masses built here from first principles (rigid modes and
//! M_R = Phi_R^T M Phi_R from node coordinates), so that total mass, the planar case and
//! the collinear case have independent answers.

use std::f64::consts::PI;
use std::path::Path;

use fxbody::body::{Body, BodyError};
use fxbody::fxb::{self, FxbFile};

fn read(name: &str) -> FxbFile {
    fxb::read_path(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name),
    )
    .unwrap()
}

fn body_err(f: &FxbFile) -> (BodyError, String) {
    let e = Body::from_fxb(f, "b.fxb").expect_err("must be refused");
    let msg = e.to_string();
    (e, msg)
}

/// A free body of point masses (no rotations), P0 = I, L0 at the centre of mass, one
/// local mode (unit x translation of the first node) with stiffness k.
fn point_mass_body(coords: &[[f64; 3]], masses: &[f64], k: f64) -> FxbFile {
    let n = coords.len();
    let mtot: f64 = masses.iter().sum();
    let cog: Vec<f64> = (0..3)
        .map(|c| {
            coords
                .iter()
                .zip(masses)
                .map(|(x, m)| x[c] * m)
                .sum::<f64>()
                / mtot
        })
        .collect();
    let mut rigid = vec![0.0; 12 * n * 6];
    for (p, x) in coords.iter().enumerate() {
        let loc = [x[0] - cog[0], x[1] - cog[1], x[2] - cog[2]];
        for c in 0..3 {
            for j in 0..3 {
                rigid[(3 * j + c) * 6 * n + 6 * p + c] = loc[j];
            }
            rigid[(9 + c) * 6 * n + 6 * p + c] = 1.0 - loc[0] - loc[1] - loc[2];
        }
    }
    let dot = |a: usize, b: usize| -> f64 {
        (0..n)
            .map(|p| {
                (0..3)
                    .map(|c| {
                        rigid[a * 6 * n + 6 * p + c] * rigid[b * 6 * n + 6 * p + c] * masses[p]
                    })
                    .sum::<f64>()
            })
            .sum()
    };
    let m_r: Vec<f64> = (0..12)
        .flat_map(|i| (i..12).map(move |j| (i, j)))
        .map(|(i, j)| dot(i, j))
        .collect();
    let mut local = vec![0.0; 6 * n];
    local[0] = 1.0;
    let m1 = masses[0];
    FxbFile {
        nbmod: 1,
        nbstat: 0,
        nbnod: n,
        irot: false,
        idamp: false,
        iblo: false,
        ifile: false,
        node_ids: (1..=n as i64).collect(),
        p0: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        freq: (k / m1).sqrt() / (2.0 * PI),
        damping: None,
        rigid_modes: rigid,
        local_modes: local,
        m_l: vec![m1],
        k_full: vec![],
        k_diag: vec![k],
        m_r,
        m_c: vec![0.0; 9 * 12],
        k_c: vec![0.0; 9 * 12],
    }
}

#[test]
fn planar_body_is_valid_and_its_mass_is_the_sum_of_masses() {
    // Three masses in the plane z = 0: M_R is singular (the fields Z e_c vanish at every
    // node) but positive definite on the rigid motions, which is what the solvers need.
    let f = point_mass_body(
        &[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[1.0, 2.0, 3.0],
        400.0,
    );
    let b = Body::from_fxb(&f, "plate").unwrap_or_else(|e| panic!("{e}"));
    assert!((b.total_mass().unwrap() - 6.0).abs() < 1e-12);
    assert!((b.frequencies_hz()[0] - 20.0 / (2.0 * PI)).abs() < 1e-12);
    assert!(b.warnings().is_empty());
}

#[test]
fn tetrahedron_of_masses() {
    let f = point_mass_body(
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        &[0.5, 0.5, 0.5, 0.5],
        1.0,
    );
    let b = Body::from_fxb(&f, "tet").unwrap();
    assert!((b.total_mass().unwrap() - 2.0).abs() < 1e-12);
    assert!(!b.node_has_rotation(0), "Irot = 0: no node has rotations");
}

#[test]
fn collinear_nodes_are_reported() {
    let f = point_mass_body(
        &[[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [3.0, 3.0, 3.0]],
        &[1.0, 1.0, 1.0],
        1.0,
    );
    let (e, msg) = body_err(&f);
    assert!(matches!(e, BodyError::SingularRotation { .. }), "{msg}");
    assert!(
        msg.starts_with("b.fxb: block 11 (rigid mass M_R)") && msg.contains("one line"),
        "{msg}"
    );
}

#[test]
fn all_mass_in_one_point_is_reported() {
    let f = point_mass_body(&[[1.0, 2.0, 3.0]], &[1.0], 1.0);
    assert!(matches!(body_err(&f).0, BodyError::SingularRotation { .. }));
}

#[test]
fn frame_must_be_a_rotation() {
    let mut f = read("fmt_fixed.fxb");
    f.p0[1] = 1e-5;
    let (e, msg) = body_err(&f);
    assert!(matches!(e, BodyError::FrameNotRotation { .. }));
    assert!(
        msg.starts_with("b.fxb: block 3") && msg.contains("1e-5"),
        "{msg}"
    );
    f.p0[1] = 5e-7; // within the 1e-6 tolerance
    assert!(Body::from_fxb(&f, "b").is_ok());
    let mut f = read("fmt_fixed.fxb");
    f.p0[8] = -1.0;
    let (_, msg) = body_err(&f);
    assert!(msg.contains("reflection"), "{msg}");
}

#[test]
fn local_masses_must_be_positive() {
    let mut f = read("fmt_fixed.fxb");
    f.m_l[1] = 0.0;
    let (e, msg) = body_err(&f);
    assert!(matches!(e, BodyError::NonPositiveMass { mode: 2, .. }));
    assert!(
        msg.starts_with("b.fxb: block 8 (local mass m_L)") && msg.contains("m_L(2) = 0"),
        "{msg}"
    );
}

#[test]
fn stiffness_must_be_positive_semi_definite() {
    let mut f = read("fmt_fixed.fxb");
    // [[800, -100], [-100, 10]] has determinant -2000: one negative eigenvalue.
    f.k_diag[0] = 10.0;
    let (e, msg) = body_err(&f);
    assert!(matches!(e, BodyError::StiffnessNotPsd { .. }), "{msg}");
    assert!(msg.starts_with("b.fxb: blocks 9-10"), "{msg}");
    // A zero-frequency (rigid) local mode is fine: [[800, -100], [-100, 12.5]] is singular.
    f.k_diag[0] = 12.5;
    let b = Body::from_fxb(&f, "b").unwrap();
    assert!(b.frequencies_hz()[0].abs() < 1e-6);
}

#[test]
fn overflowing_matrices_are_refused_not_passed_as_nan() {
    let mut f = read("fmt_fixed.fxb");
    f.k_full = vec![1e308, -1e308];
    f.k_diag = vec![1e308];
    f.m_l = vec![1e-300, 1e-300];
    let (e, msg) = body_err(&f);
    // Issue 13: refused at the cause, the mass that makes K_L(1,1)/m_L(1) overflow.
    assert!(
        matches!(e, BodyError::MassTooSmall { mode: 1, .. }),
        "{msg}"
    );
    assert!(msg.contains("block 8") && msg.contains("1e-300"), "{msg}");
    // Large but representable numbers are not an overflow: M_R scaled by 1e300 is a
    // valid (absurdly heavy) body.
    let mut f = read("body_b0_r0_d0.fxb");
    f.m_r.iter_mut().for_each(|v| *v *= 1e300);
    let b = Body::from_fxb(&f, "b.fxb").unwrap();
    assert!((b.total_mass().unwrap() / 5e300 - 1.0).abs() < 1e-8);
}

#[test]
fn rigid_mass_must_be_positive_semi_definite() {
    let mut f = read("body_b0_r0_d0.fxb");
    f.m_r[0] = -1.0e3;
    let (e, msg) = body_err(&f);
    assert!(matches!(e, BodyError::RigidMassNotPsd { .. }), "{msg}");
    assert!(msg.starts_with("b.fxb: block 11"), "{msg}");
}

#[test]
fn stored_freq_checks() {
    let mut f = read("fmt_fixed.fxb");
    let exact = f.freq;
    f.freq = exact * 1.05;
    let b = Body::from_fxb(&f, "b.fxb").unwrap();
    assert_eq!(b.warnings().len(), 1);
    assert!(
        b.warnings()[0].contains("block 3") && b.warnings()[0].contains("1%"),
        "{:?}",
        b.warnings()
    );
    f.freq = exact * 1.009;
    assert!(Body::from_fxb(&f, "b.fxb").unwrap().warnings().is_empty());
    f.freq = 0.0;
    let (e, msg) = body_err(&f);
    assert!(matches!(e, BodyError::FreqNotPositive { .. }));
    assert!(msg.contains("Freq must be > 0"), "{msg}");
}

#[test]
fn inconsistent_hand_built_files_are_refused_not_indexed() {
    let mut f = read("body_b0_r1_d1.fxb");
    f.m_c.pop();
    let (e, msg) = body_err(&f);
    assert!(
        matches!(
            e,
            BodyError::Inconsistent {
                expected: 405,
                found: 404,
                ..
            }
        ),
        "{msg}"
    );
    let mut f = read("fmt_fixed.fxb");
    f.local_modes[3] = f64::NAN;
    assert!(matches!(
        body_err(&f).0,
        BodyError::NotFinite { index: 4, .. }
    ));
    let mut f = read("fmt_fixed.fxb");
    f.nbnod = 0;
    f.node_ids.clear();
    assert!(matches!(body_err(&f).0, BodyError::NoNodes { .. }));
}

#[test]
fn stable_step_formulas() {
    // Undamped: 1/(pi Freq). Damped: the smaller of the two expressions of section 4.
    let f = 12.5;
    assert!((fxbody::body::stable_step(f, 0.0) - 1.0 / (PI * f)).abs() < 1e-15);
    let w = 2.0 * PI * f;
    let beta = 2.0e-4;
    let want = (((beta * w).powi(2) + 4.0).sqrt() - beta * w) / w;
    assert!(want < 2.0 / (beta * w * w));
    assert!((fxbody::body::stable_step(f, beta) - want).abs() < 1e-15);
}

#[test]
fn load_body_reads_and_validates() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let b = fxbody::body::load(&dir.join("body_b0_r0_d1.fxb"), Default::default()).unwrap();
    assert!((b.total_mass().unwrap() - 5.0).abs() < 1e-8);
    let e = fxbody::body::load(&dir.join("labels_r0_d0_ns1.fxb"), Default::default()).unwrap_err();
    assert!(matches!(e, fxbody::body::LoadError::Body(_)), "{e}");
    let e = fxbody::body::load(&dir.join("missing.fxb"), Default::default()).unwrap_err();
    assert!(matches!(e, fxbody::body::LoadError::File(_)), "{e}");
    assert!(
        e.to_string()
            .contains("missing.fxb: cannot read the body file")
    );
}

#[test]
fn too_many_local_modes_for_a_dense_eigen_analysis() {
    let mut f = read("fmt_fixed.fxb");
    f.nbmod = fxbody::body::MAX_LOCAL_MODES + 1;
    let (e, msg) = body_err(&f);
    assert!(matches!(e, BodyError::TooManyModes { .. }), "{msg}");
}

#[test]
fn rigid_mass_without_translational_mass() {
    // Only the rotary-inertia modes 13-15 carry mass: no mass for rigid translations.
    let mut f = read("body_b0_r1_d0.fxb");
    let nr = 15;
    let mut k = 0;
    for i in 0..nr {
        for j in i..nr {
            f.m_r[k] = if i == j && i >= 12 { 0.03 } else { 0.0 };
            k += 1;
        }
    }
    let (e, msg) = body_err(&f);
    assert!(matches!(e, BodyError::NoMass { .. }), "{msg}");
    assert!(msg.starts_with("b.fxb: block 11"), "{msg}");
}

/// Issue 13 class 3: impossible bodies are refused with the block and the value.
#[test]
fn negative_rayleigh_damping_is_refused() {
    for (k, which) in [(0, "alpha"), (1, "beta")] {
        let mut f = read("body_b0_r0_d1.fxb");
        let (mut a, mut b) = f.damping.unwrap();
        if k == 0 {
            a = -0.5;
        } else {
            b = -2e-4;
        }
        f.damping = Some((a, b));
        let (e, msg) = body_err(&f);
        assert!(matches!(e, BodyError::NegativeDamping { .. }), "{msg}");
        let v = if k == 0 { "-0.5" } else { "-0.0002" };
        assert_eq!(
            msg,
            format!("b.fxb: block 4 (Rayleigh damping): {which} must be >= 0, found {which} = {v}")
        );
    }
}

#[test]
fn subnormal_local_mass_is_refused() {
    let mut f = read("fmt_fixed.fxb");
    f.m_l[0] = 1e-320;
    let (e, msg) = body_err(&f);
    assert!(
        matches!(e, BodyError::MassTooSmall { mode: 1, .. }),
        "{msg}"
    );
    assert!(
        msg.starts_with("b.fxb: block 8 (local mass m_L): m_L(1) = 1e-320"),
        "{msg}"
    );
}

#[test]
fn body_stable_step_comes_from_the_computed_frequency() {
    // Stored Freq 1e98 (above every mode, as OpenRadioss's cut-off is: a warning only;
    // far below them is a corrupt file, refused): the step comes from the computed
    // frequency, the same value the explicit solver uses.
    let mut f = read("fmt_fixed.fxb");
    f.freq = 1e98;
    let b = Body::from_fxb(&f, "b.fxb").unwrap();
    let beta = b.damping().map_or(0.0, |d| d.beta);
    let want = fxbody::body::stable_step(b.frequencies_hz()[1], beta);
    assert!((b.explicit_stable_step() - want).abs() < 1e-15 * want);
    assert!(
        b.explicit_stable_step() < 1.0,
        "{}",
        b.explicit_stable_step()
    );
    assert_eq!(b.warnings().len(), 1);
    // The stored value is printed compactly, not with 98 zeros.
    assert!(
        b.warnings()[0].contains("stored Freq = 1e98 Hz"),
        "{}",
        b.warnings()[0]
    );
}
