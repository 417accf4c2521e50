//! Disney's principled BRDF (Burley 2012, "Physically Based Shading at Disney",
//! SIGGRAPH course notes, and its public reference shader `disney.brdf` in
//! BRDF Explorer), with these fixed choices: linear `base_color`,
//! `Cdlum = 0.3R + 0.6G + 0.1B`, specular G = separable Smith GGX with (αx, αy).

use crate::batch::{Kernel, LaneKernel, LaneMask, Lanes, math};
use crate::fresnel::schlick_weight;
use crate::microfacet::{self, Distribution, Microfacet, Scale, ScaleLanes};
use crate::model::{Build, GpuPort, ModelInfo};
use crate::params::decl::{Applies, ColorSpec, FloatSpec, ParamDecl, ParamKind};
use crate::params::value::Params;
use crate::{Brdf, Claims, FresnelTerm, MicrofacetTerms, Ndf, Result, Rgb, mean_rgb, sampling};
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_1_PI, PI};
use std::sync::Arc;

const fn unit(id: &'static str, label: &'static str, doc: &'static str, default: f64) -> ParamDecl {
    ParamDecl {
        id,
        label,
        doc,
        kind: ParamKind::Float(FloatSpec::linear(0.0, 1.0, default)),
        applies: Applies::Always,
    }
}

/// Parameter declaration, with the reference shader's defaults.
pub const PARAMS: &[ParamDecl] = &[
    ParamDecl {
        id: "base_color",
        label: "base colour",
        doc: "Surface colour (linear RGB; the shader's gamma 2.2 conversion is not applied)",
        kind: ParamKind::Color(ColorSpec::unit_range([0.82, 0.67, 0.16])),
        applies: Applies::Always,
    },
    unit(
        "metallic",
        "metallic",
        "Dielectric (0) to metal (1): metals have no diffuse and a base-coloured specular",
        0.0,
    ),
    unit(
        "subsurface",
        "subsurface",
        "Blend from the diffuse term to the Hanrahan-Krueger-like subsurface term",
        0.0,
    ),
    unit(
        "specular",
        "specular",
        "Dielectric specular amount: F0 = 0.08 · specular (0.5 ⇔ F0 = 0.04, η = 1.5)",
        0.5,
    ),
    unit(
        "specular_tint",
        "specular tint",
        "Tints the dielectric specular towards the base colour's hue",
        0.0,
    ),
    unit(
        "roughness",
        "roughness",
        "Surface roughness; α = roughness² for the specular lobe",
        0.5,
    ),
    unit(
        "anisotropic",
        "anisotropic",
        "Aspect ratio of the specular lobe (0 = isotropic)",
        0.0,
    ),
    unit("sheen", "sheen", "Grazing-angle sheen for cloth", 0.0),
    unit(
        "sheen_tint",
        "sheen tint",
        "Tints the sheen towards the base colour's hue",
        0.5,
    ),
    unit(
        "clearcoat",
        "clearcoat",
        "Second, GTR1 specular lobe of a clear coat (F0 = 0.04)",
        0.0,
    ),
    unit(
        "clearcoat_gloss",
        "clearcoat gloss",
        "Clearcoat glossiness: GTR1 α from 0.1 (0) to 0.001 (1)",
        1.0,
    ),
];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "disney",
    name: "Disney principled",
    summary: "Burley's artist-friendly BRDF: diffuse, subsurface, sheen, GTR2 specular, GTR1 clearcoat",
    citation: "Burley 2012, Physically Based Shading at Disney; reference shader disney.brdf",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: Some(
        GpuPort::new(
            "bv::models::disney",
            "shaders/models/disney.wgsl",
            include_str!("../../../../shaders/models/disney.wgsl"),
        )
        .with_sampling_lobe(),
    ),
};

/// Linear interpolation `a (1 − t) + b t` (GLSL `mix`).
#[inline]
fn mix(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

/// Burley's GTR1 (γ = 1 "generalised Trowbridge-Reitz") distribution, normalised
/// so that `∫ D cosθh dω = 1` (Burley 2012, appendix B.2, eq. 4):
/// `(α² − 1) / (π ln(α²) (1 + (α² − 1) cos²θh))`; `1/π` at α = 1 (its limit).
pub fn gtr1(cos_h: f64, alpha: f64) -> f64 {
    if alpha >= 1.0 {
        return FRAC_1_PI;
    }
    let a2 = alpha * alpha;
    let t = 1.0 + (a2 - 1.0) * cos_h * cos_h;
    (a2 - 1.0) / (PI * a2.ln() * t)
}

/// A microfacet normal with density `GTR1 · cosθh` (Burley 2012, appendix B.2,
/// eq. 5): `cos²θh = (1 − α^{2(1−u)}) / (1 − α²)`, φh uniform.
pub fn sample_gtr1(alpha: f64, u: DVec2) -> DVec3 {
    let a2 = alpha * alpha;
    let cos2 = if alpha >= 1.0 {
        // Uniform D (1/π): D cosθh makes cos²θh uniform on [0, 1].
        u.x
    } else {
        ((1.0 - a2.powf(1.0 - u.x)) / (1.0 - a2)).clamp(0.0, 1.0)
    };
    let cos_h = cos2.sqrt();
    let sin_h = (1.0 - cos2).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u.y).sin_cos();
    DVec3::new(sin_h * c, sin_h * s, cos_h)
}

