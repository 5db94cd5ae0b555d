//! A header that claims a billion nodes must fail before anything in proportion to the
//! claim is allocated. This binary counts the bytes live on the heap (its only test, so
//! no other test allocates meanwhile).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator unchanged; only counts sizes.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let live = LIVE.fetch_add(layout.size(), Ordering::SeqCst) + layout.size();
        PEAK.fetch_max(live, Ordering::SeqCst);
        // SAFETY: same layout contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::SeqCst);
        // SAFETY: ptr was allocated by System with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

#[test]
fn billion_node_header_allocates_nothing_in_proportion() {
    let mut text = String::from("       0       0 1000000000       0       0       1       0\n");
    text.push_str(
        "       1       2       3       4       5       6       7       8       9      10\n",
    );
    while text.len() < 300 {
        text.push_str(" 1.000000000E+00\n");
    }
    let text = text.into_bytes();
    let base = LIVE.load(Ordering::SeqCst);
    PEAK.store(base, Ordering::SeqCst);
    let result = fxbody::fxb::parse(&text, "big.fxb");
    let peak = PEAK.load(Ordering::SeqCst) - base;
    let msg = result.expect_err("must be refused").to_string();
    assert!(
        msg.contains("Nbnod = 1000000000") && msg.contains("big.fxb:1:"),
        "{msg}"
    );
    // A few kilobytes for the message and line buffers; 1e9 nodes would need 8 GB.
    assert!(peak < 16 * 1024, "peak heap use {peak} bytes");
}
