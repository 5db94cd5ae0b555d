//! FMI misuse, states and lifetimes (issue 9): damaged, truncated, random and
//! hand-made serialised states, serialisation buffers of the wrong size, double frees of
//! states and NULL instances, '%' in instance names and log texts, fmi2Instantiate with
//! bad arguments, a master without a logger.
//!
//! References: every refusal is fmi2Error (NULL for fmi2Instantiate) with the reason
//! logged through the format "%s"; the model's state byte for byte unchanged; an
//! undisturbed twin's results, bit for bit, after recovery.

// Raw FFI: this test calls the exported fmi2* functions directly, as a C master does,
// which is `unsafe`; the workspace denies `unsafe_code` outside the FMI boundary.
#![allow(unsafe_code)]
#![cfg(target_os = "linux")]

use std::collections::BTreeMap;
use std::ffi::CString;
use std::ptr::{null, null_mut};

use crate::common::fmu::{
    AFTER, BEFORE, H, Slave, midway, packed, print_counts, reference, run, same_bits,
};
use fxbody::fmi::exports::*;
use fxbody::fmi::fmu_state::*;
use fxbody::fmi::state::FmiState;
use fxbody::fmi::types::*;
use fxbody::fmu::snapshot::Snapshot;

/// FNV-free crafting: states built as Snapshots, then serialised by the library's own
/// writer (so the checksum is right and the reader must judge the content).
fn crafted(good: &Snapshot) -> Vec<(&'static str, Snapshot)> {
    let mut out = Vec::new();
    let mut add = |what, f: &dyn Fn(&mut Snapshot)| {
        let mut s = good.clone();
        f(&mut s);
        out.push((what, s));
    };
    add("time NaN", &|s| s.time = f64::NAN);
    add("time Inf", &|s| s.time = f64::INFINITY);
    add("start NaN", &|s| s.start_time = f64::NAN);
    add("stop NaN", &|s| s.stop_time = Some(f64::NAN));
    add("stop before time", &|s| s.stop_time = Some(s.time - 1.0));
    add("rho_inf NaN", &|s| s.rho_inf = f64::NAN);
    add("rho_inf 2", &|s| s.rho_inf = 2.0);
    add("gravity Inf", &|s| s.gravity[1] = f64::INFINITY);
    add("v0 NaN", &|s| s.v0[0] = f64::NAN);
    add("w0 NaN", &|s| s.w0[2] = f64::NAN);
    add("load NaN", &|s| s.loads[1] = f64::NAN);
    add("rate Inf", &|s| s.rates[1] = f64::NEG_INFINITY);
    add("one load too many", &|s| s.loads.push(0.0));
    add("one rate too few", &|s| {
        s.rates.pop();
    });
    add("phase 99", &|s| s.phase = 99);
    add("phase Error", &|s| s.phase = 7);
    add("method 0", &|s| s.method = 0);
    add("method 99", &|s| s.method = 99);
    add("solver data short", &|s| {
        if let Some(st) = s.solver.as_mut() {
            st.data.pop();
        }
    });
    add("solver data long", &|s| {
        if let Some(st) = s.solver.as_mut() {
            st.data.push(1.0);
        }
    });
    add("solver data NaN", &|s| {
        if let Some(st) = s.solver.as_mut() {
            st.data[0] = f64::NAN;
        }
    });
    add("solver method differs", &|s| {
        if let Some(st) = s.solver.as_mut() {
            st.method = if st.method == fxbody::solver::Method::Exact {
                fxbody::solver::Method::Implicit
            } else {
                fxbody::solver::Method::Exact
            };
        }
    });
    out
}

