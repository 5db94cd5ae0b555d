//! Reading a store-only zip archive (a `.fmu` as `fxbody pack` writes it), with every
//! member's CRC-32 checked by an implementation of its own (not the packer's), so a
//! wrong checksum on the writing side is caught.

/// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320), bit by bit.
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

/// Read back a store-only archive of stored members (what `fxbody pack` writes): `(name, data)` in order, with every CRC checked. Used by the tests and by
/// `demo` to unpack an FMU without a zip crate.
pub fn read(bytes: &[u8]) -> Result<Vec<(String, Vec<u8>)>, String> {
    let u16_at = |p: usize| -> Result<u16, String> {
        bytes
            .get(p..p + 2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
            .ok_or("zip: truncated".to_string())
    };
    let u32_at = |p: usize| -> Result<u32, String> {
        bytes
            .get(p..p + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or("zip: truncated".to_string())
    };
    let mut out = Vec::new();
    let mut p = 0;
    while u32_at(p).is_ok_and(|sig| sig == 0x0403_4b50) {
        let method = u16_at(p + 8)?;
        let crc = u32_at(p + 14)?;
        let size = u32_at(p + 18)? as usize;
        let nlen = u16_at(p + 26)? as usize;
        let xlen = u16_at(p + 28)? as usize;
        if method != 0 {
            return Err(format!(
                "zip: member at offset {p} is compressed (method {method}); only stored members are read"
            ));
        }
        let name = bytes
            .get(p + 30..p + 30 + nlen)
            .ok_or("zip: truncated name")?;
        let start = p + 30 + nlen + xlen;
        let data = bytes
            .get(start..start + size)
            .ok_or("zip: truncated data")?;
        let name = String::from_utf8_lossy(name).into_owned();
        if crc32(data) != crc {
            return Err(format!("zip: CRC mismatch in {name}"));
        }
        out.push((name, data.to_vec()));
        p = start + size;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc32_of_the_standard_check_string() {
        // The check value of CRC-32/ISO-HDLC for "123456789".
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }

    #[test]
    fn a_hand_built_stored_member_reads_back_and_a_bad_crc_is_refused() {
        let data = b"hello";
        let mut z = Vec::new();
        z.extend_from_slice(&0x0403_4b50u32.to_le_bytes());
        z.extend_from_slice(&[20, 0, 0, 0, 0, 0, 0, 0, 0, 0]);
        z.extend_from_slice(&crc32(data).to_le_bytes());
        z.extend_from_slice(&5u32.to_le_bytes());
        z.extend_from_slice(&5u32.to_le_bytes());
        z.extend_from_slice(&5u16.to_le_bytes());
        z.extend_from_slice(&0u16.to_le_bytes());
        z.extend_from_slice(b"a.txt");
        z.extend_from_slice(data);
        assert_eq!(
            read(&z).unwrap(),
            vec![("a.txt".to_string(), data.to_vec())]
        );
        let n = z.len();
        z[n - 1] = b'O';
        assert!(read(&z).unwrap_err().contains("CRC mismatch in a.txt"));
    }
}
