//! The rotation and angular-velocity outputs through the FMI boundary (issue 15): read
//! with fmi2GetReal they are the solver's numbers; their output derivatives exist where
//! they hold (blocked bodies) and are refused with a reason where they do not (free).

#![allow(unsafe_code)]
#![cfg(target_os = "linux")]

use fxbody::fmi::types::*;
use fxbody::fmi::values::*;

use crate::common::fmu::{Packed, Slave, packed, packed_body};

fn step_under_load(fx: &Packed, node: i64, n: usize) -> Slave {
    let s = Slave::started(fx, None);
    let f = [
        fx.vr(&format!("node_{node}.fy")),
        fx.vr(&format!("node_{node}.mx")),
    ];
    assert_eq!(s.set_real(&f, &[1.0, 0.05]), fmi2OK);
    for k in 0..n {
        assert_eq!(
            s.do_step(k as f64 * 1e-4, 1e-4),
            fmi2OK,
            "{}",
            s.last_error()
        );
    }
    s
}

fn derivative(s: &Slave, vr: u32, order: i32) -> (fmi2Status, f64) {
    let mut v = f64::NAN;
    // SAFETY: a live instance, arrays of one element.
    let st = unsafe { fmi2GetRealOutputDerivatives(s.c, &vr, 1, &order, &mut v) };
    (st, v)
}

#[test]
fn blocked_rotation_outputs_and_their_derivatives() {
    let fx = packed("rot_blocked");
    let s = step_under_load(&fx, 121, 50);
    let names = ["rx", "ry", "rz", "wx", "wy", "wz"].map(|c| fx.vr(&format!("node_121.{c}")));
    let mut o = [0.0; 6];
    assert_eq!(s.get_real(&names, &mut o), fmi2OK);
    // Under fy and mx the tip turns about z (bending) and x (torsion): both nonzero.
    assert!(o[0].abs() > 1e-9 && o[2].abs() > 1e-9, "{o:?}");
    // d/dt of a rotation is the angular velocity output, bit for bit (the same rows).
    for c in 0..3 {
        let (st, d) = derivative(&s, names[c], 1);
        assert_eq!(st, fmi2OK);
        assert_eq!(d.to_bits(), o[3 + c].to_bits(), "{c}");
        // Order 2 of the rotation and order 1 of the angular velocity agree.
        let (st2, a2) = derivative(&s, names[c], 2);
        let (st1, a1) = derivative(&s, names[3 + c], 1);
        assert_eq!((st2, st1), (fmi2OK, fmi2OK));
        assert_eq!(a2.to_bits(), a1.to_bits());
        assert!(a1.is_finite());
    }
}

#[test]
fn free_rotation_derivatives_are_refused_with_the_reason() {
    let fx = packed_body("rot_free", "freefree", 521);
    let s = step_under_load(&fx, 521, 20);
    let rx = fx.vr("node_521.rx");
    let mut o = [f64::NAN];
    assert_eq!(s.get_real(&[rx], &mut o), fmi2OK);
    assert!(o[0].is_finite() && o[0] != 0.0);
    let (st, _) = derivative(&s, rx, 1);
    assert_eq!(st, fmi2Error);
    assert!(s.last_error().contains("node_521.rx"), "{}", s.last_error());
}
