//! Banks' anisotropic fibre model, fibre along the tangent
//! `t = +x`:
//! `f = kd · √(1 − (wi·t)²) + ks · max(0, √(1 − (wi·t)²) √(1 − (wo·t)²) − (wi·t)(wo·t))^e`.
//!
//! Banks 1994, "Illumination in diverse codimensions" (SIGGRAPH '94), §4: a
//! fibre has no single normal, so the diffuse term uses the normal in the plane
//! of `t` and `wi` (`n·wi = sin αi`, αi the angle between `wi` and `t`), and
//! the specular term the cosine between `wo` and the reflection cone:
//! with `cos α = w·t`, the base is `sin αi sin αo − cos αi cos αo = −cos(αi + αo)`,
//! 1 when `wo` lies on the cone `αo = π − αi` of mirror directions about the
//! fibre. The BRDF form (both terms as given, no cosine division, Banks'
//! self-shadowing absorbed into the diffuse `sin αi`) is the one the lecture
//! shows as the anisotropic counterpart of Phong. Like Phong's, it is not
//! reciprocal: the diffuse part depends on `wi` only.

use super::lobes::clamped_pow;
use crate::batch::{Kernel, LaneKernel, LaneMask, Lanes, WideLanes, math};
use crate::model::{Build, GpuPort, ModelInfo};
use crate::params::decl::{Applies, ColorSpec, FloatSpec, ParamDecl, ParamKind};
use crate::params::value::Params;
use crate::{Brdf, Claims, Result, Rgb, mean_rgb, sampling};
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// Parameter declaration (exponent 0..10000, log slider 1..1000).
pub const PARAMS: &[ParamDecl] = &[
    ParamDecl {
        id: "kd",
        label: "kd",
        doc: "Diffuse coefficient (not divided by π, as in Banks' shading rule)",
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
        doc: "Exponent of the specular cone around the fibre (tangent x)",
        kind: ParamKind::Float(FloatSpec::log(0.0, 10000.0, 20.0, 1.0, 1000.0)),
        applies: Applies::Always,
    },
];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "banks",
    name: "Banks (anisotropic fibres)",
    summary: "Fibres along the tangent x: kd sin αi + ks (sin αi sin αo − cos αi cos αo)^e; anisotropic, not reciprocal",
    citation: "Banks 1994, \"Illumination in diverse codimensions\", §4",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: Some(GpuPort::new(
        "bv::models::banks",
        "shaders/models/banks.wgsl",
        include_str!("../../../../shaders/models/banks.wgsl"),
    )),
};

/// Banks fibre BRDF.
#[derive(Debug, Clone)]
pub struct Banks {
    kd: Rgb,
    ks: Rgb,
    e: f64,
    kernel: BanksLanes,
}

/// [`Banks`]'s f32 batch kernel: `kd sin αi + ks clamped_pow(sin αi sin αo −
/// cos αi cos αo, e)`. The lobe's base is formed in f64 and the power taken
/// from `1 − base` ([`math::pow_1m`]): with exponents up to 10⁴ an f32 base's
/// rounding alone would move the peak by 10⁻³.
#[derive(Debug, Clone, Copy)]
struct BanksLanes {
    kd: [f32; 3],
    ks: [f32; 3],
    e: f32,
}

impl LaneKernel for BanksLanes {
    #[inline(always)]
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        let [ix, iy, iz] = math::widen3(wi);
        let [ox, oy, oz] = math::widen3(wo);
        let one = V::Wide::splat(1.0);
        let si = (iy * iy + iz * iz).sqrt().min(one);
        let so = (oy * oy + oz * oz).sqrt().min(one);
        let x = si * so - ix * ox;
        let lobe = math::pow_1m(V::narrow(x), V::narrow(x.one_minus()), self.e);
        let si = V::narrow(si);
        let above = wi[2].gt(V::splat(0.0)) & wo[2].gt(V::splat(0.0));
        math::channels!(|c| above.select(si * self.kd[c] + lobe * self.ks[c], V::splat(0.0)))
    }
}

/// `sin α = √(1 − (w·t)²)` for `t = +x`, computed as `√(y² + z²)` (accurate
/// when `w` is close to the fibre), at most 1.
#[inline]
fn sin_to_fibre(w: DVec3) -> f64 {
    (w.y * w.y + w.z * w.z).sqrt().min(1.0)
}

