//! A whole FE model (10^4 to 10^6 DOFs, sparse K and M) to a body: the route `fxbody
//! import` takes when a model is too large for the dense solver ([`crate::MAX_DENSE_DOFS`]).
//!
//! 1. The connection nodes: the spiders' REF nodes (a `*RIGID BODY`'s REF node's
//!    directions 1-3 and its ROT node's directions 1-3 make one six-DOF node), or the
//!    nodes the user lists.
//! 2. Free or blocked: from K's null space (the six rigid motions built from the
//!    coordinates with the spider reading), or as the user says.
//! 3. The sparse reduction ([`crate::sparse`]): every eigenpair below `fmax` (counted by
//!    inertia, found by block shift-invert Lanczos) and one static mode per connection DOF.
//! 4. [`interface`]: K and M projected on that basis (with a free body's rigid motions)
//!    and rewritten over [connection DOFs, modal amplitudes].
//! 5. That small model (grid DOFs of the connection nodes plus scalar points) goes through
//!    the dense pipeline ([`crate::build`]): the same exact rigid part, M_C and report as a
//!    reduced model imported from Nastran.
//!
//! Every frequency of the body below `fmax` is then the model's own (checked here
//! against the sparse eigen-solver's to [`FREQ_MATCH`]), and statics at the connections are
//! exact.

pub mod cb;
pub mod distributing;
pub mod faces;
pub mod interface;
pub mod spider;

use std::collections::{BTreeMap, HashMap, HashSet};

use faer::Mat;

use crate::fe::{Deck, Dof, SymMatrix};
use crate::sparse::eigen::{self, Modes, Solver, Support as SparseSupport};
use crate::sparse::rigid::{null_residual, rigid_motions};
use crate::sparse::{SymCsc, statics};
use crate::{ImportError, Imported, Options, Stages, Support};
use fxbody::num::num;

/// A free model's rigid motions lie in K's null space to this relative residual
/// (`|K r| / (|K| |r|)`; the bracket gives 3e-16); a held model's are far from it (0.1 and
/// more). Between the two, `--free` or `--blocked` decides.
pub const RIGID_TOL: f64 = 1e-9;

/// The body's frequencies below fmax agree with the sparse eigen-solver's to this
/// relative difference, or nothing is written.
pub const FREQ_MATCH: f64 = 1e-8;

/// The whole-model route's own options.
#[derive(Debug, Clone, Default)]
pub struct WholeOptions {
    /// Spiders to build from node sets first ([`spider`]).
    pub spiders: Vec<spider::SpiderSpec>,
    /// Craig-Bampton instead of the model's own modes ([`cb`]).
    pub craig_bampton: bool,
}

/// A whole model: its DOFs (equation order) and upper-triangle K and M.
#[derive(Debug, Clone)]
pub struct WholeModel {
    /// The DOF of each equation.
    pub dofs: Vec<Dof>,
    /// Stiffness.
    pub k: SymCsc,
    /// Mass.
    pub m: SymCsc,
    /// How the files are named in messages (`job.sti/.mas/.dof`).
    pub name: String,
}

impl WholeModel {
    /// A whole model from matrices read term by term (Abaqus, Nastran DMIG): over the
    /// union of the DOFs K and M mention, sorted as [`SymMatrix::dofs`] are.
    pub fn from_terms(
        k: &SymMatrix,
        m: &SymMatrix,
        name: String,
    ) -> Result<WholeModel, ImportError> {
        let mut dofs: Vec<Dof> = k.dofs.iter().chain(&m.dofs).copied().collect();
        dofs.sort_by_key(Dof::order_key);
        dofs.dedup();
        let csc = |a: &SymMatrix| {
            let at: Vec<usize> = a
                .dofs
                .iter()
                .map(|d| {
                    dofs.binary_search_by_key(&d.order_key(), Dof::order_key)
                        .unwrap_or_default()
                })
                .collect();
            let n = dofs.len();
            let mut count = vec![0usize; n + 1];
            for &(_, j, _) in &a.terms {
                count[at[j] + 1] += 1;
            }
            for j in 0..n {
                count[j + 1] += count[j];
            }
            let mut next = count.clone();
            let mut rows = vec![(0usize, 0.0f64); a.terms.len()];
            for &(i, j, v) in &a.terms {
                let c = at[j];
                rows[next[c]] = (at[i], v);
                next[c] += 1;
            }
            for j in 0..n {
                rows[count[j]..count[j + 1]].sort_unstable_by_key(|r| r.0);
            }
            let (row_idx, values) = rows.into_iter().unzip();
            SymCsc::from_parts(n, count, row_idx, values).map_err(whole_err)
        };
        Ok(WholeModel {
            k: csc(k)?,
            m: csc(m)?,
            dofs,
            name,
        })
    }
}

