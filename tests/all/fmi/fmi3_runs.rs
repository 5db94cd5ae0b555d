//! The FMI 3.0 co-simulation FMU against the FMI 2.0 one (issue 26.1): the same body
//! packed both ways, driven through each version's exports with the same loads, gives
//! the same outputs bit for bit for every method and fixture (one library, one model;
//! only the boundary differs); its FMU states round-trip; FMI 3.0's own conventions
//! (nValues, the independent variable `time`, loggingOn, '#' in messages, the
//! instantiation arguments) hold.

// Raw FFI: this test calls the exported fmi2*/fmi3* functions directly, as a C master
// does, which is `unsafe`; the workspace denies `unsafe_code` outside the FMI boundary.
#![allow(unsafe_code)]
#![cfg(target_os = "linux")]

use crate::common::fmu::{BEFORE, H, Packed, Slave, Stepper, packed_as_version, same_bits};
use crate::common::fmu3::{Slave3, packed3};
use fxbody::fmi::fmi3::exports::*;
use fxbody::fmi::fmi3::types::*;
use fxbody::fmi::fmi3::values::*;
use fxbody::fmi::state::FmiState;
use fxbody::fmi::types::{fmi2OK, fmi2Warning};
use fxbody::fmi::values::{fmi2GetRealOutputDerivatives, fmi2SetInteger};
use fxbody::fmu::fmi_version::FmiVersion;
use fxbody::fmu::vars::{Causality, Kind};

/// Steps of each comparison run.
const STEPS: usize = 60;

/// The loads of a run: every load input of the exposed node, each its own smooth signal
/// (a different frequency and phase per component, so that a swapped value reference
/// shows).
fn loads(fx: &Packed, t: f64) -> (Vec<u32>, Vec<f64>) {
    let mut vrs = Vec::new();
    let mut vals = Vec::new();
    for v in &fx.p.table.vars {
        if let Kind::Load { comp, .. } = v.kind {
            let c = comp as f64;
            vrs.push(v.vr);
            vals.push((1.0 + 0.5 * c) * ((200.0 + 70.0 * c) * t + 0.3 * c).cos());
        }
    }
    (vrs, vals)
}

/// Every output's value reference.
fn outputs(fx: &Packed) -> Vec<u32> {
    let o: Vec<u32> =
        fx.p.table
            .vars
            .iter()
            .filter(|v| v.causality == Causality::Output)
            .map(|v| v.vr)
            .collect();
    assert!(o.len() >= 6, "outputs: {o:?}");
    o
}

/// `STEPS` steps with [`loads`]: each step's status and every output after it.
fn history(s: &impl Stepper, fx: &Packed) -> Vec<f64> {
    let outs = outputs(fx);
    let mut all = Vec::with_capacity(STEPS * outs.len());
    let mut o = vec![0.0; outs.len()];
    for k in 0..STEPS {
        let t = k as f64 * H;
        let (vrs, vals) = loads(fx, t);
        assert_eq!(s.set_real(&vrs, &vals), fmi2OK, "{}", s.last_error());
        // A step may warn (the explicit method's stability, logged): the status is part
        // of the history compared.
        let st = s.do_step(t, H);
        assert!(st <= fmi2Warning, "step {k}: {st}: {}", s.last_error());
        assert_eq!(s.get_real(&outs, &mut o), fmi2OK, "{}", s.last_error());
        all.push(f64::from(st));
        all.extend_from_slice(&o);
    }
    all
}

/// Position outputs (the ones with output derivatives) and their derivatives of order 1
/// and 2, through the FMI 2.0 or 3.0 function.
fn output_derivatives(fx: &Packed, c: *mut std::ffi::c_void, v3: bool) -> Vec<f64> {
    let pos: Vec<u32> =
        fx.p.table
            .vars
            .iter()
            .filter(|v| matches!(v.kind, Kind::Position { .. }))
            .map(|v| v.vr)
            .collect();
    let mut out = Vec::new();
    for order in [1, 2] {
        let ords = vec![order; pos.len()];
        let mut d = vec![f64::NAN; pos.len()];
        // SAFETY: a live instance; arrays of `pos.len()` elements, `d` writable.
        let st = unsafe {
            if v3 {
                fmi3GetOutputDerivatives(
                    c,
                    pos.as_ptr(),
                    pos.len(),
                    ords.as_ptr(),
                    d.as_mut_ptr(),
                    d.len(),
                )
            } else {
                fmi2GetRealOutputDerivatives(
                    c,
                    pos.as_ptr(),
                    pos.len(),
                    ords.as_ptr(),
                    d.as_mut_ptr(),
                )
            }
        };
        assert_eq!(st, fmi2OK);
        out.extend(d);
    }
    out
}

