//! fxbody-sparse: whole FE models as sparse matrices, and the eigen-solver and static
//! modes that reduce them.

pub mod calculix;
pub mod coo;
pub mod csc;
pub mod dense;
pub mod dof;
pub mod eigen;
pub mod error;
pub mod factor;
pub mod lanczos;
pub mod par;
pub mod rigid;
pub mod statics;
pub mod terms;
pub mod text;

pub use calculix::{MatrixStorage, read_job};
pub use coo::Coo;
pub use csc::SymCsc;
pub use dof::Dof;
pub use error::{ReadError, SolveError};
pub use terms::{DofMatrix, TermStream};
