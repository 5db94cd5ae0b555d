//! Reading an input file safely: only regular files, never more bytes than the file's
//! format can need, and a compressed archive named as such instead of parsed as text.
//! Every command opens its `.fxb` through [`open_fxb`] (or reads it whole through
//! [`read_fxb_bytes`]), and every other input (coordinates, node lists, FE matrices,
//! libraries) through [`read_bounded`] or [`check_input`] with the bound of its kind
//! ([`Limit`]), so `fxbody info /dev/zero`, a FIFO or a 50 GB file given by mistake is
//! refused at once instead of read without end.
//!
//! A path is checked twice: by its metadata before it is opened (a device is never
//! opened, which for some devices has effects of its own), and by the opened file's
//! metadata, opened without blocking (so a path swapped for a FIFO in between neither
//! hangs nor is read).

use std::fs::File;
use std::io::{self, Read};
use std::path::{Path, PathBuf};

/// Bytes read before the header is looked at (enough for any comments before it).
const PREFIX: u64 = 64 * 1024;

/// Bytes allowed per value the header calls for: a value takes at most 16 columns of an
/// 80-column line plus its share of the line end; four times that leaves room for
/// comments and free-format spacing.
const BYTES_PER_VALUE: u128 = 80;

/// Allowance on top of the per-value bound (comments, blank lines, the header itself).
const SLACK: u128 = 16 * 1024 * 1024;

/// The largest file of each kind of input without a header that sizes it: what a
/// command reads is refused above it, before it is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Limit {
    /// Node coordinates (a `/NODE` deck, a CSV file, GRID or `*NODE` cards):
    /// [`MAX_TEXT`]. The formats carry no count, and a deck may be a whole model's
    /// starter file.
    Coordinates,
    /// FE matrix files (DMIG, Abaqus, CalculiX `.sti`/`.mas`/`.dof`): [`MAX_TEXT`].
    Matrix,
    /// A reference the `demo` and `study` commands read (JSON or CSV): [`MAX_TEXT`].
    Reference,
    /// A node list (`--nodes-file`): [`MAX_NODE_LIST`].
    NodeList,
    /// A shared library (`--lib`, `--binary`): [`MAX_LIBRARY`].
    Library,
}

/// The largest coordinate, FE matrix or reference file read: 4 GiB, far above the
/// starter deck of a whole vehicle model (a /NODE line takes 70 bytes: 60 million nodes)
/// or a dense matrix of the import's largest size in any of its formats.
pub const MAX_TEXT: u64 = 4 << 30;

/// The largest node list read: 64 MiB, three million node IDs of 20 characters.
pub const MAX_NODE_LIST: u64 = 64 << 20;

/// The largest shared library read: 256 MiB. fxbody's own release library is about
/// 1.3 MB and a debug build about 60 MB; anything larger is not one.
pub const MAX_LIBRARY: u64 = 256 << 20;

impl Limit {
    /// The bound in bytes.
    pub fn bytes(self) -> u64 {
        match self {
            Limit::Coordinates | Limit::Matrix | Limit::Reference => MAX_TEXT,
            Limit::NodeList => MAX_NODE_LIST,
            Limit::Library => MAX_LIBRARY,
        }
    }

    /// What such a file is, for messages.
    pub fn what(self) -> &'static str {
        match self {
            Limit::Coordinates => "coordinate file",
            Limit::Matrix => "matrix file",
            Limit::Reference => "reference file",
            Limit::NodeList => "node list",
            Limit::Library => "shared library",
        }
    }
}

fn refused(why: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, why)
}

/// What kind of non-regular file `meta` describes, for messages.
fn kind(meta: &std::fs::Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        "a directory"
    } else {
        special_kind(&t)
    }
}

/// The kind of a special file, named where the platform has names for them.
#[cfg(unix)]
fn special_kind(t: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if t.is_fifo() {
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

/// The kind of a special file: std names none of them off Unix (a Windows device or
/// pipe path is refused as not a regular file).
#[cfg(not(unix))]
fn special_kind(_: &std::fs::FileType) -> &'static str {
    "not a regular file"
}

/// Refuse `meta` unless it is a regular file.
fn regular(meta: &std::fs::Metadata) -> io::Result<u64> {
    if meta.is_file() {
        Ok(meta.len())
    } else {
        Err(refused(format!(
            "expected a regular file, found {}",
            kind(meta)
        )))
    }
}

/// The size of `path`, refusing anything but a regular file (following links) before
/// opening it: a device or FIFO would be read without end.
pub fn regular_size(path: &Path) -> io::Result<u64> {
    regular(&std::fs::metadata(path)?)
}

/// Open `path` for reading if it is a regular file: checked by its metadata before it
/// is opened, then opened without blocking and checked again on the open file (a path
/// swapped for a FIFO or a device in between is refused, not waited on). Returns the
/// file and its size.
pub fn open_regular(path: &Path) -> io::Result<(File, u64)> {
    regular_size(path)?;
    let file = open_nonblocking(path)?;
    let size = regular(&file.metadata()?)?;
    Ok((file, size))
}

/// `path` opened for reading without waiting on it: on Unix with `O_NONBLOCK`, so that a
/// FIFO put in the file's place after its check is not waited on (the check on the open
/// file then refuses it).
#[cfg(unix)]
fn open_nonblocking(path: &Path) -> io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
}

