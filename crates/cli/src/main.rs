//! The `fxbody` command: a thin dispatcher, one subcommand per module, over the library
//! (`fxbody`), the FE import (`fxbody-import`) and the FMI importer (`fxbody-host`, for
//! `demo`). The speed/accuracy study is a command of its own (`fxbody-study`), not
//! compiled in here.

mod demo;
mod grammar;
mod import;
mod info;
mod info_modes;
mod pack;
mod progress;
mod reduce;

use clap::{Parser, Subcommand};

/// What `fxbody --help` says first: what the tool does for its users.
const ABOUT: &str = "Turn a Radioss flexible body (/FXBODY, .fxb) or FE matrices into an FMI 2.0 \
                     co-simulation unit (.fmu) for any FMI master, C program or fmpy";

/// The command line: one subcommand per job.
#[derive(Debug, Parser)]
#[command(name = "fxbody", version, about = ABOUT)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Show what a .fxb file holds: counts, flags, nodes, frequencies, stable step, mass.
    Info(info::InfoArgs),
    /// Pack a .fxb file into an FMI 2.0 co-simulation FMU.
    Pack(Box<pack::PackArgs>),
    /// Build a .fxb body from FE matrices (Nastran DMIG, Abaqus, CalculiX) and coordinates.
    Import(Box<import::ImportArgs>),
    /// Write a smaller .fxb: only the chosen nodes, only the modes up to fmax.
    Reduce(reduce::ReduceArgs),
    /// The main job: pack the shipped cantilever, run a tip step load through the FMU's C ABI.
    Demo(demo::DemoArgs),
}

fn main() {
    let cli = Cli::parse_from(grammar::join_pairs(std::env::args_os()));
    let result = match &cli.command {
        Command::Info(args) => info::run(args),
        Command::Pack(args) => pack::run(args),
        Command::Reduce(args) => reduce::run(args),
        Command::Import(args) => import::run(args),
        Command::Demo(args) => demo::run(args),
    };
    if let Err(message) = result {
        eprintln!("fxbody: {message}");
        std::process::exit(2);
    }
}
