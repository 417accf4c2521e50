//! `bv fit`: fits the free parameters of a model to a target BRDF — a
//! measured file (MERL `.binary`, RGL `.bsdf`), a user `.brdf` file or a
//! built-in model with its own parameters — by Levenberg–Marquardt over
//! bv-core's fixed sample set (`bv_core::fit`), and prints the fitted
//! parameters, the error and its profile over θi; `--out` writes a scene
//! with the target and the fit overlaid.

use super::output::{eprint, print};
use super::params::spec_from_cli;
use crate::session::scene_file as scene;
use crate::session::state::AppState;
use anyhow::{Context as _, Result, bail};
use bv_core::error::quote;
use bv_core::fit::{self, FitOptions, FitProgress, Metric};
use serde_json::json;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// Arguments of `bv fit`.
#[derive(Debug, Clone, clap::Args)]
#[command(after_help = "Examples:\n  \
    bv fit -m blinn-phong --to cook-torrance --to-param distribution=ggx --to-param alpha=0.2\n  \
    bv fit -m cook-torrance -p distribution=ggx --free kd,ks,alpha --to gold.bsdf --json\n  \
    bv fit -m ward --to blue-acrylic.binary --metric e2 --out fit.toml")]
pub struct FitArgs {
    /// The model to fit: an id (see `bv models`) or a `.brdf` file.
    #[arg(short, long, value_name = "ID")]
    pub model: String,
    /// A value of the fitted model, repeatable (`-p distribution=ggx`): fixed
    /// when the parameter is not free, the first start's value when it is.
    #[arg(short, long = "param", value_name = "NAME=VALUE")]
    pub params: Vec<String>,
    /// The parameters to fit, comma-separated (an alias such as `alpha`
    /// fits α x = α y as one). Default: every float and colour parameter that
    /// applies under the model's choices. A colour is fitted per channel.
    #[arg(long, value_name = "A,B,…", value_delimiter = ',')]
    pub free: Option<Vec<String>>,
    /// The target: a model id, or a file named by its path (`.binary` MERL,
    /// `.bsdf` RGL, `.brdf` user file).
    #[arg(long, value_name = "TARGET")]
    pub to: String,
    /// A parameter of the target model, repeatable (`--to-param alpha=0.2`).
    #[arg(long = "to-param", value_name = "NAME=VALUE")]
    pub to_params: Vec<String>,
    /// The error minimised: `ngan` (Ngan et al. 2005: cube root of f cos θi)
    /// or `e2` (Löw et al. 2012: ln(1 + f cos θi)).
    #[arg(long, value_enum, default_value_t = MetricChoice::Ngan)]
    pub metric: MetricChoice,
    /// Starting points: the given values, then points spread over the
    /// parameters' ranges (deterministic).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u16).range(1..=64))]
    pub starts: u16,
    /// Print the result as JSON: `{"model", "params", "metric", "error",
    /// "residuals", …}`.
    #[arg(long)]
    pub json: bool,
    /// Also write a scene file with the target and the fit overlaid (see
    /// --help for what happens to an existing file).
    #[arg(long, value_name = "FILE.toml", long_help = super::output::OUT_HELP)]
    pub out: Option<PathBuf>,
}

/// The metrics as the command line names them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MetricChoice {
    /// Ngan et al. 2005: cube root of the cosine-weighted BRDF.
    Ngan,
    /// Löw et al. 2012's E2: ln(1 + f cos θi).
    E2,
}

impl From<MetricChoice> for Metric {
    fn from(m: MetricChoice) -> Self {
        match m {
            MetricChoice::Ngan => Metric::Ngan,
            MetricChoice::E2 => Metric::E2,
        }
    }
}

/// The target's spec, with messages that name `--to` and `--to-param`
/// (the parsing and range checks are the core's, as for `--param`).
fn target_spec(to: &str, params: &[String]) -> Result<bv_core::ModelSpec> {
    let mut spec =
        bv_core::ModelSpec::new(to.trim()).with_context(|| format!("--to {}", quote(to)))?;
    for p in params {
        let shown = quote(p);
        let Some((name, value)) = p.split_once('=') else {
            bail!("--to-param {shown}: expected NAME=VALUE (e.g. --to-param alpha=0.3)");
        };
        spec.set_str(name.trim(), value.trim())
            .with_context(|| format!("--to-param {shown}"))?;
    }
    Ok(spec)
}

/// The result as `bv fit --json` prints it (less the time taken): the
/// fitted model and every parameter, the metric and its error (and at the
/// given values), the residuals per θi band, the unknowns, the target and
/// the effort. The Python module returns the same.
pub fn report_json(result: &fit::FitResult, target: &bv_core::ModelSpec) -> serde_json::Value {
    json!({
        "model": result.spec.id(),
        "params": result.spec.params().to_json(),
        "metric": result.metric.name(),
        "error": result.error,
        "initial_error": result.initial_error,
        "residuals": result.residuals,
        "free": result.unknowns,
        "target": target.to_json(),
        "pairs": result.pairs,
        "iterations": result.iterations,
        "evaluations": result.evaluations,
    })
}