/// `path` opened for reading. Off Unix an open does not wait on a named pipe's writer
/// the way a Unix FIFO's does, so a plain open is enough; the check on the open file
/// refuses what is not a regular file.
#[cfg(not(unix))]
fn open_nonblocking(path: &Path) -> io::Result<File> {
    File::open(path)
}

/// The message of a file larger than its format can need.
fn too_large(size: u64, bound: u128, what: &str) -> io::Error {
    refused(format!(
        "the file has {size} bytes, more than the {bound} bytes a {what} can need: is it the right file?"
    ))
}

/// [`open_regular`], refusing a file larger than `limit` allows, before reading it.
pub fn open_bounded(path: &Path, limit: Limit) -> io::Result<(File, u64)> {
    let (file, size) = open_regular(path)?;
    if size > limit.bytes() {
        return Err(too_large(size, limit.bytes().into(), limit.what()));
    }
    Ok((file, size))
}

/// Read a whole file checked as [`open_bounded`] says, refusing a compressed one.
pub fn read_bounded(path: &Path, limit: Limit) -> io::Result<Vec<u8>> {
    let (file, size) = open_bounded(path, limit)?;
    read_whole(file, size)
}

/// The `size` bytes of an open regular file (no more, should it grow meanwhile),
/// refusing a compressed file.
fn read_whole(file: File, size: u64) -> io::Result<Vec<u8>> {
    let mut bytes = Vec::with_capacity(size.min(1 << 30) as usize);
    file.take(size).read_to_end(&mut bytes)?;
    if let Some(what) = compressed_kind(&bytes) {
        return Err(refused(format!("this is {what}")));
    }
    Ok(bytes)
}

/// Which input a refused path was given as. The library's own inputs are data (a
/// command names the option that set them); a command's inputs carry the command's name
/// for them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Input {
    /// A pack's node coordinate file.
    Coords,
    /// The FMU library a pack embeds, given by its caller.
    Library,
    /// The FMU library named by the `FXBODY_LIB` environment variable.
    LibraryEnv,
    /// An input a command named itself (its option, or an environment variable as
    /// `NAME=`).
    Named(String),
}

impl From<&str> for Input {
    fn from(name: &str) -> Input {
        Input::Named(name.into())
    }
}

impl std::fmt::Display for Input {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Input::Coords => f.write_str("coordinate file"),
            Input::Library => f.write_str("library"),
            Input::LibraryEnv => f.write_str("FXBODY_LIB="),
            Input::Named(name) => f.write_str(name),
        }
    }
}

/// An input refused before it was read: which input ([`Input`]), the path, and why:
/// what the path is instead of a regular file, that it is missing, or that it is larger
/// than its kind of file can need.
#[derive(Debug)]
pub struct InputError {
    /// Which input the path was given as.
    pub input: Input,
    /// The path as given.
    pub path: PathBuf,
    /// Why it was refused.
    pub source: io::Error,
}

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.worded(&self.input.to_string(), f)
    }
}

impl std::error::Error for InputError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.source)
    }
}

/// An I/O error in words: "no such file" rather than the system's "(os error 2)".
pub fn describe(e: &io::Error) -> String {
    match e.kind() {
        io::ErrorKind::NotFound => "no such file".into(),
        io::ErrorKind::PermissionDenied => "permission denied".into(),
        _ => e.to_string(),
    }
}

impl InputError {
    /// `source` as the refusal of `path`, given as `input`.
    pub fn new(input: impl Into<Input>, path: &Path, source: io::Error) -> InputError {
        InputError {
            input: input.into(),
            path: path.to_path_buf(),
            source,
        }
    }

    /// The message with the input called `name` (an option, or `NAME=` for an
    /// environment variable): how a command words the library's inputs.
    pub fn worded(&self, name: &str, f: &mut impl std::fmt::Write) -> std::fmt::Result {
        let sep = if name.ends_with('=') { "" } else { " " };
        write!(
            f,
            "{name}{sep}{}: {}",
            self.path.display(),
            describe(&self.source)
        )
    }
}

/// Check the input `path`, given as `input`, before anything reads it: a regular file
/// no larger than `limit` allows. Returns its size.
pub fn check_input(input: impl Into<Input>, path: &Path, limit: Limit) -> Result<u64, InputError> {
    open_bounded(path, limit)
        .map(|(_, size)| size)
        .map_err(|e| InputError::new(input, path, e))
}

