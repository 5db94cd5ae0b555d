//! FMI misuse, bad arguments (issue 9): NULL arrays, nvr = 0, unknown value references,
//! values on outputs and on fixed parameters, the wrong type, NaN and infinite forces and
//! rates (alone and after a valid value in the same call), derivative orders that do
//! not exist, bad step sizes and communication points, steps past stopTime, unknown
//! status kinds and log categories. The calls go straight to the crate's exports.
//!
//! References, per case: fmi2Error with a logged reason naming the fault; the model's
//! complete state (serialised snapshot) byte for byte unchanged; allowed to go on, the
//! next steps equal those of an undisturbed twin bit for bit; and the FMI way out,
//! fmi2SetFMUstate, gives the same bits. Each test prints its case counts.

// Raw FFI: this test calls the exported fmi2* functions directly, as a C master does,
// which is `unsafe`; the workspace denies `unsafe_code` outside the FMI boundary.
#![allow(unsafe_code)]
// The tables of bad-argument cases hold dozens of one-line unsafe closures under one
// `// SAFETY (all closures):` comment each, which clippy cannot attribute to them.
#![allow(clippy::undocumented_unsafe_blocks)]
#![cfg(target_os = "linux")]

use std::collections::BTreeMap;
use std::ffi::{CString, c_char};
use std::ptr::{null, null_mut};

use crate::common::fmu::{
    AFTER, BEFORE, H, Slave, midway, packed, print_counts, reference, run, same_bits,
};
use fxbody::fmi::exports::*;
use fxbody::fmi::fmu_state::*;
use fxbody::fmi::state::FmiState;
use fxbody::fmi::types::*;
use fxbody::fmi::values::*;
use fxbody::fmu::vars::Causality;

