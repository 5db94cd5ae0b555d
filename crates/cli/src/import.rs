//! `fxbody import`: build a `.fxb` body from FE matrices ([`fxbody_import`]).
//!
//! `fxbody import model.pch --coords nodes.csv -o body.fxb` (Nastran DMIG KAAX/MAAX), or
//! `fxbody import --stiffness K.mtx --mass M.mtx [--dof-map job.dof] --coords ... -o
//! body.fxb` (Abaqus MATRIX INPUT lines, or CalculiX `.sti`/`.mas` with `.dof`), or a
//! whole CalculiX model, `fxbody import JOB.inp --fmax F -o body.fxb` (the deck, with
//! `JOB.sti`, `JOB.mas`, `JOB.dof` beside it). Writes the body, its node coordinates
//! beside it (`body.nodes.csv`, for `fxbody pack --coords`), a report on stdout and, with
//! `--report`, as JSON.
//!
//! Route: a model above [`fxbody_import::MAX_DENSE_DOFS`] DOFs, a CalculiX deck, or
//! `--sparse` goes through the whole-model route ([`fxbody_import::whole`]); a small
//! reduced model (a Nastran punch) through the dense one.

mod stages;

use std::path::{Path, PathBuf};

use fxbody::fxb;
use fxbody_import::fe::{self, Deck, SymMatrix};
use fxbody_import::report::MAYBE_FREE;
use fxbody_import::whole::spider::SpiderSpec;
use fxbody_import::whole::{WholeModel, WholeOptions};
use fxbody_import::{
    ImportError, Imported, MAX_DENSE_DOFS, Options, SingularHint, Support, Warning,
};

/// Arguments of `import`.
#[derive(Debug, clap::Args)]
pub struct ImportArgs {
    /// Nastran DMIG file (punch `.pch` or bulk data) holding the stiffness and mass, or a
    /// CalculiX deck `JOB.inp` whose matrix storage (`JOB.sti`, `JOB.mas`, `JOB.dof`, from
    /// `*FREQUENCY, SOLVER=MATRIXSTORAGE`) lies beside it: the whole model, with its
    /// `*RIGID BODY` spiders as connection nodes.
    pub model: Option<PathBuf>,
    /// Stiffness file (Abaqus `*MATRIX OUTPUT` lines, or CalculiX `.sti` with --dof-map),
    /// instead of a DMIG file.
    #[arg(long, conflicts_with = "model", requires = "mass")]
    pub stiffness: Option<PathBuf>,
    /// Mass file, same format as --stiffness.
    #[arg(long, conflicts_with = "model", requires = "stiffness")]
    pub mass: Option<PathBuf>,
    /// CalculiX `.dof` file mapping equation numbers to `node.dof`.
    #[arg(long, requires = "stiffness")]
    pub dof_map: Option<PathBuf>,
    /// Node coordinates (GRID cards, Radioss /NODE, Abaqus *NODE, or CSV id,x,y,z), in the
    /// matrices' length unit, global frame. Required for a free body.
    #[arg(long)]
    pub coords: Option<PathBuf>,
    /// The `.fxb` file to write.
    #[arg(short, long, required_unless_present = "check")]
    pub output: Option<PathBuf>,
    /// The body is free (K's null space must be the six rigid motions).
    #[arg(long, conflicts_with = "blocked")]
    pub free: bool,
    /// The body is held (K must be positive definite).
    #[arg(long)]
    pub blocked: bool,
    /// DMIG name of the stiffness.
    #[arg(long, default_value = "KAAX")]
    pub k_name: String,
    /// DMIG name of the mass.
    #[arg(long, default_value = "MAAX")]
    pub m_name: String,
    /// Keep the eigenmodes up to this frequency (Hz in the target units) and add static
    /// modes so that statics at the nodes stay exact.
    #[arg(long)]
    pub fmax: Option<f64>,
    /// Units: FROM:TO converts from the matrices' system to the body's; one system says
    /// the matrices are in it and the body stays in it. Each system SI, or
    /// LENGTH-MASS-TIME with length m|cm|mm|um|km, mass kg|g|mg|t, time s|ms|us (e.g.
    /// mm-t-s:mm-kg-ms, SI:mm-t-s, mm-kg-ms). Declare the body's system in the FMU with
    /// `pack --units`.
    #[arg(long, value_parser = crate::grammar::unit_conversion)]
    pub units: Option<crate::grammar::Conversion>,
    /// FXB node IDs, and ranges A-B, separated by commas and/or blanks (e.g. 101,105-110;
    /// default: every grid point).
    #[arg(long, value_parser = crate::grammar::node_list)]
    pub nodes: Option<crate::grammar::NodeIds>,
    /// Rayleigh damping ALPHA,BETA (1/s, s in the body's units; e.g. 5,1e-5).
    #[arg(long, value_parser = crate::grammar::pair, value_name = "ALPHA,BETA")]
    pub damping: Option<(f64, f64)>,
    /// Also write the report as JSON to this file.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Check and report only; write no body.
    #[arg(long)]
    pub check: bool,
    /// Build a spider on a node set of the deck, as a connection node: NSET:rigid
    /// (RBE2-like: a new six-DOF node at the set's centroid, the set's nodes tied rigidly
    /// to it) or NSET:distributing (RBE3-like: a new six-DOF node at the set's
    /// area-weighted centre whose motion is the weighted mean of the set's, adding no
    /// stiffness); whole models only. May be repeated.
    #[arg(long)]
    pub spider: Vec<String>,
    /// Whole models: `modes` keeps the model's own modes below --fmax plus static modes
    /// (the body's frequencies below fmax are the model's); `craig-bampton` keeps the
    /// fixed-interface modes below --fmax plus constraint modes.
    #[arg(long, default_value = "modes")]
    pub reduction: String,
    /// Take the whole-model route (sparse reduction, needs --fmax) whatever the model's
    /// size; by default only models above 3000 DOFs and CalculiX decks take it.
    #[arg(long)]
    pub sparse: bool,
    /// No progress display on stderr.
    #[arg(long, short)]
    pub quiet: bool,
    /// Test only: write OpenRadioss's naive M_R = Phi_R^T M Phi_R.
    #[arg(long, hide = true)]
    pub naive_mass_r: bool,
}

