//! DOF bookkeeping: one order for K and M, unit conversion, dead DOFs dropped, and massless
//! DOFs condensed out exactly.
//!
//! Order: grid DOFs by (id, component), then scalar points ([`Dof::order_key`]). A DOF
//! whose K and M rows are both zero is dead: dropped, with a note. A DOF whose M row is
//! zero carries no inertia, so it is condensed out statically, exactly:
//! `K~ = K_aa - K_az K_zz^-1 K_za`, and its values in any mode are rebuilt as
//! `z = T a` with `T = -K_zz^-1 K_za`.

use nalgebra::DMatrix;

use super::report::{Report, Warning};
use super::{ImportError, MAX_DENSE_DOFS, Units};
use crate::fe::{Dof, SymMatrix};

/// K and M as dense matrices over one DOF list.
#[derive(Debug, Clone)]
pub struct DofMatrices {
    /// DOFs in order.
    pub dofs: Vec<Dof>,
    /// Stiffness.
    pub k: DMatrix<f64>,
    /// Mass.
    pub m: DMatrix<f64>,
}

impl DofMatrices {
    /// K and M over the union of their DOFs (a DOF missing from one matrix has a zero row
    /// there). Refuses more than [`MAX_DENSE_DOFS`] DOFs before allocating.
    pub fn from_matrices(k: &SymMatrix, m: &SymMatrix) -> Result<DofMatrices, ImportError> {
        let mut dofs: Vec<Dof> = k.dofs.iter().chain(&m.dofs).copied().collect();
        dofs.sort_by_key(Dof::order_key);
        dofs.dedup();
        let n = dofs.len();
        if n > MAX_DENSE_DOFS {
            return Err(ImportError::TooLarge(n));
        }
        let index = |d: &Dof| {
            dofs.binary_search_by_key(&d.order_key(), Dof::order_key)
                .expect("DOF is in the union")
        };
        let dense = |s: &SymMatrix| {
            let map: Vec<usize> = s.dofs.iter().map(index).collect();
            let mut a = DMatrix::zeros(n, n);
            for &(i, j, v) in &s.terms {
                a[(map[i], map[j])] = v;
                a[(map[j], map[i])] = v;
            }
            a
        };
        Ok(DofMatrices {
            k: dense(k),
            m: dense(m),
            dofs,
        })
    }

    /// Convert to the target units (see [`super::units`]).
    pub fn convert(&mut self, u: &Units) {
        let f: Vec<f64> = self
            .dofs
            .iter()
            .map(|d| {
                if (1..=3).contains(&d.comp) {
                    u.length
                } else {
                    1.0
                }
            })
            .collect();
        let fe = u.energy();
        let fm = u.mass * u.length * u.length;
        let n = self.dofs.len();
        for j in 0..n {
            for i in 0..n {
                self.k[(i, j)] *= fe / (f[i] * f[j]);
                self.m[(i, j)] *= fm / (f[i] * f[j]);
            }
        }
    }
}

/// The model after dead-DOF removal and massless condensation.
#[derive(Debug, Clone)]
pub struct Reduced {
    /// Every DOF kept (dead ones removed), in order.
    pub all: Vec<Dof>,
    /// Positions in `all` of the DOFs with mass (the a-set), ascending.
    pub a: Vec<usize>,
    /// Positions in `all` of the massless DOFs (the z-set), ascending.
    pub z: Vec<usize>,
    /// Condensed stiffness over the a-set.
    pub k: DMatrix<f64>,
    /// Mass over the a-set.
    pub m: DMatrix<f64>,
    /// `z = T a`, `|z| x |a|`.
    pub t: DMatrix<f64>,
    /// The powers of two K and M were scaled by ([`super::scale`]); every output is
    /// scaled back.
    pub scale: super::scale::Scale,
}

impl Reduced {
    /// The a-set DOFs.
    pub fn a_dofs(&self) -> Vec<Dof> {
        self.a.iter().map(|&i| self.all[i]).collect()
    }

    /// Every grid ID, ascending.
    pub fn grid_ids(&self) -> Vec<i64> {
        let mut ids: Vec<i64> = self
            .all
            .iter()
            .filter(|d| !d.is_scalar())
            .map(|d| d.id)
            .collect();
        ids.dedup();
        ids
    }

    /// Vectors over the a-set (columns) extended to every DOF of `all`.
    pub fn expand(&self, va: &DMatrix<f64>) -> DMatrix<f64> {
        let mut out = DMatrix::zeros(self.all.len(), va.ncols());
        let vz = &self.t * va;
        for (r, &i) in self.a.iter().enumerate() {
            out.row_mut(i).copy_from(&va.row(r));
        }
        for (r, &i) in self.z.iter().enumerate() {
            out.row_mut(i).copy_from(&vz.row(r));
        }
        out
    }