#[test]
fn bad_arguments_are_refused_and_change_nothing() {
    let fx = packed("args");
    let twin = reference(&fx);
    let m = midway(&fx, None);
    let (c, fy, fz, y) = (
        m.s.c,
        fx.vr("node_121.fy"),
        fx.vr("node_121.fz"),
        fx.vr("node_121.y"),
    );
    let mut counts = BTreeMap::new();
    let mut count = |k| *counts.entry(k).or_insert(0usize) += 1;
    let mut v = [0.0; 2];
    let mut iv = [0; 2];
    let mut bv = [0; 2];
    let mut sv: [fmi2String; 2] = [null(); 2];
    let t = BEFORE as f64 * H;

    // NULL arrays with nvr > 0: each call runs from StepComplete (the previous refusal
    // is undone by `unchanged`, which ends with SetFMUstate).
    type Bad = Box<dyn Fn() -> fmi2Status>;
    let (pv, piv, pbv, psv, saved) = (
        v.as_mut_ptr(),
        iv.as_mut_ptr(),
        bv.as_mut_ptr(),
        sv.as_mut_ptr(),
        m.saved,
    );
    let zeros = [0 as c_char; 64];
    let pz = zeros.as_ptr();
    // SAFETY (all closures): `c` is live; each non-NULL pointer is valid for the length
    // given; the NULL pointers are what is being tested.
    let null_cases: Vec<(&str, &str, Bad)> = vec![
        (
            "GetReal vr",
            "vr is NULL",
            Box::new(move || unsafe { fmi2GetReal(c, null(), 1, pv) }),
        ),
        (
            "GetReal value",
            "value is NULL",
            Box::new(move || unsafe { fmi2GetReal(c, &y, 1, null_mut()) }),
        ),
        (
            "SetReal vr",
            "vr is NULL",
            Box::new(move || unsafe { fmi2SetReal(c, null(), 1, pv) }),
        ),
        (
            "SetReal value",
            "value is NULL",
            Box::new(move || unsafe { fmi2SetReal(c, &fy, 1, null()) }),
        ),
        (
            "GetInteger vr",
            "vr is NULL",
            Box::new(move || unsafe { fmi2GetInteger(c, null(), 1, piv) }),
        ),
        (
            "SetInteger value",
            "value is NULL",
            Box::new(move || unsafe { fmi2SetInteger(c, &y, 1, null()) }),
        ),
        (
            "GetBoolean vr",
            "vr is NULL",
            Box::new(move || unsafe { fmi2GetBoolean(c, null(), 1, pbv) }),
        ),
        (
            "SetBoolean vr",
            "vr is NULL",
            Box::new(move || unsafe { fmi2SetBoolean(c, null(), 1, pbv) }),
        ),
        (
            "GetString vr",
            "vr is NULL",
            Box::new(move || unsafe { fmi2GetString(c, null(), 1, psv) }),
        ),
        (
            "SetString vr",
            "vr is NULL",
            Box::new(move || unsafe { fmi2SetString(c, null(), 1, psv) }),
        ),
        (
            "SetRealInputDerivatives order",
            "order is NULL",
            Box::new(move || unsafe { fmi2SetRealInputDerivatives(c, &fy, 1, null(), pv) }),
        ),
        (
            "SetRealInputDerivatives value",
            "value is NULL",
            Box::new(move || unsafe { fmi2SetRealInputDerivatives(c, &fy, 1, &1, null()) }),
        ),
        (
            "GetRealOutputDerivatives value",
            "value is NULL",
            Box::new(move || unsafe { fmi2GetRealOutputDerivatives(c, &y, 1, &1, null_mut()) }),
        ),
        (
            "SetDebugLogging categories",
            "categories is NULL",
            Box::new(move || unsafe { fmi2SetDebugLogging(c, fmi2True, 3, null()) }),
        ),
        (
            "SetDebugLogging category",
            "category name is NULL",
            Box::new(move || unsafe { fmi2SetDebugLogging(c, fmi2True, 1, [null()].as_ptr()) }),
        ),
        (
            "GetFMUstate",
            "pointer is NULL",
            Box::new(move || unsafe { fmi2GetFMUstate(c, null_mut()) }),
        ),
        (
            "SetFMUstate",
            "FMUstate is NULL",
            Box::new(move || unsafe { fmi2SetFMUstate(c, null_mut()) }),
        ),
        (
            "SerializedFMUstateSize state",
            "FMUstate is NULL",
            Box::new(move || unsafe { fmi2SerializedFMUstateSize(c, null_mut(), &mut 0) }),
        ),
        (
            "SerializedFMUstateSize size",
            "size pointer is NULL",
            Box::new(move || unsafe { fmi2SerializedFMUstateSize(c, saved, null_mut()) }),
        ),
        (
            "SerializeFMUstate buffer",
            "buffer is",
            Box::new(move || unsafe { fmi2SerializeFMUstate(c, saved, null_mut(), 16) }),
        ),
        (
            "DeSerializeFMUstate bytes",
            "serializedState is NULL",
            Box::new(move || unsafe { fmi2DeSerializeFMUstate(c, null(), 64, &mut null_mut()) }),
        ),
        (
            "DeSerializeFMUstate state",
            "FMUstate pointer is NULL",
            Box::new(move || unsafe { fmi2DeSerializeFMUstate(c, pz, 64, null_mut()) }),
        ),
        (
            "GetRealStatus value",
            "value pointer is NULL",
            Box::new(move || unsafe { fmi2GetRealStatus(c, fmi2LastSuccessfulTime, null_mut()) }),
        ),
        (
            "GetBooleanStatus value",
            "value pointer is NULL",
            Box::new(move || unsafe { fmi2GetBooleanStatus(c, fmi2Terminated, null_mut()) }),
        ),
    ];
    for (what, says, call) in &null_cases {
        m.refused(call(), says, what);
        m.unchanged(&fx, &twin, what);
        count("NULL array");
    }

    // nvr = 0 with NULL arrays: nothing to do, OK, nothing changes, no error state.
    // SAFETY (all closures): nvr = 0, so no pointer is read.
    let empty: Vec<(&str, Bad)> = vec![
        (
            "GetReal",
            Box::new(move || unsafe { fmi2GetReal(c, null(), 0, null_mut()) }),
        ),
        (
            "SetReal",
            Box::new(move || unsafe { fmi2SetReal(c, null(), 0, null()) }),
        ),
        (
            "GetInteger",
            Box::new(move || unsafe { fmi2GetInteger(c, null(), 0, null_mut()) }),
        ),
        (
            "SetInteger",
            Box::new(move || unsafe { fmi2SetInteger(c, null(), 0, null()) }),
        ),
        (
            "GetBoolean",
            Box::new(move || unsafe { fmi2GetBoolean(c, null(), 0, null_mut()) }),
        ),
        (
            "SetBoolean",
            Box::new(move || unsafe { fmi2SetBoolean(c, null(), 0, null()) }),
        ),
        (
            "GetString",
            Box::new(move || unsafe { fmi2GetString(c, null(), 0, null_mut()) }),
        ),
        (
            "SetString",
            Box::new(move || unsafe { fmi2SetString(c, null(), 0, null()) }),
        ),
        (
            "SetRealInputDerivatives",
            Box::new(move || unsafe { fmi2SetRealInputDerivatives(c, null(), 0, null(), null()) }),
        ),
        (
            "GetRealOutputDerivatives",
            Box::new(move || unsafe {
                fmi2GetRealOutputDerivatives(c, null(), 0, null(), null_mut())
            }),
        ),
    ];
    for (what, call) in &empty {
        assert_eq!(call(), fmi2OK, "{what} with nvr = 0");
        assert_eq!(m.s.fmi_state(), FmiState::StepComplete, "{what}");
        m.unchanged(&fx, &twin, what);
        count("nvr = 0");
    }

    // Unknown value references, in every function that takes one.
    let n = fx.p.table.vars.len() as u32;
    for bad in [n, n + 1, 99_999, u32::MAX] {
        let b = [bad];
        let pb = b.as_ptr();
        // SAFETY (all closures): arrays of one element.
        let unknown: Vec<(&str, &str, Bad)> = vec![
            (
                "GetReal",
                "unknown value reference",
                Box::new(move || unsafe { fmi2GetReal(c, pb, 1, pv) }),
            ),
            (
                "SetReal",
                "unknown value reference",
                Box::new(move || unsafe { fmi2SetReal(c, pb, 1, &1.0) }),
            ),
            (
                "GetInteger",
                "unknown value reference",
                Box::new(move || unsafe { fmi2GetInteger(c, pb, 1, piv) }),
            ),
            (
                "SetInteger",
                "unknown value reference",
                Box::new(move || unsafe { fmi2SetInteger(c, pb, 1, &1) }),
            ),
            (
                "GetBoolean",
                "no Boolean variables",
                Box::new(move || unsafe { fmi2GetBoolean(c, pb, 1, pbv) }),
            ),
            (
                "SetBoolean",
                "no Boolean variables",
                Box::new(move || unsafe { fmi2SetBoolean(c, pb, 1, &1) }),
            ),
            (
                "GetString",
                "no String variables",
                Box::new(move || unsafe { fmi2GetString(c, pb, 1, psv) }),
            ),
            (
                "SetString",
                "no String variables",
                Box::new(move || unsafe { fmi2SetString(c, pb, 1, [c"x".as_ptr()].as_ptr()) }),
            ),
            (
                "SetRealInputDerivatives",
                "unknown value reference",
                Box::new(move || unsafe { fmi2SetRealInputDerivatives(c, pb, 1, &1, &1.0) }),
            ),
            (
                "GetRealOutputDerivatives",
                "unknown value reference",
                Box::new(move || unsafe { fmi2GetRealOutputDerivatives(c, pb, 1, &1, pv) }),
            ),
        ];
        for (what, says, call) in &unknown {
            m.refused(call(), says, &format!("{what} vr {bad}"));
            m.unchanged(&fx, &twin, what);
            count("unknown value reference");
        }
        // A good reference first and the unknown one second: still all refused.
        let pair = [fy, bad];
        m.refused(
            // SAFETY: arrays of two elements.
            unsafe { fmi2SetReal(c, pair.as_ptr(), 2, [3.0, 1.0].as_ptr()) },
            "unknown value reference",
            "SetReal good + unknown",
        );
        m.unchanged(&fx, &twin, "SetReal good + unknown");
        count("unknown value reference");
    }

    // Values set on outputs, and on parameters after initialisation; the wrong type.
    for var in &fx.p.table.vars {
        let (st, says) = if var.is_integer() {
            // SAFETY: arrays of one element.
            (
                unsafe { fmi2SetReal(c, &var.vr, 1, &1.0) },
                "fmi2SetInteger",
            )
        } else {
            // SAFETY: arrays of one element.
            (unsafe { fmi2SetInteger(c, &var.vr, 1, &1) }, "fmi2SetReal")
        };
        m.refused(st, says, &format!("wrong type on {}", var.name));
        m.unchanged(&fx, &twin, &var.name);
        count("wrong type");
        let says = match var.causality {
            Causality::Input | Causality::Local => continue,
            Causality::Output => "is an output",
            Causality::Parameter => "fixed parameter",
        };
        let st = if var.is_integer() {
            // SAFETY: arrays of one element.
            unsafe { fmi2SetInteger(c, &var.vr, 1, &1) }
        } else {
            // SAFETY: arrays of one element.
            unsafe { fmi2SetReal(c, &var.vr, 1, &0.5) }
        };
        m.refused(st, says, &var.name);
        m.unchanged(&fx, &twin, &var.name);
        count(if var.causality == Causality::Output {
            "set an output"
        } else {
            "set a parameter after initialisation"
        });
    }

    // NaN and infinite forces and force rates: alone, and after a valid value in the
    // same call (the valid one must not be applied either).
    for bad in [f64::NAN, -f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        m.refused(m.s.set_real(&[fy], &[bad]), "must be finite", "bad force");
        m.unchanged(&fx, &twin, "bad force");
        m.refused(
            m.s.set_real(&[fz, fy], &[2.0, bad]),
            "must be finite",
            "good + bad",
        );
        m.unchanged(&fx, &twin, "good + bad force");
        m.refused(
            // SAFETY: arrays of two elements.
            unsafe {
                fmi2SetRealInputDerivatives(
                    c,
                    [fz, fy].as_ptr(),
                    2,
                    [1, 1].as_ptr(),
                    [2.0, bad].as_ptr(),
                )
            },
            "must be finite",
            "bad force rate",
        );
        m.unchanged(&fx, &twin, "bad force rate");
        count("non-finite force");
        count("non-finite force");
        count("non-finite force");
    }
    // Derivative orders that do not exist.
    for order in [0, 2, 3, -1, i32::MAX] {
        m.refused(
            // SAFETY: arrays of one element.
            unsafe { fmi2SetRealInputDerivatives(c, &fy, 1, &order, &1.0) },
            "order",
            "input derivative order",
        );
        m.unchanged(&fx, &twin, "input derivative order");
        count("bad derivative order");
    }
    for order in [0, 3, -1, i32::MIN] {
        m.refused(
            // SAFETY: arrays of one element.
            unsafe { fmi2GetRealOutputDerivatives(c, &y, 1, &order, pv) },
            "no derivative of order",
            "output derivative order",
        );
        m.unchanged(&fx, &twin, "output derivative order");
        count("bad derivative order");
    }

    // Step sizes and communication points that are wrong.
    for h in [
        0.0,
        -0.0,
        -H,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        -f64::MIN_POSITIVE,
    ] {
        m.refused(
            m.s.do_step(t, h),
            "communicationStepSize",
            &format!("h = {h}"),
        );
        m.unchanged(&fx, &twin, "bad h");
        count("h <= 0 or not finite");
    }
    for tc in [
        t + H,
        t - H,
        0.0,
        1e9,
        -t,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        t * (1.0 + 1e-6),
    ] {
        m.refused(m.s.do_step(tc, H), "current time", &format!("t = {tc}"));
        m.unchanged(&fx, &twin, "wrong time");
        count("wrong current time");
    }
    // Status kinds that do not exist: Discard, nothing written, the instance continues.
    for kind in [-1, 4, 99, i32::MIN] {
        let mut r = -7.0;
        let mut b = -7;
        // SAFETY: writable values.
        let (s1, s2) = unsafe {
            (
                fmi2GetRealStatus(c, kind, &mut r),
                fmi2GetBooleanStatus(c, kind, &mut b),
            )
        };
        assert_eq!((s1, s2, r, b), (fmi2Discard, fmi2Discard, -7.0, -7));
        assert_eq!(m.s.fmi_state(), FmiState::StepComplete);
        m.unchanged(&fx, &twin, "status kind");
        count("unknown status kind");
    }
    // Unknown log categories (with '%' in the name: the text reaches the log as is).
    let cat = CString::new("%s%n%d").unwrap();
    m.refused(
        // SAFETY: one valid category string.
        unsafe { fmi2SetDebugLogging(c, fmi2True, 1, [cat.as_ptr()].as_ptr()) },
        "unknown log category '%s%n%d'",
        "category",
    );
    m.unchanged(&fx, &twin, "category");
    count("unknown log category");
    print_counts("bad arguments", &counts);
}

