//! A free body's directional derivative through the exports (issue 26.2): FMI 3.0's
//! fmi3GetDirectionalDerivative equals FMI 2.0's fmi2GetDirectionalDerivative bit for
//! bit (one model behind both versions) on the tumbling free-free beam, modes moved and
//! loads on, for a seed over several states and a load at once, and it is the sum of
//! the single-known columns (the derivative is linear in the seed: within 1e-6 of the
//! column scale, the central difference's step following the seed); a non-finite seed
//! is refused with a logged reason. Its accuracy against an independent Richardson
//! difference: free::me.

#![allow(unsafe_code)]
#![allow(clippy::undocumented_unsafe_blocks)]
#![cfg(target_os = "linux")]

use crate::common::fmu::{Packed, Slave, packed_with};
use crate::common::fmu3::Slave3;
use fxbody::fmi::exports::*;
use fxbody::fmi::fmi3::exports as e3;
use fxbody::fmi::fmi3::model_exchange as me3;
use fxbody::fmi::fmi3::types::*;
use fxbody::fmi::fmi3::values as v3;
use fxbody::fmi::model_exchange::*;
use fxbody::fmi::types::*;
use fxbody::fmi::values::*;
use fxbody::fmu::fmi_version::FmiVersion;
use fxbody::fmu::interface::Interfaces;

fn free(tag: &str, fmi: FmiVersion) -> Packed {
    packed_with(tag, "freefree", 521, None, fmi, Interfaces::ModelExchange)
}

#[test]
fn fmi3_free_directional_derivative_is_fmi2_s() {
    let (fx2, fx3) = (
        free("me_free_dd2", FmiVersion::Fmi2),
        free("me_free_dd3", FmiVersion::Fmi3),
    );
    let spin = ["w0.x", "w0.y", "w0.z"].map(|k| fx2.vr(k));
    let w0 = [3.0, -1.0, 2.0];
    let s2 = Slave::new_me(&fx2, "dd2");
    let s3 = Slave3::new_me(&fx3, "dd3");
    assert_eq!(s2.setup(0.0, None), fmi2OK);
    unsafe {
        assert_eq!(fmi2SetReal(s2.c, spin.as_ptr(), 3, w0.as_ptr()), fmi2OK);
        assert_eq!(
            v3::fmi3SetFloat64(s3.c, spin.as_ptr(), 3, w0.as_ptr(), 3),
            fmi3OK
        );
        assert_eq!(fmi2EnterInitializationMode(s2.c), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(s2.c), fmi2OK);
        assert_eq!(fmi2EnterContinuousTimeMode(s2.c), fmi2OK);
        assert_eq!(
            e3::fmi3EnterInitializationMode(s3.c, false, 0.0, 0.0, false, 0.0),
            fmi3OK
        );
        assert_eq!(e3::fmi3ExitInitializationMode(s3.c), fmi3OK);
        assert_eq!(me3::fmi3EnterContinuousTimeMode(s3.c), fmi3OK);
    }
    let n = fx2.p.table.state_count();
    let (mut x, mut nom) = (vec![0.0; n], vec![0.0; n]);
    unsafe {
        assert_eq!(fmi2GetContinuousStates(s2.c, x.as_mut_ptr(), n), fmi2OK);
        assert_eq!(
            fmi2GetNominalsOfContinuousStates(s2.c, nom.as_mut_ptr(), n),
            fmi2OK
        );
    }
    // Tumbling (w0 set), the modes moved by up to their nominals, a tip load on.
    for j in 13..n {
        x[j] = nom[j] * (0.9 * j as f64).sin();
    }
    let fy = fx2.vr("node_521.fy");
    unsafe {
        assert_eq!(fmi2SetReal(s2.c, &fy, 1, &0.07), fmi2OK);
        assert_eq!(v3::fmi3SetFloat64(s3.c, &fy, 1, &0.07, 1), fmi3OK);
        assert_eq!(fmi2SetContinuousStates(s2.c, x.as_ptr(), n), fmi2OK);
        assert_eq!(me3::fmi3SetContinuousStates(s3.c, x.as_ptr(), n), fmi3OK);
    }
    let name = |i: usize, der: bool| {
        let v = &fx2.p.table.vars[fx2.p.table.state_ref(i).unwrap() as usize];
        if der {
            fx2.vr(&format!("der({})", v.name))
        } else {
            v.vr
        }
    };
    // Every state derivative as the unknowns; a quaternion component, an angular
    // velocity, a modal amplitude and velocity and the load as the knowns.
    let unknowns: Vec<u32> = (0..n).map(|i| name(i, true)).collect();
    let knowns = [
        name(4, false),
        name(11, false),
        name(14, false),
        name(n - 2, false),
        fy,
    ];
    let seed = [0.3, -0.2, 0.5 * nom[14], 0.4 * nom[n - 2], 0.05];
    let (mut j2, mut j3) = (vec![0.0; n], vec![0.0; n]);
    let before = s2.fingerprint();
    unsafe {
        assert_eq!(
            fmi2GetDirectionalDerivative(
                s2.c,
                unknowns.as_ptr(),
                n,
                knowns.as_ptr(),
                5,
                seed.as_ptr(),
                j2.as_mut_ptr()
            ),
            fmi2OK,
            "{}",
            s2.last_error()
        );
        assert_eq!(
            v3::fmi3GetDirectionalDerivative(
                s3.c,
                unknowns.as_ptr(),
                n,
                knowns.as_ptr(),
                5,
                seed.as_ptr(),
                5,
                j3.as_mut_ptr(),
                n
            ),
            fmi3OK
        );
    }
    assert_eq!(s2.fingerprint(), before, "the call changed the model");
    assert!(j2.iter().filter(|v| **v != 0.0).count() > n / 2, "{j2:?}");
    assert_eq!(j2, j3);
    // The sum of the single-known columns.
    let mut sum = vec![0.0; n];
    let mut col = vec![0.0; n];
    for (k, s) in knowns.iter().zip(&seed) {
        unsafe {
            assert_eq!(
                fmi2GetDirectionalDerivative(s2.c, unknowns.as_ptr(), n, k, 1, s, col.as_mut_ptr()),
                fmi2OK
            );
        }
        for (a, b) in sum.iter_mut().zip(&col) {
            *a += b;
        }
    }
    let scale = sum.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let gap = j2
        .iter()
        .zip(&sum)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    println!(
        "free J s against the sum of its columns: {:.2e} of the largest",
        gap / scale
    );
    assert!(gap < 1e-6 * scale, "{:.2e}", gap / scale);
    // A non-finite seed: refused, the reason logged.
    let st = unsafe {
        fmi2GetDirectionalDerivative(
            s2.c,
            unknowns.as_ptr(),
            n,
            &fy,
            1,
            &f64::NAN,
            col.as_mut_ptr(),
        )
    };
    assert_eq!(st, fmi2Error);
    assert!(
        s2.last_error()
            .contains("the seed of node_521.fy: value must be finite"),
        "{}",
        s2.last_error()
    );
}
