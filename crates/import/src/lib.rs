//! fxbody-import: build a `.fxb` body from a user's finite-element matrices (`fxbody
//! import`). The only user of the large linear-algebra crates (faer, rayon) and of JSON:
//! the product package (the FMU and the packer) needs none of them.
//!
//! A user who reduced a structure in an FE code (Guyan, Craig-Bampton, or a small full
//! model) brings symmetric K and M over grid DOFs (components 1..6, global frame) and
//! scalar points (modal coordinates), read by [`fe`], and the node coordinates.
//! The pipeline, one idea per file:
//! - [`dofs`]: one DOF order for K and M, unit conversion, dead DOFs dropped, massless DOFs
//!   condensed out exactly (`K~ = K_aa - K_az K_zz^-1 K_za`);
//! - [`rigid`]: the six rigid motions, the exact mass properties (mass, centre of mass,
//!   inertia) and from them an `M_R` that is the same at every attitude;
//! - [`modes`]: the eigenproblem, free or blocked from K's null space, the rigid pairs
//!   removed, `--fmax` with static modes so that statics at the nodes stay exact;
//! - [`assemble`]: m_L, K_L (from the eigen relations), M_C,kl, K_C,kl into an
//!   [`FxbFile`];
//! - [`report`]: what was built and dropped, as text and JSON, to compare with the FE
//!   code's own mass printout.
//!
//! Where we differ from OpenRadioss's own DMIG route: M_R is built from the exact rigid
//! mass properties (OpenRadioss uses `Phi_R^T M Phi_R`, which for a reduced mass is not
//! rotation-invariant), M_C carries the rotation on the rigid mode (a reduced mass couples
//! directions), and Freq is the largest eigenfrequency of (K_L, m_L), not the cut-off.

use std::collections::BTreeMap;

use crate::fe::{Dof, SymMatrix};
use fxbody::fxb::FxbFile;
use fxbody::num::num;

pub mod assemble;
pub mod dense;
pub mod dofs;
pub mod fe;
pub mod modes;
pub mod par;
pub mod report;
pub mod rigid;
pub mod scale;
pub mod sparse;
pub mod support;
pub mod tridiag;
pub mod units;
pub mod whole;

pub use report::{Report, Resolution, Warning};
pub use units::Units;

/// The largest dense problem `import` solves (DOFs, before dead-DOF removal). Above it the
/// user is asked to reduce in the FE code. The work is O(n^3) (Cholesky, the standard-form
/// matrix, the symmetric eigen-solver, the products of [`assemble`]; [`dense`], on two
/// threads). Measured on a quiet 2-core machine (tests/python/import_sizes.py, a free
/// grillage, FXBODY_IMPORT_TIMES for the stages), beside LAPACK's generalised
/// eigen-solver alone (one thread) on the same matrices in the same run: 1008 DOFs 0.5 s
/// (LAPACK 0.3 s), 2040 DOFs 2.3 s (1.8 s), 3000 DOFs 7.6 s (5.7 s; 3.2 s of it faer's
/// eigen-solver, 1.3 s the Cholesky and standard form); with `--fmax 2000` 3000 DOFs
/// 6.0 s (5.9 s). LAPACK alone takes 15.7 s at 4032 DOFs: past 3000 an import is no
/// longer a matter of seconds, so the limit stays there.
pub const MAX_DENSE_DOFS: usize = 3000;

/// Free or blocked, as asked on the command line; `Detect` takes it from K's null space.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Support {
    /// Decide from K: singular is free, positive definite is blocked.
    Detect,
    /// The body floats: K's null space must be exactly the six rigid motions.
    Free,
    /// The body is held: K must be positive definite.
    Blocked,
}

