//! FMI 2.0 Model Exchange through the exports (issue 26.2), as a C master calls them:
//! the directional derivative against central finite differences of
//! fmi2GetDerivatives; the state and derivative variables read by fmi2GetReal against
//! fmi2GetContinuousStates and fmi2GetDerivatives; and the misuse matrix extended to
//! Model Exchange: every export called in every reachable Model Exchange state where
//! the FMI 2.0 Model Exchange table (section 3.2.3, written here from the standard,
//! independently of src/fmi/state.rs) or the interface forbids it.
//!
//! References and tolerances: the system is linear, so central differences of the
//! derivatives are exact up to rounding (row-scaled 1e-7); reads of the same values by
//! two functions are bit for bit; a refused call returns fmi2Error, logs why and leaves
//! the model's serialised state byte for byte unchanged.

#![allow(unsafe_code)]
#![allow(clippy::undocumented_unsafe_blocks)]
#![cfg(target_os = "linux")]

use std::collections::BTreeMap;
use std::ptr::{null, null_mut};

use super::matrix::{self, Matrix};
use crate::common::fmu::{Msg, Packed, Slave, packed_me, packed_with, print_counts};
use fxbody::fmi::exports::*;
use fxbody::fmi::fmu_state::*;
use fxbody::fmi::model_exchange::*;
use fxbody::fmi::types::*;
use fxbody::fmi::values::*;
use fxbody::fmu::fmi_version::FmiVersion;
use fxbody::fmu::interface::Interfaces;
use fxbody::fmu::vars::Kind;

/// A Model Exchange instance initialised and in Continuous-Time Mode.
fn in_continuous_time(fx: &Packed) -> Slave {
    let s = Slave::new_me(fx, "me");
    assert_eq!(s.setup(0.0, None), fmi2OK);
    unsafe {
        assert_eq!(fmi2EnterInitializationMode(s.c), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(s.c), fmi2OK);
        assert_eq!(fmi2EnterContinuousTimeMode(s.c), fmi2OK);
    }
    s
}

fn refs(fx: &Packed, f: impl Fn(Kind) -> bool) -> Vec<u32> {
    fx.p.table
        .vars
        .iter()
        .filter(|v| f(v.kind))
        .map(|v| v.vr)
        .collect()
}

fn derivatives(s: &Slave, x: &[f64], out: &mut [f64]) {
    unsafe {
        assert_eq!(fmi2SetContinuousStates(s.c, x.as_ptr(), x.len()), fmi2OK);
        assert_eq!(fmi2GetDerivatives(s.c, out.as_mut_ptr(), out.len()), fmi2OK);
    }
}

