//! `bv slice`: the curves the 2D plots draw, as numbers. One row
//! per sample; `--csv` writes comma-separated values with a header row.
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

use super::params::ModelArgs;
use crate::derive::{albedo, slices};
use anyhow::{Result, bail};
use bv_core::error::fmt_num;
use bv_core::mean_rgb;
use std::fmt::Write as _;
use std::sync::atomic::{AtomicBool, AtomicUsize};

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
    being its error estimate; Monte Carlo for measured ones, one standard error)."
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

    /// Intervals along the curve, 2 to 1000000 (rows = N + 1; albedo uses its own 45 angles).
    #[arg(long, value_name = "N", default_value_t = 180)]
    pub samples: usize,

    /// Comma-separated values with a header row (default: aligned columns).
    #[arg(long)]
    pub csv: bool,
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
    if !(2..=1_000_000).contains(&a.samples) {
        bail!("--samples {}: expected 2..=1000000", a.samples);
    }
    let row = |s: &slices::Sample| {
        vec![
            s.x.to_degrees(),
            s.rgb.x,
            s.rgb.y,
            s.rgb.z,
            mean_rgb(s.rgb),
            slices::shown_value(s.rgb, wo_z(s.x), true),
        ]
    };
    let f_cols = |first| vec![first, "f_r", "f_g", "f_b", "f_mean", "f_cos_mean"];
    let work = match a.curve {
        // The albedo view's Monte Carlo: 90 angles of 4096 samples.
        Curve::Albedo => super::budget::Work {
            serial: 0,
            parallel: 90 * 4096,
            threads: rayon::current_num_threads(),
        },
        _ => super::budget::Work {
            serial: a.samples as u64,
            parallel: 0,
            threads: 1,
        },
    };
    super::budget::start(brdf.as_ref(), "bv slice", work, super::budget::LONG)?;
    let table = match a.curve {
        Curve::ThetaO => {
            let s = slices::plane_of_incidence(
                brdf.as_ref(),
                a.theta_i.to_radians(),
                a.phi_i.to_radians(),
                a.samples,
                false,
            );
            (f_cols("theta_o_deg"), s.iter().map(row).collect())
        }
        Curve::ThetaH | Curve::ThetaD => {
            let axis = if a.curve == Curve::ThetaH {
                slices::HalfDiffAxis::ThetaH
            } else {
                slices::HalfDiffAxis::ThetaD
            };
            let s = slices::half_diff_slice(
                brdf.as_ref(),
                axis,
                a.fixed.to_radians(),
                a.samples,
                false,
            );
            let rows = s
                .iter()
                .map(|p| {
                    let (th, td) = match axis {
                        slices::HalfDiffAxis::ThetaH => (p.x, a.fixed.to_radians()),
                        slices::HalfDiffAxis::ThetaD => (a.fixed.to_radians(), p.x),
                    };
                    let (_, wo) = slices::half_diff_pair(th, td);
                    let mut r = row(p);
                    r[5] = slices::shown_value(p.rgb, wo, true);
                    r
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
            let d = albedo::AlbedoData::compute(
                brdf.as_ref(),
                a.phi_i.to_radians(),
                &AtomicUsize::new(0),
                &AtomicBool::new(false),
            )
            .ok_or_else(|| anyhow::anyhow!("albedo computation was cancelled"))?;
            let rows = d
                .rho
                .iter()
                .zip(&d.theta_deg)
                .map(|(e, t)| {
                    vec![
                        *t,
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

/// The table as text.
pub fn format(header: &[&str], rows: &[Vec<f64>], csv: bool) -> String {
    let mut out = String::new();
    if csv {
        out.push_str(&header.join(","));
        out.push('\n');
        for r in rows {
            let cells: Vec<String> = r.iter().map(|v| format!("{v}")).collect();
            out.push_str(&cells.join(","));
            out.push('\n');
        }
    } else {
        for h in header {
            let _ = write!(out, "{h:>16}");
        }
        out.push('\n');
        for r in rows {
            for v in r {
                let _ = write!(out, "{:>16}", format!("{v:.6e}"));
            }
            out.push('\n');
        }
    }
    out
}

/// Runs `bv slice`.
pub fn run(a: &SliceArgs) -> Result<()> {
    let (header, rows) = table(a)?;
    super::output::print(&format(&header, &rows, a.csv))
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
            samples: 10,
            csv: true,
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
}
