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
use fxbody::fmu::osp::OspClash;
use fxbody::fmu::pack::{
    Fmax, PackError, PackNote, PackOptions, PackRequest, find_library, pack, refuse_overwrite,
};
use fxbody::fxb::input::Input;
use fxbody::num::{count, num};

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
            Some(fxbody::fmu::header::macro_prefix(h).map_err(|e| format!("--header {e}"))?)
        }
        None => None,
    };
    let progress = super::progress::Progress::start("packing");
    let p = pack(
        &req,
        &popts,
        &lib,
        &args.output,
        Some(&mut |done, total| progress.update(done, total)),
    )
    .map_err(|e| worded(&e, "-o"))?;
    drop(progress);
    for n in &p.notes {
        eprintln!("fxbody pack: {}", note_worded(n));
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
        PackError::Osp(OspClash::OtherFmu { .. }) => {
            format!("{output} {e}; give this pack another --name, or another folder")
        }
        PackError::Osp(OspClash::NotOurs { .. }) => {
            format!("{output} {e}; move it away, or give this pack another --name")
        }
        PackError::Input(i) => {
            let name = match &i.input {
                Input::Coords => "--coords".to_string(),
                Input::Library => "--lib".to_string(),
                other => other.to_string(),
            };
            let mut text = String::new();
            let _ = i.worded(&name, &mut text);
            text
        }
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

/// A pack note on the command line: the library's notes carry data; this command names
/// the options that set it. Warnings start with `warning: `.
pub fn note_worded(n: &PackNote) -> String {
    let text = match n {
        PackNote::Body(w) => w.clone(),
        PackNote::CoordsDerived => "no --coords: node coordinates derived from the rigid modes, \
             frame origin L0 at (0, 0, 0)"
            .to_string(),
        PackNote::OriginPlaced { coords, origin } => format!(
            "{}: node positions match the rigid modes; frame origin L0 placed at ({}, {}, {})",
            coords.display(),
            num(origin[0]),
            num(origin[1]),
            num(origin[2])
        ),
        PackNote::FmaxAuto { hz, step } => format!(
            "--fmax auto: {} Hz, twice the Nyquist frequency 1/(2H) of the DefaultExperiment \
             step H = {} s",
            num(*hz),
            num(*step)
        ),
        PackNote::FmaxBelowFirstMode { fmax, first } => format!(
            "--fmax {} Hz is below the first mode ({} Hz): no mode kept, the body follows its \
             loads only quasi-statically (residual flexibility); raise --fmax to keep modes",
            num(*fmax),
            num(*first)
        ),
        PackNote::FmaxKeepsAll { fmax, kept } => format!(
            "--fmax {} Hz: all {kept} modes kept (every mode is below it), no residual correction",
            num(*fmax)
        ),
        PackNote::FmaxKeeps { fmax, kept, total } => format!(
            "--fmax {} Hz: {kept} of {total} modes kept, the other {} by their static \
             (residual-flexibility) contribution; positions, rotations and strain energy now \
             depend on the same-instant loads",
            num(*fmax),
            total - kept
        ),
        PackNote::NodeBlocked { id, body } => format!(
            "node {id} is fully blocked: no mode of {body} moves it, so its outputs stay at \
             their initial values and loads on it do nothing"
        ),
        PackNote::ExperimentTooLong {
            stop,
            step,
            steps,
            step_given,
            stop_given,
        } => {
            let advice = match (step_given, stop_given) {
                (true, true) => "give a longer --step or a shorter --stop",
                (true, false) => "give a longer --step (or --stop)",
                _ => "give a shorter --stop (or a longer --step)",
            };
            format!(
                "the DefaultExperiment (stop time {} s, step {} s) takes {} steps, more than {}: \
                 a master running it as written would not finish in a useful time; {advice}",
                num(*stop),
                num(*step),
                num(*steps),
                num(fxbody::fmu::pack::experiment::MAX_EXPERIMENT_STEPS)
            )
        }
        PackNote::StepTooSmall {
            step,
            lowest_hz,
            step_given,
        } => format!(
            "{} {} s is {} of the lowest mode's period {} s, below {}: nothing in the body \
             moves on that time scale; a step of about 1/20 of the period ({} s) resolves the \
             lowest mode",
            if *step_given { "--step" } else { "the step" },
            num(*step),
            num(step * lowest_hz),
            num(1.0 / lowest_hz),
            num(fxbody::fmu::pack::experiment::MIN_STEP_PER_PERIOD),
            num(1.0 / (20.0 * lowest_hz))
        ),
        PackNote::AllNodesExposed { nodes, variables } => format!(
            "all {nodes} nodes are exposed, which makes {variables} variables; expose only the \
             nodes the scene couples to (--nodes or --nodes-file)"
        ),
    };
    if n.is_warning() {
        format!("warning: {text}")
    } else {
        text
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Every note worded as the library wrote it before the notes became data (the
    /// strings of `prepare_reporting` and `experiment::warnings` before issue 27.6,
    /// with the values filled in by hand), so the command's output is unchanged.
    #[test]
    fn every_note_reads_as_before_it_became_data() {
        let cases = [
            (PackNote::Body("w".into()), "warning: w".to_string()),
            (
                PackNote::CoordsDerived,
                "no --coords: node coordinates derived from the rigid modes, frame origin L0 at (0, 0, 0)".into(),
            ),
            (
                PackNote::OriginPlaced {
                    coords: "a/b.csv".into(),
                    origin: [10.0, -3.0, 0.5],
                },
                "a/b.csv: node positions match the rigid modes; frame origin L0 placed at (10, -3, 0.5)".into(),
            ),
            (
                PackNote::FmaxAuto {
                    hz: 1000.0,
                    step: 1e-3,
                },
                "--fmax auto: 1000 Hz, twice the Nyquist frequency 1/(2H) of the DefaultExperiment step H = 0.001 s".into(),
            ),
            (
                PackNote::FmaxBelowFirstMode {
                    fmax: 2.0,
                    first: 6.5,
                },
                "warning: --fmax 2 Hz is below the first mode (6.5 Hz): no mode kept, the body follows its loads only quasi-statically (residual flexibility); raise --fmax to keep modes".into(),
            ),
            (
                PackNote::FmaxKeepsAll {
                    fmax: 1e3,
                    kept: 20,
                },
                "--fmax 1000 Hz: all 20 modes kept (every mode is below it), no residual correction"
                    .into(),
            ),
            (
                PackNote::FmaxKeeps {
                    fmax: 50.0,
                    kept: 3,
                    total: 20,
                },
                "--fmax 50 Hz: 3 of 20 modes kept, the other 17 by their static (residual-flexibility) contribution; positions, rotations and strain energy now depend on the same-instant loads".into(),
            ),
            (
                PackNote::NodeBlocked {
                    id: 101,
                    body: "c.fxb".into(),
                },
                "warning: node 101 is fully blocked: no mode of c.fxb moves it, so its outputs stay at their initial values and loads on it do nothing".into(),
            ),
            (
                PackNote::ExperimentTooLong {
                    stop: 1e6,
                    step: 1e-4,
                    steps: 1e10,
                    step_given: true,
                    stop_given: false,
                },
                "warning: the DefaultExperiment (stop time 1000000 s, step 0.0001 s) takes 1e10 steps, more than 1e9: a master running it as written would not finish in a useful time; give a longer --step (or --stop)".into(),
            ),
            (
                PackNote::StepTooSmall {
                    step: 1e-12,
                    lowest_hz: 10.0,
                    step_given: false,
                },
                "warning: the step 1e-12 s is 1e-11 of the lowest mode's period 0.1 s, below 1e-9: nothing in the body moves on that time scale; a step of about 1/20 of the period (0.005 s) resolves the lowest mode".into(),
            ),
            (
                PackNote::AllNodesExposed {
                    nodes: 56,
                    variables: 1013,
                },
                "warning: all 56 nodes are exposed, which makes 1013 variables; expose only the nodes the scene couples to (--nodes or --nodes-file)".into(),
            ),
        ];
        for (note, want) in cases {
            assert_eq!(note_worded(&note), want);
        }
    }
}
