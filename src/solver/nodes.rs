//! What every blocked-body method shares: the exposed-node rows of the local modes turned
//! into the global frame, the load held by the caller (value, rate, time it was set) and
//! its projection onto the modes, and the node outputs. Everything is sized at build
//! time; nothing here allocates after [`Exposed::new`].

use std::cell::{Cell, OnceCell};

use nalgebra::{DMatrix, DVector};

use super::dense::{dot, gemv_acc};

use super::SolverError;
use super::loads::Loads;
use crate::scene::Scene;

/// Exposed-node rows of a mode basis in the global frame, and the caller's load.
///
/// For a basis `B` (`nL x nb`: the identity for the physical coordinates, or the modal
/// basis of the exact method), the rows `P0 Phi_trans(n) B` and `P0 Phi_rot(n) B` of every
/// exposed node n are stored transposed, as the columns of `gt` in the caller's load
/// order (node by node: fx fy fz mx my mz), so that
/// - the generalised load `sum_c gt[.., c] loads[c]` runs down contiguous columns with
///   no regrouping (FORMULATION.md section 2 with P = P0),
/// - each node output is one contiguous dot product with the coordinates.
///
/// One copy of the rows serves both, which matters for cache use on large scenes.
#[derive(Debug, Clone)]
pub struct Exposed {
    /// Number of exposed nodes m.
    pub nodes: usize,
    /// `nb x 6m`: column `6k + c` is the transposed global row c of exposed node k
    /// (c < 3 translations, c >= 3 rotations, zero for nodes without rotational DOFs).
    pub gt: DMatrix<f64>,
    /// Initial global coordinates, 3 per exposed node.
    pub x0: DVector<f64>,
    /// The caller's loads and rates (6 per node).
    pub held: Loads,
    /// `gt loads`.
    pub f: DVector<f64>,
    /// `gt rates`.
    pub fd: DVector<f64>,
}

impl Exposed {
    /// Precompute the rows for the scene's exposed nodes in the basis `basis`
    /// (`nL x nb`).
    pub fn new(scene: &Scene, basis: &DMatrix<f64>) -> Result<Exposed, SolverError> {
        let body = &scene.body;
        let m = scene.nodes.len();
        if scene.x0.len() != m {
            return Err(SolverError::BadLength {
                what: "scene node coordinates",
                expected: m,
                found: scene.x0.len(),
            });
        }
        if let Some(&bad) = scene.nodes.iter().find(|&&n| n >= body.nnodes()) {
            return Err(SolverError::BadInput(super::BadInput::Node {
                index: bad,
                nodes: body.nnodes(),
            }));
        }
        let nb = basis.ncols();
        let rows = scene.exposed_rows(&body.phi_l) * basis;
        let mut gt = DMatrix::zeros(nb, 6 * m);
        for (k, &node) in scene.nodes.iter().enumerate() {
            let rot = body.node_has_rotation(node);
            for j in 0..nb {
                for c in 0..3 {
                    let mut t = 0.0;
                    let mut r = 0.0;
                    for l in 0..3 {
                        t += body.p0[(c, l)] * rows[(6 * k + l, j)];
                        r += body.p0[(c, l)] * rows[(6 * k + 3 + l, j)];
                    }
                    if !rot {
                        r = 0.0;
                    }
                    gt[(j, 6 * k + c)] = t;
                    gt[(j, 6 * k + 3 + c)] = r;
                }
            }
        }
        let x0 = DVector::from_iterator(3 * m, scene.x0.iter().flat_map(|p| p.iter().copied()));
        Ok(Exposed {
            nodes: m,
            gt,
            x0,
            held: Loads::new(6 * m),
            f: DVector::zeros(nb),
            fd: DVector::zeros(nb),
        })
    }

    /// Column `6k + c` of `gt` (length nb).
    #[inline]
    pub fn row(&self, k: usize, c: usize) -> &[f64] {
        let nb = self.gt.nrows();
        let j = 6 * k + c;
        &self.gt.as_slice()[j * nb..(j + 1) * nb]
    }

