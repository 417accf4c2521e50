//! `bv slice`: the curves the 2D plots draw, as numbers. One row
//! per sample; `--csv` writes comma-separated values with a header row,
//! `--json` an object with the columns and rows.
//!
//! Columns (stated in `--help` and the README):
//! - `--curve theta-o` (default; the polar and Cartesian plots):
//!   `theta_o_deg,f_r,f_g,f_b,f_mean,f_cos_mean`: θo signed in the plane of
//!   incidence (negative on the light's side), f per linear-RGB channel
//!   (1/sr, no cosine), its channel mean, and the mean times |cos θo|.
//! - `--curve theta-h` / `theta-d`: the same columns with `theta_h_deg` or
//!   `theta_d_deg` first (φh = 0, φd = 90°, the other angle fixed by `--fixed`).
//! - `--curve albedo`: `theta_i_deg,rho_r,rho_g,rho_b,rho_mean,std_error_mean`
//!   (the albedo plot's ρhd and the standard error of its mean).
//!
//! The abscissae are whole multiples of `--step` degrees (1 by default)
//! within the curve's span, computed in degrees so that they print as
//! typed (`30`, not `29.999999999999996`); `--samples N` spaces N intervals
//! over the span instead. Numbers print in the shortest form that reads
//! back to the same f64 (`0.25`, `1e-50`).

use super::params::ModelArgs;
use crate::derive::{albedo, slices};
use anyhow::{Context as _, Result, bail};
use bv_core::error::fmt_num;
use bv_core::mean_rgb;
use rayon::prelude::*;
use serde_json::{Value, json};
use std::fmt::Write as _;

/// Which curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Curve {
    /// f along θo in the plane of incidence.
    ThetaO,
    /// f along θh at fixed θd.
    ThetaH,
    /// f along θd at fixed θh.
    ThetaD,
    /// ρhd along θi.
    Albedo,
}

/// Options of `bv slice`.
#[derive(Debug, Clone, clap::Args)]
#[command(
    long_about = "Print a BRDF slice, the numbers behind the 2D plots.\n\n\
    Columns (--csv adds a header row with these names):\n  \
    theta-o (default): theta_o_deg,f_r,f_g,f_b,f_mean,f_cos_mean\n    \
    theta_o_deg is signed in the plane of incidence, negative on the light's side;\n    \
    f_* are f(wi, wo) per linear-RGB channel in 1/sr (no cosine), f_mean their mean,\n    \
    f_cos_mean = f_mean * |cos theta_o|.\n  \
    theta-h, theta-d: the same with theta_h_deg / theta_d_deg first (phi_h = 0,\n    \
    phi_d = 90 deg; the other angle is --fixed).\n  \
    albedo: theta_i_deg,rho_r,rho_g,rho_b,rho_mean,std_error_mean (the albedo view's\n    \
    estimators: Gauss-Kronrod quadrature for analytic models, std_error_mean then\n    \
    being its error estimate; Monte Carlo for measured ones, one standard error).\n\n\
    Abscissae: whole multiples of --step degrees (default 1) within the curve's span, or\n\
    --samples N intervals spanning it. Numbers print in the shortest form that reads back\n\
    to the same double (30, 0.25, 1e-50). --json prints one object with model, params,\n\
    curve, columns and rows (arrays in the column order; null for a non-finite value)."
)]
pub struct SliceArgs {
    /// The model and its parameters.
    #[command(flatten)]
    pub model: ModelArgs,

    /// Which curve.
    #[arg(long, value_enum, default_value = "theta-o")]
    pub curve: Curve,

    /// Polar angle of the light, degrees (theta-o; albedo ignores it): 0..90,
    /// up to 180 (light below the surface) for a model that transmits.
    #[arg(
        long = "theta-i",
        value_name = "DEG",
        default_value_t = 45.0,
        allow_negative_numbers = true
    )]
    pub theta_i: f64,

    /// Azimuth of the light, degrees.
    #[arg(
        long = "phi-i",
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub phi_i: f64,

    /// The fixed angle of theta-h (θd) or theta-d (θh) curves, degrees.
    #[arg(long, value_name = "DEG", default_value_t = 30.0)]
    pub fixed: f64,

    /// Spacing of the abscissae in degrees (default 1): whole multiples of
    /// it within the curve's span (θo −89..89, or −180..180 for a model that
    /// transmits; θh, θd 0..89; θi 0..89, or 0..180 less the band 89..91
    /// for a model that transmits).
    #[arg(long, value_name = "DEG", conflicts_with = "samples")]
    pub step: Option<f64>,

    /// Instead of --step: N intervals spanning the curve's span evenly (see
    /// --step), 2 to 1000000 (rows = N + 1), for every curve.
    #[arg(long, value_name = "N")]
    pub samples: Option<usize>,

    /// Comma-separated values with a header row (default: aligned columns).
    #[arg(long, conflicts_with = "json")]
    pub csv: bool,

    /// One JSON object: `model`, `params`, `curve`, `columns` and `rows`
    /// (arrays of numbers in the column order; null for a non-finite value).
    #[arg(long)]
    pub json: bool,
}

