//! Command line (SPEC §5).

use clap::Parser;
use std::process::ExitCode;

pub mod info;
pub mod tabulate;

/// `bv`: an interactive BRDF viewer and its command-line tools.
#[derive(Debug, Parser)]
#[command(name = "bv", version, about)]
pub struct Cli {
    /// A sub-command; without one, the viewer opens.
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Options of the viewer window (used when no sub-command is given).
    #[command(flatten)]
    pub viewer: crate::app::ViewerArgs,
}

/// Sub-commands (SPEC §5).
#[derive(Debug, clap::Subcommand)]
pub enum Command {
    /// Sample a model into a MERL-layout .binary table.
    Tabulate(tabulate::TabulateArgs),
    /// Describe a MERL .binary file: dimensions, ranges, ρhd, reciprocity.
    Info(info::InfoArgs),
}

/// Entry point of the binary.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Some(Command::Tabulate(a)) => tabulate::run(a),
        Some(Command::Info(a)) => info::run(a),
        None => crate::app::run(&cli.viewer),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("bv: {e:#}");
            ExitCode::FAILURE
        }
    }
}