    /// Loads at time `now`: stored and projected; the rate is kept.
    pub fn set_loads(&mut self, loads: &[f64], now: f64) -> Result<(), SolverError> {
        super::loads::check("loads", loads, 6 * self.nodes)?;
        self.held.set(loads, now);
        self.project_loads();
        Ok(())
    }

    /// New rates from `now` on. The load value reached at `now` becomes the new base, so
    /// the load stays continuous.
    pub fn set_rates(&mut self, rates: &[f64], now: f64) -> Result<(), SolverError> {
        super::loads::check("load rates", rates, 6 * self.nodes)?;
        self.held.set_rates(rates, now);
        self.project_loads();
        self.project_rates();
        Ok(())
    }

    /// `f = gt loads` (only the nonzero loads cost anything).
    fn project_loads(&mut self) {
        self.f.as_mut_slice().fill(0.0);
        gemv_acc(self.gt.as_slice(), &self.held.values, self.f.as_mut_slice());
    }

    /// `fd = gt rates` (only the nonzero rates cost anything).
    fn project_rates(&mut self) {
        self.fd.as_mut_slice().fill(0.0);
        gemv_acc(self.gt.as_slice(), &self.held.rates, self.fd.as_mut_slice());
    }

    /// Generalised load component `i` at time `t`.
    #[inline]
    pub fn force(&self, i: usize, t: f64) -> f64 {
        self.f[i] + self.fd[i] * (t - self.held.t_set)
    }

    /// Generalised load at time `t` into `out` (length nb).
    pub fn force_into(&self, t: f64, out: &mut DVector<f64>) {
        let dt = t - self.held.t_set;
        for ((o, &f), &fd) in out.iter_mut().zip(self.f.iter()).zip(self.fd.iter()) {
            *o = f + fd * dt;
        }
    }

    /// `out[3k + c] = base[3k + c] + row(k, off + c) . coords` for the first `out.len()`
    /// values (at most 3 per exposed node).
    fn rows_dot(&self, off: usize, c: &[f64], base: Option<&[f64]>, out: &mut [f64]) {
        let n = out.len().min(3 * self.nodes);
        for (i, o) in out[..n].iter_mut().enumerate() {
            let v = dot(self.row(i / 3, off + i % 3), c);
            *o = base.map_or(v, |b| b[i] + v);
        }
    }

    /// Node positions `x0 + g_trans c` for coordinates `c`. A short `out` gets the first
    /// values only (the contract is 3 per exposed node).
    pub fn positions(&self, c: &DVector<f64>, out: &mut [f64]) {
        self.rows_dot(0, c.as_slice(), Some(self.x0.as_slice()), out);
    }

    /// Position value `k` (node `k / 3`, component `k % 3`) alone: `x0[k] + row . c`,
    /// the same bits as [`Exposed::positions`] gives for that entry. A master that polls
    /// one position then pays for one row, not all of them.
    pub fn position(&self, k: usize, c: &DVector<f64>) -> Option<f64> {
        (k < 3 * self.nodes).then(|| self.x0[k] + dot(self.row(k / 3, k % 3), c.as_slice()))
    }

    /// Translation rows times `c` (velocities or accelerations).
    pub fn translations(&self, c: &DVector<f64>, out: &mut [f64]) {
        self.rows_dot(0, c.as_slice(), None, out);
    }

    /// Rotation rows times `c` (rotation rates from modal velocities).
    pub fn rotations(&self, c: &DVector<f64>, out: &mut [f64]) {
        self.rows_dot(3, c.as_slice(), None, out);
    }

    /// Length of the saved load part: `t_set`, loads, rates.
    pub fn saved_len(&self) -> usize {
        self.held.state_len()
    }

    /// Append the load part of a state.
    pub fn save(&self, data: &mut Vec<f64>) {
        self.held.save_time_first(data);
    }

    /// Restore the load part of a state (length already checked) and re-project it.
    pub fn restore(&mut self, data: &[f64]) {
        self.held.load_time_first(data);
        self.project_loads();
        self.project_rates();
    }

    /// The length of a blocked method's state: the time, the load part and `parts`.
    pub fn state_len(&self, parts: &[&[f64]]) -> usize {
        1 + self.saved_len() + parts.iter().map(|p| p.len()).sum::<usize>()
    }

