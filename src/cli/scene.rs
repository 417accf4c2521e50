//! `bv scene`: check, print and create scene files from the command line
//! (the viewer opens them with `bv --scene FILE` or Ctrl+O; `bv render
//! --scene FILE` draws them).

use crate::app::scene;
use crate::app::state::AppState;
use anyhow::{Context as _, Result};
use std::path::PathBuf;

/// Options of `bv scene`.
#[derive(Debug, Clone, clap::Args)]
pub struct SceneArgs {
    /// What to do.
    #[command(subcommand)]
    pub action: SceneAction,
}

/// The `bv scene` sub-commands.
#[derive(Debug, Clone, clap::Subcommand)]
pub enum SceneAction {
    /// Read a scene file and report what it holds, its warnings (unknown
    /// keys) or the error that refuses it (exit status 1).
    Check {
        /// The scene file.
        file: PathBuf,
    },
    /// Print a scene file as bv writes it (defaults filled in, keys sorted).
    Print {
        /// The scene file.
        file: PathBuf,
    },
    /// Write a new scene file from the command line (the same options as
    /// `bv render`: --model, --param, --theta-i, --phi-i, --light, --log, …).
    New {
        /// The scene's contents.
        #[command(flatten)]
        opts: NewScene,
        /// Where to write it (atomically).
        #[arg(short, long, value_name = "FILE")]
        out: PathBuf,
    },
}

/// The contents of `bv scene new`.
#[derive(Debug, Clone, clap::Args)]
pub struct NewScene {
    /// Model id (repeat --model for several BRDFs; each takes the --param
    /// values that follow it up to the next --model).
    #[arg(short, long, value_name = "ID")]
    pub model: Vec<String>,
    /// Parameters, `NAME=VALUE` (applied to the last --model before them).
    #[arg(short, long = "param", value_name = "NAME=VALUE")]
    pub params: Vec<String>,
    /// Polar angle of the light, degrees.
    #[arg(long = "theta-i", value_name = "DEG", allow_negative_numbers = true)]
    pub theta_i: Option<f64>,
    /// Azimuth of the light, degrees.
    #[arg(long = "phi-i", value_name = "DEG", allow_negative_numbers = true)]
    pub phi_i: Option<f64>,
    /// Light theme.
    #[arg(long)]
    pub light: bool,
    /// Logarithmic scale.
    #[arg(long)]
    pub log: bool,
    /// Show f · cos θo.
    #[arg(long)]
    pub cosine: bool,
}

fn summary(s: &AppState) -> String {
    let models: Vec<String> = s
        .brdfs
        .iter()
        .map(|b| {
            format!(
                "{}{}",
                b.spec.model,
                if b.visible { "" } else { " (hidden)" }
            )
        })
        .collect();
    format!(
        "{} BRDF{}: {}; light at θi = {}°, φi = {}°{}{}",
        s.brdfs.len(),
        if s.brdfs.len() == 1 { "" } else { "s" },
        if models.is_empty() {
            "none".to_string()
        } else {
            models.join(", ")
        },
        s.incident.theta_deg,
        s.incident.phi_deg,
        if s.display.log { "; log scale" } else { "" },
        if s.display.cosine { "; × cos θo" } else { "" },
    )
}

/// Runs `bv scene`.
pub fn run(a: &SceneArgs, argv: &[String]) -> Result<()> {
    match &a.action {
        SceneAction::Check { file } => {
            let loaded = scene::load(file).with_context(|| format!("{}", file.display()))?;
            for w in &loaded.warnings {
                eprintln!("bv scene: {}: warning: {w}", file.display());
            }
            super::output::print(&format!(
                "{}: ok ({} warning{}): {}\n",
                file.display(),
                loaded.warnings.len(),
                if loaded.warnings.len() == 1 { "" } else { "s" },
                summary(&loaded.state)
            ))
        }
        SceneAction::Print { file } => {
            let loaded = scene::load(file).with_context(|| format!("{}", file.display()))?;
            for w in &loaded.warnings {
                eprintln!("bv scene: {}: warning: {w}", file.display());
            }
            super::output::print(&scene::to_toml(&loaded.state)?)
        }
        SceneAction::New { opts, out } => {
            let state = new_state(opts, argv)?;
            scene::save(out, &state)?;
            eprintln!("bv scene: wrote {}: {}", out.display(), summary(&state));
            Ok(())
        }
    }
}

/// Builds the state of `bv scene new`, pairing each --param with the
/// --model before it on the command line.
pub fn new_state(o: &NewScene, argv: &[String]) -> Result<AppState> {
    let mut state = AppState::default();
    let groups = group_params(argv);
    if o.model.is_empty() {
        state = AppState::first_run();
    }
    for (k, m) in o.model.iter().enumerate() {
        let params = groups.get(k).cloned().unwrap_or_default();
        let spec = super::params::spec_from_cli(m, &params)?;
        state.add(spec);
    }
    if let Some(first) = state.brdfs.first() {
        state.selected = Some(first.id);
    }
    if let Some(t) = o.theta_i {
        state.incident.theta_deg = t;
    }
    if let Some(p) = o.phi_i {
        state.incident.phi_deg = p;
    }
    state.display.log = o.log;
    state.display.cosine = o.cosine;
    if o.light {
        state.theme = crate::app::state::Theme::Light;
    }
    // The same checks a scene file gets.
    let text = scene::to_toml(&state)?;
    Ok(scene::from_toml(&text)?.state)
}

/// The `--param` values after each `--model` (index k: the k-th model).
fn group_params(argv: &[String]) -> Vec<Vec<String>> {
    let mut groups: Vec<Vec<String>> = Vec::new();
    let mut it = argv.iter().peekable();
    while let Some(a) = it.next() {
        let (flag, inline) = match a.split_once('=') {
            Some((f, v)) if f.starts_with("--") => (f, Some(v.to_string())),
            _ => (a.as_str(), None),
        };
        match flag {
            "--model" | "-m" => {
                groups.push(Vec::new());
                if inline.is_none() {
                    it.next();
                }
            }
            "--param" | "-p" => {
                let v = inline.or_else(|| it.next().cloned());
                if let (Some(v), Some(g)) = (v, groups.last_mut()) {
                    g.push(v);
                }
            }
            _ => {}
        }
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn params_follow_their_model() {
        let argv: Vec<String> = [
            "bv",
            "scene",
            "new",
            "--model",
            "lambert",
            "-p",
            "albedo=0.2",
            "--model=ward",
            "--param",
            "alpha_x=0.1",
            "--out",
            "x.toml",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        assert_eq!(
            group_params(&argv),
            vec![
                vec!["albedo=0.2".to_string()],
                vec!["alpha_x=0.1".to_string()]
            ]
        );
    }
}