/// What the sparse stage found, for the report.
#[derive(Debug, Clone, Default)]
pub struct WholeReport {
    /// Equations of the model.
    pub equations: usize,
    /// Stored terms of K.
    pub nnz: usize,
    /// The cut, in the body's units.
    pub fmax: f64,
    /// The model's frequencies below fmax (elastic; body units), by the sparse solver.
    pub model_hz: Vec<f64>,
    /// Largest relative difference between those and the body's.
    pub freq_match: f64,
    /// Static modes (connection DOFs).
    pub static_modes: usize,
    /// `|K r| / (|K| |r|)` of the rigid motions with the spider reading.
    pub rigid_residual: f64,
    /// Connection nodes, with where their six DOFs come from.
    pub connections: Vec<String>,
    /// Ritz basis directions dropped as dependent.
    pub dropped: usize,
    /// Lanczos block steps.
    pub lanczos_steps: usize,
    /// Craig-Bampton reduction: `model_hz` are the fixed-interface frequencies.
    pub craig_bampton: bool,
    /// Craig-Bampton: per elastic mode of the body (ascending), the estimated relative
    /// frequency error against the full model, `f_body / f_model - 1` ([`cb`]).
    pub cb_error_estimates: Vec<f64>,
}

/// One connection node: its ID and, per component of the body, the model's equation.
struct Connection {
    id: i64,
    eqs: Vec<(u8, usize)>,
    from: String,
}

fn whole_err(e: impl std::fmt::Display) -> ImportError {
    ImportError::Whole(e.to_string())
}

/// The connection nodes: `nodes`, or every spider whose REF node has equations.
fn connections(
    model: &WholeModel,
    deck: &Deck,
    deck_name: &str,
    nodes: Option<&[i64]>,
    built: &[spider::BuiltSpider],
) -> Result<Vec<Connection>, ImportError> {
    let eq: HashMap<Dof, usize> = model
        .dofs
        .iter()
        .enumerate()
        .map(|(i, &d)| (d, i))
        .collect();
    let spider = |id: i64| deck.spiders.iter().find(|s| s.reference == id);
    let one = |id: i64| -> Result<Connection, ImportError> {
        if let Some(s) = deck.spiders.iter().find(|s| s.rotation == id) {
            return Err(ImportError::BadNodes(format!(
                "node {id} is the ROT node of the spider at {} (its directions are the \
                 spider's rotations): give its REF node {}",
                s.at, s.reference
            )));
        }
        let mut eqs = Vec::new();
        let from = match spider(id) {
            Some(s) => {
                for c in 1..=3u8 {
                    if let Some(&e) = eq.get(&Dof::new(s.reference, c)) {
                        eqs.push((c, e));
                    }
                    if let Some(&e) = eq.get(&Dof::new(s.rotation, c)) {
                        eqs.push((c + 3, e));
                    }
                }
                format!(
                    "spider {} ({}): translations of node {}, rotations = node {}'s directions 1-3",
                    s.nset, s.at, s.reference, s.rotation
                )
            }
            None => {
                for c in 1..=6u8 {
                    if let Some(&e) = eq.get(&Dof::new(id, c)) {
                        eqs.push((c, e));
                    }
                }
                match built.iter().find(|b| b.id == id) {
                    Some(b) => b.what.clone(),
                    None => format!("node {id}"),
                }
            }
        };
        eqs.sort_unstable();
        if eqs.is_empty() {
            return Err(ImportError::BadNodes(format!(
                "node {id} has no equation in {} (held by *BOUNDARY, or not a node of the \
                 model)",
                model.name
            )));
        }
        if !deck.nodes.contains_key(&id) {
            return Err(ImportError::NoCoordinates {
                id,
                file: deck_name.to_string(),
            });
        }
        Ok(Connection { id, eqs, from })
    };
    let ids: Vec<i64> = match nodes {
        Some(ids) => ids.to_vec(),
        None => deck
            .spiders
            .iter()
            .filter(|s| (1..=3).any(|c| eq.contains_key(&Dof::new(s.reference, c))))
            .map(|s| s.reference)
            .chain(built.iter().map(|b| b.id))
            .collect(),
    };
    if ids.is_empty() {
        return Err(ImportError::NoConnections {
            deck: deck_name.to_string(),
        });
    }
    let mut seen = HashSet::new();
    let mut out = Vec::new();
    for id in ids {
        if !seen.insert(id) {
            return Err(ImportError::BadNodes(format!("node {id} is listed twice")));
        }
        out.push(one(id)?);
    }
    out.sort_by_key(|c| c.id);
    Ok(out)
}