/// What the user asked for, besides the matrices.
#[derive(Debug, Clone)]
pub struct Options {
    /// Free, blocked, or detect.
    pub support: Support,
    /// Keep eigenmodes up to this frequency (in the target units' 1/time) and add static
    /// modes for the nodes' DOFs.
    pub fmax: Option<f64>,
    /// Unit conversion of the matrices and coordinates.
    pub units: Option<Units>,
    /// The FXB nodes (default: every grid point, ascending).
    pub nodes: Option<Vec<i64>>,
    /// Rayleigh damping (alpha, beta), written as block 4.
    pub damping: Option<(f64, f64)>,
    /// Test only: write the naive `M_R = Phi_R^T M Phi_R` (as OpenRadioss does), to show
    /// that it is wrong for a reduced mass.
    pub naive_mass_r: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            support: Support::Detect,
            fmax: None,
            units: None,
            nodes: None,
            damping: None,
            naive_mass_r: false,
        }
    }
}

/// What a singular K of a body imported as blocked suggests besides importing it as
/// free: data, the command words it with its options.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SingularHint {
    /// K's zero modes are exactly the coordinates' rigid motions: a free body.
    RigidMotions,
    /// No coordinates were given, and a free body is recognised by them.
    GiveCoords,
}

/// Why a body could not be built. Each message names the cause and, where one exists,
/// the DOF and the value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImportError {
    /// Too many DOFs for the dense solver.
    #[error(
        "dense size {0} DOFs exceeds the limit of {MAX_DENSE_DOFS}: import the whole model \
         through the sparse route (the whole-model import: a CalculiX deck, or these matrices with their \
         coordinates and connection nodes, and the highest frequency to keep), or reduce it \
         in your FE code"
    )]
    TooLarge(usize),
    /// The whole-model route (sparse reduction) failed: the cause, named.
    #[error("{0}")]
    Whole(String),
    /// A whole model without a connection node: no spider whose reference node moves,
    /// none built, none named.
    #[error(
        "{deck} has no *RIGID BODY spider whose REF node moves: give the connection nodes, \
         or build a spider on a node set"
    )]
    NoConnections {
        /// The deck's name.
        deck: String,
    },
    /// A spider to build on a node set cannot be built as asked: the cause, named.
    #[error("{0}")]
    BadSpider(String),
    /// A whole model needs the highest frequency its body must keep.
    #[error(
        "{model} is a whole model ({dofs} DOFs): it needs the highest frequency the body \
         must keep (every mode of the model below it is kept exactly, with a static mode per \
         connection DOF)"
    )]
    FmaxNeeded {
        /// The model's name (its files).
        model: String,
        /// Its number of DOFs.
        dofs: usize,
    },
    /// Nothing to build from.
    #[error("the matrices hold no DOF with stiffness or mass")]
    Empty,
    /// A grid point needed for the rigid motions has no coordinates.
    #[error("node {id} has no coordinates in {file}")]
    NoCoordinates {
        /// The grid point.
        id: i64,
        /// The coordinates file.
        file: String,
    },
    /// A free body needs coordinates.
    #[error("a free body needs node coordinates")]
    CoordinatesNeeded,
    /// The exposed nodes asked for: none, one twice, or one that is not a grid point of
    /// the matrices.
    #[error("exposed nodes: {0}")]
    BadNodes(String),
    /// Massless DOFs that cannot be condensed out.
    #[error(
        "K restricted to the {count} massless DOFs is singular (at {dof}): they cannot be \
         condensed out; a massless part is not held by stiffness"
    )]
    MasslessSingular {
        /// How many massless DOFs.
        count: usize,
        /// The DOF where the factorisation failed.
        dof: Dof,
    },
    /// M not positive: a negative eigenvalue.
    #[error("M has a negative eigenvalue ({}, largest {}): a mass matrix must be positive", num(*.value), num(*.largest))]
    NegativeMass {
        /// The most negative eigenvalue.
        value: f64,
        /// The largest eigenvalue, for scale.
        largest: f64,
    },
    /// M singular on the DOFs that carry mass.
    #[error(
        "M is singular (eigenvalue {} of largest {}): a combination of DOFs carries no mass; \
         condense it out in the FE code", num(*.value), num(*.largest))]
    SingularMass {
        /// The smallest eigenvalue.
        value: f64,
        /// The largest eigenvalue.
        largest: f64,
    },
    /// K has a clearly negative eigenvalue.
    #[error("K has a negative eigenvalue ({} of largest {}): a stiffness matrix must be positive semi-definite", num(*.value), num(*.largest))]
    NegativeStiffness {
        /// The most negative eigenvalue of K phi = lambda M phi.
        value: f64,
        /// The largest.
        largest: f64,
    },
    /// A rigid motion is not a zero-energy motion of K.
    #[error(
        "rigid motion '{motion}' is not in K's null space (|K r|/|K||r| = {}, largest \
         residual at {dof}){diagnosis}", num(*.rel))]
    NotRigid {
        /// Which of the six motions (e.g. `rotation about z through the CoM`).
        motion: String,
        /// The relative residual.
        rel: f64,
        /// The DOF with the largest residual.
        dof: Dof,
        /// What K's null space says instead (units, zero-energy count), from `"; "`.
        diagnosis: String,
        /// K has no zero-energy mode: the matrices are of a held body, which the command
        /// can say how to import.
        held: bool,
    },
    /// More zero-energy modes than rigid motions.
    #[error("K has {0} zero-energy modes (6 expected): mechanism")]
    Mechanism(usize),
    /// One DOF's stiffness-to-mass ratio is so far from the others' that no
    /// double-precision eigen-solve resolves both ([`scale::SPREAD_LIMIT`]).
    #[error(
        "{entries}: the ratios K_ii/M_ii of the DOFs span {spread} (DOF {dof} against \
         {other}), more than double precision resolves ({}): check that entry (a unit \
         slip or a typo)",
        num(scale::SPREAD_LIMIT)
    )]
    Spread {
        /// The DOF farthest from the others.
        dof: Dof,
        /// The DOF at the other end of the spread.
        other: Dof,
        /// Its K and M diagonal entries and the matrices' names, printed.
        entries: String,
        /// The spread, as a power of ten.
        spread: String,
    },
    /// Blocked asked for (or detected), K singular.
    #[error(
        "{first}K is singular ({zero} zero-energy modes): apply the supports before \
         reduction"
    )]
    SingularBlocked {
        /// Number of zero-energy modes.
        zero: usize,
        /// What the coordinates say about K's null space, said first (units), or empty.
        first: String,
        /// What the command could suggest besides importing the body as free.
        hint: Option<SingularHint>,
    },
    /// K is positive definite, but its lowest eigenvalue is at round-off of the largest.
    #[error(
        "K's lowest eigenvalue ({}) is at the eigen-solver's round-off of the largest ({}): \
         the model's frequencies span more than double precision resolves (a stiffness \
         or mass entry far off, or a model that needs a reduction in the FE code first)",
        num(*.lowest), num(*.largest))]
    Unresolved {
        /// The lowest eigenvalue computed.
        lowest: f64,
        /// The largest.
        largest: f64,
    },
    /// Nothing left after the cut.
    #[error("no local mode: {0}")]
    NoModes(String),
    /// The built body fails the `.fxb` checks (a defect of the import, or an input at the
    /// edge of what a body can be).
    #[error("the built body is not valid: {0}")]
    Invalid(String),
    /// A cut-off frequency that is not finite and positive.
    #[error("the cut-off frequency must be finite and > 0 Hz, got {}", num(*.0))]
    BadFmax(f64),
    /// Rayleigh damping coefficients (alpha, beta) not finite and >= 0.
    #[error("Rayleigh alpha and beta must be finite and >= 0, got {},{}", num(*.0), num(*.1))]
    BadDamping(f64, f64),
    /// The eigen-solve came back inaccurate: the modes are not orthogonal to round-off.
    #[error(
        "the computed modes are not the eigenmodes of the matrices: Phi^T M Phi and \
         Phi^T K Phi depart from diagonal by {} (at most {} from round-off at that mode); \
         the eigen-solver failed on these matrices, nothing was written",
        fxbody::num::num(*.departure),
        fxbody::num::num(*.allowed)
    )]
    Inaccurate {
        /// The departure found.
        departure: f64,
        /// What round-off allows there ([`assemble::MAX_DEPARTURE`] plus the eigen-solve's
        /// own floor for that mode).
        allowed: f64,
    },
}

