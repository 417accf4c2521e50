//! `bv check`: the properties of SPEC §3 for one model and parameter set.

use super::params::ModelArgs;

/// Options of `bv check`.
#[derive(Debug, Clone, clap::Args)]
pub struct CheckArgs {
    /// The model and its parameters.
    #[command(flatten)]
    pub model: ModelArgs,

    /// Print JSON instead of the readable table.
    #[arg(long)]
    pub json: bool,
}

/// Runs `bv check`.
pub fn run(args: &CheckArgs) -> anyhow::Result<()> {
    let _spec = args.model.spec()?;
    anyhow::bail!("`bv check` is not part of this build yet")
}
