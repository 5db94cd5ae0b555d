//! An FMI 2.0 co-simulation importer: load a packed FMU's library (`libloading`) and call
//! it through its C ABI, exactly as a master would; read the `.fmu` archive ([`zip`]);
//! build the resource location URI ([`uri`]). Used by `fxbody demo`, the tests and the
//! benches, so that they exercise the real exports rather than the Rust functions behind
//! them. Never part of the FMU.
//!
//! The one module of this package with `unsafe`: every call through the loaded library
//! is a foreign call whose contract the FMI 2.0 standard states.

// Loading a library and calls through its function pointers cannot be safe Rust; each
// block says why it holds (clippy::undocumented_unsafe_blocks).
#![allow(unsafe_code)]

pub mod fmi2;
pub mod uri;
pub mod zip;

use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use fmi2::*;
pub use uri::file_uri;

type Instantiate = unsafe extern "C" fn(
    fmi2String,
    fmi2Type,
    fmi2String,
    fmi2String,
    *const fmi2CallbackFunctions,
    fmi2Boolean,
    fmi2Boolean,
) -> fmi2Component;
type Free = unsafe extern "C" fn(fmi2Component);
type Setup = unsafe extern "C" fn(
    fmi2Component,
    fmi2Boolean,
    fmi2Real,
    fmi2Real,
    fmi2Boolean,
    fmi2Real,
) -> fmi2Status;
type Plain = unsafe extern "C" fn(fmi2Component) -> fmi2Status;
type GetReal = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *mut fmi2Real,
) -> fmi2Status;
type SetReal = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2Real,
) -> fmi2Status;
type SetInteger = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2Integer,
) -> fmi2Status;
type DoStep = unsafe extern "C" fn(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean) -> fmi2Status;
type GetState = unsafe extern "C" fn(fmi2Component, *mut fmi2FMUstate) -> fmi2Status;
type SetState = unsafe extern "C" fn(fmi2Component, fmi2FMUstate) -> fmi2Status;
type StateSize = unsafe extern "C" fn(fmi2Component, fmi2FMUstate, *mut usize) -> fmi2Status;
type Serialize =
    unsafe extern "C" fn(fmi2Component, fmi2FMUstate, *mut fmi2Byte, usize) -> fmi2Status;
type Deserialize =
    unsafe extern "C" fn(fmi2Component, *const fmi2Byte, usize, *mut fmi2FMUstate) -> fmi2Status;
type Derivs = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2Integer,
    *const fmi2Real,
) -> fmi2Status;
type OutDerivs = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2Integer,
    *mut fmi2Real,
) -> fmi2Status;

/// The functions a host uses, resolved from the library.
struct Fns {
    instantiate: Instantiate,
    free: Free,
    setup: Setup,
    enter_init: Plain,
    exit_init: Plain,
    terminate: Plain,
    reset: Plain,
    get_real: GetReal,
    set_real: SetReal,
    set_integer: SetInteger,
    do_step: DoStep,
    get_state: GetState,
    set_state: SetState,
    free_state: GetState,
    state_size: StateSize,
    serialize: Serialize,
    deserialize: Deserialize,
    set_input_derivatives: Derivs,
    get_output_derivatives: OutDerivs,
}

/// A loaded FMU library (closed on drop).
pub struct FmuLibrary {
    f: Fns,
    /// Keeps the code `f` points into loaded; instances borrow the library, so none
    /// outlives it.
    _lib: libloading::Library,
}

/// Load the library at `path`, resolving every symbol now and keeping them to this
/// library (two loaded FMUs export the same names).
#[cfg(unix)]
fn load(path: &Path) -> Result<libloading::Library, libloading::Error> {
    use libloading::os::unix::{Library, RTLD_LOCAL, RTLD_NOW};
    // SAFETY: loading runs the library's initialisers; an FMU's are its own static
    // constructors, which the FMI standard lets an importer run by loading it.
    unsafe { Library::open(Some(path), RTLD_NOW | RTLD_LOCAL) }.map(Into::into)
}

/// Load the library at `path` (LoadLibraryExW on Windows: symbols stay per library).
#[cfg(not(unix))]
fn load(path: &Path) -> Result<libloading::Library, libloading::Error> {
    // SAFETY: as on Unix: loading runs the FMU's own initialisers.
    unsafe { libloading::Library::new(path) }
}

