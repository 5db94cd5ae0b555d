//! The `.fxb` file format only: reading (fixed-column and free-format), writing, and
//! errors that name the file, line and block. No physics here: [`FxbFile`] holds the
//! numbers exactly in file order; [`crate::body::Body`] turns them into matrices.

/// The raw contents of a flexible-body file, block by block, in file order.
///
/// Counts follow FORMULATION.md section 1: `nl = nbmod`, `ns = nbstat`, `n = nbnod`,
/// `nr = 12` (irot false) or `15` (irot true). Blocks absent for the given flags are empty.
#[derive(Debug, Clone, PartialEq)]
pub struct FxbFile {
    /// Block 1: total number of local modes (Nbmod).
    pub nbmod: usize,
    /// Block 1: number of static modes (Nbstat), the first `nbstat` local modes.
    pub nbstat: usize,
    /// Block 1: number of nodes (Nbnod).
    pub nbnod: usize,
    /// Block 1: the body has nodes with rotational DOFs (Irot = 1): 15 rigid modes.
    pub irot: bool,
    /// Block 1: Rayleigh damping present (Idamp = 1).
    pub idamp: bool,
    /// Block 1: blocked body (Iblo = 1): no rigid modes, no M_R, M_C, K_C.
    pub iblo: bool,
    /// Block 1: Ifile; only tells Radioss where to keep mode data. No effect on results.
    pub ifile: bool,
    /// Block 2: node IDs, in the order the mode blocks list nodes.
    pub node_ids: Vec<i64>,
    /// Block 3: initial frame P0, row-major (P11 P12 P13 P21 ... P33).
    pub p0: [f64; 9],
    /// Block 3: the largest eigenfrequency of (K_L, M_L) in Hz, as stored.
    pub freq: f64,
    /// Block 4: Rayleigh (alpha, beta); `None` when Idamp = 0.
    pub damping: Option<(f64, f64)>,
    /// Blocks 5+6: rigid modes, `nr * n * 6` values: mode-major, then node, then
    /// component (X Y Z XX YY ZZ). Empty when Iblo = 1.
    pub rigid_modes: Vec<f64>,
    /// Block 7: local modes, `nl * n * 6` values, same order as `rigid_modes`.
    pub local_modes: Vec<f64>,
    /// Block 8: diagonal local mass m_L, `nl` values.
    pub m_l: Vec<f64>,
    /// Block 9: full part of K_L, `ns (2 nl - ns + 1) / 2` values (skyline rows).
    pub k_full: Vec<f64>,
    /// Block 10: diagonal part of K_L, `nl - ns` values.
    pub k_diag: Vec<f64>,
    /// Block 11: M_R upper triangle row by row, `nr (nr + 1) / 2` values; empty if Iblo = 1.
    pub m_r: Vec<f64>,
    /// Block 12: nine M_C,kl sub-blocks, `9 * nr * nl` values; sub-block `3(k-1)+(l-1)`
    /// (0-based), each row-major nr x nl. Empty if Iblo = 1 or nl = 0.
    pub m_c: Vec<f64>,
    /// Block 13: nine K_C,kl sub-blocks, same layout as `m_c`.
    pub k_c: Vec<f64>,
}

impl FxbFile {
    /// Number of rigid modes (12, or 15 with rotational DOFs); 0 for a blocked body.
    pub fn nr(&self) -> usize {
        match (self.iblo, self.irot) {
            (true, _) => 0,
            (false, false) => 12,
            (false, true) => 15,
        }
    }
}
