//! The block structure of a `.fxb` file (FORMULATION.md section 1): which blocks come,
//! how many values each holds, and how they are laid out on lines. Line-level reading is
//! in [`super::fields`].

use std::collections::HashMap;
use std::io::Read;

use super::error::{At, Block, FxbError};
use super::fast::{self, FastField, MAX_FIELDS};
use super::fields::{LineIssue, read_line, shown};
use super::lines::Lines;
use super::{FxbFile, Reading};

/// Bytes between two progress reports.
const PROGRESS_STEP: u64 = 1 << 20;

/// Values per line in real-valued blocks.
const REALS_PER_LINE: usize = 5;
/// Node IDs per line in block 2.
const IDS_PER_LINE: usize = 10;

struct Reader<'a, 'p> {
    file: &'a str,
    lines: Lines<'a>,
    /// Read every line both ways in full (no fast path).
    exact: bool,
    /// Told (bytes read, total bytes) every [`PROGRESS_STEP`] bytes.
    progress: Option<&'p mut dyn FnMut(u64, u64)>,
    /// The byte offset of the next progress report.
    next_report: u64,
}

impl Reader<'_, '_> {
    /// Tell the progress callback, if any, how far reading has come.
    fn report(&mut self, force: bool) {
        let at = self.lines.offset();
        if let Some(tell) = self.progress.as_mut()
            && (force || at >= self.next_report)
        {
            tell(at, self.lines.total());
            self.next_report = at + PROGRESS_STEP;
        }
    }

    /// The next data line ([`Lines::next_data`]), a failing read as the file's error.
    fn next_data(&mut self) -> Result<Option<(usize, std::ops::Range<usize>)>, FxbError> {
        self.lines.next_data().map_err(|source| FxbError::Io {
            file: self.file.to_string(),
            source,
        })
    }

    fn at(&self, line: usize, block: Block) -> At {
        At {
            file: self.file.to_string(),
            line,
            block,
        }
    }

    /// Append `count` values to `out`, `per_line` to a line, the last line possibly short.
    /// `what` describes the values for messages (only called on error).
    fn read_into<T: FastField>(
        &mut self,
        out: &mut Vec<T>,
        block: Block,
        count: usize,
        per_line: usize,
        what: &dyn Fn() -> String,
    ) -> Result<(), FxbError> {
        let mut left = count;
        while left > 0 {
            let need = left.min(per_line);
            let Some((ln, range)) = self.next_data()? else {
                return Err(FxbError::UnexpectedEof {
                    at: self.at(self.lines.line_no(), block),
                    expected: format!("{left} more value(s) of {}", what()),
                });
            };
            let line = self.lines.text(range);
            let mut buf = [T::ZERO; MAX_FIELDS];
            let slow;
            let vals: &[T] = match (!self.exact)
                .then(|| fast::read_line(line, &mut buf))
                .flatten()
            {
                Some(n) => &buf[..n],
                None => {
                    slow = self.read_full(line, ln, block, what)?;
                    &slow
                }
            };
            if vals.len() > need {
                return Err(FxbError::TooManyValues {
                    at: self.at(ln, block),
                    expected: need,
                    found: vals.len(),
                    what: what(),
                });
            }
            if vals.len() < need {
                return Err(FxbError::ShortLine {
                    at: self.at(ln, block),
                    expected: need,
                    found: vals.len(),
                    what: what(),
                });
            }
            out.extend_from_slice(vals);
            left -= need;
            self.report(false);
        }
        Ok(())
    }

    /// The full two-way reading of one line ([`read_line`]), its issues as errors.
    fn read_full<T: FastField>(
        &self,
        line: &[u8],
        ln: usize,
        block: Block,
        what: &dyn Fn() -> String,
    ) -> Result<Vec<T>, FxbError> {
        read_line::<T>(line).map_err(|issue| match issue {
            LineIssue::Unparsable(found) => FxbError::Unparsable {
                at: self.at(ln, block),
                expected: format!("{} ({})", T::WHAT, what()),
                found,
            },
            LineIssue::Ambiguous { fixed, free, note } => FxbError::Ambiguous {
                at: self.at(ln, block),
                fixed,
                free,
                width: T::WIDTH,
                note,
            },
        })
    }

    /// A run of `count` reals, 5 to a line.
    fn reals(&mut self, block: Block, count: usize) -> Result<Vec<f64>, FxbError> {
        let mut out = Vec::with_capacity(count);
        let what = || format!("{} values of {block}", count);
        self.read_into(&mut out, block, count, REALS_PER_LINE, &what)?;
        Ok(out)
    }

