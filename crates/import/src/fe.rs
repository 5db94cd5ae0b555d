//! FE matrix files: readers only, no physics.
//!
//! A user who reduced a structure in a finite-element code brings its stiffness and mass
//! matrices and its node coordinates; `fxbody import` builds a body from them. This
//! module reads those files into one neutral form, [`SymMatrix`] over [`Dof`]s, and node
//! coordinates, and says exactly where and why a file cannot be read. It decides nothing
//! about the physics: whether K and M mention the same DOFs, whether M is positive, and
//! which nodes need coordinates are the builder's questions.
//!
//! Formats:
//! - Nastran `DMIG` ([`read_dmig`]): as Nastran punches it (small-field header, large-field
//!   column cards, values touching the field before them), as pyNastran writes it (large
//!   field throughout), small field, and free field (commas);
//! - Abaqus `*MATRIX OUTPUT, FORMAT=MATRIX INPUT` lines `node, dof, node, dof, value`
//!   ([`read_abaqus`]);
//! - CalculiX matrix storage, `.sti`/`.mas` with `.dof` ([`read_calculix`]; the whole
//!   model, for the sparse path: [`calculix::read_job`]);
//! - a CalculiX deck's nodes, node sets and `*RIGID BODY` spiders ([`read_deck`]);
//! - coordinates from Nastran `GRID` cards, a Radioss `/NODE` deck, Abaqus `*NODE`, or CSV
//!   `id,x,y,z` ([`read_model_coords`]).

mod abaqus;
pub mod calculix;
mod cards;
mod coords;
pub mod deck;
mod dmig;
mod error;
mod fields;
mod terms;

use std::fmt;

pub use abaqus::read_abaqus;
pub use calculix::read_calculix;
pub use coords::read_model_coords;
pub use deck::{Deck, FACE_TYPES, RigidBody, read_deck};
pub use dmig::read_dmig;
pub use error::{Cols, FeError, Loc};
pub use fields::nastran_real;
pub use terms::{SYM_NOISE, SYM_REL_TOL};

/// One degree of freedom of an FE model: a GRID/node component 1..6 (1-3 translations,
/// 4-6 rotations, global frame), or a scalar point (comp 0: e.g. a Craig-Bampton modal
/// coordinate).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Dof {
    /// Grid, node or scalar-point ID.
    pub id: i64,
    /// Component: 1..6 for a grid point, 0 for a scalar point.
    pub comp: u8,
}

impl Dof {
    /// Grid or node `id`, component `comp`.
    pub fn new(id: i64, comp: u8) -> Dof {
        Dof { id, comp }
    }

    /// Whether this is a scalar point (component 0).
    pub fn is_scalar(&self) -> bool {
        self.comp == 0
    }

    /// The key that orders DOFs as [`SymMatrix::dofs`] holds them: grid DOFs by
    /// (id, comp), then scalar points by id.
    pub fn order_key(&self) -> (bool, i64, u8) {
        (self.is_scalar(), self.id, self.comp)
    }
}

/// `id.comp`, the way Nastran, Abaqus and CalculiX users write a DOF (`12.3`; a scalar
/// point is `900001.0`).
impl fmt::Display for Dof {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}", self.id, self.comp)
    }
}

/// A symmetric matrix as read: the DOFs it mentions and its upper triangle.
#[derive(Debug, Clone, PartialEq)]
pub struct SymMatrix {
    /// DMIG name, or the file stem.
    pub name: String,
    /// Every DOF mentioned, sorted: GRID DOFs by (id, comp), then scalar points by id.
    pub dofs: Vec<Dof>,
    /// (i, j) indices into dofs with i <= j, each pair once, zeros kept out, sorted by
    /// (i, j).
    pub terms: Vec<(usize, usize, f64)>,
    /// DMIG only: the fewest significant digits of a value that fills its 8-column
    /// small field (rounded to fit it), when there is one; `None` otherwise.
    pub small_field_digits: Option<u32>,
}

