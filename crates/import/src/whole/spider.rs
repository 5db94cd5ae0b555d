//! Spiders built from a node set, for a model that has none where the body connects:
//! `--spider NSET:rigid` ties the set's nodes rigidly to a new six-DOF node at their
//! centroid (Nastran RBE2-like, CalculiX `*RIGID BODY`-like).
//!
//! The set's translations become dependent: a node at `x` moves by `u_r + theta x (x -
//! x_r)` (a set node's own rotations 4-6, on shells, by `theta`), where `u_r` and `theta`
//! are the new node's six DOFs. With T the map from the remaining DOFs and the new six to
//! the old ones, the model's matrices become `T^T K T` and `T^T M T`, formed term by term
//! on the stored triangle (each dependent DOF expands into at most three). A rigid motion
//! of the whole stays a rigid motion, so a free model's K keeps the six rigid motions in
//! its null space (checked by the import like any model's).
//!
//! A distributing spider (RBE3-like, `NSET:distributing`) is built by
//! [`super::distributing`]: its node's motion is a weighted mean of the set's, and the set
//! stays free to deform.

use std::collections::HashMap;

use crate::fe::{Deck, Dof};
use crate::sparse::SymCsc;
use crate::{ImportError, whole::WholeModel};

/// What a `--spider` asks for.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SpiderSpec {
    /// The node set (upper case).
    pub nset: String,
    /// Rigid (RBE2-like); `false` is distributing.
    pub rigid: bool,
}

impl SpiderSpec {
    /// Parse `NSET:rigid` or `NSET:distributing`.
    pub fn parse(s: &str) -> Result<SpiderSpec, ImportError> {
        let bad = || {
            ImportError::BadSpider(format!(
                "expected NSET:rigid or NSET:distributing, got '{s}'"
            ))
        };
        let (set, kind) = s.split_once(':').ok_or_else(bad)?;
        let rigid = match kind.to_ascii_lowercase().as_str() {
            "rigid" => true,
            "distributing" => false,
            _ => return Err(bad()),
        };
        if set.trim().is_empty() {
            return Err(bad());
        }
        Ok(SpiderSpec {
            nset: set.trim().to_uppercase(),
            rigid,
        })
    }
}

/// A spider built from a node set: its new node and how it was made (for the report).
#[derive(Debug, Clone)]
pub struct BuiltSpider {
    /// The new six-DOF node.
    pub id: i64,
    /// What it is, in words.
    pub what: String,
}