#[test]
fn directional_derivative_is_the_central_difference_of_get_derivatives() {
    let fx = packed_me("me_dd");
    let s = in_continuous_time(&fx);
    let n = fx.p.table.state_count();
    assert_eq!(n, 2 * fx.p.scene.body.nl());
    let ders = refs(&fx, |k| matches!(k, Kind::Derivative(_)));
    let states = refs(&fx, |k| matches!(k, Kind::State(_)));
    let loads = refs(&fx, |k| matches!(k, Kind::Load { .. }));
    let mut nom = vec![0.0; n];
    unsafe {
        assert_eq!(
            fmi2GetNominalsOfContinuousStates(s.c, nom.as_mut_ptr(), n),
            fmi2OK
        );
    }
    // Away from rest, loads on.
    let x0: Vec<f64> = (0..n)
        .map(|j| nom[j] * (0.3 + 0.7 * j as f64).sin())
        .collect();
    let u0: Vec<f64> = (0..loads.len()).map(|k| 0.5 + k as f64).collect();
    assert_eq!(s.set_real(&loads, &u0), fmi2OK);
    let (mut fp, mut fm, mut dd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut worst = 0.0f64;
    let mut x = x0.clone();
    // Each state, then each load, as the known; every derivative as the unknown.
    for (j, &known) in states.iter().chain(&loads).enumerate() {
        let e;
        if j < n {
            e = 1e-3 * nom[j];
            x[j] = x0[j] + e;
            derivatives(&s, &x, &mut fp);
            x[j] = x0[j] - e;
            derivatives(&s, &x, &mut fm);
            x[j] = x0[j];
            derivatives(&s, &x, &mut dd);
        } else {
            let k = j - n;
            e = 1e-3;
            assert_eq!(s.set_real(&[known], &[u0[k] + e]), fmi2OK);
            derivatives(&s, &x0, &mut fp);
            assert_eq!(s.set_real(&[known], &[u0[k] - e]), fmi2OK);
            derivatives(&s, &x0, &mut fm);
            assert_eq!(s.set_real(&[known], &[u0[k]]), fmi2OK);
        }
        let st = unsafe {
            fmi2GetDirectionalDerivative(s.c, ders.as_ptr(), n, &known, 1, &1.0, dd.as_mut_ptr())
        };
        assert_eq!(st, fmi2OK, "{}", s.last_error());
        for i in 0..n {
            let fd = (fp[i] - fm[i]) / (2.0 * e);
            let scale = fp[i].abs().max(fm[i].abs()).max(dd[i].abs()) / e.max(1e-300);
            let gap = (fd - dd[i]).abs() / scale.max(1e-300);
            worst = worst.max(if fd == dd[i] { 0.0 } else { gap });
        }
    }
    println!("directional derivative vs central differences: worst {worst:.2e} (scaled)");
    assert!(
        worst < 1e-7,
        "directional derivative off finite differences: {worst:e}"
    );
    // The state and derivative variables read what the vector functions give.
    let (mut xs, mut dx) = (vec![0.0; n], vec![0.0; n]);
    derivatives(&s, &x0, &mut dx);
    unsafe { assert_eq!(fmi2GetContinuousStates(s.c, xs.as_mut_ptr(), n), fmi2OK) };
    let (mut gx, mut gd) = (vec![0.0; n], vec![0.0; n]);
    assert_eq!(s.get_real(&states, &mut gx), fmi2OK);
    assert_eq!(s.get_real(&ders, &mut gd), fmi2OK);
    assert_eq!(xs, x0);
    assert_eq!((gx, gd), (xs, dx));
    // A state variable is set through fmi2SetContinuousStates only.
    assert_eq!(s.set_real(&states[..1], &[1.0]), fmi2Error);
    assert!(
        s.last_error().contains("fmi2SetContinuousStates"),
        "{}",
        s.last_error()
    );
}

/// The Model Exchange states a master can reach.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum At {
    Instantiated,
    InitializationMode,
    EventMode,
    ContinuousTimeMode,
    Terminated,
    /// Error after a refused call in Continuous-Time Mode.
    Error,
}
use At::*;
const ALL: [At; 6] = [
    Instantiated,
    InitializationMode,
    EventMode,
    ContinuousTimeMode,
    Terminated,
    Error,
];

fn reach(fx: &Packed, at: At) -> Slave {
    let s = Slave::new_me(fx, "me_matrix");
    if at == Instantiated {
        return s;
    }
    assert_eq!(s.setup(0.0, None), fmi2OK);
    unsafe { assert_eq!(fmi2EnterInitializationMode(s.c), fmi2OK) };
    if at == InitializationMode {
        return s;
    }
    unsafe { assert_eq!(fmi2ExitInitializationMode(s.c), fmi2OK) };
    if at == EventMode {
        return s;
    }
    unsafe { assert_eq!(fmi2EnterContinuousTimeMode(s.c), fmi2OK) };
    // Away from rest, so that an unwanted change would show.
    let n = fx.p.table.state_count();
    let x: Vec<f64> = (0..n).map(|j| 1e-6 * (1.0 + j as f64).sin()).collect();
    unsafe {
        assert_eq!(fmi2SetTime(s.c, 0.01), fmi2OK);
        assert_eq!(fmi2SetContinuousStates(s.c, x.as_ptr(), n), fmi2OK);
    }
    match at {
        Terminated => unsafe { assert_eq!(fmi2Terminate(s.c), fmi2OK) },
        Error => {
            let bad = vec![f64::NAN; n];
            unsafe {
                assert_eq!(fmi2SetContinuousStates(s.c, bad.as_ptr(), n), fmi2Error);
            }
        }
        _ => {}
    }
    s
}