    /// `modes` modes of `nodes` nodes, two lines per node (X Y Z XX YY, then ZZ).
    /// `first_mode` is the 1-based number of the first mode; `block_of` names the block a
    /// mode belongs to (rigid modes 13-15 are block 6).
    fn modes(
        &mut self,
        node_ids: &[i64],
        modes: usize,
        first_mode: usize,
        block_of: &dyn Fn(usize) -> Block,
        kind: &str,
    ) -> Result<Vec<f64>, FxbError> {
        // Counts were bounded by the file size before we get here.
        let mut out = Vec::with_capacity(modes * node_ids.len() * 6);
        for m in 0..modes {
            let mode = first_mode + m;
            let block = block_of(mode);
            for (k, id) in node_ids.iter().enumerate() {
                let head = || {
                    format!(
                        "{kind} mode {mode}, node {id} (node {} of {}): X Y Z XX YY",
                        k + 1,
                        node_ids.len()
                    )
                };
                self.read_into(&mut out, block, 5, 5, &head)?;
                let tail = || {
                    format!(
                        "{kind} mode {mode}, node {id} (node {} of {}): ZZ",
                        k + 1,
                        node_ids.len()
                    )
                };
                self.read_into(&mut out, block, 1, 1, &tail)?;
            }
        }
        Ok(out)
    }
}

/// Header counts, checked.
struct Header {
    nbmod: usize,
    nbstat: usize,
    nbnod: usize,
    irot: bool,
    idamp: bool,
    iblo: bool,
    ifile: bool,
}

impl Header {
    fn nr(&self) -> usize {
        match (self.iblo, self.irot) {
            (true, _) => 0,
            (false, false) => 12,
            (false, true) => 15,
        }
    }

    /// Values the rest of the file must hold, `None` on overflow.
    fn values_needed(&self) -> Option<u128> {
        let (n, nl, ns, nr) = (
            self.nbnod as u128,
            self.nbmod as u128,
            self.nbstat as u128,
            self.nr() as u128,
        );
        let mut total = n.checked_add(10)?;
        if self.idamp {
            total = total.checked_add(2)?;
        }
        let per_mode = n.checked_mul(6)?;
        total = total.checked_add(nr.checked_add(nl)?.checked_mul(per_mode)?)?;
        total = total.checked_add(nl.checked_mul(2)?)?; // m_L, diagonal part (+ nS below)
        total = total.checked_add(ns.checked_mul(nl.checked_mul(2)?.checked_add(1)? - ns)? / 2)?;
        total = total.checked_add(nr * (nr + 1) / 2)?;
        if nr > 0 {
            total = total.checked_add(nr.checked_mul(nl)?.checked_mul(18)?)?;
        }
        Some(total)
    }
}