/// Build every spider of `specs` into the model: the model over the remaining DOFs and
/// each spider's new node (numbered after the deck's largest node), and the deck with
/// those nodes' coordinates (the sets' centroids, area-weighted for a distributing one).
/// Returns the new nodes too.
pub fn build_spiders(
    model: &WholeModel,
    deck: &Deck,
    deck_name: &str,
    specs: &[SpiderSpec],
) -> Result<(WholeModel, Deck, Vec<BuiltSpider>), ImportError> {
    let mut model = model.clone();
    let mut deck = deck.clone();
    let mut ids = Vec::new();
    for spec in specs {
        let set = deck.nsets.get(&spec.nset).ok_or_else(|| {
            let mut known: Vec<&String> = deck.nsets.keys().collect();
            known.sort();
            ImportError::BadSpider(format!(
                "no node set {} in {deck_name} (sets: {})",
                spec.nset,
                known
                    .iter()
                    .map(|s| s.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
        let id = deck.nodes.keys().next_back().copied().unwrap_or(0) + 1;
        let (m2, centre, what) = if spec.rigid {
            let (m2, centre) = rigid(&model, set, &deck, deck_name, id)?;
            let what = format!(
                "node {id}, a rigid spider on set {} built at its centroid",
                spec.nset
            );
            (m2, centre, what)
        } else {
            let (m2, b) =
                super::distributing::distributing(&model, &spec.nset, set, &deck, deck_name, id)?;
            let what = format!(
                "node {id}, a distributing spider on set {} ({} faces, {} weighted nodes) \
                 built at its area-weighted centre",
                spec.nset, b.faces, b.weighted
            );
            (m2, b.centre, what)
        };
        model = m2;
        deck.nodes.insert(id, centre);
        ids.push(BuiltSpider { id, what });
    }
    Ok((model, deck, ids))
}

/// Tie `set` rigidly to a new node `id` at the set's centroid (see the module text).
fn rigid(
    model: &WholeModel,
    set: &[i64],
    deck: &Deck,
    deck_name: &str,
    id: i64,
) -> Result<(WholeModel, [f64; 3]), ImportError> {
    let mut centre = [0.0; 3];
    for n in set {
        let x = deck
            .nodes
            .get(n)
            .ok_or_else(|| ImportError::NoCoordinates {
                id: *n,
                file: deck_name.to_string(),
            })?;
        for k in 0..3 {
            centre[k] += x[k] / set.len() as f64;
        }
    }
    let in_set: HashMap<i64, [f64; 3]> = set
        .iter()
        .map(|n| {
            let x = deck.nodes[n];
            (*n, [x[0] - centre[0], x[1] - centre[1], x[2] - centre[2]])
        })
        .collect();
    // New DOF order: the independent DOFs as they were, then the new node's six.
    let mut dofs = Vec::new();
    let mut index = vec![usize::MAX; model.dofs.len()];
    for (old, d) in model.dofs.iter().enumerate() {
        if !(in_set.contains_key(&d.id) && d.comp >= 1) {
            index[old] = dofs.len();
            dofs.push(*d);
        }
    }
    if dofs.len() == model.dofs.len() {
        return Err(ImportError::BadSpider(format!(
            "no node of the set has equations in {} (held, or not the model's nodes)",
            model.name
        )));
    }
    let first = dofs.len();
    dofs.extend((1..=6).map(|c| Dof::new(id, c)));
    // Each old DOF as a combination of new ones.
    let expand = |old: usize| -> Vec<(usize, f64)> {
        let d = model.dofs[old];
        match in_set.get(&d.id) {
            Some(p) if d.comp >= 1 => {
                let c = d.comp as usize - 1;
                if c >= 3 {
                    return vec![(first + c, 1.0)];
                }
                let mut e = vec![(first + c, 1.0)];
                for k in 0..3 {
                    // (e_k x p)_c
                    let v = match (k, c) {
                        (0, 1) => -p[2],
                        (0, 2) => p[1],
                        (1, 0) => p[2],
                        (1, 2) => -p[0],
                        (2, 0) => -p[1],
                        (2, 1) => p[0],
                        _ => 0.0,
                    };
                    if v != 0.0 {
                        e.push((first + 3 + k, v));
                    }
                }
                e
            }
            _ => vec![(index[old], 1.0)],
        }
    };
    let map: Vec<Vec<(usize, f64)>> = (0..model.dofs.len()).map(expand).collect();
    let n = dofs.len();
    let k = transform(&model.k, &map, n).map_err(|e| ImportError::Whole(e.to_string()))?;
    let m = transform(&model.m, &map, n).map_err(|e| ImportError::Whole(e.to_string()))?;
    Ok((
        WholeModel {
            dofs,
            k,
            m,
            name: model.name.clone(),
        },
        centre,
    ))
}

/// `T^T A T` for `T` given row by row (`map[i]`: the new columns of old DOF i and their
/// coefficients), on A's stored upper triangle (see the module text).
pub(crate) fn transform(
    a: &SymCsc,
    map: &[Vec<(usize, f64)>],
    n: usize,
) -> Result<SymCsc, crate::sparse::SolveError> {
    let (ptr, rows, values) = (a.col_ptr(), a.row_idx(), a.values());
    let mut terms: Vec<(usize, usize, f64)> = Vec::with_capacity(values.len() + 64);
    for j in 0..a.n() {
        for p in ptr[j]..ptr[j + 1] {
            let (i, v) = (rows[p], values[p]);
            for &(r, x) in &map[i] {
                for &(s, y) in &map[j] {
                    if i == j {
                        // A full diagonal term: every ordered pair, kept once in the upper.
                        if r <= s {
                            terms.push((s, r, v * x * y));
                        }
                    } else {
                        // Two full terms (i, j) and (j, i): one upper entry, twice on
                        // the diagonal.
                        let w = if r == s { 2.0 } else { 1.0 };
                        terms.push((r.max(s), r.min(s), w * v * x * y));
                    }
                }
            }
        }
    }
    // (column, row) order; equal positions summed.
    terms.sort_unstable_by_key(|&(c, r, _)| (c, r));
    let mut col_ptr = vec![0usize; n + 1];
    let mut row_idx = Vec::with_capacity(terms.len());
    let mut vals: Vec<f64> = Vec::with_capacity(terms.len());
    let mut last = None;
    for (c, r, v) in terms {
        if last == Some((c, r)) {
            if let Some(x) = vals.last_mut() {
                *x += v;
            }
            continue;
        }
        last = Some((c, r));
        col_ptr[c + 1] += 1;
        row_idx.push(r);
        vals.push(v);
    }
    for c in 0..n {
        col_ptr[c + 1] += col_ptr[c];
    }
    SymCsc::from_parts(n, col_ptr, row_idx, vals)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_option() {
        let s = SpiderSpec::parse("holeB:rigid").unwrap();
        assert_eq!((s.nset.as_str(), s.rigid), ("HOLEB", true));
        assert!(!SpiderSpec::parse("A:distributing").unwrap().rigid);
        let e = SpiderSpec::parse("A:glued").unwrap_err().to_string();
        assert!(
            e.contains("expected NSET:rigid or NSET:distributing"),
            "{e}"
        );
        assert!(SpiderSpec::parse(":rigid").is_err());
    }

    /// `T^T A T` term by term equals the dense product.
    #[test]
    fn transform_is_t_transpose_a_t() {
        let n = 3;
        let a = [4.0, 1.0, 0.5, 1.0, 3.0, -1.0, 0.5, -1.0, 2.0];
        let csc = SymCsc::from_dense(n, &a);
        // Old 0 -> new 0; old 1 -> new 1 + 2 new 2; old 2 -> new 1 - new 2.
        let map = vec![
            vec![(0, 1.0)],
            vec![(1, 1.0), (2, 2.0)],
            vec![(1, 1.0), (2, -1.0)],
        ];
        let got = transform(&csc, &map, 3).unwrap().to_dense();
        let t = [[1.0, 0.0, 0.0], [0.0, 1.0, 2.0], [0.0, 1.0, -1.0]];
        for p in 0..3 {
            for q in 0..3 {
                let mut want = 0.0;
                for i in 0..3 {
                    for j in 0..3 {
                        want += t[i][p] * a[i * n + j] * t[j][q];
                    }
                }
                assert!(
                    (got[p * 3 + q] - want).abs() < 1e-12,
                    "({p},{q}) {} {want}",
                    got[p * 3 + q]
                );
            }
        }
    }
}
