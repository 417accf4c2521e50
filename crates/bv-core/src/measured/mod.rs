//! Measured BRDF data (issue 5): the MERL half/difference-angle tables of
//! Matusik et al. 2003, "A Data-Driven Reflectance Model" (SPEC §4), and the
//! small estimators `bv info` reports about any tabulated model.

pub mod merl;

pub use merl::{Interpolation, MerlDims, MerlTable, MerlWarnings};

use crate::{Brdf, Rgb, frame, sampling};
use glam::DVec3;

/// Directional albedo `ρhd(θi) = ∫ f(wi, wo) cos θo dωo` by cosine-weighted
/// Monte Carlo (`wo ~ cos θo / π`, so each sample contributes `π f`), with a
/// fixed seed. Returns the estimate and its standard error per channel.
///
/// A deliberately small estimator so that `bv info` needs nothing from the
/// property analysis; with `n` samples the standard error is
/// `π σ(f) / √n` (it vanishes for a constant `f`, e.g. Lambert).
pub fn rho_hd_mc(brdf: &dyn Brdf, theta_i: f64, n: usize, seed: u64) -> (Rgb, Rgb) {
    let wi = frame::from_spherical(theta_i, 0.0);
    let n = n.max(2);
    let mut rng = sampling::rng(seed);
    let mut sum = Rgb::ZERO;
    let mut sum2 = Rgb::ZERO;
    for _ in 0..n {
        let wo = sampling::cosine_hemisphere(sampling::uniform2(&mut rng));
        let x = if wo.z > 0.0 {
            brdf.eval(wi, wo) * std::f64::consts::PI
        } else {
            Rgb::ZERO
        };
        let x = if x.is_finite() { x } else { Rgb::ZERO };
        sum += x;
        sum2 += x * x;
    }
    let nf = n as f64;
    let mean = sum / nf;
    let var = ((sum2 / nf - mean * mean) * (nf / (nf - 1.0))).max(Rgb::ZERO);
    (mean, (var / nf).map(f64::sqrt))
}

/// Largest Helmholtz-reciprocity violation `max |f(wi,wo) − f(wo,wi)| / max f`
/// (SPEC §3) over `n` pairs of cosine-distributed directions (fixed seed), on
/// the channel mean. 0 when `f` vanishes everywhere on the set.
pub fn max_reciprocity_error(brdf: &dyn Brdf, n: usize, seed: u64) -> f64 {
    let mut rng = sampling::rng(seed);
    let mut max_f = 0.0f64;
    let mut max_diff = 0.0f64;
    for _ in 0..n {
        let wi: DVec3 = sampling::cosine_hemisphere(sampling::uniform2(&mut rng));
        let wo: DVec3 = sampling::cosine_hemisphere(sampling::uniform2(&mut rng));
        if wi.z <= 0.0 || wo.z <= 0.0 {
            continue;
        }
        let a = crate::mean_rgb(brdf.eval(wi, wo));
        let b = crate::mean_rgb(brdf.eval(wo, wi));
        if a.is_finite() && b.is_finite() {
            max_f = max_f.max(a.abs()).max(b.abs());
            max_diff = max_diff.max((a - b).abs());
        }
    }
    if max_f > 0.0 { max_diff / max_f } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::lambert::Lambert;

    #[test]
    fn lambert_albedo_is_exact_with_zero_error() {
        // f = ρ/π is constant, so π f = ρ for every sample: no variance.
        let b = Lambert::new(Rgb::new(0.2, 0.5, 0.8));
        let (m, e) = rho_hd_mc(&b, 0.7, 1000, 1);
        assert!((m - Rgb::new(0.2, 0.5, 0.8)).abs().max_element() < 1e-12);
        assert!(e.max_element() < 1e-7);
        assert_eq!(max_reciprocity_error(&b, 1000, 2), 0.0);
    }
}
