//! Mass properties from M_R (`fxbody info`): the centre of gravity and the inertia
//! tensor at it against the full finite-element models of the fixtures.
//! - truss (57 pin-jointed bars, consistent linear bar mass, which integrates the affine
//!   rigid modes exactly): every bar as a uniform rod,
//!   `int x x^T dm = m (a a^T + b b^T) / 3 + m (a b^T + b a^T) / 6`, summed from the fixture's bar list, node deck, rho and A;
//!   agreement to 1e-8 of the largest inertia (the file's values carry about 10
//!   significant digits);
//! - freefree beam: the axial inertia is the torsional rho Ip L (from rotation rows
//!   13-15) to 1e-8; the transverse ones m L^2 / 12 to 2e-3, the discretisation's share:
//!   the rigid modes carry no nodal rotations, so the Hermite consistent mass integrates
//!   a field that matches X only at the nodes;
//! - both: the centre of gravity placed at L0 + P0 c equals the reference's centre of
//!   mass to 1e-9 m.

use fxbody::body::mass_props::mass_properties;
use nalgebra::{Matrix3, Vector3};

use crate::common::{fixture, fixture_reference, nums};

fn frame(r: &serde_json::Value) -> (Matrix3<f64>, Vector3<f64>) {
    let p0 = r["frame"]["P0"].as_array().unwrap();
    let p = Matrix3::from_fn(|i, j| nums(&p0[i])[j]);
    let x = nums(&r["frame"]["x_L0"]);
    (p, Vector3::new(x[0], x[1], x[2]))
}

#[test]
fn truss_inertia_equals_the_bars_sum() {
    let body = fxbody::body::load(&fixture("truss.fxb")).unwrap();
    let r = fixture_reference("truss");
    let xyz = fxbody::fxb::coords::to_map(
        &fxbody::fxb::coords::read_coords(&fixture("truss.nodes.rad")).unwrap(),
    );
    let rho = r["model"]["rho"].as_f64().unwrap();
    let area = r["model"]["A"].as_f64().unwrap();
    let (mut m, mut s1, mut s2) = (0.0, Vector3::zeros(), Matrix3::zeros());
    for bar in r["model"]["bars"].as_array().unwrap() {
        let ids = bar.as_array().unwrap();
        let at = |k: usize| Vector3::from(xyz[&ids[k].as_i64().unwrap()]);
        let (a, b) = (at(0), at(1));
        let mb = rho * area * (b - a).norm();
        m += mb;
        s1 += mb * (a + b) / 2.0;
        s2 += mb * (a * a.transpose() + b * b.transpose()) / 3.0
            + mb * (a * b.transpose() + b * a.transpose()) / 6.0;
    }
    let c = s1 / m;
    let e = s2 - m * c * c.transpose();
    let inertia = Matrix3::identity() * e.trace() - e;
    let p = mass_properties(&body).expect("a free body has mass properties");
    let (_, x_l0) = frame(&r);
    assert!((p.mass - m).abs() < 1e-9 * m, "{} vs {m}", p.mass);
    let com = nums(&r["center_of_mass"]);
    let got = x_l0 + p.cog_from_l0;
    for k in 0..3 {
        assert!((got[k] - c[k]).abs() < 1e-9, "cog {got} vs bars {c}");
        assert!(
            (got[k] - com[k]).abs() < 1e-9,
            "cog {got} vs reference {com:?}"
        );
    }
    let scale = inertia.abs().max();
    let err = (p.inertia - inertia).abs().max();
    assert!(
        err < 1e-8 * scale,
        "inertia {} vs {inertia}: {err}",
        p.inertia
    );
}

#[test]
fn freefree_beam_inertia_is_the_rods() {
    let body = fxbody::body::load(&fixture("freefree.fxb")).unwrap();
    let r = fixture_reference("freefree");
    let model = &r["model"];
    let (rho, len) = (
        model["rho"].as_f64().unwrap(),
        model["length"].as_f64().unwrap(),
    );
    let ip = model["section"]["Ip"].as_f64().unwrap();
    let m = r["total_mass"].as_f64().unwrap();
    let p = mass_properties(&body).unwrap();
    let (p0, x_l0) = frame(&r);
    let com = nums(&r["center_of_mass"]);
    for k in 0..3 {
        assert!((x_l0[k] + p.cog_from_l0[k] - com[k]).abs() < 1e-9);
    }
    // Back to the local axes (beam along X).
    let local = p0.transpose() * p.inertia * p0;
    let axial = rho * ip * len;
    let transverse = m * len * len / 12.0;
    assert!(
        (local[(0, 0)] - axial).abs() < 1e-8 * axial,
        "{} vs {axial}",
        local[(0, 0)]
    );
    for k in 1..3 {
        let rel = (local[(k, k)] - transverse).abs() / transverse;
        assert!(rel < 2e-3, "{} vs {transverse}: {rel}", local[(k, k)]);
    }
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        assert!(local[(i, j)].abs() < 1e-9 * transverse, "{local}");
    }
}
