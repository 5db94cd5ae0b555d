//! The step guard of an FMU instance: a step that would leave a non-finite number in an
//! output a master can read is refused, and the instance keeps its state from before the
//! step ("right or loud"). Putting the state back is the solver's own business
//! ([`Solver::checkpoint`] and [`Solver::rewind`], `crate::solver::rollback`); the guard
//! only decides whether the outputs of a step are acceptable.
//!
//! Two paths. Where the method bounds a step before it is taken ([`BoundedStep`]: the
//! exact method, loads held), the guard keeps a running upper bound of the solver's
//! [`BoundedStep::measure`] and of every load's magnitude (the model reports each load
//! as it is set, [`StepGuard::note_load`]); when the bound after the step keeps every
//! state entry and input below `output_bound`, the step cannot make anything
//! non-finite, so the guard asks for no checkpoint and reads nothing: a few
//! multiplications per step. When the bound says "maybe" (after a restore, or with a
//! stale load magnitude) it is first tightened from the actual state and loads; only if
//! that fails too does the step take the checked path.
//!
//! The checked path (every other method, rates on, or a state near the bound) takes a
//! checkpoint of the solver before the step's loads are passed (one copy of the state,
//! into the solver's own buffer, no allocation). After the step it asks the solver
//! whether its state is below the output bound ([`Solver::state_below`], a second copy
//! and a sum of squares) and bounds the inputs over the step the same way: below the
//! bound every output is certainly finite (`output_bound`) and the step is accepted
//! without computing one. Only a step that reaches the bound computes every output a
//! master can read: node positions, velocities, rotations and their rates, the
//! accelerations, both energies and the modal coordinates. A finite state does not make
//! them finite: they are sums of products of the state with the body's matrices (and,
//! for a truncated body, with the loads themselves), which can overflow. On failure the
//! solver rewinds to the checkpoint and the message names the first non-finite variable
//! and the input with the largest magnitude, the usual cause. (Computing the outputs
//! after every checked step made a communication step 1.1 to 2 times as long; see
//! docs/ROBUSTNESS.md.)

use super::vars::{Kind, VarTable};
use crate::num::num;
use crate::scene::Scene;
use crate::solver::damping::LocalDamping;
use crate::solver::rollback::squares_below;
use crate::solver::{BoundedStep, Growth, Options, Solver, SolverError};

/// The running bounds and the output workspace of one instance.
pub struct StepGuard {
    /// The running step was bounded before it was taken: no checkpoint was taken.
    bounded: bool,
    /// An upper bound of the solver's [`BoundedStep::measure`] now (infinite: unknown).
    measure: f64,
    /// The bound of the measure after the running bounded step.
    next: f64,
    /// An upper bound of the magnitude of the solver's time now (infinite: unknown),
    /// and after the running bounded step. Rounding is monotone, so `time + h` rounded
    /// bounds the solver's own `t + h` rounded.
    time: f64,
    next_time: f64,
    /// The solver's growth for steps of `growth_h` (NaN: none asked for since the
    /// solver last changed outside a step). Kept here so that a run of equal steps asks
    /// the solver once; a step of another size asks again, which also makes the solver
    /// hold that step's coefficients.
    growth: Growth,
    growth_h: f64,
    /// An upper bound of every load's magnitude (each load set raises it; it is
    /// tightened to the actual largest load when the bound test fails).
    cap: f64,
    out: Vec<f64>,
    /// Below this magnitude of every state entry and input, every checked output is
    /// certainly finite ([`output_bound`]): the outputs need not be computed.
    bound: f64,
    /// Tests: never bound a step in advance (the twin every bounded step is compared to).
    #[cfg(test)]
    pub checked_only: bool,
}

