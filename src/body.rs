//! The validated flexible body: the file's numbers as the matrices the solvers want,
//! with the checks Radioss does not make. No I/O here.

use nalgebra::{DMatrix, DVector, Matrix3};

use crate::fxb::FxbFile;

mod checks;
pub mod invariance;
mod load;
pub mod mass_props;
mod modal;
pub mod placement;

pub use checks::{BodyError, FREQ_RATIO, MAX_LOCAL_MODES, Places, check_scene_body};
pub use load::{LoadError, LoadOptions, load};
pub use modal::Modal;

/// Rayleigh damping `C_L = alpha diag(m_L) + beta K_L` (block 4); zero when absent.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Rayleigh {
    /// Mass-proportional coefficient (1/s).
    pub alpha: f64,
    /// Stiffness-proportional coefficient (s).
    pub beta: f64,
}

/// Whether a body moves as a whole: the file's Iblo flag as a type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Support {
    /// Iblo = 1: the body is held in its frame, no rigid modes (nR = 0).
    Blocked,
    /// Iblo = 0: the body moves freely, 12 rigid modes (15 with Irot = 1).
    Free,
}

impl Support {
    /// The support the file's Iblo flag states.
    pub fn from_iblo(iblo: bool) -> Support {
        if iblo {
            Support::Blocked
        } else {
            Support::Free
        }
    }

    /// The file's Iblo flag for this support.
    pub fn iblo(self) -> bool {
        self == Support::Blocked
    }

    /// Number of rigid modes a body with this support and rotational DOFs `irot` has:
    /// 0 blocked, 12 free, 15 free with rotations.
    pub fn rigid_modes(self, irot: bool) -> usize {
        match (self, irot) {
            (Support::Blocked, _) => 0,
            (Support::Free, false) => 12,
            (Support::Free, true) => 15,
        }
    }
}

