//! `fxbody reduce FILE -o OUT.fxb [--nodes ID,...] [--fmax HZ]`: a smaller, valid `.fxb`
//! holding only the chosen nodes' mode rows and the modes up to fmax
//! ([`fxbody::scene::reduce`]). The dropped modes' residual flexibility cannot be written in the
//! file format: it is printed, and `fxbody pack --fmax` recomputes it from the full file.

use std::fmt::Write;
use std::path::PathBuf;

use fxbody::fxb;
use fxbody::num::{count, num};
use fxbody::scene::reduce::{ReduceError, node_indices, select_nodes, to_fxb, truncate};

/// Arguments of `reduce`.
#[derive(Debug, clap::Args)]
pub struct ReduceArgs {
    /// The `.fxb` file.
    pub file: PathBuf,
    /// The reduced `.fxb` file to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Node IDs to keep, and ranges A-B, separated by commas and/or blanks (default:
    /// all).
    #[arg(long, value_parser = crate::grammar::node_list)]
    pub nodes: Option<crate::grammar::NodeIds>,
    /// Keep the modes of (K_L, m_L) up to this frequency, Hz (default: all).
    #[arg(long)]
    pub fmax: Option<f64>,
}

/// Run `reduce`: write the file and a summary on stdout, or the error message.
pub fn run(args: &ReduceArgs) -> Result<(), String> {
    let body = fxbody::body::load(&args.file, Default::default())
        .map_err(|e| crate::info::not_a_body(&args.file).unwrap_or_else(|| e.to_string()))?;
    for w in body.warnings() {
        eprintln!("warning: {w}");
    }
    let input_nodes = body.nnodes();
    let nodes = match &args.nodes {
        Some(ids) => node_indices(&body, &ids.0).map_err(|e| format!("--nodes: {e}"))?,
        None => (0..body.nnodes()).collect(),
    };
    let mut o = String::new();
    let (body, residual) = match args.fmax {
        Some(fmax) => {
            let t = truncate(&body, fmax).map_err(|e| match e {
                ReduceError::BadFmax(_) => format!("--fmax: {e}"),
                e => e.to_string(),
            })?;
            let _ = writeln!(
                o,
                "modes: kept {} of {} (up to {} Hz; highest kept {:.6e} Hz), dropped {}",
                t.kept,
                body.nl(),
                num(fmax),
                t.kept_hz.last().copied().unwrap_or(0.0),
                t.dropped_hz.len()
            );
            (t.body.clone(), Some(t.residual(&nodes)))
        }
        None => (body, None),
    };
    let reduced = select_nodes(&body, &nodes);
    let text = fxb::write(&to_fxb(&reduced));
    std::fs::write(&args.output, &text)
        .map_err(|e| format!("{}: cannot write: {e}", args.output.display()))?;
    let _ = writeln!(
        o,
        "{}: {}, {}, Freq {:.9e} Hz, {} bytes (input {})",
        args.output.display(),
        count(reduced.nnodes(), "node"),
        count(reduced.nl(), "local mode"),
        reduced.freq_file(),
        text.len(),
        count(input_nodes, "node")
    );
    if let Some(r) = residual
        && r.dropped > 0
    {
        o.push_str(
            "residual flexibility of the dropped modes (local frame; not expressible in \
             .fxb: `fxbody pack --fmax` recomputes it from the full file). Diagonal, \
             per node X Y Z (m/N) XX YY ZZ (rad/(N m)):\n",
        );
        for (k, &n) in nodes.iter().enumerate() {
            let d: Vec<String> = (0..6)
                .map(|c| format!("{:.6e}", r.r[(6 * k + c, 6 * k + c)]))
                .collect();
            let _ = writeln!(o, "  node {}: {}", body.node_ids()[n], d.join(" "));
        }
    }
    print!("{o}");
    Ok(())
}
