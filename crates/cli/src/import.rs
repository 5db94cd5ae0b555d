//! `fxbody import`: build a `.fxb` body from FE matrices ([`fxbody::import`]).
//!
//! `fxbody import model.pch --coords nodes.csv -o body.fxb` (Nastran DMIG KAAX/MAAX), or
//! `fxbody import --stiffness K.mtx --mass M.mtx [--dof-map job.dof] --coords ... -o
//! body.fxb` (Abaqus MATRIX INPUT lines, or CalculiX `.sti`/`.mas` with `.dof`). Writes
//! the body, its node coordinates beside it (`body.nodes.csv`, for `fxbody pack
//! --coords`), a report on stdout and, with `--report`, as JSON.

use std::path::{Path, PathBuf};

use fxbody::fe::{self, SymMatrix};
use fxbody::fxb;
use fxbody::import::{self, Options, Support};

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

/// Run `import`: write the files and the report, or return the error message.
pub fn run(args: &ImportArgs) -> Result<(), String> {
    let (k, m) = read_matrices(args)?;
    let coords = match &args.coords {
        Some(p) => Some(fe::read_coords(p).map_err(|e| e.to_string())?),
        None => None,
    };
    let opts = Options {
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
    };
    let coords_name = args
        .coords
        .as_ref()
        .map_or_else(String::new, |p| p.display().to_string());
    let built =
        import::build(&k, &m, coords.as_ref(), &coords_name, &opts).map_err(|e| e.to_string())?;
    let mut out = built.report.text();
    if let Some(c) = args.units {
        out.push_str(&format!(
            "units: the body is in {} (declare them in the FMU with fxbody pack --units {})\n",
            c.to, c.to
        ));
    }
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
