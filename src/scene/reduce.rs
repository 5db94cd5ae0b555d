//! Model no more than a scene needs: keep the nodes it couples to and the modes its
//! frequencies reach, and represent the dropped modes by their static contribution.
//!
//! Mode truncation. The modes of (K_L, m_L), `K_L Psi = diag(m_L) Psi Omega^2` with
//! `Psi^T diag(m_L) Psi = I`, are split at `fmax` into kept (k) and dropped (d). The
//! truncated body has the local modes `Phi_L Psi_k`: `m_L' = 1`, `K_L' = Omega_k^2`,
//! `M_C,kl' = M_C,kl Psi_k`, `K_C,kl' = K_C,kl Psi_k`, no static modes, and Freq the
//! largest kept frequency. It is an ordinary [`Body`], so every solver runs it unchanged
//! and the explicit method's stable step follows the kept modes only (for a free body,
//! the kept modes coupled to the rigid motion: `solver::free::explicit`). Rayleigh damping
//! stays Rayleigh (`alpha I + beta Omega_k^2`).
//!
//! Static (residual-flexibility) correction. The dropped modes answer a slowly varying
//! load quasi-statically: `q_d = Omega_d^-2 Psi_d^T F_L`. At the exposed nodes this is
//! `u = R f` with `R = G Psi_d Omega_d^-2 Psi_d^T G^T` (`G` the exposed-node rows of
//! `Phi_L`, local frame), which equals `G (K_L^-1 - Psi_k Omega_k^-2 Psi_k^T) G^T` but
//! needs no inverse of K_L. [`Residual`] holds R; [`crate::solver::residual`] adds it to
//! the outputs. For a free body the dropped modes' share of the frame-acceleration load
//! (`M_C^T a_R`, the inertia relief) is left out: the correction is the clamped-frame
//! static flexibility of the dropped modes, exact for blocked bodies only.
//!
//! Node selection ([`select_nodes`]) keeps the chosen nodes' rows of the rigid and local
//! modes. M_R, M_C and K_C are mode-space matrices and stay exact: M_R of a node subset
//! still describes the whole body's inertia, which is what a scene coupling to a few
//! nodes of a heavy body wants.

use nalgebra::{DMatrix, DVector};

mod participation;

pub use participation::{Participation, effective_mass, static_participation};

use crate::body::Body;
use crate::fxb::FxbFile;

/// Relative slack when comparing a frequency with `fmax`, so that `fmax` equal to a
/// printed frequency keeps that mode.
const FMAX_SLACK: f64 = 1e-9;

/// Why a reduction was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReduceError {
    /// `fmax` not finite and positive.
    #[error("the cut-off frequency must be finite and > 0 Hz, got {}", crate::num::num(*.0))]
    BadFmax(f64),
    /// A node ID that is not in the body.
    #[error("node {0} is not in the body")]
    UnknownNode(i64),
    /// No node chosen, or one chosen twice.
    #[error("node selection: {0}")]
    BadSelection(String),
}

/// The modes of (K_L, m_L), ascending: mass-normalised `psi` (`nL x nL`, column j is mode
/// j) and circular frequencies `omega` (rad/s; round-off negatives read as 0).
#[derive(Debug, Clone)]
pub struct ModalBasis {
    /// Mode shapes in local-mode coordinates, `psi^T diag(m_L) psi = I`.
    pub psi: DMatrix<f64>,
    /// Circular frequencies, ascending.
    pub omega: Vec<f64>,
}

impl ModalBasis {
    /// The body's modes ([`Body::modal`]) sorted by frequency.
    pub fn of(body: &Body) -> ModalBasis {
        let modal = &body.modal;
        let nl = modal.ascending.len();
        let psi = DMatrix::from_fn(nl, nl, |i, j| modal.shapes[(i, modal.ascending[j])]);
        let omega = modal
            .ascending
            .iter()
            .map(|&j| modal.lambda[j].max(0.0).sqrt())
            .collect();
        ModalBasis { psi, omega }
    }

