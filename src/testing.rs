//! What the unit tests share: a seeded pseudo-random sequence, so that a randomised test
//! repeats exactly and needs no dependency.

/// Marsaglia's xorshift64 from `seed` (nonzero): the same numbers on every run.
pub fn xorshift(seed: u64) -> impl FnMut() -> u64 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    }
}
