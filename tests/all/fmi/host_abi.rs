//! The exports driven through `dlopen` by the workspace's FMI importer (crates/host): every
//! form of resource URI, recovery from the Error state by fmi2SetFMUstate, saved states
//! from before initialisation, and the logged reasons. References: a second run of the
//! same FMU, which must match bit for bit.

use fxbody::fmu::pack::Prepared;
use fxbody_host::{FmuLibrary, Instance, file_uri};

use crate::common::fmu::unpack_tip as packed;

fn vr(p: &Prepared, name: &str) -> u32 {
    p.table.vars.iter().find(|v| v.name == name).unwrap().vr
}

/// `n` steps of 0.1 ms from step number `k0`, load cos(300 t) on the tip.
fn run(inst: &Instance, p: &Prepared, k0: usize, n: usize) -> Vec<f64> {
    let (f, y) = (vr(p, "node_121.fy"), vr(p, "node_121.y"));
    let mut out = Vec::new();
    let mut o = [0.0];
    for k in 0..n {
        let t = (k0 + k) as f64 * 1e-4;
        inst.set_real(&[f], &[(300.0 * t).cos()]).unwrap();
        inst.do_step(t, 1e-4).unwrap();
        inst.get_real(&[y], &mut o).unwrap();
        out.push(o[0]);
    }
    out
}

fn started<'a>(lib: &'a FmuLibrary, p: &Prepared, uri: &str) -> Instance<'a> {
    let i = lib
        .instantiate("abi", &p.guid, uri, false)
        .unwrap_or_else(|e| panic!("{uri}: {e}"));
    i.initialise(0.0, None).unwrap();
    i
}

#[test]
fn every_uri_form_finds_the_resources() {
    let dir = std::env::temp_dir().join(format!("fxbody abi uri {}", std::process::id()));
    let (p, so) = packed(&dir);
    let lib = FmuLibrary::open(&so).unwrap();
    let res = dir.join("resources");
    let plain = res.display().to_string();
    let encoded = file_uri(&res);
    assert!(encoded.contains("%20"), "{encoded}");
    let forms = [
        encoded.clone(),
        format!("{encoded}/"),
        encoded.replacen("file://", "file://localhost", 1),
        encoded.replacen("file://", "file:", 1),
        plain.clone(),
    ];
    let base = run(&started(&lib, &p, &forms[0]), &p, 0, 50);
    assert!(base.iter().any(|v| v.abs() > 1e-7));
    for f in &forms[1..] {
        assert_eq!(run(&started(&lib, &p, f), &p, 0, 50), base, "{f}");
    }
    let err = lib
        .instantiate("abi", &p.guid, "file://otherhost/x", false)
        .err()
        .unwrap();
    assert!(err.contains("is not local"), "{err}");
    let err = lib
        .instantiate("abi", &p.guid, &file_uri(&dir.join("nothing here")), false)
        .err()
        .unwrap();
    assert!(err.contains("cannot read"), "{err}");
    drop(lib);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn set_fmu_state_is_the_way_out_of_an_error() {
    let dir = std::env::temp_dir().join(format!("fxbody_abi_err_{}", std::process::id()));
    let (p, so) = packed(&dir);
    let lib = FmuLibrary::open(&so).unwrap();
    let uri = file_uri(&dir.join("resources"));
    // Reference: 100 uninterrupted steps.
    let whole = run(&started(&lib, &p, &uri), &p, 0, 100);
    let inst = started(&lib, &p, &uri);
    let first = run(&inst, &p, 0, 40);
    let saved = inst.get_state().unwrap();
    // A step from the wrong time: an error, logged, and the instance is in Error.
    let e = inst.do_step(1.0, 1e-4).unwrap_err();
    assert!(e.contains("is not the FMU's current time"), "{e}");
    // FMI 2.0 allows fmi2GetReal in Error: it returns the last consistent values, those
    // before the refused step.
    let mut o = [0.0];
    inst.get_real(&[vr(&p, "node_121.y")], &mut o).unwrap();
    assert_eq!(o[0].to_bits(), first[39].to_bits());
    inst.set_state(&saved).unwrap();
    let rest = run(&inst, &p, 40, 60);
    assert_eq!([first, rest].concat(), whole);
    // The serialised form of a state restores in a fresh instance of the same FMU.
    let bytes = inst.serialize(&saved).unwrap();
    inst.free_state(saved).unwrap();
    let other = lib.instantiate("other", &p.guid, &uri, false).unwrap();
    let s2 = other.deserialize(&bytes).unwrap();
    other.set_state(&s2).unwrap();
    assert_eq!(run(&other, &p, 40, 60), whole[40..].to_vec());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_state_saved_before_initialisation_restores_that_phase() {
    let dir = std::env::temp_dir().join(format!("fxbody_abi_phase_{}", std::process::id()));
    let (p, so) = packed(&dir);
    let lib = FmuLibrary::open(&so).unwrap();
    let uri = file_uri(&dir.join("resources"));
    let inst = lib.instantiate("phase", &p.guid, &uri, false).unwrap();
    let fresh = inst.get_state().unwrap();
    inst.initialise(0.0, None).unwrap();
    let a = run(&inst, &p, 0, 30);
    inst.set_state(&fresh).unwrap();
    // Back in Instantiated: stepping is illegal until initialisation again.
    assert!(
        inst.do_step(0.0, 1e-4)
            .unwrap_err()
            .contains("illegal call in state Instantiated")
    );
    inst.set_state(&fresh).unwrap();
    inst.initialise(0.0, None).unwrap();
    assert_eq!(run(&inst, &p, 0, 30), a);
    // Parameters: `method` is an Integer; exact=3, implicit=2 are offered, 7 is not.
    let inst2 = lib.instantiate("params", &p.guid, &uri, false).unwrap();
    let e = inst2.set_integer(&[vr(&p, "method")], &[7]).unwrap_err();
    assert!(e.contains("method: 7 is not offered"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn steps_stop_at_a_defined_stop_time_and_need_positive_sizes() {
    let dir = std::env::temp_dir().join(format!("fxbody_abi_stop_{}", std::process::id()));
    let (p, so) = packed(&dir);
    let lib = FmuLibrary::open(&so).unwrap();
    let inst = lib
        .instantiate("stop", &p.guid, &file_uri(&dir.join("resources")), false)
        .unwrap();
    inst.initialise(0.5, Some(0.5 + 10.0 * 1e-4)).unwrap();
    // The first step must start at startTime.
    assert!(
        inst.do_step(0.0, 1e-4)
            .unwrap_err()
            .contains("is not the FMU's current time 0.5")
    );
    let inst = lib
        .instantiate("stop2", &p.guid, &file_uri(&dir.join("resources")), false)
        .unwrap();
    inst.initialise(0.5, Some(0.5 + 10.0 * 1e-4)).unwrap();
    for k in 0..10 {
        inst.do_step(0.5 + k as f64 * 1e-4, 1e-4).unwrap();
    }
    let e = inst.do_step(0.5 + 10.0 * 1e-4, 1e-4).unwrap_err();
    assert!(e.contains("goes past stopTime"), "{e}");
    let inst = lib
        .instantiate("neg", &p.guid, &file_uri(&dir.join("resources")), false)
        .unwrap();
    inst.initialise(0.0, None).unwrap();
    let e = inst.do_step(0.0, -1e-4).unwrap_err();
    assert!(e.contains("must be finite and > 0"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
