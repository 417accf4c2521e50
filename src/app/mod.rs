//! The viewer window (issue 3 builds it).

/// Options of the viewer window, flattened into the top-level command line.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ViewerArgs {}

/// Opens the viewer window.
pub fn run(_args: &ViewerArgs) -> anyhow::Result<()> {
    anyhow::bail!("the viewer window is not part of this build yet")
}
