//! Machinery shared by the cosine-lobe models (`phong`, `blinn-phong`,
//! `modified-phong`, `lafortune`, `banks`, `ward`): the clamped power of a lobe,
//! the grazing-angle floor, a half vector that cannot underflow, and the
//! "diffuse + power-cosine lobes" sampling mixture.
//!
//! # A lemma the energy claims rest on
//!
//! For unit `r` and `n`, and `e ≥ 0`,
//! `∫_{S²} max(0, r·w)^e · max(0, n·w) dω ≤ 2π/(e+2)`, with equality when `r = n`.
//!
//! Proof. Both factors are non-increasing functions of the angle to their
//! own axis, so their super-level sets `A_s = {(r·w)₊^e > s}` and
//! `B_t = {(n·w)₊ > t}` are spherical caps centred on `r` and `n`. By the
//! layer-cake representation `g(w) = ∫₀^∞ 1[g(w) > s] ds`,
//! `∫ g h dω = ∫₀^∞∫₀^∞ |A_s ∩ B_t| ds dt ≤ ∫∫ min(|A_s|, |B_t|) ds dt`.
//! Cap areas do not depend on where the cap is centred, and when `r = n` the
//! caps are concentric, hence nested, so `|A_s ∩ B_t| = min(|A_s|, |B_t|)`:
//! the bound is attained at `r = n`. There the integral is the one of
//! `cos^{e+1} θ` over the hemisphere, `2π ∫₀¹ μ^{e+1} dμ = 2π/(e+2)`. ∎
//!
//! This is the step behind "the normalised Phong lobe `(e+2)/(2π) cos^e` reflects
//! at most all of the light" (Lafortune & Willems 1994, §3; Lewis 1994).

use crate::sampling;
use glam::{DVec2, DVec3};

/// Smallest cosine a model divides by. Every unit direction with `z` at or
/// above it is evaluated by the exact formula; below it (sub-`1e-150`
/// cosines, down to subnormals) the cosine is replaced by the floor so that
/// `1/cosθ` stays finite: `ks / 1e-150` and Ward's `1/(4π αx αy · 1e-150)`
/// are far from `f64::MAX`.
pub const COS_FLOOR: f64 = 1e-150;

/// The lobe `max(0, x)^e`.
///
/// Decision for `e = 0` (the formula leaves it open): the lobe is 0 wherever
/// `x ≤ 0`, for every `e`, including `x = 0` exactly. So `e = 0` gives the
/// indicator of the open hemisphere around the lobe axis rather than the
/// `0⁰ = 1` of `powf`; this is the limit of `x^e` as `e → 0⁺` at `x = 0`,
/// and the boundary has measure zero, so no integral depends on it.
///
/// `x` is clamped to 1: in every use `x` is a dot product of unit vectors
/// (or bounded by one, Cauchy–Schwarz), and the clamp only removes rounding
/// above 1 that `x^10000` would amplify.
#[inline]
pub fn clamped_pow(x: f64, e: f64) -> f64 {
    if x > 0.0 { x.min(1.0).powf(e) } else { 0.0 }
}

/// `wi + wo` scaled so that its largest component has magnitude 1: its
/// direction is the half vector's, and nothing underflows even for
/// near-opposite grazing directions (where `|wi + wo|` can be ~1e-300).
/// Returns `+z` when `wi + wo` is exactly zero (impossible for two directions
/// above the horizon).
#[inline]
pub fn half_unnormalised(wi: DVec3, wo: DVec3) -> DVec3 {
    let v = wi + wo;
    let m = v.abs().max_element();
    if m > 0.0 && m.is_finite() {
        v / m
    } else {
        DVec3::Z
    }
}

/// Unit half vector `normalize(wi + wo)` without underflow (see
/// [`half_unnormalised`]).
#[inline]
pub fn half_vector(wi: DVec3, wo: DVec3) -> DVec3 {
    half_unnormalised(wi, wo).normalize()
}

/// One power-cosine lobe of a sampling [`Mixture`]: density
/// `(e+1)/(2π) · max(0, axis·w)^e` ([`sampling::power_cosine`]).
#[derive(Debug, Clone, Copy)]
pub struct PowerLobe {
    /// Unit lobe axis.
    pub axis: DVec3,
    /// Exponent.
    pub e: f64,
    /// Unnormalised selection weight (≥ 0).
    pub weight: f64,
}

