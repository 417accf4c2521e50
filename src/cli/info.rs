//! `bv info FILE`: what is in a MERL `.binary` table, or in any other
//! measured file a model of the catalogue reads (an RGL `.bsdf`): its
//! reader's summary, ρhd and reciprocity.

use anyhow::Result;
use bv_core::analysis::{albedo, directions, reciprocity};
use bv_core::measured::merl::{self, Interpolation, MerlTable};
use bv_core::model::FileFormat;
use bv_core::models::merl::Merl;
use serde_json::{Value, json};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

/// Incident angles (degrees) at which `bv info` estimates ρhd.
pub const THETA_I_DEG: [f64; 5] = [0.0, 30.0, 60.0, 75.0, 85.0];

/// Most Monte Carlo samples per ρhd estimate (`--samples`): the estimates
/// stream, so this bounds time (about a second per million), not memory.
pub const MAX_SAMPLES: usize = 10_000_000;

/// Most reciprocity pairs (`--pairs`): the pairs are held in memory, 48
/// bytes each (96 MB at the cap).
pub const MAX_PAIRS: usize = 2_000_000;

/// Arguments of `bv info`.
#[derive(Debug, Clone, clap::Args)]
pub struct InfoArgs {
    /// A measured file: a MERL .binary table, an RGL .bsdf material.
    pub file: PathBuf,
    /// Print one JSON object instead of the report.
    #[arg(long)]
    pub json: bool,
    /// Monte Carlo samples per ρhd estimate (bv_core::analysis, fixed seed),
    /// 1 to 10000000.
    #[arg(long, default_value_t = 65536, value_parser = samples_count)]
    pub samples: usize,
    /// Direction pairs for the reciprocity check, 1 to 2000000.
    #[arg(long, default_value_t = 100_000, value_parser = pairs_count)]
    pub pairs: usize,
    /// Lookup used for ρhd and reciprocity: trilinear or nearest.
    #[arg(long, default_value = "trilinear")]
    pub interpolation: String,
}

fn count_in(s: &str, max: usize) -> Result<usize, String> {
    let n = super::bench::parse_whole(s)?;
    if n < 1.0 || n > max as f64 {
        return Err(format!("{s} is outside 1..={max}"));
    }
    Ok(n as usize)
}

fn samples_count(s: &str) -> Result<usize, String> {
    count_in(s, MAX_SAMPLES)
}

fn pairs_count(s: &str) -> Result<usize, String> {
    count_in(s, MAX_PAIRS)
}

/// Runs `bv info`.
pub fn run(args: &InfoArgs) -> Result<()> {
    let name = args.file.to_string_lossy();
    // Formats compare by tag, not by address: the formats are zero-sized
    // statics, and zero-sized statics may share one address (they did once
    // the core's codegen units changed: an RGL file went to the MERL reader).
    let merl = bv_core::models::merl::MERL_FILES.tag();
    if let Some((info, _)) = bv_core::registry::file_model(&name)
        && info.file_param().is_some_and(|(_, f)| f.tag() != merl)
    {
        return run_other(args);
    }
    let mode = Interpolation::from_name(&args.interpolation)?;
    let start = Instant::now();
    let table = Arc::new(MerlTable::read(&args.file)?);
    let load_ms = start.elapsed().as_secs_f64() * 1e3;
    let report = report(&table, args, mode, load_ms);
    if args.json {
        super::output::print(&format!("{report}\n"))
    } else {
        super::output::print(&text(&report))
    }
}

