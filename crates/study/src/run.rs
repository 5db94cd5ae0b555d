//! One point of the study: a case run by one method at one communication step, its error
//! against the reference and its CPU time per simulated second.

use std::hint::black_box;
use std::time::Instant;

use fxbody::solver::{Solver, SolverError, build};

use super::scenes::{Case, Reference, Variant};

/// What one point measured.
#[derive(Debug, Clone)]
pub struct Point {
    /// Max over the compared samples of |u - u_ref|, relative to the reference's peak.
    pub error: f64,
    /// CPU seconds of stepping per simulated second (fastest repetition).
    pub cpu_per_s: f64,
    /// Nanoseconds per communication step (same measurement).
    pub ns_per_step: f64,
    /// Number of reference samples compared.
    pub compared: usize,
    /// Why the point has no result, if it has none (error and time are then NaN): data
    /// of the map, not a failure of the study.
    pub outcome: Option<Outcome>,
}

/// A point without a result: the method went unstable at this step, or refused it.
/// Expected at large steps (that is what the study maps), so it is reported as data.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// The run grew without bound (a non-finite output or state).
    Unstable(String),
    /// The method refused the body or the step (for example a step needing more internal
    /// steps than it allows).
    Refused(String),
}

impl std::fmt::Display for Outcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Outcome::Unstable(why) => write!(f, "unstable ({why})"),
            Outcome::Refused(why) => write!(f, "refused ({why})"),
        }
    }
}

impl From<SolverError> for Outcome {
    fn from(e: SolverError) -> Outcome {
        match e {
            SolverError::NonFinite { .. } => Outcome::Unstable(e.to_string()),
            _ => Outcome::Refused(e.to_string()),
        }
    }
}

/// Loads for every step: (value, rate) of the tip's fy.
fn load_table(case: &Case, h: f64, n: usize) -> Vec<(f64, f64)> {
    (0..n).map(|i| case.load.sample(i as f64 * h, h)).collect()
}

/// Drive `s` through the case, calling `each(i, displacement)` after every step.
fn drive(
    s: &mut dyn Solver,
    case: &Case,
    loads: &[(f64, f64)],
    h: f64,
    mut each: impl FnMut(usize, &[f64; 3]),
) -> Result<(), Outcome> {
    let mut f = [0.0; 6];
    let mut r = [0.0; 6];
    let mut pos = [0.0; 3];
    let x0 = case.scene.x0[0];
    let rates = loads.iter().any(|l| l.1 != 0.0);
    for (i, &(v, rate)) in loads.iter().enumerate() {
        f[1] = v;
        s.set_loads(&f)?;
        if rates {
            r[1] = rate;
            s.set_load_rates(&r)?;
        }
        s.step(h)?;
        s.positions(&mut pos);
        let u = [pos[0] - x0[0], pos[1] - x0[1], pos[2] - x0[2]];
        each(i, &u);
    }
    Ok(())
}

/// The tip displacement history of a run with step h, sampled every `every` steps (used
/// to make fine-step references).
pub fn history(
    case: &Case,
    v: &Variant,
    h: f64,
    every: usize,
    components: usize,
) -> Result<Vec<Vec<f64>>, String> {
    let n = (case.duration / h).round() as usize;
    let loads = load_table(case, h, n);
    let mut s = build(&case.scene, v.method, &v.opts).map_err(|e| e.to_string())?;
    let mut out = vec![vec![0.0; components]];
    drive(s.as_mut(), case, &loads, h, |i, u| {
        if (i + 1) % every == 0 {
            out.push(pick(u, components));
        }
    })
    .map_err(|e| e.to_string())?;
    Ok(out)
}

fn pick(u: &[f64; 3], components: usize) -> Vec<f64> {
    if components == 1 {
        vec![u[1]]
    } else {
        u.to_vec()
    }
}

/// Error of a history sampled at steps of h against the reference grid.
fn compare(reference: &Reference, h: f64, i: usize, u: &[f64]) -> Option<f64> {
    let t = (i + 1) as f64 * h;
    let k = (t / reference.dt).round();
    if (k * reference.dt - t).abs() > 1e-6 * reference.dt {
        return None;
    }
    let r = reference.u.get(k as usize)?;
    Some(
        r.iter()
            .zip(u)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt(),
    )
}

/// Run the case with method `v` at step h: error, then timing (the fastest of several
/// repetitions of the stepping loop from the same initial state).
pub fn measure(case: &Case, v: &Variant, h: f64, min_time: f64) -> Point {
    match measure_inner(case, v, h, min_time) {
        Ok(p) => p,
        Err(e) => Point {
            error: f64::NAN,
            cpu_per_s: f64::NAN,
            ns_per_step: f64::NAN,
            compared: 0,
            outcome: Some(e),
        },
    }
}

fn measure_inner(case: &Case, v: &Variant, h: f64, min_time: f64) -> Result<Point, Outcome> {
    let reference = case
        .reference
        .as_ref()
        .ok_or_else(|| Outcome::Refused("no reference".into()))?;
    let n = (case.duration / h).round() as usize;
    let loads = load_table(case, h, n);
    let mut s = build(&case.scene, v.method, &v.opts)?;
    let s0 = s.state();
    let mut worst: f64 = 0.0;
    let mut compared = 0;
    let mut finite = true;
    drive(s.as_mut(), case, &loads, h, |i, u| {
        finite &= u.iter().all(|x| x.is_finite());
        if let Some(e) = compare(reference, h, i, &pick(u, case.components)) {
            worst = worst.max(e);
            compared += 1;
        }
    })?;
    if !finite {
        return Err(Outcome::Unstable("non-finite output".into()));
    }
    let peak = reference.peak();
    // Timing: the same loop without the comparison.
    let mut best = f64::INFINITY;
    let mut total = 0.0;
    let mut reps = 0;
    while reps < 3 || (total < min_time && reps < 200) {
        s.set_state(&s0)?;
        let start = Instant::now();
        drive(s.as_mut(), case, &loads, h, |_, u| {
            black_box(u);
        })?;
        let el = start.elapsed().as_secs_f64();
        best = best.min(el);
        total += el;
        reps += 1;
    }
    Ok(Point {
        error: worst / peak,
        cpu_per_s: best / (n as f64 * h),
        ns_per_step: best / n as f64 * 1e9,
        compared,
        outcome: None,
    })
}