    /// Frequencies in Hz, ascending.
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.omega
            .iter()
            .map(|w| w / (2.0 * std::f64::consts::PI))
            .collect()
    }

    /// How many modes have a frequency at or below `fmax_hz` (with a 1e-9 relative
    /// slack, so that a printed frequency used as fmax keeps its mode).
    pub fn count_below(&self, fmax_hz: f64) -> usize {
        let limit = fmax_hz * (1.0 + FMAX_SLACK);
        self.frequencies_hz()
            .iter()
            .filter(|&&f| f <= limit)
            .count()
    }
}

/// The static flexibility of the dropped modes at some nodes, local frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Residual {
    /// `R`, `6m x 6m` for m nodes: row/column `6 k + c` is node k, component c
    /// (X Y Z XX YY ZZ), local frame; displacement = R load.
    pub r: DMatrix<f64>,
    /// Number of dropped modes it represents.
    pub dropped: usize,
}

/// A body truncated to the modes up to `fmax`, and what that dropped.
#[derive(Debug, Clone)]
pub struct Truncation {
    /// The body in the kept modal basis (all nodes of the input body).
    pub body: Body,
    /// Modes kept.
    pub kept: usize,
    /// Frequencies of the kept modes, Hz.
    pub kept_hz: Vec<f64>,
    /// Frequencies of the dropped modes, Hz.
    pub dropped_hz: Vec<f64>,
    /// Dropped-mode flexibility in local-mode coordinates, `Psi_d Omega_d^-2 Psi_d^T`
    /// (`nL x nL` of the input body).
    pub flex: DMatrix<f64>,
    /// Local modes of the input body (for [`Truncation::residual`] at any node set).
    phi_l: DMatrix<f64>,
}

impl Residual {
    /// Whether the dropped modes rotate exposed node `k` (index into the scene's exposed
    /// nodes): a non-zero rotational diagonal entry of R. R is positive semi-definite, so
    /// a zero diagonal means zero rows: such a node neither rotates under nor transmits a
    /// moment through the dropped modes.
    pub fn rotates(&self, k: usize) -> bool {
        (6 * k + 3..6 * k + 6).any(|i| i < self.r.nrows() && self.r[(i, i)] != 0.0)
    }
}

impl Truncation {
    /// Residual flexibility at the nodes `nodes` (indices into the body's node list).
    pub fn residual(&self, nodes: &[usize]) -> Residual {
        let g = DMatrix::from_fn(6 * nodes.len(), self.phi_l.ncols(), |row, j| {
            self.phi_l[(6 * nodes[row / 6] + row % 6, j)]
        });
        Residual {
            r: &g * &self.flex * g.transpose(),
            dropped: self.dropped_hz.len(),
        }
    }
}

/// Keep the modes of (K_L, m_L) up to `fmax_hz` (see the module notes).
pub fn truncate(body: &Body, fmax_hz: f64) -> Result<Truncation, ReduceError> {
    if !(fmax_hz.is_finite() && fmax_hz > 0.0) {
        return Err(ReduceError::BadFmax(fmax_hz));
    }
    let basis = ModalBasis::of(body);
    let nl = body.nl();
    let k = basis.count_below(fmax_hz);
    let psi_k = basis.psi.columns(0, k).into_owned();
    let psi_d = basis.psi.columns(k, nl - k);
    let inv_w2 = DVector::from_iterator(nl - k, basis.omega[k..].iter().map(|w| 1.0 / (w * w)));
    let flex = psi_d * DMatrix::from_diagonal(&inv_w2) * psi_d.transpose();
    let w2 = DVector::from_iterator(k, basis.omega[..k].iter().map(|w| w * w));
    let mut out = body.clone();
    out.phi_l = &body.phi_l * &psi_k;
    out.m_l = DVector::from_element(k, 1.0);
    out.k_l = DMatrix::from_diagonal(&w2);
    out.nbstat = 0;
    out.m_c = body.m_c.iter().map(|m| m * &psi_k).collect();
    out.k_c = body.k_c.iter().map(|m| m * &psi_k).collect();
    out.solve_modes();
    let hz = basis.frequencies_hz();
    out.freq_file = hz[..k].last().copied().unwrap_or(0.0);
    out.warnings = Vec::new();
    Ok(Truncation {
        body: out,
        kept: k,
        kept_hz: hz[..k].to_vec(),
        dropped_hz: hz[k..].to_vec(),
        flex,
        phi_l: body.phi_l.clone(),
    })
}