/// The most rows a slice may have (`--samples 1000000`).
const MAX_ROWS: usize = 1_000_001;

/// The abscissae in degrees over `[lo, hi]`: whole multiples of `step`, or
/// `samples` intervals from `lo` to `hi`.
fn grid(lo: f64, hi: f64, step: Option<f64>, samples: Option<usize>) -> Result<Vec<f64>> {
    if let Some(n) = samples {
        if !(2..=1_000_000).contains(&n) {
            bail!("--samples {n}: expected 2..=1000000");
        }
        return Ok((0..=n)
            .map(|k| snap(lo + (hi - lo) * k as f64 / n as f64))
            .collect());
    }
    let step = step.unwrap_or(1.0);
    if !(step.is_finite() && step > 0.0 && step <= 360.0) {
        bail!(
            "--step {}: expected a spacing in degrees, 0 < DEG <= 360",
            fmt_num(step)
        );
    }
    // Integers k with lo <= k·step <= hi (a rounding hair tolerated: a
    // span end that is a multiple of the step is kept).
    let first = (lo / step - 1e-9).ceil();
    let last = (hi / step + 1e-9).floor();
    let rows = last - first + 1.0;
    if !(rows >= 1.0 && rows <= MAX_ROWS as f64) {
        bail!(
            "--step {}: {} rows (at most {MAX_ROWS})",
            fmt_num(step),
            fmt_num(rows.max(0.0))
        );
    }
    Ok((first as i64..=last as i64)
        .map(|k| snap(k as f64 * step))
        .collect())
}

/// `x` rounded to 12 significant digits: the grid is meant in decimal
/// degrees, and `3 × 0.1` is `0.30000000000000004` in binary; the nearest
/// 12-digit decimal is the angle the user meant (and what is evaluated).
fn snap(x: f64) -> f64 {
    format!("{x:.11e}").parse().unwrap_or(x)
}

