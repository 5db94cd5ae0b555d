//! The frame check of each explicit internal step, and its halving: an internal step
//! whose frame error passes `FRAME_RETRY_FRACTION` of the refusal threshold is undone and
//! redone in halves (FORMULATION.md section 10.7; [`super`] holds the scheme).

use super::super::{FRAME_RETRY_FRACTION, MAX_HALVINGS, frame_error, frame_invalid};
use super::Explicit;
use crate::solver::{FrameAdvice, MAX_INTERNAL_STEPS, SolverError};

impl Explicit {
    /// One internal step of `dt` with its frame checked. When the frame error passes
    /// `FRAME_RETRY_FRACTION x frame_tol` the step is undone (state restored from the
    /// preallocated copy) and redone in halves, each half checked the same way, down to
    /// `dt / 2^MAX_HALVINGS`; a part at that size is accepted up to `frame_tol` and
    /// refused beyond. Unequal consecutive steps are the scheme's own (`dt1`, `dt2`).
    /// Without a halving the arithmetic is exactly that of `substep(dt)`. Returns the
    /// internal steps computed (undone ones included), counted against
    /// `MAX_INTERNAL_STEPS` with `taken` already spent in this communication step `h`.
    pub(super) fn checked_substep(
        &mut self,
        dt: f64,
        h: f64,
        taken: f64,
    ) -> Result<f64, SolverError> {
        let retry = FRAME_RETRY_FRACTION * self.frame_tol;
        let total: u64 = 1 << MAX_HALVINGS;
        let t_a = self.t;
        let (mut pos, mut level, mut count) = (0u64, 0u32, 0.0);
        while pos < total {
            let size = total >> level;
            if retry.is_finite() {
                self.save_substep();
            }
            let d = if level == 0 {
                dt
            } else {
                dt * (size as f64 / total as f64)
            };
            self.substep(d)?;
            count += 1.0;
            let err = frame_error(&self.p);
            if !err.is_finite() {
                // Overflow: no halving brings the numbers back.
                self.restore_substep();
                return Err(frame_invalid(
                    err,
                    h,
                    self.spin_rate(),
                    FrameAdvice::SmallerSteps,
                ));
            }
            if err > retry && level < MAX_HALVINGS {
                self.restore_substep();
                if level == 0 {
                    self.halved += 1;
                }
                level += 1;
                if taken + count + (total >> level) as f64 > MAX_INTERNAL_STEPS {
                    let internal = dt / f64::from(1u32 << level);
                    return Err(SolverError::TooManySteps {
                        h,
                        steps: taken + count + (h / internal).ceil(),
                        internal,
                        max_h: MAX_INTERNAL_STEPS * internal,
                    });
                }
                continue;
            }
            if err > self.frame_tol {
                // The spin rate of before the broken internal step (the state is restored
                // by the caller anyway).
                self.restore_substep();
                return Err(frame_invalid(
                    err,
                    h,
                    self.spin_rate(),
                    FrameAdvice::AngularAcceleration {
                        internal: d,
                        halvings: MAX_HALVINGS,
                    },
                ));
            }
            pos += size;
            if pos < total {
                self.t = t_a + dt * (pos as f64 / total as f64);
            }
        }
        Ok(count)
    }

    /// Copy the state an internal step starts from (no allocation).
    fn save_substep(&mut self) {
        self.sub_q.copy_from(&self.q);
        self.sub_v.copy_from(&self.v);
        self.sub_p = self.p;
        self.sub_dt1 = self.dt1;
    }

    /// Back to the state saved by `save_substep`.
    fn restore_substep(&mut self) {
        self.q.copy_from(&self.sub_q);
        self.v.copy_from(&self.sub_v);
        self.p = self.sub_p;
        self.dt1 = self.sub_dt1;
        self.w.key = super::super::NO_KEY;
        self.w.a_valid = false;
    }
}
