//! Oren-Nayar: rough diffuse reflection from V-cavities with a Gaussian slope
//! distribution of standard deviation σ, in the "qualitative model" of Oren &
//! Nayar 1994, "Generalization of Lambert's reflectance model" (SIGGRAPH), eq. 30.

use crate::batch::{Kernel, LaneKernel, LaneMask, Lanes, math};
use crate::model::{Build, GpuPort, ModelInfo};
use crate::params::decl::{Applies, ColorSpec, FloatSpec, ParamDecl, ParamKind};
use crate::params::value::Params;
use crate::{Brdf, Claims, Result, Rgb};
use glam::DVec3;
use std::f64::consts::{FRAC_1_PI, FRAC_PI_2};

/// Parameter declaration (albedo 0..1, σ 0..π/2 radians).
pub const PARAMS: &[ParamDecl] = &[
    ParamDecl {
        id: "albedo",
        label: "albedo",
        doc: "Albedo ρ of the facets (the model is ρ/π when σ = 0)",
        kind: ParamKind::Color(ColorSpec::unit_range([0.5, 0.5, 0.5])),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "sigma",
        label: "σ",
        doc: "Roughness: standard deviation of the facet slope angle",
        kind: ParamKind::Float(FloatSpec::linear(0.0, FRAC_PI_2, 0.3).with_unit("rad")),
        applies: Applies::Always,
    },
];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "oren-nayar",
    name: "Oren-Nayar",
    summary: "Rough diffuse surfaces: Lambertian V-cavities, brighter towards the light",
    citation: "Oren & Nayar 1994, \"Generalization of Lambert's reflectance model\", eq. 30",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: Some(GpuPort::new(
        "bv::models::oren_nayar",
        "shaders/models/oren_nayar.wgsl",
        include_str!("../../../../shaders/models/oren_nayar.wgsl"),
    )),
};

/// The qualitative Oren-Nayar model.
#[derive(Debug, Clone)]
pub struct OrenNayar {
    /// ρ/π, computed exactly as Lambert does so that σ = 0 matches it bit for bit.
    albedo_over_pi: Rgb,
    albedo: Rgb,
    /// `A = 1 − 0.5 σ²/(σ² + 0.33)`.
    a: f64,
    /// `B = 0.45 σ²/(σ² + 0.09)`.
    b: f64,
    kernel: OrenNayarLanes,
}

/// [`OrenNayar`]'s f32 batch kernel: the same `ρ/π (A + B t)` with
/// `t = max(0, wi·wo tangential)/max(cosθi, cosθo)`.
#[derive(Debug, Clone, Copy)]
struct OrenNayarLanes {
    albedo_over_pi: [f32; 3],
    a: f32,
    b: f32,
}

impl LaneKernel for OrenNayarLanes {
    #[inline(always)]
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        let zero = V::splat(0.0);
        let tangential = wi[0] * wo[0] + wi[1] * wo[1];
        let t = tangential.max(zero) / wi[2].max(wo[2]);
        let s = t * self.b + self.a;
        let above = wi[2].gt(zero) & wo[2].gt(zero);
        math::channels!(|c| above.select(s * self.albedo_over_pi[c], zero))
    }
}

impl OrenNayar {
    /// The model for albedo `albedo` and roughness `sigma` (radians).
    pub fn new(albedo: Rgb, sigma: f64) -> Self {
        let s2 = sigma * sigma;
        let (a, b) = (1.0 - 0.5 * s2 / (s2 + 0.33), 0.45 * s2 / (s2 + 0.09));
        Self {
            albedo_over_pi: albedo * FRAC_1_PI,
            albedo,
            a,
            b,
            kernel: OrenNayarLanes {
                albedo_over_pi: math::rgb(albedo * FRAC_1_PI),
                a: a as f32,
                b: b as f32,
            },
        }
    }