impl SymMatrix {
    /// The full matrix, row-major, `dofs.len()` squared entries: for tests and small
    /// matrices (a 3000-DOF matrix takes 72 MB).
    pub fn to_dense(&self) -> Vec<f64> {
        let n = self.dofs.len();
        let mut a = vec![0.0; n * n];
        for &(i, j, v) in &self.terms {
            a[i * n + j] = v;
            a[j * n + i] = v;
        }
        a
    }

    /// The matrix `a` over `dofs` (the DOF of each row, in any order), in this form: over
    /// the DOFs its stored terms mention, sorted, zeros left out.
    pub fn from_csc(name: String, dofs: &[Dof], a: &crate::sparse::SymCsc) -> SymMatrix {
        let n = dofs.len();
        let (ptr, rows, values) = (a.col_ptr(), a.row_idx(), a.values());
        let mut mentioned = vec![false; n];
        for j in 0..n {
            for &i in &rows[ptr[j]..ptr[j + 1]] {
                mentioned[i] = true;
                mentioned[j] = true;
            }
        }
        let mut order: Vec<usize> = (0..n).filter(|&k| mentioned[k]).collect();
        order.sort_by_key(|&k| dofs[k].order_key());
        let mut rank = vec![0; n];
        for (new, &old) in order.iter().enumerate() {
            rank[old] = new;
        }
        let mut terms = Vec::with_capacity(values.len());
        for j in 0..n {
            for p in ptr[j]..ptr[j + 1] {
                if values[p] != 0.0 {
                    let (r, c) = (rank[rows[p]], rank[j]);
                    terms.push((r.min(c), r.max(c), values[p]));
                }
            }
        }
        terms.sort_unstable_by_key(|&(i, j, _)| (i, j));
        SymMatrix {
            name,
            dofs: order.iter().map(|&k| dofs[k]).collect(),
            terms,
            small_field_digits: None,
        }
    }

    /// The value at DOFs `a`, `b` (0 when not stored or when a DOF is not in the matrix).
    pub fn get(&self, a: Dof, b: Dof) -> f64 {
        let find = |d: Dof| {
            self.dofs
                .binary_search_by_key(&d.order_key(), Dof::order_key)
                .ok()
        };
        let (Some(i), Some(j)) = (find(a), find(b)) else {
            return 0.0;
        };
        let key = (i.min(j), i.max(j));
        self.terms
            .binary_search_by_key(&key, |&(i, j, _)| (i, j))
            .map_or(0.0, |k| self.terms[k].2)
    }
}

/// A refusal of the input checks ([`fxbody::fxb::input`]) or an I/O error, naming `path`:
/// a device, FIFO or oversized file is refused with the kind of file found.
fn input_error(path: &std::path::Path, e: std::io::Error) -> FeError {
    let file = path.display().to_string();
    if e.kind() == std::io::ErrorKind::InvalidInput {
        FeError::invalid(&file, 0, e.to_string())
    } else {
        FeError::Io { file, source: e }
    }
}

/// Read a whole coordinate file, checked as every command's input is (a regular file no
/// larger than its kind can need), naming it in the error.
fn read_file(path: &std::path::Path) -> Result<Vec<u8>, FeError> {
    use fxbody::fxb::input::{Limit, read_bounded};
    read_bounded(path, Limit::Coordinates).map_err(|e| input_error(path, e))
}

/// Open a matrix or DOF file to stream it, checked the same way; the file and its size.
fn open(path: &std::path::Path) -> Result<(std::fs::File, u64), FeError> {
    use fxbody::fxb::input::{Limit, open_bounded};
    open_bounded(path, Limit::Matrix).map_err(|e| input_error(path, e))
}

/// The file stem, the name of a matrix that has no name inside its file.
fn stem(path: &std::path::Path) -> String {
    path.file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned())
}
