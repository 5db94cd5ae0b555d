//! Shared helpers of the robustness tests: a packed cantilever (tip node only) unpacked
//! into a temporary folder, a recording logger, and a thin slave that calls the crate's
//! `extern "C"` exports directly, so that a test can pass what a careless master passes
//! (NULL pointers, wrong lengths, calls out of sequence) and look inside the instance
//! afterwards to check nothing changed.

// These helpers call the exported fmi2* functions directly with raw pointers (what a C
// master does), which is `unsafe`; the workspace denies `unsafe_code` elsewhere.
#![allow(unsafe_code)]
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::ffi::{CStr, CString, c_char, c_void};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Every export under one name, whichever module of src/fmi defines it.
mod x {
    pub use fxbody::fmi::exports::*;
    pub use fxbody::fmi::fmu_state::*;
    pub use fxbody::fmi::values::*;
}
use fxbody::fmi::instance::Instance as Inner;
use fxbody::fmi::state::FmiState;
use fxbody::fmi::types::*;
use fxbody::fmu::fmi_version::FmiVersion;
use fxbody::fmu::interface::Interfaces;
use fxbody::fmu::pack::{PackOptions, PackRequest, Prepared, find_library, pack};

use super::fixture;

/// Time step of every run.
pub const H: f64 = 1e-4;

/// A packed and unpacked FMU: the preparation (variables, GUID), the folder, the
/// resource URI and the library path.
pub struct Packed {
    pub p: Prepared,
    pub dir: PathBuf,
    pub uri: String,
    pub so: PathBuf,
}

impl Packed {
    /// The resources folder as FMI 3.0 passes it: an absolute path with a trailing
    /// separator.
    pub fn resource_path(&self) -> String {
        format!("{}/", self.dir.join("resources").display())
    }

    /// Value reference of a variable by name.
    pub fn vr(&self, name: &str) -> u32 {
        self.p
            .table
            .vars
            .iter()
            .find(|v| v.name == name)
            .unwrap_or_else(|| panic!("no variable {name}"))
            .vr
    }
}

