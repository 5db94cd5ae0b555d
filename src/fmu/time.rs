//! The time arguments of fmi2DoStep: when a communication point names the FMU's current
//! instant, and when a step ends past stopTime. One tolerance for both, scaled by the
//! floating-point spacing at the times involved and by the step.

use super::simulation_error::TimeError;

/// Floating-point spacings (ulps) allowed between a master's time and the FMU's, at the
/// largest magnitude involved (the two times and the start time): a master that computes
/// `start + n h` (fmpy does) or converts integer ticks differs from the FMU's `t + h` by
/// one or two roundings at that magnitude per step (the FMU adopts the master's time every
/// step, so the difference never accumulates); 16 leaves room for masters that round a
/// few times more.
const TIME_ULPS: f64 = 16.0;
/// The part of the step size allowed as well: near t = 0 the ulps vanish, and a master that
/// derives h from printed or differenced times is off by about 1e-15 h; 1e-9 h covers it
/// a millionfold and moves the step's end by far less than any method's truncation error.
const TIME_STEP_FRACTION: f64 = 1e-9;

/// How far two times `a` and `b` may be apart and still name the same instant, for a step
/// of size `h` in a run that started at `start`: `TIME_ULPS` spacings at the largest
/// magnitude plus `TIME_STEP_FRACTION` of `h`. NaN or infinite inputs give NaN or
/// infinity: callers check finiteness first.
pub fn time_tolerance(a: f64, b: f64, start: f64, h: f64) -> f64 {
    let big = a.abs().max(b.abs()).max(start.abs());
    // The spacing of f64 values at `big`: 2^(exponent - 52), at least the smallest
    // subnormal.
    let ulp = if big == 0.0 {
        f64::from_bits(1)
    } else if big == f64::MAX {
        big - f64::from_bits(big.to_bits() - 1)
    } else {
        f64::from_bits(big.to_bits() + 1) - big
    };
    TIME_ULPS * ulp + TIME_STEP_FRACTION * h
}

/// The checks fmi2DoStep makes on its time arguments before anything changes: `h`
/// finite and positive, `t` the FMU's current `time` (within [`time_tolerance`] for a run
/// that started at `start`), and `t + h` not past `stop` (within the same tolerance,
/// whatever the sign of the times).
///
/// The usual step passes on comparisons alone: `h` finite and positive, `t` finite and
/// within `TIME_STEP_FRACTION h` of `time` (a part of every tolerance), and no stop or a
/// finite `t + h` at or before it. Only a step that fails one of these computes the
/// tolerances, so the answer is the same as computing them every time.
#[inline]
pub fn check_step_times(
    t: f64,
    h: f64,
    time: f64,
    start: f64,
    stop: Option<f64>,
) -> Result<(), TimeError> {
    // Comparisons only, combined without branches (a NaN fails each): `x <= f64::MAX`
    // with `x > 0` or on `|x|` is finiteness (`is_finite` compiles to a bit-pattern
    // classification, several times the cost).
    let end = t + h;
    let stop_ok = match stop {
        None => true,
        Some(stop) => (end <= stop) & (end <= f64::MAX),
    };
    // A master that computes `t = k h` is off by an ulp now and then: the distance
    // comparison still settles the call.
    if (h > 0.0)
        & (h <= f64::MAX)
        & ((t - time).abs() <= TIME_STEP_FRACTION * h)
        & (t.abs() <= f64::MAX)
        & stop_ok
    {
        return Ok(());
    }
    check_with_tolerance(t, h, time, start, stop)
}

/// [`check_step_times`] with the tolerances computed.
#[cold]
#[inline(never)]
fn check_with_tolerance(
    t: f64,
    h: f64,
    time: f64,
    start: f64,
    stop: Option<f64>,
) -> Result<(), TimeError> {
    if !(h.is_finite() && h > 0.0) {
        return Err(TimeError::StepSize(h));
    }
    // A NaN time compares false, so it is not close and is refused.
    let tol = time_tolerance(t, time, start, h);
    if !(t.is_finite() && (t - time).abs() <= tol) {
        return Err(TimeError::NotCurrent { t, time, tol });
    }
    let end = t + h;
    if let Some(stop) = stop
        && !(end.is_finite() && (end <= stop || end - stop <= time_tolerance(end, stop, start, h)))
    {
        return Err(TimeError::PastStop { end, stop });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{check_step_times, check_with_tolerance};

    /// The comparisons-only path gives the answer of the full computation with the
    /// tolerances (the reference) on every combination of ordinary and extreme times:
    /// equal and one ulp apart, zero of both signs, huge, infinite and NaN values, with
    /// and without a stop time at, just before and just after the step's end.
    #[test]
    fn the_fast_path_agrees_with_the_tolerances() {
        let up = |x: f64| f64::from_bits(x.to_bits() + 1);
        let mut times = vec![0.0, -0.0, 1e-3, -3.0, 1e9, 1e308, f64::MAX, -f64::MAX];
        times.extend([
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            up(1e9),
            up(1e-3),
        ]);
        let steps = [
            1e-3,
            5e-324,
            1e308,
            f64::MAX,
            0.0,
            -1e-3,
            f64::INFINITY,
            f64::NAN,
        ];
        let (mut cases, mut accepted) = (0, 0);
        for &time in &times {
            for &t in &times {
                for &h in &steps {
                    let end = t + h;
                    let stops = [None, Some(end), Some(up(end)), Some(end - 1e-3), Some(1e9)];
                    for stop in stops {
                        let fast = check_step_times(t, h, time, 0.0, stop).is_ok();
                        let full = check_with_tolerance(t, h, time, 0.0, stop).is_ok();
                        assert_eq!(fast, full, "t {t}, h {h}, time {time}, stop {stop:?}");
                        cases += 1;
                        accepted += usize::from(full);
                    }
                }
            }
        }
        assert!(
            accepted > 100 && cases - accepted > 100,
            "{accepted} of {cases}"
        );
    }
}
