//! Matrix terms as a reader finds them, turned into a [`SymMatrix`]: the checks every
//! format shares (an ID is a grid point or a scalar point, never both; a term is given
//! once; mirrored terms agree) live here once.
//!
//! One pass, no quadratic step: DOFs are numbered through a hash map as they are met,
//! the terms are sorted once by their (row, column) pair, and the checks run over
//! neighbours in that order.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use super::error::{FeError, Loc};
use super::{Dof, SymMatrix};

/// Largest relative difference accepted between a term and its mirror when a file gives
/// both triangles (the two are averaged). Files written from one symmetric matrix give
/// equal text; 1e-6 leaves room for a code that assembles both triangles in its own
/// arithmetic and prints about 7 digits.
pub const SYM_REL_TOL: f64 = 1e-6;

/// Differences below this fraction of the largest term in the matrix are round-off on
/// terms that are themselves round-off (a coupling of 1e-9 in a matrix of 1e8), and are
/// accepted whatever their relative size.
pub const SYM_NOISE: f64 = 1e-12;

/// How a format stores a symmetric matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Storage {
    /// Each off-diagonal term from either triangle; when both are given they must agree
    /// (Nastran DMIG with IFO=6).
    Either,
    /// Every off-diagonal term in both triangles (Nastran DMIG with IFO=1: a missing
    /// mirror is a zero, so the matrix would not be symmetric).
    Full,
    /// One triangle, or both: full storage as soon as one pair is given in both
    /// triangles, and then every pair must be (Abaqus, CalculiX).
    Detect,
}

/// A fast hasher for small integer keys (std's SipHash guards against hostile keys,
/// which a matrix file's DOF IDs are not, and costs a third of the reading time).
#[derive(Default)]
struct IdHasher(u64);

impl Hasher for IdHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_u8(&mut self, n: u8) {
        self.write_u64(u64::from(n));
    }
    fn write_i64(&mut self, n: i64) {
        self.write_u64(n as u64);
    }
    fn write_u64(&mut self, n: u64) {
        self.0 = (self.0.rotate_left(5) ^ n).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

type FastMap<K, V> = HashMap<K, V, BuildHasherDefault<IdHasher>>;

/// One term as read: row and column as indices into [`Terms::dofs`] (order of first
/// mention), and the line it is on.
#[derive(Clone, Copy)]
struct Entry {
    row: u32,
    col: u32,
    line: u32,
    value: f64,
}

/// Terms being collected from one file.
pub struct Terms<'a> {
    file: &'a str,
    index: FastMap<Dof, u32>,
    dofs: Vec<Dof>,
    /// For each ID: the component it was first seen with and the line.
    kinds: FastMap<i64, (u8, usize)>,
    entries: Vec<Entry>,
    /// The DOF looked up last and its index (a column's DOF repeats line after line).
    last: Option<(Dof, u32)>,
}