/// The specular lobe's distribution GTR2 = anisotropic GGX, exposed for the
/// D-normalisation check.
#[derive(Debug, Clone, Copy)]
struct Gtr2(Microfacet);

impl Ndf for Gtr2 {
    fn d(&self, h: DVec3) -> f64 {
        self.0.d(h)
    }

    fn slopes(&self) -> Option<(crate::microfacet::Distribution, f64, f64)> {
        self.0.slopes()
    }
}

/// Burley's principled BRDF.
#[derive(Debug, Clone)]
pub struct Disney {
    base: Rgb,
    metallic: f64,
    subsurface: f64,
    roughness: f64,
    anisotropic: f64,
    sheen: f64,
    clearcoat: f64,
    /// mix(0.08 · specular · mix(1, Ctint, specular_tint), base, metallic).
    cspec0: Rgb,
    /// mix(1, Ctint, sheen_tint).
    csheen: Rgb,
    /// GTR1 α of the clearcoat, mix(0.1, 0.001, clearcoat_gloss).
    clearcoat_alpha: f64,
    /// GTR2 (anisotropic GGX) with (αx, αy) and its Smith Λ.
    spec: Gtr2,
    /// Lobe selection probabilities for sampling: diffuse, specular (clearcoat
    /// takes the rest).
    p_diffuse: f64,
    p_spec: f64,
    kernel: DisneyLanes,
}

/// [`Disney`]'s f32 batch kernel: the f64 `eval` term by term, with the
/// specular `D G / (4 cosθi cosθo)` from the GGX lanes of
/// [`ScaleLanes::ggx_dg`] (separable Smith, as `eval`) and the clearcoat's
/// Smith G from [`ScaleLanes::one_plus_lambda`].
#[derive(Debug, Clone, Copy)]
struct DisneyLanes {
    /// `(1 − metallic) base / π`.
    diffuse: [f32; 3],
    /// `(1 − metallic) sheen · Csheen`.
    sheen: [f32; 3],
    roughness: f32,
    subsurface: f32,
    cspec0: [f32; 3],
    spec: ScaleLanes,
    /// `0.25 · clearcoat`.
    coat: f32,
    /// GTR1 as `coat_num / (α² cos²θh + sin²θh)`: the same as
    /// `1 + (α² − 1) cos²θh` for a unit h, without its cancellation near the
    /// peak of a glossy coat (α down to 0.001).
    coat_num: f32,
    coat_a2: f32,
    coat_g: ScaleLanes,
}

impl LaneKernel for DisneyLanes {
    #[inline(always)]
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        let (zero, one) = (V::splat(0.0), V::splat(1.0));
        let (nl, nv) = (wi[2], wo[2]);
        let hu = math::add3(wi, wo);
        let l2 = math::dot(hu, hu);
        let inv = one / l2.sqrt();
        let h = math::scale3(hu, inv);
        let lh = math::dot(wi, h).clamp(0.0, 1.0);
        let weight = math::schlick_weight::<V>;
        let (fl, fv, fh) = (weight(nl), weight(nv), weight(lh));
        let mix = math::lerp::<V>;
        let fd90 = lh * lh * (2.0 * self.roughness) + 0.5;
        let fd = mix(one, fd90, fl) * mix(one, fd90, fv);
        let fss90 = lh * lh * self.roughness;
        let fss = mix(one, fss90, fl) * mix(one, fss90, fv);
        let ss = (fss * (one / (nl + nv) - 0.5) + 0.5) * 1.25;
        let diffuse = mix(fd, ss, V::splat(self.subsurface));
        let dg = self.spec.ggx_dg::<false, V>(wi, wo, hu, l2);
        // A branch on the model's constant, not on a lane.
        let coat = if self.coat > 0.0 {
            let dr =
                V::splat(self.coat_num) / (h[2] * h[2] * self.coat_a2 + h[0] * h[0] + h[1] * h[1]);
            let fr = fh * 0.96 + 0.04;
            let g = self.coat_g.one_plus_lambda::<{ ScaleLanes::GGX }, V>(wi)
                * self.coat_g.one_plus_lambda::<{ ScaleLanes::GGX }, V>(wo);
            dr * self.coat * fr / (g * 4.0 * nl * nv)
        } else {
            zero
        };
        let valid = nl.gt(zero) & nv.gt(zero) & l2.gt(V::splat(1e-24));
        math::channels!(|c| {
            let fs = fh * (1.0 - self.cspec0[c]) + self.cspec0[c];
            let f = diffuse * self.diffuse[c] + fh * self.sheen[c] + fs * dg + coat;
            (valid & f.is_finite()).select(f, zero)
        })
    }
}

