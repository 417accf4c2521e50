//! Classical Phong cast as a BRDF:
//! `f = kd + ks · max(0, R(wo)·wi)^e / cosθi`.
//!
//! Phong's (1975, "Illumination for computer generated pictures") shading
//! rule `L = (kd cosθi + ks (R·wi)^e) Li` divided by the irradiance factor
//! `cosθi`, exactly as the lecture writes it (seed, "Classical Phong Model").
//! It is kept deliberately flawed, because showing the flaws is the point:
//! - `kd` is not divided by π, so the diffuse albedo is `π kd`;
//! - the `1/cosθi` makes it non-reciprocal (the lobe `(R(wo)·wi)^e` itself is
//!   symmetric, since `R(wo)·wi = R(wi)·wo`), and
//! - its directional albedo grows without bound at grazing incidence
//!   (Lewis 1994, "Making shaders more physically plausible", §2).

use super::lobes::{COS_FLOOR, Mixture, PowerLobe, clamped_pow};
use crate::batch::{Kernel, LaneKernel, LaneMask, Lanes, math};
use crate::model::{Build, GpuPort, ModelInfo};
use crate::params::decl::{Applies, ColorSpec, FloatSpec, ParamDecl, ParamKind};
use crate::params::value::Params;
use crate::{Brdf, Claims, Result, Rgb, frame, mean_rgb};
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// Parameter declaration. Exponent range 0..10000 ("Phong-family
/// exponents"), shown on a logarithmic slider over 1..1000.
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
        doc: "Phong exponent (sharpness of the highlight)",
        kind: ParamKind::Float(FloatSpec::log(0.0, 10000.0, 20.0, 1.0, 1000.0)),
        applies: Applies::Always,
    },
];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "phong",
    name: "Phong (classical)",
    summary: "Classical Phong as a BRDF: kd + ks (R(wo)·wi)^e / cosθi; not reciprocal, not energy-conserving",
    citation: "Phong 1975, \"Illumination for computer generated pictures\"; BRDF form as in the lecture; flaws: Lewis 1994",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: Some(
        GpuPort::new(
            "bv::models::phong",
            "shaders/models/phong.wgsl",
            include_str!("../../../../shaders/models/phong.wgsl"),
        )
        .with_sampling_lobe(),
    ),
};

/// Classical Phong BRDF.
#[derive(Debug, Clone)]
pub struct Phong {
    kd: Rgb,
    ks: Rgb,
    e: f64,
    kernel: PhongLanes,
}

/// [`Phong`]'s f32 batch kernel: `kd + ks (R(wo)·wi)^e / cosθi`, the lobe
/// by [`math::mirror_lobe`].
#[derive(Debug, Clone, Copy)]
struct PhongLanes {
    kd: [f32; 3],
    ks: [f32; 3],
    e: f32,
}

impl LaneKernel for PhongLanes {
    #[inline(always)]
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        let lobe = math::mirror_lobe(wi, wo, self.e);
        let spec = lobe / wi[2];
        let above = wi[2].gt(V::splat(0.0)) & wo[2].gt(V::splat(0.0));
        math::channels!(|c| above.select(spec * self.ks[c] + self.kd[c], V::splat(0.0)))
    }
}

impl Phong {
    /// A classical Phong BRDF with the given coefficients and exponent.
    pub fn new(kd: Rgb, ks: Rgb, e: f64) -> Self {
        let kernel = PhongLanes {
            kd: math::rgb(kd),
            ks: math::rgb(ks),
            e: e as f32,
        };
        Self { kd, ks, e, kernel }
    }

    /// Sampling mixture at `wi`: cosine sampling for `kd`, a power-cosine lobe
    /// about `R(wi)` for the specular part (its shape in `wo`, since
    /// `R(wo)·wi = R(wi)·wo`). Selection weights are the parts' albedos at
    /// normal incidence (`π kd` and `2π ks/(e+2)`), the specular one scaled
    /// by the `1/cosθi` of `f` (floored at 0.05 so the diffuse part is still
    /// drawn at grazing incidence). Only efficiency depends on them.
    fn lobe(&self, wi: DVec3) -> [PowerLobe; 1] {
        [PowerLobe {
            axis: frame::reflect(wi),
            e: self.e,
            weight: mean_rgb(self.ks) * 2.0 * PI / ((self.e + 2.0) * wi.z.max(0.05)),
        }]
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    Ok(Box::new(Phong::new(
        p.color("kd")?,
        p.color("ks")?,
        p.float("e")?,
    )))
}

impl Brdf for Phong {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        let lobe = clamped_pow(frame::reflect(wo).dot(wi), self.e);
        self.kd + self.ks * (lobe / wi.z.max(COS_FLOOR))
    }