struct Args {
    fy: u32,
    y: u32,
    der: u32,
    state: u32,
    n: usize,
}

/// Every export, with the Model Exchange states where FMI 2.0 allows it; the
/// co-simulation-only ones nowhere (refused for the state or for the interface).
fn calls() -> Vec<matrix::Call<At, Args>> {
    const INS: &[At] = &[
        Instantiated,
        InitializationMode,
        EventMode,
        ContinuousTimeMode,
    ];
    const GETS: &[At] = &[
        InitializationMode,
        EventMode,
        ContinuousTimeMode,
        Terminated,
        Error,
    ];
    const SAVE: &[At] = &ALL;
    const RUNNING: &[At] = &[EventMode, ContinuousTimeMode];
    vec![
        ("fmi2SetDebugLogging", SAVE, |c, _| unsafe {
            fmi2SetDebugLogging(c, fmi2True, 0, null())
        }),
        ("fmi2SetupExperiment", &[Instantiated], |c, _| unsafe {
            fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0)
        }),
        (
            "fmi2EnterInitializationMode",
            &[Instantiated],
            |c, _| unsafe { fmi2EnterInitializationMode(c) },
        ),
        (
            "fmi2ExitInitializationMode",
            &[InitializationMode],
            |c, _| unsafe { fmi2ExitInitializationMode(c) },
        ),
        ("fmi2Terminate", RUNNING, |c, _| unsafe { fmi2Terminate(c) }),
        ("fmi2GetReal", GETS, |c, a| unsafe {
            let mut v = [0.0];
            fmi2GetReal(c, &a.y, 1, v.as_mut_ptr())
        }),
        ("fmi2SetReal", INS, |c, a| unsafe {
            fmi2SetReal(c, &a.fy, 1, &0.25)
        }),
        ("fmi2GetFMUstate", SAVE, |c, _| unsafe {
            let mut s = null_mut();
            let st = fmi2GetFMUstate(c, &mut s);
            if !s.is_null() {
                fmi2FreeFMUstate(c, &mut s);
            }
            st
        }),
        (
            "fmi2GetDirectionalDerivative",
            &[
                InitializationMode,
                EventMode,
                ContinuousTimeMode,
                Terminated,
                Error,
            ],
            |c, a| unsafe {
                let mut v = 0.0;
                fmi2GetDirectionalDerivative(c, &a.der, 1, &a.state, 1, &1.0, &mut v)
            },
        ),
        ("fmi2EnterEventMode", RUNNING, |c, _| unsafe {
            fmi2EnterEventMode(c)
        }),
        ("fmi2NewDiscreteStates", &[EventMode], |c, _| unsafe {
            let mut info = fmi2EventInfo {
                newDiscreteStatesNeeded: 1,
                terminateSimulation: 1,
                nominalsOfContinuousStatesChanged: 1,
                valuesOfContinuousStatesChanged: 1,
                nextEventTimeDefined: 1,
                nextEventTime: 0.0,
            };
            fmi2NewDiscreteStates(c, &mut info)
        }),
        ("fmi2EnterContinuousTimeMode", &[EventMode], |c, _| unsafe {
            fmi2EnterContinuousTimeMode(c)
        }),
        (
            "fmi2CompletedIntegratorStep",
            &[ContinuousTimeMode],
            |c, _| unsafe {
                let (mut e, mut t) = (1, 1);
                fmi2CompletedIntegratorStep(c, fmi2True, &mut e, &mut t)
            },
        ),
        ("fmi2SetTime", RUNNING, |c, _| unsafe {
            fmi2SetTime(c, 0.01)
        }),
        (
            "fmi2SetContinuousStates",
            &[ContinuousTimeMode],
            |c, a| unsafe {
                let x = vec![0.0; a.n];
                fmi2SetContinuousStates(c, x.as_ptr(), a.n)
            },
        ),
        ("fmi2GetDerivatives", GETS, |c, a| unsafe {
            let mut x = vec![0.0; a.n];
            fmi2GetDerivatives(c, x.as_mut_ptr(), a.n)
        }),
        ("fmi2GetEventIndicators", GETS, |c, _| unsafe {
            fmi2GetEventIndicators(c, null_mut(), 0)
        }),
        ("fmi2GetContinuousStates", GETS, |c, a| unsafe {
            let mut x = vec![0.0; a.n];
            fmi2GetContinuousStates(c, x.as_mut_ptr(), a.n)
        }),
        ("fmi2GetNominalsOfContinuousStates", SAVE, |c, a| unsafe {
            let mut x = vec![0.0; a.n];
            fmi2GetNominalsOfContinuousStates(c, x.as_mut_ptr(), a.n)
        }),
        // Co-simulation only: refused in every Model Exchange state.
        ("fmi2DoStep", &[], |c, _| unsafe {
            fmi2DoStep(c, 0.0, 1e-4, fmi2True)
        }),
        ("fmi2CancelStep", &[], |c, _| unsafe { fmi2CancelStep(c) }),
        ("fmi2SetRealInputDerivatives", &[], |c, a| unsafe {
            fmi2SetRealInputDerivatives(c, &a.fy, 1, &1, &0.5)
        }),
        ("fmi2GetRealOutputDerivatives", &[], |c, a| unsafe {
            let mut v = 0.0;
            fmi2GetRealOutputDerivatives(c, &a.y, 1, &1, &mut v)
        }),
        ("fmi2GetRealStatus", &[], |c, _| unsafe {
            let mut v = 0.0;
            fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &mut v)
        }),
        ("fmi2GetBooleanStatus", &[], |c, _| unsafe {
            let mut v = 0;
            fmi2GetBooleanStatus(c, fmi2Terminated, &mut v)
        }),
    ]
}

