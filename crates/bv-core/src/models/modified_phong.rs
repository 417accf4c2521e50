//! Modified Phong:
//! `f = kd/π + ks (e+2)/(2π) · max(0, R(wo)·wi)^e`.
//!
//! Lafortune & Willems 1994, "Using the modified Phong reflectance model for
//! physically based rendering", eq. for `f_r` in §3: the Phong lobe without the
//! `1/cosθi` (hence reciprocal, as `R(wo)·wi = R(wi)·wo`) and normalised by
//! `(e+2)/(2π)` so that the specular albedo at normal incidence is exactly `ks`.

use super::lobes::{Mixture, PowerLobe, clamped_pow};
use crate::batch::{Kernel, LaneKernel, LaneMask, Lanes, math};
use crate::model::{Build, GpuPort, ModelInfo};
use crate::params::decl::{Applies, ColorSpec, FloatSpec, ParamDecl, ParamKind};
use crate::params::value::Params;
use crate::{Brdf, Claims, Result, Rgb, frame, mean_rgb};
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_1_PI, PI};

/// Parameter declaration (exponent 0..10000, log slider 1..1000).
pub const PARAMS: &[ParamDecl] = &[
    ParamDecl {
        id: "kd",
        label: "kd",
        doc: "Diffuse albedo (the diffuse term is kd/π)",
        kind: ParamKind::Color(ColorSpec::unit_range([0.5, 0.5, 0.5])),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "ks",
        label: "ks",
        doc: "Specular albedo at normal incidence",
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
    id: "modified-phong",
    name: "Modified Phong",
    summary: "Normalised, reciprocal Phong: kd/π + ks (e+2)/(2π) (R(wo)·wi)^e",
    citation: "Lafortune & Willems 1994, \"Using the modified Phong reflectance model for physically based rendering\", §3",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: Some(
        GpuPort::new(
            "bv::models::modified_phong",
            "shaders/models/modified_phong.wgsl",
            include_str!("../../../../shaders/models/modified_phong.wgsl"),
        )
        .with_sampling_lobe(),
    ),
};

/// Modified Phong BRDF.
#[derive(Debug, Clone)]
pub struct ModifiedPhong {
    kd: Rgb,
    ks: Rgb,
    e: f64,
    /// `(e+2)/(2π)`, precomputed.
    norm: f64,
    kernel: ModifiedPhongLanes,
}

/// [`ModifiedPhong`]'s f32 batch kernel: `kd/π + ks (e+2)/(2π) (R(wo)·wi)^e`,
/// the lobe by [`math::mirror_lobe`].
#[derive(Debug, Clone, Copy)]
struct ModifiedPhongLanes {
    diffuse: [f32; 3],
    /// ks (e+2)/(2π).
    spec: [f32; 3],
    e: f32,
}

impl LaneKernel for ModifiedPhongLanes {
    #[inline(always)]
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        let lobe = math::mirror_lobe(wi, wo, self.e);
        let above = wi[2].gt(V::splat(0.0)) & wo[2].gt(V::splat(0.0));
        math::channels!(|c| above.select(lobe * self.spec[c] + self.diffuse[c], V::splat(0.0)))
    }
}

impl ModifiedPhong {
    /// A modified Phong BRDF.
    pub fn new(kd: Rgb, ks: Rgb, e: f64) -> Self {
        Self {
            kd,
            ks,
            e,
            norm: (e + 2.0) / (2.0 * PI),
            kernel: ModifiedPhongLanes {
                diffuse: math::rgb(kd * FRAC_1_PI),
                spec: math::rgb(ks * ((e + 2.0) / (2.0 * PI))),
                e: e as f32,
            },
        }
    }

    /// Sampling mixture: cosine sampling for the diffuse part and the
    /// power-cosine lobe about `R(wi)` (the exact shape of the specular lobe
    /// in `wo`), selected in proportion to their albedos at normal incidence,
    /// `kd` and `ks` (mean over channels).
    fn mixture_parts(&self, wi: DVec3) -> (f64, [PowerLobe; 1]) {
        (
            mean_rgb(self.kd),
            [PowerLobe {
                axis: frame::reflect(wi),
                e: self.e,
                weight: mean_rgb(self.ks),
            }],
        )
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    Ok(Box::new(ModifiedPhong::new(
        p.color("kd")?,
        p.color("ks")?,
        p.float("e")?,
    )))
}

impl Brdf for ModifiedPhong {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        let lobe = clamped_pow(frame::reflect(wo).dot(wi), self.e);
        self.kd * FRAC_1_PI + self.ks * (self.norm * lobe)
    }