    /// Reciprocal only without a specular part (then `f = kd`): for `ks > 0`
    /// `f(wi,wo) − f(wo,wi) = ks lobe (1/cosθi − 1/cosθo) ≠ 0`. Energy:
    /// `ρhd(θi) = π kd + ks/cosθi · ∫ lobe cosθo dωo`, and as `θi → 90°` the
    /// integral tends to a positive limit (the lobe about the grazing `R(wi)`
    /// still covers directions above the horizon) while `1/cosθi → ∞`: every
    /// `ks > 0` exceeds 1 near grazing. So it conserves energy iff `ks = 0`
    /// and `π kd ≤ 1`.
    /// The lobe depends on `wo` through `R(wo)·wi = wo·R(wi)` alone, the
    /// cosine of the angle from the mirror direction, so `f` is constant on
    /// every ring about `R(wi)`: the albedo quadrature integrates in polar
    /// coordinates about it, where over the half vector the lobe is an
    /// ellipse that narrows towards grazing.
    fn pole(&self, wi: DVec3) -> Option<DVec3> {
        Some(frame::reflect(wi))
    }

    /// The clamp `max(0, R(wo)·wi)` switches branch 90° from the mirror
    /// direction (a kink for exponents near 1 or below).
    fn kinks(&self, wi: DVec3) -> Vec<crate::Kink<'_>> {
        let r = frame::reflect(wi);
        vec![Box::new(move |wo: DVec3| wo.dot(r))]
    }

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
        let lobes = self.lobe(wi);
        Mixture {
            diffuse: PI * mean_rgb(self.kd),
            lobes: &lobes,
        }
        .sample(u)
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 {
            return 0.0;
        }
        let lobes = self.lobe(wi);
        Mixture {
            diffuse: PI * mean_rgb(self.kd),
            lobes: &lobes,
        }
        .pdf(wo)
    }
}

#[cfg(test)]
mod tests {
    use super::super::lobes::testing::*;
    use super::*;
    use crate::frame::from_spherical;
    use proptest::prelude::*;
    use serde_json::json;

    fn phong(kd: f64, ks: f64, e: f64) -> Box<dyn Brdf> {
        build_model("phong", json!({"kd": kd, "ks": ks, "e": e}))
    }

    #[test]
    fn mirror_direction_is_kd_plus_ks_over_cos() {
        // At wo = R(wi), R(wo)·wi = 1 for every e: f = kd + ks / cosθi.
        let b = phong(0.2, 0.7, 35.0);
        for theta in [0.0, 0.4, 1.2, 1.5] {
            let wi = from_spherical(theta, 0.8);
            let f = b.eval(wi, frame::reflect(wi));
            let want = 0.2 + 0.7 / theta.cos();
            assert!(
                (f.x - want).abs() < 1e-12 * want,
                "θ {theta}: {f} vs {want}"
            );
        }
    }

    #[test]
    fn off_mirror_value_follows_cos_power() {
        // In the plane of incidence, wo at angle β beyond R(wi) has
        // R(wo)·wi = cos β: f = kd + ks cos^e β / cosθi.
        let (theta, beta, e) = (0.5f64, 0.3f64, 7.0);
        let b = build_model(
            "phong",
            json!({"kd": [0.1, 0.2, 0.3], "ks": [0.5, 0.4, 0.0], "e": e}),
        );
        let wi = from_spherical(theta, 0.0);
        let wo = from_spherical(theta + beta, PI);
        let spec = beta.cos().powf(e) / theta.cos();
        let want = Rgb::new(0.1 + 0.5 * spec, 0.2 + 0.4 * spec, 0.3);
        assert!(rel_diff(b.eval(wi, wo), want) < 1e-12);
    }

    #[test]
    fn exponent_zero_is_the_hemisphere_indicator() {
        // Decision documented on `clamped_pow`: with e = 0 the lobe is 1 where
        // R(wo)·wi > 0 and 0 where it is ≤ 0, including exactly 0.
        let b = phong(0.1, 0.5, 0.0);
        let wi = DVec3::new(0.6, 0.0, 0.8);
        // R(wo)·wi = −0.8·0.6 + 0.6·0.8 = 0 exactly.
        let f = b.eval(wi, DVec3::new(0.8, 0.0, 0.6));
        assert_eq!(f.x, 0.1);
        let f = b.eval(wi, DVec3::new(0.0, 0.6, 0.8));
        assert!((f.x - (0.1 + 0.5 / 0.8)).abs() < 1e-15);
        let f = b.eval(wi, DVec3::new(0.96, 0.0, 0.28));
        assert_eq!(f.x, 0.1);
    }

    #[test]
    fn below_horizon_is_zero() {
        let b = phong(0.5, 0.5, 10.0);
        let up = from_spherical(0.3, 0.0);
        let down = DVec3::new(0.6, 0.0, -0.8);
        assert_eq!(b.eval(up, down), Rgb::ZERO);
        assert_eq!(b.eval(down, up), Rgb::ZERO);
        assert_eq!(b.eval(DVec3::X, up), Rgb::ZERO);
    }