/// Node indices of the IDs `ids`, in that order; an unknown or repeated ID is an error.
pub fn node_indices(body: &Body, ids: &[i64]) -> Result<Vec<usize>, ReduceError> {
    if ids.is_empty() {
        return Err(ReduceError::BadSelection("no node chosen".into()));
    }
    let mut out = Vec::with_capacity(ids.len());
    for (k, &id) in ids.iter().enumerate() {
        if ids[..k].contains(&id) {
            return Err(ReduceError::BadSelection(format!("node {id} chosen twice")));
        }
        out.push(body.node_index(id).ok_or(ReduceError::UnknownNode(id))?);
    }
    Ok(out)
}

/// The body restricted to the nodes `nodes` (indices, in the new file order): their rows
/// of the rigid and local modes; every mode-space matrix unchanged.
pub fn select_nodes(body: &Body, nodes: &[usize]) -> Body {
    let rows = |m: &DMatrix<f64>| {
        DMatrix::from_fn(6 * nodes.len(), m.ncols(), |row, j| {
            m[(6 * nodes[row / 6] + row % 6, j)]
        })
    };
    // Field by field: cloning the body first would copy every node's modes (tens of MB
    // for a large body) only to replace them.
    Body {
        node_ids: nodes.iter().map(|&n| body.node_ids[n]).collect(),
        nbstat: body.nbstat,
        irot: body.irot,
        support: body.support,
        ifile: body.ifile,
        p0: body.p0,
        freq_file: body.freq_file,
        damping: body.damping,
        phi_r: rows(&body.phi_r),
        phi_l: rows(&body.phi_l),
        m_l: body.m_l.clone(),
        k_l: body.k_l.clone(),
        m_r: body.m_r.clone(),
        m_c: body.m_c.clone(),
        k_c: body.k_c.clone(),
        frequencies_hz: body.frequencies_hz.clone(),
        modal: body.modal.clone(),
        warnings: Vec::new(),
    }
}

/// The file blocks of a body, in the storage orders of FORMULATION.md section 1, for
/// [`crate::fxb::write`]. The inverse of [`Body::from_fxb`].
pub fn to_fxb(body: &Body) -> FxbFile {
    let n = body.nnodes();
    let nl = body.nl();
    let ns = body.nbstat;
    let nr = body.nr();
    let modes = |m: &DMatrix<f64>| -> Vec<f64> {
        (0..m.ncols())
            .flat_map(|j| (0..6 * n).map(move |row| (j, row)))
            .map(|(j, row)| m[(row, j)])
            .collect()
    };
    let k_full = (0..ns)
        .flat_map(|r| (r..nl).map(move |c| (r, c)))
        .map(|rc| body.k_l[rc])
        .collect();
    let k_diag = (ns..nl).map(|r| body.k_l[(r, r)]).collect();
    let m_r = (0..nr)
        .flat_map(|i| (i..nr).map(move |j| (i, j)))
        .map(|ij| body.m_r[ij])
        .collect();
    let sub = |blocks: &[DMatrix<f64>]| -> Vec<f64> {
        if body.is_blocked() || nl == 0 {
            return Vec::new();
        }
        blocks
            .iter()
            .flat_map(|b| (0..nr).flat_map(move |i| (0..nl).map(move |j| b[(i, j)])))
            .collect()
    };
    let p = &body.p0;
    FxbFile {
        nbmod: nl,
        nbstat: ns,
        nbnod: n,
        irot: body.irot,
        idamp: body.damping.is_some(),
        iblo: body.is_blocked(),
        ifile: body.ifile,
        node_ids: body.node_ids.clone(),
        p0: [
            p[(0, 0)],
            p[(0, 1)],
            p[(0, 2)],
            p[(1, 0)],
            p[(1, 1)],
            p[(1, 2)],
            p[(2, 0)],
            p[(2, 1)],
            p[(2, 2)],
        ],
        freq: body.freq_file,
        damping: body.damping.map(|d| (d.alpha, d.beta)),
        rigid_modes: if body.is_blocked() {
            Vec::new()
        } else {
            modes(&body.phi_r)
        },
        local_modes: modes(&body.phi_l),
        m_l: body.m_l.iter().copied().collect(),
        k_full,
        k_diag,
        m_r,
        m_c: sub(&body.m_c),
        k_c: sub(&body.k_c),
    }
}