impl Drop for Packed {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Pack `fixtures/BODY.fxb` (with its node deck) with `node` exposed into `dir/tip.fmu`
/// under the model name `model` (default: the body's name) and unpack it into `dir`: the
/// preparation and the path of the unpacked library.
pub fn unpack(dir: &Path, body: &str, node: i64, model: Option<&str>) -> (Prepared, PathBuf) {
    unpack_as(dir, body, node, model, FmiVersion::Fmi2)
}

/// [`unpack`] for FMI version `fmi` (`pack --fmi`).
pub fn unpack_as(
    dir: &Path,
    body: &str,
    node: i64,
    model: Option<&str>,
    fmi: FmiVersion,
) -> (Prepared, PathBuf) {
    unpack_with(dir, body, node, model, fmi, Interfaces::CoSimulation)
}

/// [`unpack_as`] declaring `interface` (`pack --interface`).
pub fn unpack_with(
    dir: &Path,
    body: &str,
    node: i64,
    model: Option<&str>,
    fmi: FmiVersion,
    interface: Interfaces,
) -> (Prepared, PathBuf) {
    std::fs::create_dir_all(dir).unwrap();
    let lib = find_library(None).expect("libfxbody.so next to the test executable");
    let fmu = dir.join("tip.fmu");
    let req = PackRequest {
        body: fixture(&format!("{body}.fxb")),
        coords: Some(fixture(&format!("{body}.nodes.rad"))),
        nodes: Some(vec![node]),
        name: model.map(str::to_string),
        ..PackRequest::default()
    };
    let opts = PackOptions {
        fmi,
        interface,
        ..PackOptions::default()
    };
    let p = pack(&req, &opts, &lib, &fmu, None).unwrap();
    extract(&fmu, dir);
    let so = dir.join(format!(
        "binaries/{}/{}.so",
        fmi.native_platform(),
        model.unwrap_or(body)
    ));
    (p, so)
}

/// Unzip the FMU `fmu` into `dir`.
pub fn extract(fmu: &Path, dir: &Path) {
    for (name, data) in fxbody_host::zip::read(&std::fs::read(fmu).unwrap()).unwrap() {
        let path = dir.join(&name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, data).unwrap();
    }
}

/// Pack the cantilever with its tip node 121 exposed into `dir/tip.fmu` and unpack it
/// into `dir`: the preparation and the path of the unpacked library.
pub fn unpack_tip(dir: &Path) -> (Prepared, PathBuf) {
    unpack(dir, "cantilever", 121, None)
}

/// Pack the cantilever with its tip node 121 exposed and unpack it under a temporary
/// folder named after `tag`.
pub fn packed(tag: &str) -> Packed {
    packed_full(tag, "cantilever", 121, None)
}

/// As [`packed`], under the model name `name`: another GUID and another library file.
pub fn packed_as(tag: &str, name: &str) -> Packed {
    packed_full(tag, "cantilever", 121, Some(name))
}

/// Pack a fixture body (`fixtures/NAME.fxb` with its node deck) with one node exposed
/// and unpack it under a temporary folder named after `tag`.
pub fn packed_body(tag: &str, name: &str, node: i64) -> Packed {
    packed_full(tag, name, node, None)
}

/// [`unpack`] under a temporary folder named after `tag`, with the resource URI.
fn packed_full(tag: &str, body: &str, node: i64, model: Option<&str>) -> Packed {
    packed_as_version(tag, body, node, model, FmiVersion::Fmi2)
}

/// The cantilever with its tip exposed, packed for FMI 2.0 Model Exchange
/// (`--interface me`), under a temporary folder named after `tag`.
pub fn packed_me(tag: &str) -> Packed {
    packed_with(
        tag,
        "cantilever",
        121,
        None,
        FmiVersion::Fmi2,
        Interfaces::ModelExchange,
    )
}

/// [`unpack_as`] under a temporary folder named after `tag`, with the resource URI.
pub fn packed_as_version(
    tag: &str,
    body: &str,
    node: i64,
    model: Option<&str>,
    fmi: FmiVersion,
) -> Packed {
    packed_with(tag, body, node, model, fmi, Interfaces::CoSimulation)
}

/// [`unpack_with`] under a temporary folder named after `tag`, with the resource URI.
pub fn packed_with(
    tag: &str,
    body: &str,
    node: i64,
    model: Option<&str>,
    fmi: FmiVersion,
    interface: Interfaces,
) -> Packed {
    let dir = std::env::temp_dir().join(format!("fxbody_robust_{tag}_{}", std::process::id()));
    let (p, so) = unpack_with(&dir, body, node, model, fmi, interface);
    let uri = fxbody_host::file_uri(&dir.join("resources"));
    Packed { p, dir, uri, so }
}

/// One logged message, as the logger received it.
#[derive(Debug, Clone)]
pub struct Msg {
    pub name: String,
    pub status: fmi2Status,
    pub category: String,
    pub format: String,
    pub text: String,
}

/// Where the logger writes: one per instance, its address is the environment pointer.
pub type LogSink = Mutex<Vec<Msg>>;

/// The recording sink behind the host's C logger ([`fxbody_host::c_logger`], a real
/// C-variadic function that formats the message): it records the instance name, status,
/// category, the format as the library passed it (so a test can check it is "%s"
/// whatever the text holds) and the formatted text.
extern "C" fn record(
    data: *mut c_void,
    name: fmi2String,
    status: fmi2Status,
    category: fmi2String,
    format: fmi2String,
    text: *const c_char,
) {
    if data.is_null() {
        return;
    }
    // SAFETY: `data` is the LogSink of the instance being called (set by `log_env`).
    let sink = unsafe { &*data.cast::<LogSink>() };
    let s = |p: *const c_char| {
        if p.is_null() {
            String::from("<NULL>")
        } else {
            // SAFETY: non-null pointers the logger passes are NUL-terminated strings.
            unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
        }
    };
    let m = Msg {
        name: s(name),
        status,
        category: s(category),
        format: s(format),
        text: s(text),
    };
    if let Ok(mut l) = sink.lock() {
        l.push(m);
    }
}

/// The logger callback to pass with [`log_env`]: the host's C-variadic logger.
pub fn logger() -> fmi2CallbackLogger {
    fxbody_host::c_logger()
}

/// The component environment that makes [`logger`] record into `sink`; keep the box
/// alive (and the sink) as long as the instance.
pub fn log_env(sink: &LogSink) -> Box<fxbody_host::LogEnv> {
    Box::new(fxbody_host::LogEnv {
        sink: record,
        data: (sink as *const LogSink).cast_mut().cast(),
    })
}

/// An instance created through `fmi2Instantiate` of this crate (not a loaded copy),
/// with its own log. Freed on drop unless already freed.
pub struct Slave {
    /// The instance and its log, looked into alike for both FMI versions.
    h: Handle,
    /// The logger's environment, at a fixed address for the instance's life.
    _env: Box<fxbody_host::LogEnv>,
}

/// An instance of this crate (of either FMI version) and its log: the white-box view the
/// FMI 2.0 [`Slave`] and the FMI 3.0 [`super::fmu3::Slave3`] share (each derefs to it).
pub struct Handle {
    pub c: *mut c_void,
    pub log: Box<LogSink>,
}

impl Handle {
    /// Look inside: the FMI state the instance is in (white box, for the checks only).
    pub fn fmi_state(&self) -> FmiState {
        // SAFETY: `c` is a live instance of this crate, no call is running on it.
        unsafe { &*self.c.cast::<Inner>() }.state
    }