/// A flexible body ready for simulation: built only by the validated constructors
/// ([`Body::from_fxb`], [`Body::from_parts`], [`load`], and the crate's scene-file reader
/// and node selection of a valid body), so that every `Body` holds the invariants the
/// solvers rely on without checking them again:
///
/// - shape: `6 N` mode rows; `nR` = [`Support::rigid_modes`] (0, 12 or 15); M_R
///   `nR x nR`; nine M_C,kl and K_C,kl blocks of `nR x nL`; K_L `nL x nL`; m_L, the
///   frequencies and the modal solution of length `nL`; `nbstat <= nL`;
/// - values: every number finite; m_L > 0 and normal; P0 a rotation (1e-6); K_L positive
///   semi-definite; Rayleigh coefficients >= 0; for a free body M_R positive
///   semi-definite with a positive translation mass and definite on the rigid motions;
/// - the modal solution is the modes of the current (K_L, m_L).
///
/// The fields are private for that reason: read them through the accessors
/// ([`Body::m_l`], [`Body::phi_r`], ...); change a body by taking its [`BodyParts`],
/// editing them and building it again with [`Body::from_parts`], which checks them.
///
/// Mode matrices have one row per node DOF: row `6 * n + c` is node `n` (position in
/// `node_ids`), component `c` (X Y Z XX YY ZZ). Local modes are in the local frame,
/// rigid modes in the global frame (FORMULATION.md section 1).
///
/// Load a fixture and read its frequencies: the first is the cantilever's first bending
/// mode, which Euler-Bernoulli theory puts at `1.8751^2 / (2 pi) sqrt(E I / (rho A L^4))`
/// = 6.684133 Hz (steel, 1 m, 12 x 8 mm, bending about the thin side).
///
/// ```
/// use std::path::Path;
///
/// let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/cantilever.fxb");
/// let body = fxbody::body::load(&path, Default::default())?;
/// assert_eq!((body.nnodes(), body.nl(), body.nr()), (21, 20, 0)); // blocked: no rigid modes
/// let f1 = body.frequencies_hz()[0];
/// assert!((f1 - 6.684133).abs() < 1e-5 * 6.684133, "{f1} Hz");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// A body cannot be written field by field outside the crate, nor changed in place:
///
/// ```compile_fail,E0451
/// # use nalgebra::{DMatrix, DVector, Matrix3};
/// let body = fxbody::body::Body {
///     node_ids: vec![1],
///     nbstat: 0,
///     irot: false,
///     support: fxbody::body::Support::Blocked,
///     ifile: false,
///     p0: Matrix3::identity(),
///     freq_file: 0.0,
///     damping: None,
///     phi_r: DMatrix::zeros(6, 0),
///     phi_l: DMatrix::zeros(6, 0),
///     m_l: DVector::zeros(0),
///     k_l: DMatrix::zeros(0, 0),
///     m_r: DMatrix::zeros(0, 0),
///     m_c: Vec::new(),
///     k_c: Vec::new(),
///     frequencies_hz: Vec::new(),
///     modal: fxbody::body::Modal::of(&DMatrix::zeros(0, 0), &DVector::zeros(0)),
///     warnings: Vec::new(),
/// };
/// ```
///
/// ```compile_fail,E0616
/// # use std::path::Path;
/// let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/cantilever.fxb");
/// let mut body = fxbody::body::load(&path, Default::default()).unwrap();
/// body.m_l[0] = -1.0; // the fields are private: no unchecked edit
/// ```
#[derive(Debug, Clone)]
pub struct Body {
    /// Node IDs in file order.
    pub(crate) node_ids: Vec<i64>,
    /// Number of static modes (the first `nbstat` local modes).
    pub(crate) nbstat: usize,
    /// Nodes carry rotational DOFs (15 rigid modes when free).
    pub(crate) irot: bool,
    /// Blocked or free (the file's Iblo).
    pub(crate) support: Support,
    /// Ifile flag, kept only to write the file back; no effect on results.
    pub(crate) ifile: bool,
    /// Initial frame P0 (column j = local axis j in global components).
    pub(crate) p0: Matrix3<f64>,
    /// Largest eigenfrequency as stored in the file (Hz).
    pub(crate) freq_file: f64,
    /// Rayleigh damping, `None` when the file has no block 4.
    pub(crate) damping: Option<Rayleigh>,
    /// Rigid modes, `6 N x nR` (empty for a blocked body).
    pub(crate) phi_r: DMatrix<f64>,
    /// Local modes, `6 N x nL`.
    pub(crate) phi_l: DMatrix<f64>,
    /// Diagonal local mass m_L.
    pub(crate) m_l: DVector<f64>,
    /// Local stiffness K_L, symmetric `nL x nL`.
    pub(crate) k_l: DMatrix<f64>,
    /// Rigid mass M_R, symmetric `nR x nR` (empty for a blocked body).
    pub(crate) m_r: DMatrix<f64>,
    /// Coupled mass sub-blocks M_C,kl at index `3(k-1)+(l-1)`, each `nR x nL`.
    pub(crate) m_c: Vec<DMatrix<f64>>,
    /// Coupled stiffness sub-blocks K_C,kl at index `3(k-1)+(l-1)`, each `nR x nL`.
    pub(crate) k_c: Vec<DMatrix<f64>>,
    /// Eigenfrequencies of (K_L, m_L) in Hz, ascending (from [`Body::modal`]).
    pub(crate) frequencies_hz: Vec<f64>,
    /// The modes of (K_L, m_L), solved once: the checks, the reduction and the blocked
    /// solvers all read this one solution. [`Body::solve_modes`] renews it (and
    /// `frequencies_hz`) after K_L or m_L change.
    pub(crate) modal: Modal,
    /// Non-fatal findings (for example stored Freq far from the computed one).
    pub(crate) warnings: Vec<String>,
}

