//! Issue 28 point 9, messages: every number in a message goes through the one printing
//! function (`fxbody::num::num`), so a user who passed 1e300 reads 1e300 back, never a
//! 301-digit number. Checked where the numbers come from: the implicit method's refusal
//! of h = 1e300 through the FMI exports, `pack --fmax 1e300` and `--fmax 1e-300`,
//! `pack --step 1e-300` (which now warns), `reduce --fmax 1e300`, and the messages of
//! the body checks, the solvers and `pack` built with extreme values. A number printed
//! any other way (`{}` of 1e300 or 1e-30) shows as a long run of digits.

// Raw FFI: the FMI part calls the exported fmi2* functions as a C master does.
#![allow(unsafe_code)]

use super::{pack_cantilever, run, scratch};
use fxbody::body::BodyError;
use fxbody::fmu::pack::PackError;
use fxbody::fxb::Block;
use fxbody::solver::SolverError;

use crate::common::fmu::{Slave, packed};

/// Panic when `text` holds a number not printed by `num`: a run of more than 22 digits
/// (a 300-digit step, 0.000...01). `num` prints at most 17 significant digits and, in
/// plain notation, at most 3 zeros after the point: 21 digits at most.
fn assert_short_numbers(text: &str, what: &str) {
    let mut run = 0usize;
    for c in text.chars() {
        if c.is_ascii_digit() {
            run += 1;
            assert!(
                run <= 22,
                "{what}: a number of more than 22 digits in: {text}"
            );
        } else if c != '.' {
            run = 0;
        }
    }
}

#[test]
fn the_checker_sees_a_long_number() {
    let caught = std::panic::catch_unwind(|| {
        assert_short_numbers(&format!("step {} s", 1e300), "1e300 with {}")
    });
    assert!(caught.is_err());
    let caught = std::panic::catch_unwind(|| {
        assert_short_numbers(&format!("h = {}", 1e-30), "1e-30 with {}")
    });
    assert!(caught.is_err());
    assert_short_numbers("h = 1e300, 0.1, 6.684139054836714 Hz, GUID {12}", "short");
}

#[test]
fn implicit_refusal_of_a_1e300_step_prints_1e300() {
    let fx = packed("numbers");
    let (method, implicit) = (fx.vr("method"), 2);
    let s = Slave::new(&fx, "numbers");
    assert_eq!(s.setup(0.0, None), 0);
    // SAFETY: a live instance, arrays of one element.
    unsafe {
        assert_eq!(
            fxbody::fmi::values::fmi2SetInteger(s.c, &method, 1, &implicit),
            0
        );
        assert_eq!(fxbody::fmi::exports::fmi2EnterInitializationMode(s.c), 0);
        assert_eq!(fxbody::fmi::exports::fmi2ExitInitializationMode(s.c), 0);
    }
    assert_ne!(s.do_step(0.0, 1e300), 0, "a step of 1e300 s is refused");
    let e = s.last_error();
    assert!(
        e.contains("h = 1e300") && e.contains("a step of 1e300 s"),
        "{e}"
    );
    assert_short_numbers(&e, "implicit h = 1e300");
}

#[test]
fn pack_and_reduce_echo_extreme_numbers_as_given() {
    let d = scratch("numbers_echo");
    let out = d.join("o.fmu");
    let base = ["--nodes", "121", "-o", out.to_str().unwrap()];
    for (extra, says) in [
        (["--fmax", "1e300"], "--fmax 1e300 Hz: all 20 modes kept"),
        (
            ["--fmax", "1e-300"],
            "--fmax 1e-300 Hz is below the first mode (6.684139054836714 Hz)",
        ),
        (
            ["--step", "1e-300"],
            "--step 1e-300 s is 6.684139054836714e-300 of the lowest mode's period",
        ),
        (
            ["--stop", "1e300"],
            "stop time 1e300 s, step 0.001 s) takes 1e303 steps",
        ),
    ] {
        let o = pack_cantilever(&[&base[..], &extra[..]].concat());
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{extra:?}: {err}");
        assert!(err.contains(says), "{extra:?}: expected '{says}' in: {err}");
        assert_short_numbers(&err, &format!("pack {extra:?}"));
    }
    let o = run(&[
        "reduce",
        "fixtures/cantilever.fxb",
        "--fmax",
        "1e300",
        "-o",
        d.join("r.fxb").to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("(up to 1e300 Hz;"), "{text}");
    assert_short_numbers(&text, "reduce --fmax 1e300");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn library_messages_print_numbers_short() {
    let name = || "b.fxb".to_string();
    let messages: Vec<String> = vec![
        BodyError::NotFinite {
            name: name(),
            block: Block::new(8),
            index: 1,
            value: f64::NAN,
        }
        .to_string(),
        BodyError::FreqNotPositive {
            name: name(),
            place: "block 3",
            freq: -1e300,
        }
        .to_string(),
        BodyError::NonPositiveMass {
            name: name(),
            place: "block 8",
            mode: 1,
            value: -1e-300,
        }
        .to_string(),
        BodyError::FrequencyNotFinite {
            name: name(),
            place: "blocks 8-10",
            index: 2,
            value: f64::INFINITY,
        }
        .to_string(),
        BodyError::StiffnessNotPsd {
            name: name(),
            place: "blocks 9-10",
            min: fxbody::num::num(-1e300),
            max: fxbody::num::num(1e-300),
        }
        .to_string(),
        BodyError::RigidMassNotPsd {
            name: name(),
            place: "block 11",
            min: -1e-300,
            max: 1e300,
        }
        .to_string(),
        SolverError::BadStep(1e-300).to_string(),
        PackError::Time {
            what: "step",
            value: 1e300,
        }
        .to_string(),
        PackError::StepAfterStop {
            step: 1e300,
            stop: 1e-300,
            stop_given: true,
        }
        .to_string(),
        fxbody::scene::reduce::ReduceError::BadFmax(-1e300).to_string(),
    ];
    for m in &messages {
        assert_short_numbers(m, m);
        assert!(
            m.contains("e300") || m.contains("e-300") || m.contains("NaN") || m.contains("inf"),
            "{m}"
        );
    }
}