/// The largest magnitude `s` of the state entries and inputs under which every output
/// the guard checks is certainly finite, so that a step whose state and inputs stay below
/// it needs no output evaluated. Every output (and output derivative) is a sum over at
/// most `n` terms per coefficient of products of at most 10 coefficients of magnitude at
/// most `a` and at most 8 factors that are state entries (the time and the loads' values
/// and rates among them), inputs or the step: the explicit method's velocity is
/// `v + dt/2 M^-1 (F(t) - K q - C v)` with `F(t) = F0 + F1 (t - t_set)` (degree 3 in the
/// state), its kinetic energy a quadratic form of it in a mass that depends on the frame
/// P, itself part of a free body's state (degree 7). With `s >= 1` each is below
/// `(n a)^10 s^8`, so `s <= (1e300 / (n a)^10)^(1/8)` keeps them finite. Realistic states
/// (1e-6 .. 1e6) are far below the bound (5e23 on the shipped cantilever), so the costly
/// path only runs for a step that is already suspect. (Until issue 28 the bound was
/// `1e90 / (n a)`, counting one coefficient and three state factors per term: the blocked
/// explicit method's kinetic energy from a state of 5e77 was infinite.)
///
/// The coefficients are the body's matrix entries and what the methods form from them
/// and from the parameters: the largest `omega^2`, `2 / omega_max` (the explicit step)
/// and modal damping coefficient (Rayleigh plus `2 zeta omega`, which `damping.ratio`
/// can make as large as 1e300), the inverse local masses, the inverse of the rigid mass
/// scale (free bodies: the frame's accelerations divide by it, and the body checks keep
/// every inertia above 1e-10 of it), gravity, the initial velocities and spin. A
/// parameter that makes `a` huge thus sends every step to the full check rather than
/// letting a product of a bounded state with a huge coefficient pass unseen.
pub(crate) fn output_bound(scene: &Scene, opts: &Options) -> f64 {
    let b = &scene.body;
    let mut a: f64 = 1.0;
    let mut grow = |m: &[f64]| {
        for &x in m {
            // Not `max`: a NaN must win, and make the bound 0 (every step checked).
            let x = x.abs();
            if x.is_nan() || x > a {
                a = x;
            }
        }
    };
    grow(b.phi_l.as_slice());
    grow(b.phi_r.as_slice());
    grow(b.k_l.as_slice());
    grow(b.m_l.as_slice());
    grow(b.m_r.as_slice());
    for m in b.m_c.iter().chain(&b.k_c) {
        grow(m.as_slice());
    }
    if let Some(r) = &scene.residual {
        grow(r.r.as_slice());
    }
    for x in &scene.x0 {
        grow(x);
    }
    grow(&scene.gravity);
    grow(&scene.v0);
    grow(&scene.w0);
    let inverse_masses: Vec<f64> = b.m_l.iter().map(|m| 1.0 / m).collect();
    grow(&inverse_masses);
    if b.nr() > 0 {
        let scale = (0..b.nr().min(12))
            .map(|i| b.m_r[(i, i)].abs())
            .fold(0.0, f64::max);
        grow(&[1e10 / scale]);
    }
    let w = 2.0 * std::f64::consts::PI * b.freq_max_hz();
    grow(&[w * w]);
    if w > 0.0 {
        grow(&[2.0 / w]);
    }
    if let Ok(d) = LocalDamping::new(b, opts.damping_ratio) {
        grow(&[d.modal(w), d.alpha]);
    }
    let n = (6 * b.nnodes() + b.nr() + b.nl() + 12) as f64;
    // In logarithms: (n a)^10 overflows long before the bound reaches 0.
    let log_bound = (300.0 - 10.0 * (n * a).log10()) / 8.0;
    if log_bound > -300.0 {
        10f64.powf(log_bound)
    } else {
        0.0
    }
}

impl StepGuard {
    /// A guard for the scene's solver (one row of outputs per exposed node), for the
    /// default options until [`StepGuard::adopt`] gives it the solver's.
    pub fn new(scene: &Scene) -> StepGuard {
        let nodes = scene.nodes.len();
        StepGuard {
            bound: output_bound(scene, &Options::default()),
            bounded: false,
            measure: f64::INFINITY,
            next: f64::INFINITY,
            time: f64::INFINITY,
            next_time: f64::INFINITY,
            growth: Growth {
                state: f64::INFINITY,
                load: f64::INFINITY,
                scale: f64::INFINITY,
            },
            growth_h: f64::NAN,
            cap: 0.0,
            out: vec![0.0; 3 * nodes],
            #[cfg(test)]
            checked_only: false,
        }
    }

    /// A load was set to `v` (finite): the running load bound covers it.
    #[inline(always)]
    pub fn note_load(&mut self, v: f64) {
        // Not `f64::max`, whose NaN rule costs instructions: both are finite.
        let a = v.abs();
        if a > self.cap {
            self.cap = a;
        }
    }

    /// The loads were replaced wholesale (a restored FMU state): the load bound is their
    /// largest magnitude.
    pub fn set_loads(&mut self, loads: &[f64]) {
        self.cap = largest_magnitude(loads);
    }

    /// A new solver, built for `scene` (with the parameters' gravity and initial
    /// velocities) and `opts`: the output bound for them, and forget the old solver's
    /// measure.
    pub fn adopt(&mut self, scene: &Scene, opts: &Options) {
        self.bound = output_bound(scene, opts);
        self.forget();
    }