/// The numbers of a body as plain data, unchecked: what [`Body::into_parts`] gives and
/// [`Body::from_parts`] checks and builds a body from. The field meanings and layouts
/// are [`Body`]'s; the frequencies are derived from `modal`.
#[derive(Debug, Clone)]
pub struct BodyParts {
    /// Node IDs in file order.
    pub node_ids: Vec<i64>,
    /// Number of static modes (the first `nbstat` local modes).
    pub nbstat: usize,
    /// Nodes carry rotational DOFs (15 rigid modes when free).
    pub irot: bool,
    /// Blocked or free.
    pub support: Support,
    /// Ifile flag, kept only to write the file back.
    pub ifile: bool,
    /// Initial frame P0 (column j = local axis j in global components).
    pub p0: Matrix3<f64>,
    /// Largest eigenfrequency as stored in the file (Hz).
    pub freq_file: f64,
    /// Rayleigh damping.
    pub damping: Option<Rayleigh>,
    /// Rigid modes, `6 N x nR`.
    pub phi_r: DMatrix<f64>,
    /// Local modes, `6 N x nL`.
    pub phi_l: DMatrix<f64>,
    /// Diagonal local mass m_L.
    pub m_l: DVector<f64>,
    /// Local stiffness K_L, `nL x nL`.
    pub k_l: DMatrix<f64>,
    /// Rigid mass M_R, `nR x nR`.
    pub m_r: DMatrix<f64>,
    /// Coupled mass sub-blocks M_C,kl, nine of `nR x nL`.
    pub m_c: Vec<DMatrix<f64>>,
    /// Coupled stiffness sub-blocks K_C,kl, nine of `nR x nL`.
    pub k_c: Vec<DMatrix<f64>>,
    /// The modes of (K_L, m_L); [`BodyParts::solve_modes`] solves them again.
    pub modal: Modal,
}

impl BodyParts {
    /// The parts of a `.fxb` file, assembled in the storage orders of FORMULATION.md
    /// section 1 after checking only that its block lengths fit its header (errors name
    /// `source`): the file's numbers as they are, for a look at the storage orders or an
    /// edit before [`Body::from_parts`] checks them.
    pub fn assemble(file: &FxbFile, source: &str) -> Result<BodyParts, BodyError> {
        checks::check_counts(file, source)?;
        Ok(Body::assemble_with(
            file,
            file.rigid_modes.clone(),
            file.local_modes.clone(),
        ))
    }

    /// Solve the modes of the current (K_L, m_L) into `modal`, after an edit of either.
    pub fn solve_modes(&mut self) {
        self.modal = Modal::of(&self.k_l, &self.m_l);
    }

    /// Largest eigenfrequency (Hz) of the stored modes, 0 without local modes.
    pub fn freq_max_hz(&self) -> f64 {
        self.modal.frequencies_hz().last().copied().unwrap_or(0.0)
    }

    /// The first shape rule [`Body`] states that these parts break, as an error naming
    /// `source`.
    fn check_shape(&self, source: &str) -> Result<(), BodyError> {
        let rows = 6 * self.node_ids.len();
        let nl = self.m_l.len();
        let nr = self.support.rigid_modes(self.irot);
        let shape = |what: &'static str, expected: (usize, usize), found: (usize, usize)| {
            Err(BodyError::Shape {
                name: source.into(),
                what,
                expected,
                found,
            })
        };
        let dims = |m: &DMatrix<f64>| (m.nrows(), m.ncols());
        for (what, m, expected) in [
            ("the rigid modes", &self.phi_r, (rows, nr)),
            ("the local modes", &self.phi_l, (rows, nl)),
            ("K_L", &self.k_l, (nl, nl)),
            ("M_R", &self.m_r, (nr, nr)),
            ("the mode shapes", &self.modal.shapes, (nl, nl)),
        ] {
            if dims(m) != expected {
                return shape(what, expected, dims(m));
            }
        }
        for (what, blocks) in [("M_C", &self.m_c), ("K_C", &self.k_c)] {
            if blocks.len() != 9 {
                return shape(what, (9, 1), (blocks.len(), 1));
            }
            if let Some(b) = blocks.iter().find(|b| dims(b) != (nr, nl)) {
                return shape(what, (nr, nl), dims(b));
            }
        }
        let (lam, order) = (self.modal.lambda.len(), self.modal.ascending.len());
        if (lam, order) != (nl, nl) {
            return shape("the eigenvalues and their order", (nl, nl), (lam, order));
        }
        if self.nbstat > nl {
            return shape("the static modes", (nl, 1), (self.nbstat, 1));
        }
        let numbers = [
            &self.phi_r,
            &self.phi_l,
            &self.k_l,
            &self.m_r,
            &self.modal.shapes,
        ]
        .into_iter()
        .flat_map(|m| m.iter())
        .chain(self.m_l.iter())
        .chain(self.modal.lambda.iter())
        .chain(self.m_c.iter().chain(&self.k_c).flat_map(|m| m.iter()))
        .chain(self.p0.iter())
        .chain(std::iter::once(&self.freq_file));
        if let Some(&value) = numbers.into_iter().find(|v| !v.is_finite()) {
            return Err(BodyError::PartNotFinite {
                name: source.into(),
                value,
            });
        }
        Ok(())
    }
}