/// Every input of `import`, checked before any is read: a regular file no larger than
/// its kind can need (a device, FIFO or directory is refused naming the option).
fn check_inputs(args: &ImportArgs) -> Result<(), String> {
    use fxbody::fxb::input::{Limit, check_input};
    let given = [
        ("DMIG file", &args.model, Limit::Matrix),
        ("--stiffness", &args.stiffness, Limit::Matrix),
        ("--mass", &args.mass, Limit::Matrix),
        ("--dof-map", &args.dof_map, Limit::Matrix),
        ("--coords", &args.coords, Limit::Coordinates),
    ];
    for (option, path, limit) in given {
        if let Some(p) = path {
            check_input(option, p, limit).map_err(|e| e.to_string())?;
        }
    }
    Ok(())
}

/// What the import builds from: a small model's matrices for the dense route, or a whole
/// model with its deck (coordinates, spiders) and the deck's name.
enum Source {
    Dense(SymMatrix, SymMatrix),
    Whole(WholeModel, Deck, String),
}

/// Whether `path` names a CalculiX/Abaqus deck (`.inp`).
fn is_deck(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("inp"))
}

/// `dir/JOB.inp` -> `dir/JOB`.
fn job_of(deck: &Path) -> PathBuf {
    deck.with_extension("")
}

