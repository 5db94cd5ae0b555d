//! Reading an input file safely: only regular files, never more bytes than the file can
//! need, and a compressed archive named as such instead of parsed as text. Every command
//! opens its `.fxb` through [`open_fxb`] (or reads it whole through [`read_fxb_bytes`])
//! and its coordinate file through [`read_regular`], so `fxbody info /dev/zero` is
//! refused at once instead of growing without bound.

use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

/// Bytes read before the header is looked at (enough for any comments before it).
const PREFIX: u64 = 64 * 1024;

/// Bytes allowed per value the header calls for: a value takes at most 16 columns of an
/// 80-column line plus its share of the line end; four times that leaves room for
/// comments and free-format spacing.
const BYTES_PER_VALUE: u128 = 80;

/// Allowance on top of the per-value bound (comments, blank lines, the header itself).
const SLACK: u128 = 16 * 1024 * 1024;

fn refused(why: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, why)
}

/// What kind of non-regular file `meta` describes, for messages.
fn kind(meta: &std::fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = meta.file_type();
    if t.is_dir() {
        "a directory"
    } else if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

/// The size of `path`, refusing anything but a regular file (following links) before
/// opening it: a device or FIFO would be read without end.
pub fn regular_size(path: &Path) -> io::Result<u64> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(refused(format!(
            "expected a regular file, found {}",
            kind(&meta)
        )));
    }
    Ok(meta.len())
}

/// The archive format whose magic number `bytes` start with, if any.
pub fn compressed_kind(bytes: &[u8]) -> Option<&'static str> {
    if bytes.starts_with(b"\x1f\x8b") {
        Some("a gzip-compressed file: decompress it first (gunzip)")
    } else if bytes.starts_with(b"PK\x03\x04") || bytes.starts_with(b"PK\x05\x06") {
        Some("a zip archive (an FMU?): extract the file from it first")
    } else if bytes.starts_with(b"\x28\xb5\x2f\xfd") {
        Some("a zstd-compressed file: decompress it first")
    } else if bytes.starts_with(b"BZh") {
        Some("a bzip2-compressed file: decompress it first")
    } else if bytes.starts_with(b"\xfd7zXZ\x00") {
        Some("an xz-compressed file: decompress it first")
    } else {
        None
    }
}

/// Read a whole regular file (refusing devices, FIFOs, directories and compressed
/// files).
pub fn read_regular(path: &Path) -> io::Result<Vec<u8>> {
    let size = regular_size(path)?;
    let mut bytes = Vec::with_capacity(size.min(1 << 30) as usize);
    File::open(path)?.take(size).read_to_end(&mut bytes)?;
    if let Some(what) = compressed_kind(&bytes) {
        return Err(refused(format!("this is {what}")));
    }
    Ok(bytes)
}

/// The most bytes a `.fxb` file with this 7-integer header can sensibly need:
/// [`BYTES_PER_VALUE`] per value the counts call for, plus [`SLACK`].
pub fn size_bound(header: &[i64; 7]) -> u128 {
    let [nl, _ns, n, irot, _idamp, _iblo, _ifile] = header.map(|v| v.max(0) as u128);
    let nr = if irot > 0 { 15 } else { 12 };
    let values = n                      // node IDs
        + 12                            // P0, Freq, damping
        + (nr + nl) * 6 * n             // rigid and local modes
        + nl                            // m_L
        + nl * (nl + 1) / 2             // K_L at most full
        + nr * (nr + 1) / 2             // M_R
        + 18 * nr * nl; // M_C, K_C
    values.saturating_mul(BYTES_PER_VALUE).saturating_add(SLACK)
}

/// The header as blank-separated integers on the first line that is not a comment or
/// blank; `None` when it does not read so (the parser then reports it).
fn header_of(prefix: &[u8]) -> Option<[i64; 7]> {
    let line = prefix
        .split(|&b| b == b'\n')
        .map(|l| l.strip_suffix(b"\r").unwrap_or(l))
        .find(|l| {
            !(l.starts_with(b"#") || l.starts_with(b"$") || l.iter().all(u8::is_ascii_whitespace))
        })?;
    let text = std::str::from_utf8(line).ok()?;
    let v: Vec<i64> = text
        .split_ascii_whitespace()
        .map(|t| t.parse().ok())
        .collect::<Option<_>>()?;
    v.try_into().ok()
}

/// A `.fxb` file opened for reading, checked as [`open_fxb`] says.
pub struct FxbInput {
    /// The first bytes of the file, already read (up to 64 KiB).
    pub prefix: Vec<u8>,
    /// The rest of the file.
    pub rest: std::io::Take<File>,
    /// The file's size in bytes.
    pub size: u64,
}

/// Open a `.fxb` file: a regular file, not compressed, and no larger than its header
/// counts can need ([`size_bound`]); refused before it is read whole otherwise. Its first
/// bytes are read to check this; the rest is left to the caller.
pub fn open_fxb(path: &Path) -> io::Result<FxbInput> {
    let size = regular_size(path)?;
    let mut file = File::open(path)?;
    let mut prefix = Vec::new();
    (&mut file)
        .take(PREFIX.min(size))
        .read_to_end(&mut prefix)?;
    if let Some(what) = compressed_kind(&prefix) {
        return Err(refused(format!("this is {what}")));
    }
    if let Some(h) = header_of(&prefix) {
        let bound = size_bound(&h);
        if u128::from(size) > bound {
            return Err(refused(format!(
                "the file has {size} bytes, more than the {bound} bytes its header (Nbmod {} Nbstat {} Nbnod {} Irot {}) can need: is it the right file?",
                h[0], h[1], h[2], h[3]
            )));
        }
    }
    let rest = file.take(size - prefix.len() as u64);
    Ok(FxbInput { prefix, rest, size })
}

/// Read a `.fxb` file whole, checked as [`open_fxb`] says.
pub fn read_fxb_bytes(path: &Path) -> io::Result<Vec<u8>> {
    let FxbInput {
        mut prefix,
        mut rest,
        size,
    } = open_fxb(path)?;
    // Reserved at once: growing by doubling would copy and touch the bytes again.
    prefix.reserve_exact((size as usize).saturating_sub(prefix.len()));
    rest.read_to_end(&mut prefix)?;
    Ok(prefix)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_and_bound() {
        let h = header_of(b"# c\n$ d\n\n   2 1  3 0 1 1 0\n1 2\n").unwrap();
        assert_eq!(h, [2, 1, 3, 0, 1, 1, 0]);
        // 3 ids + 12 + 14*6*3 modes + 2 + 3 + 78 + 18*12*2 = 782 values.
        assert_eq!(size_bound(&h), 782 * 80 + 16 * 1024 * 1024);
        assert!(header_of(b"abc\n").is_none());
        assert_eq!(
            compressed_kind(b"\x1f\x8b\x08"),
            compressed_kind(b"\x1f\x8b")
        );
        assert!(compressed_kind(b"PK\x03\x04").unwrap().contains("zip"));
        assert!(compressed_kind(b"    2").is_none());
    }
}
