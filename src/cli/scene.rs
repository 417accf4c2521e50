//! `bv scene`: check, print and create scene files from the command line
//! (the viewer opens them with `bv --scene FILE` or Ctrl+O; `bv render
//! --scene FILE` draws them).

use super::output::eprint;
use crate::session::scene_file as scene;
use crate::session::state::AppState;
use anyhow::{Result, bail};
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
        /// Where to write it (see --help for what happens to an existing file).
        #[arg(short, long, value_name = "FILE", long_help = super::output::OUT_HELP)]
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
                b.spec.id(),
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

/// Reads a scene file; the message names the file once (what `bv scene
/// check` says, and the Python module's `bv.Scene.load` raises).
pub fn load(file: &std::path::Path) -> Result<scene::Loaded> {
    scene::load(file).map_err(|e| match e {
        scene::SceneError::File(e) => anyhow::Error::new(e),
        e => anyhow::Error::new(e).context(file.display().to_string()),
    })
}

/// Runs `bv scene`.
pub fn run(a: &SceneArgs, argv: &[String]) -> Result<()> {
    match &a.action {
        SceneAction::Check { file } => {
            let loaded = load(file)?;
            for w in &loaded.warnings {
                eprint(&format!("bv scene: {}: warning: {w}\n", file.display()));
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
            let loaded = load(file)?;
            for w in &loaded.warnings {
                eprint(&format!("bv scene: {}: warning: {w}\n", file.display()));
            }
            // Paths as they would be saved in this file (relative to its folder).
            super::output::print(&scene::to_toml_for(file, &loaded.state)?)
        }
        SceneAction::New { opts, out } => {
            let state = new_state(opts, argv)?;
            scene::save(out, &state)?;
            eprint(&format!(
                "bv scene: wrote {}: {}\n",
                out.display(),
                summary(&state)
            ));
            Ok(())
        }
    }
}

/// Builds the state of `bv scene new`, pairing each --param with the
/// --model before it on the command line.
pub fn new_state(o: &NewScene, argv: &[String]) -> Result<AppState> {
    let groups = group_params(argv)?;
    let grouped: usize = groups.iter().map(Vec::len).sum();
    if groups.len() != o.model.len() || grouped != o.params.len() {
        // The command line has a form the pairing below does not read; refuse
        // rather than give a parameter to the wrong model or drop it.
        bail!(
            "cannot tell which --model each --param belongs to; write each as \
             `--param NAME=VALUE` after its `--model ID`"
        );
    }
    let mut specs = Vec::with_capacity(o.model.len());
    for (k, m) in o.model.iter().enumerate() {
        let params = groups.get(k).cloned().unwrap_or_default();
        specs.push(super::params::spec_from_cli(m, &params)?);
    }
    state_with(specs, o)
}

/// The scene of `specs` (in order; none: the first-run scene's BRDFs) with
/// `o`'s light and display options (its `model`/`params` are not read),
/// checked as a scene file is: what `bv scene new` writes, and the Python
/// module's `bv.Scene(models, …)` holds.
pub fn state_with(specs: Vec<bv_core::ModelSpec>, o: &NewScene) -> Result<AppState> {
    let mut state = if specs.is_empty() {
        AppState::first_run()
    } else {
        AppState::default()
    };
    for spec in specs {
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
        state.theme = crate::session::state::Theme::Light;
    }
    // The same checks a scene file gets; what it would clamp is refused here,
    // where the user can say it again.
    let text = scene::to_toml(&state)?;
    let loaded = scene::from_toml(&text)?;
    if let Some(w) = loaded.warnings.first() {
        bail!("{w}");
    }
    Ok(loaded.state)
}

/// The `--param` values after each `--model` (index k: the k-th model).
/// A `--param` before any `--model` is an error (there is no model for it).
fn group_params(argv: &[String]) -> Result<Vec<Vec<String>>> {
    let mut groups: Vec<Vec<String>> = Vec::new();
    let mut it = argv.iter().skip(1);
    while let Some(a) = it.next() {
        if a == "--" {
            break;
        }
        // `--name=value`, `-xvalue`, `-x=value`, or a flag whose value follows.
        let (flag, inline) = if let Some(rest) = a.strip_prefix("--") {
            match rest.split_once('=') {
                Some((f, v)) => (format!("--{f}"), Some(v.to_string())),
                None => (a.clone(), None),
            }
        } else if a.len() > 2 && a.starts_with('-') && a.is_char_boundary(2) {
            let v = &a[2..];
            (
                a[..2].to_string(),
                Some(v.strip_prefix('=').unwrap_or(v).to_string()),
            )
        } else {
            (a.clone(), None)
        };
        let mut value = || inline.clone().or_else(|| it.next().cloned());
        match flag.as_str() {
            "--model" | "-m" => {
                let _ = value();
                groups.push(Vec::new());
            }
            "--param" | "-p" => {
                let v = value().unwrap_or_default();
                match groups.last_mut() {
                    Some(g) => g.push(v),
                    None => bail!(
                        "{flag} {v} comes before any --model: each --param sets the \
                         --model before it, e.g. `--model lambert --param albedo=0.3`"
                    ),
                }
            }
            // Options that take a value: skip it, so that a value is never
            // read as a flag.
            "--out" | "-o" | "--theta-i" | "--phi-i" => {
                let _ = value();
            }
            _ => {}
        }
    }
    Ok(groups)
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
            group_params(&argv).unwrap(),
            vec![
                vec!["albedo=0.2".to_string()],
                vec!["alpha_x=0.1".to_string()]
            ]
        );
    }

    fn args(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn attached_short_values_are_paired_too() {
        let argv = args(&[
            "bv",
            "scene",
            "new",
            "-mlambert",
            "-palbedo=0.2",
            "-o",
            "-p",
        ]);
        assert_eq!(
            group_params(&argv).unwrap(),
            vec![vec!["albedo=0.2".to_string()]]
        );
    }

    #[test]
    fn a_param_before_any_model_is_an_error() {
        let argv = args(&["bv", "scene", "new", "-p", "albedo=0.2", "-m", "lambert"]);
        let e = group_params(&argv).unwrap_err().to_string();
        assert!(e.contains("-p albedo=0.2 comes before any --model"), "{e}");
    }
}