#[test]
fn every_model_exchange_call_in_every_state_where_it_is_illegal() {
    let fx = packed_me("me_matrix");
    let n = fx.p.table.state_count();
    let a = Args {
        fy: fx.vr("node_121.fy"),
        y: fx.vr("node_121.y"),
        der: fx.vr("der(modal.qd[1])"),
        state: fx.vr("modal.q[1]"),
        n,
    };
    let mut counts = BTreeMap::new();
    let reach = |at: At| reach(&fx, at);
    let said = |name: &str, _: At, new: &[Msg]| {
        new.iter().any(|m| {
            m.status == fmi2Error
                && (m
                    .text
                    .starts_with(&format!("{name}: illegal call in state"))
                    || m.text.starts_with(&format!(
                        "{name}: a co-simulation function, and this instance is a \
                         Model Exchange one"
                    )))
        })
    };
    let after = |_: &Slave, _: &str| {};
    Matrix::new(&ALL, &a, &reach, &said, &after).run(&calls(), "illegal state", &mut counts);
    // A co-simulation instance refuses every Model Exchange function, whatever its
    // state allows.
    let cs = crate::common::fmu::packed("me_cs_matrix");
    let s = Slave::started(&cs, None);
    for (name, call) in [
        (
            "fmi2SetTime",
            (|c| unsafe { fmi2SetTime(c, 0.0) }) as fn(fmi2Component) -> i32,
        ),
        ("fmi2GetDerivatives", |c| unsafe {
            fmi2GetDerivatives(c, null_mut(), 0)
        }),
        ("fmi2EnterEventMode", |c| unsafe { fmi2EnterEventMode(c) }),
    ] {
        let st = call(s.c);
        assert_eq!(st, fmi2Error, "{name} on co-simulation");
        *counts.entry("co-simulation instance").or_insert(0) += 1;
        unsafe { assert_eq!(fmi2Reset(s.c), fmi2OK) };
    }
    print_counts("Model Exchange misuse matrix", &counts);
    assert!(counts["illegal state"] > 60, "{counts:?}");
}

