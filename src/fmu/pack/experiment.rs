//! Warnings about the DefaultExperiment `pack` writes: a step so small, or a stop time
//! so long, that no master can run it in a useful time, or a step far below anything the
//! body's dynamics can resolve (`pack --step 1e-300` was accepted silently).

use crate::num::num;
use crate::scene::Scene;

/// More communication steps than this in the DefaultExperiment is warned about: at the
/// fastest step an FMU takes (about 100 ns through the FMI layer, docs/ROBUSTNESS.md) a
/// billion steps is minutes of pure overhead, and at a typical master's rate, hours.
pub const MAX_EXPERIMENT_STEPS: f64 = 1e9;

/// A step below this fraction of the lowest mode's period is warned about: nine orders
/// of magnitude under the slowest motion the body has, where the time `t + h` itself
/// loses the step to round-off long before the body moves.
pub const MIN_STEP_PER_PERIOD: f64 = 1e-9;

/// The warnings (`warning: ...`) for a DefaultExperiment of `stop` s in steps of `h` s
/// of `scene`; `step_given` and `stop_given` say which came from `--step` and `--stop`,
/// so the advice names the option to change.
pub fn warnings(
    scene: &Scene,
    stop: f64,
    h: f64,
    step_given: bool,
    stop_given: bool,
) -> Vec<String> {
    let mut out = Vec::new();
    let steps = stop / h;
    if steps > MAX_EXPERIMENT_STEPS {
        let advice = match (step_given, stop_given) {
            (true, true) => "give a longer --step or a shorter --stop",
            (true, false) => "give a longer --step (or --stop)",
            _ => "give a shorter --stop (or a longer --step)",
        };
        out.push(format!(
            "warning: the DefaultExperiment (stop time {} s, step {} s) takes {} steps, more than {}: a master running it as written would not finish in a useful time; {advice}",
            num(stop),
            num(h),
            num(steps.ceil()),
            num(MAX_EXPERIMENT_STEPS)
        ));
    }
    if let Some(f1) = crate::fmu::xml::lowest_frequency(scene)
        && h < MIN_STEP_PER_PERIOD / f1
    {
        let option = if step_given { "--step" } else { "the step" };
        out.push(format!(
            "warning: {option} {} s is {} of the lowest mode's period {} s, below {}: nothing in the body moves on that time scale; a step of about 1/20 of the period ({} s) resolves the lowest mode",
            num(h),
            num(h * f1),
            num(1.0 / f1),
            num(MIN_STEP_PER_PERIOD),
            num(1.0 / (20.0 * f1))
        ));
    }
    out
}