impl FmuLibrary {
    /// Load the library at `path` and resolve the functions.
    pub fn open(path: &Path) -> Result<FmuLibrary, String> {
        let lib = load(path).map_err(|e| format!("cannot load {}: {e}", path.display()))?;
        macro_rules! sym {
            ($name:literal, $ty:ty) => {{
                // SAFETY: the symbol is the FMI 2.0 function of that name, whose C
                // signature is `$ty` (fmi2Functions.h); the pointer copied out of the
                // `Symbol` is used only while `lib`, kept in the same `FmuLibrary`, is
                // loaded.
                let s = unsafe { lib.get::<$ty>(concat!($name, "\0").as_bytes()) }
                    .map_err(|_| format!("{}: missing export {}", path.display(), $name))?;
                *s
            }};
        }
        let f = Fns {
            instantiate: sym!("fmi2Instantiate", Instantiate),
            free: sym!("fmi2FreeInstance", Free),
            setup: sym!("fmi2SetupExperiment", Setup),
            enter_init: sym!("fmi2EnterInitializationMode", Plain),
            exit_init: sym!("fmi2ExitInitializationMode", Plain),
            terminate: sym!("fmi2Terminate", Plain),
            reset: sym!("fmi2Reset", Plain),
            get_real: sym!("fmi2GetReal", GetReal),
            set_real: sym!("fmi2SetReal", SetReal),
            set_integer: sym!("fmi2SetInteger", SetInteger),
            do_step: sym!("fmi2DoStep", DoStep),
            get_state: sym!("fmi2GetFMUstate", GetState),
            set_state: sym!("fmi2SetFMUstate", SetState),
            free_state: sym!("fmi2FreeFMUstate", GetState),
            state_size: sym!("fmi2SerializedFMUstateSize", StateSize),
            serialize: sym!("fmi2SerializeFMUstate", Serialize),
            deserialize: sym!("fmi2DeSerializeFMUstate", Deserialize),
            set_input_derivatives: sym!("fmi2SetRealInputDerivatives", Derivs),
            get_output_derivatives: sym!("fmi2GetRealOutputDerivatives", OutDerivs),
        };
        Ok(FmuLibrary { f, _lib: lib })
    }

    /// Instantiate a co-simulation slave with debug logging `debug`. On failure the
    /// error holds what the FMU logged.
    pub fn instantiate(
        &self,
        name: &str,
        guid: &str,
        resource_uri: &str,
        debug: bool,
    ) -> Result<Instance<'_>, String> {
        let log = Box::new(Mutex::new(Vec::new()));
        let env = Box::new(LogEnv {
            sink,
            data: (&*log as *const Mutex<Vec<String>>).cast_mut().cast(),
        });
        let functions = fmi2CallbackFunctions {
            logger: Some(fxbody_host_logger),
            allocateMemory: std::ptr::null(),
            freeMemory: std::ptr::null(),
            stepFinished: std::ptr::null(),
            componentEnvironment: (&*env as *const LogEnv).cast_mut().cast(),
        };
        let (n, g, r) = (c_text(name), c_text(guid), c_text(resource_uri));
        // SAFETY: valid C strings and callbacks for the call; the environment (the boxed
        // `LogEnv` and the log it points at) lives as long as the instance, which owns
        // both.
        let c = unsafe {
            (self.f.instantiate)(
                n.as_ptr(),
                fmi2CoSimulation,
                g.as_ptr(),
                r.as_ptr(),
                &functions,
                fmi2False,
                c_int::from(debug),
            )
        };
        if c.is_null() {
            let msgs = log.lock().map(|m| m.join("; ")).unwrap_or_default();
            return Err(format!("fmi2Instantiate returned NULL: {msgs}"));
        }
        Ok(Instance {
            lib: self,
            c,
            log,
            _env: env,
        })
    }
}

unsafe extern "C" {
    /// The C-variadic logger of `logger.c`: formats the message with `vsnprintf` and
    /// calls `LogEnv::sink` with the text.
    fn fxbody_host_logger(
        env: fmi2ComponentEnvironment,
        name: fmi2String,
        status: fmi2Status,
        category: fmi2String,
        fmt: fmi2String,
        ...
    );
}

/// A fixed-arity receiver of log messages: `(data, instance name, status, category, the
/// format as the FMU passed it, the formatted text)`. The C shim `logger.c` calls it.
pub type LogSinkFn =
    extern "C" fn(*mut c_void, fmi2String, fmi2Status, fmi2String, fmi2String, *const c_char);

