//! Command line .
//!
//! `bv` with no sub-command opens the viewer (through the [`Shell`] the
//! binary hands in, so that this layer does not import the window); each
//! sub-command lives in its own module and prints results for scripts:
//!
//! - [`eval`]: JSON Lines queries on stdin, one answer per line on stdout;
//! - [`models`]: the model catalogue with every parameter's range and default;
//! - [`check`]: the properties for one parameter set;
//! - [`bench`]: batch evaluation speed;
//! - [`render`]: figures without a window (PNG, SVG, OBJ/PLY);
//! - [`slice`]: the plotted curves as numbers (CSV);
//! - [`scene`]: check, print and create scene files;
//! - [`simulate`]: the virtual gonioreflectometer on a random microsurface;
//! - [`fit`]: a model's parameters fitted to measured data or another model.
//!
//! Errors are reported as `bv: <message>` on stderr with a non-zero exit
//! status; nothing a user types makes the program panic.

pub mod bench;
pub mod budget;
pub mod check;
pub mod eval;
pub mod fit;
pub mod info;
pub mod models;
pub mod output;
pub mod params;
pub mod render;
pub mod scene;
pub mod simulate;
pub mod slice;
pub mod tabulate;
pub mod viewer_args;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// `bv`: an interactive BRDF viewer and its command-line tools.
#[derive(Debug, Parser)]
#[command(
    name = "bv",
    version,
    about,
    long_about = "bv: an interactive BRDF viewer (lobes, slices, properties).\n\n\
                  With no sub-command it opens the viewer window; the sub-commands \
                  print results for scripts. Conventions: normal +z, tangent +x; \
                  wi (towards the light) and wo (towards the viewer) point away \
                  from the surface; f(wi, wo) is given WITHOUT the cosine factor, \
                  in 1/sr per linear-RGB channel.",
    args_conflicts_with_subcommands = true
)]
pub struct Cli {
    /// What to do; the viewer opens when none is given.
    #[command(subcommand)]
    pub command: Option<Command>,

    /// Options of the viewer window (used when no sub-command is given).
    #[command(flatten)]
    pub viewer: viewer_args::ViewerArgs,
}

/// The sub-commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Evaluate f(wi, wo) for JSON Lines queries read from stdin.
    Eval(eval::EvalArgs),
    /// List every model with its parameters (ranges, defaults, units).
    Models(models::ModelsArgs),
    /// Report a model's properties: positivity, reciprocity, isotropy, energy.
    Check(check::CheckArgs),
    /// Measure batch evaluation speed on fixed-seed random direction pairs.
    Bench(bench::BenchArgs),
    /// Sample a model into a MERL-layout .binary table.
    Tabulate(tabulate::TabulateArgs),
    /// Describe a MERL .binary file: dimensions, ranges, ρhd, reciprocity.
    Info(info::InfoArgs),
    /// Draw a view to PNG (SVG for 2D plots, OBJ/PLY for the lobe) without a window.
    Render(render::RenderArgs),
    /// Print a BRDF slice (the numbers behind the 2D plots), e.g. as CSV.
    Slice(slice::SliceArgs),
    /// Check, print or create scene files.
    Scene(scene::SceneArgs),
    /// Ray-trace a random microsurface: G1, NDF, BRDF and ρhd against the analytic model.
    Simulate(simulate::SimulateArgs),
    /// Fit a model's parameters to a measured file, a user file or another model.
    Fit(fit::FitArgs),
}

/// What the command line needs from the window above it: the binary wires
/// the application's functions in (`src/main.rs`).
#[derive(Clone, Copy)]
pub struct Shell {
    /// Opens the viewer window and returns when it is closed.
    pub run_viewer: fn(&viewer_args::ViewerArgs) -> anyhow::Result<()>,
    /// The window as a figure (`bv render --view window`).
    pub window: crate::export::MakeWindow,
    /// One slide of a lecture deck as presentation mode shows it
    /// (`bv render --deck`).
    pub slide: crate::export::MakeSlide,
}