/// Read what the chosen route needs (see the module text).
fn read_source(args: &ImportArgs, stages: &mut stages::StageBar) -> Result<Source, String> {
    check_inputs(args)?;
    let e = |e: fe::FeError| e.to_string();
    stages.stage("read");
    if let Some(deck_path) = args.model.as_ref().filter(|p| is_deck(p)) {
        if args.coords.is_some() {
            return Err(format!(
                "--coords: the deck {} gives the node coordinates; leave --coords out",
                deck_path.display()
            ));
        }
        let job = job_of(deck_path);
        let deck = fe::read_deck(deck_path).map_err(e)?;
        let ms = fe::calculix::read_job(&job).map_err(e)?;
        let name = format!("{}.sti/.mas/.dof", job.display());
        return Ok(Source::Whole(
            WholeModel {
                dofs: ms.dofs,
                k: ms.k,
                m: ms.m,
                name,
            },
            deck,
            deck_path.display().to_string(),
        ));
    }
    if let (Some(k), Some(m), Some(map)) = (&args.stiffness, &args.mass, &args.dof_map) {
        let dofs = fe::calculix::read_dofs(map).map_err(e)?;
        if args.sparse || dofs.len() > fxbody_import::MAX_DENSE_DOFS {
            let deck = read_whole_coords(args)?;
            let kk = fe::calculix::read_matrix(k, &dofs, map).map_err(e)?;
            let mm = fe::calculix::read_matrix(m, &dofs, map).map_err(e)?;
            let name = format!("{}, {}, {}", k.display(), m.display(), map.display());
            return Ok(Source::Whole(
                WholeModel {
                    dofs,
                    k: kk,
                    m: mm,
                    name,
                },
                deck.0,
                deck.1,
            ));
        }
    }
    let (k, m) = read_matrices(args)?;
    let size = k.dofs.len().max(m.dofs.len());
    if args.sparse || size > fxbody_import::MAX_DENSE_DOFS {
        let (deck, deck_name) = read_whole_coords(args)?;
        let name = args
            .model
            .as_ref()
            .or(args.stiffness.as_ref())
            .map_or_else(String::new, |p| p.display().to_string());
        let model = WholeModel::from_terms(&k, &m, name).map_err(|e| e.to_string())?;
        return Ok(Source::Whole(model, deck, deck_name));
    }
    Ok(Source::Dense(k, m))
}

/// The coordinates (and spiders, from a deck) of a whole model given by --stiffness,
/// --mass, --dof-map: a `.inp` deck is read as one, any other coordinate file for its
/// nodes only.
fn read_whole_coords(args: &ImportArgs) -> Result<(Deck, String), String> {
    let Some(p) = &args.coords else {
        return Err(
            "a whole model needs its node coordinates: give --coords with the deck (.inp, \
             which also gives the *RIGID BODY spiders) or a coordinate file"
                .into(),
        );
    };
    let name = p.display().to_string();
    if is_deck(p) {
        return Ok((fe::read_deck(p).map_err(|e| e.to_string())?, name));
    }
    let nodes = fe::read_model_coords(p)
        .map_err(|e| e.to_string())?
        .into_iter()
        .collect();
    Ok((
        Deck {
            nodes,
            ..Deck::default()
        },
        name,
    ))
}

fn read_matrices(args: &ImportArgs) -> Result<(SymMatrix, SymMatrix), String> {
    let e = |e: fe::FeError| e.to_string();
    if let Some(model) = &args.model {
        let (k, m) = (
            fe::read_dmig(model, &args.k_name).map_err(e)?,
            fe::read_dmig(model, &args.m_name).map_err(e)?,
        );
        for a in [&k, &m] {
            if let Some(w) = small_field_warning(a, model) {
                eprintln!("fxbody import: warning: {w}");
            }
        }
        return Ok((k, m));
    }
    let (Some(k), Some(m)) = (&args.stiffness, &args.mass) else {
        return Err(
            "give a DMIG file (fxbody import model.pch ...) or --stiffness and --mass".into(),
        );
    };
    Ok(match &args.dof_map {
        Some(map) => (
            fe::read_calculix(k, map).map_err(e)?,
            fe::read_calculix(m, map).map_err(e)?,
        ),
        None => (
            fe::read_abaqus(k).map_err(e)?,
            fe::read_abaqus(m).map_err(e)?,
        ),
    })
}

/// Values with fewer significant digits than this are warned about (a 1e-7 relative
/// rounding and more).
const WARN_DIGITS: u32 = 8;

/// The warning for a DMIG matrix whose 8-character values carry fewer than
/// [`WARN_DIGITS`] significant digits: the relative rounding of its values, and why it
/// matters more than it seems (docs/IMPORT.md, "Precision").
fn small_field_warning(a: &SymMatrix, file: &Path) -> Option<String> {
    let d = a.small_field_digits.filter(|&d| d < WARN_DIGITS)?;
    let rounding = 0.5 * 10f64.powi(1 - d as i32);
    Some(format!(
        "{}: DMIG {}: values written in 8 characters (small field) carry as few as {d} \
         significant digits, a relative rounding of up to {rounding:.0e}; frequencies can \
         move by much more where stiffness terms cancel (docs/IMPORT.md, \"Precision\"): \
         write the matrices in large field (16 columns) or free field",
        file.display(),
        a.name
    ))
}

/// `body.fxb` -> `body.nodes.csv`.
fn coords_path(output: &Path) -> PathBuf {
    output.with_extension("nodes.csv")
}

