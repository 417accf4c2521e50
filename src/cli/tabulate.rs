//! `bv tabulate`: samples any model into a MERL-layout `.binary` table
//! (issue 5, item 3), so that users can build tables and tests can build
//! realistic full-size files.

use anyhow::{Context, Result};
use bv_core::ModelSpec;
use bv_core::measured::merl::{self, MerlDims};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `bv tabulate`.
#[derive(Debug, Clone, clap::Args)]
pub struct TabulateArgs {
    /// Model id (see SPEC §2), e.g. `lambert`.
    #[arg(long)]
    pub model: String,
    /// A parameter as NAME=VALUE (repeatable); a colour as `kd=0.2,0.5,0.8`.
    #[arg(long = "param", value_name = "NAME=VALUE")]
    pub params: Vec<String>,
    /// Output file (written atomically).
    #[arg(long, value_name = "FILE.binary")]
    pub out: PathBuf,
    /// Cells along θh, θd, φd.
    #[arg(long, default_value = "90,90,180", value_name = "NθH,NθD,NΦD")]
    pub dims: String,
}

/// Builds the model from `--model` and `--param`s.
pub fn model_spec(model: &str, params: &[String]) -> Result<ModelSpec> {
    let mut spec = ModelSpec::new(model)?;
    for p in params {
        let (name, value) = p
            .split_once('=')
            .with_context(|| format!("--param `{p}`: expected NAME=VALUE"))?;
        spec.set_str(name.trim(), value.trim())?;
    }
    Ok(spec)
}

/// Runs `bv tabulate`.
pub fn run(args: &TabulateArgs) -> Result<()> {
    let dims = MerlDims::parse(&args.dims).context("--dims")?;
    let spec = model_spec(&args.model, &args.params)?;
    let brdf = spec.build()?;
    if !brdf.claims().isotropic {
        eprintln!(
            "bv: warning: `{}` is anisotropic; the MERL layout has no φh axis, so the table holds its φh = 0 slice",
            args.model
        );
    }
    if !brdf.deltas(glam::DVec3::Z).is_empty() {
        eprintln!(
            "bv: warning: `{}` has delta lobes, which a table cannot hold (they tabulate as 0)",
            args.model
        );
    }
    let start = Instant::now();
    let table = merl::tabulate(brdf.as_ref(), dims)?;
    let tab_s = start.elapsed().as_secs_f64();
    for w in table.warnings().messages() {
        eprintln!("bv: warning: {w}");
    }
    table.write(&args.out)?;
    println!(
        "wrote {}: {} {}, dims {} ({} bytes), tabulated in {:.2} s",
        args.out.display(),
        spec.model,
        spec.params.to_json(),
        dims,
        dims.file_len(),
        tab_s
    );
    Ok(())
}