/// FMI 3.0 Model Exchange through its own exports, beside FMI 2.0's on the same body:
/// the same states, derivatives, nominals and directional derivative, bit for bit (one
/// model behind both versions); FMI 3.0's state machine (Event Mode after
/// initialisation, fmi3UpdateDiscreteStates asks for nothing, fmi3DoStep illegal in
/// Continuous-Time Mode, fmi3CompletedIntegratorStep's flags false).
#[test]
fn fmi3_model_exchange_matches_fmi2_bit_for_bit() {
    use crate::common::fmu::packed_with;
    use crate::common::fmu3::Slave3;
    use fxbody::fmi::fmi3::exports as e3;
    use fxbody::fmi::fmi3::model_exchange as me3;
    use fxbody::fmi::fmi3::types::*;
    use fxbody::fmi::fmi3::values as v3;
    use fxbody::fmi::state::FmiState;
    use fxbody::fmu::fmi_version::FmiVersion;
    use fxbody::fmu::interface::Interfaces;

    let fx2 = packed_me("me_v2");
    let fx3 = packed_with(
        "me_v3",
        "cantilever",
        121,
        None,
        FmiVersion::Fmi3,
        Interfaces::ModelExchange,
    );
    let s2 = in_continuous_time(&fx2);
    let s3 = Slave3::new_me(&fx3, "me3");
    let n = fx2.p.table.state_count();
    unsafe {
        assert_eq!(
            e3::fmi3EnterInitializationMode(s3.c, false, 0.0, 0.0, false, 0.0),
            fmi3OK
        );
        assert_eq!(e3::fmi3ExitInitializationMode(s3.c), fmi3OK);
    }
    assert_eq!(s3.fmi_state(), FmiState::EventMode);
    let mut flags = [true; 5];
    let mut next = 1.0;
    unsafe {
        let [a, b, c, d, f] = &mut flags;
        assert_eq!(
            fxbody::fmi::fmi3::clocks::fmi3UpdateDiscreteStates(s3.c, a, b, c, d, f, &mut next),
            fmi3OK
        );
    }
    assert_eq!(flags, [false; 5]);
    unsafe { assert_eq!(me3::fmi3EnterContinuousTimeMode(s3.c), fmi3OK) };
    let mut count = 0;
    unsafe {
        assert_eq!(
            me3::fmi3GetNumberOfContinuousStates(s3.c, &mut count),
            fmi3OK
        )
    };
    assert_eq!(count, n);
    unsafe {
        assert_eq!(
            me3::fmi3GetNumberOfEventIndicators(s3.c, &mut count),
            fmi3OK
        )
    };
    assert_eq!(count, 0);
    let x: Vec<f64> = (0..n).map(|j| 1e-6 * (0.5 + j as f64).cos()).collect();
    let (fy2, fy3) = (fx2.vr("node_121.fy"), fx3.vr("node_121.fy"));
    assert_eq!(fy2, fy3);
    assert_eq!(s2.set_real(&[fy2], &[2.5]), fmi2OK);
    let (mut d2, mut d3) = (vec![0.0; n], vec![0.0; n]);
    let (mut n2, mut n3) = (vec![0.0; n], vec![0.0; n]);
    unsafe {
        assert_eq!(v3::fmi3SetFloat64(s3.c, &fy3, 1, &2.5, 1), fmi3OK);
        assert_eq!(fmi2SetTime(s2.c, 0.02), fmi2OK);
        assert_eq!(me3::fmi3SetTime(s3.c, 0.02), fmi3OK);
        assert_eq!(fmi2SetContinuousStates(s2.c, x.as_ptr(), n), fmi2OK);
        assert_eq!(me3::fmi3SetContinuousStates(s3.c, x.as_ptr(), n), fmi3OK);
        assert_eq!(fmi2GetDerivatives(s2.c, d2.as_mut_ptr(), n), fmi2OK);
        assert_eq!(
            me3::fmi3GetContinuousStateDerivatives(s3.c, d3.as_mut_ptr(), n),
            fmi3OK
        );
        assert_eq!(
            fmi2GetNominalsOfContinuousStates(s2.c, n2.as_mut_ptr(), n),
            fmi2OK
        );
        assert_eq!(
            me3::fmi3GetNominalsOfContinuousStates(s3.c, n3.as_mut_ptr(), n),
            fmi3OK
        );
    }
    assert!(d2.iter().any(|v| *v != 0.0));
    assert_eq!(d2, d3);
    assert_eq!(n2, n3);
    let (der, q) = (fx3.vr("der(modal.qd[2])"), fx3.vr("modal.q[2]"));
    let (mut j2, mut j3) = (0.0, 0.0);
    unsafe {
        assert_eq!(
            fmi2GetDirectionalDerivative(s2.c, &der, 1, &q, 1, &1.0, &mut j2),
            fmi2OK
        );
        assert_eq!(
            v3::fmi3GetDirectionalDerivative(s3.c, &der, 1, &q, 1, &1.0, 1, &mut j3, 1),
            fmi3OK
        );
    }
    // d der(qd_2) / d q_2 = -w_2^2.
    assert!(j2 < 0.0 && j2 == j3, "{j2} {j3}");
    let (mut ev, mut term) = (true, true);
    unsafe {
        assert_eq!(
            me3::fmi3CompletedIntegratorStep(s3.c, true, &mut ev, &mut term),
            fmi3OK
        );
    }
    assert!(!ev && !term);
    // A co-simulation call in Continuous-Time Mode: illegal, logged, nothing changed.
    let print = s3.fingerprint();
    let (mut a, mut b, mut c, mut last) = (false, false, false, 0.0);
    let st = unsafe { e3::fmi3DoStep(s3.c, 0.02, 1e-4, true, &mut a, &mut b, &mut c, &mut last) };
    assert_eq!(st, fmi3Error);
    assert!(
        s3.last_error()
            .contains("fmi3DoStep: illegal call in state ContinuousTimeMode"),
        "{}",
        s3.last_error()
    );
    assert!(s3.fingerprint() == print);
}

