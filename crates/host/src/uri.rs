//! The resource location an importer passes to fmi2Instantiate: a `file:` URI of the
//! unpacked FMU's `resources` folder. (The FMU's side, decoding it, is the product's
//! `fmi::uri`.)

use std::path::Path;

/// The `file:` URI of a folder, percent-encoding every byte outside the unreserved set
/// (so spaces and non-ASCII names survive): `file:///tmp/x` on Unix.
#[cfg(not(windows))]
pub fn file_uri(dir: &Path) -> String {
    let segments: Vec<&[u8]> = dir
        .as_os_str()
        .as_encoded_bytes()
        .split(|&b| b == b'/')
        .collect();
    uri_from_parts(None, &segments)
}

/// The `file:` URI of a folder on Windows: the drive letter and the components, joined
/// by `/` whatever the separator was (`C:\a b\c` -> `file:///C:/a%20b/c`). A UNC path
/// (`\\server\share`) has no drive letter and is not supported by this test host.
#[cfg(windows)]
pub fn file_uri(dir: &Path) -> String {
    use std::path::{Component, Prefix};
    let mut drive = None;
    let mut segments: Vec<&[u8]> = Vec::new();
    for c in dir.components() {
        match c {
            Component::Prefix(p) => {
                if let Prefix::Disk(d) | Prefix::VerbatimDisk(d) = p.kind() {
                    drive = Some(char::from(d));
                }
            }
            Component::RootDir => segments.push(b""),
            other => segments.push(other.as_os_str().as_encoded_bytes()),
        }
    }
    uri_from_parts(drive, &segments)
}

/// The `file:` URI of a path given as its parts, the platform-free half of
/// [`file_uri`]: an optional drive letter and the path's segments (bytes, the first
/// empty for an absolute path), each percent-encoded and joined by `/`.
pub fn uri_from_parts(drive: Option<char>, segments: &[&[u8]]) -> String {
    let mut s = String::from("file://");
    if let Some(d) = drive {
        s.push('/');
        s.push(d);
        s.push(':');
    }
    for (i, seg) in segments.iter().enumerate() {
        if i > 0 {
            s.push('/');
        }
        for &b in *seg {
            if b.is_ascii_alphanumeric() || b"-._~".contains(&b) {
                s.push(b as char);
            } else {
                s.push_str(&format!("%{b:02X}"));
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spaces_and_non_ascii_bytes_are_percent_encoded() {
        assert_eq!(
            file_uri(Path::new("/tmp/my dir/café")),
            "file:///tmp/my%20dir/caf%C3%A9"
        );
    }

    /// The Windows side's parts (as `file_uri` splits `C:\my dir\café` there), checked
    /// here on Linux against RFC 8089's form `file:///C:/...`.
    #[test]
    fn a_drive_letter_makes_a_three_slash_uri() {
        let segs: [&[u8]; 3] = [b"", b"my dir", "café".as_bytes()];
        assert_eq!(
            uri_from_parts(Some('C'), &segs),
            "file:///C:/my%20dir/caf%C3%A9"
        );
        // A backslash left inside a segment is data, not a separator.
        assert_eq!(
            uri_from_parts(Some('D'), &[b"", b"a\\b"]),
            "file:///D:/a%5Cb"
        );
    }
}
