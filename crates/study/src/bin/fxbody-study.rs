//! `fxbody-study`: the speed/accuracy study as a command of its own, so that the research
//! harness is not compiled into the `fxbody` command users install. Run it from the
//! repository with `cargo run --release -p fxbody-study -- --quick` (or
//! `scripts/study.sh`, which runs the peers and the co-simulation study around it).

use clap::Parser;

/// Speed against accuracy: every method over a range of steps, stability map, bound.
#[derive(Debug, Parser)]
#[command(name = "fxbody-study", version)]
struct Cli {
    #[command(flatten)]
    args: fxbody_study::StudyArgs,
}

fn main() {
    let cli = Cli::parse();
    if let Err(message) = fxbody_study::run(&cli.args) {
        eprintln!("fxbody-study: {message}");
        std::process::exit(2);
    }
}