#[test]
fn steps_past_stop_time_are_refused() {
    let fx = packed("stop");
    let twin = reference(&fx);
    let stop = (BEFORE + AFTER) as f64 * H;
    let m = midway(&fx, Some(stop));
    let t = BEFORE as f64 * H;
    let mut n = 0;
    for h in [stop, 2.0 * stop, (AFTER as f64 + 0.01) * H, 1e300] {
        m.refused(m.s.do_step(t, h), "past stopTime", &format!("h = {h}"));
        m.unchanged(&fx, &twin, "past stopTime");
        n += 1;
    }
    // Right up to stopTime is fine; one more step is not.
    assert_eq!(
        run(&m.s, &fx, BEFORE, AFTER).unwrap(),
        twin[BEFORE..].to_vec()
    );
    assert_eq!(m.s.do_step(stop, H), fmi2Error);
    assert!(m.s.last_error().contains("past stopTime"));
    // A stop time before the start, or NaN, is refused at setup.
    for (start, stop) in [
        (1.0, 0.5),
        (0.0, f64::NAN),
        (f64::NAN, 1.0),
        (f64::INFINITY, 1.0),
    ] {
        let s = Slave::new(&fx, "setup");
        assert_eq!(s.setup(start, Some(stop)), fmi2Error, "{start} {stop}");
        n += 1;
    }
    println!("past stopTime: {} cases", n + 1);
}

