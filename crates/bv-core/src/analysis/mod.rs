//! Property analysis : what `bv check` prints and the
//! GUI shows. Every number comes with the sample or quadrature count it used
//! and an error estimate, and every verdict is printed beside what the model
//! claims about itself ([`Brdf::claims`]).
//!
//! - [`positivity`]: min f over a dense direction set, non-finite values counted.
//! - [`reciprocity`]: Helmholtz reciprocity, max |f(wi,wo) − f(wo,wi)| / max f.
//! - [`isotropy`]: max change of f under a common rotation about the normal.
//! - [`albedo`]: ρhd(θi) curves with errors, their maximum, ρhh, the verdict.
//! - [`ndf`]: `∫ D cos θh dωh` for microfacet models.
//! - [`gonio`]: a virtual gonioreflectometer (photons from the model's sampler, a detector swept through the plane of incidence).

pub mod albedo;
pub mod chi2;
pub mod directions;
pub mod estimate;
pub mod gauss_kronrod;
pub mod gonio;
pub mod hemi_map;
pub mod isotropy;
pub mod ndf;
pub mod positivity;
pub mod quadrature;
pub mod reciprocity;
pub mod reciprocity_map;
pub mod sample_histogram;

use crate::{Brdf, Rgb};
use albedo::{AlbedoCurve, Estimate};
use glam::DVec3;
use serde::Serialize;
use std::fmt;
use std::time::Duration;

/// How long `bv check` may spend evaluating a model whose evaluations are
/// timed ([`Brdf::eval_cost`]: user files): with the compile and the probe,
/// the check of any file of up to 1 MB ends within 10 s. A model that
/// [`CheckOptions::estimated_time`] puts beyond it is refused by `bv check`,
/// and the panel's badges keep their preview for it.
pub const CHECK_BUDGET: Duration = Duration::from_secs(7);

/// What [`check`] measures and how hard it tries. The defaults run in well
/// under 2 s in a release build for every model of the catalogue on one core
/// (about 0.4 M evaluations for an isotropic model, 1.5 M for an anisotropic
/// one, plus ≤ 1 M NDF evaluations).
#[derive(Debug, Clone, PartialEq)]
pub struct CheckOptions {
    /// Direction pairs for positivity, reciprocity and isotropy (default
    /// 20 000; see [`directions::upper_pairs`] for how they are spread).
    pub pairs: usize,
    /// θi angles of each ρhd curve: 0°, 90°/n, …, 90° − 90°/n (default 90, so
    /// 0°, 1°, …, 89°).
    pub theta_count: usize,
    /// Extra θi (degrees) examined for the energy verdict, beyond the curve's
    /// grid: near grazing, where `1/cos θi` factors make ρhd grow without bound
    /// (seed Phong exceeds 1 only above ~88°). Default 89.5°, 89.9°, 89.99°,
    /// 89.999°.
    pub grazing_deg: Vec<f64>,
    /// Samples per ρhd value (default 4096, in 16 replicas for the error).
    pub samples_per_angle: usize,
    /// Incident azimuths for the ρhd curves of an anisotropic model:
    /// φi = k · 180°/n, `k = 0..n` (default 4: 0°, 45°, 90°, 135°). An isotropic
    /// model (measured and claimed) gets φi = 0° only.
    pub anisotropic_azimuths: usize,
    /// Samples for ρhh (default 65 536).
    pub hh_samples: usize,
    /// Which estimator the albedo uses (default: quadrature for analytic
    /// models, Monte Carlo for measured and user-defined ones).
    pub albedo_method: albedo::AlbedoMethod,
    /// Tolerance and budgets of the albedo quadrature.
    pub quadrature: quadrature::QuadratureOptions,
    /// Threshold of the reciprocity and isotropy verdicts, relative to max f
    /// (default 1e-6).
    pub tolerance: f64,
    /// Energy verdict: the model conserves energy when every ρhd value is
    /// at most `1 + energy_sigmas · std_error` (+1e-9 for rounding). Default 5:
    /// the verdict tests some 100–400 values at once, and a model whose ρhd
    /// is 1 to within its noise (a smooth microfacet mirror without Fresnel)
    /// would exceed 3 σ somewhere a third of the time; with a Student t of 15
    /// degrees of freedom, P(t > 5) ≈ 8e-5, so a false alarm stays near 1 %.
    pub energy_sigmas: f64,
    /// Target relative error of the D normalisation quadrature (default 1e-8).
    pub ndf_rel_tol: f64,
    /// Budget of D evaluations, about (default 2 000 000).
    pub ndf_max_evals: usize,
    /// Verdict tolerance for `∫ D cos θh dωh = 1` (default 1e-4).
    pub ndf_tolerance: f64,
    /// Seed of every random choice (default 1): reports are repeatable.
    pub seed: u64,
}

impl Default for CheckOptions {
    fn default() -> Self {
        Self {
            pairs: 20_000,
            theta_count: 90,
            grazing_deg: vec![89.5, 89.9, 89.99, 89.999],
            samples_per_angle: 4096,
            anisotropic_azimuths: 4,
            hh_samples: 65_536,
            albedo_method: albedo::AlbedoMethod::Auto,
            quadrature: quadrature::QuadratureOptions::default(),
            tolerance: 1e-6,
            energy_sigmas: 5.0,
            ndf_rel_tol: 1e-8,
            ndf_max_evals: 2_000_000,
            ndf_tolerance: 1e-4,
            seed: 1,
        }
    }
}

