//! The `fxbody` command: a thin dispatcher over the library, one subcommand per file in
//! `src/cli/`.

mod cli;

use clap::{Parser, Subcommand};

/// Radioss flexible bodies (/FXBODY, .fxb) for FMI co-simulation.
#[derive(Debug, Parser)]
#[command(name = "fxbody", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Show what a .fxb file holds: counts, flags, nodes, frequencies, stable step, mass.
    Info(cli::info::InfoArgs),
    /// Pack a .fxb file into an FMI 2.0 co-simulation FMU.
    Pack(cli::pack::PackArgs),
    /// Build a .fxb body from FE matrices (Nastran DMIG, Abaqus, CalculiX) and coordinates.
    Import(Box<cli::import::ImportArgs>),
    /// Write a smaller .fxb: only the chosen nodes, only the modes up to fmax.
    Reduce(cli::reduce::ReduceArgs),
    /// The main job: pack the shipped cantilever, run a tip step load through the FMU's C ABI.
    Demo(cli::demo::DemoArgs),
    /// Speed against accuracy: every method over a range of steps, stability map, bound.
    Study(cli::study::StudyArgs),
}

fn main() {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Info(args) => cli::info::run(args),
        Command::Pack(args) => cli::pack::run(args),
        Command::Reduce(args) => cli::reduce::run(args),
        Command::Import(args) => cli::import::run(args),
        Command::Demo(args) => cli::demo::run(args),
        Command::Study(args) => cli::study::run(args),
    };
    if let Err(message) = result {
        eprintln!("fxbody: {message}");
        std::process::exit(2);
    }
}