    /// Supremum over θi of ρhd(θi)/albedo: `A + B/2`. Proof: with
    /// `t = max(0, cos Δφ) sin α tan β`, ρ/albedo = A + B K(θi) where
    /// `K = (1/π) ∫ t cos θo dωo = (2/π) sin θi ∫₀^{π/2} sin²θo cos θo / max(cos θi, cos θo) dθo`
    /// (∫ max(0, cos Δφ) dΔφ = 2). The ratio cos θo / max(…) ≤ 1 gives
    /// `K ≤ (2/π) sin θi · π/4 ≤ 1/2`, and K → 1/2 as θi → π/2.
    fn albedo_bound(&self) -> f64 {
        self.a + 0.5 * self.b
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    Ok(Box::new(OrenNayar::new(
        p.color("albedo")?,
        p.float("sigma")?,
    )))
}

impl Brdf for OrenNayar {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        // cos(φi − φo) sin α tan β without any angle: with α the larger polar
        // angle and β the smaller, sin α tan β = sin θi sin θo / cos β
        // = sin θi sin θo / max(cos θi, cos θo), and sin θi sin θo cos(φi − φo) is
        // the dot product of the tangential parts. This is exact, symmetric in
        // (wi, wo), and needs no azimuth (undefined at the normal, where the
        // tangential part and hence the term vanish).
        let tangential = wi.x * wo.x + wi.y * wo.y;
        let t = tangential.max(0.0) / wi.z.max(wo.z);
        self.albedo_over_pi * (self.a + self.b * t)
    }