/// A direction pair and the values found there (for "where is the worst case").
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PairSample {
    /// `wi`.
    pub wi: DVec3,
    /// `wo`.
    pub wo: DVec3,
    /// `[θ, φ]` of `wi` in degrees.
    pub wi_deg: [f64; 2],
    /// `[θ, φ]` of `wo` in degrees.
    pub wo_deg: [f64; 2],
    /// `f(wi, wo)` (for reciprocity across an interface, divided by ηo²).
    pub f: Rgb,
    /// The value it was compared with: `f(wo, wi)` for reciprocity (across an
    /// interface, divided by ηi²), the rotated pair's value for isotropy, `f`
    /// itself for positivity.
    pub f_swapped: Rgb,
}

impl PairSample {
    /// A pair with its two values.
    pub fn new(wi: DVec3, wo: DVec3, f: Rgb, f_swapped: Rgb) -> Self {
        Self {
            wi,
            wo,
            wi_deg: directions::angles_deg(wi),
            wo_deg: directions::angles_deg(wo),
            f,
            f_swapped,
        }
    }
}

/// What the model claims (copied from [`crate::Claims`] for the report).
/// `None` (JSON `null`, "—" in the table) where the model claims nothing:
/// a file's data (MERL, user `.brdf`) makes no promises
/// ([`Brdf::claims_declared`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct ClaimsReport {
    /// Claims Helmholtz reciprocity.
    pub reciprocal: Option<bool>,
    /// Claims ρhd ≤ 1 everywhere.
    pub energy_conserving: Option<bool>,
    /// Claims isotropy.
    pub isotropic: Option<bool>,
}

impl ClaimsReport {
    /// The report's copy of `brdf`'s claims: `None` for each when they are
    /// observations rather than promises.
    pub fn of(brdf: &dyn Brdf) -> Self {
        let c = brdf.claims();
        let declared = brdf.claims_declared();
        let claim = |b: bool| declared.then_some(b);
        Self {
            reciprocal: claim(c.reciprocal),
            energy_conserving: claim(c.energy_conserving),
            isotropic: claim(c.isotropic),
        }
    }
}

/// The energy section of a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Energy {
    /// ρhd curves on the uniform θi grid, one per incident azimuth examined.
    pub curves: Vec<AlbedoCurve>,
    /// ρhd at the near-grazing θi of [`CheckOptions::grazing_deg`], one per
    /// azimuth.
    pub grazing: Vec<AlbedoCurve>,
    /// For a transmitting model, ρhd for light from below the surface (θi
    /// from −z, the uniform grid and the grazing angles), one curve per
    /// azimuth; each curve of a transmitting model carries ρR and ρT besides
    /// ρhd = ρR + ρT. Empty for a reflection model.
    pub below: Vec<AlbedoCurve>,
    /// The largest ρhd over the curves (by its largest channel).
    pub max: Estimate,
    /// θi of the maximum (degrees from +z: above 90° for light from below).
    pub argmax_theta_deg: f64,
    /// φi of the maximum (degrees).
    pub argmax_phi_deg: f64,
    /// ρhh with its error.
    pub rho_hh: Estimate,
    /// Whether the model has delta lobes (their weights are included in ρhd).
    pub has_deltas: bool,
    /// Whether the model transmits (ρhd then integrates over the whole sphere).
    pub transmits: bool,
    /// How ρhd and ρhh were computed: `quadrature` or `monte carlo`.
    pub method: &'static str,
    /// Whether every quadrature met its tolerance (always true for Monte
    /// Carlo).
    pub converged: bool,
    /// Largest `(ρhd − 1) / std_error` over the curves (how significant an excess
    /// is; negative when every value is below 1).
    pub max_excess_sigmas: f64,
    /// The multiple of the error allowed by the verdict.
    pub sigmas: f64,
    /// Verdict: every ρhd value ≤ 1 + its allowance (+1e-9): `sigmas`
    /// standard errors for Monte Carlo, the error estimate for quadrature.
    pub conserves: bool,
}

/// The D-normalisation section of a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NdfReport {
    /// `∫ D cos θh dωh` with its quadrature error and evaluation count.
    pub integral: ndf::Quadrature,
    /// Tolerance of the verdict.
    pub tolerance: f64,
    /// Verdict: `|integral − 1| ≤ tolerance + error`.
    pub normalised: bool,
}

/// Everything `bv check` reports for one model .
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PropertyReport {
    /// Model id.
    pub model: String,
    /// What the model claims for its parameters.
    pub claims: ClaimsReport,
    /// Positivity and finiteness.
    pub positivity: positivity::Positivity,
    /// Helmholtz reciprocity.
    pub reciprocity: reciprocity::Reciprocity,
    /// Isotropy.
    pub isotropy: isotropy::Isotropy,
    /// Directional and bihemispherical albedo.
    pub energy: Energy,
    /// D normalisation, for models with a microfacet distribution.
    pub ndf: Option<NdfReport>,
}

