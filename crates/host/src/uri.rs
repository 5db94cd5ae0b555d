//! The resource location an importer passes to fmi2Instantiate: a `file:` URI of the
//! unpacked FMU's `resources` folder. (The FMU's side, decoding it, is the product's
//! `fmi::uri`.)

use std::path::Path;

/// The `file:` URI of a folder, percent-encoding every byte outside the unreserved set
/// and `/` (so spaces and non-ASCII names survive).
pub fn file_uri(dir: &Path) -> String {
    let mut s = String::from("file://");
    for &b in dir.as_os_str().as_encoded_bytes() {
        if b.is_ascii_alphanumeric() || b"/-._~".contains(&b) {
            s.push(b as char);
        } else {
            s.push_str(&format!("%{b:02X}"));
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
}
