//! `bv check`: the properties of SPEC §3 (positivity, reciprocity, isotropy,
//! energy, D normalisation) for one model and parameter set, each with its
//! sample or quadrature count and error, beside what the model claims.

use super::output::print;
use super::params::ModelArgs;
use anyhow::Context;
use bv_core::analysis::{self, CheckOptions};
use serde_json::Value;

/// Options of `bv check`.
#[derive(Debug, Clone, clap::Args)]
pub struct CheckArgs {
    /// The model and its parameters.
    #[command(flatten)]
    pub model: ModelArgs,

    /// Print the report as JSON (with the parameters used) instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Runs `bv check`.
pub fn run(args: &CheckArgs) -> anyhow::Result<()> {
    let spec = args.model.spec()?;
    let brdf = spec
        .build()
        .with_context(|| format!("building model `{}`", spec.model))?;
    let report = analysis::check(brdf.as_ref(), &CheckOptions::default());
    if args.json {
        let mut v = serde_json::to_value(&report).context("encoding the report as JSON")?;
        // The report names the model; the parameters make it reproducible.
        if let Value::Object(m) = &mut v {
            m.insert("params".into(), spec.params.to_json());
        }
        print(&format!("{}\n", serde_json::to_string_pretty(&v)?))
    } else {
        print(&format!("{report}"))
    }
}