impl Banks {
    /// A Banks BRDF with the given coefficients and exponent.
    pub fn new(kd: Rgb, ks: Rgb, e: f64) -> Self {
        Self {
            kd,
            ks,
            e,
            kernel: BanksLanes {
                kd: math::rgb(kd),
                ks: math::rgb(ks),
                e: e as f32,
            },
        }
    }

    /// Width of the Cauchy density used to sample the angle to the fibre:
    /// `cos^e δ ≈ exp(−e δ²/2)` has width `1/√e`; the Cauchy's heavy tails
    /// keep the weight `f cos/pdf` bounded away from the peak. `e = 0` gives
    /// width 1 (nearly uniform over `[0, π]`).
    fn width(&self) -> f64 {
        1.0 / (self.e + 1.0).sqrt()
    }

    /// Centre `αc = π − αi` of the specular cone, as an angle to the fibre.
    fn cone_angle(wi: DVec3) -> f64 {
        PI - wi.x.clamp(-1.0, 1.0).acos()
    }

    /// Selection weights (diffuse, specular). Diffuse: its albedo bound `π kd`.
    /// Specular: `ks` times roughly the lobe's solid angle, `2π` for a wide
    /// lobe down to `≈ 2.5 · 2π/√e` for a sharp one. Only efficiency depends
    /// on them.
    fn weights(&self) -> (f64, f64) {
        let d = PI * mean_rgb(self.kd);
        let s = mean_rgb(self.ks) * PI * (2.5 * self.width()).min(1.0);
        if d + s > 0.0 { (d, s) } else { (1.0, 0.0) }
    }

    /// Density of the specular strategy in solid angle. It draws the angle
    /// `αo ∈ [0, π]` to the fibre from a Cauchy density centred on `αc`
    /// truncated to `[0, π]`, `q(α) = (1/w) / (1 + ((α − αc)/w)²) / (B − A)`
    /// with `A = atan(−αc/w)`, `B = atan((π − αc)/w)`, and the azimuth ψ about
    /// the fibre uniformly; the solid angle element about the fibre is
    /// `sin α dα dψ`, so the density is `q(αo) / (2π sin αo)` (finite above the
    /// horizon: `sin αo ≥ wo.z > 0`).
    fn specular_pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        let (w, ac) = (self.width(), Self::cone_angle(wi));
        let (a, b) = ((-ac / w).atan(), ((PI - ac) / w).atan());
        let alpha = wo.x.clamp(-1.0, 1.0).acos();
        let d = (alpha - ac) / w;
        let q = 1.0 / (w * (1.0 + d * d) * (b - a));
        q / (2.0 * PI * sin_to_fibre(wo))
    }

    /// Inverse-CDF draw of the specular strategy (see [`Banks::specular_pdf`]).
    fn sample_specular(&self, wi: DVec3, u: DVec2) -> DVec3 {
        let (w, ac) = (self.width(), Self::cone_angle(wi));
        let (a, b) = ((-ac / w).atan(), ((PI - ac) / w).atan());
        let alpha = (ac + w * (a + u.x * (b - a)).tan()).clamp(0.0, PI);
        let psi = 2.0 * PI * u.y;
        let (sa, ca) = alpha.sin_cos();
        DVec3::new(ca, sa * psi.cos(), sa * psi.sin())
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    Ok(Box::new(Banks::new(
        p.color("kd")?,
        p.color("ks")?,
        p.float("e")?,
    )))
}

impl Brdf for Banks {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn batch_kernel(&self) -> Option<&dyn Kernel> {
        Some(&self.kernel)
    }

    /// The fibre `t = +x`: both terms depend on `wo` through `wo·t = cos αo`
    /// alone (Banks 1994, §4), so `f` is constant on every ring about it and
    /// the albedo quadrature integrates in polar coordinates about it,
    /// where over the half vector the cone `αo = π − αi` is a ridge across
    /// every circle.
    fn pole(&self, _wi: DVec3) -> Option<DVec3> {
        Some(DVec3::X)
    }

