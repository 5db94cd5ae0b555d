//! The output side of the model: Real values by value reference (computed only for
//! what is asked for, into buffers sized at instantiation: no allocation) and output
//! derivatives.

use super::{Simulation, SimulationError};
use crate::fmu::vars::Kind;

impl Simulation {
    /// Get Real values for `vrs` into `out` (same length). Needs a solver. Inlined into
    /// fmi2GetReal, its one caller on the step path.
    #[inline]
    pub fn get_reals(&mut self, vrs: &[u32], out: &mut [f64]) -> Result<(), SimulationError> {
        self.ensure_solver()?;
        // A truncated scene's positions depend on the same-instant loads (residual
        // flexibility): pass changed loads before reading.
        if self.scene.residual.is_some()
            && self.loads_dirty
            && let Some(s) = self.solver.as_mut()
        {
            s.set_loads(&self.loads)?;
            self.guard.forget();
            self.loads_dirty = false;
        }
        // Model Exchange's state and derivative variables: from the first-order form,
        // once per call.
        if self.table.state_count() > 0 && self.asks_continuous(vrs) {
            self.fill_continuous()?;
        }
        let Some(s) = self.solver.as_ref() else {
            return Err(SimulationError::NoSolver);
        };
        // Only what is asked for: a master polling one position pays for that position
        // (one row) when the method can give it alone, otherwise for the positions only;
        // velocities likewise are computed only when one is asked for.
        let (mut all_pos, mut all_vel) = (false, false);
        let (mut all_rot, mut all_omega) = (false, false);
        for (&vr, o) in vrs.iter().zip(out.iter_mut()) {
            let Some(var) = self.table.get(vr) else {
                return Err(SimulationError::UnknownReference {
                    vr,
                    count: self.table.vars.len(),
                });
            };
            *o = match var.kind {
                Kind::Method => {
                    return Err(SimulationError::WrongType {
                        name: var.name.clone(),
                        vr,
                        is: "an Integer",
                        use_instead: "get it with fmi2GetInteger",
                    });
                }
                Kind::RhoInf => self.opts.rho_inf,
                Kind::DampingRatio => self.opts.damping_ratio,
                Kind::Gravity(c) => self.scene.gravity[c],
                Kind::V0(c) => self.scene.v0[c],
                Kind::W0(c) => self.scene.w0[c],
                Kind::Load { node, comp } => self.loads[6 * node + comp],
                Kind::Position { node, comp } => match s.position(3 * node + comp) {
                    Some(x) => x,
                    None => {
                        if !all_pos {
                            s.positions(&mut self.pos);
                            all_pos = true;
                        }
                        self.pos[3 * node + comp]
                    }
                },
                Kind::Velocity { node, comp } => {
                    if !all_vel {
                        s.velocities(&mut self.vel);
                        all_vel = true;
                    }
                    self.vel[3 * node + comp]
                }
                Kind::Rotation { node, comp } => {
                    if !all_rot {
                        s.rotations(&mut self.rot);
                        all_rot = true;
                    }
                    self.rot[3 * node + comp]
                }
                Kind::AngularVelocity { node, comp } => {
                    if !all_omega {
                        s.rotation_rates(&mut self.omega);
                        all_omega = true;
                    }
                    self.omega[3 * node + comp]
                }
                Kind::KineticEnergy => s.kinetic_energy(),
                Kind::StrainEnergy => s.strain_energy(),
                Kind::FrameOrigin(c) => s.frame().map_or(f64::NAN, |f| f.origin[c]),
                Kind::FrameP(k) => s.frame().map_or(f64::NAN, |f| f.p[k]),
                Kind::FrameVelocity(c) => s.frame_rates().map_or(f64::NAN, |f| f.velocity[c]),
                Kind::FrameAngularVelocity(c) => s.frame_rates().map_or(f64::NAN, |f| f.omega[c]),
                Kind::State(i) => self.xs[i],
                Kind::Derivative(i) => self.dxs[i],
            };
        }
        Ok(())
    }

    /// The common fmi2GetReal in a step loop: `vr` is a position that the solver, built
    /// and current, gives alone ([`crate::solver::Solver::position`]), with no loads to
    /// pass first; the same bits as [`Simulation::get_reals`]. `None` for anything else, which
    /// then takes `get_reals` and its messages.
    #[inline(always)]
    pub fn get_position(&self, vr: u32) -> Option<f64> {
        let Some(Kind::Position { node, comp }) = self.table.get(vr).map(|var| var.kind) else {
            return None;
        };
        if self.dirty || (self.loads_dirty && self.scene.residual.is_some()) {
            return None;
        }
        self.solver.as_ref()?.position(3 * node + comp)
    }

    /// Derivative of order 1 or 2 of an output (fmi2GetRealOutputDerivatives): positions
    /// give velocities and accelerations, velocities give accelerations (order 1). On a
    /// blocked body, whose rotations are linear in the modes, rotations likewise give
    /// angular velocities and accelerations, angular velocities give angular
    /// accelerations. A free body's rotation vector is not the integral of its angular
    /// velocity, and its methods have no exact angular acceleration: refused.
    pub fn get_output_derivative(&mut self, vr: u32, order: i32) -> Result<f64, SimulationError> {
        let var = self.var(vr)?;
        let (kind, name) = (var.kind, &var.name);
        let Some(s) = self.solver.as_ref() else {
            return Err(SimulationError::NoSolver);
        };
        match (kind, order) {
            (Kind::Position { node, comp }, 1) => {
                s.velocities(&mut self.vel);
                Ok(self.vel[3 * node + comp])
            }
            (Kind::Position { node, comp }, 2) | (Kind::Velocity { node, comp }, 1) => {
                s.accelerations(&mut self.acc);
                Ok(self.acc[3 * node + comp])
            }
            (Kind::Rotation { node, comp }, 1) if !self.table.free => {
                s.rotation_rates(&mut self.omega);
                Ok(self.omega[3 * node + comp])
            }
            (Kind::Rotation { node, comp }, 2) | (Kind::AngularVelocity { node, comp }, 1)
                if !self.table.free =>
            {
                if s.rotation_accelerations(&mut self.acc) {
                    Ok(self.acc[3 * node + comp])
                } else {
                    Err(SimulationError::NoOutputDerivative {
                        name: self.table.vars[vr as usize].name.clone(),
                        order,
                    })
                }
            }
            _ => Err(SimulationError::NoOutputDerivative {
                name: name.clone(),
                order,
            }),
        }
    }
}
