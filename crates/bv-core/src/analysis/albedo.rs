//! Energy: the directional albedo `ρhd(wi) = ∫ f(wi, wo) |cos θo| dωo` (plus
//! the weights of the delta lobes) and the bihemispherical albedo
//! `ρhh = (1/π) ∫∫ f cos θi cos θo dωi dωo`, by Monte Carlo with an honest
//! standard error. Analytic models are better served by the deterministic
//! rule of [`super::quadrature`]; [`rho_hd_auto`] picks the method.
//!
//! # Estimator
//! Each sample count is split evenly between two techniques: the model's own
//! [`Brdf::sample`] and a cosine-weighted direction (over the whole sphere for
//! transmitting models). Every sample is weighted by the *mixture* density
//! `½ pdf_model + ½ pdf_cos` (Veach & Guibas 1995, the balance heuristic with
//! equal counts, a.k.a. the deterministic defensive mixture; Hesterberg 1995).
//! The model's sampler concentrates the samples in sharp lobes (Phong
//! e = 10000, GGX α = 0.001), and the cosine half bounds the weight
//! `f cos / pdf` where the model's sampler is poor, so neither a sharp lobe
//! nor a crude sampler ruins the estimate. The estimator is unbiased exactly
//! when `pdf` is the density of `sample` (the property tests hold every model
//! to that).
//!
//! Within each technique the unit square is stratified on a full `k × k`
//! jittered grid, one uniform point per cell: every cell has area `1/k²` and
//! weight `1/k²`, so the stratified mean is unbiased. (A grid with a cut-short
//! last row leaves part of the square unsampled while weighting every sample
//! as if it covered it: a bias of a few per cent for lobes that the missing
//! strip maps to.)
//!
//! The error is honest rather than asymptotic: the estimate is the mean of
//! [`REPLICAS`] independent replicas (independent jitter), and `std_error` is
//! the sample standard deviation of the replica means over `√REPLICAS`. With 16
//! replicas, ±3 `std_error` covers the true value with about 99 % probability
//! (Student t, 15 degrees of freedom) when the replica means are close to
//! normal, which stratification and the bounded mixture weight make them.

use super::directions::stream_seed;
use super::quadrature::{self, QuadratureOptions};
use crate::sampling::{self, BvRng};
use crate::{Brdf, DeltaKind, Rgb, frame};
use glam::{DVec2, DVec3};
use rand::Rng;
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::{FRAC_PI_2, PI};

/// Independent replicas per estimate (the error estimate's degrees of freedom
/// plus one).
pub const REPLICAS: usize = 16;

pub use super::estimate::{AlbedoParts, Estimate, Method};

/// Mean of replica means, and their standard error.
fn from_replicas(means: &[Rgb], samples: usize, rejected: usize, exact: Rgb) -> Estimate {
    let k = means.len().max(1) as f64;
    let mean = means.iter().copied().sum::<Rgb>() / k;
    let var = if means.len() > 1 {
        means.iter().map(|&m| (m - mean) * (m - mean)).sum::<Rgb>() / (k - 1.0)
    } else {
        Rgb::ZERO
    };
    Estimate {
        value: mean + exact,
        std_error: (var / k).map(f64::sqrt),
        samples,
        rejected,
        method: Method::MonteCarlo {
            replicas: means.len(),
        },
    }
}

/// ρhd over θi for one incident azimuth (the GUI's albedo plot).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AlbedoCurve {
    /// Incident azimuth φi (degrees).
    pub phi_i_deg: f64,
    /// Incident polar angles θi (degrees): `k · 90 / n` for `k = 0..n`.
    pub theta_deg: Vec<f64>,
    /// ρhd at each θi.
    pub rho: Vec<Estimate>,
    /// Whether the light comes from below the surface (a transmitting
    /// model's inside): θi is then measured from −z.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub from_below: bool,
    /// For a transmitting model, ρR at each θi (what leaves on the light's
    /// side); empty otherwise.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub reflected: Vec<Estimate>,
    /// For a transmitting model, ρT at each θi (what crosses the surface);
    /// `rho = reflected + transmitted`. Empty otherwise.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub transmitted: Vec<Estimate>,
}

