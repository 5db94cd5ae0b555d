//! One counting global allocator for the test binaries that check heap use (no
//! allocation in a step; heap bounded by the input's size). A binary installs it with
//!
//! ```ignore
//! mod alloc_counter;
//! #[global_allocator]
//! static GLOBAL: alloc_counter::Counting = alloc_counter::Counting;
//! ```
//!
//! It counts allocation calls per thread (so tests running in parallel threads do not
//! see each other's allocations) and live and peak bytes for the whole process.

// A counting global allocator implements `GlobalAlloc`, an unsafe trait; the workspace
// denies `unsafe_code` outside the FMI boundary, so this module says so.
#![allow(unsafe_code)]
#![allow(dead_code)] // each binary uses the part it needs

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The counting allocator: the system allocator plus counters.
pub struct Counting;

thread_local! {
    static CALLS: Cell<usize> = const { Cell::new(0) };
}

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn count_call() {
    // A const-initialised Cell has no destructor, so this works on any thread at any time.
    let _ = CALLS.try_with(|c| c.set(c.get() + 1));
}

fn add_live(bytes: usize) {
    let live = LIVE.fetch_add(bytes, Ordering::SeqCst) + bytes;
    PEAK.fetch_max(live, Ordering::SeqCst);
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
        LIVE.fetch_sub(layout.size(), Ordering::SeqCst);
        // SAFETY: `ptr` was allocated by System with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count_call();
        add_live(new_size);
        // SAFETY: `ptr` was allocated by System with this layout; same contract.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        let freed = if p.is_null() { new_size } else { layout.size() };
        LIVE.fetch_sub(freed, Ordering::SeqCst);
        p
    }
}

/// Allocation calls (alloc and realloc) made by the calling thread so far.
pub fn allocations() -> usize {
    CALLS.with(Cell::get)
}

/// Start a peak measurement: the peak is reset to the bytes live now, which are returned.
pub fn reset_peak() -> usize {
    let base = LIVE.load(Ordering::SeqCst);
    PEAK.store(base, Ordering::SeqCst);
    base
}

/// Largest number of live bytes since the last [`reset_peak`].
pub fn peak_bytes() -> usize {
    PEAK.load(Ordering::SeqCst)
}