    /// Look inside: force the FMI state (white box: to show that a refused call left the
    /// model able to continue exactly as if it had not been made).
    pub fn force_state(&self, s: FmiState) {
        // SAFETY: as in `fmi_state`; exclusive use by this thread.
        unsafe { &mut *self.c.cast::<Inner>() }.state = s;
    }

    /// Look inside: the serialised snapshot of the model's complete state (parameters,
    /// inputs, times, solver), to compare before and after a refused call.
    pub fn fingerprint(&self) -> Vec<u8> {
        // SAFETY: as in `fmi_state`.
        let inner = unsafe { &*self.c.cast::<Inner>() };
        inner.simulation.snapshot(0).to_bytes("fingerprint")
    }

    /// Messages so far.
    pub fn messages(&self) -> Vec<Msg> {
        self.log.lock().unwrap().clone()
    }

    /// Text of the last error-status message (fmi2Error and fmi3Error are both 3).
    pub fn last_error(&self) -> String {
        self.messages()
            .iter()
            .rev()
            .find(|m| m.status >= fmi2Error)
            .map(|m| m.text.clone())
            .unwrap_or_default()
    }
}

impl std::ops::Deref for Slave {
    type Target = Handle;
    fn deref(&self) -> &Handle {
        &self.h
    }
}

impl std::ops::DerefMut for Slave {
    fn deref_mut(&mut self) -> &mut Handle {
        &mut self.h
    }
}

impl Slave {
    /// Instantiate with `name` (debug logging on, so every message is recorded).
    pub fn try_new(fx: &Packed, name: &str) -> Result<Slave, Vec<Msg>> {
        Slave::try_with(&fx.p.guid, &fx.uri, name)
    }

    /// Instantiate with an explicit GUID and resource URI.
    pub fn try_with(guid: &str, uri: &str, name: &str) -> Result<Slave, Vec<Msg>> {
        Slave::try_typed(guid, uri, name, fmi2CoSimulation)
    }

    /// A Model Exchange instance (fmi2Instantiate with fmi2ModelExchange) named `name`.
    pub fn new_me(fx: &Packed, name: &str) -> Slave {
        Slave::try_typed(&fx.p.guid, &fx.uri, name, fmi2ModelExchange)
            .unwrap_or_else(|m| panic!("instantiate failed: {m:?}"))
    }

    /// Instantiate for `fmu_type` with an explicit GUID and resource URI.
    pub fn try_typed(
        guid: &str,
        uri: &str,
        name: &str,
        fmu_type: fmi2Type,
    ) -> Result<Slave, Vec<Msg>> {
        let log: Box<LogSink> = Box::new(Mutex::new(Vec::new()));
        let env = log_env(&log);
        let functions = fmi2CallbackFunctions {
            logger: logger(),
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: (&*env as *const fxbody_host::LogEnv).cast_mut().cast(),
        };
        let (n, g, r) = (
            CString::new(name).unwrap(),
            CString::new(guid).unwrap(),
            CString::new(uri).unwrap(),
        );
        // SAFETY: valid strings and callbacks for the call; the sink outlives the
        // instance (both are owned by the Slave, the instance is freed first).
        let c = unsafe {
            x::fmi2Instantiate(
                n.as_ptr(),
                fmu_type,
                g.as_ptr(),
                r.as_ptr(),
                &functions,
                fmi2False,
                fmi2True,
            )
        };
        if c.is_null() {
            return Err(log.lock().unwrap().clone());
        }
        Ok(Slave {
            h: Handle { c, log },
            _env: env,
        })
    }

    pub fn new(fx: &Packed, name: &str) -> Slave {
        Slave::try_new(fx, name).unwrap_or_else(|m| panic!("instantiate failed: {m:?}"))
    }