/// Largest `f64` below 1, so that a rescaled uniform stays in `[0, 1)`.
const ONE_MINUS_EPS: f64 = 1.0 - f64::EPSILON / 2.0;

/// Sampling mixture of a cosine-weighted hemisphere (for the diffuse part) and
/// power-cosine lobes (for the specular ones). Samples that land below the
/// horizon are refused (`None`): the density returned by [`Mixture::pdf`] is
/// that of the accepted directions, so it integrates to the acceptance
/// probability, and `E[g(wo)/pdf(wo)]` over accepted samples (refusals counting
/// 0) is exactly `∫ g` over the upper hemisphere wherever `pdf > 0`.
#[derive(Debug, Clone, Copy)]
pub struct Mixture<'a> {
    /// Weight of cosine-weighted sampling.
    pub diffuse: f64,
    /// The lobes.
    pub lobes: &'a [PowerLobe],
}

/// A weight usable for selection: finite and non-negative, else 0.
#[inline]
fn usable(w: f64) -> f64 {
    if w.is_finite() && w > 0.0 { w } else { 0.0 }
}

impl Mixture<'_> {
    /// Weights (diffuse, total), with a cosine-only fallback when every weight is 0.
    fn weights(&self) -> (f64, f64) {
        let d = usable(self.diffuse);
        let total = d + self.lobes.iter().map(|l| usable(l.weight)).sum::<f64>();
        if total > 0.0 && total.is_finite() {
            (d, total)
        } else {
            (1.0, 1.0)
        }
    }

    /// Draws a direction: `u.x` picks the component (and is rescaled to a
    /// fresh uniform), `u.y` and the rescaled `u.x` drive its warp.
    pub fn sample(&self, u: DVec2) -> Option<DVec3> {
        let (d, total) = self.weights();
        let mut t = u.x * total;
        let rescale = |t: f64, w: f64| (t / w).clamp(0.0, ONE_MINUS_EPS);
        let wo = if t < d || d == total {
            sampling::cosine_hemisphere(DVec2::new(rescale(t, d), u.y))
        } else {
            t -= d;
            // Last lobe with a usable weight catches rounding at the top end.
            let mut chosen = None;
            for l in self.lobes {
                let w = usable(l.weight);
                if w == 0.0 {
                    continue;
                }
                chosen = Some((l, t.min(w)));
                if t < w {
                    break;
                }
                t -= w;
            }
            let (l, t) = chosen?;
            sampling::power_cosine(l.axis, l.e, DVec2::new(rescale(t, usable(l.weight)), u.y))
        };
        (wo.z > 0.0 && wo.is_finite()).then_some(wo)
    }

    /// Solid-angle density of [`Mixture::sample`] at `wo`.
    pub fn pdf(&self, wo: DVec3) -> f64 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        let (d, total) = self.weights();
        let mut p = d * sampling::cosine_hemisphere_pdf(wo);
        if d < total {
            for l in self.lobes {
                let w = usable(l.weight);
                if w > 0.0 {
                    p += w * sampling::power_cosine_pdf(l.axis, l.e, wo);
                }
            }
        }
        p / total
    }
}

/// Test helpers shared by the models' unit tests: quadrature of the directional
/// albedo and of the sampling density, Monte Carlo checks of `sample`/`pdf`, and
/// proptest strategies.
#[cfg(test)]
pub mod testing {
    use crate::{Brdf, ModelSpec, Rgb, sampling};
    use glam::DVec3;
    use proptest::prelude::*;
    use std::f64::consts::PI;

    /// Builds model `id` from JSON parameters.
    pub fn build_model(id: &str, params: serde_json::Value) -> Box<dyn Brdf> {
        ModelSpec::from_json(id, &params).unwrap().build().unwrap()
    }