/// The header and rows of a slice.
pub fn table(a: &SliceArgs) -> Result<(Vec<&'static str>, Vec<Vec<f64>>)> {
    let spec = a.model.spec()?;
    let brdf = spec.build()?;
    // A transmitting model may be lit from below (issue 33): θi up to 180°.
    let max_theta = if brdf.transmits() { 180.0 } else { 90.0 };
    if !(a.theta_i.is_finite() && (0.0..=max_theta).contains(&a.theta_i)) {
        bail!(
            "--theta-i {}: out of range 0..={max_theta}°{}",
            fmt_num(a.theta_i),
            if brdf.transmits() {
                ""
            } else {
                " (a light below the surface needs a model that transmits)"
            }
        );
    }
    if !a.phi_i.is_finite() {
        bail!("--phi-i {}: not a finite angle", fmt_num(a.phi_i));
    }
    if !(a.fixed.is_finite() && (0.0..=90.0).contains(&a.fixed)) {
        bail!("--fixed {}: out of range 0..=90°", fmt_num(a.fixed));
    }
    // The spans in degrees: a reflection curve stops at 89° (at the horizon
    // f is 0 by convention and θi = 90° lights nothing); a transmitting
    // model's θo covers the circle, its θi both sides but the horizon.
    const LAST: f64 = 89.0;
    let transmits = brdf.transmits();
    let xs = match a.curve {
        Curve::ThetaO if transmits => grid(-180.0, 180.0, a.step, a.samples)?,
        Curve::ThetaO => grid(-LAST, LAST, a.step, a.samples)?,
        Curve::ThetaH | Curve::ThetaD => grid(0.0, LAST, a.step, a.samples)?,
        Curve::Albedo if transmits => grid(0.0, 180.0, a.step, a.samples)?
            .into_iter()
            .filter(|t| (t - 90.0).abs() >= 90.0 - LAST)
            .collect(),
        Curve::Albedo => grid(0.0, LAST, a.step, a.samples)?,
    };
    let f_cols = |first| vec![first, "f_r", "f_g", "f_b", "f_mean", "f_cos_mean"];
    let work = match a.curve {
        Curve::Albedo => super::budget::Work {
            serial: 0,
            parallel: (xs.len() * albedo::SAMPLES) as u64,
            threads: rayon::current_num_threads(),
        },
        _ => super::budget::Work {
            serial: xs.len() as u64,
            parallel: 0,
            threads: 1,
        },
    };
    super::budget::start(brdf.as_ref(), "bv slice", work, super::budget::LONG)?;
    // One row: the abscissa as the grid has it (degrees, not a round trip
    // through radians), f per channel, its mean, and the shown value.
    let row = |deg: f64, s: slices::Sample, wo: glam::DVec3| {
        vec![
            deg,
            s.rgb.x,
            s.rgb.y,
            s.rgb.z,
            mean_rgb(s.rgb),
            slices::shown_value(s.rgb, wo, true),
        ]
    };
    let table = match a.curve {
        Curve::ThetaO => {
            let (ti, pi) = (a.theta_i.to_radians(), a.phi_i.to_radians());
            let rows = xs
                .iter()
                .map(|&d| {
                    let x = d.to_radians();
                    row(
                        d,
                        slices::plane_value(brdf.as_ref(), ti, pi, x, false),
                        wo_z(x),
                    )
                })
                .collect();
            (f_cols("theta_o_deg"), rows)
        }
        Curve::ThetaH | Curve::ThetaD => {
            let axis = if a.curve == Curve::ThetaH {
                slices::HalfDiffAxis::ThetaH
            } else {
                slices::HalfDiffAxis::ThetaD
            };
            let fixed = a.fixed.to_radians();
            let rows = xs
                .iter()
                .map(|&d| {
                    let x = d.to_radians();
                    let (th, td) = match axis {
                        slices::HalfDiffAxis::ThetaH => (x, fixed),
                        slices::HalfDiffAxis::ThetaD => (fixed, x),
                    };
                    let (_, wo) = slices::half_diff_pair(th, td);
                    let s = slices::half_diff_value(brdf.as_ref(), axis, fixed, x, false);
                    row(d, s, wo)
                })
                .collect();
            let first = if a.curve == Curve::ThetaH {
                "theta_h_deg"
            } else {
                "theta_d_deg"
            };
            (f_cols(first), rows)
        }
        Curve::Albedo => {
            let phi = a.phi_i.to_radians();
            let rows = xs
                .par_iter()
                .enumerate()
                .map(|(k, &t)| {
                    let e = albedo::rho_hd_at(brdf.as_ref(), t.to_radians(), phi, k as u64);
                    vec![
                        t,
                        e.value.x,
                        e.value.y,
                        e.value.z,
                        mean_rgb(e.value),
                        mean_rgb(e.std_error),
                    ]
                })
                .collect();
            (
                vec![
                    "theta_i_deg",
                    "rho_r",
                    "rho_g",
                    "rho_b",
                    "rho_mean",
                    "std_error_mean",
                ],
                rows,
            )
        }
    };
    super::budget::finish(brdf.as_ref(), "slice")?;
    Ok(table)
}

/// A unit direction with the `z` of signed in-plane angle `x` (for the cosine
/// column; only |z| matters).
fn wo_z(x: f64) -> glam::DVec3 {
    glam::DVec3::new(x.sin(), 0.0, x.cos())
}

/// A number in the shortest form that reads back to the same f64: plain
/// (`30`, `0.25`) for moderate magnitudes, scientific (`1e-50`,
/// `7.63e-17`) for tiny or huge ones (Rust's shortest round-trip digits
/// either way).
pub fn fmt_short(x: f64) -> String {
    fmt_num(x)
}