/// The θi grid of [`rho_hd_curve`]: `n` angles `k · (π/2) / n`, `k = 0..n`
/// (0°, 1°, …, 89° for `n = 90`), radians. 90° itself is left out because a
/// reflection model sees no light there (`cos θi = 0`).
pub fn theta_grid(n: usize) -> Vec<f64> {
    (0..n).map(|k| FRAC_PI_2 * k as f64 / n as f64).collect()
}

/// Cosine-weighted direction; for transmitting models, on the upper or lower
/// hemisphere with probability ½ each (`u.x` picks the side, so the
/// stratification carries over).
fn cosine_direction(u: DVec2, transmits: bool) -> DVec3 {
    if !transmits {
        return sampling::cosine_hemisphere(u);
    }
    if u.x < 0.5 {
        sampling::cosine_hemisphere(DVec2::new(2.0 * u.x, u.y))
    } else {
        let w = sampling::cosine_hemisphere(DVec2::new(2.0 * u.x - 1.0, u.y));
        DVec3::new(w.x, w.y, -w.z)
    }
}

/// Density of [`cosine_direction`].
fn cosine_density(w: DVec3, transmits: bool) -> f64 {
    if transmits {
        w.z.abs() / (2.0 * PI)
    } else {
        sampling::cosine_hemisphere_pdf(w)
    }
}

/// One sample's weight `f |cos θo| / (½ pdf_model + ½ pdf_cos)`; `Err(())`
/// for a non-finite value or density.
fn weight(brdf: &dyn Brdf, wi: DVec3, wo: DVec3, transmits: bool) -> Result<Rgb, ()> {
    if !wo.is_finite() {
        return Err(());
    }
    let cos_o = if transmits { wo.z.abs() } else { wo.z };
    if cos_o <= 0.0 {
        return Ok(Rgb::ZERO);
    }
    let f = brdf.eval(wi, wo);
    if f == Rgb::ZERO {
        return Ok(Rgb::ZERO);
    }
    let p = 0.5 * brdf.pdf(wi, wo) + 0.5 * cosine_density(wo, transmits);
    // p ≥ ½ pdf_cos > 0 here; only a NaN or infinite model density can spoil it.
    if !f.is_finite() || !p.is_finite() || p <= 0.0 {
        return Err(());
    }
    Ok(f * (cos_o / p))
}

/// Jittered grid points of the unit square: one uniform point in each cell
/// of a `k × k` grid (`k²` points).
fn jittered(k: usize, rng: &mut BvRng, mut visit: impl FnMut(DVec2)) {
    let inv = 1.0 / k as f64;
    for j in 0..k {
        for i in 0..k {
            let u = DVec2::new(
                (i as f64 + rng.random::<f64>()) * inv,
                (j as f64 + rng.random::<f64>()) * inv,
            );
            // Keep u in [0, 1): (i + r)/k can round up to 1.
            visit(u.min(DVec2::splat(1.0 - f64::EPSILON / 2.0)));
        }
    }
}

/// One replica of ρhd: `k²` stratified samples from each technique; the
/// sums of the samples that stay on `wi`'s side and of those that cross the
/// surface, and the rejected count.
fn replica(
    brdf: &dyn Brdf,
    wi: DVec3,
    k: usize,
    rng: &mut BvRng,
    transmits: bool,
) -> (Rgb, Rgb, usize) {
    let n = k * k;
    let mut sum = [Rgb::ZERO; 2];
    let mut rejected = 0;
    let mut add = |wo: DVec3, w: Result<Rgb, ()>| match w {
        Ok(v) => sum[usize::from((wo.z > 0.0) != (wi.z > 0.0))] += v,
        Err(()) => rejected += 1,
    };
    let mut us = Vec::with_capacity(n);
    jittered(k, rng, |u| us.push(u));
    for &u in &us {
        if let Some(wo) = brdf.sample(wi, u) {
            add(wo, weight(brdf, wi, wo, transmits));
        }
    }
    us.clear();
    jittered(k, rng, |u| us.push(u));
    for &u in &us {
        let wo = cosine_direction(u, transmits);
        add(wo, weight(brdf, wi, wo, transmits));
    }
    let m = (2 * n) as f64;
    (sum[0] / m, sum[1] / m, rejected)
}

/// Total weight of the delta lobes for light from `wi` (exact, no error).
fn delta_weight(brdf: &dyn Brdf, wi: DVec3) -> Rgb {
    brdf.deltas(wi).iter().map(|d| d.weight).sum()
}