    /// `∫ h(wo) dωo` over the upper hemisphere by the midpoint rule in
    /// `(s, φ)` with `cosθo = s²` (`dω = 2s ds dφ`), which resolves grazing
    /// directions finely and removes the `√cosθo` kink of Ward's integrand.
    pub fn hemisphere_quad<F: FnMut(DVec3) -> Rgb>(n_s: usize, n_phi: usize, mut h: F) -> Rgb {
        let mut sum = Rgb::ZERO;
        for i in 0..n_s {
            let s = (i as f64 + 0.5) / n_s as f64;
            let mu = s * s;
            let st = (1.0 - mu * mu).max(0.0).sqrt();
            for j in 0..n_phi {
                let phi = 2.0 * PI * (j as f64 + 0.5) / n_phi as f64;
                let w = DVec3::new(st * phi.cos(), st * phi.sin(), mu);
                sum += h(w) * (2.0 * s);
            }
        }
        sum * (2.0 * PI / (n_s * n_phi) as f64)
    }

    /// Directional albedo `ρhd(wi) = ∫ f(wi, wo) cosθo dωo` by quadrature.
    pub fn albedo(b: &dyn Brdf, wi: DVec3, n_s: usize, n_phi: usize) -> Rgb {
        hemisphere_quad(n_s, n_phi, |wo| b.eval(wi, wo) * wo.z)
    }

    /// `∫ pdf(wi, wo) dωo` over the upper hemisphere by quadrature.
    pub fn pdf_integral(b: &dyn Brdf, wi: DVec3, n_s: usize, n_phi: usize) -> f64 {
        hemisphere_quad(n_s, n_phi, |wo| Rgb::splat(b.pdf(wi, wo))).x
    }

    /// Result of [`monte_carlo`]: estimates with their standard errors.
    #[derive(Debug, Clone, Copy)]
    pub struct McResult {
        /// `E[g/pdf]` for `g(w) = cosθ (1 + w.x)²`.
        pub g: f64,
        /// Standard error of `g`.
        pub g_se: f64,
        /// `E[f cosθo/pdf]`, mean channel: the directional albedo.
        pub albedo: f64,
        /// Standard error of `albedo`.
        pub albedo_se: f64,
        /// Fraction of draws that returned a direction.
        pub accepted: f64,
    }

    /// Monte Carlo over `b.sample` with `n` draws, refused samples counting 0,
    /// for the smooth `g(w) = cosθ (1 + w.x)²` whose integral over the upper
    /// hemisphere is [`SMOOTH_INTEGRAL`] and for `f cosθo`. Also asserts that
    /// every drawn direction is a unit vector above the horizon with a positive
    /// density.
    pub fn monte_carlo(b: &dyn Brdf, wi: DVec3, n: usize, seed: u64) -> McResult {
        let mut rng = sampling::rng(seed);
        let (mut g1, mut g2, mut f1, mut f2, mut accepted) = (0.0, 0.0, 0.0, 0.0, 0usize);
        for _ in 0..n {
            let Some(wo) = b.sample(wi, sampling::uniform2(&mut rng)) else {
                continue;
            };
            assert!((wo.length() - 1.0).abs() < 1e-9 && wo.z > 0.0, "{wo}");
            let p = b.pdf(wi, wo);
            assert!(p > 0.0 && p.is_finite(), "pdf {p} at sampled {wo}");
            accepted += 1;
            let g = wo.z * (1.0 + wo.x).powi(2) / p;
            let f = crate::mean_rgb(b.eval(wi, wo)) * wo.z / p;
            g1 += g;
            g2 += g * g;
            f1 += f;
            f2 += f * f;
        }
        let n = n as f64;
        let se = |s1: f64, s2: f64| ((s2 / n - (s1 / n).powi(2)).max(0.0) / (n - 1.0)).sqrt();
        McResult {
            g: g1 / n,
            g_se: se(g1, g2),
            albedo: f1 / n,
            albedo_se: se(f1, f2),
            accepted: accepted as f64 / n,
        }
    }

    /// `∫ cosθ (1 + w.x)² dω` over the upper hemisphere: `π` from the 1, 0 from
    /// the odd `2x`, and `∫ cosθ sin²θ cos²φ dω = π/4` from `x²`.
    pub const SMOOTH_INTEGRAL: f64 = 5.0 * PI / 4.0;