impl Body {
    /// Check `parts` and build a body of them: the shape rules of [`Body`], every number
    /// finite, and the physical checks of a body read from a file (P0 a rotation, m_L
    /// positive and normal, Rayleigh coefficients >= 0, `modal` the modes of (K_L, m_L),
    /// K_L positive semi-definite, the stored Freq against the modes, a free body's rigid
    /// modes the affine field and M_R definite on the rigid motions). `source` names the
    /// body in messages. The way to change a body: [`Body::into_parts`], edit, rebuild.
    pub fn from_parts(parts: BodyParts, source: &str) -> Result<Body, BodyError> {
        Body::from_parts_at(parts, source, &Places::PARTS)
    }

    /// [`Body::from_parts`], naming the checked quantities' places in the file they came
    /// from (`places`): the scene-file reader's constructor.
    pub(crate) fn from_parts_at(
        parts: BodyParts,
        source: &str,
        places: &Places,
    ) -> Result<Body, BodyError> {
        parts.check_shape(source)?;
        let body = Body::unchecked(parts);
        let mut body = body;
        body.warnings = checks::check_parts(&body, places, source)?;
        body.warnings.extend(invariance::check(&body, source));
        Ok(body)
    }

    /// The body's numbers as plain data, to edit and build again with
    /// [`Body::from_parts`].
    pub fn into_parts(self) -> BodyParts {
        BodyParts {
            node_ids: self.node_ids,
            nbstat: self.nbstat,
            irot: self.irot,
            support: self.support,
            ifile: self.ifile,
            p0: self.p0,
            freq_file: self.freq_file,
            damping: self.damping,
            phi_r: self.phi_r,
            phi_l: self.phi_l,
            m_l: self.m_l,
            k_l: self.k_l,
            m_r: self.m_r,
            m_c: self.m_c,
            k_c: self.k_c,
            modal: self.modal,
        }
    }

    /// Node IDs in file order.
    pub fn node_ids(&self) -> &[i64] {
        &self.node_ids
    }

    /// Number of static modes (the first `nbstat` local modes).
    pub fn nbstat(&self) -> usize {
        self.nbstat
    }

    /// Nodes carry rotational DOFs (Irot = 1: 15 rigid modes when free).
    pub fn irot(&self) -> bool {
        self.irot
    }

    /// Blocked or free.
    pub fn support(&self) -> Support {
        self.support
    }

    /// Blocked body (Iblo = 1): no rigid motion, nR = 0.
    pub fn is_blocked(&self) -> bool {
        self.support == Support::Blocked
    }

    /// Ifile flag, kept only to write the file back; no effect on results.
    pub fn ifile(&self) -> bool {
        self.ifile
    }

    /// Initial frame P0 (column j = local axis j in global components), a rotation.
    pub fn p0(&self) -> &Matrix3<f64> {
        &self.p0
    }

    /// Largest eigenfrequency as stored in the file (Hz).
    pub fn freq_file(&self) -> f64 {
        self.freq_file
    }

    /// Rayleigh damping, `None` when the file has no block 4.
    pub fn damping(&self) -> Option<Rayleigh> {
        self.damping
    }

    /// Rigid modes, `6 N x nR` (empty for a blocked body).
    pub fn phi_r(&self) -> &DMatrix<f64> {
        &self.phi_r
    }

    /// Local modes, `6 N x nL`.
    pub fn phi_l(&self) -> &DMatrix<f64> {
        &self.phi_l
    }