    /// Write a blocked method's state into `data` (cleared first): the time `time`, the
    /// load part, then each of `parts` whole. No allocation once `data` has held it.
    pub fn write_state(&self, data: &mut Vec<f64>, time: f64, parts: &[&[f64]]) {
        data.clear();
        data.push(time);
        self.save(data);
        for p in parts {
            data.extend_from_slice(p);
        }
    }

    /// Read a state [`Exposed::write_state`] wrote for `method`: checked whole first
    /// ([`check_state`]), then the load part restored and `parts` filled; the time is
    /// returned. Refused with nothing changed when the state does not fit.
    pub fn read_state(
        &mut self,
        state: &super::State,
        method: super::Method,
        parts: &mut [&mut [f64]],
    ) -> Result<f64, SolverError> {
        let len = 1 + self.saved_len() + parts.iter().map(|p| p.len()).sum::<usize>();
        check_state(state, method, len)?;
        let d = &state.data;
        let mut k = 1 + self.saved_len();
        self.restore(&d[1..k]);
        for p in parts {
            p.copy_from_slice(&d[k..k + p.len()]);
            k += p.len();
        }
        Ok(d[0])
    }
}

/// Cut a saved state into its parts after checking method and length.
pub fn check_state(
    state: &super::State,
    method: super::Method,
    expected: usize,
) -> Result<(), SolverError> {
    if state.method != method {
        return Err(SolverError::BadState(super::BadState::Method {
            saved: state.method,
            runs: method,
        }));
    }
    if state.data.len() != expected {
        return Err(SolverError::BadState(super::BadState::Length {
            expected,
            found: state.data.len(),
        }));
    }
    if state.data.iter().any(|x| !x.is_finite()) {
        return Err(SolverError::BadState(super::BadState::NotFinite));
    }
    Ok(())
}

/// The [`super::Solver`] items the exact and the implicit method answer alike from their
/// modal state (they step the same mass-normalised modes): the method and time, the
/// loads, the outputs read through the exposed rows from the modal amplitudes `self.y`
/// and the modal velocities `self.$v`, the local coordinates, both energies and the
/// state items of [`super::rollback`]. Invoked inside each method's `impl Solver`; the
/// method writes `step`, the accelerations and `set_state` itself, and `refresh` (run
/// after the loads changed: the acceleration output of the implicit method holds them).
macro_rules! modal_solver_items {
    ($method:expr, $v:ident) => {
        fn method(&self) -> $crate::solver::Method {
            $method
        }

        fn time(&self) -> f64 {
            self.time
        }

        fn set_loads(&mut self, loads: &[f64]) -> Result<(), $crate::solver::SolverError> {
            self.io.set_loads(loads, self.time)?;
            self.rollback.touch();
            self.refresh();
            Ok(())
        }

        fn set_load_rates(&mut self, rates: &[f64]) -> Result<(), $crate::solver::SolverError> {
            self.io.set_rates(rates, self.time)?;
            self.rollback.touch();
            self.refresh();
            Ok(())
        }

        fn positions(&self, out: &mut [f64]) {
            self.io.positions(&self.y, out);
        }

        fn position(&self, k: usize) -> Option<f64> {
            self.io.position(k, &self.y)
        }

        fn velocities(&self, out: &mut [f64]) {
            self.io.translations(&self.$v, out);
        }

        fn rotation_rates(&self, out: &mut [f64]) {
            self.io.rotations(&self.$v, out);
        }

        fn rotations(&self, out: &mut [f64]) {
            self.io.rotations(&self.y, out);
        }

        fn modal(&self) -> &[f64] {
            self.alpha.get(&self.modes.basis, &self.y)
        }

        fn strain_energy(&self) -> f64 {
            $crate::solver::nodes::modal_strain_energy(&self.y, &self.modes.w2)
        }

        fn kinetic_energy(&self) -> f64 {
            0.5 * self.$v.norm_squared()
        }

        fn frame(&self) -> Option<$crate::solver::Frame> {
            None
        }

        $crate::solver::rollback::rollback_items!();
    };
}
pub(crate) use modal_solver_items;

