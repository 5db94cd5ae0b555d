//! `method` is an FMI Integer parameter (issue 15: libcosim and ecos ignore Enumeration
//! variables): every value of the method table is settable, a value outside it or for
//! another kind of body (exact on a free body) is refused with a logged reason, and the
//! instance stays usable with the method it had.

// Raw FFI: the exported fmi2* functions, called as a C master does.
#![allow(unsafe_code)]
#![cfg(target_os = "linux")]

use fxbody::fmi::exports::*;
use fxbody::fmi::state::FmiState;
use fxbody::fmi::types::*;
use fxbody::fmi::values::*;

use crate::common::fmu::{Packed, Slave, packed, packed_body};

fn set_method(s: &Slave, fx: &Packed, v: i32) -> fmi2Status {
    let m = fx.vr("method");
    // SAFETY: a live instance, arrays of one element.
    unsafe { fmi2SetInteger(s.c, &m, 1, &v) }
}

fn get_method(s: &Slave, fx: &Packed) -> i32 {
    let m = fx.vr("method");
    let mut v = -1;
    // SAFETY: a live instance, arrays of one element.
    assert_eq!(unsafe { fmi2GetInteger(s.c, &m, 1, &mut v) }, fmi2OK);
    v
}

/// Initialise and take ten steps under a tip load; the tip's y after them.
fn run_tip(s: &Slave, fx: &Packed, node: i64) -> f64 {
    assert_eq!(s.setup(0.0, None), fmi2OK);
    // SAFETY: a live instance.
    unsafe {
        assert_eq!(fmi2EnterInitializationMode(s.c), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(s.c), fmi2OK);
    }
    let (f, y) = (
        fx.vr(&format!("node_{node}.fy")),
        fx.vr(&format!("node_{node}.y")),
    );
    assert_eq!(s.set_real(&[f], &[1.0]), fmi2OK);
    for k in 0..10 {
        assert_eq!(
            s.do_step(k as f64 * 1e-4, 1e-4),
            fmi2OK,
            "{}",
            s.last_error()
        );
    }
    let mut o = [0.0];
    assert_eq!(s.get_real(&[y], &mut o), fmi2OK);
    o[0]
}

#[test]
fn out_of_range_methods_are_refused_with_the_range_and_the_instance_runs_on() {
    let fx = packed("method_range");
    let twin = run_tip(&Slave::new(&fx, "twin"), &fx, 121);
    // 4 (split) exists but handles free bodies only: refused on this blocked body with
    // that reason.
    let s = Slave::new(&fx, "split");
    assert_eq!(set_method(&s, &fx, 4), fmi2Error);
    let e = s.last_error();
    assert!(
        e.contains("split (4) handles free (Iblo=0) bodies only and this body is blocked"),
        "{e}"
    );
    for bad in [0, 5, -1, i32::MIN, i32::MAX] {
        let s = Slave::new(&fx, "bad");
        assert_eq!(set_method(&s, &fx, bad), fmi2Error, "{bad}");
        let e = s.last_error();
        assert!(
            e.contains(&format!("method: {bad} is not offered"))
                && e.contains("no method has the value")
                && e.contains("values 1..4")
                && e.contains("explicit=1, implicit=2, exact=3"),
            "{e}"
        );
        // Nothing changed (the complete state equals a fresh twin's, byte for byte);
        // allowed to go on (white box, as in bad_args.rs: FMI puts the instance in its
        // Error state), it still runs the default (exact) and steps like the twin.
        assert_eq!(s.fingerprint(), Slave::new(&fx, "fresh").fingerprint());
        s.force_state(FmiState::Instantiated);
        assert_eq!(run_tip(&s, &fx, 121).to_bits(), twin.to_bits(), "{bad}");
        assert_eq!(get_method(&s, &fx), 3);
    }
    // Every value of the table is accepted and read back.
    for v in 1..=3 {
        let s = Slave::new(&fx, "ok");
        assert_eq!(set_method(&s, &fx, v), fmi2OK);
        assert!(run_tip(&s, &fx, 121).abs() > 1e-9);
        assert_eq!(get_method(&s, &fx), v);
    }
}

#[test]
fn exact_on_a_free_body_is_refused_naming_the_body_kind() {
    let fx = packed_body("method_free", "freefree", 521);
    let s = Slave::new(&fx, "free");
    assert_eq!(set_method(&s, &fx, 3), fmi2Error);
    let e = s.last_error();
    assert!(
        e.contains("exact (3) handles blocked (Iblo=1) bodies only and this body is free")
            && e.contains("explicit=1, implicit=2")
            && !e.contains("exact=3"),
        "{e}"
    );
    // The refusal changed nothing (state byte for byte that of a fresh instance);
    // allowed to go on (white box), explicit can still be chosen and runs.
    assert_eq!(s.fingerprint(), Slave::new(&fx, "fresh").fingerprint());
    s.force_state(FmiState::Instantiated);
    assert_eq!(set_method(&s, &fx, 1), fmi2OK);
    assert!(run_tip(&s, &fx, 521).is_finite());
    assert_eq!(get_method(&s, &fx), 1);
}

#[test]
fn damping_ratio_is_a_real_parameter_that_reaches_the_solver_and_refuses_negatives() {
    let fx = packed("damping_param");
    let d = fx.vr("damping.ratio");
    let s = Slave::new(&fx, "neg");
    assert_eq!(s.set_real(&[d], &[-0.01]), fmi2Error);
    let e = s.last_error();
    assert!(
        e.contains("damping.ratio must be >= 0") && e.contains("-0.01"),
        "{e}"
    );
    // The same run with 0 (the start value) and with 0.05: the damped tip moves less
    // after ten steps of a step load than the undamped one, by the analytic amount to
    // first order (the solver's own tests check the decay against the damped
    // oscillator; this shows the FMU parameter is the one they read).
    let plain = run_tip(&Slave::new(&fx, "zero"), &fx, 121);
    let damped = Slave::new(&fx, "damped");
    assert_eq!(damped.set_real(&[d], &[0.05]), fmi2OK);
    let y = run_tip(&damped, &fx, 121);
    let mut back = [f64::NAN];
    assert_eq!(damped.get_real(&[d], &mut back), fmi2OK);
    assert_eq!(back[0], 0.05);
    assert!(y != plain && y.abs() < plain.abs(), "{y} vs {plain}");
}
