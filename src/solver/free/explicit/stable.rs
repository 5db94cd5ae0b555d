//! The stable step of the explicit free-body scheme: the highest frequency of the modes
//! coupled to the rigid motion, not only of the local modes ([`super`] holds the scheme).
//!
//! The local modes of a free body are often computed on a support (3-2-1 or clamped
//! interface), so they carry mass coupled to the rigid motion (`M_C != 0`). Released,
//! the body's effective local mass is the Schur complement `m_L - M_C^T M_R^-1 M_C`
//! (on the rigid motions the frame constraints allow), smaller than `m_L`, and its
//! highest free-free frequency lies above the highest local one, by however much the
//! top kept mode couples. The central-difference step bound `2 / omega_max` must use
//! that frequency. Measured on the truss tower reduced on a 3-2-1 support
//! (tests/data/truss_supported.fxb) truncated at its middle mode (28 of 54 local modes,
//! highest local 2855 Hz): the coupled top frequency is higher, and the scheme at
//! `0.9 x 2 / omega_L,max` grew the energy from 1e-3 J to 1e4 J in 10 ms under 0.05 N
//! loads before its spin-rate bound collapsed the step; with the coupled bound it
//! follows the implicit and split methods. That truss's full highest local mode couples
//! little, so its bound hardly changes; free-free modes (the shipped bodies) do not
//! couple at all.
//!
//! The frequency is taken from the scheme itself: the linear map from the local
//! coordinates to their accelerations (`a_L = -A alpha` at rest, loads and gravity
//! removed as the difference to the `alpha = 0` evaluation), one column per local
//! mode, and `omega_max^2` is the spectral radius of `A`. Built once, at construction.

use std::f64::consts::PI;

use nalgebra::DMatrix;

use super::Explicit;
use crate::solver::SolverError;

impl Explicit {
    /// Highest frequency (Hz) of the local modes coupled to the constrained rigid
    /// motion, at the initial frame and at rest (0 without local modes).
    pub(super) fn coupled_frequency_hz(&mut self) -> Result<f64, SolverError> {
        if self.m.nl == 0 {
            return Ok(0.0);
        }
        let d = self.opts.dt_factor * self.dt_fx;
        let d = if d.is_finite() && d > 0.0 { d } else { 1e-3 };
        // At rest: the velocities only add terms that do not depend on alpha.
        let v = self.v.clone();
        self.v.fill(0.0);
        let result = self.coupled_map(d).map(|a| {
            // Divide out the semi-implicit mass damping of step 6, a factor on every
            // local acceleration.
            let f2 = 1.0 + self.m.ray_a * d / 2.0;
            let rho = if a.iter().all(|x| x.is_finite()) {
                a.complex_eigenvalues()
                    .iter()
                    .map(|z| z.norm())
                    .fold(0.0, f64::max)
            } else {
                f64::INFINITY
            };
            (rho * f2).sqrt() / (2.0 * PI)
        });
        self.v.copy_from(&v);
        self.w.key = super::super::NO_KEY;
        self.w.a_valid = false;
        result
    }

    /// `A` with `a_L = -A alpha` (at the current frame and velocities, for a first step
    /// `d`, as at build: a singular system is reported as the body's own).
    fn coupled_map(&mut self, d: f64) -> Result<DMatrix<f64>, SolverError> {
        let (nr, nl) = (self.m.nr, self.m.nl);
        self.w.key = super::super::NO_KEY;
        self.w.a_valid = false;
        self.accelerations(0.0, 0.0, d)?;
        let base = self.w.a.rows(nr, nl).clone_owned();
        let mut a = DMatrix::zeros(nl, nl);
        for j in 0..nl {
            let keep = self.q[nr + j];
            self.q[nr + j] = keep + 1.0;
            self.w.a_valid = false;
            let r = self.accelerations(0.0, 0.0, d);
            self.q[nr + j] = keep;
            r?;
            for i in 0..nl {
                a[(i, j)] = base[i] - self.w.a[nr + i];
            }
        }
        Ok(a)
    }
}