impl PropertyReport {
    /// Whether every measured verdict agrees with a "yes" claim (a model may
    /// claim less than it measures, never more), and positivity holds.
    pub fn consistent_with_claims(&self) -> bool {
        let yes = |c: Option<bool>| c == Some(true);
        self.positivity.ok
            && (!yes(self.claims.reciprocal) || self.reciprocity.reciprocal)
            && (!yes(self.claims.energy_conserving) || self.energy.conserves)
            && (!yes(self.claims.isotropic) || self.isotropy.isotropic)
            && self.ndf.as_ref().is_none_or(|n| n.normalised)
    }

    /// Whether a script should treat the report as a failure (`bv check
    /// --strict` exits 3): a verdict contradicts a claim or a property every
    /// BRDF needs (positivity, D normalisation), or energy is violated,
    /// claimed or not.
    pub fn strict_failure(&self) -> bool {
        !self.consistent_with_claims() || !self.energy.conserves
    }
}

impl CheckOptions {
    /// About how many evaluations of `brdf` [`check`] makes: `(serial,
    /// parallel)`, the pair checks run on one thread and the Monte Carlo
    /// albedo on all. The quadrature's count depends on the model (its
    /// panels adapt), so with quadrature only the pair checks are counted:
    /// the command's time limit bounds the rest. For a time estimate before
    /// a slow model is analysed.
    pub fn evaluations(&self, brdf: &dyn Brdf) -> (u64, u64) {
        let pairs = self.pairs as u64;
        // Transmitting models: pairs across the surface (both orders) and
        // below it, for positivity and reciprocity.
        let (cross, below) = if brdf.transmits() {
            (pairs / 2, pairs / 2)
        } else {
            (0, 0)
        };
        // Positivity once (twice for the pairs below), reciprocity and
        // isotropy twice per pair.
        let serial = pairs + 2 * cross + 2 * below + 2 * (pairs + cross + below) + 2 * pairs;
        let aopts = albedo::AlbedoOptions {
            method: self.albedo_method,
            ..albedo::AlbedoOptions::default()
        };
        if aopts.uses_quadrature(brdf) {
            return (serial, 0);
        }
        let azimuths = if brdf.claims().isotropic {
            1
        } else {
            self.anisotropic_azimuths.max(1)
        } as u64;
        let angles = (self.theta_count.max(1) + self.grazing_deg.len()) as u64;
        let parallel = azimuths * angles * self.samples_per_angle as u64 + self.hh_samples as u64;
        (serial, parallel)
    }

    /// About how long [`check`] takes on `threads` threads at `brdf`'s
    /// measured cost per evaluation ([`Brdf::eval_cost`]): the
    /// [`evaluations`](Self::evaluations) times that cost. `None` for a model
    /// whose cost is not measured (the catalogue's, a fraction of a
    /// microsecond each).
    pub fn estimated_time(&self, brdf: &dyn Brdf, threads: usize) -> Option<Duration> {
        let cost = brdf.eval_cost()?.as_secs_f64();
        let (serial, parallel) = self.evaluations(brdf);
        let secs = cost * (serial as f64 + parallel as f64 / threads.max(1) as f64);
        Some(Duration::from_secs_f64(secs.clamp(0.0, 1e9)))
    }
}

/// Runs every property check on `brdf`.
pub fn check(brdf: &dyn Brdf, opts: &CheckOptions) -> PropertyReport {
    let claims = ClaimsReport::of(brdf);
    let pairs = directions::upper_pairs(opts.pairs, opts.seed);
    // A transmitting model is examined on the whole sphere: pairs across the
    // surface in both orders and pairs with both directions below it (light
    // from inside), for positivity and reciprocity (whose check applies the
    // generalised form across an interface).
    let (lower, sphere) = if brdf.transmits() {
        let cross = directions::transmission_pairs(opts.pairs / 2, opts.seed);
        let below = directions::lower_pairs(opts.pairs / 2, opts.seed);
        let mut lower = cross.clone();
        lower.extend(cross.iter().map(|&(a, b)| (b, a)));
        lower.extend(below.iter().flat_map(|&(a, b)| [(a, b), (b, a)]));
        let mut sphere = pairs.clone();
        sphere.extend(cross);
        sphere.extend(below);
        (lower, sphere)
    } else {
        (Vec::new(), pairs.clone())
    };
    let positivity = positivity::check(brdf, &pairs, &lower);
    let reciprocity = reciprocity::check(brdf, &sphere, opts.tolerance);
    let isotropy = isotropy::check(brdf, &pairs, opts.tolerance, opts.seed);
    // The (possibly only observed) claim steers the azimuths: a table with
    // no φh axis is examined at one.
    let isotropic = isotropy.isotropic && brdf.claims().isotropic;
    let energy = energy(brdf, opts, isotropic);
    let ndf = brdf.ndf().map(|d| {
        let integral = ndf::normalisation(d, opts.ndf_rel_tol, opts.ndf_max_evals);
        NdfReport {
            integral,
            tolerance: opts.ndf_tolerance,
            normalised: (integral.value - 1.0).abs() <= opts.ndf_tolerance + integral.error,
        }
    });
    PropertyReport {
        model: brdf.id().to_string(),
        claims,
        positivity,
        reciprocity,
        isotropy,
        energy,
        ndf,
    }
}