/// The table as text: aligned columns, or CSV with a header row.
pub fn format(header: &[&str], rows: &[Vec<f64>], csv: bool) -> String {
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|r| r.iter().map(|&v| fmt_short(v)).collect())
        .collect();
    let mut out = String::new();
    if csv {
        out.push_str(&header.join(","));
        out.push('\n');
        for r in &cells {
            out.push_str(&r.join(","));
            out.push('\n');
        }
    } else {
        let widths: Vec<usize> = (0..header.len())
            .map(|c| {
                cells
                    .iter()
                    .filter_map(|r| r.get(c).map(String::len))
                    .chain([header[c].len()])
                    .max()
                    .unwrap_or(0)
                    + 2
            })
            .collect();
        for (h, w) in header.iter().zip(&widths) {
            let _ = write!(out, "{h:>w$}");
        }
        out.push('\n');
        for r in &cells {
            for (v, w) in r.iter().zip(&widths) {
                let _ = write!(out, "{v:>w$}");
            }
            out.push('\n');
        }
    }
    out
}

/// The table as `--json` prints it.
pub fn to_json(a: &SliceArgs, header: &[&str], rows: &[Vec<f64>]) -> Result<Value> {
    let spec = a.model.spec()?;
    let curve = clap::ValueEnum::to_possible_value(&a.curve)
        .map(|v| v.get_name().to_string())
        .context("naming the curve")?;
    let rows: Vec<Value> = rows
        .iter()
        .map(|r| Value::Array(r.iter().map(|&v| super::output::json_f64(v)).collect()))
        .collect();
    Ok(json!({
        "model": spec.id(),
        "params": spec.params().to_json(),
        "curve": curve,
        "columns": header,
        "rows": rows,
    }))
}

/// Runs `bv slice`.
pub fn run(a: &SliceArgs) -> Result<()> {
    let (header, rows) = table(a)?;
    if a.json {
        let v = to_json(a, &header, &rows)?;
        super::output::print(&format!("{}\n", serde_json::to_string(&v)?))
    } else {
        super::output::print(&format(&header, &rows, a.csv))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(curve: Curve) -> SliceArgs {
        SliceArgs {
            model: ModelArgs {
                model: Some("lambert".into()),
                preset: None,
                params: vec!["albedo=0.5".into()],
            },
            curve,
            theta_i: 30.0,
            phi_i: 0.0,
            fixed: 20.0,
            step: None,
            samples: Some(10),
            csv: true,
            json: false,
        }
    }

    #[test]
    fn lambert_slice_is_albedo_over_pi() {
        let (h, rows) = table(&args(Curve::ThetaO)).unwrap();
        assert_eq!(h[0], "theta_o_deg");
        assert_eq!(rows.len(), 11);
        for r in &rows {
            assert!((r[4] - 0.5 / std::f64::consts::PI).abs() < 1e-12);
            assert!((r[5] - r[4] * r[0].to_radians().cos()).abs() < 1e-12);
        }
        let text = format(&h, &rows, true);
        assert!(text.starts_with("theta_o_deg,f_r,f_g,f_b,f_mean,f_cos_mean\n"));
        assert_eq!(text.lines().count(), 12);
    }

    #[test]
    fn grids_are_whole_multiples_of_the_step() {
        let g = grid(-89.94, 89.94, None, None).unwrap();
        assert_eq!(g.len(), 179);
        assert_eq!((g[0], g[89], g[178]), (-89.0, 0.0, 89.0));
        assert!(g.iter().all(|x| x.fract() == 0.0));
        let g = grid(0.0, 1.0, Some(0.1), None).unwrap();
        assert_eq!(g.len(), 11);
        assert_eq!(g[3], 0.3);
        assert_eq!(g[7], 0.7);
        assert_eq!(
            grid(0.0, 90.0, Some(30.0), None).unwrap(),
            [0.0, 30.0, 60.0, 90.0]
        );
        assert_eq!(
            grid(0.0, 90.0, None, Some(3)).unwrap(),
            [0.0, 30.0, 60.0, 90.0]
        );
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e-9] {
            assert!(grid(0.0, 90.0, Some(bad), None).is_err(), "{bad}");
        }
        assert!(grid(0.0, 90.0, None, Some(1)).is_err());
    }

    #[test]
    fn numbers_read_back() {
        for x in [30.0, 0.25, 1e-50, 7.63e-17, -1.5e300, 0.1 + 0.2, 1.0 / 3.0] {
            let s = fmt_short(x);
            assert_eq!(s.parse::<f64>().unwrap(), x, "{s}");
            assert!(s.len() <= 24, "{s}");
        }
        assert_eq!(fmt_short(30.0), "30");
        assert_eq!(fmt_short(1e-50), "1e-50");
    }
}