/// Read the whole input `path`, given as `input`, checked as [`check_input`] says.
pub fn read_input(
    input: impl Into<Input>,
    path: &Path,
    limit: Limit,
) -> Result<Vec<u8>, InputError> {
    read_bounded(path, limit).map_err(|e| InputError::new(input, path, e))
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
/// files), of any size: for files whose format bounds them itself (the FMU's scene file).
pub fn read_regular(path: &Path) -> io::Result<Vec<u8>> {
    let (file, size) = open_regular(path)?;
    read_whole(file, size)
}

/// The most bytes a `.fxb` file with this 7-integer header can sensibly need:
/// `BYTES_PER_VALUE` per value the counts call for, plus `SLACK`.
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

/// What the start of a `.fxb` text says about its header.
#[derive(Debug, PartialEq)]
enum Seen {
    /// The first data line, read as the parser reads it: the 7 header integers.
    Header([i64; 7]),
    /// The first data line is no header: the parser refuses it without reading on.
    NoHeader,
    /// No complete data line yet.
    NotYet,
}

/// The header on the first data line of `prefix` (after comments, blank lines and a
/// byte-order mark), read as the parser reads it ([`super::fields::read_line`], or the
/// blank-separated reading the parser uses to explain an ambiguous header). A line is
/// looked at only when it ends inside `prefix` or `complete` says the prefix is the
/// whole file.
fn header_of(prefix: &[u8], complete: bool) -> Seen {
    let text = prefix.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(prefix);
    let mut lines = text.split(|&b| b == b'\n').peekable();
    while let Some(line) = lines.next() {
        if lines.peek().is_none() && !complete {
            return Seen::NotYet;
        }
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        let comment = matches!(line.first(), Some(b'#' | b'$'));
        if comment || line.iter().all(|&b| super::fields::is_blank(b)) {
            continue;
        }
        let values = super::fields::read_line::<i64>(line)
            .ok()
            .or_else(|| super::fields::free_values::<i64>(line));
        return match values.and_then(|v| <[i64; 7]>::try_from(v).ok()) {
            Some(h) => Seen::Header(h),
            None => Seen::NoHeader,
        };
    }
    Seen::NotYet
}

/// A `.fxb` file opened for reading, checked as [`open_fxb`] says.
pub struct FxbInput {
    /// The first bytes of the file, already read: up to its header line (at least
    /// 64 KiB, at most 16 MiB).
    pub prefix: Vec<u8>,
    /// The rest of the file.
    pub rest: std::io::Take<File>,
    /// The file's size in bytes.
    pub size: u64,
}

/// Open a `.fxb` file: a regular file, not compressed, and no larger than its header
/// counts can need ([`size_bound`]); refused before it is read whole otherwise. Its first
/// bytes are read to check this (64 KiB, then doubling, up to the header line; a file with
/// no header line in its first 16 MiB is refused); the rest is left to the caller.
pub fn open_fxb(path: &Path) -> io::Result<FxbInput> {
    let (mut file, size) = open_regular(path)?;
    let mut prefix = Vec::new();
    let seen = loop {
        // Doubling: a long run of comments costs a few scans, not one per 64 KiB.
        let want = PREFIX
            .max(prefix.len() as u64)
            .min(size - prefix.len() as u64);
        (&mut file).take(want).read_to_end(&mut prefix)?;
        if let Some(what) = compressed_kind(&prefix) {
            return Err(refused(format!("this is {what}")));
        }
        let complete = prefix.len() as u64 >= size || want == 0;
        match header_of(&prefix, complete) {
            Seen::NotYet if !complete && (prefix.len() as u128) < SLACK => continue,
            seen => break seen,
        }
    };
    match seen {
        Seen::Header(h) => {
            let bound = size_bound(&h);
            if u128::from(size) > bound {
                let what = format!(
                    "body file with this header (Nbmod {} Nbstat {} Nbnod {} Irot {})",
                    h[0], h[1], h[2], h[3]
                );
                return Err(too_large(size, bound, &what));
            }
        }
        // The parser stops at the first data line, which is in the prefix.
        Seen::NoHeader => {}
        Seen::NotYet if prefix.len() as u64 >= size => {}
        Seen::NotYet => {
            return Err(refused(format!(
                "no header line (the 7 integers Nbmod Nbstat Nbnod Irot Idamp Iblo Ifile) in the first {} bytes of {size}: is it a .fxb file?",
                prefix.len()
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
        let Seen::Header(h) = header_of(b"# c\n$ d\n\n   2 1  3 0 1 1 0\n1 2\n", false) else {
            panic!("no header")
        };
        assert_eq!(h, [2, 1, 3, 0, 1, 1, 0]);
        // Fixed columns whose numbers touch, as the parser reads them.
        let touching = b"       2       1       3       0       1       1       0\n";
        assert!(matches!(header_of(touching, false), Seen::Header(_)));
        assert_eq!(header_of(b"# only a comment\n   2 1", false), Seen::NotYet);
        assert!(matches!(
            header_of(b"   2 1 3 0 1 1 0", true),
            Seen::Header(_)
        ));
        // 3 ids + 12 + 14*6*3 modes + 2 + 3 + 78 + 18*12*2 = 782 values.
        assert_eq!(size_bound(&h), 782 * 80 + 16 * 1024 * 1024);
        assert_eq!(header_of(b"abc\n", false), Seen::NoHeader);
        assert_eq!(
            compressed_kind(b"\x1f\x8b\x08"),
            compressed_kind(b"\x1f\x8b")
        );
        assert!(compressed_kind(b"PK\x03\x04").unwrap().contains("zip"));
        assert!(compressed_kind(b"    2").is_none());
    }
}