/// Runs `bv fit`.
pub fn run(args: &FitArgs) -> Result<()> {
    let model = spec_from_cli(&args.model, &args.params)?;
    let target = target_spec(&args.to, &args.to_params)?;
    let free: Vec<String> = match &args.free {
        Some(list) => {
            let list: Vec<String> = list
                .iter()
                .map(|s| s.trim().to_string())
                .filter(|s| !s.is_empty())
                .collect();
            if list.is_empty() {
                bail!("--free: no parameter named (give e.g. --free kd,ks,alpha)");
            }
            list
        }
        None => fit::default_free(&model)
            .into_iter()
            .map(str::to_string)
            .collect(),
    };
    if free.is_empty() {
        bail!(
            "model `{}` has no float or colour parameter to fit",
            model.id()
        );
    }
    // A file target is shown by its file name, a model by its id.
    let target_name = match target.model().file_param() {
        Some(_) => std::path::Path::new(args.to.trim())
            .file_name()
            .map_or_else(
                || target.id().to_string(),
                |n| n.to_string_lossy().into_owned(),
            ),
        None => target.id().to_string(),
    };
    let free_refs: Vec<&str> = free.iter().map(String::as_str).collect();
    let target_brdf = target
        .build()
        .with_context(|| format!("building the target `{}`", target.id()))?;
    let opts = FitOptions {
        metric: args.metric.into(),
        starts: usize::from(args.starts),
        ..FitOptions::default()
    };
    // The target is evaluated once per pair; the model about
    // starts × iterations × (2 × unknowns + 2) times per pair.
    let pairs = fit::SampleSet::new(&opts.samples).len() as u64;
    let threads = rayon::current_num_threads();
    let work = |evals: u64| super::budget::Work {
        serial: 0,
        parallel: pairs * evals,
        threads,
    };
    super::budget::start(target_brdf.as_ref(), "bv fit", work(1), super::budget::LONG)?;
    let first = model
        .build()
        .with_context(|| format!("building model `{}`", model.id()))?;
    let evals = (opts.starts * opts.max_iterations * (2 * 3 * free.len() + 2)) as u64;
    super::budget::start(first.as_ref(), "bv fit", work(evals), super::budget::LONG)?;

    let started = Instant::now();
    let mut last_start = usize::MAX;
    let mut progress = |p: &FitProgress| {
        if p.start != last_start || p.iteration.is_multiple_of(10) {
            last_start = p.start;
            eprint(&format!(
                "bv fit: start {}/{}, iteration {}: error {:.6}\n",
                p.start + 1,
                p.starts,
                p.iteration,
                p.error
            ));
        }
    };
    let result = fit::fit(
        &model,
        &free_refs,
        target_brdf.as_ref(),
        &opts,
        &AtomicBool::new(false),
        &mut progress,
    )
    .with_context(|| format!("fitting `{}` to `{}`", model.id(), target.id()))?;
    super::budget::finish(target_brdf.as_ref(), "fit")?;
    let seconds = started.elapsed().as_secs_f64();

    if let Some(out) = &args.out {
        let mut state = AppState::default();
        state.add_named(target.clone(), Some(format!("target: {target_name}")));
        let fitted = state.add_named(
            result.spec.clone(),
            Some(format!(
                "fit: {} ({} {:.4})",
                model.id(),
                result.metric.name(),
                result.error
            )),
        );
        state.selected = Some(fitted);
        // The error names the file (as `bv scene new`'s does).
        scene::save(out, &state)?;
        eprint(&format!("bv fit: wrote {}\n", out.display()));
    }

    if args.json {
        let mut v = report_json(&result, &target);
        v["seconds"] = json!(seconds);
        return print(&format!("{}\n", serde_json::to_string_pretty(&v)?));
    }
    let mut text = format!(
        "fit of {} to {} ({} metric, {} pairs, {} starts, {} iterations, {:.2} s)\n\
         error {:.6} (from {:.6} at the given values)\nparams {}\n\nθi band      error     pairs\n",
        model.id(),
        target_name,
        result.metric.name(),
        result.pairs,
        opts.starts,
        result.iterations,
        seconds,
        result.error,
        result.initial_error,
        result.spec.params().to_json()
    );
    for b in &result.residuals {
        text.push_str(&format!(
            "{:>2}–{:>2}°     {:>9.6}  {:>6}\n",
            b.theta_i_min, b.theta_i_max, b.error, b.samples
        ));
    }
    print(&text)
}
