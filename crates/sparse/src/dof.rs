//! Degrees of freedom as FE codes name them: a node and a direction.

use std::fmt;

/// One degree of freedom of an FE model: a node's direction 1..6 (1-3 translations,
/// 4-6 rotations, global frame), or a scalar point (direction 0: e.g. a Craig-Bampton
/// modal coordinate). A CalculiX `*RIGID BODY` ROT node carries the spider's rotations in
/// its directions 1-3; that reading is the caller's ([`crate::rigid`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Dof {
    /// Node, grid or scalar-point ID.
    pub id: i64,
    /// Direction: 1..6 for a node, 0 for a scalar point.
    pub comp: u8,
}

impl Dof {
    /// A node's direction `comp`.
    pub fn new(id: i64, comp: u8) -> Dof {
        Dof { id, comp }
    }

    /// Whether this is a scalar point (direction 0).
    pub fn is_scalar(&self) -> bool {
        self.comp == 0
    }

    /// The key that orders DOFs in a term stream's result ([`crate::TermStream`]): node
    /// DOFs by (id, direction), then scalar points by id.
    pub fn order_key(&self) -> (bool, i64, u8) {
        (self.is_scalar(), self.id, self.comp)
    }
}

/// `id.comp`, the way Nastran, Abaqus and CalculiX users write a DOF (`12.3`).
impl fmt::Display for Dof {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}", self.id, self.comp)
    }
}
