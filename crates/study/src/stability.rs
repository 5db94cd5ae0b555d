//! The stability map: the largest step each method survives, as a multiple of the
//! body's dt_fx, found by bisection on energy growth over a fixed number of steps.
//!
//! A run: one step with a load of impulse `IMPULSE` on all six components of the tip (so
//! every mode is excited, and by the same amount whatever the step), then free vibration without sub-cycling for `STEPS` steps. It counts as
//! unstable when the final energy exceeds `GROWTH` times the largest energy of the
//! first ten steps, when anything is non-finite, or when the solver refuses a step.

use fxbody::body::stable_step;
use fxbody::scene::Scene;
use fxbody::solver::{Options, build};

use super::scenes::Variant;

/// Impulse of the first step's load (N s, N m s).
pub const IMPULSE: f64 = 1e-6;
/// Free-vibration steps per trial.
pub const STEPS: usize = 2000;
/// Energy growth that counts as unstable.
pub const GROWTH: f64 = 100.0;
/// Largest ratio tried; a method stable there is reported as ">= MAX_RATIO".
pub const MAX_RATIO: f64 = 1e4;

/// The body's dt_fx (FORMULATION.md section 4).
pub fn dt_fx(scene: &Scene) -> f64 {
    let fmax = scene.body.frequencies_hz().last().copied().unwrap_or(0.0);
    let beta = scene.body.damping().map_or(0.0, |r| r.beta);
    stable_step(fmax, beta)
}

/// Whether `v` is stable at step `h`; the text says why not.
pub fn stable(scene: &Scene, v: &Variant, h: f64) -> Result<(), String> {
    let opts = Options {
        subcycle: false,
        ..v.opts
    };
    let mut s = build(scene, v.method, &opts).map_err(|e| e.to_string())?;
    let mut f = [IMPULSE / h; 6];
    s.set_loads(&f).map_err(|e| e.to_string())?;
    s.step(h).map_err(|e| e.to_string())?;
    f = [0.0; 6];
    s.set_loads(&f).map_err(|e| e.to_string())?;
    let mut early: f64 = 0.0;
    let mut e = 0.0;
    for i in 0..STEPS {
        s.step(h).map_err(|e| format!("step {i}: {e}"))?;
        e = s.strain_energy() + s.kinetic_energy();
        if !e.is_finite() {
            return Err(format!("non-finite energy at step {i}"));
        }
        if i < 10 {
            early = early.max(e);
        }
    }
    if e > GROWTH * early {
        return Err(format!("energy grew {:.2e} times", e / early));
    }
    Ok(())
}

/// The largest stable ratio h/dt_fx (bisection to 0.1% in the log), or `None` when stable
/// up to `MAX_RATIO`; also the reason the first unstable ratio failed.
pub fn largest_stable(scene: &Scene, v: &Variant) -> (Option<f64>, String) {
    let dt = dt_fx(scene);
    let stable = |scene: &Scene, v: &Variant, h: f64| {
        let t = std::time::Instant::now();
        let r = stable(scene, v, h);
        eprintln!(
            "    {:<17} h/dt_fx = {:<10.4} {} ({:.2} s)",
            v.label,
            h / dt,
            if r.is_ok() { "stable" } else { "unstable" },
            t.elapsed().as_secs_f64()
        );
        r
    };
    if stable(scene, v, MAX_RATIO * dt).is_ok() {
        return (None, String::new());
    }
    let mut lo = 0.05;
    if let Err(e) = stable(scene, v, lo * dt) {
        return (Some(0.0), e);
    }
    let mut hi = MAX_RATIO;
    let mut why = String::new();
    while hi / lo > 1.001 {
        let mid = (lo * hi).sqrt();
        match stable(scene, v, mid * dt) {
            Ok(()) => lo = mid,
            Err(e) => {
                hi = mid;
                why = e;
            }
        }
    }
    (Some(lo), why)
}