/// The message of an import error on the command line: the library's errors carry data
/// and name no option; the options that set that data are this command's to name.
fn worded(e: &ImportError) -> String {
    match e {
        ImportError::BadFmax(_) => format!("--fmax: {e}"),
        ImportError::BadDamping(..) => format!("--damping: {e}"),
        ImportError::BadNodes(_) => format!("--nodes: {e}"),
        ImportError::CoordinatesNeeded => format!("{e}: give --coords"),
        ImportError::TooLarge(n) => format!(
            "dense size {n} DOFs exceeds the limit of {MAX_DENSE_DOFS}: import the whole model \
             through the sparse route with --fmax (a CalculiX deck JOB.inp, or these matrices \
             with --coords and --nodes), or reduce it in your FE code"
        ),
        ImportError::NotRigid { held: true, .. } => format!("{e} (import them without --free)"),
        ImportError::NoConnections { deck } => format!(
            "{deck} has no *RIGID BODY spider whose REF node moves: give the connection nodes \
             with --nodes, or build a spider with --spider NSET:rigid"
        ),
        ImportError::BadSpider(_) => format!("--spider: {e}"),
        ImportError::FmaxNeeded { .. } => format!("{e}: give --fmax"),
        ImportError::SingularBlocked { hint, .. } => format!(
            "{e}, or use --free{}",
            match hint {
                Some(SingularHint::RigidMotions) => {
                    "; K's zero modes are exactly rigid motions: did you mean --free?"
                }
                Some(SingularHint::GiveCoords) =>
                    "; for a free body give its coordinates (--coords)",
                None => "",
            }
        ),
        _ => e.to_string(),
    }
}

/// A warning of the import's report on the command line: the advice names the options
/// that give what the library's wording only describes.
fn warning_worded(w: &Warning) -> String {
    match w {
        Warning::Resolution(r) if r.maybe_free => format!(
            "{}{MAYBE_FREE}: give its coordinates (--coords) and --free",
            r.finding()
        ),
        _ => w.to_string(),
    }
}

/// Run `import`: write the files and the report, or return the error message.
pub fn run(args: &ImportArgs) -> Result<(), String> {
    let mut stages = stages::StageBar::new(args.quiet);
    let built = build(args, &mut stages)?;
    stages.stage("write");
    let out = write(args, &built)?;
    drop(stages);
    print!("{out}");
    Ok(())
}

/// The body, by the route the input takes.
fn build(args: &ImportArgs, stages: &mut stages::StageBar) -> Result<Imported, String> {
    let source = read_source(args, stages)?;
    let opts = options(args)?;
    match source {
        Source::Whole(model, deck, deck_name) => {
            let spiders = args
                .spider
                .iter()
                .map(|s| SpiderSpec::parse(s))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| e.to_string())?;
            let whole = WholeOptions {
                spiders,
                craig_bampton: match args.reduction.as_str() {
                    "modes" => false,
                    "craig-bampton" => true,
                    other => {
                        return Err(format!(
                            "--reduction: expected modes or craig-bampton, got '{other}'"
                        ));
                    }
                },
            };
            fxbody_import::whole::build_whole(&model, &deck, &deck_name, &opts, &whole, &mut |s| {
                stages.stage(s)
            })
            .map_err(|e| worded(&e))
        }
        Source::Dense(k, m) => {
            if !args.spider.is_empty() {
                return Err(
                    "--spider: spiders are built on whole models only (a CalculiX \
                            deck, or matrices above 3000 DOFs, or --sparse)"
                        .into(),
                );
            }
            let coords = match &args.coords {
                Some(p) => Some(
                    fe::read_model_coords(p)
                        .map_err(|e| e.to_string())?
                        .into_iter()
                        .collect(),
                ),
                None => None,
            };
            let coords_name = args
                .coords
                .as_ref()
                .map_or_else(String::new, |p| p.display().to_string());
            stages.stage("body");
            fxbody_import::build(&k, &m, coords.as_ref(), &coords_name, &opts)
                .map_err(|e| worded(&e))
        }
    }
}

/// The import options from the arguments.
fn options(args: &ImportArgs) -> Result<Options, String> {
    Ok(Options {
        support: match (args.free, args.blocked) {
            (true, _) => Support::Free,
            (_, true) => Support::Blocked,
            _ => Support::Detect,
        },
        fmax: args.fmax,
        units: args.units.map(|c| c.factors()),
        nodes: args.nodes.clone().map(|n| n.0),
        damping: args.damping,
        naive_mass_r: args.naive_mass_r,
    })
}