/// What a master passes as the component environment when its logger is [`c_logger`]:
/// the layout `logger.c` reads (`fxbody_host_env`), a fixed-arity sink and its data. It
/// must stay at a fixed address while the instance lives (box it).
#[repr(C)]
pub struct LogEnv {
    /// Called once per message with the formatted text.
    pub sink: LogSinkFn,
    /// Passed to `sink` as its first argument.
    pub data: *mut c_void,
}

/// The FMI 2.0 logger callback, C-variadic as the standard declares it, implemented in C
/// (`logger.c`): it formats the message with `vsnprintf` and hands the text to the
/// [`LogEnv`] given as component environment. Sound on every platform with a C compiler,
/// unlike a fixed-arity Rust function transmuted to the variadic type.
pub fn c_logger() -> fmi2CallbackLogger {
    Some(fxbody_host_logger)
}

/// Stores `"[category] text"` in the log `data` points to.
extern "C" fn sink(
    data: *mut c_void,
    _name: fmi2String,
    _status: fmi2Status,
    category: *const c_char,
    _format: fmi2String,
    text: *const c_char,
) {
    if data.is_null() {
        return;
    }
    // SAFETY: `data` is the `log` of a `LogEnv`, which points at the instance's boxed
    // log; the instance owns both and outlives every call into the FMU.
    let log = unsafe { &*data.cast::<Mutex<Vec<String>>>() };
    // SAFETY: category and text are NULL or NUL-terminated strings for the call
    // (logger.c passes its formatted buffer, the FMU its category).
    let (cat, text) = unsafe {
        (
            text_arg(category).unwrap_or_default(),
            text_arg(text).unwrap_or_default(),
        )
    };
    if let Ok(mut l) = log.lock() {
        l.push(format!("[{cat}] {text}"));
    }
}

/// A C string from text, with any NUL byte replaced.
fn c_text(s: &str) -> CString {
    CString::new(s.replace('\0', "\u{fffd}")).unwrap_or_default()
}

/// Text of a C string; `None` for NULL.
///
/// # Safety
/// `p` is NULL or a NUL-terminated string valid for the call.
unsafe fn text_arg(p: *const c_char) -> Option<String> {
    if p.is_null() {
        return None;
    }
    // SAFETY: non-null and NUL-terminated by the caller's contract.
    Some(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
}

/// A live instance of a loaded FMU (freed on drop).
pub struct Instance<'a> {
    lib: &'a FmuLibrary,
    c: fmi2Component,
    log: Box<Mutex<Vec<String>>>,
    /// The logger's environment, kept alive (and at a fixed address) with the instance.
    _env: Box<LogEnv>,
}

/// A saved FMU state owned by the host (free it with [`Instance::free_state`]).
pub struct SavedState(fmi2FMUstate);

fn check(what: &str, s: fmi2Status, log: &Mutex<Vec<String>>) -> Result<(), String> {
    if s == fmi2OK {
        Ok(())
    } else {
        let last = log
            .lock()
            .ok()
            .and_then(|l| l.last().cloned())
            .unwrap_or_default();
        Err(format!("{what} returned status {s}: {last}"))
    }
}