    /// Instantiate, set up (start 0, optional stop), initialise: ready to step.
    pub fn started(fx: &Packed, stop: Option<f64>) -> Slave {
        let s = Slave::new(fx, "robust");
        assert_eq!(s.setup(0.0, stop), fmi2OK);
        // SAFETY: a live instance.
        unsafe {
            assert_eq!(x::fmi2EnterInitializationMode(s.c), fmi2OK);
            assert_eq!(x::fmi2ExitInitializationMode(s.c), fmi2OK);
        }
        s
    }

    pub fn setup(&self, start: f64, stop: Option<f64>) -> fmi2Status {
        // SAFETY: a live instance.
        unsafe {
            x::fmi2SetupExperiment(
                self.c,
                fmi2False,
                0.0,
                start,
                i32::from(stop.is_some()),
                stop.unwrap_or(0.0),
            )
        }
    }

    pub fn set_real(&self, vrs: &[u32], vals: &[f64]) -> fmi2Status {
        assert_eq!(vrs.len(), vals.len());
        // SAFETY: arrays of `vrs.len()` elements.
        unsafe { x::fmi2SetReal(self.c, vrs.as_ptr(), vrs.len(), vals.as_ptr()) }
    }

    pub fn get_real(&self, vrs: &[u32], out: &mut [f64]) -> fmi2Status {
        assert_eq!(vrs.len(), out.len());
        // SAFETY: arrays of `vrs.len()` elements, `out` writable.
        unsafe { x::fmi2GetReal(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) }
    }

    pub fn do_step(&self, t: f64, h: f64) -> fmi2Status {
        // SAFETY: a live instance.
        unsafe { x::fmi2DoStep(self.c, t, h, fmi2True) }
    }

    /// fmi2GetFMUstate into a new handle.
    pub fn get_state(&self) -> fmi2FMUstate {
        let mut s: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: a writable NULL handle.
        assert_eq!(unsafe { x::fmi2GetFMUstate(self.c, &mut s) }, fmi2OK);
        s
    }

    pub fn set_state(&self, s: fmi2FMUstate) -> fmi2Status {
        // SAFETY: `s` is a live state of this library (or NULL, refused).
        unsafe { x::fmi2SetFMUstate(self.c, s) }
    }

    pub fn free_state(&self, mut s: fmi2FMUstate) {
        // SAFETY: `s` is a live state of this library, freed once.
        assert_eq!(unsafe { x::fmi2FreeFMUstate(self.c, &mut s) }, fmi2OK);
        assert!(s.is_null());
    }

    /// Serialise a live state.
    pub fn serialize(&self, s: fmi2FMUstate) -> Vec<u8> {
        let mut n = 0usize;
        assert_eq!(
            // SAFETY: live state, writable size.
            unsafe { x::fmi2SerializedFMUstateSize(self.c, s, &mut n) },
            fmi2OK
        );
        let mut buf = vec![0u8; n];
        assert_eq!(
            // SAFETY: `buf` holds `n` writable bytes.
            unsafe { x::fmi2SerializeFMUstate(self.c, s, buf.as_mut_ptr().cast(), n) },
            fmi2OK
        );
        buf
    }