fn energy(brdf: &dyn Brdf, opts: &CheckOptions, isotropic: bool) -> Energy {
    let azimuths = if isotropic {
        1
    } else {
        opts.anisotropic_azimuths.max(1)
    };
    let n_theta = opts.theta_count.max(1);
    let phis: Vec<f64> = (0..azimuths)
        .map(|k| std::f64::consts::PI * k as f64 / azimuths as f64)
        .collect();
    let aopts = albedo::AlbedoOptions {
        method: opts.albedo_method,
        samples: opts.samples_per_angle,
        seed: opts.seed,
        quadrature: opts.quadrature,
    };
    let curves: Vec<AlbedoCurve> = phis
        .iter()
        .enumerate()
        .map(|(k, &phi)| {
            albedo::rho_hd_curve(
                brdf,
                phi,
                n_theta,
                &aopts.with_seed(directions::stream_seed(opts.seed, 1000 + k as u64)),
            )
        })
        .collect();
    let grazing_rad: Vec<f64> = opts
        .grazing_deg
        .iter()
        .map(|d| d.clamp(0.0, 90.0).to_radians())
        .collect();
    let grazing: Vec<AlbedoCurve> = phis
        .iter()
        .enumerate()
        .map(|(k, &phi)| {
            albedo::rho_hd_angles(
                brdf,
                phi,
                &grazing_rad,
                &aopts.with_seed(directions::stream_seed(opts.seed, 2000 + k as u64)),
            )
        })
        .collect();
    let below: Vec<AlbedoCurve> = if brdf.transmits() {
        let mut thetas = albedo::theta_grid(n_theta);
        thetas.extend(&grazing_rad);
        phis.iter()
            .enumerate()
            .map(|(k, &phi)| {
                albedo::rho_hd_angles_side(
                    brdf,
                    phi,
                    &thetas,
                    &aopts.with_seed(directions::stream_seed(opts.seed, 3000 + k as u64)),
                    true,
                )
            })
            .collect()
    } else {
        Vec::new()
    };
    let mut max = None::<(Estimate, f64, f64)>;
    let mut max_excess_sigmas = f64::NEG_INFINITY;
    let mut conserves = true;
    for curve in curves.iter().chain(&grazing).chain(&below) {
        for (e, &t) in curve.rho.iter().zip(&curve.theta_deg) {
            // θi of light from below is reported from +z (90°..180°).
            let t = if curve.from_below { 180.0 - t } else { t };
            let allow = e.allowance(opts.energy_sigmas);
            for ch in 0..3 {
                let (v, s) = (e.value[ch], e.std_error[ch]);
                // A NaN estimate cannot vouch for energy conservation.
                if v.is_nan() || v > 1.0 + allow[ch] + 1e-9 {
                    conserves = false;
                }
                let z = if s > 0.0 {
                    (v - 1.0) / s
                } else if v > 1.0 + 1e-9 {
                    f64::INFINITY
                } else if v >= 1.0 - 1e-9 {
                    0.0
                } else {
                    f64::NEG_INFINITY
                };
                max_excess_sigmas = max_excess_sigmas.max(z);
            }
            let better = match &max {
                None => true,
                Some((m, _, _)) => e.max_channel().0 > m.max_channel().0,
            };
            if better {
                max = Some((*e, t, curve.phi_i_deg));
            }
        }
    }
    let (max, argmax_theta_deg, argmax_phi_deg) = max.unwrap_or((
        Estimate {
            value: Rgb::ZERO,
            std_error: Rgb::ZERO,
            samples: 0,
            rejected: 0,
            method: albedo::Method::Quadrature { converged: true },
        },
        0.0,
        0.0,
    ));
    let rho_hh = albedo::rho_hh_auto(
        brdf,
        opts.hh_samples,
        &aopts.with_seed(directions::stream_seed(opts.seed, 77)),
    );
    let quad = aopts.uses_quadrature(brdf);
    let converged = curves
        .iter()
        .chain(&grazing)
        .chain(&below)
        .flat_map(|c| &c.rho)
        .chain(std::iter::once(&rho_hh))
        .all(|e| !matches!(e.method, albedo::Method::Quadrature { converged: false }));
    Energy {
        curves,
        grazing,
        below,
        max,
        argmax_theta_deg,
        argmax_phi_deg,
        rho_hh,
        has_deltas: !brdf.deltas(DVec3::new(0.6, 0.0, 0.8)).is_empty()
            || !brdf.deltas(DVec3::Z).is_empty(),
        transmits: brdf.transmits(),
        method: if quad { "quadrature" } else { "monte carlo" },
        converged,
        max_excess_sigmas,
        sigmas: opts.energy_sigmas,
        conserves,
    }
}

/// A claim as text.
/// The widest line of `bv check`'s table (issue 30: a terminal or a log,
/// not 200 columns).
pub const TABLE_WIDTH: usize = 100;