/// Smith GGX Λ for the clearcoat, fixed α = 0.25 (the reference shader's
/// `smithG_GGX(NdotV, .25)`).
const CLEARCOAT_G_ALPHA: f64 = 0.25;

impl Disney {
    /// The model for the given parameters.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        base: Rgb,
        metallic: f64,
        subsurface: f64,
        specular: f64,
        specular_tint: f64,
        roughness: f64,
        anisotropic: f64,
        sheen: f64,
        sheen_tint: f64,
        clearcoat: f64,
        clearcoat_gloss: f64,
    ) -> Self {
        // Luminance approximation and hue/saturation tint (white for black).
        let cdlum = 0.3 * base.x + 0.6 * base.y + 0.1 * base.z;
        let ctint = if cdlum > 0.0 { base / cdlum } else { Rgb::ONE };
        let cspec0 = (specular * 0.08 * Rgb::ONE.lerp(ctint, specular_tint)).lerp(base, metallic);
        let csheen = Rgb::ONE.lerp(ctint, sheen_tint);
        let aspect = (1.0 - 0.9 * anisotropic).sqrt();
        let r2 = roughness * roughness;
        let ax = (r2 / aspect).max(0.001);
        let ay = (r2 * aspect).max(0.001);
        // Lobe sampling weights: diffuse by its albedo scale, the specular lobe
        // always (its Fresnel reaches 1 at grazing), the clearcoat by its weight.
        let wd = (1.0 - metallic) * mean_rgb(base).max(0.0);
        let ws = 1.0;
        let wc = 0.25 * clearcoat;
        let sum = wd + ws + wc;
        let clearcoat_alpha = mix(0.1, 0.001, clearcoat_gloss);
        let (coat_num, coat_a2) = if clearcoat_alpha >= 1.0 {
            (FRAC_1_PI, 1.0)
        } else {
            let a2 = clearcoat_alpha * clearcoat_alpha;
            ((a2 - 1.0) / (PI * a2.ln()), a2)
        };
        let lanes = |dist, ax, ay| ScaleLanes::new(&Scale::new(dist, ax, ay)).map(|(_, l)| l);
        let (Some(spec_lanes), Some(coat_g)) = (
            lanes(Distribution::Ggx, ax, ay),
            lanes(Distribution::Ggx, CLEARCOAT_G_ALPHA, CLEARCOAT_G_ALPHA),
        ) else {
            unreachable!("GGX always has a lane form")
        };
        let kernel = DisneyLanes {
            diffuse: math::rgb(base * ((1.0 - metallic) * FRAC_1_PI)),
            sheen: math::rgb(csheen * (sheen * (1.0 - metallic))),
            roughness: roughness as f32,
            subsurface: subsurface as f32,
            cspec0: math::rgb(cspec0),
            spec: spec_lanes,
            coat: (0.25 * clearcoat) as f32,
            coat_num: coat_num as f32,
            coat_a2: coat_a2 as f32,
            coat_g,
        };
        Self {
            base,
            metallic,
            subsurface,
            roughness,
            anisotropic,
            sheen,
            clearcoat,
            cspec0,
            csheen,
            clearcoat_alpha,
            spec: Gtr2(Microfacet::new(Distribution::Ggx, ax, ay)),
            p_diffuse: wd / sum,
            p_spec: ws / sum,
            kernel,
        }
    }

    /// (αx, αy) of the specular lobe.
    pub fn alphas(&self) -> (f64, f64) {
        (self.spec.0.first.ax, self.spec.0.first.ay)
    }

    fn clearcoat_g1(w: DVec3) -> f64 {
        1.0 / (1.0 + microfacet::ggx_lambda(w, CLEARCOAT_G_ALPHA, CLEARCOAT_G_ALPHA))
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    Ok(Box::new(Disney::new(
        p.color("base_color")?,
        p.float("metallic")?,
        p.float("subsurface")?,
        p.float("specular")?,
        p.float("specular_tint")?,
        p.float("roughness")?,
        p.float("anisotropic")?,
        p.float("sheen")?,
        p.float("sheen_tint")?,
        p.float("clearcoat")?,
        p.float("clearcoat_gloss")?,
    )))
}