    /// fmi2DeSerializeFMUstate of `bytes` into a new handle (NULL when refused).
    pub fn deserialize(&self, bytes: &[u8]) -> (fmi2Status, fmi2FMUstate) {
        let mut s: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: `bytes` valid for the call, `s` a writable NULL handle.
        let st = unsafe {
            x::fmi2DeSerializeFMUstate(self.c, bytes.as_ptr().cast(), bytes.len(), &mut s)
        };
        (st, s)
    }
}

impl Drop for Slave {
    fn drop(&mut self) {
        // SAFETY: a live instance (or NULL after a test freed it), freed once.
        unsafe { x::fmi2FreeInstance(self.c) };
    }
}

/// The load every run applies: cos(300 t) on the tip's fy.
pub fn load(t: f64) -> f64 {
    (300.0 * t).cos()
}

/// What a run needs of a slave, whichever FMI version drives it (the FMI 3.0 slave is
/// [`super::fmu3::Slave3`]).
pub trait Stepper {
    /// Set Real (Float64) values.
    fn set_real(&self, vrs: &[u32], vals: &[f64]) -> fmi2Status;
    /// Get Real (Float64) values.
    fn get_real(&self, vrs: &[u32], out: &mut [f64]) -> fmi2Status;
    /// One step.
    fn do_step(&self, t: f64, h: f64) -> fmi2Status;
    /// Text of the last error-status message.
    fn last_error(&self) -> String;
}

impl Stepper for Slave {
    fn set_real(&self, vrs: &[u32], vals: &[f64]) -> fmi2Status {
        Slave::set_real(self, vrs, vals)
    }
    fn get_real(&self, vrs: &[u32], out: &mut [f64]) -> fmi2Status {
        Slave::get_real(self, vrs, out)
    }
    fn do_step(&self, t: f64, h: f64) -> fmi2Status {
        Slave::do_step(self, t, h)
    }
    fn last_error(&self) -> String {
        self.h.last_error()
    }
}

/// `n` steps from step number `k0`, returning the tip's y after each, or the first
/// failing status with the logged reason.
pub fn run(s: &impl Stepper, fx: &Packed, k0: usize, n: usize) -> Result<Vec<f64>, String> {
    let (f, y) = (fx.vr("node_121.fy"), fx.vr("node_121.y"));
    let mut out = Vec::with_capacity(n);
    let mut o = [0.0];
    for k in k0..k0 + n {
        let t = k as f64 * H;
        for st in [
            s.set_real(&[f], &[load(t)]),
            s.do_step(t, H),
            s.get_real(&[y], &mut o),
        ] {
            if st != fmi2OK {
                return Err(format!("step {k}: status {st}: {}", s.last_error()));
            }
        }
        out.push(o[0]);
    }
    Ok(out)
}

/// Bitwise equality of two result series (NaN-safe, -0.0 distinct).
pub fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// Steps run before a misuse, and after it.
pub const BEFORE: usize = 5;
pub const AFTER: usize = 5;

/// The undisturbed twin: BEFORE + AFTER steps from a fresh start.
pub fn reference(fx: &Packed) -> Vec<f64> {
    let r = run(&Slave::started(fx, None), fx, 0, BEFORE + AFTER).unwrap();
    assert!(r.iter().any(|v| v.abs() > 1e-9), "a real response: {r:?}");
    r
}

pub fn print_counts(what: &str, counts: &BTreeMap<&str, usize>) {
    let total: usize = counts.values().sum();
    for (k, n) in counts {
        println!("{what}: {k}: {n}");
    }
    println!("{what}: total {total}");
}

/// A slave after BEFORE steps, its saved state and fingerprint.
pub struct Midway {
    pub s: Slave,
    pub saved: fmi2FMUstate,
    pub print: Vec<u8>,
}

pub fn midway(fx: &Packed, stop: Option<f64>) -> Midway {
    let s = Slave::started(fx, stop);
    run(&s, fx, 0, BEFORE).unwrap();
    let saved = s.get_state();
    let print = s.fingerprint();
    Midway { s, saved, print }
}

impl Midway {
    /// The refused call left the model untouched: the fingerprint is the same, and
    /// (white box) allowed to continue, the next steps equal the twin's bit for bit;
    /// then the FMI way out, SetFMUstate, gives the same bits again.
    pub fn unchanged(&self, fx: &Packed, twin: &[f64], what: &str) {
        let s = &self.s;
        assert!(s.fingerprint() == self.print, "{what}: model changed");
        if s.fmi_state() == FmiState::Error {
            s.force_state(FmiState::StepComplete);
        }
        let cont = run(s, fx, BEFORE, AFTER).unwrap();
        assert!(same_bits(&cont, &twin[BEFORE..]), "{what}: {cont:?}");
        assert_eq!(s.set_state(self.saved), fmi2OK);
        let again = run(s, fx, BEFORE, AFTER).unwrap();
        assert!(same_bits(&again, &twin[BEFORE..]), "{what} (restored)");
        assert_eq!(s.set_state(self.saved), fmi2OK);
    }

    /// A call refused with fmi2Error and a logged reason holding `says`.
    pub fn refused(&self, st: fmi2Status, says: &str, what: &str) {
        assert_eq!(st, fmi2Error, "{what}");
        assert_eq!(self.s.fmi_state(), FmiState::Error, "{what}");
        let e = self.s.last_error();
        assert!(e.contains(says), "{what}: logged '{e}', expected '{says}'");
    }
}

impl Drop for Midway {
    fn drop(&mut self) {
        let mut s = self.saved;
        // SAFETY: the live state of this instance, freed once.
        unsafe { x::fmi2FreeFMUstate(self.s.c, &mut s) };
    }
}
