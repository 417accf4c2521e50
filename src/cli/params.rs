//! The model and parameter options shared by the sub-commands
//! (`--model ID --param NAME=VALUE …`).

use anyhow::{Context, bail};
use bv_core::ModelSpec;

/// `--model ID [--param NAME=VALUE]…`, flattened into `check` and `bench`.
#[derive(Debug, Clone, clap::Args)]
pub struct ModelArgs {
    /// Model id (see `bv models`).
    #[arg(short, long, value_name = "ID")]
    pub model: String,

    /// A parameter value, repeatable: `--param alpha=0.3`, a colour as
    /// `--param kd=0.2,0.5,0.8` (one number means grey), a choice by name
    /// (`--param distribution=ggx`), lists as JSON. Unset parameters keep their
    /// defaults; a later value for the same name wins.
    #[arg(short, long = "param", value_name = "NAME=VALUE")]
    pub params: Vec<String>,
}

impl ModelArgs {
    /// The validated model spec these options describe.
    pub fn spec(&self) -> anyhow::Result<ModelSpec> {
        spec_from_cli(&self.model, &self.params)
    }
}

/// Builds a validated [`ModelSpec`] from a model id and `NAME=VALUE` strings.
///
/// Parsing and range checks are the core's (`ModelSpec::set_str`), so the
/// command line accepts exactly what scene files and `bv eval` accept, with the
/// same messages naming the parameter and its range.
pub fn spec_from_cli(model: &str, params: &[String]) -> anyhow::Result<ModelSpec> {
    let mut spec = ModelSpec::new(model.trim()).with_context(|| format!("--model {model}"))?;
    for p in params {
        let Some((name, value)) = p.split_once('=') else {
            bail!("--param {p}: expected NAME=VALUE (e.g. --param alpha=0.3)");
        };
        let name = name.trim();
        if name.is_empty() {
            bail!("--param {p}: the parameter name is empty (expected NAME=VALUE)");
        }
        spec.set_str(name, value.trim())
            .with_context(|| format!("--param {p}"))?;
    }
    Ok(spec)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strings(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn grey_and_colour_forms() {
        let s = spec_from_cli("lambert", &strings(&["albedo=0.25"])).unwrap();
        assert_eq!(
            s.params().color("albedo").unwrap(),
            glam::DVec3::splat(0.25)
        );
        let s = spec_from_cli("lambert", &strings(&["albedo = 0.1, 0.2,0.3"])).unwrap();
        assert_eq!(
            s.params().color("albedo").unwrap(),
            glam::DVec3::new(0.1, 0.2, 0.3)
        );
    }

    #[test]
    fn defaults_when_no_param() {
        let s = spec_from_cli("lambert", &[]).unwrap();
        assert_eq!(s, ModelSpec::new("lambert").unwrap());
    }

    #[test]
    fn errors_name_the_culprit() {
        let msg = |m: &str, p: &[&str]| format!("{:#}", spec_from_cli(m, &strings(p)).unwrap_err());
        assert!(msg("nope", &[]).contains("unknown model `nope`"));
        assert!(msg("lambert", &["albedo"]).contains("expected NAME=VALUE"));
        assert!(msg("lambert", &["=0.3"]).contains("name is empty"));
        let e = msg("lambert", &["albedo=2"]);
        assert!(e.contains("albedo") && e.contains("out of range"), "{e}");
        let e = msg("lambert", &["rho=0.3"]);
        assert!(
            e.contains("no parameter `rho`") && e.contains("albedo"),
            "{e}"
        );
        assert!(msg("lambert", &["albedo=abc"]).contains("not a number"));
        assert!(msg("lambert", &["albedo=0.1,0.2"]).contains("albedo"));
    }
}