    fn kinks(&self, wi: DVec3) -> Vec<crate::Kink<'_>> {
        // The two clamps of `eval`: the tangential parts turn perpendicular
        // (cos Δφ = 0), and θo passes θi (α and β swap).
        let (tx, ty, cz) = (wi.x, wi.y, wi.z);
        vec![
            Box::new(move |wo: DVec3| tx * wo.x + ty * wo.y),
            Box::new(move |wo: DVec3| wo.z - cz),
        ]
    }

    fn batch_kernel(&self) -> Option<&dyn Kernel> {
        Some(&self.kernel)
    }

    fn claims(&self) -> Claims {
        Claims {
            reciprocal: true,
            // sup ρhd = albedo (A + B/2) per channel (see `albedo_bound`): for
            // 0 < σ < 0.326 rad (σ² < 0.02925/0.275) A + B/2 exceeds 1 (1.015 at
            // σ = 0.2), so a
            // white Oren-Nayar surface reflects more than it receives at grazing
            // incidence: a known flaw of the qualitative model.
            energy_conserving: self.albedo.max_element() * self.albedo_bound() <= 1.0,
            isotropic: true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;
    use crate::frame::from_spherical;
    use crate::models::testkit::*;
    use proptest::prelude::*;
    use serde_json::json;
    use std::f64::consts::{FRAC_PI_3, FRAC_PI_6, PI};

    fn model(p: serde_json::Value) -> Box<dyn Brdf> {
        ModelSpec::from_json("oren-nayar", &p)
            .unwrap()
            .build()
            .unwrap()
    }

    #[test]
    fn sigma_zero_is_lambert_exactly() {
        let on = model(json!({"albedo": [0.2, 0.5, 0.9], "sigma": 0.0}));
        let l = ModelSpec::from_json("lambert", &json!({"albedo": [0.2, 0.5, 0.9]}))
            .unwrap()
            .build()
            .unwrap();
        for &(wi, wo) in &[
            (from_spherical(0.3, 0.2), from_spherical(1.2, 0.1)),
            (from_spherical(1.5, 0.0), from_spherical(1.4, 0.05)),
            (DVec3::Z, from_spherical(0.8, 2.0)),
            (dir_grazing(6.0, 0.0), dir_grazing(6.0, 0.0)),
        ] {
            assert_eq!(on.eval(wi, wo), l.eval(wi, wo));
        }
    }

    #[test]
    fn hand_values_in_and_out_of_plane() {
        // σ = 0.5: σ² = 0.25, A = 1 − 0.125/0.58, B = 0.1125/0.34.
        // θi = 60°, θo = 30°: sin α tan β = sin 60° tan 30° = 1/2.
        let a = 1.0 - 0.125 / 0.58;
        let b = 0.1125 / 0.34;
        let on = model(json!({"albedo": 0.6, "sigma": 0.5}));
        let wi = from_spherical(FRAC_PI_3, 0.0);
        let cases = [
            (0.0, a + b * 0.5),        // same azimuth: cos Δφ = 1
            (FRAC_PI_3, a + b * 0.25), // cos Δφ = 1/2
            (FRAC_PI_2, a),            // perpendicular planes
            (PI, a),                   // opposite sides: max(0, −1) = 0
            (-2.0 * FRAC_PI_3, a),     // cos Δφ = −1/2
        ];
        for (phi_o, factor) in cases {
            let f = on.eval(wi, from_spherical(FRAC_PI_6, phi_o)).x;
            let want = 0.6 / PI * factor;
            assert!((f - want).abs() < 1e-15, "φo {phi_o}: {f} {want}");
        }
        // At the normal the azimuth is undefined and the term is 0: f = ρA/π.
        let f = on.eval(DVec3::Z, from_spherical(1.0, 0.7)).x;
        assert!((f - 0.6 / PI * a).abs() < 1e-15);
    }

    #[test]
    fn grazing_albedo_approaches_the_bound_and_the_claim_follows_it() {
        // σ = 0.2: A + B/2 = 1 − 0.02/0.37 + 0.009/0.13 ≈ 1.0152 > 1.
        let bound = 1.0 - 0.02 / 0.37 + 0.009 / 0.13;
        let white = model(json!({"albedo": 1.0, "sigma": 0.2}));
        assert!(!white.claims().energy_conserving);
        // ρ(θi) = A + B K(θi), K(θi) → 1/2 at grazing (K ≈ 0.5 − O(cos θi ln)).
        let wi = from_spherical(PI / 2.0 - 1e-4, 0.0);
        let rho = albedo(white.as_ref(), wi, 2000, 400).x;
        assert!(rho > 1.0, "ρ = {rho}");
        assert!((rho - bound).abs() < 2e-3, "ρ = {rho}, bound {bound}");
        // At normal incidence the B term vanishes: ρ = A exactly.
        let rho0 = albedo(white.as_ref(), DVec3::Z, 400, 64).x;
        assert!((rho0 - (1.0 - 0.02 / 0.37)).abs() < 1e-5, "{rho0}");
        // Rough enough or dark enough: conserving, and ρ ≤ 1 everywhere we look.
        for p in [
            json!({"albedo": 1.0, "sigma": 1.0}),
            json!({"albedo": 0.9, "sigma": 0.2}),
        ] {
            let m = model(p.clone());
            assert!(m.claims().energy_conserving, "{p}");
            for &t in &[0.0, 0.8, 1.3, FRAC_PI_2 - 1e-4] {
                let r = albedo(m.as_ref(), from_spherical(t, 0.0), 600, 200).x;
                assert!(r <= 1.0, "{p} θi {t}: {r}");
            }
        }
    }

    #[test]
    fn cosine_sampling_matches_pdf() {
        let m = model(json!({"sigma": 0.8}));
        let wi = from_spherical(1.1, 0.3);
        let (est, se) = sampled_integral(m.as_ref(), wi, |w| w.z * (1.0 + 0.5 * w.x), 100_000, 5);
        assert!((est - PI).abs() < 5.0 * se + 1e-9, "{est} ± {se}");
    }

    proptest! {
        #[test]
        fn finite_nonneg_and_reciprocal(
            albedo in 0.0..=1.0f64, sigma in 0.0..=FRAC_PI_2,
            wi in upper_dir(), wo in upper_dir(),
        ) {
            let m = OrenNayar::new(Rgb::splat(albedo), sigma);
            let f = m.eval(wi, wo);
            prop_assert!(finite_nonneg(f), "{f}");
            prop_assert!(rel_close(f, m.eval(wo, wi), 1e-6));
            // Isotropic: a common rotation about n changes nothing.
            let r = |w: DVec3| DVec3::new(0.6 * w.x - 0.8 * w.y, 0.8 * w.x + 0.6 * w.y, w.z);
            prop_assert!(rel_close(f, m.eval(r(wi), r(wo)), 1e-6));
        }
    }
}
