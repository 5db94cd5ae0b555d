//! The `.fxb` file format only: reading (fixed-column and free-format), writing, and
//! errors that name the file, line and block. No physics here: [`FxbFile`] holds the
//! numbers exactly in file order; the body layer (`crate::body`) turns them into matrices
//! and loads a body from a path.
//!
//! Reading rules (FORMULATION.md section 1): comments (`#` or `$` in column 1) and blank
//! lines may appear anywhere; each line is read both in Radioss fixed columns and as
//! blank- or tab-separated values, and a line the two readings see differently is an
//! error ([`fields`]); each block and sub-block starts on a new line, values run five to a
//! line and only a block's last line may be short; a mode takes two lines per node.
//! The Ifile flag is read and kept but has no effect on anything this crate computes (it
//! only tells Radioss whether to keep mode data in memory or on disk).

use std::path::Path;

pub mod coords;
mod error;
mod fast;
pub mod fields;
pub mod input;
mod lines;
mod reader;
mod writer;

pub use error::{At, Block, FxbError};
pub use writer::{format_real, write};

/// Read and parse a `.fxb` file; the file name in errors is the path as given.
pub fn read_path(path: &Path) -> Result<FxbFile, FxbError> {
    read_path_with(path, Reading::default())
}

/// [`read_path`], reading as `how` says. The file is parsed while it is read, a window
/// at a time, never whole in memory: the same checks as [`read_bytes`] before, the same
/// numbers and messages as [`parse_with`] on its bytes.
pub fn read_path_with(path: &Path, how: Reading<'_>) -> Result<FxbFile, FxbError> {
    let name = path.display().to_string();
    let io = |source| FxbError::Io {
        file: name.clone(),
        source,
    };
    let input::FxbInput { prefix, rest, size } = input::open_fxb(path).map_err(io)?;
    let head = prefix.strip_prefix(BOM).unwrap_or(&prefix);
    refuse_compressed(head, &name)?;
    let total = size - (prefix.len() - head.len()) as u64;
    let mut text = std::io::Read::chain(head, rest);
    reader::parse_input(&mut text, total, &name, how)
}

/// A byte-order mark, as some Windows editors write: not part of line 1.
const BOM: &[u8] = b"\xEF\xBB\xBF";

/// Refuse a text that starts like a compressed file, naming its kind.
fn refuse_compressed(text: &[u8], file_name: &str) -> Result<(), FxbError> {
    match input::compressed_kind(text) {
        Some(what) => Err(FxbError::Io {
            file: file_name.into(),
            source: std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("this is {what}"),
            ),
        }),
        None => Ok(()),
    }
}

/// The bytes of a `.fxb` file, checked before they are read whole
/// ([`input::read_fxb_bytes`]: a regular file, not compressed, no larger than its header
/// can need), for a caller that keeps them (`pack --embed-source`); the commands
/// otherwise parse the file as it is read ([`read_path_with`]), after the same checks.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>, FxbError> {
    input::read_fxb_bytes(path).map_err(|source| FxbError::Io {
        file: path.display().to_string(),
        source,
    })
}

/// Parse the text of a `.fxb` file (a `&str` or raw bytes). `file_name` is only used in
/// error messages. Bytes that are not UTF-8 are allowed in comments and are an
/// unparsable-field error anywhere else; a leading byte-order mark is skipped.
pub fn parse(text: impl AsRef<[u8]>, file_name: &str) -> Result<FxbFile, FxbError> {
    parse_with(text, file_name, Reading::default())
}

/// How [`parse_with`] reads: which line reader, and who hears how far it has come.
#[derive(Default)]
pub struct Reading<'a> {
    /// Read every line both ways in full, without the fast path for common lines. The
    /// result is the same, bit for bit, only slower (about four times): this is the
    /// reference the fast path is tested and benchmarked against.
    pub exact: bool,
    /// Called with (bytes read, total bytes) about every MiB and once at the end, so a
    /// command can draw a progress bar for a large file. Reading has no other side
    /// effect.
    pub progress: Option<&'a mut dyn FnMut(u64, u64)>,
}

