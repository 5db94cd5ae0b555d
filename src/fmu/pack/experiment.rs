//! Warnings about the DefaultExperiment `pack` writes: a step so small, or a stop time
//! so long, that no master can run it in a useful time, or a step far below anything the
//! body's dynamics can resolve (`pack --step 1e-300` was accepted silently).

use super::PackNote;
use crate::scene::Scene;

/// More communication steps than this in the DefaultExperiment is warned about: at the
/// fastest step an FMU takes (about 100 ns through the FMI layer, docs/ROBUSTNESS.md) a
/// billion steps is minutes of pure overhead, and at a typical master's rate, hours.
pub const MAX_EXPERIMENT_STEPS: f64 = 1e9;

/// A step below this fraction of the lowest mode's period is warned about: nine orders
/// of magnitude under the slowest motion the body has, where the time `t + h` itself
/// loses the step to round-off long before the body moves.
pub const MIN_STEP_PER_PERIOD: f64 = 1e-9;

/// The warnings for a DefaultExperiment of `stop` s in steps of `h` s of `scene`;
/// `step_given` and `stop_given` say which were given rather than derived, so the
/// command's advice can name the option to change.
pub fn warnings(
    scene: &Scene,
    stop: f64,
    h: f64,
    step_given: bool,
    stop_given: bool,
) -> Vec<PackNote> {
    let mut out = Vec::new();
    let steps = stop / h;
    if steps > MAX_EXPERIMENT_STEPS {
        out.push(PackNote::ExperimentTooLong {
            stop,
            step: h,
            steps: steps.ceil(),
            step_given,
            stop_given,
        });
    }
    if let Some(f1) = crate::fmu::xml::lowest_frequency(scene)
        && h < MIN_STEP_PER_PERIOD / f1
    {
        out.push(PackNote::StepTooSmall {
            step: h,
            lowest_hz: f1,
            step_given,
        });
    }
    out
}
