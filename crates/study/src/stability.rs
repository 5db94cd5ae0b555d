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
    let fmax = scene.body.frequencies_hz.last().copied().unwrap_or(0.0);
    let beta = scene.body.damping.map_or(0.0, |r| r.beta);
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