    /// Energy: `ρhd(θi) = kd + ks · (e+2)/(2π) · ∫ max(0, R(wi)·wo)^e cosθo dωo`.
    /// By the lemma in [`super::lobes`] (with `r = R(wi)`), the integral is at
    /// most `2π/(e+2)`, with equality at normal incidence where `R(wi) = n`:
    /// there it is `∫ cos^{e+1}θ dω = 2π/(e+2)` exactly, so the specular
    /// albedo is exactly `ks` at normal incidence (1 for `ks = 1`) and at most
    /// `ks` elsewhere. Hence `max ρhd = kd + ks`, reached at normal incidence:
    /// energy is conserved **iff** `kd + ks ≤ 1` in every channel (the lecture's
    /// "sufficient" condition is also necessary for this model).
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
        Claims {
            reciprocal: true,
            energy_conserving: (self.kd + self.ks).max_element() <= 1.0,
            isotropic: true,
        }
    }

    fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        if wi.z <= 0.0 {
            return None;
        }
        let (diffuse, lobes) = self.mixture_parts(wi);
        Mixture {
            diffuse,
            lobes: &lobes,
        }
        .sample(u)
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 {
            return 0.0;
        }
        let (diffuse, lobes) = self.mixture_parts(wi);
        Mixture {
            diffuse,
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

    fn model(kd: f64, ks: f64, e: f64) -> Box<dyn Brdf> {
        build_model("modified-phong", json!({"kd": kd, "ks": ks, "e": e}))
    }

    #[test]
    fn peak_value() {
        // At wo = R(wi) the lobe is 1: f = kd/π + ks (e+2)/(2π).
        let b = model(0.4, 0.6, 48.0);
        let wi = from_spherical(0.9, -1.0);
        let f = b.eval(wi, frame::reflect(wi)).x;
        let want = 0.4 / PI + 0.6 * 50.0 / (2.0 * PI);
        assert!((f - want).abs() < 1e-13 * want);
        // Far outside the lobe (R(wo)·wi < 0) only the diffuse term is left.
        let f = b.eval(from_spherical(1.2, 0.0), from_spherical(1.2, 0.0)).x;
        // R(wo)·wi = −sin²θ + cos²θ = cos 2.4 < 0.
        assert!((f - 0.4 / PI).abs() < 1e-15);
    }

    #[test]
    fn specular_albedo_at_normal_incidence_is_exactly_ks() {
        // ks (e+2)/(2π) · ∫ cos^{e+1} dω = ks (e+2)/(2π) · 2π/(e+2) = ks.
        for e in [0.0, 1.0, 10.0, 60.0] {
            let b = model(0.0, 1.0, e);
            let a = albedo(&*b, DVec3::Z, 4000, 8).x;
            assert!((a - 1.0).abs() < 2e-4, "e {e}: {a}");
        }
        // With the diffuse part: ρhd(0) = kd + ks.
        let a = albedo(&*model(0.3, 0.5, 5.0), DVec3::Z, 2000, 8).x;
        assert!((a - 0.8).abs() < 1e-4, "{a}");
    }

    #[test]
    fn specular_albedo_e1_closed_form_and_below_ks() {
        // e = 1: ρs(θi) = ks · (3/(2π)) · (2/3)(sinθ + (π−θ)cosθ)
        //        = ks (sinθ + (π−θ)cosθ)/π, which decreases from ks at θ = 0.
        let ks = 0.8;
        let b = model(0.0, ks, 1.0);
        for deg in [0.0f64, 20.0, 45.0, 70.0, 89.0] {
            let t = deg.to_radians();
            let want = ks * (t.sin() + (PI - t) * t.cos()) / PI;
            let got = albedo(&*b, from_spherical(t, 2.0), 600, 600).x;
            assert!((got - want).abs() < 2e-4, "θ {deg}: {got} vs {want}");
            assert!(got <= ks + 1e-4);
        }
    }

    #[test]
    fn energy_claim_is_exact() {
        // kd + ks = 1: claimed, and the albedo stays ≤ 1 at every angle.
        let b = model(0.4, 0.6, 30.0);
        assert!(b.claims().energy_conserving);
        for deg in [0.0f64, 40.0, 75.0, 88.0] {
            let a = albedo(&*b, from_spherical(deg.to_radians(), 0.0), 1000, 600).x;
            assert!(a <= 1.0 + 1e-3, "θ {deg}: {a}");
        }
        // kd + ks = 1.1: not claimed, and indeed ρhd(0) = 1.1.
        let b = model(0.6, 0.5, 30.0);
        assert!(!b.claims().energy_conserving);
        assert!(albedo(&*b, DVec3::Z, 2000, 8).x > 1.09);
        // Per channel.
        let c = build_model(
            "modified-phong",
            json!({"kd": [0.9, 0.1, 0.1], "ks": [0.2, 0.1, 0.1]}),
        );
        assert!(!c.claims().energy_conserving);
    }

    #[test]
    fn sampling_agrees_with_pdf() {
        for (theta, e) in [(0.0, 20.0), (0.8, 3.0), (1.4, 300.0)] {
            let b = model(0.5, 0.4, e);
            check_sampling(&*b, from_spherical(theta, -0.7));
        }
    }

    proptest! {
        #[test]
        fn finite_nonnegative_and_reciprocal(
            kd in colour(1.0), ks in colour(1.0), e in exponent(),
            wi in direction(), wo in direction(),
        ) {
            let b = build_model("modified-phong", json!({"kd": kd, "ks": ks, "e": e}));
            let f = b.eval(wi, wo);
            assert_finite_nonneg(f, "modified-phong");
            assert_finite_nonneg(b.eval(wi, frame::reflect(wi)), "at mirror");
            prop_assert!(rel_diff(f, b.eval(wo, wi)) < 1e-6);
            prop_assert!(b.claims().reciprocal);
            let p = b.pdf(wi, wo);
            prop_assert!(p.is_finite() && p >= 0.0);
        }
    }
}