/// Parse the `total` bytes of text `input` gives (a file being read, or bytes in
/// memory). See [`super::parse_with`].
pub fn parse_input(
    input: &mut dyn Read,
    total: u64,
    file: &str,
    how: Reading<'_>,
) -> Result<FxbFile, FxbError> {
    let mut r = Reader {
        file,
        lines: Lines::new(input, total),
        exact: how.exact,
        progress: how.progress,
        next_report: 0,
    };
    let b1 = Block::new(1);
    let mut raw: Vec<i64> = Vec::with_capacity(7);
    let read = r.read_into(&mut raw, b1, 7, 7, &|| {
        "the 7 header integers Nbmod Nbstat Nbnod Irot Idamp Iblo Ifile".into()
    });
    if let Err(e) = read {
        // A header that cannot fit 8-column fields (Nbnod = 1000000000) is ambiguous;
        // if its blank-separated reading claims more than the file holds, say that.
        if matches!(e, FxbError::Ambiguous { .. }) {
            r.lines.unread();
            if let Some((ln, range)) = r.next_data()? {
                let free = super::fields::free_values::<i64>(r.lines.text(range));
                if let Some(h) = free
                    .as_deref()
                    .filter(|v| v.len() == 7)
                    .and_then(|v| header(&r, v, ln).ok())
                {
                    too_large(
                        &r,
                        &h,
                        ln,
                        " (blank-separated reading; the line is also ambiguous in fixed columns)",
                    )?;
                }
            }
        }
        return Err(e);
    }
    let header_line = r.lines.line_no();
    let h = header(&r, &raw, header_line)?;
    too_large(&r, &h, header_line, "")?;
    let (n, nl, ns, nr) = (h.nbnod, h.nbmod, h.nbstat, h.nr());

    // Block 2: node IDs, 10 per line, each once.
    let b2 = Block::new(2);
    let mut node_ids: Vec<i64> = Vec::with_capacity(n);
    let mut first_line: HashMap<i64, usize> = HashMap::with_capacity(n);
    while node_ids.len() < n {
        let before = node_ids.len();
        let left = n - before;
        let what = || format!("{n} node IDs, 10 per line");
        r.read_into(
            &mut node_ids,
            b2,
            left.min(IDS_PER_LINE),
            IDS_PER_LINE,
            &what,
        )?;
        let ln = r.lines.line_no();
        for &id in &node_ids[before..] {
            if id <= 0 {
                return Err(FxbError::BadNodeId {
                    at: r.at(ln, b2),
                    id,
                });
            }
            if let Some(&first) = first_line.get(&id) {
                return Err(FxbError::DuplicateNodeId {
                    at: r.at(ln, b2),
                    id,
                    first_line: first,
                });
            }
            first_line.insert(id, ln);
        }
    }

    let frame = r.reals(Block::new(3), 10)?;
    let mut p0 = [0.0; 9];
    p0.copy_from_slice(&frame[..9]);
    let freq = frame[9];

    let damping = if h.idamp {
        let d = r.reals(Block::new(4), 2)?;
        Some((d[0], d[1]))
    } else {
        None
    };

    let rigid_block = |mode: usize| Block::new(if mode <= 12 { 5 } else { 6 });
    let rigid_modes = r.modes(&node_ids, nr, 1, &rigid_block, "rigid")?;
    let local_modes = r.modes(&node_ids, nl, 1, &|_| Block::new(7), "local")?;
    let m_l = r.reals(Block::new(8), nl)?;
    let k_full = r.reals(Block::new(9), ns * (2 * nl - ns + 1) / 2)?;
    let k_diag = r.reals(Block::new(10), nl - ns)?;
    let m_r = r.reals(Block::new(11), nr * (nr + 1) / 2)?;
    let mut coupled = |number: u8| -> Result<Vec<f64>, FxbError> {
        let mut out = Vec::with_capacity(9 * nr * nl);
        if nr > 0 && nl > 0 {
            for m in 1..=9u8 {
                let block = Block::sub(number, m);
                let what = || format!("{} values ({nr} rows x {nl} columns) of {block}", nr * nl);
                r.read_into(&mut out, block, nr * nl, REALS_PER_LINE, &what)?;
            }
        }
        Ok(out)
    };
    let m_c = coupled(12)?;
    let k_c = coupled(13)?;

    if let Some((ln, range)) = r.next_data()? {
        let line = r.lines.text(range);
        let last = match (nr > 0, nl > 0) {
            (true, true) => 13,
            (true, false) => 11,
            (false, _) => 10,
        };
        return Err(FxbError::TrailingData {
            at: r.at(ln, Block::new(last)),
            found: shown(line),
        });
    }

    r.report(true);
    Ok(FxbFile {
        nbmod: nl,
        nbstat: ns,
        nbnod: n,
        irot: h.irot,
        idamp: h.idamp,
        iblo: h.iblo,
        ifile: h.ifile,
        node_ids,
        p0,
        freq,
        damping,
        rigid_modes,
        local_modes,
        m_l,
        k_full,
        k_diag,
        m_r,
        m_c,
        k_c,
    })
}

/// Refuse header counts that the rest of the text cannot hold, before allocating.
fn too_large(r: &Reader<'_, '_>, h: &Header, line: usize, note: &str) -> Result<(), FxbError> {
    let needed = h.values_needed();
    let available = r.lines.remaining();
    if needed.is_none_or(|v| v > u128::from(available)) {
        return Err(FxbError::TooLarge {
            at: r.at(line, Block::new(1)),
            claim: format!(
                "Nbmod = {}, Nbstat = {}, Nbnod = {}{note}",
                h.nbmod, h.nbstat, h.nbnod
            ),
            needed: needed.unwrap_or(u128::MAX),
            available: usize::try_from(available).unwrap_or(usize::MAX),
        });
    }
    Ok(())
}

/// Check the seven header integers.
fn header(r: &Reader<'_, '_>, raw: &[i64], line: usize) -> Result<Header, FxbError> {
    let at = || r.at(line, Block::new(1));
    let names = ["Nbmod", "Nbstat", "Nbnod", "Irot", "Idamp", "Iblo", "Ifile"];
    let mut counts = [0usize; 3];
    let mut flags = [false; 4];
    for (k, (&v, name)) in raw.iter().zip(names).enumerate() {
        if k < 3 {
            counts[k] = usize::try_from(v).map_err(|_| FxbError::NegativeCount {
                at: at(),
                name,
                found: v,
            })?;
        } else {
            flags[k - 3] = match v {
                0 => false,
                1 => true,
                _ => {
                    return Err(FxbError::BadFlag {
                        at: at(),
                        name,
                        found: v,
                    });
                }
            };
        }
    }
    let [nbmod, nbstat, nbnod] = counts;
    if nbstat > nbmod {
        return Err(FxbError::NbstatExceedsNbmod {
            at: at(),
            nbstat,
            nbmod,
        });
    }
    let [irot, idamp, iblo, ifile] = flags;
    Ok(Header {
        nbmod,
        nbstat,
        nbnod,
        irot,
        idamp,
        iblo,
        ifile,
    })
}