#[test]
fn damaged_serialised_states_are_refused() {
    let fx = packed("deser");
    let twin = reference(&fx);
    let m = midway(&fx, None);
    let good = m.s.serialize(m.saved);
    let mut counts = BTreeMap::new();
    // Every check: refused with fmi2Error (the instance reports it), the model
    // unchanged, and SetFMUstate of the good state continues like the twin.
    let mut refuse = |bytes: &[u8], kind: &'static str| {
        let (st, h) = m.s.deserialize(bytes);
        assert_eq!(st, fmi2Error, "{kind}: {} bytes accepted", bytes.len());
        assert!(h.is_null());
        assert!(m.s.fingerprint() == m.print, "{kind}");
        *counts.entry(kind).or_insert(0usize) += 1;
    };
    for n in 0..good.len() {
        refuse(&good[..n], "truncated");
    }
    let mut longer = good.clone();
    longer.push(0);
    refuse(&longer, "truncated");
    for p in 0..good.len() {
        for mask in [0x01u8, 0x80, 0xff] {
            let mut b = good.clone();
            b[p] ^= mask;
            refuse(&b, "byte flip");
        }
    }
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        rng
    };
    for k in 0..1000 {
        let n = (next() % 2048) as usize;
        let mut b: Vec<u8> = (0..n).map(|_| next() as u8).collect();
        if k % 2 == 0 && b.len() >= 8 {
            b[..8].copy_from_slice(b"FXBSTATE");
        }
        refuse(&b, "random bytes");
    }
    // Well-formed bytes (right checksum) with content that must not be restored.
    let snap = Snapshot::from_bytes(&good, &fx.p.guid).unwrap();
    for (what, bad) in crafted(&snap) {
        let bytes = bad.to_bytes(&fx.p.guid);
        let (st, h) = m.s.deserialize(&bytes);
        if st == fmi2OK {
            let st = m.s.set_state(h);
            let mut hh = h;
            // SAFETY: the live state just made, freed once.
            unsafe { fmi2FreeFMUstate(m.s.c, &mut hh) };
            assert_eq!(st, fmi2Error, "{what}: restored");
        } else {
            assert_eq!(st, fmi2Error, "{what}");
        }
        assert_eq!(m.s.fmi_state(), FmiState::Error, "{what}");
        m.unchanged(&fx, &twin, what);
        *counts.entry("crafted content").or_insert(0) += 1;
    }
    // And the good bytes still restore to the twin's future.
    let (st, h) = m.s.deserialize(&good);
    assert_eq!(st, fmi2OK);
    assert_eq!(m.s.set_state(h), fmi2OK);
    assert!(same_bits(
        &run(&m.s, &fx, BEFORE, AFTER).unwrap(),
        &twin[BEFORE..]
    ));
    m.s.free_state(h);
    assert_eq!(m.s.set_state(m.saved), fmi2OK);
    // A buffer of the wrong size for fmi2SerializeFMUstate.
    for n in [0, good.len() - 1, good.len() + 1] {
        let mut buf = vec![0u8; n.max(1)];
        // SAFETY: `buf` holds at least `n` writable bytes.
        let st = unsafe { fmi2SerializeFMUstate(m.s.c, m.saved, buf.as_mut_ptr().cast(), n) };
        assert_eq!(st, fmi2Error, "buffer of {n} bytes");
        m.unchanged(&fx, &twin, "serialise buffer");
        *counts.entry("serialise buffer size").or_insert(0) += 1;
    }
    print_counts("deserialise", &counts);
}

#[test]
fn double_frees_and_percent_names() {
    let fx = packed("free");
    let twin = reference(&fx);
    let mut n = 0;
    // FreeFMUstate sets the handle to NULL, so freeing the same variable twice is a
    // no-op; a NULL handle pointer is ignored too.
    let s = Slave::started(&fx, None);
    let mut st = s.get_state();
    // SAFETY: a live state, then the NULL it was set to; then a NULL pointer.
    unsafe {
        assert_eq!(fmi2FreeFMUstate(s.c, &mut st), fmi2OK);
        assert!(st.is_null());
        assert_eq!(fmi2FreeFMUstate(s.c, &mut st), fmi2OK);
        assert_eq!(fmi2FreeFMUstate(s.c, null_mut()), fmi2OK);
    }
    n += 3;
    assert!(same_bits(&run(&s, &fx, 0, twin.len()).unwrap(), &twin));
    // FreeInstance(NULL), twice, between live instances: ignored.
    // SAFETY: NULL is allowed.
    unsafe {
        fmi2FreeInstance(null_mut());
        fmi2FreeInstance(null_mut());
    }
    n += 2;
    // A freed instance whose handle the master clears (as fmpy does) can be "freed"
    // again: that is FreeInstance(NULL). Freeing a dangling handle is undefined in FMI
    // and not detected (docs/ROBUSTNESS.md): no global registry of instances exists.
    let mut t = Slave::new(&fx, "freed");
    // SAFETY: a live instance, freed once; the handle is then cleared.
    unsafe { fmi2FreeInstance(t.c) };
    t.c = null_mut();
    drop(t);
    n += 1;
    println!("double free: {n} cases");

    // '%' in the instance name: every message reaches the logger with the format "%s"
    // and the name verbatim.
    let name = "100%s %n %d%% %";
    let p = Slave::new(&fx, name);
    assert_eq!(p.do_step(0.0, H), fmi2Error);
    // SAFETY: a live instance.
    assert_eq!(unsafe { fmi2Reset(p.c) }, fmi2OK);
    let msgs = p.messages();
    assert!(msgs.len() >= 3, "{msgs:?}");
    for msg in &msgs {
        assert_eq!(msg.format, "%s", "{msg:?}");
        assert_eq!(msg.name, name, "{msg:?}");
    }
    assert!(msgs.iter().any(|m| m.text.contains("illegal call")));
    // Instantiation that fails still logs through "%s" with the name.
    let msgs = Slave::try_with(&fx.p.guid, "file:///no/such/%25s/dir", name)
        .err()
        .unwrap();
    assert!(!msgs.is_empty());
    for msg in &msgs {
        assert_eq!((msg.format.as_str(), msg.name.as_str()), ("%s", name));
    }
    println!(
        "percent in names: {} messages checked",
        p.messages().len() + msgs.len()
    );
}