    /// Diagonal local mass m_L (every entry positive and normal).
    pub fn m_l(&self) -> &DVector<f64> {
        &self.m_l
    }

    /// Local stiffness K_L, symmetric positive semi-definite `nL x nL`.
    pub fn k_l(&self) -> &DMatrix<f64> {
        &self.k_l
    }

    /// Rigid mass M_R, symmetric `nR x nR` (empty for a blocked body).
    pub fn m_r(&self) -> &DMatrix<f64> {
        &self.m_r
    }

    /// Coupled mass sub-blocks M_C,kl at index `3(k-1)+(l-1)`, nine of `nR x nL`.
    pub fn m_c(&self) -> &[DMatrix<f64>] {
        &self.m_c
    }

    /// Coupled stiffness sub-blocks K_C,kl at index `3(k-1)+(l-1)`, nine of `nR x nL`.
    pub fn k_c(&self) -> &[DMatrix<f64>] {
        &self.k_c
    }

    /// Eigenfrequencies of (K_L, m_L) in Hz, ascending.
    pub fn frequencies_hz(&self) -> &[f64] {
        &self.frequencies_hz
    }

    /// The modes of (K_L, m_L), solved once: the checks, the reduction and the blocked
    /// solvers all read this one solution.
    pub fn modal(&self) -> &Modal {
        &self.modal
    }

    /// Non-fatal findings (for example stored Freq far from the computed one).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Number of local modes nL.
    pub fn nl(&self) -> usize {
        self.m_l.len()
    }

    /// Number of rigid modes nR (0 for a blocked body).
    pub fn nr(&self) -> usize {
        self.phi_r.ncols()
    }

    /// Number of nodes N.
    pub fn nnodes(&self) -> usize {
        self.node_ids.len()
    }

    /// Largest computed eigenfrequency of (K_L, m_L) in Hz (0 without local modes). The
    /// solvers and `info` take the stable step from this, not from the stored Freq.
    pub fn freq_max_hz(&self) -> f64 {
        self.frequencies_hz.last().copied().unwrap_or(0.0)
    }

    /// Stable step of the explicit scheme for this body: [`stable_step`] of the largest
    /// computed eigenfrequency and the stiffness damping beta. The one place both
    /// explicit solvers and `fxbody info` get it from.
    pub fn explicit_stable_step(&self) -> f64 {
        stable_step(self.freq_max_hz(), self.damping.map_or(0.0, |d| d.beta))
    }

    /// Global initial position of every node of a free body from its rigid modes, with
    /// the frame origin L0 at the global origin; `None` for a blocked body.
    ///
    /// Rigid mode 1 is `X e_1` on the translation rows, mode 4 is `Y e_1` and mode 7 is
    /// `Z e_1` (FORMULATION.md section 1), so the x-translation rows of modes 1, 4 and 7
    /// give each node's local coordinates `(X, Y, Z)`, and `x0 = P0 (X, Y, Z)`. These
    /// fix every node relative to L0: a coordinate file only places L0
    /// ([`placement::check_coords`]).
    pub fn rigid_mode_positions(&self) -> Option<Vec<[f64; 3]>> {
        if self.nr() < 12 {
            return None;
        }
        Some(
            (0..self.nnodes())
                .map(|n| {
                    let r = 6 * n;
                    let local = nalgebra::Vector3::new(
                        self.phi_r[(r, 0)],
                        self.phi_r[(r, 3)],
                        self.phi_r[(r, 6)],
                    );
                    let x = self.p0 * local;
                    [x[0], x[1], x[2]]
                })
                .collect(),
        )
    }

    /// Solve the modes of the current (K_L, m_L) into [`Body::modal`] and
    /// [`Body::frequencies_hz`]: called by assembly and by whatever replaces the
    /// local modes (the reduction), so that the two never describe another K_L.
    pub(crate) fn solve_modes(&mut self) {
        self.modal = Modal::of(&self.k_l, &self.m_l);
        self.frequencies_hz = self.modal.frequencies_hz();
    }

    /// Position of a node ID in the node list.
    pub fn node_index(&self, id: i64) -> Option<usize> {
        self.node_ids.iter().position(|&n| n == id)
    }