impl Instance<'_> {
    /// Messages the FMU logged so far.
    pub fn messages(&self) -> Vec<String> {
        self.log.lock().map(|l| l.clone()).unwrap_or_default()
    }

    /// fmi2SetupExperiment.
    pub fn setup(&self, start: f64, stop: Option<f64>) -> Result<(), String> {
        // SAFETY: `c` is a live instance of `lib`.
        let s = unsafe {
            (self.lib.f.setup)(
                self.c,
                fmi2False,
                0.0,
                start,
                c_int::from(stop.is_some()),
                stop.unwrap_or(0.0),
            )
        };
        check("fmi2SetupExperiment", s, &self.log)
    }

    fn plain(&self, what: &str, f: Plain) -> Result<(), String> {
        // SAFETY: `c` is a live instance of `lib`.
        check(what, unsafe { f(self.c) }, &self.log)
    }

    /// fmi2EnterInitializationMode.
    pub fn enter_init(&self) -> Result<(), String> {
        self.plain("fmi2EnterInitializationMode", self.lib.f.enter_init)
    }

    /// fmi2ExitInitializationMode.
    pub fn exit_init(&self) -> Result<(), String> {
        self.plain("fmi2ExitInitializationMode", self.lib.f.exit_init)
    }

    /// fmi2SetupExperiment, fmi2EnterInitializationMode and fmi2ExitInitializationMode
    /// in turn: the usual way to a stepping instance, stopping at the first refusal.
    pub fn initialise(&self, start: f64, stop: Option<f64>) -> Result<(), String> {
        self.setup(start, stop)?;
        self.enter_init()?;
        self.exit_init()
    }

    /// fmi2Terminate.
    pub fn terminate(&self) -> Result<(), String> {
        self.plain("fmi2Terminate", self.lib.f.terminate)
    }

    /// fmi2Reset.
    pub fn reset(&self) -> Result<(), String> {
        self.plain("fmi2Reset", self.lib.f.reset)
    }

    /// fmi2SetReal.
    pub fn set_real(&self, vrs: &[u32], vals: &[f64]) -> Result<(), String> {
        assert_eq!(vrs.len(), vals.len(), "one value per value reference");
        // SAFETY: arrays of `vrs.len()` elements for the call.
        check(
            "fmi2SetReal",
            unsafe { (self.lib.f.set_real)(self.c, vrs.as_ptr(), vrs.len(), vals.as_ptr()) },
            &self.log,
        )
    }

    /// fmi2SetInteger.
    pub fn set_integer(&self, vrs: &[u32], vals: &[i32]) -> Result<(), String> {
        assert_eq!(vrs.len(), vals.len(), "one value per value reference");
        // SAFETY: arrays of `vrs.len()` elements for the call.
        check(
            "fmi2SetInteger",
            unsafe { (self.lib.f.set_integer)(self.c, vrs.as_ptr(), vrs.len(), vals.as_ptr()) },
            &self.log,
        )
    }

    /// fmi2GetReal into `out` (same length as `vrs`).
    pub fn get_real(&self, vrs: &[u32], out: &mut [f64]) -> Result<(), String> {
        assert_eq!(vrs.len(), out.len(), "one slot per value reference");
        // SAFETY: arrays of `vrs.len()` elements for the call, `out` writable.
        check(
            "fmi2GetReal",
            unsafe { (self.lib.f.get_real)(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) },
            &self.log,
        )
    }

    /// fmi2DoStep.
    pub fn do_step(&self, t: f64, h: f64) -> Result<(), String> {
        // SAFETY: `c` is a live instance.
        check(
            "fmi2DoStep",
            unsafe { (self.lib.f.do_step)(self.c, t, h, fmi2True) },
            &self.log,
        )
    }

    /// fmi2SetRealInputDerivatives (order 1 for each).
    pub fn set_input_rates(&self, vrs: &[u32], rates: &[f64]) -> Result<(), String> {
        let orders = vec![1; vrs.len()];
        // SAFETY: arrays of `vrs.len()` elements for the call.
        check(
            "fmi2SetRealInputDerivatives",
            unsafe {
                (self.lib.f.set_input_derivatives)(
                    self.c,
                    vrs.as_ptr(),
                    vrs.len(),
                    orders.as_ptr(),
                    rates.as_ptr(),
                )
            },
            &self.log,
        )
    }

    /// fmi2GetRealOutputDerivatives of one order for each of `vrs`.
    pub fn output_derivatives(
        &self,
        vrs: &[u32],
        order: i32,
        out: &mut [f64],
    ) -> Result<(), String> {
        let orders = vec![order; vrs.len()];
        // SAFETY: arrays of `vrs.len()` elements, `out` writable.
        check(
            "fmi2GetRealOutputDerivatives",
            unsafe {
                (self.lib.f.get_output_derivatives)(
                    self.c,
                    vrs.as_ptr(),
                    vrs.len(),
                    orders.as_ptr(),
                    out.as_mut_ptr(),
                )
            },
            &self.log,
        )
    }

    /// fmi2GetFMUstate (a new state).
    pub fn get_state(&self) -> Result<SavedState, String> {
        let mut s: fmi2FMUstate = std::ptr::null_mut();
        check(
            "fmi2GetFMUstate",
            // SAFETY: `s` is a writable NULL handle.
            unsafe { (self.lib.f.get_state)(self.c, &mut s) },
            &self.log,
        )?;
        Ok(SavedState(s))
    }

    /// fmi2SetFMUstate.
    pub fn set_state(&self, s: &SavedState) -> Result<(), String> {
        // SAFETY: `s` is a live state of this library.
        check(
            "fmi2SetFMUstate",
            unsafe { (self.lib.f.set_state)(self.c, s.0) },
            &self.log,
        )
    }

    /// fmi2FreeFMUstate.
    pub fn free_state(&self, mut s: SavedState) -> Result<(), String> {
        // SAFETY: `s.0` is a live state of this library, freed once.
        check(
            "fmi2FreeFMUstate",
            unsafe { (self.lib.f.free_state)(self.c, &mut s.0) },
            &self.log,
        )
    }

    /// fmi2SerializedFMUstateSize + fmi2SerializeFMUstate.
    pub fn serialize(&self, s: &SavedState) -> Result<Vec<u8>, String> {
        let mut n = 0usize;
        check(
            "fmi2SerializedFMUstateSize",
            // SAFETY: `s` is live, `n` writable.
            unsafe { (self.lib.f.state_size)(self.c, s.0, &mut n) },
            &self.log,
        )?;
        let mut buf = vec![0u8; n];
        check(
            "fmi2SerializeFMUstate",
            // SAFETY: `buf` holds `n` writable bytes.
            unsafe { (self.lib.f.serialize)(self.c, s.0, buf.as_mut_ptr().cast(), n) },
            &self.log,
        )?;
        Ok(buf)
    }

    /// fmi2DeSerializeFMUstate into a new state.
    pub fn deserialize(&self, bytes: &[u8]) -> Result<SavedState, String> {
        let mut s: fmi2FMUstate = std::ptr::null_mut();
        check(
            "fmi2DeSerializeFMUstate",
            // SAFETY: `bytes` for the call, `s` a writable NULL handle.
            unsafe { (self.lib.f.deserialize)(self.c, bytes.as_ptr().cast(), bytes.len(), &mut s) },
            &self.log,
        )?;
        Ok(SavedState(s))
    }
}