/// Issue 26.1 and 26.4: for every fixture and every method it offers, the FMI 3.0 FMU's
/// outputs and output derivatives equal the FMI 2.0 FMU's bit for bit over a run with
/// loads on all six components of the exposed node. Reference: the FMI 2.0 FMU (the
/// product's tested interface). A real response is required (no vacuous equality), and
/// each method must differ from the others (the method parameter reached the solver
/// through fmi3SetInt32).
#[test]
fn fmi3_outputs_equal_fmi2_bit_for_bit_for_every_method_and_fixture() {
    let mut runs = 0;
    for (body, node) in [
        ("cantilever", 121),
        ("cantilever_damped", 121),
        ("freefree", 521),
        ("truss", 1043),
    ] {
        let fx2 = packed_as_version(&format!("v2_{body}"), body, node, None, FmiVersion::Fmi2);
        let fx3 = packed_as_version(&format!("v3_{body}"), body, node, None, FmiVersion::Fmi3);
        // The same variable table: names and value references agree.
        let names = |fx: &Packed| -> Vec<(String, u32)> {
            fx.p.table
                .vars
                .iter()
                .map(|v| (v.name.clone(), v.vr))
                .collect()
        };
        assert_eq!(names(&fx2), names(&fx3), "{body}");
        assert_eq!(fx2.p.guid, fx3.p.guid, "{body}: one GUID source");
        let methods: &[i32] = if fx2.p.table.free {
            &[1, 2, 4]
        } else {
            &[1, 2, 3]
        };
        let m = fx2.vr("method");
        let mut per_method: Vec<Vec<f64>> = Vec::new();
        for &method in methods {
            let s2 = Slave::new(&fx2, "v2");
            // SAFETY: a live instance; one value reference and one value.
            assert_eq!(unsafe { fmi2SetInteger(s2.c, &m, 1, &method) }, fmi2OK);
            assert_eq!(s2.setup(0.0, None), fmi2OK);
            // SAFETY: a live instance.
            unsafe {
                assert_eq!(
                    fxbody::fmi::exports::fmi2EnterInitializationMode(s2.c),
                    fmi2OK
                );
                assert_eq!(
                    fxbody::fmi::exports::fmi2ExitInitializationMode(s2.c),
                    fmi2OK
                );
            }
            let s3 = Slave3::new(&fx3, "v3");
            assert_eq!(s3.set_int(&[m], &[method]), fmi3OK, "{}", s3.last_error());
            assert_eq!(s3.enter_init(0.0, None), fmi3OK);
            // SAFETY: a live instance.
            assert_eq!(unsafe { fmi3ExitInitializationMode(s3.c) }, fmi3OK);
            let (mut a, mut b) = (history(&s2, &fx2), history(&s3, &fx3));
            a.extend(output_derivatives(&fx2, s2.c, false));
            b.extend(output_derivatives(&fx3, s3.c, true));
            let peak = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(
                peak > 0.0 && a.iter().all(|v| v.is_finite()),
                "{body} {method}"
            );
            assert!(
                same_bits(&a, &b),
                "{body}, method {method}: FMI 3.0 differs"
            );
            assert!(
                per_method.iter().all(|p| !same_bits(p, &a)),
                "{body}, method {method}: the same history as another method"
            );
            per_method.push(a);
            runs += 1;
        }
    }
    assert_eq!(runs, 12);
    println!("fmi3 vs fmi2: {runs} runs of {STEPS} steps, equal bit for bit");
}