#[test]
fn instantiate_refuses_bad_arguments() {
    let fx = packed("inst");
    let twin = reference(&fx);
    let sink: crate::common::fmu::LogSink = std::sync::Mutex::new(Vec::new());
    let env = crate::common::fmu::log_env(&sink);
    let cb = fmi2CallbackFunctions {
        logger: crate::common::fmu::logger(),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: (&*env as *const fxbody_host::LogEnv).cast_mut().cast(),
    };
    let guid = CString::new(fx.p.guid.as_str()).unwrap();
    let uri = CString::new(fx.uri.as_str()).unwrap();
    let name = c"inst";
    let raw = |s: &[u8]| CString::new(s).unwrap();
    let uris = [
        raw(b""),
        raw(b"file://otherhost/x"),
        raw(b"file:///no/such/dir"),
        raw(b"http://example.com/resources"),
        raw(b"file://%zz%"),
        raw(b"%"),
        raw(b"file:///\xff\xfe/resources"),
        raw(b"file:///tmp/%00x"),
    ];
    let other_guid = raw(b"{00000000-0000-0000-0000-000000000000}");
    let mut cases: Vec<(String, fmi2Component)> = Vec::new();
    // SAFETY: (all calls) every pointer is NULL or a valid C string / callback struct
    // for the call.
    unsafe {
        let mut try_one = |what: &str,
                           n: fmi2String,
                           ty,
                           g: fmi2String,
                           u: fmi2String,
                           f: *const fmi2CallbackFunctions| {
            cases.push((
                what.to_string(),
                fmi2Instantiate(n, ty, g, u, f, fmi2False, fmi2False),
            ));
        };
        try_one(
            "NULL name",
            null(),
            fmi2CoSimulation,
            guid.as_ptr(),
            uri.as_ptr(),
            &cb,
        );
        try_one(
            "empty name",
            c"".as_ptr(),
            fmi2CoSimulation,
            guid.as_ptr(),
            uri.as_ptr(),
            &cb,
        );
        try_one(
            "model exchange",
            name.as_ptr(),
            fmi2ModelExchange,
            guid.as_ptr(),
            uri.as_ptr(),
            &cb,
        );
        try_one("type 7", name.as_ptr(), 7, guid.as_ptr(), uri.as_ptr(), &cb);
        try_one(
            "NULL GUID",
            name.as_ptr(),
            fmi2CoSimulation,
            null(),
            uri.as_ptr(),
            &cb,
        );
        try_one(
            "other GUID",
            name.as_ptr(),
            fmi2CoSimulation,
            other_guid.as_ptr(),
            uri.as_ptr(),
            &cb,
        );
        try_one(
            "NULL URI",
            name.as_ptr(),
            fmi2CoSimulation,
            guid.as_ptr(),
            null(),
            &cb,
        );
        try_one(
            "NULL callbacks",
            name.as_ptr(),
            fmi2CoSimulation,
            guid.as_ptr(),
            uri.as_ptr(),
            null(),
        );
        for u in &uris {
            try_one(
                &format!("URI {u:?}"),
                name.as_ptr(),
                fmi2CoSimulation,
                guid.as_ptr(),
                u.as_ptr(),
                &cb,
            );
        }
    }
    for (what, c) in &cases {
        assert!(c.is_null(), "{what}: instantiated");
    }
    // Every refusal with callbacks was logged, through "%s".
    let msgs = sink.lock().unwrap().clone();
    assert_eq!(msgs.len(), cases.len() - 1, "{msgs:#?}");
    assert!(
        msgs.iter()
            .all(|m| m.format == "%s" && m.status >= fmi2Error)
    );
    // A logger-less master (all callbacks NULL) is refused or served without a crash.
    let quiet = fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: null_mut(),
    };
    // SAFETY: valid strings and callbacks.
    let c = unsafe {
        fmi2Instantiate(
            name.as_ptr(),
            fmi2CoSimulation,
            guid.as_ptr(),
            uri.as_ptr(),
            &quiet,
            fmi2False,
            fmi2True,
        )
    };
    assert!(!c.is_null());
    // SAFETY: a live instance; an illegal call logs to nobody.
    unsafe {
        assert_eq!(fmi2DoStep(c, 0.0, H, fmi2True), fmi2Error);
        assert_eq!(fmi2Reset(c), fmi2OK);
        fmi2FreeInstance(c);
    }
    // The instances that were refused left nothing behind that disturbs a good one.
    assert!(same_bits(
        &run(&Slave::started(&fx, None), &fx, 0, twin.len()).unwrap(),
        &twin
    ));
    println!(
        "instantiate refused: {} cases, 1 logger-less instance",
        cases.len()
    );
}