    /// Check a raw file and assemble it into a body: counts consistent, values finite,
    /// P0 a rotation (1e-6), m_L > 0, Freq > 0 when there are local modes, K_L positive
    /// semi-definite, and for free bodies M_R positive semi-definite and definite on the
    /// rigid motions (a body whose nodes are all on one line is refused). M_R itself may
    /// be singular: the affine rigid modes of a flat body have a null space that the
    /// frame constraints remove. A stored Freq more than 1% from the largest computed
    /// eigenfrequency is a warning in [`Body::warnings`], and so is a free body whose
    /// rigid part does not turn with it ([`invariance::check`]). `source` names the file
    /// in messages.
    pub fn from_fxb(file: &FxbFile, source: &str) -> Result<Body, BodyError> {
        Body::from_fxb_owned(file.clone(), source)
    }

    /// [`Body::from_fxb`], taking the file: its mode blocks become the mode matrices
    /// without a copy (they are already stored mode by mode), which spares a large body
    /// tens of MB of memory traffic.
    pub fn from_fxb_owned(mut file: FxbFile, source: &str) -> Result<Body, BodyError> {
        checks::check_raw(&file, source)?;
        let rigid = std::mem::take(&mut file.rigid_modes);
        let local = std::mem::take(&mut file.local_modes);
        let mut body = Body::unchecked(Body::assemble_with(&file, rigid, local));
        body.warnings = checks::check_body(&body, source)?;
        body.warnings.extend(invariance::check(&body, source));
        Ok(body)
    }

    /// Whether node `node_index` (position in `node_ids`) has rotational DOFs: Irot = 1
    /// and some rigid or local mode has a nonzero rotational component there.
    pub fn node_has_rotation(&self, node_index: usize) -> bool {
        if !self.irot || node_index >= self.nnodes() {
            return false;
        }
        let rows = 6 * node_index + 3..6 * node_index + 6;
        [&self.phi_r, &self.phi_l]
            .iter()
            .any(|m| rows.clone().any(|r| m.row(r).iter().any(|&v| v != 0.0)))
    }

    /// Total mass of a free body, `s^T M_R s` for a unit uniform translation along x
    /// (`s = e1 + e4 + e7 + e10`); `None` for a blocked body, whose file has no M_R.
    pub fn total_mass(&self) -> Option<f64> {
        if self.nr() < 12 {
            return None;
        }
        let s = [0, 3, 6, 9];
        Some(
            s.iter()
                .flat_map(|&i| s.iter().map(move |&j| (i, j)))
                .map(|ij| self.m_r[ij])
                .sum(),
        )
    }

