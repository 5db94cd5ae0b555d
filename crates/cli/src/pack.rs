//! `fxbody pack FILE -o OUT.fmu [--coords DECK|CSV] [--nodes ID,...] [--name NAME]
//! [--units NAME] [--lib PATH] [--nodes-file FILE] [--fmax HZ|auto] [--step H] [--stop T]
//! [--method NAME] [--header FILE.h] [--binary PLATFORM=PATH]... [--embed-source]
//! [--fmi 2|3] [--interface cs|me|both]`: a flexible body as an FMI 2.0 (default) or
//! FMI 3.0 FMU for co-simulation (default), Model Exchange or both, with its OSP model
//! description beside it.

use std::path::PathBuf;

use fxbody::fmu::fmi_version::FmiVersion;
use fxbody::fmu::interface::Interfaces;
use fxbody::fmu::options::method_by_name;
use fxbody::fmu::pack::{
    Fmax, PackError, PackOptions, PackRequest, find_library, pack_reporting, refuse_overwrite,
};
use fxbody::num::count;

/// Arguments of `pack`.
#[derive(Debug, clap::Args)]
pub struct PackArgs {
    /// The `.fxb` file.
    pub file: PathBuf,
    /// The FMU to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Node coordinates: a Radioss starter deck with /NODE, or a CSV file id,x,y,z.
    /// Required for blocked bodies; free bodies without it get coordinates from their
    /// rigid modes (frame origin at 0).
    #[arg(long)]
    pub coords: Option<PathBuf>,
    /// Exposed node IDs, and ranges A-B, separated by commas and/or blanks (e.g.
    /// 121,111 or 101-121; default: all nodes of the body).
    #[arg(long, value_parser = crate::grammar::node_list, conflicts_with = "nodes_file")]
    pub nodes: Option<crate::grammar::NodeIds>,
    /// Exposed node IDs from a file, in the form of --nodes on each line, `#` starts a
    /// comment.
    #[arg(long)]
    pub nodes_file: Option<PathBuf>,
    /// Keep the modes up to this frequency (Hz) and the rest as a static correction;
    /// `auto`: twice the Nyquist frequency of the DefaultExperiment step. Default: all
    /// modes.
    #[arg(long)]
    pub fmax: Option<String>,
    /// Model name (default: the file name without extension).
    #[arg(long)]
    pub name: Option<String>,
    /// Declare the body's units: SI, or LENGTH-MASS-TIME with length m|cm|mm|um|km, mass
    /// kg|g|mg|t, time s|ms|us (e.g. m-kg-s, mm-t-s, mm-kg-ms). Default: none declared.
    #[arg(long, value_parser = crate::grammar::unit_system)]
    pub units: Option<fxbody::units::UnitSystem>,
    /// The FMU library to embed. Without it, the first found of: $FXBODY_LIB;
    /// libfxbody.so next to this executable (a build's target/release/); one folder up;
    /// PREFIX/lib/fxbody/libfxbody.so for this executable at PREFIX/bin/fxbody (what
    /// scripts/install.sh PREFIX installs).
    #[arg(long)]
    pub lib: Option<PathBuf>,
    /// Also store the body file in the FMU (resources/source.fxb), for traceability
    /// only: the FMU runs from its scene file, sized to the exposed nodes.
    #[arg(long)]
    pub embed_source: bool,
    /// DefaultExperiment step size, s (default: derived from the lowest mode, at most
    /// 1 ms); `--fmax auto` follows it.
    #[arg(long)]
    pub step: Option<f64>,
    /// DefaultExperiment stop time, s (default: five periods of the lowest mode).
    #[arg(long)]
    pub stop: Option<f64>,
    /// Start value of the `method` parameter: explicit, implicit, exact (blocked bodies
    /// only) or split (free bodies only), for masters that cannot set parameters.
    /// Default: exact for blocked bodies (no time-discretisation error, any step); split
    /// for free ones (local modes exact between samples, frame second order, any step,
    /// each step's impulse exact: the most accurate per unit of cost on the free bodies
    /// of docs/STUDY.md, where implicit damps the highest modes and explicit is bound by
    /// the stable step).
    #[arg(long)]
    pub method: Option<String>,
    /// Also write a C header with the GUID and every variable's value reference.
    #[arg(long)]
    pub header: Option<PathBuf>,
    /// Add a library built on another platform (`cargo build --release` there):
    /// PLATFORM=PATH with an FMI 2.0 platform name (win32, win64, linux32, darwin32,
    /// darwin64); repeatable.
    #[arg(long, value_parser = binary_arg)]
    pub binary: Vec<(String, PathBuf)>,
    /// FMI version of the FMU: 2 (FMI 2.0, the default, which every master runs) or 3
    /// (FMI 3.0: Float64/Int32 variables, the same names and value references,
    /// binaries/x86_64-linux/). The library inside serves both.
    #[arg(long, default_value = "2", value_parser = fmi_arg)]
    pub fmi: FmiVersion,
    /// FMI interfaces the FMU declares: cs (co-simulation, the default: the body steps
    /// itself), me (Model Exchange: the master's integrator integrates the body's
    /// continuous states; blocked bodies) or both.
    #[arg(long, default_value = "cs", value_parser = interface_arg)]
    pub interface: Interfaces,
}

/// clap value parser of `--interface cs|me|both`.
fn interface_arg(s: &str) -> Result<Interfaces, String> {
    Interfaces::parse(s).ok_or_else(|| {
        format!("expected cs (co-simulation), me (Model Exchange) or both, found '{s}'")
    })
}

/// clap value parser of `--fmi 2|3`.
fn fmi_arg(s: &str) -> Result<FmiVersion, String> {
    FmiVersion::parse(s).ok_or_else(|| format!("expected 2 or 3 (FMI 2.0 or FMI 3.0), found '{s}'"))
}