/// [`parse`], reading as `how` says (the reference reader, a progress callback).
pub fn parse_with(
    text: impl AsRef<[u8]>,
    file_name: &str,
    how: Reading<'_>,
) -> Result<FxbFile, FxbError> {
    let text = text.as_ref();
    let mut text = text.strip_prefix(BOM).unwrap_or(text);
    refuse_compressed(text, file_name)?;
    let total = text.len() as u64;
    reader::parse_input(&mut text, total, file_name, how)
}

/// The raw contents of a flexible-body file, block by block, in file order.
///
/// Counts follow FORMULATION.md section 1: `nl = nbmod`, `ns = nbstat`, `n = nbnod`,
/// `nr = 12` (irot false) or `15` (irot true). Blocks absent for the given flags are empty.
#[derive(Debug, Clone, PartialEq)]
pub struct FxbFile {
    /// Block 1: total number of local modes (Nbmod).
    pub nbmod: usize,
    /// Block 1: number of static modes (Nbstat), the first `nbstat` local modes.
    pub nbstat: usize,
    /// Block 1: number of nodes (Nbnod).
    pub nbnod: usize,
    /// Block 1: the body has nodes with rotational DOFs (Irot = 1): 15 rigid modes.
    pub irot: bool,
    /// Block 1: Rayleigh damping present (Idamp = 1).
    pub idamp: bool,
    /// Block 1: blocked body (Iblo = 1): no rigid modes, no M_R, M_C, K_C.
    pub iblo: bool,
    /// Block 1: Ifile; only tells Radioss where to keep mode data. No effect on results.
    pub ifile: bool,
    /// Block 2: node IDs, in the order the mode blocks list nodes.
    pub node_ids: Vec<i64>,
    /// Block 3: initial frame P0, row-major (P11 P12 P13 P21 ... P33).
    pub p0: [f64; 9],
    /// Block 3: the largest eigenfrequency of (K_L, M_L) in Hz, as stored.
    pub freq: f64,
    /// Block 4: Rayleigh (alpha, beta); `None` when Idamp = 0.
    pub damping: Option<(f64, f64)>,
    /// Blocks 5+6: rigid modes, `nr * n * 6` values: mode-major, then node, then
    /// component (X Y Z XX YY ZZ). Empty when Iblo = 1.
    pub rigid_modes: Vec<f64>,
    /// Block 7: local modes, `nl * n * 6` values, same order as `rigid_modes`.
    pub local_modes: Vec<f64>,
    /// Block 8: diagonal local mass m_L, `nl` values.
    pub m_l: Vec<f64>,
    /// Block 9: full part of K_L, `ns (2 nl - ns + 1) / 2` values (skyline rows).
    pub k_full: Vec<f64>,
    /// Block 10: diagonal part of K_L, `nl - ns` values.
    pub k_diag: Vec<f64>,
    /// Block 11: M_R upper triangle row by row, `nr (nr + 1) / 2` values; empty if Iblo = 1.
    pub m_r: Vec<f64>,
    /// Block 12: nine M_C,kl sub-blocks, `9 * nr * nl` values; sub-block `3(k-1)+(l-1)`
    /// (0-based), each row-major nr x nl. Empty if Iblo = 1 or nl = 0.
    pub m_c: Vec<f64>,
    /// Block 13: nine K_C,kl sub-blocks, same layout as `m_c`.
    pub k_c: Vec<f64>,
}

impl FxbFile {
    /// Number of rigid modes (12, or 15 with rotational DOFs); 0 for a blocked body.
    pub fn nr(&self) -> usize {
        match (self.iblo, self.irot) {
            (true, _) => 0,
            (false, false) => 12,
            (false, true) => 15,
        }
    }
}