    /// Unit loads on every DOF of the grid points `ids`, as loads on the a-set
    /// (`E^T e_d`, `E = [I; T]`): one column per grid DOF.
    pub fn grid_loads(&self, ids: &[i64]) -> DMatrix<f64> {
        let picked: Vec<usize> = (0..self.all.len())
            .filter(|&i| !self.all[i].is_scalar() && ids.contains(&self.all[i].id))
            .collect();
        let mut f = DMatrix::zeros(self.a.len(), picked.len());
        for (col, &i) in picked.iter().enumerate() {
            if let Ok(r) = self.a.binary_search(&i) {
                f[(r, col)] = 1.0;
            } else if let Ok(r) = self.z.binary_search(&i) {
                for c in 0..self.a.len() {
                    f[(c, col)] = self.t[(r, c)];
                }
            }
        }
        f
    }
}

fn row_is_zero(a: &DMatrix<f64>, i: usize) -> bool {
    a.row(i).iter().all(|&v| v == 0.0)
}

fn sub(a: &DMatrix<f64>, rows: &[usize], cols: &[usize]) -> DMatrix<f64> {
    DMatrix::from_fn(rows.len(), cols.len(), |i, j| a[(rows[i], cols[j])])
}

/// Drop dead DOFs and condense massless ones (see the module text).
pub fn reduce(model: DofMatrices, report: &mut Report) -> Result<Reduced, ImportError> {
    let n = model.dofs.len();
    let keep: Vec<usize> = (0..n)
        .filter(|&i| {
            let dead = row_is_zero(&model.k, i) && row_is_zero(&model.m, i);
            if dead {
                report.dead.push(model.dofs[i].to_string());
            }
            !dead
        })
        .collect();
    if keep.is_empty() {
        return Err(ImportError::Empty);
    }
    let all: Vec<Dof> = keep.iter().map(|&i| model.dofs[i]).collect();
    let k = sub(&model.k, &keep, &keep);
    let m = sub(&model.m, &keep, &keep);
    let (mut a, mut z) = (Vec::new(), Vec::new());
    for (i, dof) in all.iter().enumerate() {
        if row_is_zero(&m, i) {
            z.push(i);
        } else {
            if row_is_zero(&k, i) {
                report.warnings.push(Warning::Text(format!(
                    "DOF {dof} has mass but no stiffness"
                )));
            }
            a.push(i);
        }
    }
    report.condensed = z.iter().map(|&i| all[i].to_string()).collect();
    let kaa = sub(&k, &a, &a);
    let maa = sub(&m, &a, &a);
    if z.is_empty() {
        return Ok(Reduced {
            t: DMatrix::zeros(0, a.len()),
            all,
            a,
            z,
            k: kaa,
            m: maa,
            scale: super::scale::Scale::ONE,
        });
    }
    let kzz = sub(&k, &z, &z);
    let kza = sub(&k, &z, &a);
    let Some(chol) = kzz.clone().cholesky() else {
        let dof = all[z[failing_pivot(&kzz)]];
        return Err(ImportError::MasslessSingular {
            count: z.len(),
            dof,
        });
    };
    let t = -chol.solve(&kza);
    let mut kt = kaa + kza.transpose() * &t;
    kt = (&kt + kt.transpose()) * 0.5;
    Ok(Reduced {
        all,
        a,
        z,
        k: kt,
        m: maa,
        t,
        scale: super::scale::Scale::ONE,
    })
}

/// The first pivot at which a Cholesky factorisation of the symmetric `a` fails (a
/// pivot at or below 1e-12 of the largest diagonal), for the error message.
fn failing_pivot(a: &DMatrix<f64>) -> usize {
    let n = a.nrows();
    let scale = a.diagonal().amax().max(f64::MIN_POSITIVE);
    let mut l = a.clone();
    for p in 0..n {
        let d = l[(p, p)];
        if d <= 1e-12 * scale {
            return p;
        }
        let s = d.sqrt();
        for i in p..n {
            l[(i, p)] /= s;
        }
        for j in p + 1..n {
            for i in j..n {
                l[(i, j)] -= l[(i, p)] * l[(j, p)];
            }
        }
    }
    n.saturating_sub(1)
}

/// Check a `--nodes` list against the grid points; returns it in the order given.
pub fn check_nodes(ids: &[i64], grid: &[i64]) -> Result<Vec<i64>, ImportError> {
    if ids.is_empty() {
        return Err(ImportError::BadNodes("no node given".into()));
    }
    for (k, id) in ids.iter().enumerate() {
        if ids[..k].contains(id) {
            return Err(ImportError::BadNodes(format!("node {id} given twice")));
        }
        if grid.binary_search(id).is_err() {
            return Err(ImportError::BadNodes(format!(
                "node {id} is not a grid point of the matrices"
            )));
        }
    }
    Ok(ids.to_vec())
}
