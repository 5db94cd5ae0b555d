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

/// The largest modal damping coefficient the methods use (1/s). A mode damped more (an
/// added ratio near f64::MAX makes `2 zeta w` overflow) loses its velocity within 1e-300 s
/// and creeps by `f h / d`, below 1e-300 of anything a double holds beside it: it is this
/// mode, and every product the methods form with the coefficient (`d v` in the
/// accelerations, `d h` in the exact transition) stays finite.
pub const MAX_MODAL_DAMPING: f64 = 1e300;

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
            return Err(SolverError::BadInput(super::BadInput::DampingRatio(zeta)));
        }
        let (alpha, beta) = body.damping.map_or((0.0, 0.0), |r| (r.alpha, r.beta));
        Ok(LocalDamping { alpha, beta, zeta })
    }

    /// Damping coefficient of a mass-normalised mode of circular frequency `w`:
    /// `alpha + beta w^2 + 2 zeta w` (the first two terms alone when `zeta = 0`), at most
    /// [`MAX_MODAL_DAMPING`].
    #[inline]
    pub fn modal(&self, w: f64) -> f64 {
        let rayleigh = self.alpha + self.beta * (w * w);
        let d = if self.zeta == 0.0 {
            rayleigh
        } else {
            rayleigh + 2.0 * self.zeta * w
        };
        d.min(MAX_MODAL_DAMPING)
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
    /// coefficient `c = beta w^2 + 2 zeta w`, the root `(sqrt(c^2 + 4 w^2) - c) / w^2`
    /// computed without overflow or cancellation ([`crate::body::damped_stable_step`]
    /// of `kappa = c / (2 w) = beta w / 2 + zeta`; the mass damping is semi-implicit and
    /// does not enter).
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
        crate::body::damped_stable_step(w, 0.5 * self.beta * w + self.zeta)
    }
}

/// Refuse an explicit solver whose stable step `dt` (with the added ratio `zeta`) is no
/// usable number: with `damping.ratio` near f64::MAX the lagged damping shortens the step
/// to a subnormal or to 0, and no communication step could be sub-cycled by it. An
/// infinite step (a body without stiffness) is usable.
pub fn check_explicit_step(dt: f64, zeta: f64) -> Result<(), SolverError> {
    if dt.is_normal() && dt > 0.0 || dt == f64::INFINITY {
        return Ok(());
    }
    Err(SolverError::Unsupported {
        method: super::Method::Explicit,
        why: super::Unsupported::DampedStep { zeta, step: dt },
    })
}

#[cfg(test)]
mod tests {
    use crate::body::damped_stable_step;

    /// The stable step is the positive root `s` of `w^2 s^2 + 2 c s = 4`: with `x = s w`
    /// and `kappa = c / (2 w)`, `x^2 / 4 + kappa x = 1`, a residual that can be evaluated
    /// without overflow. Over c from 1e-300 to 1.79e308 (every power of ten, and
    /// f64::MAX) and w from 1e-3 to 1e8 rad/s, wherever the step is a normal number the
    /// residual is within 4 ulps (measured at most 2), and the step is positive and
    /// finite everywhere. The form it replaces, `(sqrt(c^2 + 4 w^2) - c) / w^2`, misses by
    /// up to a factor 3.8 near c = 1e8 w, gives 0 above it and an infinite step once
    /// `c^2` overflows: checked here too, so that the test shows what it guards against.
    #[test]
    fn the_stable_step_is_the_root_over_the_whole_range() {
        let (mut worst, mut naive_worst) = (0.0f64, 0.0f64);
        let mut cs: Vec<f64> = (-300..=308).map(|k| 10f64.powi(k)).collect();
        cs.push(f64::MAX);
        for w in [1e-3, 1.0, 42.0, 1e4, 1e8] {
            for &c in &cs {
                let kappa = 0.5 * (c / w);
                if !kappa.is_finite() {
                    continue;
                }
                let s = damped_stable_step(w, kappa);
                assert!(s >= 0.0 && s.is_finite(), "w {w} c {c:e}: {s}");
                if !s.is_normal() {
                    continue;
                }
                let x = s * w;
                let residual = (0.25 * x * x + kappa * x - 1.0).abs();
                worst = worst.max(residual / f64::EPSILON);
                assert!(
                    residual <= 4.0 * f64::EPSILON,
                    "w {w} c {c:e}: residual {residual:e}"
                );
                let naive = ((c * c + 4.0 * w * w).sqrt() - c) / (w * w);
                let xn = naive * w;
                let rn = (0.25 * xn * xn + kappa * xn - 1.0).abs();
                if rn.is_finite() {
                    naive_worst = naive_worst.max(rn);
                } else {
                    naive_worst = f64::INFINITY;
                }
            }
        }
        println!("largest residual {worst:.1} ulp; the naive form's {naive_worst:e}");
        assert!(
            naive_worst > 1.0,
            "the naive form should fail somewhere: {naive_worst:e}"
        );
    }

    /// An added ratio so large that the step underflows refuses the explicit method at
    /// build with the ratio and the remedy, never a step of 0 s.
    #[test]
    fn an_unusable_step_refuses_the_explicit_method() {
        assert!(super::check_explicit_step(1e-4, 0.0).is_ok());
        assert!(super::check_explicit_step(f64::INFINITY, 0.0).is_ok());
        for dt in [0.0, 2.1e-313] {
            let e = super::check_explicit_step(dt, f64::MAX)
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("damping.ratio 1.7976931348623157e308") && e.contains("split"),
                "{e}"
            );
        }
    }
}