    #[test]
    fn not_reciprocal_with_specular_part() {
        // Specular parts only: f(wi,wo)/f(wo,wi) = cosθo/cosθi.
        let b = phong(0.0, 0.5, 4.0);
        let wi = from_spherical(0.2, 0.0);
        let wo = from_spherical(1.0, 2.8);
        let (a, r) = (b.eval(wi, wo).x, b.eval(wo, wi).x);
        assert!(a > 0.0);
        assert!((a / r - wo.z / wi.z).abs() < 1e-12);
        assert!((a - r).abs() > 0.1 * a);
        assert!(!b.claims().reciprocal);
        // Without specular part it is the constant kd: reciprocal, and claimed so.
        let d = phong(0.3, 0.0, 4.0);
        assert_eq!(d.eval(wi, wo), d.eval(wo, wi));
        assert!(d.claims().reciprocal);
    }

    #[test]
    fn albedo_matches_closed_form_for_e1_and_exceeds_one() {
        // e = 1: ρhd(θi) = π kd + ks/cosθi · ∫ max(0, R(wi)·w) cosθo dω, and the
        // overlap of two clamped cosines at angle θi is (2/3)(sinθ + (π−θ)cosθ).
        let (kd, ks) = (0.05, 0.5);
        let b = phong(kd, ks, 1.0);
        let mut max = 0.0f64;
        for deg in [0.0f64, 30.0, 60.0, 80.0, 85.0] {
            let t = deg.to_radians();
            let want = PI * kd + ks * (2.0 / 3.0) * (t.sin() + (PI - t) * t.cos()) / t.cos();
            let got = albedo(&*b, from_spherical(t, 0.3), 600, 600).x;
            assert!((got - want).abs() < 1e-3 * want, "θ {deg}: {got} vs {want}");
            max = max.max(got);
        }
        // 0.157 + 0.5·2π/3 = 1.20 at normal incidence already, and growing as
        // 1/cosθi (3.9 at 85°).
        assert!(max > 1.0, "{max}");
        assert!(!b.claims().energy_conserving);
        // Even a dim, sharp highlight exceeds 1 close enough to grazing:
        // ks = 0.1, e = 50 gives ρhd ≈ 0.084 at 89.5° but > 1 at cosθi = 1e-4.
        let dim = phong(0.0, 0.1, 50.0);
        let zi = 1e-4f64;
        let wi = DVec3::new((1.0 - zi * zi).sqrt(), 0.0, zi);
        let a = albedo(&*dim, wi, 1500, 1500).x;
        assert!(a > 1.0, "{a}");
        assert!(!dim.claims().energy_conserving);
    }

    #[test]
    fn diffuse_only_energy_claim() {
        // ks = 0: f = kd, ρhd = π kd at every angle; claimed iff π kd ≤ 1.
        let ok = phong(0.3, 0.0, 10.0);
        assert!(ok.claims().energy_conserving);
        let a = albedo(&*ok, from_spherical(1.3, 0.0), 200, 64).x;
        assert!((a - 0.3 * PI).abs() < 1e-4 && a <= 1.0);
        let bright = phong(0.33, 0.0, 10.0);
        assert!(!bright.claims().energy_conserving);
        assert!(albedo(&*bright, DVec3::Z, 200, 64).x > 1.0);
    }

    #[test]
    fn subnormal_cosine_stays_finite() {
        let b = phong(1.0, 1.0, 0.0);
        let wi = DVec3::new(1.0, 0.0, 1e-310);
        let f = b.eval(wi, frame::reflect(wi));
        assert!(f.is_finite() && f.x > 1e149, "{f}");
    }

    #[test]
    fn sampling_agrees_with_pdf() {
        for (theta, e) in [(0.0, 20.0), (0.7, 5.0), (1.3, 100.0)] {
            let b = phong(0.15, 0.3, e);
            check_sampling(&*b, from_spherical(theta, 0.4));
        }
    }

    #[test]
    fn default_claims() {
        let b = build_model("phong", json!({}));
        assert_eq!(
            b.claims(),
            Claims {
                reciprocal: false,
                energy_conserving: false,
                isotropic: true
            }
        );
    }

    proptest! {
        #[test]
        fn finite_and_nonnegative(
            kd in colour(1.0), ks in colour(1.0), e in exponent(),
            wi in direction(), wo in direction(),
        ) {
            let b = build_model("phong", json!({"kd": kd, "ks": ks, "e": e}));
            assert_finite_nonneg(b.eval(wi, wo), "phong");
            assert_finite_nonneg(b.eval(wi, frame::reflect(wi)), "phong at mirror");
            let p = b.pdf(wi, wo);
            prop_assert!(p.is_finite() && p >= 0.0);
        }
    }
}