/// Issue 13: fmi2SetFMUstate (and the other handle functions) refuse a state handle made
/// by an instance of another FMU, naming both GUIDs, before touching anything. Two FMUs
/// (the same body packed under two names: two GUIDs, two library files) loaded with
/// `dlopen` in one process, as a master holding both would. Reference: the twin's
/// results, bit for bit, after recovery by the instance's own saved state.
#[test]
fn a_state_of_another_fmu_is_refused() {
    use fxbody_host::FmuLibrary;
    let a = packed("guid_a");
    let b = crate::common::fmu::packed_as("guid_b", "other");
    assert_ne!(a.p.guid, b.p.guid);
    assert_ne!(a.so, b.so);
    let twin = reference(&a);
    let lib_a = FmuLibrary::open(&a.so).unwrap();
    let lib_b = FmuLibrary::open(&b.so).unwrap();
    fn start<'l>(
        lib: &'l FmuLibrary,
        fx: &crate::common::fmu::Packed,
    ) -> fxbody_host::Instance<'l> {
        let i = lib.instantiate("guid", &fx.p.guid, &fx.uri, false).unwrap();
        i.initialise(0.0, None).unwrap();
        i
    }
    let steps = |i: &fxbody_host::Instance, fx: &crate::common::fmu::Packed, k0, n| {
        let (f, y) = (fx.vr("node_121.fy"), fx.vr("node_121.y"));
        let mut o = [0.0];
        (k0..k0 + n)
            .map(|k| {
                let t = k as f64 * H;
                i.set_real(&[f], &[crate::common::fmu::load(t)]).unwrap();
                i.do_step(t, H).unwrap();
                i.get_real(&[y], &mut o).unwrap();
                o[0]
            })
            .collect::<Vec<f64>>()
    };
    let ia = start(&lib_a, &a);
    let ib = start(&lib_b, &b);
    assert!(same_bits(&steps(&ia, &a, 0, BEFORE), &twin[..BEFORE]));
    assert!(same_bits(&steps(&ib, &b, 0, BEFORE), &twin[..BEFORE]));
    let sa = ia.get_state().unwrap();
    let sb = ib.get_state().unwrap();
    let mut n = 0;
    // SetFMUstate, Serialize and FreeFMUstate of A's handle on B: refused, both GUIDs
    // named; B's own state still restores and continues like the twin.
    for (what, r) in [
        ("fmi2SetFMUstate", ib.set_state(&sa).map(|_| ())),
        ("fmi2SerializedFMUstateSize", ib.serialize(&sa).map(|_| ())),
    ] {
        let e = r.unwrap_err();
        assert!(e.contains(what), "{e}");
        assert!(
            e.contains(&a.p.guid) && e.contains(&b.p.guid),
            "{what}: {e}"
        );
        ib.set_state(&sb).unwrap();
        assert!(same_bits(&steps(&ib, &b, BEFORE, AFTER), &twin[BEFORE..]));
        ib.set_state(&sb).unwrap();
        n += 1;
    }
    // A's handle still works in A (it was not freed or changed by B).
    ia.set_state(&sa).unwrap();
    assert!(same_bits(&steps(&ia, &a, BEFORE, AFTER), &twin[BEFORE..]));
    let e = ib.free_state(sa).unwrap_err();
    assert!(e.contains(&a.p.guid), "{e}");
    n += 1;
    ib.free_state(sb).unwrap();
    // (A's handle leaks here: B refused to free it and the host's SavedState was moved.)

    // A pointer that is no fxbody handle at all (64 zero bytes) is refused unread
    // beyond its first 8 bytes.
    let s = Slave::started(&a, None);
    let fake = Box::new([0u64; 8]);
    let st = s.set_state((&*fake as *const [u64; 8]).cast_mut().cast());
    assert_eq!(st, fmi2Error);
    assert!(
        s.last_error().contains("not made by an fxbody FMU"),
        "{}",
        s.last_error()
    );
    n += 1;
    println!("foreign state handles refused: {n} cases");
}
