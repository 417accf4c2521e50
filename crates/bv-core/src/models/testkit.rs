//! Test helpers shared by the model modules' unit tests: quadrature over the
//! hemisphere, the sampling/pdf agreement checks, reciprocity comparison and
//! proptest strategies for in-range directions including grazing ones.

use crate::{Brdf, Rgb, sampling};
use glam::{DVec2, DVec3};
use proptest::prelude::*;
use std::f64::consts::PI;

/// `∫ g(w) dω` over the upper hemisphere by the midpoint rule in (θ, φ) with
/// the `sin θ` Jacobian; error O(1/n²) for smooth `g`.
pub fn hemisphere_integral(g: impl Fn(DVec3) -> f64, n_theta: usize, n_phi: usize) -> f64 {
    let dt = 0.5 * PI / n_theta as f64;
    let dp = 2.0 * PI / n_phi as f64;
    let mut sum = 0.0;
    for i in 0..n_theta {
        let t = (i as f64 + 0.5) * dt;
        let st = t.sin();
        let mut row = 0.0;
        for j in 0..n_phi {
            let p = (j as f64 + 0.5) * dp;
            row += g(crate::frame::from_spherical(t, p));
        }
        sum += row * st;
    }
    sum * dt * dp
}

/// Directional albedo `ρ(wi) = ∫ f(wi, wo) cos θo dωo` by [`hemisphere_integral`].
pub fn albedo(b: &dyn Brdf, wi: DVec3, n_theta: usize, n_phi: usize) -> Rgb {
    let r = hemisphere_integral(|wo| b.eval(wi, wo).x * wo.z, n_theta, n_phi);
    let g = hemisphere_integral(|wo| b.eval(wi, wo).y * wo.z, n_theta, n_phi);
    let bl = hemisphere_integral(|wo| b.eval(wi, wo).z * wo.z, n_theta, n_phi);
    Rgb::new(r, g, bl)
}

/// Monte Carlo estimate of `∫ g(wo) dωo` over the upper hemisphere with the
/// model's own sampler: the mean of `g(wo)/pdf(wo)` over `n` draws (a failed
/// draw contributes 0). Returns (estimate, standard error). Panics if a drawn
/// direction has a zero pdf or is not unit: that is a sampler/pdf mismatch.
pub fn sampled_integral(
    b: &dyn Brdf,
    wi: DVec3,
    g: impl Fn(DVec3) -> f64,
    n: usize,
    seed: u64,
) -> (f64, f64) {
    let mut rng = sampling::rng(seed);
    let (mut s, mut s2) = (0.0, 0.0);
    for _ in 0..n {
        let u: DVec2 = sampling::uniform2(&mut rng);
        let x = match b.sample(wi, u) {
            Some(wo) => {
                assert!((wo.length() - 1.0).abs() < 1e-9, "sample not unit: {wo}");
                if wo.z <= 0.0 {
                    0.0
                } else {
                    let p = b.pdf(wi, wo);
                    assert!(p > 0.0 && p.is_finite(), "pdf {p} at sampled {wo}");
                    g(wo) / p
                }
            }
            None => 0.0,
        };
        s += x;
        s2 += x * x;
    }
    let nf = n as f64;
    let mean = s / nf;
    let var = (s2 / nf - mean * mean).max(0.0);
    (mean, (var / nf).sqrt())
}

/// Fraction of `n` draws for which `sample` returned a direction.
pub fn success_rate(b: &dyn Brdf, wi: DVec3, n: usize, seed: u64) -> f64 {
    let mut rng = sampling::rng(seed);
    let ok = (0..n)
        .filter(|_| b.sample(wi, sampling::uniform2(&mut rng)).is_some())
        .count();
    ok as f64 / n as f64
}

/// `|a − b| ≤ rel · max(|a|, |b|)` per channel (both zero passes).
pub fn rel_close(a: Rgb, b: Rgb, rel: f64) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() <= rel * a[k].abs().max(b[k].abs()))
}

/// A unit direction in the upper hemisphere from `log10(1/cos θ) ∈ [0, 6]`
/// (so cos θ reaches down to 1e-6: grazing) and an azimuth.
pub fn dir_grazing(zexp: f64, phi: f64) -> DVec3 {
    let z = 10f64.powf(-zexp);
    let s = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(s * phi.cos(), s * phi.sin(), z)
}

/// Strategy: an upper-hemisphere direction, half of them near grazing.
pub fn upper_dir() -> impl Strategy<Value = DVec3> {
    prop_oneof![
        (0.0..1.0f64, -PI..PI).prop_map(|(z, p)| {
            let z = z.max(1e-6);
            let s = (1.0 - z * z).sqrt();
            DVec3::new(s * p.cos(), s * p.sin(), z)
        }),
        (0.0..6.0f64, -PI..PI).prop_map(|(e, p)| dir_grazing(e, p)),
    ]
}

/// Checks finiteness and non-negativity of every channel.
pub fn finite_nonneg(f: Rgb) -> bool {
    f.is_finite() && f.min_element() >= 0.0
}
