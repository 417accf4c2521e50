//! The model and parameter options shared by the sub-commands
//! (`--model ID --param NAME=VALUE …`, or `--preset NAME` for a material
//! preset's model and parameters).

use anyhow::{Context, bail};
use bv_core::ModelSpec;
use bv_core::error::quote;
use bv_core::presets::{self, Preset};

/// `--model ID [--param NAME=VALUE]…` or `--preset NAME [--param …]`,
/// flattened into `check`, `bench`, `slice` and `tabulate`.
#[derive(Debug, Clone, clap::Args)]
pub struct ModelArgs {
    /// Model id (see `bv models`).
    #[arg(
        short,
        long,
        value_name = "ID",
        required_unless_present = "preset",
        conflicts_with = "preset"
    )]
    pub model: Option<String>,

    /// A material preset (its model and parameters), by name or file name:
    /// `--preset Gold`, `--preset ct1982-copper`; `--param` values apply on
    /// top. `bv models` does not list them; an unknown name lists close ones.
    #[arg(long, value_name = "NAME")]
    pub preset: Option<String>,

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
        match (&self.preset, &self.model) {
            (Some(p), _) => preset_spec_from_cli(p, &self.params),
            (None, Some(m)) => spec_from_cli(m, &self.params),
            (None, None) => bail!("give --model ID or --preset NAME"),
        }
    }
}

/// The compiled-in presets (those that parse; the core's tests hold all).
pub fn shipped_presets() -> &'static [Preset] {
    presets::shipped_presets()
}

/// The shipped preset called `name` (its display name or its file name,
/// ignoring case). An unknown name is an error listing the close matches.
pub fn find_preset(name: &str) -> anyhow::Result<&'static Preset> {
    Ok(presets::find(name)?)
}

/// A preset's spec with `NAME=VALUE` strings applied on top (the same
/// parsing and messages as [`spec_from_cli`]).
pub fn preset_spec_from_cli(name: &str, params: &[String]) -> anyhow::Result<ModelSpec> {
    let preset = find_preset(name).with_context(|| format!("--preset {}", quote(name)))?;
    let mut spec = preset.spec.clone();
    apply_params(&mut spec, params)?;
    Ok(spec)
}

/// Builds a validated [`ModelSpec`] from a model id and `NAME=VALUE` strings.
///
/// Parsing and range checks are the core's (`ModelSpec::set_str`), so the
/// command line accepts exactly what scene files and `bv eval` accept, with the
/// same messages naming the parameter and its range.
pub fn spec_from_cli(model: &str, params: &[String]) -> anyhow::Result<ModelSpec> {
    let mut spec =
        ModelSpec::new(model.trim()).with_context(|| format!("--model {}", quote(model)))?;
    apply_params(&mut spec, params)?;
    Ok(spec)
}

/// Sets `NAME=VALUE` strings on `spec`, naming the offending `--param`.
fn apply_params(spec: &mut ModelSpec, params: &[String]) -> anyhow::Result<()> {
    for p in params {
        // The option as messages quote it: a 100 KB value is not echoed whole.
        let shown = quote(p);
        let Some((name, value)) = p.split_once('=') else {
            bail!("--param {shown}: expected NAME=VALUE (e.g. --param alpha=0.3)");
        };
        let name = name.trim();
        if name.is_empty() {
            bail!("--param {shown}: the parameter name is empty (expected NAME=VALUE)");
        }
        spec.set_str(name, value.trim())
            .with_context(|| format!("--param {shown}"))?;
    }
    Ok(())
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
        // A huge value is quoted by its start and size, never whole.
        for p in [
            format!("albedo={}", "9".repeat(100_000)),
            format!("albedo=x{}", "y".repeat(100_000)),
            format!("{}=0.5", "q".repeat(100_000)),
            "a".repeat(100_000),
        ] {
            let e = msg("lambert", &[p.as_str()]);
            assert!(
                e.len() < 600 && e.contains("bytes)"),
                "{}",
                &e[..e.len().min(600)]
            );
        }
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

    #[test]
    fn presets_by_name_or_file_and_close_matches() {
        let gold = find_preset("gold").unwrap();
        assert_eq!(gold.name, "Gold");
        assert_eq!(
            find_preset("ct1982-copper").unwrap().name,
            "Copper (Cook-Torrance 1982)"
        );
        let e = format!("{:#}", find_preset("Gld").unwrap_err());
        assert!(
            e.contains("unknown preset `Gld`") && e.contains("Gold"),
            "{e}"
        );
        assert_eq!(find_preset(" COPPER ").unwrap().name, "Copper");
        let e = format!("{:#}", find_preset("qqqqqqqqqqqq").unwrap_err());
        assert!(e.contains("the presets are") && e.contains("Water"), "{e}");
        // --param applies on top of the preset's values.
        let a = preset_spec_from_cli("Gold", &[]).unwrap();
        assert_eq!(a, gold.spec);
        let first = gold.spec.model().params[0].id;
        assert!(preset_spec_from_cli("Gold", &[format!("{first}=abc")]).is_err());
    }
}
