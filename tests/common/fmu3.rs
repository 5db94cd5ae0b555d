//! The FMI 3.0 side of the robustness tests' helpers ([`super::fmu`]): a slave that
//! calls the crate's `fmi3*` exports directly with what a careless FMI 3.0 master
//! passes, and a recording logMessage. FMI 3.0's logger is not variadic, so it is a plain
//! Rust function here (FMI 2.0's needs the host's C shim).

// These helpers call the exported fmi3* functions directly with raw pointers (what a C
// master does), which is `unsafe`; the workspace denies `unsafe_code` elsewhere.
#![allow(unsafe_code)]
#![allow(dead_code)]

use std::ffi::{CStr, CString, c_char, c_void};
use std::sync::Mutex;

use fxbody::fmi::fmi3::exports as e;
use fxbody::fmi::fmi3::fmu_state as fs;
use fxbody::fmi::fmi3::types::*;
use fxbody::fmi::fmi3::values as v;
use fxbody::fmu::fmi_version::FmiVersion;

use super::fmu::{Handle, LogSink, Msg, Packed, Stepper, packed_as_version};

/// The cantilever with its tip node 121 exposed, packed for FMI 3.0 and unpacked under a
/// temporary folder named after `tag`.
pub fn packed3(tag: &str) -> Packed {
    packed_as_version(tag, "cantilever", 121, None, FmiVersion::Fmi3)
}

/// The recording logMessage: the environment is the instance's [`LogSink`]. FMI 3.0
/// passes no instance name and no format; `name` and `format` stay empty.
pub extern "C" fn record3(
    env: fmi3InstanceEnvironment,
    status: fmi3Status,
    category: fmi3String,
    message: fmi3String,
) {
    if env.is_null() {
        return;
    }
    // SAFETY: `env` is the LogSink of the instance being called (set by Slave3).
    let sink = unsafe { &*env.cast::<LogSink>() };
    let s = |p: *const c_char| {
        if p.is_null() {
            String::from("<NULL>")
        } else {
            // SAFETY: non-null pointers the FMU passes are NUL-terminated strings.
            unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
        }
    };
    if let Ok(mut l) = sink.lock() {
        l.push(Msg {
            name: String::new(),
            status,
            category: s(category),
            format: String::new(),
            text: s(message),
        });
    }
}

/// An instance created through this crate's fmi3InstantiateCoSimulation, with its own
/// log (loggingOn as asked). Freed on drop.
pub struct Slave3 {
    /// The instance and its log, looked into as FMI 2.0's [`super::fmu::Slave`].
    h: Handle,
}

impl std::ops::Deref for Slave3 {
    type Target = Handle;
    fn deref(&self) -> &Handle {
        &self.h
    }
}

impl std::ops::DerefMut for Slave3 {
    fn deref_mut(&mut self) -> &mut Handle {
        &mut self.h
    }
}

impl Slave3 {
    /// Instantiate with an explicit token, resource path, name and loggingOn.
    pub fn try_with(
        token: Option<&str>,
        path: Option<&str>,
        name: &str,
        logging_on: bool,
    ) -> Result<Slave3, Vec<Msg>> {
        let log: Box<LogSink> = Box::new(Mutex::new(Vec::new()));
        let (n, t, p) = (
            CString::new(name).unwrap(),
            token.map(|t| CString::new(t).unwrap()),
            path.map(|p| CString::new(p).unwrap()),
        );
        let ptr = |c: &Option<CString>| c.as_ref().map_or(std::ptr::null(), |c| c.as_ptr());
        // SAFETY: valid strings for the call; the sink outlives the instance (both are
        // owned by the Slave3, the instance is freed first).
        let c = unsafe {
            e::fmi3InstantiateCoSimulation(
                n.as_ptr(),
                ptr(&t),
                ptr(&p),
                false,
                logging_on,
                false,
                false,
                std::ptr::null(),
                0,
                (&*log as *const LogSink).cast_mut().cast::<c_void>(),
                Some(record3),
                None,
            )
        };
        Slave3::made(c, log)
    }

    /// A Model Exchange instance (fmi3InstantiateModelExchange) of `fx`, logging on.
    pub fn new_me(fx: &Packed, name: &str) -> Slave3 {
        let log: Box<LogSink> = Box::new(Mutex::new(Vec::new()));
        let (n, t, p) = (
            CString::new(name).unwrap(),
            CString::new(fx.p.guid.as_str()).unwrap(),
            CString::new(fx.resource_path()).unwrap(),
        );
        // SAFETY: valid strings for the call; the sink outlives the instance.
        let c = unsafe {
            e::fmi3InstantiateModelExchange(
                n.as_ptr(),
                t.as_ptr(),
                p.as_ptr(),
                false,
                true,
                (&*log as *const LogSink).cast_mut().cast::<c_void>(),
                Some(record3),
            )
        };
        Slave3::made(c, log).unwrap_or_else(|m| panic!("instantiate failed: {m:?}"))
    }

    /// The slave of instance `c` (NULL: the messages logged instead).
    fn made(c: fmi3Instance, log: Box<LogSink>) -> Result<Slave3, Vec<Msg>> {
        if c.is_null() {
            return Err(log.lock().unwrap().clone());
        }
        Ok(Slave3 {
            h: Handle { c, log },
        })
    }