/// Weight of the delta lobes of one kind for light from `wi`.
fn delta_weight_of(brdf: &dyn Brdf, wi: DVec3, kind: DeltaKind) -> Rgb {
    brdf.deltas(wi)
        .iter()
        .filter(|d| d.kind == kind)
        .map(|d| d.weight)
        .sum()
}

/// The side `k` of the per-technique grid for a requested total: the
/// smallest `k` with `2 · REPLICAS · k² ≥ samples`.
fn grid_side(samples: usize) -> usize {
    let per = samples.div_ceil(2 * REPLICAS).max(1);
    let mut k = (per as f64).sqrt().floor() as usize;
    while k * k < per {
        k += 1;
    }
    k.max(1)
}

/// ρhd for light from the unit direction `wi`, with about `samples`
/// evaluations (rounded up to `2 · REPLICAS · k²`).
pub fn rho_hd_dir(brdf: &dyn Brdf, wi: DVec3, samples: usize, seed: u64) -> Estimate {
    rho_hd_parts_dir(brdf, wi, samples, seed).total
}

/// [`rho_hd_dir`] split into ρR (directions on `wi`'s side, with the
/// reflected delta lobes) and ρT (across the surface, with the transmitted
/// ones); each part's standard error comes from the same replicas, and
/// `total` is their sum replica by replica.
pub fn rho_hd_parts_dir(brdf: &dyn Brdf, wi: DVec3, samples: usize, seed: u64) -> AlbedoParts {
    let k = grid_side(samples);
    let n = k * k;
    let transmits = brdf.transmits();
    let mut refl = Vec::with_capacity(REPLICAS);
    let mut trans = Vec::with_capacity(REPLICAS);
    let mut total = Vec::with_capacity(REPLICAS);
    let mut rejected = 0;
    for r in 0..REPLICAS {
        let mut rng = sampling::rng(stream_seed(seed, r as u64));
        let (a, b, bad) = replica(brdf, wi, k, &mut rng, transmits);
        refl.push(a);
        trans.push(b);
        total.push(a + b);
        rejected += bad;
    }
    let count = 2 * n * REPLICAS;
    AlbedoParts {
        total: from_replicas(&total, count, rejected, delta_weight(brdf, wi)),
        reflected: from_replicas(
            &refl,
            count,
            rejected,
            delta_weight_of(brdf, wi, DeltaKind::Reflection),
        ),
        transmitted: from_replicas(
            &trans,
            count,
            rejected,
            delta_weight_of(brdf, wi, DeltaKind::Transmission),
        ),
    }
}

/// ρhd for light from polar angle `theta_i` and azimuth `phi_i` (radians).
pub fn rho_hd(brdf: &dyn Brdf, theta_i: f64, phi_i: f64, samples: usize, seed: u64) -> Estimate {
    rho_hd_dir(brdf, frame::from_spherical(theta_i, phi_i), samples, seed)
}

/// Which estimator an albedo uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AlbedoMethod {
    /// Quadrature for analytic models ([`Brdf::is_analytic`]), Monte Carlo
    /// for the others.
    #[default]
    Auto,
    /// Always Monte Carlo.
    MonteCarlo,
    /// Always quadrature.
    Quadrature,
}

/// How an albedo is computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlbedoOptions {
    /// The estimator.
    pub method: AlbedoMethod,
    /// Monte Carlo: samples per ρhd value (in [`REPLICAS`] replicas).
    pub samples: usize,
    /// Monte Carlo: the seed (results are repeatable).
    pub seed: u64,
    /// Quadrature: tolerance and budgets.
    pub quadrature: QuadratureOptions,
}

impl Default for AlbedoOptions {
    fn default() -> Self {
        Self {
            method: AlbedoMethod::Auto,
            samples: 4096,
            seed: 1,
            quadrature: QuadratureOptions::default(),
        }
    }
}

impl AlbedoOptions {
    /// Whether these options integrate `brdf` by quadrature.
    pub fn uses_quadrature(&self, brdf: &dyn Brdf) -> bool {
        match self.method {
            AlbedoMethod::Auto => brdf.is_analytic(),
            AlbedoMethod::MonteCarlo => false,
            AlbedoMethod::Quadrature => true,
        }
    }

    /// The same options with another seed.
    pub fn with_seed(&self, seed: u64) -> Self {
        Self { seed, ..*self }
    }
}