/// Build a body from a whole model (see the module text). `deck` gives the coordinates
/// and spiders; `spiders` are built from node sets first ([`spider`]); `stage` is told
/// when each stage starts (for a progress display).
pub fn build_whole(
    model: &WholeModel,
    deck: &Deck,
    deck_name: &str,
    opts: &Options,
    whole: &WholeOptions,
    stage: &mut dyn FnMut(&str),
) -> Result<Imported, ImportError> {
    if whole.spiders.is_empty() {
        return build_on(model, deck, deck_name, opts, whole, &[], stage);
    }
    stage("spiders");
    let (model, deck, built) = spider::build_spiders(model, deck, deck_name, &whole.spiders)?;
    build_on(&model, &deck, deck_name, opts, whole, &built, stage)
}

/// [`build_whole`] once the spiders are built (`built`: their new nodes).
fn build_on(
    model: &WholeModel,
    deck: &Deck,
    deck_name: &str,
    opts: &Options,
    whole: &WholeOptions,
    built: &[spider::BuiltSpider],
    stage: &mut dyn FnMut(&str),
) -> Result<Imported, ImportError> {
    let n = model.dofs.len();
    let Some(fmax) = opts.fmax else {
        return Err(ImportError::FmaxNeeded {
            model: model.name.clone(),
            dofs: n,
        });
    };
    crate::check_options(opts)?;
    let mut times = Stages::new();
    let time_factor = opts.units.map_or(1.0, |u| u.time);
    let conns = connections(model, deck, deck_name, opts.nodes.as_deref(), built)?;
    let eqs: Vec<usize> = conns
        .iter()
        .flat_map(|c| c.eqs.iter().map(|&(_, e)| e))
        .collect();
    // Rigid motions with the spider reading, about the mean of the model's nodes.
    let rot: HashSet<i64> = deck.spiders.iter().map(|s| s.rotation).collect();
    let coords: HashMap<i64, [f64; 3]> = deck.nodes.iter().map(|(&k, &v)| (k, v)).collect();
    let origin = centroid(&model.dofs, &coords, &rot);
    let r = rigid_motions(&model.dofs, &coords, &rot, origin).map_err(|e| {
        whole_err(format!(
            "{e} in {deck_name}: the rigid motions need every node's position"
        ))
    })?;
    let res = null_residual(&model.k, &r);
    let free = match opts.support {
        Support::Free => true,
        Support::Blocked => false,
        Support::Detect => res.residual < RIGID_TOL,
    };
    if free && res.residual >= RIGID_TOL {
        return Err(ImportError::NotRigid {
            motion: ["x", "y", "z", "rx", "ry", "rz"][res.column].to_string(),
            rel: res.residual,
            dof: model.dofs[res.row],
            diagnosis: "; the model is held (fixed DOFs have no equation in the .dof file), \
                        or a spider's ROT node is not declared by *RIGID BODY in the deck"
                .into(),
            held: false,
        });
    }
    times.done("whole: connections, rigid motions");
    let support = if free {
        SparseSupport::Free { rigid: Some(r) }
    } else {
        SparseSupport::Blocked
    };
    stage("order and factor");
    let lmax = eigen::lambda(fmax * time_factor);
    let mut estimates = Vec::new();
    let (basis, modes) = if whole.craig_bampton {
        stage("fixed-interface modes, constraint modes");
        let r = cb::reduce(&model.k, &model.m, &eqs, lmax).map_err(whole_err)?;
        times.done("whole: Craig-Bampton basis, error estimates");
        // The body reports elastic modes only.
        estimates = r
            .estimates
            .into_iter()
            .skip(if free { 6 } else { 0 })
            .collect();
        (r.basis, r.modes)
    } else {
        let solver = Solver::new(&model.k, &model.m, &support, lmax).map_err(whole_err)?;
        times.done("whole: order, count, factor");
        stage("eigen-solve");
        let modes = solver
            .modes(&eigen::Options::default())
            .map_err(whole_err)?;
        times.done("whole: eigen-solve");
        stage("static modes");
        let psi = statics::static_modes(&solver, &eqs, &modes).map_err(whole_err)?;
        times.done("whole: static modes");
        (
            ritz_basis(&modes, &psi, solver.rigid().map(|l| &l.x)),
            modes,
        )
    };
    stage("projection");
    let small = interface::reduce(&model.k, &model.m, &basis, &eqs).map_err(whole_err)?;
    drop(basis);
    times.done("whole: projection, interface");
    let (ks, ms, node_coords) = small_model(&conns, &small, deck);
    let dense_opts = Options {
        fmax: None,
        nodes: Some(conns.iter().map(|c| c.id).collect()),
        support: if free {
            Support::Free
        } else {
            Support::Blocked
        },
        ..opts.clone()
    };
    stage("body");
    let mut built = crate::build(&ks, &ms, Some(&node_coords), deck_name, &dense_opts)?;
    let model_hz: Vec<f64> = modes
        .lambda
        .iter()
        .map(|&l| eigen::hz(l) / time_factor)
        .collect();
    let body_hz = &built.report.frequencies_hz;
    let mut worst = 0.0f64;
    // Craig-Bampton: the body's frequencies are the CB model's, not these (the
    // fixed-interface ones).
    let compared = if whole.craig_bampton {
        0
    } else {
        model_hz.len()
    };
    for (k, &f) in model_hz.iter().enumerate().take(compared) {
        let g = body_hz.get(k).copied().unwrap_or(f64::NAN);
        let d = (g - f).abs() / f;
        if d.is_nan() || d > FREQ_MATCH {
            return Err(whole_err(format!(
                "the body's mode {} has {} Hz where the model has {} Hz (relative difference \
                 {}, at most {} allowed): the reduction lost accuracy, nothing was written",
                k + 1,
                num(g),
                num(f),
                num(d),
                num(FREQ_MATCH)
            )));
        }
        worst = worst.max(d);
    }
    if !free {
        // The small model's "rigid motion" of a held body is not the model's: no mass
        // properties are reported for it.
        built.report.mass = None;
    }
    built.report.whole = Some(WholeReport {
        equations: n,
        nnz: model.k.nnz(),
        fmax,
        model_hz,
        freq_match: worst,
        static_modes: eqs.len(),
        rigid_residual: res.residual,
        connections: conns.iter().map(|c| c.from.clone()).collect(),
        dropped: small.dropped,
        lanczos_steps: modes.steps,
        craig_bampton: whole.craig_bampton,
        cb_error_estimates: estimates,
    });
    Ok(built)
}