/// Write the body, its coordinates and the JSON report; the report text for stdout.
fn write(args: &ImportArgs, built: &Imported) -> Result<String, String> {
    let mut out = built.report.text(&warning_worded);
    if let Some(c) = args.units {
        out.push_str(&format!(
            "units: the body is in {} (declare them in the FMU with fxbody pack --units {})\n",
            c.to, c.to
        ));
    }
    if let Some(path) = &args.report {
        let text = serde_json::to_string_pretty(&built.report.json(&warning_worded))
            .map_err(|e| format!("--report: {e}"))?;
        std::fs::write(path, text + "\n")
            .map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    }
    if let (Some(path), false) = (&args.output, args.check) {
        let text = fxb::write(&built.file);
        std::fs::write(path, &text)
            .map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
        out.push_str(&format!(
            "wrote {} ({} bytes)\n",
            path.display(),
            text.len()
        ));
        if let Some(c) = &built.coords {
            let cp = coords_path(path);
            let mut csv = String::from("id,x,y,z\n");
            for (id, x) in built.file.node_ids.iter().zip(c) {
                csv.push_str(&format!("{id},{:e},{:e},{:e}\n", x[0], x[1], x[2]));
            }
            std::fs::write(&cp, csv).map_err(|e| format!("{}: cannot write: {e}", cp.display()))?;
            out.push_str(&format!(
                "wrote {} (node coordinates for fxbody pack --coords)\n",
                cp.display()
            ));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The singular-K refusal reads as it did when the library wrote the options:
    /// the hints are data, the command names --free and --coords.
    #[test]
    fn singular_blocked_hints_name_the_options() {
        let e = |hint| ImportError::SingularBlocked {
            zero: 6,
            first: String::new(),
            hint,
        };
        let base = "K is singular (6 zero-energy modes): apply the supports before reduction, \
                    or use --free";
        assert_eq!(worded(&e(None)), base);
        assert_eq!(
            worded(&e(Some(SingularHint::RigidMotions))),
            format!("{base}; K's zero modes are exactly rigid motions: did you mean --free?")
        );
        assert_eq!(
            worded(&e(Some(SingularHint::GiveCoords))),
            format!("{base}; for a free body give its coordinates (--coords)")
        );
    }

    /// The refusals and the warning whose advice the library gives as data read on the
    /// command line as they did when the library wrote the options (issue 27.6).
    #[test]
    fn refusals_and_warnings_given_as_data_name_the_options() {
        assert_eq!(
            worded(&ImportError::TooLarge(4000)),
            "dense size 4000 DOFs exceeds the limit of 3000: import the whole model through \
             the sparse route with --fmax (a CalculiX deck JOB.inp, or these matrices with \
             --coords and --nodes), or reduce it in your FE code"
        );
        let held = ImportError::NotRigid {
            motion: "x".into(),
            rel: 0.5,
            dof: fe::Dof::new(3, 1),
            diagnosis: "; K has no zero-energy mode: the matrices are of a held body".into(),
            held: true,
        };
        assert_eq!(
            worded(&held),
            "rigid motion 'x' is not in K's null space (|K r|/|K||r| = 0.5, largest residual \
             at 3.1); K has no zero-energy mode: the matrices are of a held body (import them \
             without --free)"
        );
        assert_eq!(
            worded(&ImportError::NoConnections {
                deck: "JOB.inp".into()
            }),
            "JOB.inp has no *RIGID BODY spider whose REF node moves: give the connection nodes \
             with --nodes, or build a spider with --spider NSET:rigid"
        );
        let resolution = |maybe_free| {
            warning_worded(&Warning::Resolution(fxbody_import::Resolution {
                ratio: 5.7e-15,
                accuracy: 0.039,
                maybe_free,
            }))
        };
        let finding = "the lowest eigenvalue is 5.7e-15 of the largest: double precision \
                       guarantees it only to about 0.039 relative (its frequency to half \
                       that), and matrices written with fewer digits (a punch's 10) may not \
                       determine it at all";
        assert_eq!(resolution(false), finding);
        assert_eq!(
            resolution(true),
            format!(
                "{finding}; if the body is free, its six lowest modes may be rigid motions the \
                 rounding left slightly stiff: give its coordinates (--coords) and --free"
            )
        );
    }
}