/// The names of the continuous states as modelDescription.xml declares them: each
/// derivative's `derivative` attribute (the state's 1-based index among the
/// ScalarVariables), in the derivatives' order.
fn declared_states(xml: &str) -> Vec<String> {
    let vars: Vec<&str> = xml.split("<ScalarVariable name=\"").skip(1).collect();
    let name = |v: &str| v[..v.find('"').unwrap()].to_string();
    vars.iter()
        .filter_map(|v| {
            let at = v.find("derivative=\"")? + "derivative=\"".len();
            let k: usize = v[at..at + v[at..].find('"').unwrap()].parse().unwrap();
            Some(name(vars[k - 1]))
        })
        .collect()
}

/// A free body's Model Exchange instance (issue 26.2-26.3), the free-free beam with its
/// tip exposed: the instance's state count and the state names are the description's
/// (13 frame states, then the 10 modes' amplitudes and velocities);
/// fmi2GetDirectionalDerivative answers (declared true; its accuracy is tested in
/// free::me and fmi::me_free), the model's serialised state unchanged; a quaternion
/// 1e-6 off unit norm makes fmi2CompletedIntegratorStep ask for an event without
/// touching the states (FMI changes continuous states in Event Mode only), and
/// fmi2NewDiscreteStates normalises it (to 1e-15) and reports
/// valuesOfContinuousStatesChanged, every other state kept; a unit quaternion asks for
/// nothing.
#[test]
fn a_free_body_declares_its_states_and_jacobian_and_normalises_at_events() {
    let fx = packed_with(
        "me_free",
        "freefree",
        521,
        None,
        FmiVersion::Fmi2,
        Interfaces::ModelExchange,
    );
    let xml = std::fs::read_to_string(fx.dir.join("modelDescription.xml")).unwrap();
    let declared = declared_states(&xml);
    let mut expected: Vec<String> = Vec::new();
    for (name, len) in [("X", 3), ("quat", 4), ("V", 3), ("omega", 3)] {
        expected.extend((1..=len).map(|c| format!("state.{name}[{c}]")));
    }
    expected.extend((1..=10).map(|j| format!("modal.q[{j}]")));
    expected.extend((1..=10).map(|j| format!("modal.qd[{j}]")));
    assert_eq!(declared, expected);
    assert!(xml.contains("providesDirectionalDerivative=\"true\""));
    let n = declared.len();
    assert_eq!(fx.p.table.state_count(), n);

    let s = in_continuous_time(&fx);
    let mut x = vec![0.0; n];
    unsafe {
        assert_eq!(fmi2GetContinuousStates(s.c, x.as_mut_ptr(), n), fmi2OK);
    }
    // A unit attitude at the start (the body's placement P0, a 35 degree rotation).
    let norm = |x: &[f64]| x[3..7].iter().map(|q| q * q).sum::<f64>().sqrt();
    assert!((norm(&x) - 1.0).abs() < 1e-15, "{}", norm(&x));
    assert!(
        x[3] < 1.0 - 1e-3,
        "P0 is not the identity: q = {:?}",
        &x[3..7]
    );

    // The Jacobian: d der(q_w) / d omega_x = -q_x / 2, the model unchanged.
    let der = refs(&fx, |k| k == Kind::Derivative(3));
    let state = refs(&fx, |k| k == Kind::State(10));
    unsafe { assert_eq!(fmi2SetContinuousStates(s.c, x.as_ptr(), n), fmi2OK) };
    let before = s.fingerprint();
    let mut v = 0.0;
    let st = unsafe {
        fmi2GetDirectionalDerivative(s.c, der.as_ptr(), 1, state.as_ptr(), 1, &1.0, &mut v)
    };
    assert_eq!(st, fmi2OK, "{}", s.last_error());
    assert_eq!(v, -0.5 * x[4]);
    assert_eq!(s.fingerprint(), before);

    let (mut enter, mut term) = (fmi2True, fmi2True);
    unsafe {
        assert_eq!(
            fmi2CompletedIntegratorStep(s.c, fmi2True, &mut enter, &mut term),
            fmi2OK
        );
    }
    assert_eq!(
        (enter, term),
        (fmi2False, fmi2False),
        "a unit quaternion moves nothing"
    );
    let mut drifted = x.clone();
    for q in &mut drifted[3..7] {
        *q *= 1.0 + 1e-6;
    }
    let mut read = vec![0.0; n];
    unsafe {
        assert_eq!(fmi2SetContinuousStates(s.c, drifted.as_ptr(), n), fmi2OK);
        assert_eq!(
            fmi2CompletedIntegratorStep(s.c, fmi2True, &mut enter, &mut term),
            fmi2OK
        );
        assert_eq!((enter, term), (fmi2True, fmi2False));
        assert_eq!(fmi2GetContinuousStates(s.c, read.as_mut_ptr(), n), fmi2OK);
    }
    assert_eq!(
        read[3..7],
        drifted[3..7],
        "the states changed outside Event Mode"
    );
    let mut info = fmi2EventInfo {
        newDiscreteStatesNeeded: fmi2True,
        terminateSimulation: fmi2True,
        nominalsOfContinuousStatesChanged: fmi2True,
        valuesOfContinuousStatesChanged: fmi2False,
        nextEventTimeDefined: fmi2True,
        nextEventTime: 1.0,
    };
    unsafe {
        assert_eq!(fmi2EnterEventMode(s.c), fmi2OK);
        assert_eq!(fmi2NewDiscreteStates(s.c, &mut info), fmi2OK);
        assert_eq!(fmi2GetContinuousStates(s.c, read.as_mut_ptr(), n), fmi2OK);
    }
    assert_eq!(info.valuesOfContinuousStatesChanged, fmi2True);
    assert_eq!(info.newDiscreteStatesNeeded, fmi2False);
    assert!((norm(&read) - 1.0).abs() < 1e-15, "{}", norm(&read));
    for i in 0..n {
        let want = if (3..7).contains(&i) {
            x[i]
        } else {
            drifted[i]
        };
        assert!(
            (read[i] - want).abs() <= 1e-15 * want.abs().max(1.0),
            "state {i}: {} for {want}",
            read[i]
        );
    }
    // A second event iteration changes nothing more.
    unsafe {
        assert_eq!(fmi2NewDiscreteStates(s.c, &mut info), fmi2OK);
    }
    assert_eq!(info.valuesOfContinuousStatesChanged, fmi2False);
}