/// Entry point of the binary.
pub fn main(shell: &Shell) -> ExitCode {
    // `Cli::parse` would print help, version or a usage error itself and
    // exit 0 even when that print fails (`bv --help > /dev/full`).
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return clap_exit(&e),
    };
    // A forced instruction set for the batch kernels (`BV_ISA=avx2`, to
    // measure or test one path) that this CPU cannot run is refused before
    // anything runs, rather than quietly measuring another path.
    if let Err(e) = bv_core::batch::Isa::from_env() {
        output::eprint(&format!("bv: {e}\n"));
        return ExitCode::from(2);
    }
    // Every model argument below (and the window's) may be a `.brdf` path.
    crate::session::user_models::install();
    let result = match &cli.command {
        None => (shell.run_viewer)(&cli.viewer).map(|()| ExitCode::SUCCESS),
        Some(Command::Eval(a)) => eval::run(a),
        Some(Command::Models(a)) => models::run(a).map(|()| ExitCode::SUCCESS),
        Some(Command::Check(a)) => check::run(a),
        Some(Command::Bench(a)) => bench::run(a).map(|()| ExitCode::SUCCESS),
        Some(Command::Tabulate(a)) => tabulate::run(a).map(|()| ExitCode::SUCCESS),
        Some(Command::Info(a)) => info::run(a).map(|()| ExitCode::SUCCESS),
        Some(Command::Render(a)) => render::run(a, shell).map(|()| ExitCode::SUCCESS),
        Some(Command::Slice(a)) => slice::run(a).map(|()| ExitCode::SUCCESS),
        Some(Command::Simulate(a)) => simulate::run(a),
        Some(Command::Fit(a)) => fit::run(a).map(|()| ExitCode::SUCCESS),
        Some(Command::Scene(a)) => {
            let argv: Vec<String> = std::env::args().collect();
            scene::run(a, &argv).map(|()| ExitCode::SUCCESS)
        }
    };
    match result {
        Ok(code) => code,
        // A reader that went away (`bv models | head`) is not an error worth a message.
        Err(e) if output::is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            // Best effort: with stderr gone too, the exit status still says it.
            output::eprint(&format!("bv: {}\n", output::message(&e)));
            ExitCode::FAILURE
        }
    }
}

/// Shows clap's help, version or usage error: help and version on stdout (a
/// failed write of them is an error, status 1), usage errors on stderr
/// (status 2).
fn clap_exit(e: &clap::Error) -> ExitCode {
    use std::io::IsTerminal as _;
    let to_stdout = !e.use_stderr();
    let styled = if to_stdout {
        std::io::stdout().is_terminal()
    } else {
        std::io::stderr().is_terminal()
    };
    let text = if styled {
        e.render().ansi().to_string()
    } else {
        e.render().to_string()
    };
    if to_stdout {
        match output::print(&text) {
            Ok(()) => ExitCode::SUCCESS,
            Err(err) if output::is_broken_pipe(&err) => ExitCode::SUCCESS,
            Err(err) => {
                output::eprint(&format!("bv: {}\n", output::message(&err)));
                ExitCode::FAILURE
            }
        }
    } else {
        output::eprint(&text);
        ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn command_line_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn no_sub_command_means_viewer() {
        let cli = Cli::try_parse_from(["bv"]).unwrap();
        assert!(cli.command.is_none());
    }

    #[test]
    fn params_are_repeatable() {
        let cli = Cli::try_parse_from([
            "bv",
            "bench",
            "--model",
            "lambert",
            "--param",
            "albedo=0.2",
            "-p",
            "albedo=0.3",
        ])
        .unwrap();
        match cli.command {
            Some(Command::Bench(b)) => assert_eq!(b.model.params, ["albedo=0.2", "albedo=0.3"]),
            other => panic!("parsed as {other:?}"),
        }
    }
}
