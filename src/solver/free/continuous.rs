//! A free body as a first-order system `x' = f(t, x, u)` for masters that integrate it
//! themselves (FMI Model Exchange; FORMULATION.md section 12).
//!
//! The equations are the split method's (section 11): the frame a rigid body `(X, P)`
//! moving with `(V, omega)` and the local modes in the basis of `(K_L, m_eff)`. The
//! states, `13 + 2 nL` of them:
//!
//! | states | meaning |
//! |---|---|
//! | 0..3 | X, the position of the frame point L0 (global) |
//! | 3..7 | the attitude as a quaternion `(w, x, y, z)`, `P = R(q / abs(q))` |
//! | 7..10 | V, the velocity of L0 (global) |
//! | 10..13 | omega, the frame's angular velocity in **global** components |
//! | 13..13+nL | the modal amplitudes y (split basis, `alpha = S y`) |
//! | 13+nL.. | the modal velocities y' |
//!
//! The derivatives are `X' = V`, `q' = 1/2 (0, omega) * q` (quaternion product, omega
//! global: `P' = [omega] P`), `(V', omega')` and `y''` from the one acceleration
//! function the split method's outputs use (`Split::accelerations`), so a change of
//! the equations there is a change here. `q' . q = 0`: the quaternion's norm is an
//! invariant of the exact flow, and the frame is read from `q / abs(q)` whatever the
//! norm, so the master's integration error in the norm moves nothing; the FMU puts the
//! norm back to 1 at a completed integrator step once it has drifted past
//! [`NORM_TOLERANCE`] ([`Continuous::completed_step`]).
//!
//! With Irot = 1 the rotational DOFs (the integral of omega) are not states: no output
//! reads them. No closed-form Jacobian ([`Continuous::jacobian`] answers `false`): the
//! FMU's directional derivative is a central difference of the accelerations with the
//! kinematic rows exact ([`Continuous::exact_rows`]).

use nalgebra::{Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3};

use super::Split;
use crate::solver::continuous::{Continuous, NOMINAL_LOAD, check_states};
use crate::solver::{BadInput, SolverError};

/// The states before the modal ones: X, q, V, omega.
pub const RIGID_STATES: usize = 13;

/// A drift of the quaternion's norm from 1 past which [`Continuous::completed_step`]
/// normalises it. Below it re-projecting would only make the master restart its
/// integrator (FMI: an event) for nothing the outputs can see.
pub const NORM_TOLERANCE: f64 = 1e-8;

/// Model Exchange's attitude: the quaternion as the master last set it (any norm) and
/// the frame it was read into; a frame moved since (a co-simulation step, a restored
/// state) is read back into a quaternion of the same sign.
#[derive(Debug, Clone, Copy)]
pub struct Attitude {
    q: Quaternion<f64>,
    key: Matrix3<f64>,
}

impl Attitude {
    /// The attitude of the rotation `p`.
    pub fn of(p: &Matrix3<f64>) -> Attitude {
        Attitude {
            q: quaternion_of(p),
            key: *p,
        }
    }

    /// The quaternion of the frame `p`: the stored one while `p` is the frame it was
    /// read into, otherwise `p`'s own with the stored one's sign.
    fn quaternion(&self, p: &Matrix3<f64>) -> Quaternion<f64> {
        if *p == self.key {
            return self.q;
        }
        let q = quaternion_of(p);
        if q.coords.dot(&self.q.coords) < 0.0 {
            -q
        } else {
            q
        }
    }
}

/// The unit quaternion of a rotation matrix.
fn quaternion_of(p: &Matrix3<f64>) -> Quaternion<f64> {
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*p)).into_inner()
}

/// `q' = 1/2 (0, omega) * q` for the global angular velocity omega, `(w, x, y, z)`.
pub fn quaternion_rate(q: &Quaternion<f64>, omega: &Vector3<f64>) -> [f64; 4] {
    let v = q.imag();
    let s = -omega.dot(&v);
    let r = omega * q.w + omega.cross(&v);
    [0.5 * s, 0.5 * r[0], 0.5 * r[1], 0.5 * r[2]]
}

/// The quaternion of a state vector, `(w, x, y, z)` at 3..7.
fn state_quaternion(x: &[f64]) -> Quaternion<f64> {
    Quaternion::new(x[3], x[4], x[5], x[6])
}

impl Split {
    /// A typical length of the body: the exposed nodes' largest distance from L0 (1 m
    /// when no node is exposed or all sit at L0).
    fn size(&self) -> f64 {
        let l = self
            .m
            .x0
            .iter()
            .map(|x| (x - self.m.origin0).norm())
            .fold(0.0, f64::max);
        if l > 0.0 && l.is_finite() { l } else { 1.0 }
    }
}

impl Continuous for Split {
    fn state_count(&self) -> usize {
        RIGID_STATES + 2 * self.m.nl
    }

    fn states(&self, out: &mut [f64]) {
        let nl = self.m.nl;
        let x = self.m.origin0 + self.d;
        let q = self.attitude.quaternion(&self.p);
        out[0..3].copy_from_slice(x.as_slice());
        out[3..7].copy_from_slice(&[q.w, q.i, q.j, q.k]);
        out[7..13].copy_from_slice(self.v6.as_slice());
        out[13..13 + nl].copy_from_slice(self.y.as_slice());
        out[13 + nl..13 + 2 * nl].copy_from_slice(self.yd.as_slice());
    }

