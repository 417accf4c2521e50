//! Blinn-Phong cast as a BRDF:
//! `f = kd + ks · max(0, h·n)^e / cosθi`, `h = normalize(wi + wo)`.
//!
//! Blinn 1977, "Models of light reflection for computer synthesized pictures"
//! (the half-vector form of Phong's highlight, the one fixed-function OpenGL
//! implemented), divided by `cosθi` as in the lecture (seed, "Blinn-Phong").
//! It keeps classical Phong's flaws on purpose: `kd` not divided by π, the
//! `1/cosθi` breaks reciprocity (the lobe `(h·n)^e` itself is symmetric), and
//! the directional albedo is unbounded at grazing incidence.

use super::lobes::{COS_FLOOR, clamped_pow, half_vector};
use crate::batch::{Kernel, LaneKernel, LaneMask, Lanes, math};
use crate::model::{Build, GpuPort, ModelInfo};
use crate::params::decl::{Applies, ColorSpec, FloatSpec, ParamDecl, ParamKind};
use crate::params::value::Params;
use crate::{Brdf, Claims, Result, Rgb, frame, mean_rgb, sampling};
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// Parameter declaration (exponent 0..10000, log slider 1..1000).
pub const PARAMS: &[ParamDecl] = &[
    ParamDecl {
        id: "kd",
        label: "kd",
        doc: "Diffuse coefficient (not divided by π, as in the lecture: diffuse albedo is π·kd)",
        kind: ParamKind::Color(ColorSpec::unit_range([0.15, 0.15, 0.15])),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "ks",
        label: "ks",
        doc: "Specular coefficient",
        kind: ParamKind::Color(ColorSpec::unit_range([0.3, 0.3, 0.3])),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "e",
        label: "e",
        doc: "Blinn exponent on h·n (about 4× a Phong exponent for the same highlight)",
        kind: ParamKind::Float(FloatSpec::log(0.0, 10000.0, 20.0, 1.0, 1000.0)),
        applies: Applies::Always,
    },
];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "blinn-phong",
    name: "Blinn-Phong",
    summary: "Half-vector Phong as a BRDF: kd + ks (h·n)^e / cosθi; not reciprocal, not energy-conserving",
    citation: "Blinn 1977, \"Models of light reflection for computer synthesized pictures\"; BRDF form as in the lecture",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: Some(
        GpuPort::new(
            "bv::models::blinn_phong",
            "shaders/models/blinn_phong.wgsl",
            include_str!("../../../../shaders/models/blinn_phong.wgsl"),
        )
        .with_sampling_lobe(),
    ),
};

/// Blinn-Phong BRDF.
#[derive(Debug, Clone)]
pub struct BlinnPhong {
    kd: Rgb,
    ks: Rgb,
    e: f64,
    kernel: BlinnPhongLanes,
}

/// [`BlinnPhong`]'s f32 batch kernel: `kd + ks (h·n)^e / cosθi`, the lobe
/// from `1 − h·n = (vx² + vy²)/(|v| (|v| + vz))` with `v = wi + wo` (exact
/// algebra, no cancellation), so exponents up to 10⁴ stay accurate.
#[derive(Debug, Clone, Copy)]
struct BlinnPhongLanes {
    kd: [f32; 3],
    ks: [f32; 3],
    e: f32,
}

impl LaneKernel for BlinnPhongLanes {
    #[inline(always)]
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        let v = math::add3(wi, wo);
        let t2 = v[0] * v[0] + v[1] * v[1];
        let l = (t2 + v[2] * v[2]).sqrt();
        let y = t2 / (l * (l + v[2]));
        let lobe = math::pow_1m(v[2] / l, y, self.e);
        let spec = lobe / wi[2];
        let above = wi[2].gt(V::splat(0.0)) & wo[2].gt(V::splat(0.0));
        math::channels!(|c| above.select(spec * self.ks[c] + self.kd[c], V::splat(0.0)))
    }
}

impl BlinnPhong {
    /// A Blinn-Phong BRDF with the given coefficients and exponent.
    pub fn new(kd: Rgb, ks: Rgb, e: f64) -> Self {
        let kernel = BlinnPhongLanes {
            kd: math::rgb(kd),
            ks: math::rgb(ks),
            e: e as f32,
        };
        Self { kd, ks, e, kernel }
    }