    /// The solver was changed outside a step (built, restored, given loads): the next
    /// [`StepGuard::begin`] measures it again where it bounds the step.
    #[inline]
    pub fn forget(&mut self) {
        self.measure = f64::INFINITY;
        self.time = f64::INFINITY;
        self.growth_h = f64::NAN;
    }

    /// Before a step of `h` (and before the loads it passes, `loads`; `rates_on`: some
    /// rate is nonzero): bound the step where the method can, else take a checkpoint of
    /// the solver, which a refused step goes back to.
    #[inline]
    pub fn begin(&mut self, s: &mut dyn Solver, h: f64, loads: &[f64], rates_on: bool) {
        self.bounded = !rates_on
            && match s.bounded() {
                Some(b) => self.bounds(b, h, loads),
                None => false,
            };
        if !self.bounded {
            s.checkpoint();
        }
    }

    /// Whether the step of `h` certainly keeps every state entry and input below the
    /// bound; sets `next` when it does.
    #[inline]
    fn bounds(&mut self, s: &mut dyn BoundedStep, h: f64, loads: &[f64]) -> bool {
        #[cfg(test)]
        if self.checked_only {
            return false;
        }
        if h != self.growth_h {
            match s.growth(h) {
                Some(g) => (self.growth, self.growth_h) = (g, h),
                None => return false,
            }
        }
        self.within(h) || self.tighten(s, h, loads)
    }

    /// The test of [`StepGuard::bounds`] on the running bounds: the bound after a step
    /// of `h` keeps every state entry, load and the time below the output bound; sets
    /// `next` and `next_time` when it does.
    #[inline(always)]
    fn within(&mut self, h: f64) -> bool {
        let g = self.growth;
        let next = g.state * self.measure + g.load * self.cap;
        let time = self.time + h;
        let b = self.bound;
        let ok = next * g.scale < b && self.cap < b && time < b;
        if ok {
            (self.next, self.next_time) = (next, time);
        }
        ok
    }

    /// [`StepGuard::bounds`] with the measure and the load bound taken afresh from the
    /// solver and the loads (they may be stale overestimates, or unknown).
    #[cold]
    #[inline(never)]
    fn tighten(&mut self, s: &dyn BoundedStep, h: f64, loads: &[f64]) -> bool {
        self.measure = s.measure();
        self.cap = largest_magnitude(loads);
        self.time = s.time().abs();
        self.within(h)
    }

    /// Whether the last step begun was bounded in advance (tests).
    #[cfg(test)]
    pub fn bounded(&self) -> bool {
        self.bounded
    }

    /// Put back the state from before the step begun by [`StepGuard::begin`] and refused
    /// after it completed (its outputs are not finite).
    pub fn rollback(&mut self, s: &mut dyn Solver) -> Result<(), SolverError> {
        (self.measure, self.time) = (f64::INFINITY, f64::INFINITY);
        s.rewind()
    }

    /// After a step begun bounded: accept it as it is (its bound becomes the running
    /// one) and say so; `false` after a step begun on the checked path, which
    /// [`StepGuard::check`] then checks.
    #[inline]
    pub fn accept_bounded(&mut self) -> bool {
        if self.bounded {
            (self.measure, self.time) = (self.next, self.next_time);
        }
        self.bounded
    }

    /// Check the step of `h` just taken on the checked path under `inputs` (the loads,
    /// the rates, and whether some rate is nonzero): the first non-finite output, named
    /// for the master, or `None` when every checked value is finite, in which case the
    /// step is accepted. A state and inputs below the output bound are accepted as they
    /// are; only a step that reaches the bound computes the outputs.
    #[inline(never)]
    pub fn check(
        &mut self,
        s: &mut dyn Solver,
        table: &VarTable,
        (loads, rates, rates_on): (&[f64], &[f64], bool),
        h: f64,
    ) -> Option<String> {
        // Measured again at the next bounded step.
        (self.measure, self.time) = (f64::INFINITY, f64::INFINITY);
        let b = self.bound;
        if inputs_below(loads, rates, rates_on, h, b) && s.state_below(b) {
            return None;
        }
        self.first_non_finite(s, table)
    }