fn report(table: &Arc<MerlTable>, args: &InfoArgs, mode: Interpolation, load_ms: f64) -> Value {
    let dims = table.dims();
    let brdf = Merl::from_table(table.clone(), mode);
    let names = merl::channel_names();
    let channels: Vec<Value> = (0..3)
        .map(|c| {
            let r = table.ranges()[c];
            // No valid sample: no statistics (null), and a warning says why.
            let stat = |x: f64| if r.valid == 0 { Value::Null } else { json!(x) };
            json!({
                "name": names[c],
                "min": stat(r.min),
                "max": stat(r.max),
                "mean": stat(r.mean),
                "valid": r.valid,
                "unmeasured": table.warnings().unmeasured[c],
                "non_finite": table.warnings().non_finite[c],
            })
        })
        .collect();
    let rho: Vec<Value> = THETA_I_DEG
        .iter()
        .map(|&deg| {
            let e = albedo::rho_hd(&brdf, deg.to_radians(), 0.0, args.samples, 1000);
            json!({
                "theta_i_deg": deg,
                "value": e.value.to_array(),
                "stderr": e.std_error.to_array(),
                "samples": e.samples,
            })
        })
        .collect();
    // The same pair set as `bv check`: uniform, near-mirror, near-retro,
    // grazing and on-the-normal pairs.
    let recip = reciprocity::check(&brdf, &directions::upper_pairs(args.pairs, 7), 1e-6);
    json!({
        "file": args.file.display().to_string(),
        "bytes": dims.file_len(),
        "dims": [dims.theta_h, dims.theta_d, dims.phi_d],
        "cells_per_channel": dims.cells(),
        "load_ms": load_ms,
        "channels": channels,
        "rho_hd": rho,
        "reciprocity": {
            "max_rel_error": recip.max_rel_err,
            "pairs": recip.pairs,
            "interpolation": mode.name(),
        },
        "warnings": table.warnings().messages(),
    })
}

