//! Concurrency (issue 9): instances share nothing. Reference: the same runs one after
//! another, which threads must reproduce bit for bit; first through the crate's exports,
//! then through libraries loaded with `dlopen` (the same file, and a copy that is a
//! separate library), loaded and unloaded while other instances run and are freed.

// Raw FFI: this test calls the exported fmi2* functions directly, as a C master does,
// which is `unsafe`; the workspace denies `unsafe_code` outside the FMI boundary.
#![allow(unsafe_code)]
#![cfg(target_os = "linux")]

use std::path::Path;
use std::sync::Barrier;
use std::thread;

use crate::common::fmu::{H, Packed, Slave, packed, same_bits};
use fxbody::fmi::types::fmi2OK;
use fxbody::fmi::values::fmi2SetInteger;
use fxbody_host::FmuLibrary;

const THREADS: usize = 8;
const STEPS: usize = 400;

/// Load of run `k`: its own amplitude and phase, so that runs differ.
fn force(k: usize, t: f64) -> f64 {
    (1.0 + k as f64) * (300.0 * t + k as f64).cos()
}

/// Run `k` through the crate's exports: method number k of the offered ones, STEPS
/// steps, the tip's y and vy after each.
fn direct(fx: &Packed, k: usize) -> Vec<f64> {
    let s = Slave::new(fx, &format!("thread{k}"));
    let methods = fx.p.table.methods();
    let m = methods[k % methods.len()] as i32;
    let vr = fx.vr("method");
    // SAFETY: a live instance, arrays of one element.
    assert_eq!(unsafe { fmi2SetInteger(s.c, &vr, 1, &m) }, fmi2OK);
    assert_eq!(s.setup(0.0, None), fmi2OK);
    // SAFETY: a live instance.
    unsafe {
        assert_eq!(
            fxbody::fmi::exports::fmi2EnterInitializationMode(s.c),
            fmi2OK
        );
        assert_eq!(
            fxbody::fmi::exports::fmi2ExitInitializationMode(s.c),
            fmi2OK
        );
    }
    let (f, y, vy) = (
        fx.vr("node_121.fy"),
        fx.vr("node_121.y"),
        fx.vr("node_121.vy"),
    );
    let mut out = Vec::with_capacity(2 * STEPS);
    let mut o = [0.0; 2];
    for i in 0..STEPS {
        let t = i as f64 * H;
        assert_eq!(s.set_real(&[f], &[force(k, t)]), fmi2OK);
        assert_eq!(s.do_step(t, H), fmi2OK, "{}", s.last_error());
        assert_eq!(s.get_real(&[y, vy], &mut o), fmi2OK);
        out.extend_from_slice(&o);
    }
    out
}

/// Run `k` through a library loaded from `so` (loaded here, unloaded at the end).
fn loaded(fx: &Packed, so: &Path, k: usize, steps: usize) -> Vec<f64> {
    let lib = FmuLibrary::open(so).unwrap();
    let inst = lib
        .instantiate(&format!("dl{k}"), &fx.p.guid, &fx.uri, false)
        .unwrap();
    let methods = fx.p.table.methods();
    inst.set_integer(&[fx.vr("method")], &[methods[k % methods.len()] as i32])
        .unwrap();
    inst.initialise(0.0, None).unwrap();
    let (f, y, vy) = (
        fx.vr("node_121.fy"),
        fx.vr("node_121.y"),
        fx.vr("node_121.vy"),
    );
    let mut out = Vec::with_capacity(2 * steps);
    let mut o = [0.0; 2];
    for i in 0..steps {
        let t = i as f64 * H;
        inst.set_real(&[f], &[force(k, t)]).unwrap();
        inst.do_step(t, H).unwrap();
        inst.get_real(&[y, vy], &mut o).unwrap();
        out.extend_from_slice(&o);
    }
    drop(inst);
    drop(lib);
    out
}

#[test]
fn eight_threads_equal_eight_sequential_runs() {
    let fx = packed("threads");
    let sequential: Vec<Vec<f64>> = (0..THREADS).map(|k| direct(&fx, k)).collect();
    // The runs really differ (else equality would prove little).
    for k in 1..THREADS {
        assert!(!same_bits(&sequential[k], &sequential[0]));
        assert!(sequential[k].iter().any(|v| v.abs() > 1e-9));
    }
    let start = Barrier::new(THREADS);
    let parallel: Vec<Vec<f64>> = thread::scope(|sc| {
        let handles: Vec<_> = (0..THREADS)
            .map(|k| {
                let (fx, start) = (&fx, &start);
                sc.spawn(move || {
                    start.wait();
                    direct(fx, k)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for k in 0..THREADS {
        assert!(same_bits(&parallel[k], &sequential[k]), "thread {k}");
    }
    // The same through dlopen: eight threads each loading the library themselves.
    let seq_dl: Vec<Vec<f64>> = (0..THREADS)
        .map(|k| loaded(&fx, &fx.so, k, STEPS))
        .collect();
    let par_dl: Vec<Vec<f64>> = thread::scope(|sc| {
        let handles: Vec<_> = (0..THREADS)
            .map(|k| {
                let (fx, start) = (&fx, &start);
                sc.spawn(move || {
                    start.wait();
                    loaded(fx, &fx.so, k, STEPS)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for k in 0..THREADS {
        assert!(same_bits(&par_dl[k], &seq_dl[k]), "dlopen thread {k}");
        // The loaded library is the same code as the crate: the same bits again.
        assert!(
            same_bits(&seq_dl[k], &sequential[k]),
            "dlopen vs direct {k}"
        );
    }
    println!(
        "threads: {THREADS} direct + {THREADS} dlopen instances x {STEPS} steps, bit-identical to sequential"
    );
}

#[test]
fn loading_while_another_instance_is_freed() {
    let fx = packed("dlcycle");
    // A copy under another name is a second, separate library in the process.
    let copy = fx.dir.join("copy_of_cantilever.so");
    std::fs::copy(&fx.so, &copy).unwrap();
    const ROUNDS: usize = 12;
    const SHORT: usize = 60;
    let reference: Vec<Vec<f64>> = (0..4).map(|k| loaded(&fx, &fx.so, k, SHORT)).collect();
    let long_ref = loaded(&fx, &fx.so, 5, STEPS);
    // One long-lived instance of the library steps the whole time, while three threads
    // load, instantiate, step, free and unload the same library and its copy.
    let results = thread::scope(|sc| {
        let long = sc.spawn(|| loaded(&fx, &fx.so, 5, STEPS));
        let cyclers: Vec<_> = (0..3)
            .map(|j| {
                let (fx, copy) = (&fx, &copy);
                sc.spawn(move || {
                    let mut runs = Vec::new();
                    for r in 0..ROUNDS {
                        let so = if (r + j) % 2 == 0 { &fx.so } else { copy };
                        runs.push(((r + j) % 4, loaded(fx, so, (r + j) % 4, SHORT)));
                    }
                    runs
                })
            })
            .collect();
        let runs: Vec<_> = cyclers
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect();
        (long.join().unwrap(), runs)
    });
    assert!(same_bits(&results.0, &long_ref), "long-lived instance");
    for (k, r) in &results.1 {
        assert!(same_bits(r, &reference[*k]), "cycled run {k}");
    }
    println!(
        "dlopen cycles: {} load/instantiate/free/unload cycles beside one long-lived instance, all bit-identical",
        results.1.len()
    );
}