    /// Selection weights (diffuse, specular) at `wi`. Diffuse: its albedo
    /// `π kd`. Specular: near normal incidence `h·n ≈ cos(θo/2)`, and
    /// `cos^e(θ/2) ≈ cos^{e/4} θ` for small θ, so the lobe is roughly a Phong
    /// lobe of exponent `e/4` with albedo `2π/(e/4 + 2)`, scaled by the `1/cosθi`
    /// of `f` (floored at 0.05). Only efficiency depends on these numbers.
    fn weights(&self, wi: DVec3) -> (f64, f64) {
        let d = PI * mean_rgb(self.kd);
        let s = mean_rgb(self.ks) * 2.0 * PI / ((self.e / 4.0 + 2.0) * wi.z.max(0.05));
        if d + s > 0.0 { (d, s) } else { (1.0, 0.0) }
    }

    /// Density of the specular strategy: `h` drawn with density
    /// `(e+1)/(2π) (h·n)^e` ([`sampling::power_cosine`] about `n`), then
    /// `wo = reflect(wi, h)`; the Jacobian `dωh/dωo = 1/(4 wi·h)` (Walter et
    /// al. 2007, eq. 14) turns it into a density over `wo`.
    fn specular_pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        let h = half_vector(wi, wo);
        let c = wi.dot(h);
        if c <= 0.0 {
            return 0.0;
        }
        // Floored like the cosine in `eval`: a subnormal wi·h would give ∞.
        sampling::power_cosine_pdf(DVec3::Z, self.e, h) / (4.0 * c.max(COS_FLOOR))
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    Ok(Box::new(BlinnPhong::new(
        p.color("kd")?,
        p.color("ks")?,
        p.float("e")?,
    )))
}

impl Brdf for BlinnPhong {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        let lobe = clamped_pow(half_vector(wi, wo).z, self.e);
        self.kd + self.ks * (lobe / wi.z.max(COS_FLOOR))
    }

    /// As for `phong`: reciprocal iff `ks = 0`; the albedo
    /// `π kd + ks/cosθi · ∫ (h·n)^e cosθo dωo` is unbounded as `θi → 90°` for
    /// any `ks > 0` (the integral tends to a positive limit: `h·n > 0` for
    /// every `wo` above the horizon), so energy is conserved iff `ks = 0` and
    /// `π kd ≤ 1`.
    fn batch_kernel(&self) -> Option<&dyn Kernel> {
        Some(&self.kernel)
    }

    fn claims(&self) -> Claims {
        let no_specular = self.ks.max_element() == 0.0;
        Claims {
            reciprocal: no_specular,
            energy_conserving: no_specular && self.kd.max_element() * PI <= 1.0,
            isotropic: true,
        }
    }

    fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        if wi.z <= 0.0 {
            return None;
        }
        let (d, s) = self.weights(wi);
        let t = u.x * (d + s);
        let wo = if t < d {
            sampling::cosine_hemisphere(DVec2::new((t / d).min(1.0 - f64::EPSILON), u.y))
        } else {
            let v = ((t - d) / s).clamp(0.0, 1.0 - f64::EPSILON);
            let h = sampling::power_cosine(DVec3::Z, self.e, DVec2::new(v, u.y));
            if wi.dot(h) <= 0.0 {
                return None;
            }
            frame::reflect_about(wi, h)
        };
        (wo.z > 0.0 && wo.is_finite()).then_some(wo)
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let (d, s) = self.weights(wi);
        let mut p = d * sampling::cosine_hemisphere_pdf(wo);
        if s > 0.0 {
            p += s * self.specular_pdf(wi, wo);
        }
        p / (d + s)
    }
}

#[cfg(test)]
mod tests {
    use super::super::lobes::testing::*;
    use super::*;
    use crate::frame::from_spherical;
    use proptest::prelude::*;
    use serde_json::json;

    fn model(kd: f64, ks: f64, e: f64) -> Box<dyn Brdf> {
        build_model("blinn-phong", json!({"kd": kd, "ks": ks, "e": e}))
    }

    #[test]
    fn mirror_direction_is_kd_plus_ks_over_cos() {
        // wo = R(wi) gives h = n, h·n = 1.
        let b = model(0.2, 0.6, 300.0);
        for theta in [0.0, 0.7, 1.5] {
            let wi = from_spherical(theta, 2.0);
            let f = b.eval(wi, frame::reflect(wi)).x;
            let want = 0.2 + 0.6 / theta.cos();
            assert!((f - want).abs() < 1e-12 * want, "{f} vs {want}");
        }
    }

    #[test]
    fn value_at_a_given_half_vector() {
        // wo = reflection of wi about a chosen h: f = kd + ks cos^e θh / cosθi.
        let (th, e) = (0.25f64, 12.0);
        let b = build_model(
            "blinn-phong",
            json!({"kd": [0.1, 0.0, 0.3], "ks": [0.4, 0.9, 0.0], "e": e}),
        );
        let h = from_spherical(th, 1.0);
        let wi = from_spherical(0.5, 0.3);
        let wo = frame::reflect_about(wi, h);
        assert!(wo.z > 0.0);
        let spec = th.cos().powf(e) / wi.z;
        let want = Rgb::new(0.1 + 0.4 * spec, 0.9 * spec, 0.3);
        assert!(rel_diff(b.eval(wi, wo), want) < 1e-12);
    }

