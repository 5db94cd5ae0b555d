//! `fxbody pack FILE -o OUT.fmu [--coords DECK|CSV] [--nodes ID,...] [--name NAME]
//! [--units NAME] [--lib PATH]`: a flexible body as an FMI 2.0 co-simulation FMU.

use std::path::PathBuf;

use fxbody::fmu::pack::{PackRequest, find_library, pack};

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
    /// Exposed node IDs, comma-separated (default: all nodes of the body).
    #[arg(long, value_delimiter = ',')]
    pub nodes: Option<Vec<i64>>,
    /// Model name (default: the file name without extension).
    #[arg(long)]
    pub name: Option<String>,
    /// Declare units: SI (m, kg, s) or mm-t-s (mm, tonne, s). Default: none declared.
    #[arg(long)]
    pub units: Option<String>,
    /// The FMU library to embed (default: $FXBODY_LIB, else libfxbody.so next to this
    /// executable).
    #[arg(long)]
    pub lib: Option<PathBuf>,
}

/// Run `pack`: a one-line summary on stdout, or the error message.
pub fn run(args: &PackArgs) -> Result<(), String> {
    let lib = find_library(args.lib.as_deref()).map_err(|e| e.to_string())?;
    let req = PackRequest {
        body: args.file.clone(),
        coords: args.coords.clone(),
        nodes: args.nodes.clone(),
        name: args.name.clone(),
        units: args.units.clone(),
    };
    let p = pack(&req, &lib, &args.output).map_err(|e| e.to_string())?;
    for n in &p.notes {
        eprintln!("fxbody pack: {n}");
    }
    let size = std::fs::metadata(&args.output)
        .map(|m| m.len())
        .unwrap_or(0);
    println!(
        "{}: model {} (GUID {}), {} exposed nodes, {} variables, {:.1} MB",
        args.output.display(),
        p.options.model_identifier(),
        p.guid,
        p.scene.nodes.len(),
        p.table.vars.len(),
        size as f64 / 1e6
    );
    Ok(())
}