/// ρhd for light from polar angle `theta_i` and azimuth `phi_i` (radians)
/// with the method `opts` picks for `brdf`.
pub fn rho_hd_auto(brdf: &dyn Brdf, theta_i: f64, phi_i: f64, opts: &AlbedoOptions) -> Estimate {
    if opts.uses_quadrature(brdf) {
        quadrature::rho_hd(brdf, theta_i, phi_i, &opts.quadrature)
    } else {
        rho_hd(brdf, theta_i, phi_i, opts.samples, opts.seed)
    }
}

/// ρR, ρT and their sum for light from the unit direction `wi` (on either
/// side of the surface) with the method `opts` picks for `brdf`.
pub fn rho_hd_parts_auto(brdf: &dyn Brdf, wi: DVec3, opts: &AlbedoOptions) -> AlbedoParts {
    if opts.uses_quadrature(brdf) {
        quadrature::rho_hd_parts_dir(brdf, wi, &opts.quadrature)
    } else {
        rho_hd_parts_dir(brdf, wi, opts.samples, opts.seed)
    }
}

/// ρhh with the method `opts` picks for `brdf`.
pub fn rho_hh_auto(brdf: &dyn Brdf, hh_samples: usize, opts: &AlbedoOptions) -> Estimate {
    if opts.uses_quadrature(brdf) {
        quadrature::rho_hh(brdf, &opts.quadrature)
    } else {
        rho_hh(brdf, hh_samples, opts.seed)
    }
}

/// ρhd at the `n_theta` angles of [`theta_grid`] for azimuth `phi_i`
/// (radians), in parallel over the angles.
pub fn rho_hd_curve(
    brdf: &dyn Brdf,
    phi_i: f64,
    n_theta: usize,
    opts: &AlbedoOptions,
) -> AlbedoCurve {
    rho_hd_angles(brdf, phi_i, &theta_grid(n_theta), opts)
}

/// ρhd at the given θi (radians) for azimuth `phi_i` (radians), in parallel
/// over the angles (Monte Carlo angles get independent seeds).
pub fn rho_hd_angles(
    brdf: &dyn Brdf,
    phi_i: f64,
    thetas: &[f64],
    opts: &AlbedoOptions,
) -> AlbedoCurve {
    rho_hd_angles_side(brdf, phi_i, thetas, opts, false)
}

/// [`rho_hd_angles`] with the light above the surface, or, with
/// `from_below`, below it (`wi` the mirror image through the surface of the
/// direction at θi, φi). For a transmitting model the curve carries ρR and
/// ρT at each angle besides their sum.
pub fn rho_hd_angles_side(
    brdf: &dyn Brdf,
    phi_i: f64,
    thetas: &[f64],
    opts: &AlbedoOptions,
    from_below: bool,
) -> AlbedoCurve {
    let parts: Vec<AlbedoParts> = thetas
        .par_iter()
        .enumerate()
        .map(|(k, &t)| {
            let mut wi = frame::from_spherical(t, phi_i);
            if from_below {
                wi.z = -wi.z;
            }
            let o = opts.with_seed(stream_seed(opts.seed, k as u64));
            if brdf.transmits() || from_below {
                rho_hd_parts_auto(brdf, wi, &o)
            } else {
                let total = rho_hd_auto(brdf, t, phi_i, &o);
                AlbedoParts {
                    total,
                    reflected: total,
                    transmitted: total,
                }
            }
        })
        .collect();
    let split = brdf.transmits();
    AlbedoCurve {
        phi_i_deg: phi_i.to_degrees(),
        theta_deg: thetas.iter().map(|t| t.to_degrees()).collect(),
        rho: parts.iter().map(|p| p.total).collect(),
        from_below,
        reflected: if split {
            parts.iter().map(|p| p.reflected).collect()
        } else {
            Vec::new()
        },
        transmitted: if split {
            parts.iter().map(|p| p.transmitted).collect()
        } else {
            Vec::new()
        },
    }
}