/// A built body: the file, the node coordinates it refers to, and the report.
#[derive(Debug, Clone)]
pub struct Imported {
    /// The `.fxb` contents.
    pub file: FxbFile,
    /// Coordinates of the FXB nodes (target units), in node order, when known.
    pub coords: Option<Vec<[f64; 3]>>,
    /// What was built, dropped and checked.
    pub report: Report,
}

/// Wall time of the import's stages, printed to stderr when the environment variable
/// `FXBODY_IMPORT_TIMES` is set (to profile a large import; off by default).
pub(crate) struct Stages {
    start: Option<std::time::Instant>,
    last: f64,
    lines: Vec<String>,
}

impl Stages {
    pub(crate) fn new() -> Stages {
        let on = std::env::var_os("FXBODY_IMPORT_TIMES").is_some();
        Stages {
            start: on.then(std::time::Instant::now),
            last: 0.0,
            lines: Vec::new(),
        }
    }

    /// The stage `name` ended now.
    pub(crate) fn done(&mut self, name: &str) {
        if let Some(t) = self.start {
            let now = t.elapsed().as_secs_f64();
            self.lines
                .push(format!("import stage {name:<28} {:8.3} s", now - self.last));
            self.last = now;
        }
    }
}

impl Drop for Stages {
    fn drop(&mut self) {
        if self.start.is_some() {
            for l in &self.lines {
                eprintln!("{l}");
            }
            eprintln!("import stage {:<28} {:8.3} s", "total", self.last);
        }
    }
}

