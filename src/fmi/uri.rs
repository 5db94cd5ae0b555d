//! fmuResourceLocation: a `file` URI to a local folder. Accepted forms: `file:///abs`,
//! `file://localhost/abs`, `file:/abs`, with or without a trailing slash, percent-encoded
//! (`%20` is a space), and on Windows `file:///C:/dir`; a bare absolute path is accepted
//! too, as some masters pass one.
//!
//! Parsed here rather than with the `url` crate: `url` brings Unicode domain-name tables
//! (ICU) into the FMU's library, 200 kB more in every FMU (1.48 MB -> 1.68 MB, measured),
//! for the few lines a local `file` URI needs. The one platform-specific step, decoded
//! bytes to a path, is behind `cfg` with both sides written ([`to_path`]).

use std::path::PathBuf;

/// A resource location that does not name a local folder; each names the location.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum UriError {
    /// A `file://host/` URI with a host other than localhost.
    #[error(
        "resource location '{uri}': host '{host}' is not local (expected file:///path or file://localhost/path)"
    )]
    NotLocal {
        /// The location.
        uri: String,
        /// The host.
        host: String,
    },
    /// Neither a file URI nor an absolute path.
    #[error("resource location '{0}' is not a file URI (expected file:///absolute/path)")]
    NotFile(String),
    /// A file URI whose path is not absolute.
    #[error("resource location '{0}' does not name an absolute path")]
    NotAbsolute(String),
    /// A `%` not followed by two hex digits.
    #[error(
        "resource location '{uri}': bad percent escape at byte {at}: expected %XX with two hex digits"
    )]
    BadEscape {
        /// The location.
        uri: String,
        /// The byte offset of the `%` in the path.
        at: usize,
    },
    /// `%00` in the path.
    #[error("resource location '{0}' decodes to a path with a NUL byte")]
    Nul(String),
    /// A path that is not UTF-8, where paths are Unicode (Windows).
    #[error("resource location '{0}' decodes to bytes that are not UTF-8")]
    NotUtf8(String),
}

/// The path of decoded URI bytes: on Unix a path is bytes, taken as they are.
#[cfg(unix)]
fn to_path(bytes: Vec<u8>) -> Option<PathBuf> {
    use std::os::unix::ffi::OsStringExt;
    Some(PathBuf::from(std::ffi::OsString::from_vec(bytes)))
}

/// The path of decoded URI bytes where paths are Unicode: UTF-8 text (`None` otherwise),
/// and `/C:/dir` (a drive letter after the URI's root) is `C:/dir`.
#[cfg(not(unix))]
fn to_path(bytes: Vec<u8>) -> Option<PathBuf> {
    let text = String::from_utf8(bytes).ok()?;
    let b = text.as_bytes();
    let drive = b.len() >= 3 && b[0] == b'/' && b[1].is_ascii_alphabetic() && b[2] == b':';
    Some(PathBuf::from(if drive { &text[1..] } else { &text[..] }))
}

/// The local folder a resource URI names.
pub fn resource_path(uri: &str) -> Result<PathBuf, UriError> {
    let path = if let Some(rest) = strip_prefix_ignore_case(uri, "file:") {
        if let Some(after) = rest.strip_prefix("//") {
            // Authority: empty or localhost.
            let (host, p) = match after.find('/') {
                Some(k) => (&after[..k], &after[k..]),
                None => (after, ""),
            };
            if !(host.is_empty() || host.eq_ignore_ascii_case("localhost")) {
                return Err(UriError::NotLocal {
                    uri: uri.to_string(),
                    host: host.to_string(),
                });
            }
            p
        } else {
            rest
        }
    } else if uri.starts_with('/') {
        uri
    } else {
        return Err(UriError::NotFile(uri.to_string()));
    };
    // Query or fragment parts have no meaning for a folder.
    let path = path.split(['?', '#']).next().unwrap_or("");
    if !path.starts_with('/') {
        return Err(UriError::NotAbsolute(uri.to_string()));
    }
    let bytes = percent_decode(path).map_err(|at| UriError::BadEscape {
        uri: uri.to_string(),
        at,
    })?;
    if bytes.contains(&0) {
        return Err(UriError::Nul(uri.to_string()));
    }
    let mut p = to_path(bytes).ok_or_else(|| UriError::NotUtf8(uri.to_string()))?;
    // PathBuf ignores a trailing slash in joins already; normalise it for messages.
    if p.as_os_str().len() > 1 && p.as_os_str().as_encoded_bytes().ends_with(b"/") {
        p = p.components().collect();
    }
    Ok(p)
}

fn strip_prefix_ignore_case<'a>(s: &'a str, prefix: &str) -> Option<&'a str> {
    (s.len() >= prefix.len()
        && s.as_bytes()[..prefix.len()].eq_ignore_ascii_case(prefix.as_bytes()))
    .then(|| &s[prefix.len()..])
}

/// The bytes `s` encodes; `Err(k)`: the `%` at byte `k` has no two hex digits after it.
fn percent_decode(s: &str) -> Result<Vec<u8>, usize> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut k = 0;
    while k < b.len() {
        if b[k] == b'%' {
            let hex = |c: u8| (c as char).to_digit(16);
            match (
                b.get(k + 1).copied().and_then(hex),
                b.get(k + 2).copied().and_then(hex),
            ) {
                (Some(h), Some(l)) => out.push((h * 16 + l) as u8),
                _ => {
                    return Err(k);
                }
            }
            k += 3;
        } else {
            out.push(b[k]);
            k += 1;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_common_forms_decode_to_the_same_folder() {
        let want = PathBuf::from("/tmp/my dir/res");
        for uri in [
            "file:///tmp/my%20dir/res",
            "file:///tmp/my%20dir/res/",
            "file://localhost/tmp/my%20dir/res",
            "FILE:/tmp/my%20dir/res",
            "file:/tmp/my dir/res/",
            "/tmp/my dir/res",
        ] {
            assert_eq!(resource_path(uri).unwrap(), want, "{uri}");
        }
        // UTF-8 percent-encoded: e-acute is C3 A9.
        assert_eq!(
            resource_path("file:///a/caf%C3%A9").unwrap(),
            PathBuf::from("/a/café")
        );
    }

    /// A drive-letter URI is a Windows path (built and run on Windows only: this
    /// repository's CI is linux64, README "Platforms").
    #[cfg(windows)]
    #[test]
    fn a_drive_letter_uri_is_a_windows_path() {
        assert_eq!(
            resource_path("file:///C:/my%20dir/res").unwrap(),
            PathBuf::from(r"C:/my dir/res")
        );
    }

    #[test]
    fn bad_uris_are_refused_with_a_reason() {
        assert!(
            resource_path("file://server/share")
                .unwrap_err()
                .to_string()
                .contains("not local")
        );
        assert!(
            resource_path("file:///a%2")
                .unwrap_err()
                .to_string()
                .contains("percent")
        );
        assert!(
            resource_path("file:///a%zz")
                .unwrap_err()
                .to_string()
                .contains("percent")
        );
        assert!(
            resource_path("http://x/y")
                .unwrap_err()
                .to_string()
                .contains("not a file URI")
        );
        assert!(
            resource_path("file:relative/x")
                .unwrap_err()
                .to_string()
                .contains("absolute")
        );
        assert!(
            resource_path("file:///a%00b")
                .unwrap_err()
                .to_string()
                .contains("NUL")
        );
    }
}
