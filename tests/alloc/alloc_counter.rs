//! One counting global allocator for the test binary that checks heap use (no
//! allocation in a step; heap bounded by the input's size). tests/alloc/main.rs installs
//! it with
//!
//! ```ignore
//! mod alloc_counter;
//! #[global_allocator]
//! static GLOBAL: alloc_counter::Counting = alloc_counter::Counting;
//! ```
//!
//! Everything is counted per thread: allocation calls, and live and peak bytes (bytes the
//! thread allocated minus bytes it freed). libtest runs each test on a thread of its own,
//! so tests running in parallel do not see each other's allocations, and a test measures
//! the work it runs on its own thread (the reader and the solvers start no threads).

// A counting global allocator implements `GlobalAlloc`, an unsafe trait; the workspace
// denies `unsafe_code` outside the FMI boundary, so this module says so.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The counting allocator: the system allocator plus counters.
pub struct Counting;

// Const-initialised Cells have no destructor, so these work on any thread at any time.
// Live bytes are signed: a thread may free what another allocated.
thread_local! {
    static CALLS: Cell<usize> = const { Cell::new(0) };
    static LIVE: Cell<isize> = const { Cell::new(0) };
    static PEAK: Cell<isize> = const { Cell::new(0) };
    static BASE: Cell<isize> = const { Cell::new(0) };
}

fn count_call() {
    let _ = CALLS.try_with(|c| c.set(c.get() + 1));
}

fn add_live(bytes: usize) {
    let _ = LIVE.try_with(|live| {
        let now = live.get() + bytes as isize;
        live.set(now);
        let _ = PEAK.try_with(|peak| peak.set(peak.get().max(now)));
    });
}

fn sub_live(bytes: usize) {
    let _ = LIVE.try_with(|live| live.set(live.get() - bytes as isize));
}

// SAFETY: every call is passed unchanged to the system allocator, which upholds the
// GlobalAlloc contract; the only additions are counter updates, which do not allocate.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count_call();
        add_live(layout.size());
        // SAFETY: same layout contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        sub_live(layout.size());
        // SAFETY: `ptr` was allocated by System with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count_call();
        add_live(new_size);
        // SAFETY: `ptr` was allocated by System with this layout; same contract.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        let freed = if p.is_null() { new_size } else { layout.size() };
        sub_live(freed);
        p
    }
}

/// Allocation calls (alloc and realloc) made by the calling thread so far.
pub fn allocations() -> usize {
    CALLS.with(Cell::get)
}

/// Start a peak measurement on the calling thread (the bytes live on it now are the base).
pub fn reset_peak() {
    let base = LIVE.with(Cell::get);
    BASE.with(|b| b.set(base));
    PEAK.with(|peak| peak.set(base));
}

/// The most bytes live on the calling thread since its last [`reset_peak`], above what
/// was live then.
pub fn peak_bytes() -> usize {
    (PEAK.with(Cell::get) - BASE.with(Cell::get)) as usize
}
