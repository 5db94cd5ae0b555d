//! Small checksums written here rather than pulled in as crates: FNV-1a (64 bit) for
//! the content-derived GUID and the FMU-state checksum, and its word-at-a-time form for
//! the scene file. (The zip archive's CRC-32 is `crc32fast`'s, src/fmu/zip.rs.)

/// FNV-1a 64-bit hash of `bytes`, continuing from `state` (start with [`FNV_OFFSET`]).
pub fn fnv1a64(state: u64, bytes: &[u8]) -> u64 {
    let mut h = state;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// FNV-1a 64-bit offset basis.
pub const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// FNV-1a 64 taken a 64-bit little-endian word at a time instead of a byte at a time
/// (`h = (h ^ word) * prime` from [`FNV_OFFSET`]): the scene file's payload checksum,
/// eight times fewer multiplications than [`fnv1a64`] over a megabyte of matrices.
/// Each step is a bijection of the word, so a change confined to one word always
/// changes the result. `words` must hold a whole number of words (the caller checks).
pub fn fnv1a64_words(words: &[u8]) -> u64 {
    debug_assert_eq!(words.len() % 8, 0);
    let mut h = FNV_OFFSET;
    for w in words.chunks_exact(8) {
        let mut b = [0u8; 8];
        b.copy_from_slice(w);
        h ^= u64::from_le_bytes(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// A GUID-shaped text (`{8-4-4-4-12}` hex) derived from `parts`: two FNV-1a passes
/// with different starting states give 128 bits. Same parts, same GUID.
pub fn content_guid(parts: &[&[u8]]) -> String {
    let mut a = FNV_OFFSET;
    let mut b = fnv1a64(FNV_OFFSET, b"fxbody-guid-second-lane");
    for p in parts {
        // Length prefixes keep ("ab","c") and ("a","bc") apart.
        let len = (p.len() as u64).to_le_bytes();
        a = fnv1a64(fnv1a64(a, &len), p);
        b = fnv1a64(fnv1a64(b, p), &len);
    }
    let x = format!("{a:016x}{b:016x}");
    format!(
        "{{{}-{}-{}-{}-{}}}",
        &x[0..8],
        &x[8..12],
        &x[12..16],
        &x[16..20],
        &x[20..32]
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_matches_published_vectors() {
        // Published FNV-1a 64 test vectors (Fowler/Noll/Vo): "" and "a".
        assert_eq!(fnv1a64(FNV_OFFSET, b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(FNV_OFFSET, b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64(FNV_OFFSET, b"foobar"), 0x8594_4171_f739_67e8);
    }

    /// One word is one FNV-1a step: the published byte-wise vector for "a" is the
    /// word-wise hash of the word 0x61, and every single-word change is seen.
    #[test]
    fn word_fnv_is_fnv1a_per_word() {
        assert_eq!(fnv1a64_words(b""), FNV_OFFSET);
        assert_eq!(fnv1a64_words(b"a\0\0\0\0\0\0\0"), 0xaf63_dc4c_8601_ec8c);
        let a = fnv1a64_words(&[7u8; 24]);
        for k in 0..24 {
            let mut b = [7u8; 24];
            b[k] ^= 0x80;
            assert_ne!(fnv1a64_words(&b), a, "byte {k}");
        }
    }

    #[test]
    fn guid_depends_on_every_part_and_their_boundaries() {
        let g = content_guid(&[b"ab", b"c"]);
        assert_eq!(g.len(), 38);
        assert_eq!(g, content_guid(&[b"ab", b"c"]));
        assert_ne!(g, content_guid(&[b"a", b"bc"]));
        assert_ne!(g, content_guid(&[b"ab", b"d"]));
    }
}
