//! [`TermStream`]: matrix terms keyed by DOF, as the Abaqus (`node, dof, node, dof,
//! value`) and Nastran DMIG readers produce them, collected into a [`SymCsc`] over a
//! sorted DOF list, with memory proportional to the terms.
//!
//! A reader calls [`TermStream::push`] for each term with the line it was on, then
//! [`TermStream::finish`]; the checks are [`crate::sparse::Coo`]'s (a term given once; both
//! triangles only if every mirror is given and agrees). DOFs are numbered through a hash
//! map as they are met and sorted once at the end (node DOFs by node and direction, then
//! scalar points), so the result does not depend on the order of the file. A node ID met
//! both as a scalar point (direction 0) and as a node (1..6) is refused.

use std::collections::HashMap;
use std::collections::hash_map::Entry;

use crate::fe::Dof;
use crate::fe::FeError;
use crate::sparse::coo::Coo;
use crate::sparse::csc::SymCsc;

/// A symmetric matrix over named DOFs.
#[derive(Debug, Clone, PartialEq)]
pub struct DofMatrix {
    /// Every DOF mentioned, sorted by [`Dof::order_key`].
    pub dofs: Vec<Dof>,
    /// The matrix over `dofs`.
    pub matrix: SymCsc,
}

/// Terms of one matrix being collected from one file.
pub struct TermStream {
    file: String,
    index: HashMap<Dof, u32>,
    dofs: Vec<Dof>,
    /// For each ID: whether it was first seen as a scalar point, and the line.
    kinds: HashMap<i64, (bool, usize)>,
    /// Terms by first-seen index: row, column, line, value.
    terms: Vec<(u32, u32, u32, f64)>,
}

impl TermStream {
    /// An empty stream for `file` (named in errors).
    pub fn new(file: &str) -> TermStream {
        TermStream {
            file: file.to_string(),
            index: HashMap::new(),
            dofs: Vec::new(),
            kinds: HashMap::new(),
            terms: Vec::new(),
        }
    }

    /// Terms pushed so far.
    pub fn len(&self) -> usize {
        self.terms.len()
    }

    /// Whether no term was pushed.
    pub fn is_empty(&self) -> bool {
        self.terms.is_empty()
    }

    fn number(&mut self, d: Dof, line: usize) -> Result<u32, FeError> {
        if let Some(&k) = self.index.get(&d) {
            return Ok(k);
        }
        if d.comp > 6 {
            return Err(FeError::invalid(
                &self.file,
                line,
                format!("DOF {d} not supported (only directions 1..6, or 0 for a scalar point)"),
            ));
        }
        match self.kinds.entry(d.id) {
            Entry::Occupied(e) if e.get().0 != d.is_scalar() => {
                let (first, at) = *e.get();
                let (was, now) = if first {
                    ("a scalar point (direction 0)", "a node direction")
                } else {
                    ("a node direction", "a scalar point (direction 0)")
                };
                return Err(FeError::invalid(
                    &self.file,
                    line,
                    format!("ID {} is {now} here but {was} on line {at}", d.id),
                ));
            }
            Entry::Occupied(_) => {}
            Entry::Vacant(e) => {
                e.insert((d.is_scalar(), line));
            }
        }
        if self.dofs.len() >= u32::MAX as usize {
            return Err(FeError::invalid(&self.file, line, "more than 2^32 DOFs"));
        }
        let k = self.dofs.len() as u32;
        self.index.insert(d, k);
        self.dofs.push(d);
        Ok(k)
    }

    /// Add the term `(row, col) = value` read on `line` (1-based, below 2^31); either
    /// triangle.
    pub fn push(&mut self, row: Dof, col: Dof, value: f64, line: usize) -> Result<(), FeError> {
        if !value.is_finite() {
            return Err(FeError::invalid(
                &self.file,
                line,
                format!("term ({row}, {col}) = {value}: expected a finite number"),
            ));
        }
        if line >= 1 << 31 {
            return Err(FeError::invalid(&self.file, line, "more than 2^31 lines"));
        }
        let r = self.number(row, line)?;
        let c = self.number(col, line)?;
        self.terms.push((r, c, line as u32, value));
        Ok(())
    }