    /// Assemble the matrices from the raw file, following the storage orders of
    /// FORMULATION.md section 1, with the file's rigid and local mode blocks given apart
    /// (and taken): mode after mode, node after node, so they are the mode matrices'
    /// columns. The counts in `file` must already be consistent (`checks::check_raw`).
    fn assemble_with(file: &FxbFile, rigid: Vec<f64>, local: Vec<f64>) -> BodyParts {
        let n = file.nbnod;
        let nl = file.nbmod;
        let ns = file.nbstat;
        let nr = file.nr();
        let modes = |data: Vec<f64>, count: usize| DMatrix::from_vec(6 * n, count, data);
        let mut k_l = DMatrix::zeros(nl, nl);
        for r in 0..ns {
            // Row r (0-based) starts after sum_{q<r} (nl - q) values.
            let start = r * (2 * nl - r + 1) / 2;
            for c in r..nl {
                let v = file.k_full[start + (c - r)];
                k_l[(r, c)] = v;
                k_l[(c, r)] = v;
            }
        }
        for r in ns..nl {
            k_l[(r, r)] = file.k_diag[r - ns];
        }
        let mut m_r = DMatrix::zeros(nr, nr);
        let mut idx = 0;
        for i in 0..nr {
            for j in i..nr {
                m_r[(i, j)] = file.m_r[idx];
                m_r[(j, i)] = file.m_r[idx];
                idx += 1;
            }
        }
        let sub = |data: &[f64]| -> Vec<DMatrix<f64>> {
            if data.is_empty() {
                return vec![DMatrix::zeros(nr, nl); 9];
            }
            (0..9)
                .map(|m| DMatrix::from_fn(nr, nl, |i, j| data[m * nr * nl + i * nl + j]))
                .collect()
        };
        let p = &file.p0;
        let m_l = DVector::from_column_slice(&file.m_l);
        let modal = Modal::of(&k_l, &m_l);
        BodyParts {
            node_ids: file.node_ids.clone(),
            nbstat: ns,
            irot: file.irot,
            support: Support::from_iblo(file.iblo),
            ifile: file.ifile,
            p0: Matrix3::new(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8]),
            freq_file: file.freq,
            damping: file.damping.map(|(alpha, beta)| Rayleigh { alpha, beta }),
            phi_r: modes(rigid, nr),
            phi_l: modes(local, nl),
            m_l,
            k_l,
            m_r,
            m_c: sub(&file.m_c),
            k_c: sub(&file.k_c),
            modal,
        }
    }

    /// A body of `parts`, its frequencies from their modes, unchecked: for the
    /// constructors, after or before their checks.
    fn unchecked(parts: BodyParts) -> Body {
        Body {
            frequencies_hz: parts.modal.frequencies_hz(),
            node_ids: parts.node_ids,
            nbstat: parts.nbstat,
            irot: parts.irot,
            support: parts.support,
            ifile: parts.ifile,
            p0: parts.p0,
            freq_file: parts.freq_file,
            damping: parts.damping,
            phi_r: parts.phi_r,
            phi_l: parts.phi_l,
            m_l: parts.m_l,
            k_l: parts.k_l,
            m_r: parts.m_r,
            m_c: parts.m_c,
            k_c: parts.k_c,
            modal: parts.modal,
            warnings: Vec::new(),
        }
    }
}

/// Eigenfrequencies (Hz, ascending) of `K x = w^2 diag(m) x` ([`Modal::frequencies_hz`]
/// of [`Modal::of`]), for matrices that are not a body's.
pub fn eigenfrequencies_hz(k: &DMatrix<f64>, m: &DVector<f64>) -> Vec<f64> {
    Modal::of(k, m).frequencies_hz()
}

/// Stable step of the explicit central-difference scheme for a largest frequency
/// `freq_hz` (FORMULATION.md section 4): `2/omega` undamped, and with stiffness damping
/// `beta > 0` (lagged, so it shortens the step) [`damped_stable_step`] of
/// `kappa = beta omega / 2`. Infinite for a body with no stiffness.
pub fn stable_step(freq_hz: f64, beta: f64) -> f64 {
    let omega = 2.0 * std::f64::consts::PI * freq_hz;
    if omega <= 0.0 {
        return f64::INFINITY;
    }
    if beta > 0.0 {
        damped_stable_step(omega, 0.5 * beta * omega)
    } else {
        2.0 / omega
    }
}

/// Stable step of the central-difference scheme for a mode of circular frequency
/// `omega > 0` whose lagged damping coefficient is `c = 2 kappa omega` (`kappa >= 0`, the
/// damping ratio of the lagged terms): the positive root `s` of `omega^2 s^2 + 2 c s = 4`,
/// `(sqrt(c^2 + 4 omega^2) - c) / omega^2`. That form overflows in `c^2` (an infinite step
/// above c = 1.3e154) and cancels to zero or far off between (3.8 times too long near
/// c = 1e8 omega); the same root is `2 / (omega (kappa + sqrt(kappa^2 + 1)))`, a sum of
/// positive terms, computed here with `kappa` factored out above 1 so that nothing
/// overflows for any finite `kappa`: the result is correct to a few ulps wherever it is a
/// normal number, and underflows to a subnormal or 0 only when the true step does.
pub fn damped_stable_step(omega: f64, kappa: f64) -> f64 {
    if kappa <= 1.0 {
        2.0 / (omega * (kappa + kappa.hypot(1.0)))
    } else {
        (2.0 / kappa) / omega / (1.0 + 1.0f64.hypot(1.0 / kappa))
    }
}