impl Drop for Instance<'_> {
    fn drop(&mut self) {
        // SAFETY: a live instance, freed once.
        unsafe { (self.lib.f.free)(self.c) };
    }
}

/// The path of a binary of this workspace (`name`, e.g. `"fxbody"`) for a test or a
/// bench: in the profile folder of the running executable (`target/release/deps/x` ->
/// `target/release/fxbody`). `cargo build` at the workspace root builds it (crates/cli is a
/// default member), and so does `cargo test` (the cli package has an integration test);
/// `CARGO_BIN_EXE_*` covers only a package's own binaries, and the command lives in the
/// cli package.
pub fn workspace_binary(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("the running test knows its own path");
    let mut dir = exe
        .parent()
        .expect("an executable lies in a folder")
        .to_path_buf();
    if dir.ends_with("deps") {
        dir.pop();
    }
    let path = dir.join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
    assert!(
        path.is_file(),
        "{} is missing: build the workspace first (cargo build --release)",
        path.display()
    );
    path
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_c_logger_formats_printf_style_and_hands_the_text_to_the_log() {
        let log: Mutex<Vec<String>> = Mutex::new(Vec::new());
        let env = LogEnv {
            sink,
            data: (&log as *const Mutex<Vec<String>>).cast_mut().cast(),
        };
        let env_ptr = (&env as *const LogEnv).cast_mut().cast();
        // SAFETY: a valid environment for the call and NUL-terminated strings; the
        // variadic arguments match the format (%s: char*, %d: int, %.3f: double).
        unsafe {
            fxbody_host_logger(
                env_ptr,
                c"inst".as_ptr(),
                fmi2OK,
                c"logStatusError".as_ptr(),
                c"%s: %d of %.3f (100%%)".as_ptr(),
                c"steps".as_ptr(),
                7 as c_int,
                2.5f64,
            );
        }
        // A message longer than any fixed buffer comes through whole.
        let long = c_text(&"x".repeat(5000));
        // SAFETY: as above; one char* argument for "%s".
        unsafe {
            fxbody_host_logger(
                env_ptr,
                c"inst".as_ptr(),
                fmi2OK,
                c"cat".as_ptr(),
                c"%s".as_ptr(),
                long.as_ptr(),
            );
        }
        let l = log.lock().unwrap();
        assert_eq!(l[0], "[logStatusError] steps: 7 of 2.500 (100%)");
        assert_eq!(l[1].len(), "[cat] ".len() + 5000);
    }
}