/// The option values `build` and the whole-model route refuse before any work.
pub(crate) fn check_options(opts: &Options) -> Result<(), ImportError> {
    if let Some(f) = opts.fmax
        && !(f.is_finite() && f > 0.0)
    {
        return Err(ImportError::BadFmax(f));
    }
    if let Some((a, b)) = opts.damping
        && !(a.is_finite() && b.is_finite() && a >= 0.0 && b >= 0.0)
    {
        return Err(ImportError::BadDamping(a, b));
    }
    Ok(())
}

/// Build a body from K and M (see the module text). `coords_file` names the coordinates'
/// file in messages.
pub fn build(
    k: &SymMatrix,
    m: &SymMatrix,
    coords: Option<&BTreeMap<i64, [f64; 3]>>,
    coords_file: &str,
    opts: &Options,
) -> Result<Imported, ImportError> {
    check_options(opts)?;
    let mut report = Report::default();
    let mut stages = Stages::new();
    let mut model = dofs::DofMatrices::from_matrices(k, m)?;
    let coords: Option<BTreeMap<i64, [f64; 3]>> = coords.map(|c| {
        let f = opts.units.map_or(1.0, |u| u.length);
        c.iter()
            .map(|(&id, x)| (id, [x[0] * f, x[1] * f, x[2] * f]))
            .collect()
    });
    if let Some(u) = &opts.units {
        model.convert(u);
    }
    let mut reduced = dofs::reduce(model, &mut report)?;
    scale::check_spread(&reduced, &k.name, &m.name)?;
    scale::normalise(&mut reduced);
    stages.done("DOFs, condensation");
    let grid_ids = reduced.grid_ids();
    let node_ids = match &opts.nodes {
        None => grid_ids.clone(),
        Some(ids) => dofs::check_nodes(ids, &grid_ids)?,
    };
    let on_nodes = reduced
        .z
        .iter()
        .filter(|&&i| node_ids.contains(&reduced.all[i].id) && !reduced.all[i].is_scalar())
        .count();
    if on_nodes > 0 {
        report.warnings.push(Warning::Text(format!(
            "{on_nodes} massless DOFs of the body's nodes were condensed out: a force or \
             moment applied there acts through the DOFs with mass only (its local \
             flexibility with those held has no mass to make a mode of)"
        )));
    }
    if let Some(c) = &coords
        && let Some(&id) = grid_ids.iter().find(|id| !c.contains_key(id))
    {
        return Err(ImportError::NoCoordinates {
            id,
            file: coords_file.to_string(),
        });
    }
    let props = match &coords {
        Some(c) => Some(rigid::MassProps::of(&reduced, c)?),
        None => None,
    };
    stages.done("mass properties");
    let form = modes::StandardForm::factor(&reduced)?;
    stages.done("Cholesky of M, L^-1 K L^-T");
    let free = support::classify(&reduced, props.as_ref(), opts.support, &form, &mut report)?;
    stages.done("support (definiteness)");
    let rigid = if free { props.as_ref() } else { None };
    let cut = opts
        .fmax
        .map(|f| reduced.scale.eigenvalue_in(modes::cut_eigenvalue(f)));
    let el = modes::elastic(&reduced, &form, rigid, cut, &mut |s| stages.done(s))?;
    if let Some(w) = modes::resolution_warning(&el, free, props.is_some()) {
        report.warnings.push(Warning::Resolution(w));
    }
    let basis = modes::local_basis(&reduced, &el, &form.l, rigid, &node_ids, &mut report)?;
    drop(form);
    stages.done("cut, static modes, scaling");
    let file = assemble::fxb(&reduced, &basis, rigid, &node_ids, opts, &mut report)?;
    stages.done("assembly (M_C, K_C, checks)");
    fxbody::body::Body::from_fxb(&file, "the imported body")
        .map_err(|e| ImportError::Invalid(e.to_string()))?;
    stages.done("body check");
    if let Some(p) = &props {
        report.mass_properties(p, reduced.scale);
    }
    let node_coords = coords.map(|c| node_ids.iter().map(|id| c[id]).collect());
    Ok(Imported {
        file,
        coords: node_coords,
        report,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A library message names no command-line option: no `--` followed by a letter.
    fn names_no_option(text: &str) -> bool {
        !text
            .as_bytes()
            .windows(3)
            .any(|w| w[0] == b'-' && w[1] == b'-' && w[2].is_ascii_alphabetic())
    }

    #[test]
    fn the_option_finder_finds_an_option() {
        assert!(!names_no_option("give --coords"));
        assert!(names_no_option("a - b -- c"));
    }

    /// The refusal of a model too large for the dense route says where to go, in words.
    #[test]
    fn too_large_names_no_option() {
        let text = ImportError::TooLarge(4000).to_string();
        assert!(names_no_option(&text), "{text}");
        assert!(
            text.contains("4000 DOFs exceeds the limit of 3000"),
            "{text}"
        );
        assert!(text.contains("sparse route"), "{text}");
    }

    /// Coordinates whose rigid motions K holds nowhere, on a K of a held body: the data
    /// says so, the message names no option.
    #[test]
    fn not_rigid_of_a_held_body_names_no_option() {
        let e = ImportError::NotRigid {
            motion: "x".into(),
            rel: 1.0,
            dof: Dof::new(3, 1),
            diagnosis: "; K has no zero-energy mode: the matrices are of a held body".into(),
            held: true,
        };
        let text = e.to_string();
        assert!(names_no_option(&text), "{text}");
        assert!(text.ends_with("the matrices are of a held body"), "{text}");
    }

    /// A whole model without connection nodes: what to give, in words.
    #[test]
    fn no_connections_names_no_option() {
        let e = ImportError::NoConnections {
            deck: "JOB.inp".into(),
        };
        let text = e.to_string();
        assert!(names_no_option(&text), "{text}");
        assert!(
            text.starts_with("JOB.inp has no *RIGID BODY spider"),
            "{text}"
        );
    }

    /// The resolution warning, with and without the advice for a body that may be free,
    /// in the library's words: no option named.
    #[test]
    fn the_resolution_warning_names_no_option() {
        for maybe_free in [false, true] {
            let w = Warning::Resolution(Resolution {
                ratio: 5.7e-15,
                accuracy: 0.039,
                maybe_free,
            });
            let text = w.to_string();
            assert!(names_no_option(&text), "{text}");
            assert!(text.contains("5.7e-15 of the largest"), "{text}");
            assert_eq!(text.contains("import it as free"), maybe_free, "{text}");
        }
    }
}
