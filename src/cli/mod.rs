//! Command line (SPEC §5).

use clap::Parser;
use std::process::ExitCode;

/// `bv`: an interactive BRDF viewer and its command-line tools.
#[derive(Debug, Parser)]
#[command(name = "bv", version, about)]
pub struct Cli {
    /// Options of the viewer window (used when no sub-command is given).
    #[command(flatten)]
    pub viewer: crate::app::ViewerArgs,
}

/// Entry point of the binary.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match crate::app::run(&cli.viewer) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("bv: {e:#}");
            ExitCode::FAILURE
        }
    }
}