    /// Instantiate `fx` (packed for FMI 3.0) with `name`, logging on.
    pub fn new(fx: &Packed, name: &str) -> Slave3 {
        Slave3::try_with(Some(&fx.p.guid), Some(&fx.resource_path()), name, true)
            .unwrap_or_else(|m| panic!("instantiate failed: {m:?}"))
    }

    /// Instantiate and initialise (start 0, optional stop): ready to step.
    pub fn started(fx: &Packed, stop: Option<f64>) -> Slave3 {
        let s = Slave3::new(fx, "robust3");
        assert_eq!(s.enter_init(0.0, stop), fmi3OK, "{}", s.last_error());
        assert_eq!(s.exit_init(), fmi3OK);
        s
    }

    pub fn exit_init(&self) -> fmi3Status {
        // SAFETY: a live instance.
        unsafe { e::fmi3ExitInitializationMode(self.c) }
    }

    pub fn enter_init(&self, start: f64, stop: Option<f64>) -> fmi3Status {
        // SAFETY: a live instance.
        unsafe {
            e::fmi3EnterInitializationMode(
                self.c,
                false,
                0.0,
                start,
                stop.is_some(),
                stop.unwrap_or(0.0),
            )
        }
    }

    pub fn set_int(&self, vrs: &[u32], vals: &[i32]) -> fmi3Status {
        // SAFETY: arrays of `vrs.len()` elements.
        unsafe { v::fmi3SetInt32(self.c, vrs.as_ptr(), vrs.len(), vals.as_ptr(), vals.len()) }
    }

    /// fmi3DoStep, with every output argument written checked.
    pub fn step(&self, t: f64, h: f64) -> (fmi3Status, [bool; 3], f64) {
        let (mut ev, mut term, mut early, mut last) = (true, true, true, f64::NAN);
        // SAFETY: a live instance, writable outputs.
        let st = unsafe {
            e::fmi3DoStep(
                self.c, t, h, true, &mut ev, &mut term, &mut early, &mut last,
            )
        };
        (st, [ev, term, early], last)
    }

    /// fmi3GetFMUState into a new handle.
    pub fn get_state(&self) -> fmi3FMUState {
        let mut s: fmi3FMUState = std::ptr::null_mut();
        // SAFETY: a writable NULL handle.
        assert_eq!(unsafe { fs::fmi3GetFMUState(self.c, &mut s) }, fmi3OK);
        s
    }

    pub fn set_state(&self, s: fmi3FMUState) -> fmi3Status {
        // SAFETY: `s` is a live state of this library (or NULL, refused).
        unsafe { fs::fmi3SetFMUState(self.c, s) }
    }

    pub fn free_state(&self, mut s: fmi3FMUState) {
        // SAFETY: `s` is a live state of this library, freed once.
        assert_eq!(unsafe { fs::fmi3FreeFMUState(self.c, &mut s) }, fmi3OK);
        assert!(s.is_null());
    }

    /// Serialise a live state.
    pub fn serialize(&self, s: fmi3FMUState) -> Vec<u8> {
        let mut n = 0usize;
        // SAFETY: live state, writable size.
        let st = unsafe { fs::fmi3SerializedFMUStateSize(self.c, s, &mut n) };
        assert_eq!(st, fmi3OK);
        let mut buf = vec![0u8; n];
        // SAFETY: `buf` holds `n` writable bytes.
        let st = unsafe { fs::fmi3SerializeFMUState(self.c, s, buf.as_mut_ptr(), n) };
        assert_eq!(st, fmi3OK);
        buf
    }

    /// fmi3DeserializeFMUState of `bytes` into a new handle (NULL when refused).
    pub fn deserialize(&self, bytes: &[u8]) -> (fmi3Status, fmi3FMUState) {
        let mut s: fmi3FMUState = std::ptr::null_mut();
        // SAFETY: `bytes` valid for the call, `s` a writable NULL handle.
        let st =
            unsafe { fs::fmi3DeserializeFMUState(self.c, bytes.as_ptr(), bytes.len(), &mut s) };
        (st, s)
    }
}

impl Stepper for Slave3 {
    fn set_real(&self, vrs: &[u32], vals: &[f64]) -> fmi3Status {
        assert_eq!(vrs.len(), vals.len());
        // SAFETY: arrays of `vrs.len()` elements.
        unsafe { v::fmi3SetFloat64(self.c, vrs.as_ptr(), vrs.len(), vals.as_ptr(), vals.len()) }
    }

    fn get_real(&self, vrs: &[u32], out: &mut [f64]) -> fmi3Status {
        assert_eq!(vrs.len(), out.len());
        // SAFETY: arrays of `vrs.len()` elements, `out` writable.
        unsafe { v::fmi3GetFloat64(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr(), out.len()) }
    }

    /// fmi3DoStep; a completed step must say: no event, no termination, no early
    /// return, last successful time t + h.
    fn do_step(&self, t: f64, h: f64) -> fmi3Status {
        let (st, flags, last) = self.step(t, h);
        if st <= fmi3Warning {
            assert_eq!(flags, [false; 3], "fmi3DoStep's flags");
            assert_eq!(last, t + h, "fmi3DoStep's lastSuccessfulTime");
        }
        st
    }

    fn last_error(&self) -> String {
        self.h.last_error()
    }
}

impl Drop for Slave3 {
    fn drop(&mut self) {
        // SAFETY: a live instance (or NULL after a test freed it), freed once.
        unsafe { e::fmi3FreeInstance(self.c) };
    }
}