/// fmi3GetFMUState / SetFMUState / Serialize / Deserialize: a state saved after BEFORE
/// steps and restored (in place, and serialised into a fresh instance) continues exactly
/// like the undisturbed run; a state restored into Instantiated or Terminated brings the
/// instance back to Step Mode. Reference: the undisturbed run itself.
#[test]
fn fmi3_fmu_state_round_trip() {
    let fx = packed3("state3");
    let s = Slave3::started(&fx, None);
    let first = crate::common::fmu::run(&s, &fx, 0, BEFORE).unwrap();
    let saved = s.get_state();
    let ahead = crate::common::fmu::run(&s, &fx, BEFORE, BEFORE).unwrap();
    assert!(ahead.iter().any(|v| v.abs() > 1e-9) && !same_bits(&first, &ahead));
    // In place.
    assert_eq!(s.set_state(saved), fmi3OK);
    let again = crate::common::fmu::run(&s, &fx, BEFORE, BEFORE).unwrap();
    assert!(same_bits(&again, &ahead));
    // Serialised, into a fresh instance that has not been initialised, and into one
    // that has terminated.
    let bytes = s.serialize(saved);
    for terminated in [false, true] {
        let fresh = if terminated {
            let f = Slave3::started(&fx, None);
            // SAFETY: a live instance.
            assert_eq!(unsafe { fmi3Terminate(f.c) }, fmi3OK);
            f
        } else {
            Slave3::new(&fx, "fresh")
        };
        let (st, h) = fresh.deserialize(&bytes);
        assert_eq!(st, fmi3OK, "{}", fresh.last_error());
        assert_eq!(fresh.set_state(h), fmi3OK, "{}", fresh.last_error());
        assert_eq!(fresh.fmi_state(), FmiState::StepComplete);
        let cont = crate::common::fmu::run(&fresh, &fx, BEFORE, BEFORE).unwrap();
        assert!(same_bits(&cont, &ahead), "terminated: {terminated}");
        fresh.free_state(h);
    }
    // Damaged bytes are refused with a reason, the instance unharmed.
    let mut bad = bytes.clone();
    let k = bad.len() / 2;
    bad[k] ^= 0x55;
    let (st, h) = s.deserialize(&bad[..bad.len() - 3]);
    assert_eq!(st, fmi3Error);
    assert!(h.is_null());
    assert!(
        s.last_error().contains("fmi3DeserializeFMUState"),
        "{}",
        s.last_error()
    );
    s.free_state(saved);
}

/// FMI 3.0's argument conventions: nValues other than the number of value references
/// is refused (every variable is a scalar); `time` (declared after the table's value
/// references) reads the FMU's time and cannot be set; the Int32 getter refuses a
/// Float64 variable naming the function to use.
#[test]
fn fmi3_values_follow_fmi3_conventions() {
    let fx = packed3("conv3");
    let s = Slave3::started(&fx, None);
    crate::common::fmu::run(&s, &fx, 0, BEFORE).unwrap();
    let (y, t) = (fx.vr("node_121.y"), fx.p.table.time_ref());
    assert_eq!(t as usize, fx.p.table.vars.len());
    let mut v = [0.0; 2];
    // SAFETY: `v` holds 2 writable values.
    let st = unsafe { fmi3GetFloat64(s.c, [y, t].as_ptr(), 2, v.as_mut_ptr(), 2) };
    assert_eq!(st, fmi3OK, "{}", s.last_error());
    assert_eq!(v[1], BEFORE as f64 * H);
    let print = s.fingerprint();
    // SAFETY: `v` holds 2 writable values (nValues 2 for 1 reference: refused).
    let st = unsafe { fmi3GetFloat64(s.c, &y, 1, v.as_mut_ptr(), 2) };
    assert_eq!(st, fmi3Error);
    assert!(
        s.last_error().contains("nValues is 2"),
        "{}",
        s.last_error()
    );
    s.force_state(FmiState::StepComplete);
    // SAFETY: one value reference, one value.
    let st = unsafe { fmi3SetFloat64(s.c, &t, 1, &1.0, 1) };
    assert_eq!(st, fmi3Error);
    assert!(s.last_error().contains("time"), "{}", s.last_error());
    s.force_state(FmiState::StepComplete);
    let mut i = [0];
    // SAFETY: one value reference, one writable value.
    let st = unsafe { fmi3GetInt32(s.c, &y, 1, i.as_mut_ptr(), 1) };
    assert_eq!(st, fmi3Error);
    assert!(
        s.last_error().contains("fmi3GetFloat64"),
        "{}",
        s.last_error()
    );
    assert!(s.fingerprint() == print, "refusals changed the model");
}

