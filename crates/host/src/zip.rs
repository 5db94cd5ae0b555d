//! Reading a `.fmu` archive (as `fxbody pack` writes it: stored members) through the `zip`
//! crate, which checks every member's CRC-32 as it reads it, with its own implementation
//! (not the packer's), so a wrong checksum on the writing side is caught.

use std::io::{Cursor, Read};

/// Read back an archive of stored members (what `fxbody pack` writes): `(name, data)`
/// in order, with every CRC checked. Used by the tests and by `demo` to unpack an FMU.
pub fn read(bytes: &[u8]) -> Result<Vec<(String, Vec<u8>)>, String> {
    let mut archive = zip::ZipArchive::new(Cursor::new(bytes)).map_err(|e| format!("zip: {e}"))?;
    let mut out = Vec::with_capacity(archive.len());
    for k in 0..archive.len() {
        let mut member = archive
            .by_index(k)
            .map_err(|e| format!("zip: member {k}: {e}"))?;
        let name = member
            .name()
            .map_err(|e| format!("zip: member {k}: {e}"))?
            .into_owned();
        if member.compression() != zip::CompressionMethod::Stored {
            return Err(format!(
                "zip: {name} is compressed ({}); only stored members are read",
                member.compression()
            ));
        }
        let mut data = Vec::with_capacity(usize::try_from(member.size()).unwrap_or(0));
        member
            .read_to_end(&mut data)
            .map_err(|e| format!("zip: {name}: {e}"))?;
        out.push((name, data));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    /// An archive of two stored members, written by the `zip` crate's writer.
    fn archive(members: &[(&str, &[u8])]) -> Vec<u8> {
        let mut w = zip::ZipWriter::new(Cursor::new(Vec::new()));
        let opts = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored);
        for (name, data) in members {
            w.start_file(*name, opts).unwrap();
            w.write_all(data).unwrap();
        }
        w.finish().unwrap().into_inner()
    }

    #[test]
    fn stored_members_read_back_in_order_and_a_bad_crc_is_refused() {
        let members: [(&str, &[u8]); 2] = [("a.txt", b"hello"), ("b/c.bin", &[0, 1, 2, 255])];
        let mut z = archive(&members);
        let want: Vec<(String, Vec<u8>)> = members
            .iter()
            .map(|(n, d)| (n.to_string(), d.to_vec()))
            .collect();
        assert_eq!(read(&z).unwrap(), want);
        // Damage one byte of "hello" (its CRC stays): the read must fail on a.txt.
        let at = z.windows(5).position(|w| w == b"hello").unwrap();
        z[at + 4] = b'O';
        let e = read(&z).unwrap_err();
        assert!(
            e.contains("a.txt") && e.to_lowercase().contains("checksum"),
            "{e}"
        );
    }
}