/// `text` broken at spaces into lines of at most `width` characters (a word
/// longer than that is cut). A count stays with the word after it ("0
/// non-finite", "20000 pairs"), so that a script's `grep` finds the pair.
fn wrap(text: &str, width: usize) -> Vec<String> {
    let width = width.max(1);
    let mut units: Vec<String> = Vec::new();
    let mut count: Option<&str> = None;
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        match count.take() {
            Some(n) => units.push(format!("{n} {word}")),
            None if word.bytes().all(|b| b.is_ascii_digit()) => count = Some(word),
            None => units.push(word.to_string()),
        }
    }
    units.extend(count.map(String::from));
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in &units {
        let mut word: Vec<char> = word.chars().collect();
        while word.len() > width {
            if !line.is_empty() {
                lines.push(std::mem::take(&mut line));
            }
            lines.push(word.drain(..width).collect());
        }
        let word: String = word.into_iter().collect();
        let n = line.chars().count();
        if n > 0 && n + 1 + word.chars().count() > width {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(&word);
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

/// A note under the table, indented and wrapped to [`TABLE_WIDTH`].
fn write_wrapped(f: &mut fmt::Formatter<'_>, text: &str) -> fmt::Result {
    for (k, line) in wrap(text, TABLE_WIDTH - 4).iter().enumerate() {
        let indent = if k == 0 { "  " } else { "    " };
        writeln!(f, "{indent}{line}")?;
    }
    Ok(())
}

/// A claim as the table shows it; "—" where the model claims nothing.
fn yes_no(b: Option<bool>) -> &'static str {
    match b {
        Some(true) => "yes",
        Some(false) => "no",
        None => "—",
    }
}

/// A short number: 4 significant digits, scientific when small or large.
fn num(x: f64) -> String {
    if x == 0.0 {
        "0".to_string()
    } else if !x.is_finite() {
        format!("{x}")
    } else if (1e-3..1e5).contains(&x.abs()) {
        let digits = (3 - x.abs().log10().floor() as i32).max(0) as usize;
        format!("{x:.digits$}")
    } else {
        // 3.100e-17 → 3.1e-17, 1.000e-6 → 1e-6.
        let s = format!("{x:.3e}");
        match s.split_once('e') {
            Some((m, e)) if m.contains('.') => {
                format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
            }
            _ => s,
        }
    }
}

// Angles in reports: up to 3 decimals, trailing zeros dropped.
use crate::text::fmt_deg as deg;

/// An estimate of the largest channel with its error.
/// An estimate as `bv check` prints it: the largest channel's value and
/// its error, "0.4970 ± 0.04100" (the panel's badges print the same).
pub fn fmt_estimate(e: &Estimate) -> String {
    let (v, s, _) = e.max_channel();
    format!("{} ± {}", num(v), num(s))
}

use fmt_estimate as est;

impl fmt::Display for PropertyReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let c = &self.claims;
        let p = &self.positivity;
        let r = &self.reciprocity;
        let i = &self.isotropy;
        let e = &self.energy;
        // (property, measured, verdict, claim, agrees)
        let mut rows: Vec<(String, String, String, String, bool)> = Vec::new();
        rows.push((
            "positivity".into(),
            format!(
                "min f {} over {} evaluations, {} negative, {} non-finite",
                num(p.min_f),
                p.evaluations,
                p.negative,
                p.non_finite
            ),
            if p.ok { "finite, ≥ 0" } else { "VIOLATED" }.into(),
            "".into(),
            p.ok,
        ));
        rows.push((
            "reciprocity".into(),
            format!(
                "max rel err {} over {} pairs (threshold {})",
                num(r.max_rel_err),
                r.pairs,
                num(r.threshold)
            ),
            if r.reciprocal {
                "reciprocal"
            } else {
                "not reciprocal"
            }
            .into(),
            yes_no(c.reciprocal).into(),
            r.reciprocal || c.reciprocal != Some(true),
        ));
        rows.push((
            "isotropy".into(),
            format!(
                "max rel change {} over {} rotated pairs (threshold {})",
                num(i.max_rel_change),
                i.pairs,
                num(i.threshold)
            ),
            if i.isotropic {
                "isotropic"
            } else {
                "anisotropic"
            }
            .into(),
            yes_no(c.isotropic).into(),
            i.isotropic || c.isotropic != Some(true),
        ));
        let per_angle = e.curves.first().and_then(|cv| cv.rho.first());
        let extras = match (e.has_deltas, e.transmits) {
            (true, true) => ", whole sphere, incl. delta lobes",
            (true, false) => ", incl. delta lobes",
            (false, true) => ", whole sphere",
            (false, false) => "",
        };
        rows.push((
            "energy".into(),
            format!(
                "max ρhd {} at θi = {}°, φi = {}° ({} + {} grazing θi × {} azimuth(s), {}{extras})",
                est(&e.max),
                deg(e.argmax_theta_deg),
                deg(e.argmax_phi_deg),
                e.curves.first().map_or(0, |cv| cv.rho.len()),
                e.grazing.first().map_or(0, |cv| cv.rho.len()),
                e.curves.len(),
                match per_angle.map(|x| x.method) {
                    Some(albedo::Method::Quadrature { .. }) => format!(
                        "Gauss–Kronrod quadrature, error estimate{}",
                        if e.converged {
                            ""
                        } else {
                            ", TOLERANCE NOT MET"
                        }
                    ),
                    _ => format!(
                        "Monte Carlo, {} samples each, ± one standard error",
                        per_angle.map_or(0, |x| x.samples)
                    ),
                },
            ),
            if e.conserves {
                "conserves energy"
            } else {
                "violates energy"
            }
            .into(),
            yes_no(c.energy_conserving).into(),
            e.conserves || c.energy_conserving != Some(true),
        ));
        if e.transmits {
            // ρR and ρT where ρhd peaks, and the worst case from inside.
            let at = |c: &AlbedoCurve, t: f64| -> Option<(Estimate, Estimate)> {
                let k = c.theta_deg.iter().position(|&x| {
                    let x = if c.from_below { 180.0 - x } else { x };
                    (x - t).abs() < 1e-9
                })?;
                Some((*c.reflected.get(k)?, *c.transmitted.get(k)?))
            };
            let parts = e
                .curves
                .iter()
                .chain(&e.grazing)
                .chain(&e.below)
                .filter(|c| (c.phi_i_deg - e.argmax_phi_deg).abs() < 1e-9)
                .find_map(|c| at(c, e.argmax_theta_deg));
            let inside = e
                .below
                .iter()
                .flat_map(|c| c.rho.iter())
                .map(|x| x.max_channel().0)
                .fold(f64::NEG_INFINITY, f64::max);
            rows.push((
                "".into(),
                format!(
                    "ρhd = ρR + ρT (reflected + transmitted){}; light from below: max ρhd {}",
                    parts.map_or(String::new(), |(r, t)| format!(
                        ", at the max ρR {} + ρT {}",
                        est(&r),
                        est(&t)
                    )),
                    if inside.is_finite() {
                        num(inside)
                    } else {
                        "-".into()
                    }
                ),
                "".into(),
                "".into(),
                true,
            ));
        }
        rows.push((
            "".into(),
            format!(
                "ρhh {} ({} evaluations); ρhd(0°) {}{}",
                est(&e.rho_hh),
                e.rho_hh.samples,
                per_angle.map_or("-".into(), est),
                // How significant the largest excess over 1 is; exact values
                // (no noise) below 1 say nothing here.
                if e.method == "quadrature" {
                    // Deterministic: the max ρhd above says it all; the
                    // verdict needs it beyond 1 + its error estimate.
                    String::new()
                } else if e.max_excess_sigmas.is_finite() {
                    format!(
                        "; largest (ρhd − 1)/σ {:.1} (verdict at {}σ)",
                        e.max_excess_sigmas,
                        deg(e.sigmas)
                    )
                } else if e.max_excess_sigmas > 0.0 {
                    "; exceeds 1 with no sampling error".to_string()
                } else {
                    String::new()
                }
            ),
            "".into(),
            "".into(),
            true,
        ));
        if let Some(n) = &self.ndf {
            rows.push((
                "D normalisation".into(),
                format!(
                    "∫ D cosθh dωh = {:.9} ± {} ({} evaluations)",
                    n.integral.value,
                    num(n.integral.error),
                    n.integral.evaluations
                ),
                if n.normalised {
                    "normalised"
                } else {
                    "NOT normalised"
                }
                .into(),
                "".into(),
                n.normalised,
            ));
        }
        // Columns: property, verdict, claim, then the evidence wrapped so
        // that a line fits TABLE_WIDTH (a terminal, a log, an e-mail).
        let w0 = rows
            .iter()
            .map(|r| r.0.chars().count())
            .chain(["property".len()])
            .max()
            .unwrap_or(0);
        let w2 = rows
            .iter()
            .map(|r| r.2.chars().count())
            .chain(["verdict".len()])
            .max()
            .unwrap_or(0);
        let w3 = "claimed".len();
        let indent = 2 + w0 + 2 + w2 + 2 + w3 + 2;
        let w1 = TABLE_WIDTH.saturating_sub(indent).max(24);
        writeln!(f, "properties of `{}`", self.model)?;
        let pad =
            |s: &str, w: usize| format!("{s}{}", " ".repeat(w.saturating_sub(s.chars().count())));
        writeln!(
            f,
            "  {}  {}  {}  measured",
            pad("property", w0),
            pad("verdict", w2),
            pad("claimed", w3)
        )?;
        for (name, measured, verdict, claim, agrees) in &rows {
            let mut lines = wrap(measured, w1);
            match (*agrees, claim.is_empty()) {
                (true, _) => {}
                (false, true) => lines.push("<-- required of every BRDF".into()),
                (false, false) => lines.push("<-- contradicts the claim".into()),
            }
            for (k, text) in lines.iter().enumerate() {
                let line = if k == 0 {
                    format!(
                        "  {}  {}  {}  {text}",
                        pad(name, w0),
                        pad(verdict, w2),
                        pad(claim, w3)
                    )
                } else {
                    format!("{}{text}", " ".repeat(indent))
                };
                writeln!(f, "{}", line.trim_end())?;
            }
        }
        // Where the worst cases are, for the lecture's "why".
        if let (false, Some(w)) = (r.reciprocal, &r.worst) {
            let text = format!(
                "worst reciprocity pair: wi (θ {}°, φ {}°), wo (θ {}°, φ {}°): f(wi,wo) {} vs f(wo,wi) {}",
                deg(w.wi_deg[0]),
                deg(w.wi_deg[1]),
                deg(w.wo_deg[0]),
                deg(w.wo_deg[1]),
                num(w.f.max_element()),
                num(w.f_swapped.max_element())
            );
            write_wrapped(f, &text)?;
        }
        if let (false, Some(w)) = (p.ok, &p.worst) {
            let text = format!(
                "worst positivity pair: wi (θ {}°, φ {}°), wo (θ {}°, φ {}°): f = [{}, {}, {}]",
                deg(w.wi_deg[0]),
                deg(w.wi_deg[1]),
                deg(w.wo_deg[0]),
                deg(w.wo_deg[1]),
                num(w.f.x),
                num(w.f.y),
                num(w.f.z)
            );
            write_wrapped(f, &text)?;
        }
        let rejected: usize = e
            .curves
            .iter()
            .chain(&e.grazing)
            .chain(&e.below)
            .flat_map(|c| c.rho.iter().map(|x| x.rejected))
            .sum::<usize>()
            + e.rho_hh.rejected;
        if rejected > 0 {
            write_wrapped(
                f,
                &format!(
                    "warning: {rejected} albedo samples had a NaN or infinite value or density and were left out"
                ),
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::lambert::Lambert;
    use crate::{Claims, DeltaKind, DeltaLobe, frame};

    fn quick() -> CheckOptions {
        CheckOptions {
            pairs: 2000,
            theta_count: 18,
            samples_per_angle: 512,
            hh_samples: 4096,
            ..CheckOptions::default()
        }
    }

    #[test]
    fn lambert_report() {
        let rho = Rgb::new(0.25, 0.5, 0.75);
        let rep = check(&Lambert::new(rho), &quick());
        assert!(rep.positivity.ok);
        assert_eq!(rep.reciprocity.max_rel_err, 0.0);
        assert!(rep.reciprocity.reciprocal && rep.isotropy.isotropic);
        assert!(rep.energy.conserves);
        assert_eq!(rep.energy.curves.len(), 1);
        // Quadrature (the default for an analytic model): within its error.
        let max = &rep.energy.max;
        assert_eq!(max.method.name(), "quadrature");
        assert!((max.value - rho).abs().max_element() <= max.std_error.max_element() + 1e-12);
        assert!((max.value - rho).abs().max_element() < 1e-6);
        assert!((rep.energy.rho_hh.value - rho).abs().max_element() < 1e-6);
        assert!(rep.ndf.is_none());
        assert!(rep.consistent_with_claims());
        let text = rep.to_string();
        assert!(text.contains("reciprocal"), "{text}");
        let recip = text
            .lines()
            .find(|l| l.trim_start().starts_with("reciprocity"))
            .unwrap();
        assert!(
            recip.contains(" reciprocal ") && recip.contains(" yes "),
            "{text}"
        );
        assert!(!text.contains("contradicts"), "{text}");
        assert!(!rep.strict_failure());
        for line in text.lines() {
            assert!(line.chars().count() <= TABLE_WIDTH, "{line}");
        }
        let json = serde_json::to_value(&rep).unwrap();
        assert_eq!(json["model"], "lambert");
        let hh = json["energy"]["rho_hh"]["value"][1]
            .as_f64()
            .unwrap_or(f64::NAN);
        assert!((hh - 0.5).abs() < 1e-9, "{hh}");
        assert_eq!(json["energy"]["method"], "quadrature");
    }

    /// Claims everything and delivers nothing: non-reciprocal, negative in
    /// places, anisotropic, reflecting more than it receives.
    #[derive(Debug)]
    struct Liar;
    impl Brdf for Liar {
        fn id(&self) -> &'static str {
            "liar"
        }
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            if wi.z <= 0.0 || wo.z <= 0.0 {
                return Rgb::ZERO;
            }
            Rgb::splat(0.6 + 0.3 * wi.x - 0.05 * wo.y + 0.4 * wi.z)
        }
        fn claims(&self) -> Claims {
            Claims {
                reciprocal: true,
                energy_conserving: true,
                isotropic: true,
            }
        }
    }

    #[test]
    fn a_lying_model_is_caught_on_every_count() {
        let rep = check(&Liar, &quick());
        assert!(!rep.reciprocity.reciprocal);
        assert!(!rep.isotropy.isotropic);
        // f ≥ 0.6 − 0.3 − 0.05 > 0: positive after all.
        assert!(rep.positivity.ok);
        // ρhd = π (0.6 + 0.3 x_i + 0.4 z_i) (the y_o term integrates to 0): at
        // θi = 0, 3.1 > 1.
        assert!(!rep.energy.conserves);
        // Anisotropic, so several azimuths are examined; the largest ρhd is
        // at φi = 0 (x_i > 0), θi where 0.3 sin θ + 0.4 cos θ peaks (36.9°).
        assert_eq!(rep.energy.curves.len(), 4);
        let want = PI * (0.6 + 0.5);
        assert!(
            (rep.energy.max.value.x - want).abs() < 0.02,
            "{:?}",
            rep.energy.max
        );
        assert_eq!(rep.energy.argmax_phi_deg, 0.0);
        assert!((rep.energy.argmax_theta_deg - 35.0).abs() <= 5.0);
        assert!(!rep.consistent_with_claims());
        let text = rep.to_string();
        assert!(text.contains("contradicts the claim"), "{text}");
        assert!(text.contains("worst reciprocity pair"), "{text}");
    }

    use std::f64::consts::PI;

    /// A glass-like pure delta model: reflection F and transmission 1 − F.
    #[derive(Debug)]
    struct DeltaGlass;
    impl Brdf for DeltaGlass {
        fn id(&self) -> &'static str {
            "delta-glass"
        }
        fn eval(&self, _wi: DVec3, _wo: DVec3) -> Rgb {
            Rgb::ZERO
        }
        fn claims(&self) -> Claims {
            Claims {
                reciprocal: true,
                energy_conserving: true,
                isotropic: true,
            }
        }
        fn transmits(&self) -> bool {
            true
        }
        fn deltas(&self, wi: DVec3) -> Vec<DeltaLobe> {
            let f = 0.04 + 0.96 * (1.0 - wi.z.abs()).powi(5);
            let mut v = vec![DeltaLobe {
                direction: frame::reflect(wi),
                weight: Rgb::splat(f),
                radiance_scale: Rgb::splat(f),
                kind: DeltaKind::Reflection,
            }];
            if let Some(t) = frame::refract(wi, 1.5) {
                v.push(DeltaLobe {
                    direction: t,
                    weight: Rgb::splat(1.0 - f),
                    radiance_scale: Rgb::splat((1.0 - f) * 2.25),
                    kind: DeltaKind::Transmission,
                });
            }
            v
        }
    }

    #[test]
    fn delta_model_sums_its_lobes_to_one() {
        let rep = check(&DeltaGlass, &quick());
        assert!(rep.energy.has_deltas && rep.energy.transmits);
        assert!(rep.energy.conserves);
        for c in &rep.energy.curves {
            for e in &c.rho {
                assert!((e.value.x - 1.0).abs() < 1e-12, "{e:?}");
            }
        }
        assert!((rep.energy.rho_hh.value.x - 1.0).abs() < 1e-12);
        assert!(rep.positivity.ok);
        assert!(rep.to_string().contains("incl. delta lobes"));
    }

    #[test]
    fn number_format() {
        assert_eq!(num(0.0), "0");
        assert_eq!(num(0.5), "0.5000");
        assert_eq!(num(123.456), "123.5");
        assert_eq!(num(3.1e-17), "3.1e-17");
        assert_eq!(num(1e-6), "1e-6");
        assert_eq!(num(-2.5e7), "-2.5e7");
        assert_eq!(deg(89.999), "89.999");
        assert_eq!(deg(3.0), "3");
        assert_eq!(deg(87.5), "87.5");
    }

    #[test]
    fn wrap_keeps_words_and_width() {
        let text =
            "max ρhd 0.4970 ± 0.04100 at θi = 88°, φi = 0° (45 + 3 grazing θi × 1 azimuth(s))";
        for width in [14, 24, 54] {
            let lines = wrap(text, width);
            assert!(
                lines.iter().all(|l| l.chars().count() <= width),
                "{lines:?}"
            );
            assert_eq!(lines.join(" "), text);
        }
        let long = "x".repeat(25);
        assert_eq!(
            wrap(&long, 10),
            ["x".repeat(10), "x".repeat(10), "x".repeat(5)]
        );
        assert_eq!(wrap("", 10), [""]);
        // A count keeps its word: "0 non-finite" is found on one line.
        let l = wrap(
            "min f 0.1500 over 40000 evaluations, 0 negative, 0 non-finite",
            54,
        );
        assert_eq!(
            l,
            [
                "min f 0.1500 over 40000 evaluations, 0 negative,",
                "0 non-finite"
            ]
        );
    }

    /// A file's data (claims observed, not declared) reports no claims, in
    /// the JSON (null) and the table (—), and a violation it never claimed
    /// otherwise is not a contradiction, though `--strict` still fails on it.
    #[test]
    fn undeclared_claims_show_none() {
        #[derive(Debug)]
        struct Bright;
        impl Brdf for Bright {
            fn id(&self) -> &'static str {
                "bright-file"
            }
            fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
                if wi.z > 0.0 && wo.z > 0.0 {
                    Rgb::splat(1.5 / PI)
                } else {
                    Rgb::ZERO
                }
            }
            fn claims(&self) -> Claims {
                Claims {
                    reciprocal: true,
                    energy_conserving: true,
                    isotropic: true,
                }
            }
            fn claims_declared(&self) -> bool {
                false
            }
        }
        let rep = check(&Bright, &quick());
        assert_eq!(
            rep.claims,
            ClaimsReport {
                reciprocal: None,
                energy_conserving: None,
                isotropic: None
            }
        );
        assert!(!rep.energy.conserves);
        assert!(rep.consistent_with_claims());
        assert!(rep.strict_failure());
        let json = serde_json::to_value(&rep).unwrap();
        assert!(json["claims"]["energy_conserving"].is_null(), "{json}");
        assert!(json["claims"]["reciprocal"].is_null(), "{json}");
        let text = rep.to_string();
        let energy = text
            .lines()
            .find(|l| l.trim_start().starts_with("energy"))
            .unwrap();
        assert!(
            energy.contains("violates energy") && energy.contains(" — "),
            "{text}"
        );
        assert!(!text.contains("contradicts"), "{text}");
        assert!(!text.contains("yes"), "{text}");
    }
}