/// FMI 3.0's logger: with loggingOn false the logMessage callback is never called, not
/// even for an error; fmi3SetDebugLogging switches it on; a message names the instance
/// (FMI 3.0's callback has no name argument) and doubles '#', which FMI 3.0 reads as a
/// value-reference mark.
#[test]
fn fmi3_logging_respects_logging_on_and_escapes_hashes() {
    let fx = packed3("log3");
    let s = Slave3::try_with(Some(&fx.p.guid), Some(&fx.resource_path()), "a#b", false)
        .unwrap_or_else(|m| panic!("{m:?}"));
    assert_eq!(s.step(0.0, H).0, fmi3Error);
    assert!(
        s.messages().is_empty(),
        "logged with loggingOn false: {:?}",
        s.messages()
    );
    // SAFETY: a live instance, no categories (all).
    let st = unsafe { fmi3SetDebugLogging(s.c, true, 0, std::ptr::null()) };
    assert_eq!(st, fmi3OK);
    assert_eq!(s.step(0.0, H).0, fmi3Error);
    let m = s.messages();
    let e = m
        .iter()
        .find(|m| m.status == fmi3Error)
        .expect("an error logged");
    assert!(
        e.text
            .starts_with("a##b: fmi3DoStep: illegal call in state"),
        "{}",
        e.text
    );
    assert_eq!(e.category, "logStatusError");
}

/// fmi3InstantiateCoSimulation's refusals: NULL with a logged reason (loggingOn true)
/// for a wrong token, no or a relative resource path, event mode asked for,
/// intermediate variables asked for; Model Exchange and Scheduled Execution are not
/// provided. A `file:` URI (FMI 2.0's form) is accepted as well as the path.
#[test]
fn fmi3_instantiation_refusals_are_logged() {
    let fx = packed3("inst3");
    let path = fx.resource_path();
    for (token, p, says) in [
        (Some("{nope}"), Some(path.as_str()), "{nope}"),
        (Some(fx.p.guid.as_str()), None, "resourcePath is NULL"),
        (
            Some(fx.p.guid.as_str()),
            Some("resources/"),
            "not an absolute path",
        ),
        (None, Some(path.as_str()), "instantiationToken"),
    ] {
        let m = Slave3::try_with(token, p, "i", true)
            .err()
            .expect("refused");
        assert!(
            m.iter()
                .any(|m| m.status >= fmi3Error && m.text.contains(says)),
            "{says}: {m:?}"
        );
    }
    assert!(Slave3::try_with(Some(&fx.p.guid), Some(&fx.uri), "uri", true).is_ok());
    let log: Box<crate::common::fmu::LogSink> = Box::default();
    let env = (&*log as *const crate::common::fmu::LogSink)
        .cast_mut()
        .cast();
    let (name, token, res) = (
        std::ffi::CString::new("i").unwrap(),
        std::ffi::CString::new(fx.p.guid.clone()).unwrap(),
        std::ffi::CString::new(path).unwrap(),
    );
    let rec = Some(crate::common::fmu3::record3 as _);
    // SAFETY: valid strings and callback for each call; `log` outlives it.
    let made = unsafe {
        [
            fmi3InstantiateCoSimulation(
                name.as_ptr(),
                token.as_ptr(),
                res.as_ptr(),
                false,
                true,
                true,
                false,
                std::ptr::null(),
                0,
                env,
                rec,
                None,
            ),
            fmi3InstantiateCoSimulation(
                name.as_ptr(),
                token.as_ptr(),
                res.as_ptr(),
                false,
                true,
                false,
                false,
                &0,
                1,
                env,
                rec,
                None,
            ),
            fmi3InstantiateModelExchange(
                name.as_ptr(),
                token.as_ptr(),
                res.as_ptr(),
                false,
                true,
                env,
                rec,
            ),
            fmi3InstantiateScheduledExecution(
                name.as_ptr(),
                token.as_ptr(),
                res.as_ptr(),
                false,
                true,
                env,
                rec,
                None,
                None,
                None,
            ),
        ]
    };
    assert!(made.iter().all(|c| c.is_null()));
    let texts: Vec<String> = log.lock().unwrap().iter().map(|m| m.text.clone()).collect();
    for says in [
        "eventModeUsed",
        "requiredIntermediateVariables",
        "fmi3InstantiateModelExchange: this FMU does not declare Model Exchange (it was packed with --interface cs",
        "fmi3InstantiateScheduledExecution: this FMU provides co-simulation only",
    ] {
        assert!(texts.iter().any(|t| t.contains(says)), "{says}: {texts:?}");
    }
}
