//! `bv check`: the properties (positivity, reciprocity, isotropy,
//! energy, D normalisation) for one model and parameter set, each with its
//! sample or quadrature count and error, beside what the model claims.

use super::output::print;
use super::params::ModelArgs;
use anyhow::Context;
use bv_core::analysis::albedo::AlbedoMethod;
use bv_core::analysis::{self, CheckOptions};
use serde_json::Value;
use std::process::ExitCode;

/// How `bv check` integrates the albedo.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum AlbedoChoice {
    /// Quadrature for analytic models, Monte Carlo for measured ones.
    Auto,
    /// Deterministic Gauss–Kronrod quadrature (error estimate, about 1e-6).
    Quadrature,
    /// Monte Carlo with 16 replicas (one standard error), the cross-check.
    MonteCarlo,
}

/// The exit status of `bv check --strict` when the report fails.
pub const STRICT_FAILURE: u8 = 3;

/// Options of `bv check`.
#[derive(Debug, Clone, clap::Args)]
#[command(
    after_help = "Exit status: 0 when the report was printed (whatever it says); \
    with --strict, 3 when a verdict contradicts what the model claims, positivity or D \
    normalisation fails, or energy is violated (claimed or not); 1 on an error, 2 on a usage \
    error."
)]
pub struct CheckArgs {
    /// The model and its parameters.
    #[command(flatten)]
    pub model: ModelArgs,

    /// Print the report as JSON (with the parameters used) instead of a table.
    #[arg(long)]
    pub json: bool,

    /// How the albedo (ρhd, ρhh) is integrated: `auto` uses quadrature for
    /// analytic models (within 1e-5 absolute, with its error estimate) and
    /// Monte Carlo for measured ones; `monte-carlo` cross-checks an analytic
    /// model with the sampling estimator.
    #[arg(long, value_enum, default_value = "auto")]
    pub albedo: AlbedoChoice,

    /// Exit with status 3 (after printing the report) when a verdict
    /// contradicts a claim, positivity or D normalisation fails, or energy is
    /// violated, so that a script can test the result. Without it the
    /// status is 0 whatever the report says.
    #[arg(long)]
    pub strict: bool,
}

/// Runs `bv check`: the exit status is 0, or [`STRICT_FAILURE`] with
/// `--strict` when the report fails.
pub fn run(args: &CheckArgs) -> anyhow::Result<ExitCode> {
    let spec = args.model.spec()?;
    let report = report(&spec, args.albedo)?;
    if args.json {
        let v = report_json(&report, &spec)?;
        print(&format!("{}\n", serde_json::to_string_pretty(&v)?))?;
    } else {
        print(&format!("{report}"))?;
    }
    Ok(if args.strict && report.strict_failure() {
        ExitCode::from(STRICT_FAILURE)
    } else {
        ExitCode::SUCCESS
    })
}

/// The property report of `spec` with the albedo integrated as `albedo`
/// says, within the command's time budget (what `bv check` prints, and the
/// Python module's `Model.check()` returns).
pub fn report(
    spec: &bv_core::ModelSpec,
    albedo: AlbedoChoice,
) -> anyhow::Result<analysis::PropertyReport> {
    let brdf = spec
        .build()
        .with_context(|| format!("building model `{}`", spec.id()))?;
    let opts = CheckOptions {
        albedo_method: match albedo {
            AlbedoChoice::Auto => AlbedoMethod::Auto,
            AlbedoChoice::Quadrature => AlbedoMethod::Quadrature,
            AlbedoChoice::MonteCarlo => AlbedoMethod::MonteCarlo,
        },
        ..CheckOptions::default()
    };
    let (serial, parallel) = opts.evaluations(brdf.as_ref());
    let work = super::budget::Work {
        serial,
        parallel,
        threads: rayon::current_num_threads(),
    };
    super::budget::start(brdf.as_ref(), "bv check", work, super::budget::CHECK)?;
    let report = analysis::check(brdf.as_ref(), &opts);
    super::budget::finish(brdf.as_ref(), "check")?;
    Ok(report)
}

/// The report as `bv check --json` prints it: the core's report with the
/// parameters used (the report names the model; the parameters make it
/// reproducible).
pub fn report_json(
    report: &analysis::PropertyReport,
    spec: &bv_core::ModelSpec,
) -> anyhow::Result<Value> {
    let mut v = serde_json::to_value(report).context("encoding the report as JSON")?;
    if let Value::Object(m) = &mut v {
        m.insert("params".into(), spec.params().to_json());
    }
    Ok(v)
}