    /// Where the albedo quadrature should break: the clamp
    /// `max(0, −cos(αi + αo))` switches branch on the cone `αo = π/2 − αi`
    /// (a kink for an exponent near 1 or below), and the specular lobe
    /// peaks on the cone `αo = π − αi` of mirror directions about the fibre
    /// (`wo·t = −wi·t`), which is no kink but a sign change that costs a
    /// break and puts a panel's end on the ridge (about the fibre, a ring),
    /// so that a narrow lobe (`e` up to 10⁴) is never stepped over.
    fn kinks(&self, wi: DVec3) -> Vec<crate::Kink<'_>> {
        let (ci, si) = (wi.x, sin_to_fibre(wi));
        vec![
            Box::new(move |wo: DVec3| si * sin_to_fibre(wo) - ci * wo.x),
            Box::new(move |wo: DVec3| wo.x + ci),
        ]
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        let (si, so) = (sin_to_fibre(wi), sin_to_fibre(wo));
        let lobe = clamped_pow(si * so - wi.x * wo.x, self.e);
        self.kd * si + self.ks * lobe
    }

    /// Reciprocal iff `kd = 0`: the specular base is symmetric, the diffuse
    /// `kd sin αi` is not (`f(wi,wo) − f(wo,wi) = kd (sin αi − sin αo)`).
    /// Isotropic only when the model is zero: both terms depend on the
    /// angles to the fibre `t = +x`, which a rotation about the normal moves.
    ///
    /// Energy (sufficient condition, claimed only when it holds):
    /// `π (kd + ks) ≤ 1` per channel, since `sin αi ≤ 1` and the base
    /// `−cos(αi + αo) ≤ 1` give `f ≤ kd + ks` and `∫ cosθo dωo = π`. Banks'
    /// model has no normalisation, so this is all that is claimed.
    fn claims(&self) -> Claims {
        let no_diffuse = self.kd.max_element() == 0.0;
        Claims {
            reciprocal: no_diffuse,
            energy_conserving: (PI * (self.kd + self.ks)).max_element() <= 1.0,
            isotropic: no_diffuse && self.ks.max_element() == 0.0,
        }
    }

    fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        if wi.z <= 0.0 {
            return None;
        }
        let (d, s) = self.weights();
        let t = u.x * (d + s);
        let wo = if t < d {
            sampling::cosine_hemisphere(DVec2::new((t / d).min(1.0 - f64::EPSILON), u.y))
        } else {
            let v = ((t - d) / s).clamp(0.0, 1.0 - f64::EPSILON);
            self.sample_specular(wi, DVec2::new(v, u.y))
        };
        (wo.z > 0.0 && wo.is_finite()).then_some(wo)
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let (d, s) = self.weights();
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
    use crate::frame::{self, from_spherical};
    use proptest::prelude::*;
    use serde_json::json;

    fn banks(kd: f64, ks: f64, e: f64) -> Box<dyn Brdf> {
        build_model("banks", json!({"kd": kd, "ks": ks, "e": e}))
    }

    #[test]
    fn light_perpendicular_to_the_fibre() {
        // wi·t = 0: sin αi = 1, so f = kd + ks (√(1 − wo.x²))^e.
        let (kd, ks, e) = (0.2, 0.6, 6.0);
        let b = banks(kd, ks, e);
        let wi = DVec3::new(0.0, 0.6, 0.8);
        for wo in [from_spherical(0.5, 0.3), from_spherical(1.2, 2.0), DVec3::Z] {
            let want = kd + ks * (1.0 - wo.x * wo.x).powf(e / 2.0);
            let f = b.eval(wi, wo).x;
            assert!((f - want).abs() < 1e-13, "{wo}: {f} vs {want}");
        }
    }

    #[test]
    fn peak_on_the_reflection_cone() {
        // wo.x = −wi.x puts wo on the cone αo = π − αi: the base is
        // sin²αi + cos²αi = 1, so f = kd sin αi + ks for every e and every
        // azimuth about the fibre.
        let (kd, ks) = (0.3, 0.5);
        let b = banks(kd, ks, 500.0);
        let wi = from_spherical(0.9, 0.4);
        let si = (1.0 - wi.x * wi.x).sqrt();
        for psi in [0.3f64, 1.0, 2.0] {
            let r = (1.0 - wi.x * wi.x).sqrt();
            let wo = DVec3::new(-wi.x, r * psi.cos(), r * psi.sin());
            let f = b.eval(wi, wo).x;
            assert!((f - (kd * si + ks)).abs() < 1e-10, "ψ {psi}: {f}");
        }
        // The ordinary mirror direction is on the cone too (R(wi).x = −wi.x).
        assert!((b.eval(wi, frame::reflect(wi)).x - (kd * si + ks)).abs() < 1e-10);
    }

    #[test]
    fn exponent_zero_is_the_indicator_of_the_cone_side() {
        // e = 0: the lobe is 1 where −cos(αi + αo) > 0, else 0.
        let b = banks(0.0, 1.0, 0.0);
        // αi = acos(wi.x) = acos(sin 0.5) ≈ 1.07; a wo close to the fibre
        // (αo = acos 0.99 ≈ 0.14) has αi + αo < π/2: base < 0, lobe 0.
        let wi = from_spherical(0.5, 0.0);
        let near_fibre = DVec3::new(0.99, 0.0, (1.0f64 - 0.99 * 0.99).sqrt());
        let alpha_sum = wi.x.acos() + near_fibre.x.acos();
        assert!(alpha_sum < PI / 2.0);
        assert_eq!(b.eval(wi, near_fibre).x, 0.0);
        assert_eq!(b.eval(wi, frame::reflect(wi)).x, 1.0);
    }

    #[test]
    fn reciprocity_and_anisotropy() {
        let wi = from_spherical(0.3, 0.2);
        let wo = from_spherical(1.2, 0.1);
        // Specular part alone is reciprocal, to the last bit.
        let s = banks(0.0, 0.8, 12.0);
        assert_eq!(s.eval(wi, wo), s.eval(wo, wi));
        assert!(s.claims().reciprocal);
        // The diffuse part is not: the difference is kd (sin αi − sin αo).
        let b = banks(0.4, 0.8, 12.0);
        let diff = b.eval(wi, wo).x - b.eval(wo, wi).x;
        let want = 0.4 * ((1.0 - wi.x * wi.x).sqrt() - (1.0 - wo.x * wo.x).sqrt());
        assert!((diff - want).abs() < 1e-13 && want.abs() > 0.01);
        assert!(!b.claims().reciprocal);
        // Turning both directions by 90° about the normal changes the value.
        let rot = |w: DVec3| DVec3::new(-w.y, w.x, w.z);
        assert!(rel_diff(b.eval(rot(wi), rot(wo)), b.eval(wi, wo)) > 0.05);
        assert!(!b.claims().isotropic);
    }

    #[test]
    fn diffuse_albedo_and_energy_claims() {
        // Diffuse part only: ρhd = π kd sin αi (f is constant in wo).
        let b = banks(0.25, 0.0, 1.0);
        let wi = from_spherical(0.8, 0.6);
        let want = PI * 0.25 * (1.0 - wi.x * wi.x).sqrt();
        assert!((albedo(&*b, wi, 400, 64).x - want).abs() < 1e-5);
        // π (kd + ks) = 0.94: claimed, and the albedo stays below 1.
        let ok = banks(0.1, 0.2, 2.0);
        assert!(ok.claims().energy_conserving);
        for theta in [0.0f64, 0.7, 1.4] {
            for phi in [0.0, 1.57] {
                let a = albedo(&*ok, from_spherical(theta, phi), 600, 600).x;
                assert!(a <= 1.0, "θ {theta} φ {phi}: {a}");
            }
        }
        // kd = 0.5 with light across the fibre: π/2 > 1, not claimed.
        let bright = banks(0.5, 0.0, 2.0);
        assert!(!bright.claims().energy_conserving);
        assert!(albedo(&*bright, DVec3::Z, 200, 64).x > 1.5);
    }

    #[test]
    fn sampling_agrees_with_pdf() {
        for (theta, phi, e) in [
            (0.0, 0.0, 20.0),
            (0.8, 0.3, 3.0),
            (1.2, 2.5, 300.0),
            (0.5, 1.6, 0.0),
        ] {
            let b = banks(0.15, 0.3, e);
            check_sampling(&*b, from_spherical(theta, phi));
        }
    }

    proptest! {
        #[test]
        fn finite_and_nonnegative(
            kd in colour(1.0), ks in colour(1.0), e in exponent(),
            wi in direction(), wo in direction(),
        ) {
            let b = build_model("banks", json!({"kd": kd, "ks": ks, "e": e}));
            assert_finite_nonneg(b.eval(wi, wo), "banks");
            assert_finite_nonneg(b.eval(wi, frame::reflect(wi)), "at mirror");
            let p = b.pdf(wi, wo);
            prop_assert!(p.is_finite() && p >= 0.0);
        }
    }
}
