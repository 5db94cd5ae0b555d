//! Whole finite-element models as sparse matrices, and the eigen-solver and static modes
//! that reduce them to a flexible body.
//!
//! A solid part meshed for a finite-element code has 10^4 to 10^6 DOFs; a flexible body
//! needs only the modes below the highest frequency a simulation excites plus a static
//! mode per connection DOF. This module computes exactly those from the model's stiffness K
//! and mass M, without ever forming a dense matrix of the model's size.
//!
//! # Reading
//! - [`crate::fe::calculix`]: `*FREQUENCY, SOLVER=MATRIXSTORAGE` output (`JOB.sti`, `JOB.mas`,
//!   `JOB.dof`), streamed in chunks and hand-parsed (integers by hand, reals through
//!   Clinger's exact fast path with the standard parser behind it).
//! - [`TermStream`]: terms keyed by DOF, for the Abaqus and Nastran DMIG readers, which
//!   produce `(row DOF, column DOF, value, line)`.
//! - Both gather terms in [`Coo`] (20 bytes a term) and compress them into [`SymCsc`], the
//!   upper triangle by columns (16 bytes a term). Every error names the file, the line
//!   and what was expected; a term given twice, or both triangles that disagree, are
//!   refused.
//!
//! # The method
//! The eigenproblem is `K x = lambda M x` with K and M symmetric, M positive
//! semi-definite (spider nodes and other massless DOFs), and K positive definite for a
//! blocked body or singular with the six rigid motions for a free one. `lambda = (2 pi
//! f)^2`; the task is every pair with `f <= fmax`, with none missed.
//!
//! 1. **Ordering.** An approximate minimum degree ordering of the pattern of K and M
//!    keeps the fill of the factors small; it and the supernodal structure are computed
//!    once and serve every shift ([`factor::Analysis`]).
//! 2. **Count.** `K - lambda_max M = L D L^T` (faer's supernodal LDL^T). By Sylvester's law
//!    of inertia, the number of negative pivots in D is the number of eigenvalues below
//!    `lambda_max`: the solver knows how many it must find before it starts
//!    ([`factor::Factor::inertia`]).
//! 3. **Shift and invert.** The working factor is of `K - sigma0 M`: `sigma0 = 0` for a
//!    blocked body, `sigma0 = -1e-4 lambda_max` for a free one (K itself is singular).
//!    The operator `(K - sigma0 M)^-1 M` has the eigenvalues `1 / (lambda - sigma0)`:
//!    the lowest modes become the largest and best separated ones.
//! 4. **Block Lanczos** ([`lanczos`]) builds an M-orthonormal basis of the Krylov space
//!    of that operator, a block of 16 vectors per step (one solve with 16 right-hand
//!    sides reads the factor once for all of them), fully reorthogonalised in the
//!    M-inner product so that no eigenvalue is lost or found twice. The rigid motions of
//!    a free body, when given, are kept out of the basis. It stops when as many Ritz
//!    pairs as the count promised have converged below the limit; if the basis fills
//!    first, the converged pairs are locked and a new run continues from the best
//!    unconverged Ritz vectors.
//! 5. **Check.** Each pair's backward error `|K x - lambda M x|` is computed with K and M
//!    themselves ([`eigen::RESIDUAL_BOUND`]).
//! 6. **Static modes** ([`statics`]): blocked, the columns of `K^-1` at the connection
//!    DOFs; free, inertia-relief attachment modes (a unit load balanced by the rigid
//!    body's inertia, the response with no rigid part), solved by a two-level iteration
//!    (a solve with the working factor, then a Galerkin correction in the kept modes)
//!    that shrinks its error about 10^4-fold a step.
//!
//! With the kept eigenvectors and the static modes in a reduced basis, statics at the
//! connections are exact and every frequency below `fmax` is the full model's.
//!
//! # Determinism
//! Every parallel step is split in a fixed way ([`crate::par`]): faer's calls run at a fixed two
//! threads, solves and tall products are cut in two fixed halves. The results are the
//! same bits whatever the rayon pool (tested with 1, 2 and 3 threads).
//!
//! # Spiders and rigid motions
//! [`rigid::rigid_motions`] builds the six rigid motions over a DOF list from node
//! coordinates, reading a CalculiX `*RIGID BODY` ROT node's directions 1-3 as the spider's
//! rotations; [`rigid::null_residual`] checks that they lie in K's null space.

pub mod coo;
pub mod csc;
pub mod dense;
pub mod eigen;
pub mod error;
pub mod factor;
pub mod lanczos;
pub mod rigid;
pub mod statics;
pub mod terms;
pub mod text;

pub use crate::fe::calculix::{MatrixStorage, read_job};
pub use coo::Coo;
pub use csc::SymCsc;
pub use error::SolveError;
pub use terms::{DofMatrix, TermStream};
