//! The standard scenes of the study: the fixture bodies, their loads and their
//! references (the fixtures' full-FE responses, or a fine-step run where no FE history
//! exists, said so in the `reference` text).

use std::path::Path;
use std::sync::Arc;

use fxbody::body::load as load_body;
use fxbody::fxb::coords::{read_coords, to_map};
use fxbody::scene::Scene;
use fxbody::solver::{Method, Options};

use serde_json::Value as Json;

/// A method as the study names it: the solver method and its settings.
#[derive(Debug, Clone, Copy)]
pub struct Variant {
    /// Name in the CSV and the chart legend.
    pub label: &'static str,
    /// Solver method.
    pub method: Method,
    /// Solver options (rho_inf for the implicit method).
    pub opts: Options,
    /// Chart colour.
    pub color: &'static str,
}

impl Variant {
    /// Whether the method runs on the body: exact on blocked bodies only, split on free
    /// ones only, the others on both.
    pub fn offered(&self, scene: &Scene) -> bool {
        match self.method {
            Method::Exact => scene.body.is_blocked(),
            Method::Split => !scene.body.is_blocked(),
            _ => true,
        }
    }
}

/// Every method the study runs; the exact one only on blocked bodies, the split one
/// only on free bodies.
pub fn variants() -> Vec<Variant> {
    let o = Options::default();
    vec![
        Variant {
            label: "exact",
            method: Method::Exact,
            opts: o,
            color: "#1b7837",
        },
        Variant {
            label: "implicit rho 0.9",
            method: Method::Implicit,
            opts: Options { rho_inf: 0.9, ..o },
            color: "#2166ac",
        },
        Variant {
            label: "implicit rho 0.5",
            method: Method::Implicit,
            opts: Options { rho_inf: 0.5, ..o },
            color: "#67a9cf",
        },
        Variant {
            label: "explicit",
            method: Method::Explicit,
            opts: o,
            color: "#b2182b",
        },
        Variant {
            label: "split",
            method: Method::Split,
            opts: o,
            color: "#f4a000",
        },
    ]
}

/// The load history of a scene, on the tip node's global fy.
#[derive(Debug, Clone, Copy)]
pub enum Load {
    /// `F` for t >= 0, held.
    Step(f64),
    /// `F` for 0 <= t < d; each communication step holds the step's mean load, so the
    /// impulse is right whatever the step.
    Pulse(f64, f64),
    /// `F sin(2 pi (f1 t^2 / (2 T)))`: frequency rising linearly from 0 to f1 over T;
    /// each step gets the value at its start and the rate to its end (first-order hold).
    Chirp { f: f64, f1: f64, t_end: f64 },
    /// No load.
    None,
}

impl Load {
    /// The exact load at time t.
    pub fn at(&self, t: f64) -> f64 {
        match *self {
            Load::Step(f) => f,
            Load::Pulse(f, d) => {
                if (0.0..d).contains(&t) {
                    f
                } else {
                    0.0
                }
            }
            Load::Chirp { f, f1, t_end } => {
                f * (2.0 * std::f64::consts::PI * f1 * t * t / (2.0 * t_end)).sin()
            }
            Load::None => 0.0,
        }
    }

    /// Value and rate handed to the solver for the step `[t, t + h]`.
    pub fn sample(&self, t: f64, h: f64) -> (f64, f64) {
        match *self {
            Load::Pulse(f, d) => {
                let overlap = ((t + h).min(d) - t.max(0.0)).max(0.0);
                (f * overlap / h, 0.0)
            }
            Load::Chirp { .. } => {
                let a = self.at(t);
                (a, (self.at(t + h) - a) / h)
            }
            _ => (self.at(t), 0.0),
        }
    }
}

/// A reference history of the tip displacement on a uniform time grid.
#[derive(Debug, Clone)]
pub struct Reference {
    /// Grid spacing (s).
    pub dt: f64,
    /// Displacement components per sample (1 for uy, 3 for a full vector).
    pub u: Vec<Vec<f64>>,
    /// Where it comes from.
    pub what: String,
}