/// Spin-rate stability of the explicit free-body method: the largest rotation per step
/// `|omega| dt` at which the frame stays a rotation and the energy stays bounded.
///
/// A trial: the body spins at `omega = r / h` about a given axis with
/// `h = SPIN_H_OVER_DT_FX x dt_fx` (elastically stable, so only the spin limits the step),
/// free of loads, for `SPIN_STEPS` steps without sub-cycling. It passes when the largest
/// `|P^T P - I|` over the run stays at or below [`SPIN_FRAME_TOL`] and the final energy
/// is within [`SPIN_ENERGY_TOL`] of the initial one.
pub mod spin {
    use fxbody::scene::Scene;
    use fxbody::solver::free::{Explicit, Split};
    use fxbody::solver::{Options, Solver};

    use super::dt_fx;

    /// Step of the trials as a fraction of dt_fx.
    pub const SPIN_H_OVER_DT_FX: f64 = 0.5;
    /// Steps per trial.
    pub const SPIN_STEPS: usize = 20_000;
    /// Largest `|P^T P - I|` that passes (the product refuses a step beyond 1e-6).
    pub const SPIN_FRAME_TOL: f64 = 1e-6;
    /// Largest relative energy change over a trial that passes.
    pub const SPIN_ENERGY_TOL: f64 = 1e-2;
    /// The tumbling spin axis (global, normalised in use): no principal axis of either
    /// free fixture.
    pub const TUMBLE: [f64; 3] = [1.0, 2.0, 3.0];

    /// Outcome of one trial.
    #[derive(Debug, Clone, Copy)]
    pub struct Trial {
        /// Spin rate (rad/s).
        pub omega: f64,
        /// Largest `|P^T P - I|` over the run (infinite when a step was refused).
        pub frame_error: f64,
        /// `E_end / E_0 - 1`.
        pub energy_change: f64,
    }

    impl Trial {
        /// Whether the trial passes both criteria.
        pub fn passes(&self) -> bool {
            self.frame_error <= SPIN_FRAME_TOL && self.energy_change.abs() <= SPIN_ENERGY_TOL
        }
    }

    /// Run one trial at rotation per step `r`: the explicit method (`split` false) as
    /// described above, or the split method (`split` true), which takes the step as it
    /// comes (it cuts it into internal steps of at most `ROT_STEP` rad itself).
    pub fn trial(scene: &Scene, axis: [f64; 3], r: f64, steps: usize, split: bool) -> Trial {
        let h = SPIN_H_OVER_DT_FX * dt_fx(scene);
        let omega = r / h;
        let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        let mut sc = scene.clone();
        sc.w0 = axis.map(|a| a / n * omega);
        let opts = Options {
            subcycle: false,
            ..Options::default()
        };
        let fail = Trial {
            omega,
            frame_error: f64::INFINITY,
            energy_change: f64::INFINITY,
        };
        let mut s: Box<dyn Solver> = if split {
            match Split::new(&sc, &Options::default()) {
                Ok(s) => Box::new(s),
                Err(_) => return fail,
            }
        } else {
            let Ok(mut s) = Explicit::new(&sc, &opts) else {
                return fail;
            };
            // The raw scheme: the product's frame check would stop the run at 1e-6.
            s.set_spin_limits(f64::INFINITY, f64::INFINITY);
            Box::new(s)
        };
        let e0 = s.kinetic_energy() + s.strain_energy();
        let mut worst: f64 = 0.0;
        for _ in 0..steps {
            if s.step(h).is_err() {
                return fail;
            }
            let f = s.frame().map_or(f64::INFINITY, |f| frame_error(&f.p));
            worst = worst.max(f);
        }
        let e = s.kinetic_energy() + s.strain_energy();
        Trial {
            omega,
            frame_error: worst,
            energy_change: if e.is_finite() {
                e / e0 - 1.0
            } else {
                f64::INFINITY
            },
        }
    }

    /// `|P^T P - I|` (largest entry) of a row-major frame.
    fn frame_error(p: &[f64; 9]) -> f64 {
        let mut e: f64 = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = (0..3).map(|k| p[3 * k + i] * p[3 * k + j]).sum::<f64>()
                    - if i == j { 1.0 } else { 0.0 };
                e = e.max(d.abs());
            }
        }
        if e.is_nan() { f64::INFINITY } else { e }
    }

    /// The grid of rotations per step the study runs.
    pub fn grid() -> Vec<f64> {
        vec![
            1e-5, 1e-4, 3e-4, 0.001, 0.003, 0.005, 0.01, 0.02, 0.03, 0.05, 0.1, 0.2, 0.5,
        ]
    }
}