/// `bv info` of a file another model of the catalogue reads (chosen by the
/// extension its format declares): the reader's own summary, ρhd by Monte
/// Carlo through the model's sampler and the reciprocity check.
fn run_other(args: &InfoArgs) -> Result<()> {
    use anyhow::Context as _;
    let name = args.file.to_string_lossy().into_owned();
    let start = Instant::now();
    let spec = bv_core::ModelSpec::new(&name)?;
    let brdf = spec
        .build()
        .with_context(|| format!("cannot read `{name}`"))?;
    let load_ms = start.elapsed().as_secs_f64() * 1e3;
    let data = brdf.file_data();
    let summary = data.as_ref().map(|d| d.summary()).unwrap_or_default();
    let warnings = data.as_ref().map(|d| d.warnings()).unwrap_or_default();
    let rho: Vec<Value> = THETA_I_DEG
        .iter()
        .map(|&deg| {
            let e = albedo::rho_hd(brdf.as_ref(), deg.to_radians(), 0.0, args.samples, 1000);
            json!({
                "theta_i_deg": deg,
                "value": e.value.to_array(),
                "stderr": e.std_error.to_array(),
                "samples": e.samples,
            })
        })
        .collect();
    let recip = reciprocity::check(brdf.as_ref(), &directions::upper_pairs(args.pairs, 7), 1e-6);
    let bytes = std::fs::metadata(&args.file).map(|m| m.len()).unwrap_or(0);
    let report = json!({
        "file": name,
        "model": spec.id(),
        "bytes": bytes,
        "load_ms": load_ms,
        "summary": summary,
        "rho_hd": rho,
        "reciprocity": {"max_rel_error": recip.max_rel_err, "pairs": recip.pairs},
        "warnings": warnings,
    });
    if args.json {
        return super::output::print(&format!("{report}\n"));
    }
    use std::fmt::Write as _;
    let mut out = String::new();
    let _ = writeln!(out, "file:        {name} ({} model)", spec.id());
    let _ = writeln!(out, "size:        {bytes} bytes, read in {load_ms:.0} ms");
    for line in &summary {
        let _ = writeln!(out, "  {line}");
    }
    let _ = writeln!(
        out,
        "ρhd(θi) = ∫ f cosθo dωo (Monte Carlo through the model's sampler ± standard error, {} samples each):",
        int(&report["rho_hd"][0]["samples"])
    );
    rho_rows(&mut out, &report["rho_hd"]);
    let _ = writeln!(
        out,
        "reciprocity: max |f(wi,wo) − f(wo,wi)| / max f = {:.3e} over {} pairs",
        recip.max_rel_err, recip.pairs
    );
    for w in &warnings {
        let _ = writeln!(out, "warning:     {w}");
    }
    super::output::print(&out)
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

/// `x` with `prec` decimals, in exponent form when it is large (a table of
/// absurd values must not print 40-digit numbers).
fn fixed(x: f64, prec: usize) -> String {
    if x.abs() < 1e6 || !x.is_finite() {
        format!("{x:.prec$}")
    } else {
        format!("{x:.prec$e}")
    }
}

/// A statistic of the report, `-` where there is none (no valid sample).
fn stat(v: &Value) -> String {
    v.as_f64().map_or_else(|| "-".to_string(), |x| fixed(x, 6))
}

fn int(v: &Value) -> u64 {
    v.as_u64().unwrap_or(0)
}

fn text(r: &Value) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let d = &r["dims"];
    let _ = writeln!(out, "file:        {}", r["file"].as_str().unwrap_or(""));
    let _ = writeln!(
        out,
        "size:        {} bytes, read in {:.0} ms",
        r["bytes"],
        num(&r["load_ms"])
    );
    let _ = writeln!(
        out,
        "dimensions:  θh {} × θd {} × φd {} ({} cells per channel)",
        d[0], d[1], d[2], r["cells_per_channel"]
    );
    let _ = writeln!(
        out,
        "values (f in 1/sr, channel scales applied; over valid samples):"
    );
    let _ = writeln!(
        out,
        "  {:<6} {:>12} {:>12} {:>12} {:>10} {:>11} {:>10}",
        "", "min", "max", "mean", "valid", "unmeasured", "NaN/Inf"
    );
    for c in r["channels"].as_array().into_iter().flatten() {
        let _ = writeln!(
            out,
            "  {:<6} {:>12} {:>12} {:>12} {:>10} {:>11} {:>10}",
            c["name"].as_str().unwrap_or(""),
            stat(&c["min"]),
            stat(&c["max"]),
            stat(&c["mean"]),
            int(&c["valid"]),
            int(&c["unmeasured"]),
            int(&c["non_finite"])
        );
    }
    let _ = writeln!(
        out,
        "ρhd(θi) = ∫ f cosθo dωo ({} lookup, Monte Carlo ± standard error, {} samples each):",
        r["reciprocity"]["interpolation"].as_str().unwrap_or(""),
        int(&r["rho_hd"][0]["samples"])
    );
    rho_rows(&mut out, &r["rho_hd"]);
    let _ = writeln!(
        out,
        "reciprocity: max |f(wi,wo) − f(wo,wi)| / max f = {:.3e} over {} pairs (the table folds φd by reciprocity, so this checks the lookup path)",
        num(&r["reciprocity"]["max_rel_error"]),
        r["reciprocity"]["pairs"]
    );
    for w in r["warnings"].as_array().into_iter().flatten() {
        let _ = writeln!(out, "warning:     {}", w.as_str().unwrap_or(""));
    }
    out
}

/// One line per θi of a report's `rho_hd` rows: r, g, b with their
/// standard errors (the measured-table and RGL summaries alike).
fn rho_rows(out: &mut String, rows: &serde_json::Value) {
    use std::fmt::Write as _;
    for x in rows.as_array().into_iter().flatten() {
        let v: Vec<f64> = x["value"]
            .as_array()
            .into_iter()
            .flatten()
            .map(num)
            .collect();
        let e: Vec<f64> = x["stderr"]
            .as_array()
            .into_iter()
            .flatten()
            .map(num)
            .collect();
        if v.len() == 3 && e.len() == 3 {
            let _ = writeln!(
                out,
                "  θi = {:>4.0}°  r {} ± {}  g {} ± {}  b {} ± {}",
                num(&x["theta_i_deg"]),
                fixed(v[0], 4),
                fixed(e[0], 4),
                fixed(v[1], 4),
                fixed(e[1], 4),
                fixed(v[2], 4),
                fixed(e[2], 4)
            );
        }
    }
}