    /// The check of every output behind [`StepGuard::check`], for a step whose state or
    /// inputs reach the bound.
    #[cold]
    #[inline(never)]
    fn first_non_finite(&mut self, s: &dyn Solver, table: &VarTable) -> Option<String> {
        let named = |kind: Kind| {
            table
                .vars
                .iter()
                .find(|v| v.kind == kind)
                .map_or_else(|| format!("{kind:?}"), |v| v.name.clone())
        };
        type Fill = fn(&dyn Solver, &mut [f64]);
        // The accelerations too: they are the outputs' derivatives a master reads
        // (fmi2GetRealOutputDerivatives).
        let outputs: [(Fill, &str); 6] = [
            (|s, o| s.positions(o), "position"),
            (|s, o| s.velocities(o), "velocity"),
            (|s, o| s.rotations(o), "rotation"),
            (|s, o| s.rotation_rates(o), "angular velocity"),
            (|s, o| s.accelerations(o), "acceleration"),
            (
                |s, o| {
                    if !s.rotation_accelerations(o) {
                        o.fill(0.0);
                    }
                },
                "angular acceleration",
            ),
        ];
        for (fill, what) in outputs {
            fill(s, &mut self.out);
            if let Some(k) = self.out.iter().position(|x| !x.is_finite()) {
                let (node, comp) = (k / 3, k % 3);
                return Some(match what {
                    "position" => named(Kind::Position { node, comp }),
                    "velocity" => named(Kind::Velocity { node, comp }),
                    "rotation" => named(Kind::Rotation { node, comp }),
                    "angular velocity" => named(Kind::AngularVelocity { node, comp }),
                    "acceleration" => format!(
                        "the acceleration (second derivative) of {}",
                        named(Kind::Position { node, comp })
                    ),
                    _ => format!(
                        "the angular acceleration (derivative) of {}",
                        named(Kind::AngularVelocity { node, comp })
                    ),
                });
            }
        }
        if !s.kinetic_energy().is_finite() {
            return Some(named(Kind::KineticEnergy));
        }
        if !s.strain_energy().is_finite() {
            return Some(named(Kind::StrainEnergy));
        }
        if let Some(j) = s.modal().iter().position(|x| !x.is_finite()) {
            return Some(format!("modal amplitude {}", j + 1));
        }
        None
    }
}

/// Whether any rate is nonzero (`-0.0` counts as zero, as `r != 0.0` does): an OR of the
/// bit patterns without the sign bit, which vectorises.
#[inline]
pub fn any_nonzero(rates: &[f64]) -> bool {
    rates.iter().fold(0u64, |bits, r| bits | (r.to_bits() << 1)) != 0
}

/// Whether the loads stay certainly below `bound` in magnitude over a step of `h`: held
/// value plus rate times step, as a sum of squares like the solver's state
/// ([`Solver::state_below`]); the held values alone when no rate is on. Loads and rates
/// are finite (checked when set).
#[inline]
fn inputs_below(loads: &[f64], rates: &[f64], rates_on: bool, h: f64, bound: f64) -> bool {
    if !rates_on {
        return squares_below(loads, bound);
    }
    let sum: f64 = loads
        .iter()
        .zip(rates)
        .map(|(l, r)| {
            let x = l.abs() + r.abs() * h;
            x * x
        })
        .sum();
    sum < bound * bound
}

/// The largest magnitude in `v` (0 when empty; NaN entries are skipped, and loads are
/// finite anyway).
fn largest_magnitude(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m: f64, x| m.max(x.abs()))
}

/// The input with the largest magnitude, loads and input rates, as `name = value`: the
/// likely cause of a non-finite step.
pub fn largest_input(table: &VarTable, loads: &[f64], rates: &[f64]) -> String {
    let big = |v: &[f64]| {
        v.iter().enumerate().fold(
            (0, 0.0f64),
            |b, (k, &x)| if x.abs() > b.1.abs() { (k, x) } else { b },
        )
    };
    let name = |k: usize| {
        let kind = Kind::Load {
            node: k / 6,
            comp: k % 6,
        };
        table
            .vars
            .iter()
            .find(|v| v.kind == kind)
            .map_or_else(|| format!("load {k}"), |v| v.name.clone())
    };
    let (kl, l) = big(loads);
    let (kr, r) = big(rates);
    if loads.is_empty() && rates.is_empty() {
        return "no input".into();
    }
    // Compare as magnitudes over a second for rates: a rate of 1e308 /s reaches a huge
    // load within the step, so the larger figure is reported.
    if r.abs() > l.abs() {
        format!("input derivative d/dt {} = {} /s", name(kr), num(r))
    } else {
        format!("{} = {}", name(kl), num(l))
    }
}

#[cfg(test)]
mod tests;
