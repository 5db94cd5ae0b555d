//! `fxbody info --nodes`: the static participation and effective masses against
//! independent references: the Euler-Bernoulli one-mode share 12/(beta_1 L)^4 of a
//! cantilever's tip deflection, the mass-orthogonality of free-free modes to rigid
//! translations (zero effective mass), and a direct K_L solve of the truncated body.

use std::process::Command;

use crate::common::fixture;
use fxbody::body::load as load_body;
use fxbody::scene::reduce::{effective_mass, static_participation, truncate};
use nalgebra::{DMatrix, DVector};
use serde_json::Value;

#[test]
fn cantilever_tip_share_of_the_first_bending_mode() {
    // Through the command (--json): the cumulative share at 121:Y after mode 2 (the
    // first y-bending mode, 10.03 Hz) is the Euler-Bernoulli 12/(beta_1 L)^4 = 0.970688
    // within 2e-4 (20 elements; the shape converges as h^4).
    let run = Command::new(fxbody_host::workspace_binary("fxbody"))
        .arg("info")
        .arg(fixture("cantilever.fxb"))
        .args(["--json", "--nodes", "121,111"])
        .output()
        .unwrap();
    assert!(run.status.success());
    let text = String::from_utf8(run.stdout).unwrap();
    // One JSON object (issue 15): the file summary with the modes under "modes".
    let v: Value = serde_json::from_str(&text).unwrap();
    let share = v["modes"][1]["cumulative_static_share"]["121:Y"]
        .as_f64()
        .unwrap();
    let eb = 12.0 / 1.875_104_068_7f64.powi(4);
    println!("tip Y share of modes 1-2: {share:.6} (Euler-Bernoulli {eb:.6})");
    assert!((share - eb).abs() < 2e-4);
    let last = v["modes"][19]["cumulative_static_share"]["121:Y"]
        .as_f64()
        .unwrap();
    assert!((last - 1.0).abs() < 1e-12);
}

#[test]
fn share_equals_the_truncated_static_deflection() {
    // cantilever_damped (rotated P0), tip: the cumulative share of the modes up to
    // 100 Hz in each direction equals the truncated body's static deflection (direct
    // solve with its K_L) over the full body's (direct solve), to 1e-9.
    let body = load_body(&fixture("cantilever_damped.fxb"), Default::default()).unwrap();
    let tip = body.node_index(121).unwrap();
    let p = static_participation(&body, &[tip]);
    let t = truncate(&body, 100.0).unwrap();
    let solve = |b: &fxbody::body::Body, c: usize| {
        let g = DMatrix::from_fn(6, b.nl(), |r, j| {
            let (half, k) = (r / 3, r % 3);
            (0..3)
                .map(|a| b.p0()[(k, a)] * b.phi_l()[(6 * tip + 3 * half + a, j)])
                .sum::<f64>()
        });
        let mut f = DVector::zeros(6);
        f[c] = 1.0;
        let q = b.k_l().clone().lu().solve(&(g.transpose() * &f)).unwrap();
        (g * q)[c]
    };
    for c in 0..6 {
        let share: f64 = p.fraction.column(c).rows(0, t.kept).sum();
        let want = solve(&t.body, c) / solve(&body, c);
        println!("direction {c}: share {share:.9}, direct {want:.9}");
        assert!((share - want).abs() < 1e-9, "direction {c}");
    }
}

#[test]
fn free_free_modes_carry_no_translational_mass() {
    // The modes of a free-free body are mass-orthogonal to the rigid translations:
    // effective mass below 1e-12 of the total mass in every direction (the shipped beam
    // and truss, both built as `fxbody import` builds a free body). The truss built on a
    // 3-2-1 support (tests/data/truss_supported.fxb) has modes that do carry mass
    // (printed), at most the total.
    for name in ["freefree.fxb", "truss.fxb"] {
        let ff = load_body(&fixture(name), Default::default()).unwrap();
        let m = ff.total_mass().unwrap();
        let e = effective_mass(&ff).unwrap();
        println!(
            "{name}: largest effective mass {:.1e} of the total",
            e.max() / m
        );
        assert!(e.max() < 1e-12 * m, "{name}: {}", e.max());
    }
    let truss = load_body(
        &crate::common::root().join("tests/data/truss_supported.fxb"),
        Default::default(),
    )
    .unwrap();
    let e = effective_mass(&truss).unwrap();
    let mt = truss.total_mass().unwrap();
    for c in 0..3 {
        let s = e.column(c).sum();
        println!("supported truss effective mass, direction {c}: {s:.6} of {mt:.6} kg");
        assert!(s > 0.1 * mt && s <= mt * (1.0 + 1e-9));
    }
    assert!(
        effective_mass(&load_body(&fixture("cantilever.fxb"), Default::default()).unwrap())
            .is_none()
    );
}