    fn set_states(&mut self, time: f64, x: &[f64]) -> Result<(), SolverError> {
        let nl = self.m.nl;
        check_states(x, self.state_count())?;
        let q = state_quaternion(x);
        let norm = q.norm();
        if !norm.is_finite() || norm <= 1e-3 {
            return Err(SolverError::BadInput(BadInput::Quaternion(norm)));
        }
        let p = *UnitQuaternion::new_unchecked(q / norm)
            .to_rotation_matrix()
            .matrix();
        self.d = Vector3::new(x[0], x[1], x[2]) - self.m.origin0;
        self.p = p;
        self.attitude = Attitude { q, key: p };
        self.v6.copy_from_slice(&x[7..13]);
        self.y.copy_from_slice(&x[13..13 + nl]);
        self.yd.copy_from_slice(&x[13 + nl..13 + 2 * nl]);
        self.t = time;
        self.rollback.forget();
        self.refresh()
    }

    fn set_time(&mut self, time: f64) {
        self.t = time;
        // The loads' time changed: the accelerations (and outputs) follow. The frame's
        // matrices are those of the current frame already, so nothing can fail here.
        let _ = self.refresh();
    }

    fn derivatives(&self, out: &mut [f64]) {
        let nl = self.m.nl;
        let q = self.attitude.quaternion(&self.p);
        let omega = Vector3::new(self.v6[3], self.v6[4], self.v6[5]);
        out[0..3].copy_from_slice(&self.v6.as_slice()[0..3]);
        out[3..7].copy_from_slice(&quaternion_rate(&q, &omega));
        out[7..13].copy_from_slice(self.a6.as_slice());
        out[13..13 + nl].copy_from_slice(self.yd.as_slice());
        out[13 + nl..13 + 2 * nl].copy_from_slice(self.ydd.as_slice());
    }

    /// Read at the current state (the master asks after initialisation): X: the body's
    /// size L; q: 1; V: the larger of the speed, `L |omega|` and `L` per second; omega:
    /// the larger of `|omega|` and 1 rad/s; each mode as the blocked
    /// exact method does, the static amplitude under a load of [`NOMINAL_LOAD`] on the
    /// exposed node and component that moves it most
    /// (`NOMINAL_LOAD max |S^T Phi_L(n)| / w^2`) and `w` times it for its velocity, a mode no load
    /// reaches (or a zero-frequency one) the largest of the others (L if none).
    fn nominals(&self, out: &mut [f64]) {
        let (nl, m) = (self.m.nl, &self.m);
        let l = self.size();
        let v0 = Vector3::new(self.v6[0], self.v6[1], self.v6[2]).norm();
        let w0 = Vector3::new(self.v6[3], self.v6[4], self.v6[5]).norm();
        out[0..3].fill(l);
        out[3..7].fill(1.0);
        out[7..10].fill(v0.max(l * w0).max(l));
        out[10..13].fill(w0.max(1.0));
        let amp = |j: usize| {
            let mut g = 0.0f64;
            for r in 0..6 * m.nexp {
                let row = &m.phi_l_rows[r * nl..(r + 1) * nl];
                let s: f64 = row
                    .iter()
                    .enumerate()
                    .map(|(i, f)| f * self.c.s[(i, j)])
                    .sum();
                g = g.max(s.abs());
            }
            NOMINAL_LOAD * g / (self.c.omega[j] * self.c.omega[j])
        };
        let ok = |a: f64| a.is_finite() && a > 0.0;
        let fallback = (0..nl).map(amp).filter(|&a| ok(a)).fold(0.0f64, f64::max);
        let fallback = if fallback > 0.0 { fallback } else { l };
        for j in 0..nl {
            let a = amp(j);
            let a = if ok(a) { a } else { fallback };
            out[13 + j] = a;
            out[13 + nl + j] = if self.c.omega[j] > 0.0 {
                a * self.c.omega[j]
            } else {
                a
            };
        }
    }

    /// Not provided: the frame's equations are nonlinear in the attitude and the
    /// angular velocity, and no closed-form Jacobian is written; the FMU's directional
    /// derivative differentiates the accelerations numerically and takes the kinematic
    /// rows from [`Continuous::exact_rows`].
    fn jacobian(&self, _a: &mut [f64], _b: &mut [f64]) -> bool {
        false
    }

    /// The kinematic rows, linear or bilinear in the states: `X' = V` (`dV`), the
    /// quaternion rate `1/2 (0, omega) * q` (`1/2 [(0, d omega) * q + (0, omega) * dq]`)
    /// and `y' = y'` (`dy'`).
    fn exact_rows(&self, x: &[f64], s: &[f64], js: &mut [f64]) {
        let nl = self.m.nl;
        js[0..3].copy_from_slice(&s[7..10]);
        let (q, dq) = (state_quaternion(x), state_quaternion(s));
        let omega = Vector3::new(x[10], x[11], x[12]);
        let domega = Vector3::new(s[10], s[11], s[12]);
        let a = quaternion_rate(&q, &domega);
        let b = quaternion_rate(&dq, &omega);
        for k in 0..4 {
            js[3 + k] = a[k] + b[k];
        }
        js[13..13 + nl].copy_from_slice(&s[13 + nl..13 + 2 * nl]);
    }

    /// Normalise the quaternion once its norm has drifted past [`NORM_TOLERANCE`];
    /// `true` when it did (the master must read the states again).
    fn off_manifold(&self) -> bool {
        (self.attitude.quaternion(&self.p).norm() - 1.0).abs() > NORM_TOLERANCE
    }

    fn completed_step(&mut self) -> bool {
        if !self.off_manifold() {
            return false;
        }
        let q = self.attitude.quaternion(&self.p);
        let norm = q.norm();
        self.attitude = Attitude {
            q: q / norm,
            key: self.p,
        };
        true
    }
}
