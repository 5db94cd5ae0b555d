//! A header that claims a billion nodes must fail before anything in proportion to the
//! claim is allocated. The counting allocator measures the bytes live on this test's
//! thread (per-thread counts: the other tests of the binary do not disturb it).

use crate::alloc_counter;

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
    alloc_counter::reset_peak();
    let result = fxbody::fxb::parse(&text, "big.fxb");
    let peak = alloc_counter::peak_bytes();
    let msg = result.expect_err("must be refused").to_string();
    assert!(
        msg.contains("Nbnod = 1000000000") && msg.contains("big.fxb:1:"),
        "{msg}"
    );
    // A few kilobytes for the message and line buffers; 1e9 nodes would need 8 GB.
    assert!(peak < 16 * 1024, "peak heap use {peak} bytes");
}