/// The mean position of the nodes with equations (ROT nodes left out).
fn centroid(dofs: &[Dof], coords: &HashMap<i64, [f64; 3]>, rot: &HashSet<i64>) -> [f64; 3] {
    let ids: HashSet<i64> = dofs
        .iter()
        .filter(|d| !rot.contains(&d.id))
        .map(|d| d.id)
        .collect();
    let mut o = [0.0; 3];
    let mut count = 0.0;
    for id in ids {
        if let Some(x) = coords.get(&id) {
            for k in 0..3 {
                o[k] += x[k];
            }
            count += 1.0;
        }
    }
    o.map(|v| if count > 0.0 { v / count } else { 0.0 })
}

/// `[Phi, Psi, R]`, columns side by side.
fn ritz_basis(modes: &Modes, psi: &Mat<f64>, rigid: Option<&Mat<f64>>) -> Mat<f64> {
    let (n, p, c) = (psi.nrows(), modes.vectors.ncols(), psi.ncols());
    let nr = rigid.map_or(0, |r| r.ncols());
    Mat::from_fn(n, p + c + nr, |i, j| {
        if j < p {
            modes.vectors[(i, j)]
        } else if j < p + c {
            psi[(i, j - p)]
        } else {
            rigid.map_or(0.0, |r| r[(i, j - p - c)])
        }
    })
}

/// The small model as matrices over grid DOFs (the connection nodes' components) and
/// scalar points (numbered after the largest connection node), and the connection nodes'
/// coordinates.
fn small_model(
    conns: &[Connection],
    small: &interface::Small,
    deck: &Deck,
) -> (SymMatrix, SymMatrix, BTreeMap<i64, [f64; 3]>) {
    let mut dofs: Vec<Dof> = conns
        .iter()
        .flat_map(|c| c.eqs.iter().map(move |&(comp, _)| Dof::new(c.id, comp)))
        .collect();
    let first = conns.iter().map(|c| c.id).max().unwrap_or(0) + 1;
    let q = small.k.nrows() - small.connections;
    dofs.extend((0..q as i64).map(|k| Dof::new(first + k, 0)));
    let sym = |name: &str, a: &Mat<f64>| {
        let mut terms = Vec::new();
        for j in 0..a.ncols() {
            for i in 0..=j {
                if a[(i, j)] != 0.0 {
                    terms.push((i, j, a[(i, j)]));
                }
            }
        }
        terms.sort_unstable_by_key(|&(i, j, _)| (i, j));
        SymMatrix {
            name: name.to_string(),
            dofs: dofs.clone(),
            terms,
            small_field_digits: None,
        }
    };
    let coords = conns.iter().map(|c| (c.id, deck.nodes[&c.id])).collect();
    (sym("K", &small.k), sym("M", &small.m), coords)
}