    #[test]
    fn albedo_at_normal_incidence_e2() {
        // wi = n: h·n = cos(θo/2), cos²(θo/2) = (1 + cosθo)/2, so
        // ∫ f cosθo dω = π kd + ks 2π ∫₀¹ (1+μ)/2 μ dμ = π kd + ks 5π/6.
        let (kd, ks) = (0.1, 0.3);
        let a = albedo(&*model(kd, ks, 2.0), DVec3::Z, 2000, 16).x;
        let want = PI * kd + ks * 5.0 * PI / 6.0;
        assert!((a - want).abs() < 1e-5, "{a} vs {want}");
    }

    #[test]
    fn not_reciprocal_and_albedo_exceeds_one() {
        let b = model(0.0, 0.3, 20.0);
        let wi = from_spherical(0.1, 0.0);
        let wo = from_spherical(1.1, 2.5);
        let (a, r) = (b.eval(wi, wo).x, b.eval(wo, wi).x);
        // Same lobe, different 1/cos: the ratio is cosθo/cosθi.
        assert!(a > 0.0 && (a / r - wo.z / wi.z).abs() < 1e-12);
        assert!(!b.claims().reciprocal);
        // ρhd(0) ≈ 0.3·2π/(20/4 + 2) ≈ 0.27 (the lobe is narrow), but it grows
        // as 1/cosθi: 0.49 at 88°, above 1 at cosθi = 2e-3 (≈ 89.89°).
        let at0 = albedo(&*b, DVec3::Z, 600, 600).x;
        let at88 = albedo(&*b, from_spherical(88f64.to_radians(), 0.0), 800, 800).x;
        let zi = 2e-3f64;
        let grazing = DVec3::new((1.0 - zi * zi).sqrt(), 0.0, zi);
        let at_grazing = albedo(&*b, grazing, 1500, 1500).x;
        assert!(at0 < 0.5, "{at0}");
        assert!(at88 > at0 && at_grazing > 1.0, "{at88} {at_grazing}");
        // Between the two, ρhd·cosθi (the integral of the lobe alone) tends to
        // a positive limit (0.85× its value at 88°): the growth is the 1/cosθi.
        let ratio = (at_grazing * zi) / (at88 * 88f64.to_radians().cos());
        assert!(ratio > 0.7 && ratio < 1.0, "{ratio}");
        assert!(!b.claims().energy_conserving);
        // No specular part: constant kd, reciprocal, energy iff π kd ≤ 1.
        let d = model(0.3, 0.0, 20.0);
        assert!(d.claims().reciprocal && d.claims().energy_conserving);
        assert_eq!(d.eval(wi, wo), d.eval(wo, wi));
    }

    #[test]
    fn opposite_grazing_pair_is_finite() {
        // wi + wo is vertical and tiny: h = n exactly, f = kd + ks/cosθi.
        let b = model(0.1, 0.5, 10.0);
        let wi = DVec3::new(1.0, 0.0, 1e-120);
        let wo = DVec3::new(-1.0, 0.0, 1e-120);
        let f = b.eval(wi, wo).x;
        assert!((f - (0.1 + 0.5e120)).abs() < 1e-12 * f, "{f}");
        // Below COS_FLOOR the cosine is floored: still finite.
        let f = b.eval(DVec3::new(1.0, 0.0, 1e-320), DVec3::new(-1.0, 0.0, 1e-320));
        assert!(f.is_finite());
    }

    #[test]
    fn sampling_agrees_with_pdf() {
        for (theta, e) in [(0.0, 40.0), (0.9, 4.0), (1.4, 400.0)] {
            let b = model(0.15, 0.3, e);
            check_sampling(&*b, from_spherical(theta, 1.1));
        }
    }

    proptest! {
        #[test]
        fn finite_and_nonnegative(
            kd in colour(1.0), ks in colour(1.0), e in exponent(),
            wi in direction(), wo in direction(),
        ) {
            let b = build_model("blinn-phong", json!({"kd": kd, "ks": ks, "e": e}));
            assert_finite_nonneg(b.eval(wi, wo), "blinn-phong");
            assert_finite_nonneg(b.eval(wi, frame::reflect(wi)), "at mirror");
            let p = b.pdf(wi, wo);
            prop_assert!(p.is_finite() && p >= 0.0);
        }
    }
}