impl<'a> Terms<'a> {
    /// An empty collection for `file`.
    pub fn new(file: &'a str) -> Terms<'a> {
        Terms {
            file,
            index: FastMap::default(),
            dofs: Vec::new(),
            kinds: FastMap::default(),
            entries: Vec::new(),
            last: None,
        }
    }

    /// The number of terms collected so far.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// The index of `d`, numbering it if new; refuses an ID seen both as a scalar point
    /// (component 0) and as a grid point (1..6).
    pub fn dof(&mut self, d: Dof, line: usize) -> Result<u32, FeError> {
        if let Some((last, k)) = self.last
            && last == d
        {
            return Ok(k);
        }
        if let Some(&k) = self.index.get(&d) {
            self.last = Some((d, k));
            return Ok(k);
        }
        match self.kinds.get(&d.id) {
            Some(&(c, first)) if (c == 0) != (d.comp == 0) => {
                return Err(FeError::invalid(
                    self.file,
                    line,
                    format!(
                        "node {} appears with component {} (line {first}) and {}: an ID is \
                         either a scalar point (component 0) or a grid point (1..6)",
                        d.id, c, d.comp
                    ),
                ));
            }
            Some(_) => {}
            None => {
                self.kinds.insert(d.id, (d.comp, line));
            }
        }
        let k = u32::try_from(self.dofs.len()).map_err(|_| {
            FeError::invalid(self.file, line, "more than 4e9 DOFs: not a matrix to read")
        })?;
        self.index.insert(d, k);
        self.dofs.push(d);
        Ok(k)
    }

    /// Add the term (row, col) = value read on `line`.
    pub fn push(&mut self, row: u32, col: u32, value: f64, line: usize) {
        self.entries.push(Entry {
            row,
            col,
            line: u32::try_from(line).unwrap_or(u32::MAX),
            value,
        });
    }

    /// The matrix: DOFs sorted, duplicates and asymmetry refused, zeros dropped.
    pub fn finish(self, name: String, storage: Storage) -> Result<SymMatrix, FeError> {
        let file = self.file;
        let n = self.dofs.len();
        let mut order: Vec<u32> = (0..n as u32).collect();
        order.sort_unstable_by_key(|&k| self.dofs[k as usize].order_key());
        let mut rank = vec![0u32; n];
        for (new, &old) in order.iter().enumerate() {
            rank[old as usize] = new as u32;
        }
        let dofs: Vec<Dof> = order.iter().map(|&k| self.dofs[k as usize]).collect();

        // (upper-triangle pair, given in the lower triangle) -> sorts mirrors together.
        let mut entries = self.entries;
        for e in entries.iter_mut() {
            e.row = rank[e.row as usize];
            e.col = rank[e.col as usize];
        }
        let key = |e: &Entry| {
            let (i, j) = (e.row.min(e.col), e.row.max(e.col));
            ((u64::from(i) << 32) | u64::from(j), e.row > e.col, e.line)
        };
        let entries = bucket_sort(entries, n, key);
        let scale = entries.iter().fold(0.0f64, |m, e| m.max(e.value.abs()));

        // Full storage when Detect finds any mirrored pair.
        let full = match storage {
            Storage::Full => true,
            Storage::Either => false,
            Storage::Detect => entries
                .windows(2)
                .any(|w| key(&w[0]).0 == key(&w[1]).0 && key(&w[0]).1 != key(&w[1]).1),
        };

        let mut terms = Vec::with_capacity(if full {
            entries.len() / 2 + n
        } else {
            entries.len()
        });
        let mut k = 0;
        while k < entries.len() {
            let e = entries[k];
            let (pair, _, _) = key(&e);
            let mut end = k + 1;
            while end < entries.len() && key(&entries[end]).0 == pair {
                end += 1;
            }
            let group = &entries[k..end];
            k = end;
            // Sorted by (pair, lower, line): a repeat is the next entry of the same side.
            for w in group.windows(2) {
                if w[0].row == w[1].row && w[0].col == w[1].col {
                    return Err(FeError::Duplicate {
                        at: Loc::new(file, w[1].line as usize),
                        a: dofs[w[1].row as usize],
                        b: dofs[w[1].col as usize],
                        first_line: w[0].line as usize,
                    });
                }
            }
            let (i, j) = (e.row.min(e.col) as usize, e.row.max(e.col) as usize);
            let value = match group {
                [one] if i != j && full => {
                    return Err(FeError::NotSymmetric {
                        at: Loc::new(file, one.line as usize),
                        a: dofs[one.row as usize],
                        b: dofs[one.col as usize],
                        ab: one.value,
                        ba: None,
                        rel: 1.0,
                    });
                }
                [one] => one.value,
                [up, low] => {
                    let (a, b) = (up.value, low.value);
                    let diff = (a - b).abs();
                    let big = a.abs().max(b.abs());
                    if diff > SYM_REL_TOL * big && diff > SYM_NOISE * scale {
                        return Err(FeError::NotSymmetric {
                            at: Loc::new(file, up.line as usize),
                            a: dofs[up.row as usize],
                            b: dofs[up.col as usize],
                            ab: a,
                            ba: Some((b, low.line as usize)),
                            rel: diff / big,
                        });
                    }
                    0.5 * (a + b)
                }
                _ => unreachable!("duplicates were refused above"),
            };
            if value != 0.0 {
                terms.push((i, j, value));
            }
        }
        Ok(SymMatrix {
            name,
            dofs,
            terms,
            small_field_digits: None,
        })
    }
}

/// `entries` sorted by `key`, whose first part is `min(row, col) << 32 | max(row, col)`:
/// a counting pass by the smaller index (`n` DOFs), then a sort within each bucket, which
/// the usual column-by-column order leaves almost sorted. Linear where one sort of 4.5
/// million terms is not.
fn bucket_sort<K: Ord>(entries: Vec<Entry>, n: usize, key: impl Fn(&Entry) -> K) -> Vec<Entry> {
    let first = |e: &Entry| e.row.min(e.col) as usize;
    let mut start = vec![0usize; n + 1];
    for e in &entries {
        start[first(e) + 1] += 1;
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let mut next = start.clone();
    let blank = Entry {
        row: 0,
        col: 0,
        line: 0,
        value: 0.0,
    };
    let mut out = vec![blank; entries.len()];
    for e in entries {
        let b = first(&e);
        out[next[b]] = e;
        next[b] += 1;
    }
    for k in 0..n {
        out[start[k]..start[k + 1]].sort_unstable_by_key(&key);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn g(id: i64, comp: u8) -> Dof {
        Dof { id, comp }
    }

    fn collect(storage: Storage, t: &[(Dof, Dof, f64)]) -> Result<SymMatrix, FeError> {
        let mut terms = Terms::new("m.txt");
        for (line, &(a, b, v)) in t.iter().enumerate() {
            let r = terms.dof(a, line + 1)?;
            let c = terms.dof(b, line + 1)?;
            terms.push(r, c, v, line + 1);
        }
        terms.finish("M".into(), storage)
    }

    #[test]
    fn dofs_sorted_grids_then_scalars_and_triangles_folded() {
        let m = collect(
            Storage::Detect,
            &[
                (g(900001, 0), g(900001, 0), 3.0),
                (g(7, 2), g(7, 2), 5.0),
                (g(7, 2), g(3, 6), -1.0),
                (g(3, 6), g(900001, 0), 0.0),
                (g(3, 6), g(3, 6), 2.0),
            ],
        )
        .unwrap();
        assert_eq!(m.dofs, vec![g(3, 6), g(7, 2), g(900001, 0)]);
        assert_eq!(
            m.terms,
            vec![(0, 0, 2.0), (0, 1, -1.0), (1, 1, 5.0), (2, 2, 3.0)]
        );
        assert_eq!(m.get(g(7, 2), g(3, 6)), -1.0);
        assert_eq!(m.get(g(3, 6), g(900001, 0)), 0.0);
    }

    #[test]
    fn a_term_given_twice_names_both_lines() {
        let e = collect(
            Storage::Either,
            &[
                (g(1, 1), g(2, 3), 1.0),
                (g(1, 1), g(1, 1), 1.0),
                (g(1, 1), g(2, 3), 1.0),
            ],
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "m.txt:3: term (1.1, 2.3) given twice: first on line 1"
        );
    }

    #[test]
    fn mirrors_must_agree_and_full_storage_needs_every_mirror() {
        let e = collect(
            Storage::Either,
            &[(g(12, 3), g(40, 1), 2.1e5), (g(40, 1), g(12, 3), 2.0e5)],
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("(12.3, 40.1) = 210000 but (40.1, 12.3) = 200000 (line 2)"),
            "{e}"
        );
        assert!(e.contains("rel. diff 0.047619047619047616"), "{e}");
        // Equal to 1e-7: accepted, averaged.
        let m = collect(
            Storage::Either,
            &[(g(1, 1), g(2, 1), 1.0), (g(2, 1), g(1, 1), 1.0 + 1e-7)],
        )
        .unwrap();
        assert!((m.terms[0].2 - (1.0 + 0.5e-7)).abs() < 1e-15);
        // Detect: one pair mirrored, so the unmirrored one is missing its mirror.
        let e = collect(
            Storage::Detect,
            &[
                (g(1, 1), g(2, 1), 1.0),
                (g(2, 1), g(1, 1), 1.0),
                (g(1, 1), g(3, 1), 4.0),
            ],
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("m.txt:3: not symmetric: (1.1, 3.1) = 4 but (3.1, 1.1) = 0"),
            "{e}"
        );
        // Either: a mix of triangles is fine.
        let m = collect(
            Storage::Either,
            &[(g(1, 1), g(2, 1), 1.0), (g(3, 1), g(1, 1), 4.0)],
        )
        .unwrap();
        assert_eq!(m.terms, vec![(0, 1, 1.0), (0, 2, 4.0)]);
    }

    #[test]
    fn an_id_is_a_grid_or_a_scalar_point() {
        let e = collect(
            Storage::Either,
            &[(g(12, 0), g(12, 0), 1.0), (g(12, 3), g(12, 3), 1.0)],
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "m.txt:2: node 12 appears with component 0 (line 1) and 3: an ID is either a \
             scalar point (component 0) or a grid point (1..6)"
        );
    }
}
