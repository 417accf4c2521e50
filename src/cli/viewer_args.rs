//! The options of the viewer window, flattened into `bv`'s top-level command
//! line (used when no sub-command is given).

use anyhow::{Context as _, bail};
use std::path::PathBuf;

/// Options of the viewer window, flattened into the top-level command line.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ViewerArgs {
    /// Open the viewer with these models (catalogue ids; repeat for several)
    /// instead of the saved list.
    #[arg(long = "model", value_name = "ID")]
    pub models: Vec<String>,

    /// Open the viewer with these material presets (by name or file name,
    /// e.g. `--preset Gold`; repeat for several), after any `--model`s,
    /// instead of the saved list.
    #[arg(long = "preset", value_name = "NAME")]
    pub presets: Vec<String>,

    /// Start from the defaults: ignore the saved session and do not overwrite it.
    /// (`--screenshot` and `--bench-frames` never overwrite it either.)
    #[arg(long)]
    pub fresh: bool,

    /// Benchmark: once the views have settled at rest (the environment view
    /// converged, renderers built; at most 60 s, after which the report names
    /// the views still at work), drive a scripted slider drag of the selected
    /// BRDF for N frames, print the frame-time p50/p95 and exit. (Set
    /// BV_BENCH_MAXIMISE=lobe|polar|cartesian to time one view alone.)
    #[arg(long, value_name = "N")]
    pub bench_frames: Option<usize>,

    /// Save a PNG screenshot of the window to PATH once it has drawn, and exit.
    #[arg(long, value_name = "PATH")]
    pub screenshot: Option<PathBuf>,

    /// Window size in points, as WIDTHxHEIGHT (default 1280x800).
    #[arg(long, value_name = "WxH")]
    pub size: Option<String>,

    /// Start with the light theme.
    #[arg(long)]
    pub light: bool,

    /// Open a measured BRDF (a MERL `.binary` file) as one more BRDF, read in
    /// the background with a progress bar (repeat for several); a user BRDF
    /// file (`.brdf`) is opened as a model and watched for edits.
    #[arg(long = "open", value_name = "FILE")]
    pub open: Vec<PathBuf>,

    /// Open the Fit… panel (fit a model to a BRDF of the list; also F or
    /// the top bar's button).
    #[arg(long)]
    pub fit: bool,

    /// Open this scene file (TOML, see `bv scene --help`) instead of the saved
    /// session.
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,

    /// Open this lecture deck (TOML: scenes with titles and captions) in
    /// presentation mode: arrow keys / PageDown / PageUp step the scenes,
    /// Home / End jump, Ctrl+S saves the deck with the edits, F5 leaves
    /// presentation mode. The saved session is left alone.
    #[arg(long, value_name = "FILE", conflicts_with = "scene")]
    pub deck: Option<PathBuf>,
}

/// Parses `WIDTHxHEIGHT`.
pub fn parse_size(text: &str) -> anyhow::Result<[f32; 2]> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .with_context(|| format!("window size `{text}` is not WIDTHxHEIGHT (e.g. 1280x800)"))?;
    let w: f32 = w
        .trim()
        .parse()
        .with_context(|| format!("bad width in `{text}`"))?;
    let h: f32 = h
        .trim()
        .parse()
        .with_context(|| format!("bad height in `{text}`"))?;
    if !(200.0..=16384.0).contains(&w) || !(150.0..=16384.0).contains(&h) {
        bail!("window size `{text}` is out of range (200x150 to 16384x16384)");
    }
    Ok([w, h])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_size("1280x800").unwrap(), [1280.0, 800.0]);
        assert!(parse_size("12x8").is_err());
        assert!(parse_size("wide").is_err());
    }
}