    /// The matrix over the sorted DOFs.
    pub fn finish(self) -> Result<DofMatrix, FeError> {
        if self.terms.is_empty() {
            return Err(FeError::invalid(&self.file, 0, "no matrix terms"));
        }
        let mut order: Vec<u32> = (0..self.dofs.len() as u32).collect();
        order.sort_unstable_by_key(|&k| self.dofs[k as usize].order_key());
        let mut new_of = vec![0u32; order.len()];
        for (new, &old) in order.iter().enumerate() {
            new_of[old as usize] = new as u32;
        }
        let dofs: Vec<Dof> = order.iter().map(|&k| self.dofs[k as usize]).collect();
        drop(self.index);
        let mut coo = Coo::new(dofs.len());
        coo.reserve(self.terms.len());
        for (r, c, line, v) in self.terms {
            coo.push(
                new_of[r as usize] as usize,
                new_of[c as usize] as usize,
                v,
                line as usize,
            );
        }
        let matrix = coo.finish(&self.file, &dofs)?;
        Ok(DofMatrix { dofs, matrix })
    }
}

impl DofMatrix {
    /// The same matrix over `dofs`, a sorted superset of [`DofMatrix::dofs`] (rows of DOFs
    /// it does not mention are zero): to put K and M on one DOF list.
    pub fn on(&self, dofs: &[Dof]) -> Result<SymCsc, FeError> {
        let mut to = Vec::with_capacity(self.dofs.len());
        for d in &self.dofs {
            match dofs.binary_search_by_key(&d.order_key(), Dof::order_key) {
                Ok(k) => to.push(k),
                Err(_) => {
                    return Err(FeError::invalid(
                        "",
                        0,
                        format!("DOF {d} is not in the target DOF list"),
                    ));
                }
            }
        }
        let a = &self.matrix;
        let n = dofs.len();
        // A sorted superset keeps the order, so each column stays sorted.
        let mut col_ptr = vec![0usize; n + 1];
        for (j, &t) in to.iter().enumerate() {
            col_ptr[t + 1] = a.col_ptr()[j + 1] - a.col_ptr()[j];
        }
        for j in 0..n {
            col_ptr[j + 1] += col_ptr[j];
        }
        let row_idx = a.row_idx().iter().map(|&r| to[r]).collect();
        SymCsc::from_parts(n, col_ptr, row_idx, a.values().to_vec())
            .map_err(|e| FeError::invalid("", 0, e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn g(id: i64, comp: u8) -> Dof {
        Dof::new(id, comp)
    }

    #[test]
    fn dofs_sorted_and_terms_placed_whatever_the_order() {
        let mut s = TermStream::new("k.mtx");
        s.push(g(7, 3), g(1, 1), -4.0, 1).unwrap();
        s.push(g(1, 1), g(1, 1), 2.0, 2).unwrap();
        s.push(g(900001, 0), g(900001, 0), 1.0, 3).unwrap();
        s.push(g(7, 3), g(7, 3), 5.0, 4).unwrap();
        let m = s.finish().unwrap();
        assert_eq!(m.dofs, vec![g(1, 1), g(7, 3), g(900001, 0)]);
        assert_eq!(m.matrix.get(0, 1), -4.0);
        assert_eq!(m.matrix.get(2, 2), 1.0);
        let wide = m.on(&[g(1, 1), g(2, 1), g(7, 3), g(900001, 0)]).unwrap();
        assert_eq!(wide.get(0, 2), -4.0);
        assert_eq!(wide.get(1, 1), 0.0);
        assert_eq!(wide.get(3, 3), 1.0);
    }

    #[test]
    fn mixed_kinds_and_repeats_are_refused_with_lines() {
        let mut s = TermStream::new("k.pch");
        s.push(g(5, 0), g(5, 0), 1.0, 10).unwrap();
        let e = s.push(g(5, 2), g(5, 0), 1.0, 12).unwrap_err();
        assert_eq!(
            e.to_string(),
            "k.pch:12: ID 5 is a node direction here but a scalar point (direction 0) on line 10"
        );
        let mut s = TermStream::new("k.mtx");
        s.push(g(1, 1), g(2, 1), 1.0, 3).unwrap();
        s.push(g(2, 1), g(2, 1), 1.0, 4).unwrap();
        s.push(g(1, 1), g(2, 1), 1.0, 9).unwrap();
        let e = s.finish().unwrap_err();
        assert_eq!(
            e.to_string(),
            "k.mtx:9: term (1.1, 2.1) given twice: first on line 3"
        );
    }
}