#[test]
fn extreme_step_sizes_give_finite_results_or_an_error() {
    let fx = packed("huge");
    let (fy, y, vy) = (
        fx.vr("node_121.fy"),
        fx.vr("node_121.y"),
        fx.vr("node_121.vy"),
    );
    let mut counts = BTreeMap::new();
    for &method in fx.p.table.methods() {
        for h in [5e-324, 1e-300, 1e-12, 1e-2, 1e300, f64::MAX] {
            let s = Slave::new(&fx, "extreme");
            let m = fx.vr("method");
            // SAFETY: a live instance, arrays of one element.
            assert_eq!(
                unsafe { fmi2SetInteger(s.c, &m, 1, &(method as i32)) },
                fmi2OK
            );
            assert_eq!(s.setup(0.0, None), fmi2OK);
            // SAFETY: a live instance.
            unsafe {
                assert_eq!(fmi2EnterInitializationMode(s.c), fmi2OK);
                assert_eq!(fmi2ExitInitializationMode(s.c), fmi2OK);
            }
            assert_eq!(s.set_real(&[fy], &[1.0]), fmi2OK);
            let st = s.do_step(0.0, h);
            let kind = if st == fmi2OK {
                let mut o = [0.0; 2];
                assert_eq!(s.get_real(&[y, vy], &mut o), fmi2OK);
                assert!(
                    o.iter().all(|v| v.is_finite()),
                    "{method:?} h = {h}: outputs {o:?}"
                );
                "accepted, finite outputs"
            } else {
                // Refused: allowed to go on (white box), the next ordinary step equals
                // a twin's first step bit for bit. (The snapshot itself may differ: the
                // refused step already handed the pending load to the solver, which
                // the next step would have done identically.)
                assert_eq!(st, fmi2Error, "{method:?} h = {h}");
                s.force_state(FmiState::StepComplete);
                let twin = Slave::new(&fx, "twin");
                // SAFETY: a live instance, arrays of one element.
                assert_eq!(
                    unsafe { fmi2SetInteger(twin.c, &m, 1, &(method as i32)) },
                    fmi2OK
                );
                assert_eq!(twin.setup(0.0, None), fmi2OK);
                // SAFETY: a live instance.
                unsafe {
                    assert_eq!(fmi2EnterInitializationMode(twin.c), fmi2OK);
                    assert_eq!(fmi2ExitInitializationMode(twin.c), fmi2OK);
                }
                assert_eq!(twin.set_real(&[fy], &[1.0]), fmi2OK);
                let (mut a, mut b) = ([0.0; 2], [0.0; 2]);
                for (sl, o) in [(&s, &mut a), (&twin, &mut b)] {
                    assert_eq!(sl.do_step(0.0, H), fmi2OK, "{method:?} after h = {h}");
                    assert_eq!(sl.get_real(&[y, vy], o), fmi2OK);
                }
                assert!(
                    same_bits(&a, &b),
                    "{method:?} after h = {h}: {a:?} vs {b:?}"
                );
                assert!(a[0] != 0.0 || a[1] != 0.0);
                "refused, continues like the twin"
            };
            *counts.entry(kind).or_insert(0usize) += 1;
        }
    }
    print_counts("extreme step sizes", &counts);
}