/// clap value parser of `--binary PLATFORM=PATH`.
fn binary_arg(s: &str) -> Result<(String, PathBuf), String> {
    let (p, path) = s
        .split_once('=')
        .ok_or_else(|| format!("expected PLATFORM=PATH, found '{s}'"))?;
    fxbody::fmu::platforms::check_platform(p).map_err(|e| e.to_string())?;
    Ok((p.to_string(), PathBuf::from(path)))
}

/// Run `pack`: a one-line summary on stdout, or the error message.
pub fn run(args: &PackArgs) -> Result<(), String> {
    let lib = find_library(args.lib.as_deref()).map_err(|e| worded(&e, "-o"))?;
    if let Some(p) = &args.nodes_file {
        refuse_overwrite(&args.output, &[("nodes file", p)]).map_err(|e| worded(&e, "-o"))?;
    }
    let nodes = match &args.nodes_file {
        Some(p) => Some(read_nodes_file(p)?),
        None => args.nodes.clone().map(|n| n.0),
    };
    let fmax = match args.fmax.as_deref() {
        None => None,
        Some("auto") => Some(Fmax::Auto),
        Some(s) => Some(Fmax::Hz(
            s.parse::<f64>()
                .ok()
                .filter(|f| f.is_finite() && *f > 0.0)
                .ok_or_else(|| {
                    format!("--fmax: expected a frequency > 0 (Hz) or 'auto', found '{s}'")
                })?,
        )),
    };
    let req = PackRequest {
        body: args.file.clone(),
        coords: args.coords.clone(),
        nodes,
        name: args.name.clone(),
        units: args.units.map(|u| u.name()),
        embed_source: args.embed_source,
    };
    let method = match args.method.as_deref() {
        None => None,
        Some(m) => Some(method_by_name(m).ok_or_else(|| {
            format!("--method: expected explicit, implicit, exact or split, found '{m}'")
        })?),
    };
    let popts = PackOptions {
        fmax,
        step: args.step,
        stop: args.stop,
        method,
        binaries: args.binary.clone(),
        fmi: args.fmi,
        interface: args.interface,
    };
    let header_prefix = match &args.header {
        Some(h) => {
            refuse_overwrite(h, &[("body file", &args.file)])
                .map_err(|e| worded(&e, "--header"))?;
            Some(fxbody::fmu::header::macro_prefix(h)?)
        }
        None => None,
    };
    let progress = super::progress::Progress::start("packing");
    let p = pack_reporting(&req, &popts, &lib, &args.output, &mut |done, total| {
        progress.update(done, total)
    })
    .map_err(|e| worded(&e, "-o"))?;
    drop(progress);
    for n in &p.notes {
        eprintln!("fxbody pack: {n}");
    }
    if let (Some(h), Some(prefix)) = (&args.header, &header_prefix) {
        std::fs::write(
            h,
            fxbody::fmu::header::c_header(prefix, &p.table, &p.options, &p.guid),
        )
        .map_err(|e| format!("--header {}: cannot write: {e}", h.display()))?;
    }
    let size = std::fs::metadata(&args.output)
        .map(|m| m.len())
        .unwrap_or(0);
    println!(
        "{}: FMI {} model {} (GUID {}), {}, {}, {:.1} MB",
        args.output.display(),
        p.fmi.number(),
        p.options.model_identifier(),
        p.guid,
        count(p.scene.nodes.len(), "exposed node"),
        count(p.table.vars.len(), "variable"),
        size as f64 / 1e6
    );
    Ok(())
}

/// The message of a pack error on the command line: the library's errors carry data and
/// name no option; the options that set that data are this command's to name. `output`:
/// the option that named the file an [`PackError::Overwrite`] would have overwritten.
pub fn worded(e: &PackError, output: &str) -> String {
    match e {
        PackError::BlockedNeedsCoords(_) => {
            format!("{e}: give --coords with a Radioss /NODE deck or a CSV file id,x,y,z")
        }
        PackError::UnknownNode { .. } => format!("--nodes: {e}"),
        PackError::Name(n) => format!("--name: {n}"),
        PackError::StemTooLong { .. } | PackError::StemReserved { .. } => {
            format!("{e}: give --name")
        }
        PackError::Overwrite { .. } => format!("{output} {e}"),
        PackError::LibNotFound(_) => format!("{e}, or give --lib PATH"),
        PackError::Time { what, value } => format!(
            "--{what}: expected a time > 0 (s), found {}",
            fxbody::num::num(*value)
        ),
        // "step 2 s is longer than ..." becomes "--step 2 s is longer than ...".
        PackError::StepAfterStop { stop_given, .. } => {
            format!(
                "--{e}{}",
                if *stop_given { "" } else { ": give --stop too" }
            )
        }
        PackError::NativeBinary { platform, path } => format!(
            "--binary {platform}={}: {platform} is the library this pack embeds itself \
             (give it with --lib)",
            path.display()
        ),
        PackError::Binary {
            platform,
            path,
            why,
        } => format!("--binary {platform}={}: {why}", path.display()),
        _ => e.to_string(),
    }
}

/// Node IDs from a `--nodes-file` ([`crate::grammar::node_file_text`]). Errors name the
/// file and line.
pub fn read_nodes_file(path: &std::path::Path) -> Result<Vec<i64>, String> {
    use fxbody::fxb::input::{Limit, read_input};
    let bytes = read_input("--nodes-file", path, Limit::NodeList).map_err(|e| e.to_string())?;
    let text = String::from_utf8(bytes)
        .map_err(|_| format!("--nodes-file {}: not UTF-8 text", path.display()))?;
    crate::grammar::node_file_text(&text, &path.display().to_string())
}
