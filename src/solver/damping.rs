//! The damping of the local modes, defined once for every method: Rayleigh damping from
//! the file (block 4, `C = alpha diag(m_L) + beta K_L`) plus the added modal damping
//! ratio `zeta` ([`super::Options::damping_ratio`], the FMU parameter `damping.ratio`) on
//! every local mode.
//!
//! With the mass-normalised local modes `q = S y` (`S^T diag(m_L) S = I`,
//! `S^T K_L S = diag(w^2)`), mode i has the damping coefficient
//! `d_i = alpha + beta w_i^2 + 2 zeta w_i` ([`LocalDamping::modal`]): the modal methods
//! (exact, blocked implicit) read it per mode. The added part in local coordinates is
//! `C_zeta = diag(m_L) S diag(2 zeta w) S^T diag(m_L)` ([`LocalDamping::added_matrix`]),
//! which is diagonal in the same modes with exactly `2 zeta w_i`: the methods that step
//! the local coordinates themselves (blocked explicit, free explicit and implicit) add
//! `C_zeta v` where they add the stiffness damping `beta K_L v`. A new method that reads
//! this module gets the added damping too.
//!
//! With `zeta = 0` no method does any extra arithmetic, so every output is bit for bit
//! what it was without the parameter.
//!
//! The explicit scheme lags the velocity of both the stiffness damping and the added
//! damping, so they shorten its stable step ([`LocalDamping::explicit_stable_step`]).

use nalgebra::DMatrix;

use super::SolverError;
use crate::body::Body;

/// Rayleigh damping and the added modal ratio of a body's local modes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalDamping {
    /// Rayleigh mass factor alpha (1/s), 0 without block 4.
    pub alpha: f64,
    /// Rayleigh stiffness factor beta (s), 0 without block 4.
    pub beta: f64,
    /// Added damping ratio on every local mode (>= 0).
    pub zeta: f64,
}

impl LocalDamping {
    /// The damping of `body` with the added ratio `zeta`, which must be finite and >= 0
    /// (a negative ratio would feed energy in).
    pub fn new(body: &Body, zeta: f64) -> Result<LocalDamping, SolverError> {
        if !(zeta.is_finite() && zeta >= 0.0) {
            return Err(SolverError::BadInput(format!(
                "damping ratio must be finite and >= 0, got {}",
                crate::num::num(zeta)
            )));
        }
        let (alpha, beta) = body.damping.map_or((0.0, 0.0), |r| (r.alpha, r.beta));
        Ok(LocalDamping { alpha, beta, zeta })
    }

    /// Damping coefficient of a mass-normalised mode of circular frequency `w`:
    /// `alpha + beta w^2 + 2 zeta w` (the first two terms alone when `zeta = 0`).
    #[inline]
    pub fn modal(&self, w: f64) -> f64 {
        let rayleigh = self.alpha + self.beta * (w * w);
        if self.zeta == 0.0 {
            rayleigh
        } else {
            rayleigh + 2.0 * self.zeta * w
        }
    }

    /// The added damping in local coordinates,
    /// `diag(m_L) S diag(2 zeta w) S^T diag(m_L)` (`nL x nL`); `None` when `zeta = 0`.
    pub fn added_matrix(&self, body: &Body) -> Option<DMatrix<f64>> {
        if self.zeta == 0.0 {
            return None;
        }
        let s = &body.modal.shapes;
        let omega = body.modal.omega();
        // M S, then (M S) diag(2 zeta w) (M S)^T.
        let mut ms = s.clone();
        for (r, &m) in body.m_l.iter().enumerate() {
            ms.row_mut(r).scale_mut(m);
        }
        let mut scaled = ms.clone();
        for (j, &w) in omega.iter().enumerate() {
            scaled.column_mut(j).scale_mut(2.0 * self.zeta * w);
        }
        Some(&scaled * ms.transpose())
    }

    /// Stable step of the explicit scheme: the body's ([`Body::explicit_stable_step`])
    /// when `zeta = 0`; otherwise that of its highest mode `w` with the lagged damping
    /// coefficient `c = beta w^2 + 2 zeta w`, `(sqrt(c^2 + 4 w^2) - c) / w^2` (which is
    /// the body's formula for `zeta = 0`; the mass damping is semi-implicit and does not
    /// enter).
    pub fn explicit_stable_step(&self, body: &Body) -> f64 {
        self.explicit_stable_step_at(body, body.freq_max_hz())
    }

    /// The same formula for a highest frequency `freq_hz` other than the local modes'
    /// (a free body's rigid-flexible coupling raises it: `free::explicit`).
    pub fn explicit_stable_step_at(&self, body: &Body, freq_hz: f64) -> f64 {
        if self.zeta == 0.0 {
            return crate::body::stable_step(freq_hz, body.damping.map_or(0.0, |d| d.beta));
        }
        let w = 2.0 * std::f64::consts::PI * freq_hz;
        if w <= 0.0 {
            return f64::INFINITY;
        }
        let c = self.beta * w * w + 2.0 * self.zeta * w;
        ((c * c + 4.0 * w * w).sqrt() - c) / (w * w)
    }
}