    /// Checks `sample`/`pdf` agreement at `wi` for a model whose density is
    /// positive on the whole upper hemisphere (a diffuse part is present), with
    /// 200 000 draws: `E[g/pdf] = ∫ g` within 5 standard errors; `∫ pdf` by
    /// quadrature equals the accepted fraction within 5 binomial standard
    /// errors (+ 2e-3 for the quadrature); `E[f cos/pdf]` equals the
    /// quadrature albedo within 5 standard errors (+ 0.2 % for the quadrature).
    pub fn check_sampling(b: &dyn Brdf, wi: DVec3) {
        let n = 200_000;
        let mc = monte_carlo(b, wi, n, 0x5eed);
        assert!(
            (mc.g - SMOOTH_INTEGRAL).abs() < 5.0 * mc.g_se,
            "{}: E[g/pdf] = {} ± {}, want {SMOOTH_INTEGRAL} (wi = {wi})",
            b.id(),
            mc.g,
            mc.g_se
        );
        let p_int = pdf_integral(b, wi, 800, 800);
        let acc_se = (mc.accepted * (1.0 - mc.accepted) / n as f64).sqrt();
        assert!(
            (p_int - mc.accepted).abs() < 5.0 * acc_se + 2e-3,
            "{}: ∫pdf = {p_int}, accepted fraction = {} (wi = {wi})",
            b.id(),
            mc.accepted
        );
        let a = crate::mean_rgb(albedo(b, wi, 800, 800));
        assert!(
            (mc.albedo - a).abs() < 5.0 * mc.albedo_se + 2e-3 * a,
            "{}: E[f cos/pdf] = {} ± {}, quadrature albedo = {a} (wi = {wi})",
            b.id(),
            mc.albedo,
            mc.albedo_se
        );
        // The sampler must also be useful: its standard error is a small
        // fraction of the albedo (it follows f cos, not just covers it).
        assert!(
            mc.albedo_se < 0.01 * a,
            "{}: se {} of {a}",
            b.id(),
            mc.albedo_se
        );
    }

    /// Relative difference of two colours (max over channels, scale of the larger).
    pub fn rel_diff(a: Rgb, b: Rgb) -> f64 {
        let scale = a.abs().max(b.abs()).max_element();
        if scale == 0.0 {
            0.0
        } else {
            (a - b).abs().max_element() / scale
        }
    }

    /// A unit direction above the horizon with `cosθ` log-uniform in
    /// `[1e-6, 1]` half of the time (grazing) and uniform otherwise.
    pub fn direction() -> impl Strategy<Value = DVec3> {
        (0.0..1.0f64, 0.0..(2.0 * PI), any::<bool>()).prop_map(|(u, phi, grazing)| {
            let z = if grazing {
                10f64.powf(-6.0 * u)
            } else {
                u.max(1e-6)
            };
            let r = (1.0 - z * z).max(0.0).sqrt();
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        })
    }

    /// An exponent in `0..=10000`: log-uniform over `[1e-3, 1e4]`, with the
    /// ends 0 and 10000 themselves drawn often.
    pub fn exponent() -> impl Strategy<Value = f64> {
        prop_oneof![
            1 => Just(0.0),
            1 => Just(10000.0),
            6 => (-3.0..4.0f64).prop_map(|t| 10f64.powf(t)),
        ]
    }

    /// A colour with channels in `0..=max` (0 and `max` drawn often).
    pub fn colour(max: f64) -> impl Strategy<Value = [f64; 3]> {
        let ch = prop_oneof![1 => Just(0.0), 1 => Just(max), 4 => 0.0..=max];
        [ch.clone(), ch.clone(), ch]
    }

    /// Asserts every channel finite and non-negative.
    pub fn assert_finite_nonneg(f: Rgb, what: &str) {
        assert!(f.is_finite() && f.min_element() >= 0.0, "{what}: f = {f}");
    }
}

#[cfg(test)]
mod tests {
    use super::testing::*;
    use super::*;
    use crate::Rgb;
    use std::f64::consts::PI;