impl Brdf for Disney {
    fn id(&self) -> &'static str {
        INFO.id
    }

    /// The specular lobe's terms: D = GTR2, i.e. anisotropic GGX (Burley
    /// 2012, appendix B.2, eq. 13), and the separable Smith G of GGX,
    /// `G2 = G1(wi) G1(wo)` with `G1 = 1/(1 + Λ)` (Heitz 2014, eqs. 43, 86 and
    /// 98), as `eval` multiplies them. The clearcoat's GTR1 lobe is not
    /// included.
    fn microfacet_terms(&self) -> Option<MicrofacetTerms> {
        let ndf = self.spec.0;
        let g1 = move |w: DVec3| if w.z > 0.0 { ndf.g1(w) } else { 0.0 };
        Some(MicrofacetTerms {
            distribution: "GTR2 (GGX)".into(),
            geometry: "separable Smith (Burley 2012)".into(),
            d: Arc::new(move |h| ndf.d(h)),
            g1: Arc::new(g1),
            g2: Arc::new(move |wi, wo, _h| g1(wi) * g1(wo)),
        })
    }

    fn batch_kernel(&self) -> Option<&dyn Kernel> {
        Some(&self.kernel)
    }

    /// The specular lobe in a white furnace: metallic with a white base,
    /// so that Schlick's F with F0 = 1 is 1 and the diffuse, sheen and
    /// subsurface terms (weighted by 1 − metallic) vanish; no clearcoat;
    /// the same roughness and anisotropy.
    fn furnace(&self) -> Option<Box<dyn Brdf>> {
        Some(Box::new(Disney::new(
            Rgb::ONE,
            1.0,
            0.0,
            0.0,
            0.0,
            self.roughness,
            self.anisotropic,
            0.0,
            0.0,
            0.0,
            0.0,
        )))
    }

    fn fresnel_term(&self) -> Option<FresnelTerm> {
        Some(FresnelTerm {
            fresnel: crate::fresnel::Fresnel::Schlick { f0: self.cspec0 },
            source: "Schlick, F0 from specular, specular_tint and metallic (Burley 2012)".into(),
        })
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        let (nl, nv) = (wi.z, wo.z);
        if nl <= 0.0 || nv <= 0.0 {
            return Rgb::ZERO;
        }
        let Some(h) = crate::frame::half_vector(wi, wo) else {
            return Rgb::ZERO;
        };
        let lh = wi.dot(h).clamp(0.0, 1.0);
        let (fl, fv, fh) = (schlick_weight(nl), schlick_weight(nv), schlick_weight(lh));

        // Diffuse: Schlick-like retro-reflection, FD90 = 0.5 + 2 roughness cos²θd.
        let fd90 = 0.5 + 2.0 * lh * lh * self.roughness;
        let fd = mix(1.0, fd90, fl) * mix(1.0, fd90, fv);
        // Subsurface (Hanrahan-Krueger-like), 1.25 to roughly keep the albedo.
        let fss90 = lh * lh * self.roughness;
        let fss = mix(1.0, fss90, fl) * mix(1.0, fss90, fv);
        let ss = 1.25 * (fss * (1.0 / (nl + nv) - 0.5) + 0.5);
        // Sheen.
        let fsheen = fh * self.sheen * self.csheen;
        let diffuse =
            (FRAC_1_PI * mix(fd, ss, self.subsurface) * self.base + fsheen) * (1.0 - self.metallic);

        // Specular: GTR2 D, Schlick F, separable Smith GGX G (with the 1/(4 cos cos)).
        let ds = self.spec.0.d(h);
        let fs = self.cspec0.lerp(Rgb::ONE, fh);
        let gs = self.spec.0.g1(wi) * self.spec.0.g1(wo);
        let spec = fs * (ds * gs / (4.0 * nl * nv));

        // Clearcoat: 0.25 · clearcoat · GTR1 · mix(0.04, 1, FH) · G(α = 0.25) / (4 cos cos).
        let coat = if self.clearcoat > 0.0 {
            let dr = gtr1(h.z, self.clearcoat_alpha);
            let fr = mix(0.04, 1.0, fh);
            let gr = Self::clearcoat_g1(wi) * Self::clearcoat_g1(wo);
            0.25 * self.clearcoat * dr * fr * gr / (4.0 * nl * nv)
        } else {
            0.0
        };

        let f = diffuse + spec + Rgb::splat(coat);
        if f.is_finite() { f } else { Rgb::ZERO }
    }

    fn claims(&self) -> Claims {
        let (ax, ay) = self.alphas();
        Claims {
            // Every term is symmetric: Fd, Fss and Gs are products of the same
            // function of cosθi and cosθo, FH depends on wi·h = wo·h, D on h.
            reciprocal: true,
            // Not energy conserving by design (e.g. the retro-reflective diffuse
            // with FD90 up to 2.5 and the added clearcoat and sheen lobes).
            energy_conserving: false,
            // The floor α ≥ 0.001 makes αx = αy at roughness 0 whatever
            // `anisotropic` is; otherwise isotropic iff anisotropic = 0.
            isotropic: ax == ay,
        }
    }

    fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        if wi.z <= 0.0 {
            return None;
        }
        let one = microfacet::ONE_MINUS_EPS;
        if u.x < self.p_diffuse {
            let ux = (u.x / self.p_diffuse).min(one);
            return Some(sampling::cosine_hemisphere(DVec2::new(ux, u.y)));
        }
        let rest = u.x - self.p_diffuse;
        let h = if rest < self.p_spec {
            let ux = (rest / self.p_spec).min(one);
            self.spec.0.sample_h(wi, DVec2::new(ux, u.y))
        } else {
            let p_coat = 1.0 - self.p_diffuse - self.p_spec;
            let ux = ((rest - self.p_spec) / p_coat).clamp(0.0, one);
            sample_gtr1(self.clearcoat_alpha, DVec2::new(ux, u.y))
        };
        let wo = crate::frame::reflect_about(wi, h);
        (wo.z > 0.0 && wi.dot(h) > 0.0).then_some(wo)
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let Some(h) = crate::frame::half_vector(wi, wo) else {
            return 0.0;
        };
        let oh = wo.dot(h);
        if oh <= 0.0 {
            return 0.0;
        }
        let p_coat = (1.0 - self.p_diffuse - self.p_spec).max(0.0);
        let spec_h = self.p_spec * self.spec.0.pdf_h(wi, h);
        let coat_h = if p_coat > 0.0 {
            p_coat * gtr1(h.z, self.clearcoat_alpha) * h.z
        } else {
            0.0
        };
        self.p_diffuse * sampling::cosine_hemisphere_pdf(wo) + (spec_h + coat_h) / (4.0 * oh)
    }

    fn ndf(&self) -> Option<&dyn Ndf> {
        Some(&self.spec)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specular_terms_are_gtr2_and_separable_smith() {
        // roughness 0.5, isotropic: α = r² = 0.25; GTR2 at the normal is
        // 1/(π α²) (Burley 2012, eq. 8 with γ = 2).
        let b = crate::ModelSpec::from_json(
            "disney",
            &serde_json::json!({"roughness": 0.5, "anisotropic": 0.0}),
        )
        .unwrap()
        .build()
        .unwrap();
        let t = b.microfacet_terms().unwrap();
        let a: f64 = 0.25;
        assert!(((t.d)(DVec3::Z) - 1.0 / (PI * a * a)).abs() < 1e-9 * (t.d)(DVec3::Z));
        let wi = crate::frame::from_spherical(0.6, 0.0);
        let wo = crate::frame::from_spherical(0.3, 2.0);
        let h = (wi + wo).normalize();
        let g2 = (t.g2)(wi, wo, h);
        assert!((g2 - (t.g1)(wi) * (t.g1)(wo)).abs() < 1e-15, "separable");
    }
    use crate::ModelSpec;
    use crate::frame::from_spherical;
    use crate::microfacet::tests::hemisphere_integral;
    use proptest::prelude::*;
    use serde_json::{Value, json};

    fn model(p: Value) -> Box<dyn Brdf> {
        ModelSpec::from_json("disney", &p).unwrap().build().unwrap()
    }

    /// Everything off except what a test turns on.
    fn plain(extra: Value) -> Box<dyn Brdf> {
        let mut p = json!({"base_color": 0.5, "metallic": 0.0, "subsurface": 0.0,
            "specular": 0.5, "specular_tint": 0.0, "roughness": 0.5, "anisotropic": 0.0,
            "sheen": 0.0, "sheen_tint": 0.0, "clearcoat": 0.0, "clearcoat_gloss": 1.0});
        for (k, v) in extra.as_object().unwrap() {
            p[k] = v.clone();
        }
        model(p)
    }

    #[test]
    fn gtr1_and_gtr2_are_normalised() {
        for a in [0.001, 0.01, 0.1, 0.5, 0.99] {
            let s = hemisphere_integral(|h| gtr1(h.z, a) * h.z, 64);
            assert!((s - 1.0).abs() < 1e-3, "GTR1 α {a}: {s}");
        }
        for (r, an) in [(0.5, 0.0), (0.1, 0.8), (1.0, 1.0), (0.0, 0.5)] {
            let b = plain(json!({"roughness": r, "anisotropic": an}));
            let d = b.ndf().unwrap();
            let s = hemisphere_integral(|h| d.d(h) * h.z, 256);
            assert!((s - 1.0).abs() < 1e-3, "GTR2 r {r} an {an}: {s}");
        }
    }

    #[test]
    fn normal_incidence_hand_values() {
        // wi = wo = n: h = n, FL = FV = FH = 0, Fd = 1, Fss = 1,
        // ss = 1.25 (1/2 − 1/2) + 0.625 = 0.625, D = 1/(π αx αy) with
        // αx αy = roughness⁴ = 1/16, G = 1, Fs = Cspec0 = 0.08 · 0.5 = 0.04:
        // f = 0.5/π + 0.04/(4π/16) = 0.66/π.
        let f = plain(json!({})).eval(DVec3::Z, DVec3::Z);
        assert!(
            (f - Rgb::splat(0.66 / PI)).abs().max_element() < 1e-14,
            "{f}"
        );
        // Full subsurface: diffuse × 0.625.
        let f = plain(json!({"subsurface": 1.0})).eval(DVec3::Z, DVec3::Z);
        assert!((f.x - (0.5 * 0.625 + 0.16) / PI).abs() < 1e-14);
        // Anisotropy keeps αx αy = roughness⁴, hence the value at the normal.
        let f = plain(json!({"anisotropic": 1.0})).eval(DVec3::Z, DVec3::Z);
        assert!((f.x - 0.66 / PI).abs() < 1e-14);
        // Clearcoat at the normal: GTR1(1, α) = (α² − 1)/(π ln α² · α²), Fr = 0.04,
        // Gr = 1: + 0.25 · 0.04 · GTR1 / 4. Gloss 0: α = 0.1, ln α² = −2 ln 10.
        let f = plain(json!({"clearcoat": 1.0, "clearcoat_gloss": 0.0})).eval(DVec3::Z, DVec3::Z);
        let gtr1_hand = (0.01 - 1.0) / (PI * (-2.0 * std::f64::consts::LN_10) * 0.01);
        assert!((gtr1_hand - 6.842_891).abs() < 1e-6);
        assert!((f.x - 0.66 / PI - 0.25 * 0.04 * gtr1_hand / 4.0).abs() < 1e-13);
    }

    #[test]
    fn microfacet_terms_are_gtr2_and_separable_smith() {
        // roughness 0.6, anisotropic 0.5: aspect = √0.55, αx = 0.36/aspect,
        // αy = 0.36 · aspect.
        let b = plain(json!({"roughness": 0.6, "anisotropic": 0.5}));
        let t = b.microfacet_terms().unwrap();
        let aspect = 0.55f64.sqrt();
        let (ax, ay) = (0.36 / aspect, 0.36 * aspect);
        // GTR2 (Burley 2012, eq. 13): 1/(π αx αy (tan²θ(cos²φ/αx² + sin²φ/αy²)
        // + 1)² cos⁴θ), in spherical angles.
        for (th, ph) in [(0.0, 0.0), (0.4, 0.3), (1.1, 2.0), (1.5, -0.7)] {
            let h = from_spherical(th, ph);
            let (c, tn) = (f64::cos(th), f64::tan(th));
            let e = tn * tn * (ph.cos().powi(2) / (ax * ax) + ph.sin().powi(2) / (ay * ay));
            let want = 1.0 / (PI * ax * ay * (1.0 + e).powi(2) * c.powi(4));
            let got = (t.d)(h);
            assert!(
                (got - want).abs() <= 1e-12 * want,
                "θ {th}: {got} vs {want}"
            );
        }
        // Smith G1 of GGX (Heitz 2014, eq. 86):
        // 2/(1 + √(1 + α(φ)² tan²θ)), α(φ)² = cos²φ αx² + sin²φ αy².
        let g1 = |th: f64, ph: f64| {
            let a2 = ph.cos().powi(2) * ax * ax + ph.sin().powi(2) * ay * ay;
            2.0 / (1.0 + (1.0 + a2 * th.tan().powi(2)).sqrt())
        };
        let (wi, wo) = (from_spherical(0.9, 0.2), from_spherical(1.2, 2.5));
        assert!(((t.g1)(wi) - g1(0.9, 0.2)).abs() < 1e-14);
        assert_eq!((t.g1)(DVec3::Z), 1.0);
        assert_eq!((t.g1)(from_spherical(1.7, 0.0)), 0.0);
        let h = (wi + wo).normalize();
        let g2 = (t.g2)(wi, wo, h);
        assert!((g2 - g1(0.9, 0.2) * g1(1.2, 2.5)).abs() < 1e-14);
        // They are the terms eval uses: with everything but the specular lobe
        // off (metallic 1, white base), f = F D G2/(4 cos cos), F from Schlick.
        let m = plain(
            json!({"roughness": 0.6, "anisotropic": 0.5, "metallic": 1.0,
            "base_color": 1.0}),
        );
        let tm = m.microfacet_terms().unwrap();
        let want = (tm.d)(h) * (tm.g2)(wi, wo, h) / (4.0 * wi.z * wo.z);
        assert!((m.eval(wi, wo).x - want).abs() < 1e-12 * want, "{want}");
    }

    #[test]
    fn metallic_removes_diffuse_and_sheen() {
        // metallic = 1: Cspec0 = base; at the normal f = base/(4π αx αy).
        let base = [0.9, 0.5, 0.1];
        let b = plain(json!({"metallic": 1.0, "base_color": base}));
        let f = b.eval(DVec3::Z, DVec3::Z);
        let want = Rgb::from_array(base) * 16.0 / (4.0 * PI);
        assert!((f - want).abs().max_element() < 1e-13, "{f} vs {want}");
        // Diffuse, subsurface and sheen no longer matter anywhere.
        let c = plain(
            json!({"metallic": 1.0, "base_color": base, "subsurface": 1.0,
            "sheen": 1.0, "roughness": 0.5}),
        );
        for (a, p) in [(0.3, 0.0), (1.2, 2.0), (1.5, -1.0)] {
            let (wi, wo) = (from_spherical(a, p), from_spherical(0.7, 0.4));
            assert!((b.eval(wi, wo) - c.eval(wi, wo)).abs().max_element() < 1e-15);
        }
    }

    #[test]
    fn retro_reflection_and_sheen_hand_values() {
        // wi = wo at 60°: h = wi, cosθd = 1, FH = 0 (no specular F with specular = 0,
        // no sheen), FL = FV = (1/2)⁵ = 1/32, FD90 = 0.5 + 2 roughness = 2.5:
        // f = base/π (1 + 1.5/32)².
        let w = from_spherical(PI / 3.0, 0.2);
        let b = plain(json!({"roughness": 1.0, "specular": 0.0, "sheen": 1.0}));
        let f = b.eval(w, w);
        assert!(
            (f.x - 0.5 / PI * (1.0 + 1.5 / 32.0f64).powi(2)).abs() < 1e-14,
            "{f}"
        );
        // Mirror pair at 60°: h = n, cosθd = 1/2, FH = 1/32; grey base ⇒ Ctint = 1,
        // so sheen adds FH · sheen · (1 − metallic) = 1/64 at metallic 1/2.
        let (wi, wo) = (from_spherical(PI / 3.0, 0.0), from_spherical(PI / 3.0, PI));
        let with = plain(json!({"sheen": 1.0, "metallic": 0.5})).eval(wi, wo);
        let without = plain(json!({"sheen": 0.0, "metallic": 0.5})).eval(wi, wo);
        assert!(((with - without).x - 1.0 / 64.0).abs() < 1e-14);
    }

    #[test]
    fn tints() {
        // base (1, 0.5, 0): Cdlum = 0.3 + 0.3 = 0.6, Ctint = base/0.6; full
        // specular tint ⇒ Cspec0 = 0.04 Ctint. At the normal: base/π + Cspec0 · 4/π.
        let base = Rgb::new(1.0, 0.5, 0.0);
        let b = plain(json!({"base_color": [1.0, 0.5, 0.0], "specular_tint": 1.0}));
        let want = base / PI + 0.04 * (base / 0.6) * 4.0 / PI;
        let f = b.eval(DVec3::Z, DVec3::Z);
        assert!((f - want).abs().max_element() < 1e-14, "{f} vs {want}");
        // Black base: Ctint is white, no NaN.
        let b = plain(json!({"base_color": 0.0, "specular_tint": 1.0, "sheen_tint": 1.0}));
        let f = b.eval(DVec3::Z, DVec3::Z);
        assert!(
            (f - Rgb::splat(0.16 / PI)).abs().max_element() < 1e-14,
            "{f}"
        );
    }

    #[test]
    fn claims_and_anisotropy() {
        let iso = plain(json!({}));
        let c = iso.claims();
        assert!(c.reciprocal && !c.energy_conserving && c.isotropic);
        let an = plain(json!({"anisotropic": 0.7}));
        assert!(!an.claims().isotropic);
        // aspect = √(1 − 0.9 · 0.7) = √0.37; αx = 0.25/aspect along the tangent:
        // the lobe is wider along x than along y.
        let (wi, wx, wy) = (
            DVec3::Z,
            from_spherical(0.8, 0.0),
            from_spherical(0.8, PI / 2.0),
        );
        assert!(an.eval(wi, wx).x > an.eval(wi, wy).x);
        assert!(
            plain(json!({"anisotropic": 0.7, "roughness": 0.0}))
                .claims()
                .isotropic
        );
    }

    #[test]
    fn sampling_matches_pdf() {
        let mut rng = sampling::rng(3);
        for p in [
            json!({}),
            json!({"roughness": 0.2, "anisotropic": 0.8, "clearcoat": 1.0, "clearcoat_gloss": 0.3}),
            json!({"metallic": 1.0, "roughness": 0.9, "clearcoat": 0.5}),
        ] {
            let b = plain(p.clone());
            for th in [0.3, 1.2] {
                let wi = from_spherical(th, 0.4);
                let n = 200_000;
                let (mut sum, mut ok) = (0.0, 0usize);
                for _ in 0..n {
                    if let Some(wo) = b.sample(wi, sampling::uniform2(&mut rng)) {
                        let pdf = b.pdf(wi, wo);
                        assert!(pdf > 0.0 && wo.z > 0.0);
                        sum += wo.z * wo.z / pdf;
                        ok += 1;
                    }
                }
                let est = sum / n as f64;
                assert!((est - 2.0 * PI / 3.0).abs() < 0.03, "{p} θ {th}: {est}");
                // ∫ pdf dωo, integrated over half vectors (dωo = 4 (wi·h) dω_h)
                // so that the graded quadrature resolves the sharp lobes at h = n.
                let total = hemisphere_integral(
                    |h| {
                        let c = wi.dot(h);
                        let wo = crate::frame::reflect_about(wi, h);
                        if c <= 0.0 || wo.z <= 0.0 {
                            0.0
                        } else {
                            b.pdf(wi, wo) * 4.0 * c
                        }
                    },
                    512,
                );
                let frac = ok as f64 / n as f64;
                assert!((total - frac).abs() < 0.01, "{p} θ {th}: {total} vs {frac}");
            }
        }
    }

    #[test]
    fn gtr1_sampler_matches_its_density() {
        // E[g/pdf] for g = cos²θh over the hemisphere (2π/3), pdf = GTR1 cosθh.
        let mut rng = sampling::rng(9);
        for a in [0.001, 0.05, 0.1] {
            let n = 200_000;
            let mut sum = 0.0;
            for _ in 0..n {
                let h = sample_gtr1(a, sampling::uniform2(&mut rng));
                sum += h.z * h.z / (gtr1(h.z, a) * h.z);
            }
            let est = sum / n as f64;
            assert!((est - 2.0 * PI / 3.0).abs() < 0.05, "α {a}: {est}");
        }
    }

    proptest! {
        #[test]
        fn finite_nonnegative_and_reciprocal(
            base in prop::array::uniform3(0.0f64..1.0),
            v in prop::array::uniform10(0.0f64..1.0),
            zi in prop_oneof![1e-6f64..1e-3, 1e-3f64..1.0], pi in -PI..PI,
            zo in prop_oneof![1e-6f64..1e-3, 1e-3f64..1.0], po in -PI..PI,
        ) {
            let names = ["metallic", "subsurface", "specular", "specular_tint", "roughness",
                "anisotropic", "sheen", "sheen_tint", "clearcoat", "clearcoat_gloss"];
            let mut p = json!({"base_color": base});
            for (k, x) in names.iter().zip(v) {
                p[*k] = json!(x);
            }
            let b = model(p);
            let wi = from_spherical(zi.acos(), pi);
            let wo = from_spherical(zo.acos(), po);
            let f = b.eval(wi, wo);
            let r = b.eval(wo, wi);
            prop_assert!(f.is_finite() && f.min_element() >= 0.0, "{f}");
            let scale = f.max_element().max(r.max_element());
            prop_assert!((f - r).abs().max_element() <= 1e-6 * scale, "{f} vs {r}");
            let pdf = b.pdf(wi, wo);
            prop_assert!(pdf.is_finite() && pdf >= 0.0);
        }
    }
}