impl Reference {
    /// Largest norm over the history (the error's denominator).
    pub fn peak(&self) -> f64 {
        self.u
            .iter()
            .map(|v| v.iter().map(|x| x * x).sum::<f64>().sqrt())
            .fold(0.0, f64::max)
    }
}

/// One study case: a body scene, a load and a reference.
pub struct Case {
    /// Short name (CSV, chart panel).
    pub name: String,
    /// The scene (tip node exposed).
    pub scene: Scene,
    /// Load on the tip's fy.
    pub load: Load,
    /// Simulated duration (s).
    pub duration: f64,
    /// Compare only uy (FE references) or all three components (tumble).
    pub components: usize,
    /// Communication steps to sweep.
    pub steps: Vec<f64>,
    /// The reference (filled later for the fine-step ones).
    pub reference: Option<Reference>,
}

/// A fixture body with its tip node exposed, and its parsed reference file.
pub fn fixture(dir: &Path, name: &str) -> Result<(Scene, Json), String> {
    let fxb = dir.join(format!("{name}.fxb"));
    let body = load_body(&fxb, Default::default()).map_err(|e| e.to_string())?;
    let refp = dir.join(format!("{name}.ref.json"));
    let text =
        fxbody::fxb::input::read_input("--fixtures", &refp, fxbody::fxb::input::Limit::Reference)
            .map_err(|e| e.to_string())?;
    let j =
        serde_json::from_slice::<Json>(&text).map_err(|e| format!("{}: {e}", refp.display()))?;
    let tip = j
        .get("tip_node")
        .and_then(Json::as_f64)
        .ok_or_else(|| format!("{}: no tip_node", refp.display()))? as i64;
    let deck = dir.join(format!("{name}.nodes.rad"));
    let xyz = to_map(&read_coords(&deck).map_err(|e| format!("{}: {e}", deck.display()))?);
    let k = body
        .node_index(tip)
        .ok_or_else(|| format!("{}: tip node {tip} not in the body", fxb.display()))?;
    let x = *xyz
        .get(&tip)
        .ok_or_else(|| format!("{}: no coordinates for node {tip}", deck.display()))?;
    Ok((Scene::new(Arc::new(body), vec![k], vec![x]), j))
}

/// The fixture's full-FE response `name` at the tip (uy), with its load.
pub fn fe_response(j: &Json, name: &str) -> Result<(Reference, Load, f64), String> {
    let r = j
        .get("responses")
        .and_then(Json::as_array)
        .into_iter()
        .flatten()
        .find(|r| r.get("name").and_then(Json::as_str) == Some(name))
        .ok_or_else(|| format!("reference has no response {name}"))?;
    let tip = j.get("tip_node").and_then(Json::as_f64).unwrap_or(0.0) as i64;
    let t = r.get("t").and_then(nums).ok_or("response without t")?;
    let uy = r
        .get("nodes")
        .and_then(|n| n.get(tip.to_string()))
        .and_then(|n| n.get("uy"))
        .and_then(nums)
        .ok_or("response without the tip's uy")?;
    let amp = r
        .get("amplitude")
        .and_then(Json::as_f64)
        .ok_or("no amplitude")?;
    let load = match r.get("duration").and_then(Json::as_f64) {
        Some(d) => Load::Pulse(amp, d),
        None => Load::Step(amp),
    };
    let dt = t[1] - t[0];
    let duration = *t.last().unwrap_or(&0.0);
    let reference = Reference {
        dt,
        u: uy.into_iter().map(|v| vec![v]).collect(),
        what: "full FE model, all modes (fixture ref.json)".into(),
    };
    Ok((reference, load, duration))
}

/// The numbers of a JSON array; `None` if it is not an array of numbers.
pub fn nums(v: &Json) -> Option<Vec<f64>> {
    v.as_array()?.iter().map(Json::as_f64).collect()
}

/// `base * 2^k` for k in `lo..=hi`.
pub fn doublings(base: f64, lo: i32, hi: i32) -> Vec<f64> {
    (lo..=hi).map(|k| base * 2f64.powi(k)).collect()
}
