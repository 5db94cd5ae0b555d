//! A store-only zip writer (no compression): local headers, central directory, end
//! record, CRC-32 from `crc32fast`. (Reading an archive back is the importer's job:
//! crates/host, used by the tests, reads every packed FMU and checks the CRCs.) Every entry gets the same fixed time stamp
//! (1980-01-01 00:00, the format's epoch), so equal contents give equal archives. About
//! sixty lines, which is why no zip crate is used.

/// One archive member.
pub struct Entry {
    /// Path inside the archive, `/`-separated.
    pub name: String,
    /// Contents.
    pub data: Vec<u8>,
    /// Unix mode bits (0o644, 0o755).
    pub mode: u32,
}

/// An archive the classic zip format cannot hold (no zip64 here).
#[derive(Debug, thiserror::Error)]
pub enum ZipError {
    /// One member is 4 GiB or more.
    #[error("zip: {0} is larger than 4 GiB")]
    EntryTooLarge(String),
    /// The archive is 4 GiB or more.
    #[error("zip: archive larger than 4 GiB")]
    ArchiveTooLarge,
    /// More than 65535 members.
    #[error("zip: too many entries")]
    TooManyEntries,
}

/// The archive bytes for `entries`, in the given order. Fails when an entry or the
/// archive exceeds the 4 GiB limits of the classic format.
pub fn write(entries: &[Entry]) -> Result<Vec<u8>, ZipError> {
    let mut out = Vec::new();
    let mut central = Vec::new();
    // 1980-01-01: year offset 0 (bits 9..16), month 1 (bits 5..9), day 1.
    const DOS_DATE: u16 = (1 << 5) | 1;
    const DOS_TIME: u16 = 0;
    for e in entries {
        let size =
            u32::try_from(e.data.len()).map_err(|_| ZipError::EntryTooLarge(e.name.clone()))?;
        let offset = u32::try_from(out.len()).map_err(|_| ZipError::ArchiveTooLarge)?;
        let name = e.name.as_bytes();
        let crc = crc32fast::hash(&e.data);
        // Local file header.
        out.extend_from_slice(&0x0403_4b50u32.to_le_bytes());
        out.extend_from_slice(&20u16.to_le_bytes()); // version needed
        out.extend_from_slice(&0x0800u16.to_le_bytes()); // UTF-8 names
        out.extend_from_slice(&0u16.to_le_bytes()); // stored
        out.extend_from_slice(&DOS_TIME.to_le_bytes());
        out.extend_from_slice(&DOS_DATE.to_le_bytes());
        out.extend_from_slice(&crc.to_le_bytes());
        out.extend_from_slice(&size.to_le_bytes());
        out.extend_from_slice(&size.to_le_bytes());
        out.extend_from_slice(&(name.len() as u16).to_le_bytes());
        out.extend_from_slice(&0u16.to_le_bytes());
        out.extend_from_slice(name);
        out.extend_from_slice(&e.data);
        // Central directory record.
        central.extend_from_slice(&0x0201_4b50u32.to_le_bytes());
        central.extend_from_slice(&(0x0300u16 | 20).to_le_bytes()); // made by Unix, 2.0
        central.extend_from_slice(&20u16.to_le_bytes());
        central.extend_from_slice(&0x0800u16.to_le_bytes());
        central.extend_from_slice(&0u16.to_le_bytes());
        central.extend_from_slice(&DOS_TIME.to_le_bytes());
        central.extend_from_slice(&DOS_DATE.to_le_bytes());
        central.extend_from_slice(&crc.to_le_bytes());
        central.extend_from_slice(&size.to_le_bytes());
        central.extend_from_slice(&size.to_le_bytes());
        central.extend_from_slice(&(name.len() as u16).to_le_bytes());
        central.extend_from_slice(&[0; 8]); // extra, comment, disk, internal attributes
        central.extend_from_slice(&((0o100000 | e.mode) << 16).to_le_bytes());
        central.extend_from_slice(&offset.to_le_bytes());
        central.extend_from_slice(name);
    }
    let cd_offset = u32::try_from(out.len()).map_err(|_| ZipError::ArchiveTooLarge)?;
    let count = u16::try_from(entries.len()).map_err(|_| ZipError::TooManyEntries)?;
    out.extend_from_slice(&central);
    out.extend_from_slice(&0x0605_4b50u32.to_le_bytes());
    out.extend_from_slice(&[0; 4]); // disk numbers
    out.extend_from_slice(&count.to_le_bytes());
    out.extend_from_slice(&count.to_le_bytes());
    out.extend_from_slice(&(central.len() as u32).to_le_bytes());
    out.extend_from_slice(&cd_offset.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn archive_round_trips_and_is_deterministic() {
        let entries = vec![
            Entry {
                name: "a.txt".into(),
                data: b"hello".to_vec(),
                mode: 0o644,
            },
            Entry {
                name: "d/b.bin".into(),
                data: vec![0, 1, 2, 255],
                mode: 0o755,
            },
        ];
        let z = write(&entries).unwrap();
        assert_eq!(z, write(&entries).unwrap());
        // The first member's data follows its 30-byte header and 5-byte name.
        assert_eq!(&z[35..40], b"hello");
        // End record: 2 entries, central directory right after the data.
        let n = z.len();
        assert_eq!(&z[n - 22..n - 18], &[0x50, 0x4b, 0x05, 0x06]);
        assert_eq!(u16::from_le_bytes([z[n - 12], z[n - 11]]), 2);
    }
}