/// The local coordinates `alpha = S y`, computed on the first request after a step and
/// kept until the next one. `modal()` hands out a slice from `&self`, so the value lives
/// in a cell filled on demand; the buffer moves between `value` and `spare` so that
/// neither a step nor a request allocates.
pub struct LocalCoords {
    value: OnceCell<DVector<f64>>,
    spare: Cell<Option<DVector<f64>>>,
    len: usize,
}

impl LocalCoords {
    /// Empty (stale) coordinates for `nl` local modes, with their buffer allocated now.
    pub fn new(nl: usize) -> LocalCoords {
        LocalCoords {
            value: OnceCell::new(),
            spare: Cell::new(Some(DVector::zeros(nl))),
            len: nl,
        }
    }

    /// Mark the value stale (the amplitudes changed); keeps the buffer.
    pub fn invalidate(&mut self) {
        if let Some(v) = self.value.take() {
            *self.spare.get_mut() = Some(v);
        }
    }

    /// `basis y`, computed if stale.
    pub fn get(&self, basis: &DMatrix<f64>, y: &DVector<f64>) -> &[f64] {
        self.value
            .get_or_init(|| {
                let mut v = self
                    .spare
                    .take()
                    .unwrap_or_else(|| DVector::zeros(self.len));
                v.gemv(1.0, basis, y, 0.0);
                v
            })
            .as_slice()
    }
}

impl Clone for LocalCoords {
    fn clone(&self) -> LocalCoords {
        LocalCoords {
            value: self.value.clone(),
            spare: Cell::new(Some(DVector::zeros(self.len))),
            len: self.len,
        }
    }
}

impl std::fmt::Debug for LocalCoords {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LocalCoords")
            .field("value", &self.value.get())
            .finish()
    }
}

/// Mass-normalised modes of a blocked body ([`crate::body::Modal`]): `S = m^-1/2 V` with
/// `m^-1/2 K_L m^-1/2 = V diag(w^2) V^T`, and the circular frequencies `w`. In the
/// coordinates `q = S y` the mass is the identity, the stiffness `diag(w^2)` and Rayleigh
/// damping `diag(alpha + beta w^2)`: every mode is independent.
pub fn modal_basis(body: &crate::body::Body) -> (DMatrix<f64>, Vec<f64>) {
    (body.modal.shapes.clone(), body.modal.omega())
}

/// The modes a blocked method steps one by one (the exact and the implicit method alike):
/// the mass-normalised basis ([`modal_basis`]), each mode's circular frequency, its
/// square, and its modal damping ([`super::damping::LocalDamping::modal`]: Rayleigh plus
/// the added ratio), in the order of the basis.
#[derive(Debug, Clone)]
pub struct Modes {
    /// `S = m^-1/2 V`, physical from modal coordinates.
    pub basis: DMatrix<f64>,
    /// `omega` per mode.
    pub omega: Vec<f64>,
    /// `omega^2` per mode.
    pub w2: Vec<f64>,
    /// Modal damping `alpha + beta omega^2 (+ 2 zeta omega)`.
    pub damp: Vec<f64>,
}

impl Modes {
    /// The modes of a blocked body with the added damping ratio `zeta` (refused where
    /// [`super::damping::LocalDamping::new`] refuses it).
    pub fn new(body: &crate::body::Body, zeta: f64) -> Result<Modes, SolverError> {
        let (basis, omega) = modal_basis(body);
        let damping = super::damping::LocalDamping::new(body, zeta)?;
        let w2 = omega.iter().map(|&w| w * w).collect();
        let damp = omega.iter().map(|&w| damping.modal(w)).collect();
        Ok(Modes {
            basis,
            omega,
            w2,
            damp,
        })
    }
}

/// Strain energy `1/2 sum w_i^2 y_i^2` of mass-normalised modal amplitudes `y` with
/// squared circular frequencies `w2`: equal to `1/2 alpha^T K_L alpha`.
pub fn modal_strain_energy(y: &DVector<f64>, w2: &[f64]) -> f64 {
    0.5 * y.iter().zip(w2).map(|(y, w2)| w2 * y * y).sum::<f64>()
}
