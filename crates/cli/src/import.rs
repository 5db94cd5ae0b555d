//! `fxbody import`: build a `.fxb` body from FE matrices ([`fxbody_import`]).
//!
//! `fxbody import model.pch --coords nodes.csv -o body.fxb` (Nastran DMIG KAAX/MAAX), or
//! `fxbody import --stiffness K.mtx --mass M.mtx [--dof-map job.dof] --coords ... -o
//! body.fxb` (Abaqus MATRIX INPUT lines, or CalculiX `.sti`/`.mas` with `.dof`). Writes
//! the body, its node coordinates beside it (`body.nodes.csv`, for `fxbody pack
//! --coords`), a report on stdout and, with `--report`, as JSON.

use std::path::{Path, PathBuf};

use fxbody::fxb;
use fxbody_import::fe::{self, SymMatrix};
use fxbody_import::{ImportError, Options, Support, Units};

/// Arguments of `import`.
#[derive(Debug, clap::Args)]
pub struct ImportArgs {
    /// Nastran DMIG file (punch `.pch` or bulk data) holding the stiffness and mass.
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
    /// Convert units, FROM:TO, each LENGTH-MASS-TIME (e.g. mm-t-s:mm-kg-ms).
    #[arg(long)]
    pub units: Option<String>,
    /// FXB node IDs, comma-separated (default: every grid point).
    #[arg(long, value_delimiter = ',')]
    pub nodes: Option<Vec<i64>>,
    /// Rayleigh damping ALPHA,BETA.
    #[arg(long, value_delimiter = ',', num_args = 2)]
    pub damping: Option<Vec<f64>>,
    /// Also write the report as JSON to this file.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Check and report only; write no body.
    #[arg(long)]
    pub check: bool,
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

fn read_matrices(args: &ImportArgs) -> Result<(SymMatrix, SymMatrix), String> {
    check_inputs(args)?;
    let e = |e: fe::FeError| e.to_string();
    if let Some(model) = &args.model {
        return Ok((
            fe::read_dmig(model, &args.k_name).map_err(e)?,
            fe::read_dmig(model, &args.m_name).map_err(e)?,
        ));
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

/// `body.fxb` -> `body.nodes.csv`.
fn coords_path(output: &Path) -> PathBuf {
    output.with_extension("nodes.csv")
}

/// The message of an import error on the command line: the library's errors carry data
/// and name no option; the options that set that data are this command's to name.
fn worded(e: &ImportError) -> String {
    match e {
        ImportError::BadUnits { .. } => format!("--units: {e}"),
        ImportError::BadFmax(_) => format!("--fmax: {e}"),
        ImportError::BadDamping(..) => format!("--damping: {e}"),
        ImportError::BadNodes(_) => format!("--nodes: {e}"),
        ImportError::CoordinatesNeeded => format!("{e}: give --coords"),
        _ => e.to_string(),
    }
}

/// Run `import`: write the files and the report, or return the error message.
pub fn run(args: &ImportArgs) -> Result<(), String> {
    let (k, m) = read_matrices(args)?;
    let coords = match &args.coords {
        Some(p) => Some(
            fe::read_model_coords(p)
                .map_err(|e| e.to_string())?
                .into_iter()
                .collect(),
        ),
        None => None,
    };
    let opts = Options {
        support: match (args.free, args.blocked) {
            (true, _) => Support::Free,
            (_, true) => Support::Blocked,
            _ => Support::Detect,
        },
        fmax: args.fmax,
        units: args
            .units
            .as_deref()
            .map(Units::parse)
            .transpose()
            .map_err(|e| worded(&e))?,
        nodes: args.nodes.clone(),
        damping: args.damping.as_ref().map(|d| (d[0], d[1])),
        naive_mass_r: args.naive_mass_r,
    };
    let coords_name = args
        .coords
        .as_ref()
        .map_or_else(String::new, |p| p.display().to_string());
    let built = fxbody_import::build(&k, &m, coords.as_ref(), &coords_name, &opts)
        .map_err(|e| worded(&e))?;
    let mut out = built.report.text();
    if let Some(path) = &args.report {
        let text = serde_json::to_string_pretty(&built.report.json())
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
    print!("{out}");
    Ok(())
}