    #[test]
    fn clamped_pow_conventions() {
        assert_eq!(clamped_pow(0.5, 2.0), 0.25);
        assert_eq!(clamped_pow(0.5, 0.0), 1.0);
        assert_eq!(clamped_pow(0.0, 0.0), 0.0);
        assert_eq!(clamped_pow(-0.3, 0.0), 0.0);
        assert_eq!(clamped_pow(-0.3, 3.0), 0.0);
        assert_eq!(clamped_pow(1.0 + 1e-15, 1e4), 1.0);
    }

    #[test]
    fn half_vector_survives_opposite_grazing_pair() {
        // |wi + wo| = 2e-300: a naive normalisation underflows to 0/0.
        let wi = DVec3::new(1.0, 0.0, 1e-300);
        let wo = DVec3::new(-1.0, 0.0, 1e-300);
        assert_eq!(half_vector(wi, wo), DVec3::Z);
        let h = half_vector(DVec3::new(0.6, 0.0, 0.8), DVec3::new(-0.6, 0.0, 0.8));
        assert!((h - DVec3::Z).length() < 1e-15);
    }

    #[test]
    fn lemma_bound_holds_and_is_attained_on_axis() {
        // ∫ max(0, r·w)^e max(0, n·w) dω ≤ 2π/(e+2), = at r = n: quadrature over
        // the upper hemisphere (where n·w > 0) for a few tilts and exponents.
        for e in [0.0, 1.0, 4.0, 20.0] {
            let bound = 2.0 * PI / (e + 2.0);
            for tilt in [0.0f64, 0.3, 0.8, 1.3, PI / 2.0] {
                let r = DVec3::new(tilt.sin(), 0.0, tilt.cos());
                let i =
                    hemisphere_quad(1000, 400, |w| Rgb::splat(clamped_pow(r.dot(w), e) * w.z)).x;
                if tilt == 0.0 {
                    assert!((i - bound).abs() < 2e-3 * bound, "e {e}: {i} vs {bound}");
                } else {
                    assert!(i < bound, "e {e} tilt {tilt}: {i} > {bound}");
                }
            }
        }
        // e = 1 has a closed form (overlap of two clamped cosines at angle γ):
        // (2/3)(sin γ + (π − γ) cos γ).
        let g = 0.9f64;
        let r = DVec3::new(g.sin(), 0.0, g.cos());
        let i = hemisphere_quad(1000, 400, |w| Rgb::splat(clamped_pow(r.dot(w), 1.0) * w.z)).x;
        let exact = 2.0 / 3.0 * (g.sin() + (PI - g) * g.cos());
        assert!((i - exact).abs() < 1e-4, "{i} vs {exact}");
    }

    #[test]
    fn mixture_pdf_matches_sampler() {
        let axis = DVec3::new(0.5, -0.3, 0.7).normalize();
        let lobes = [
            PowerLobe {
                axis,
                e: 8.0,
                weight: 2.0,
            },
            PowerLobe {
                axis: DVec3::Z,
                e: 0.0,
                weight: 0.0,
            },
            PowerLobe {
                axis: DVec3::new(-0.9, 0.0, 0.3).normalize(),
                e: 30.0,
                weight: 1.0,
            },
        ];
        let m = Mixture {
            diffuse: 0.5,
            lobes: &lobes,
        };
        let mut rng = crate::sampling::rng(3);
        let n = 200_000;
        let (mut sum, mut acc) = (0.0, 0usize);
        for _ in 0..n {
            if let Some(w) = m.sample(crate::sampling::uniform2(&mut rng)) {
                acc += 1;
                sum += w.z * (1.0 + w.x).powi(2) / m.pdf(w);
            }
        }
        let est = sum / n as f64;
        assert!(
            (est - SMOOTH_INTEGRAL).abs() < 0.02 * SMOOTH_INTEGRAL,
            "{est}"
        );
        let p_int = hemisphere_quad(800, 800, |w| Rgb::splat(m.pdf(w))).x;
        assert!(
            (p_int - acc as f64 / n as f64).abs() < 0.01,
            "{p_int} {acc}"
        );
        // All weights zero: cosine sampling, never refused.
        let none = Mixture {
            diffuse: 0.0,
            lobes: &[],
        };
        let w = none.sample(DVec2::new(0.3, 0.6)).unwrap();
        assert!((none.pdf(w) - w.z / PI).abs() < 1e-15);
    }
}