/// ρhh `= (1/π) ∫∫ f cos θi cos θo dωi dωo = E[ρhd(wi)]` for `wi` drawn with
/// density `cos θi / π`: per replica, stratified cosine-weighted `wi`, each
/// with one sample of each technique for `wo`. About `samples` evaluations,
/// in parallel over the replicas.
pub fn rho_hh(brdf: &dyn Brdf, samples: usize, seed: u64) -> Estimate {
    let k = grid_side(samples);
    let n = k * k;
    let transmits = brdf.transmits();
    let results: Vec<(Rgb, usize)> = (0..REPLICAS)
        .into_par_iter()
        .map(|r| {
            let mut rng = sampling::rng(stream_seed(seed ^ 0x4848, r as u64));
            let mut wis = Vec::with_capacity(n);
            jittered(k, &mut rng, |u| wis.push(sampling::cosine_hemisphere(u)));
            let mut sum = Rgb::ZERO;
            let mut rejected = 0;
            for wi in wis {
                let u1 = sampling::uniform2(&mut rng);
                let u2 = sampling::uniform2(&mut rng);
                let mut acc = Rgb::ZERO;
                if let Some(wo) = brdf.sample(wi, u1) {
                    match weight(brdf, wi, wo, transmits) {
                        Ok(v) => acc += v,
                        Err(()) => rejected += 1,
                    }
                }
                match weight(brdf, wi, cosine_direction(u2, transmits), transmits) {
                    Ok(v) => acc += v,
                    Err(()) => rejected += 1,
                }
                sum += 0.5 * acc + delta_weight(brdf, wi);
            }
            (sum / n as f64, rejected)
        })
        .collect();
    let means: Vec<Rgb> = results.iter().map(|r| r.0).collect();
    let rejected = results.iter().map(|r| r.1).sum();
    from_replicas(&means, 2 * n * REPLICAS, rejected, Rgb::ZERO)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::lambert::Lambert;
    use crate::{Claims, DeltaKind, DeltaLobe};
    use std::f64::consts::FRAC_1_PI;

    fn assert_covers(e: &Estimate, truth: Rgb, what: &str) {
        let dev = (e.value - truth).abs();
        let tol = 4.0 * e.std_error + Rgb::splat(1e-12);
        assert!(
            dev.cmple(tol).all(),
            "{what}: {} ± {} vs {truth}",
            e.value,
            e.std_error
        );
    }

    #[test]
    fn lambert_albedo_is_rho() {
        let rho = Rgb::new(0.2, 0.5, 0.9);
        let b = Lambert::new(rho);
        for deg in [0.0, 30.0, 60.0, 89.0] {
            let e = rho_hd(&b, f64::to_radians(deg), 0.3, 1000, 1);
            // Cosine sampling is exact for a constant f: the weight is ρ every time.
            assert!(
                (e.value - rho).abs().max_element() < 1e-12,
                "{deg}: {}",
                e.value
            );
            assert!(e.std_error.max_element() < 1e-12);
            assert_eq!(e.samples, 2 * 36 * REPLICAS);
            assert_eq!(e.rejected, 0);
        }
        let hh = rho_hh(&b, 4000, 2);
        assert!((hh.value - rho).abs().max_element() < 1e-12, "{}", hh.value);
        let opts = AlbedoOptions {
            method: AlbedoMethod::MonteCarlo,
            samples: 256,
            seed: 3,
            ..AlbedoOptions::default()
        };
        let curve = rho_hd_curve(&b, 0.0, 90, &opts);
        assert_eq!(curve.theta_deg.len(), 90);
        assert!((curve.theta_deg[89] - 89.0).abs() < 1e-12);
        assert!(
            curve
                .rho
                .iter()
                .all(|e| (e.value - rho).abs().max_element() < 1e-12)
        );
    }

    /// Lambert with a uniform-hemisphere sampler: the mixture weight then varies
    /// with θo, so the estimate has a genuine variance to estimate.
    #[derive(Debug)]
    struct UniformLambert(f64);
    impl Brdf for UniformLambert {
        fn id(&self) -> &'static str {
            "uniform-lambert"
        }
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            if wi.z <= 0.0 || wo.z <= 0.0 {
                return Rgb::ZERO;
            }
            Rgb::splat(self.0 * FRAC_1_PI)
        }
        fn claims(&self) -> Claims {
            Claims {
                reciprocal: true,
                energy_conserving: true,
                isotropic: true,
            }
        }
        fn sample(&self, _wi: DVec3, u: DVec2) -> Option<DVec3> {
            Some(sampling::uniform_hemisphere(u))
        }
        fn pdf(&self, _wi: DVec3, wo: DVec3) -> f64 {
            if wo.z > 0.0 { 0.5 * FRAC_1_PI } else { 0.0 }
        }
    }

    #[test]
    fn error_estimate_covers_the_true_value() {
        // Over 200 independent estimates, ±2 std_error should cover ρ about
        // 94 % of the time (t distribution, 15 d.o.f.) and ±3 about 99 %. A
        // std_error off by √REPLICAS (or by 2) fails these bounds.
        let b = UniformLambert(0.7);
        let runs = 200;
        let (mut in2, mut in3) = (0, 0);
        for s in 0..runs {
            let e = rho_hd(&b, 0.7, 0.0, 64, 1000 + s);
            assert!(e.std_error.x > 0.0);
            let z = (e.value.x - 0.7).abs() / e.std_error.x;
            in2 += usize::from(z <= 2.0);
            in3 += usize::from(z <= 3.0);
        }
        let (c2, c3) = (in2 as f64 / runs as f64, in3 as f64 / runs as f64);
        assert!((0.86..=0.995).contains(&c2), "2σ coverage {c2}");
        assert!(c3 >= 0.96, "3σ coverage {c3}");
        // More samples shrink the error like 1/√n.
        let small = rho_hd(&b, 0.7, 0.0, 1024, 5).std_error.x;
        let large = rho_hd(&b, 0.7, 0.0, 16 * 1024, 5).std_error.x;
        assert!(large < small / 2.0, "{small} {large}");
    }

    /// A half-silvered Lambertian: diffuse 0.3 plus a delta mirror of weight
    /// 0.5, so ρhd = 0.8 exactly.
    #[derive(Debug)]
    struct HalfMirror;
    impl Brdf for HalfMirror {
        fn id(&self) -> &'static str {
            "half-mirror"
        }
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            Lambert::new(Rgb::splat(0.3)).eval(wi, wo)
        }
        fn claims(&self) -> Claims {
            Claims {
                reciprocal: true,
                energy_conserving: true,
                isotropic: true,
            }
        }
        fn deltas(&self, wi: DVec3) -> Vec<DeltaLobe> {
            vec![DeltaLobe {
                direction: frame::reflect(wi),
                weight: Rgb::new(0.5, 0.4, 0.3),
                radiance_scale: Rgb::new(0.5, 0.4, 0.3),
                kind: DeltaKind::Reflection,
            }]
        }
    }

    #[test]
    fn delta_weights_are_added() {
        let e = rho_hd(&HalfMirror, 0.4, 1.0, 512, 1);
        assert!((e.value - Rgb::new(0.8, 0.7, 0.6)).abs().max_element() < 1e-12);
        let hh = rho_hh(&HalfMirror, 2000, 1);
        assert!((hh.value - Rgb::new(0.8, 0.7, 0.6)).abs().max_element() < 1e-12);
    }

    /// Normalised Phong lobe about the mirror direction, `(e+2)/(2π) cos^e α`,
    /// sampled by the power-cosine warp.
    #[derive(Debug)]
    struct NormalisedPhong(f64);
    impl Brdf for NormalisedPhong {
        fn id(&self) -> &'static str {
            "normalised-phong"
        }
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            if wi.z <= 0.0 || wo.z <= 0.0 {
                return Rgb::ZERO;
            }
            let c = frame::reflect(wi).dot(wo).max(0.0);
            Rgb::splat((self.0 + 2.0) / (2.0 * PI) * c.powf(self.0))
        }
        fn claims(&self) -> Claims {
            Claims {
                reciprocal: true,
                energy_conserving: true,
                isotropic: true,
            }
        }
        fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
            Some(sampling::power_cosine(frame::reflect(wi), self.0, u))
        }
        fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
            sampling::power_cosine_pdf(frame::reflect(wi), self.0, wo)
        }
    }

    #[test]
    fn sharp_phong_lobe_is_accurate() {
        // With r = R(wi) and wo = cos α r + sin α (cos φ t + sin φ b), the φ
        // average of cos θo is cos α (r·n), so ∫ cos^e α cos θo dω =
        // cos θi · 2π/(e+2) while the lobe stays above the horizon: ρhd = cos θi.
        // At e = 10000 the lobe's weight beyond 5° is below e^−38.
        let b = NormalisedPhong(10000.0);
        for deg in [0.0f64, 30.0, 60.0, 80.0] {
            let e = rho_hd(&b, deg.to_radians(), 0.5, 4096, 7);
            assert_covers(&e, Rgb::splat(deg.to_radians().cos()), &format!("θi={deg}"));
            assert!(e.std_error.x < 2e-3, "{deg}: {}", e.std_error.x);
        }
    }

    /// A smooth GGX microfacet mirror, `D / (4 cos θi cos θo)` (F = G = 1),
    /// sampled by drawing h with density `D cos θh` (Walter et al. 2007,
    /// eqs. 33, 35 and 38).
    #[derive(Debug)]
    struct SharpGgx(f64);
    impl SharpGgx {
        fn d(&self, h: DVec3) -> f64 {
            let a2 = self.0 * self.0;
            let c2 = h.z * h.z;
            let t2 = frame::tan2_theta(h);
            1.0 / (PI * a2 * c2 * c2 * (1.0 + t2 / a2).powi(2))
        }
    }
    impl Brdf for SharpGgx {
        fn id(&self) -> &'static str {
            "sharp-ggx"
        }
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            if wi.z <= 0.0 || wo.z <= 0.0 {
                return Rgb::ZERO;
            }
            let Some(h) = frame::half_vector(wi, wo) else {
                return Rgb::ZERO;
            };
            Rgb::splat(self.d(h) / (4.0 * wi.z * wo.z))
        }
        fn claims(&self) -> Claims {
            Claims {
                reciprocal: true,
                energy_conserving: true,
                isotropic: true,
            }
        }
        fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
            // tan²θh = α² u/(1 − u) inverts the CDF of D cos θh (Walter eq. 35).
            let t2 = self.0 * self.0 * u.x / (1.0 - u.x);
            let c = 1.0 / (1.0 + t2).sqrt();
            let s = (1.0 - c * c).max(0.0).sqrt();
            let phi = 2.0 * PI * u.y;
            let h = DVec3::new(s * phi.cos(), s * phi.sin(), c);
            Some(frame::reflect_about(wi, h))
        }
        fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
            let Some(h) = frame::half_vector(wi, wo) else {
                return 0.0;
            };
            if h.z <= 0.0 {
                return 0.0;
            }
            self.d(h) * h.z / (4.0 * wo.dot(h).abs())
        }
    }

    #[test]
    fn sharp_ggx_lobe_is_accurate() {
        // At normal incidence wo = R_h(n) has cos θo = cos 2θh, so
        // ρhd = ∫_{θh<45°} D cos θh dωh = 1 − ∫_{tan²θh>1} ... ; with
        // t = tan²θh, ∫ D cos θh dωh = (1/α²) ∫ dt / (1 + t/α²)², whose tail
        // beyond t = 1 is α²/(1 + α²).
        let a = 0.001;
        let e = rho_hd(&SharpGgx(a), 0.0, 0.0, 4096, 11);
        assert_covers(&e, Rgb::splat(1.0 - a * a / (1.0 + a * a)), "GGX α=0.001");
        assert!(e.std_error.x < 2e-3, "{}", e.std_error.x);
        // Off normal incidence the lobe stays whole: ρhd(θi) → 1 as α → 0, up
        // to O(α) shifts of the visible fraction.
        let e = rho_hd(&SharpGgx(a), 1.0, 0.0, 4096, 12);
        assert!(
            (e.value.x - 1.0).abs() < 4.0 * e.std_error.x + 1e-2,
            "{e:?}"
        );
    }

    /// NaN everywhere on one side: rejected, not averaged in.
    #[derive(Debug)]
    struct NanHalf;
    impl Brdf for NanHalf {
        fn id(&self) -> &'static str {
            "nan-half"
        }
        fn eval(&self, _wi: DVec3, wo: DVec3) -> Rgb {
            if wo.x > 0.0 {
                Rgb::splat(f64::NAN)
            } else {
                Rgb::splat(0.1)
            }
        }
        fn claims(&self) -> Claims {
            Claims {
                reciprocal: false,
                energy_conserving: false,
                isotropic: false,
            }
        }
    }

    #[test]
    fn non_finite_values_are_counted_not_averaged() {
        let e = rho_hd(&NanHalf, 0.2, 0.0, 1024, 1);
        assert!(e.value.is_finite());
        assert!(e.rejected > 300 && e.rejected < 700, "{}", e.rejected);
    }
}
