//! Ideal mirror: a single delta lobe `F(cosθi) δ(wi − R(wo)) / cosθi`
//! (the seed's "ideal specular" summary; PBRT 3rd ed. §8.2.2).

use crate::fresnel::{self, Fresnel};
use crate::model::{Build, DeltaPort, GpuPort, ModelInfo};
use crate::params::decl::ParamDecl;
use crate::params::value::Params;
use crate::{Brdf, Claims, DeltaKind, DeltaLobe, FresnelTerm, Result, Rgb, frame};
use glam::DVec3;

/// Copper's normal-incidence reflectance from [`fresnel::COPPER_ETA`] and
/// [`fresnel::COPPER_K`], `((η−1)² + k²)/((η+1)² + k²)` per channel (rounded):
/// the Schlick default, so that switching the Fresnel choice keeps the colour.
const COPPER_F0: [f64; 3] = [0.952, 0.620, 0.511];

/// Parameter declaration (the Fresnel parameters of `cook-torrance`, with a
/// copper default).
pub const PARAMS: &[ParamDecl] = &[
    fresnel::fresnel_param("conductor"),
    fresnel::eta_param(fresnel::COPPER_ETA),
    fresnel::k_param(fresnel::COPPER_K),
    fresnel::f0_param(COPPER_F0),
];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "mirror",
    name: "Mirror",
    summary: "Ideal specular reflection weighted by a Fresnel term (a delta lobe)",
    citation: "Seed lecture, ideal specular summary; PBRT 3rd ed. §8.2.2",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: Some(
        GpuPort::new(
            "bv::models::mirror",
            "shaders/models/mirror.wgsl",
            include_str!("../../../../shaders/models/mirror.wgsl"),
        )
        .with_delta(DeltaPort::Reflection),
    ),
};

/// Ideal mirror with a Fresnel term.
#[derive(Debug, Clone)]
pub struct Mirror {
    fresnel: Fresnel,
}

impl Mirror {
    /// A mirror with Fresnel term `fresnel`.
    pub fn new(fresnel: Fresnel) -> Self {
        Self { fresnel }
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    Ok(Box::new(Mirror::new(Fresnel::from_params(p)?)))
}

impl Brdf for Mirror {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn batch_kernel(&self) -> Option<&dyn crate::batch::Kernel> {
        Some(&crate::batch::Zero)
    }

    fn fresnel_term(&self) -> Option<FresnelTerm> {
        Some(FresnelTerm {
            fresnel: self.fresnel,
            source: format!("fresnel = {}", self.fresnel.kind_name()),
        })
    }

    /// Zero at every finite pair: all the energy is in the delta lobe.
    fn eval(&self, _wi: DVec3, _wo: DVec3) -> Rgb {
        Rgb::ZERO
    }

    fn claims(&self) -> Claims {
        Claims {
            // δ(wi − R(wo)) = δ(wo − R(wi)) and F depends on cosθi = cosθo.
            reciprocal: true,
            // The only lobe carries F ≤ 1 of the incident flux.
            energy_conserving: true,
            isotropic: true,
        }
    }

    fn deltas(&self, wi: DVec3) -> Vec<DeltaLobe> {
        if wi.z <= 0.0 {
            return Vec::new();
        }
        let f = self.fresnel.eval(wi.z);
        vec![DeltaLobe {
            direction: frame::reflect(wi),
            weight: f,
            radiance_scale: f,
            kind: DeltaKind::Reflection,
        }]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;
    use crate::frame::from_spherical;
    use proptest::prelude::*;
    use serde_json::{Value, json};

    fn model(p: Value) -> Box<dyn Brdf> {
        ModelSpec::from_json("mirror", &p).unwrap().build().unwrap()
    }

    #[test]
    fn copper_normal_incidence_is_the_hand_value() {
        // ((η−1)² + k²)/((η+1)² + k²) per channel, η = (0.2, 0.924, 1.102),
        // k = (3.912, 2.452, 2.142).
        let b = model(Value::Null);
        let lobes = b.deltas(DVec3::Z);
        assert_eq!(lobes.len(), 1);
        let l = lobes[0];
        let hand =
            |e: f64, k: f64| ((e - 1.0) * (e - 1.0) + k * k) / ((e + 1.0) * (e + 1.0) + k * k);
        let want = Rgb::new(hand(0.2, 3.912), hand(0.924, 2.452), hand(1.102, 2.142));
        assert!(
            (l.weight - want).abs().max_element() < 1e-14,
            "{} vs {want}",
            l.weight
        );
        // The Schlick default matches it to the 3 digits it is given with.
        assert!((want - Rgb::from_array(COPPER_F0)).abs().max_element() < 1e-3);
        assert_eq!(l.direction, DVec3::Z);
        assert_eq!(l.kind, DeltaKind::Reflection);
        assert_eq!(l.radiance_scale, l.weight);
    }

    #[test]
    fn lobe_direction_and_other_fresnel_choices() {
        let wi = from_spherical(1.0, 0.5);
        let b = model(json!({"fresnel": "dielectric", "eta": 1.5}));
        let l = b.deltas(wi)[0];
        assert!((l.direction - from_spherical(1.0, 0.5 + std::f64::consts::PI)).length() < 1e-12);
        assert!((l.weight.x - fresnel::dielectric(1.0f64.cos(), 1.5)).abs() < 1e-15);
        let b = model(json!({"fresnel": "none"}));
        assert_eq!(b.deltas(wi)[0].weight, Rgb::ONE);
        let b = model(json!({"fresnel": "schlick", "f0": 0.5}));
        let c = 1.0f64.cos();
        assert!((b.deltas(wi)[0].weight.y - (0.5 + 0.5 * (1.0 - c).powi(5))).abs() < 1e-15);
        // Light from below the surface: nothing.
        assert!(b.deltas(-wi).is_empty());
        assert_eq!(b.eval(wi, frame::reflect(wi)), Rgb::ZERO);
    }

    proptest! {
        #[test]
        fn weights_in_unit_range(
            fr in 0usize..4, eta in 0.01f64..10.0, k in 0.0f64..20.0, f0 in 0.0f64..1.0,
            z in prop_oneof![1e-6f64..1e-3, 1e-3f64..1.0], phi in -3.2f64..3.2,
        ) {
            let b = model(json!({"fresnel": fresnel::FRESNEL_OPTIONS[fr], "eta": eta, "k": k, "f0": f0}));
            let wi = from_spherical(z.acos(), phi);
            let l = b.deltas(wi)[0];
            prop_assert!(l.weight.is_finite() && l.weight.min_element() >= 0.0);
            prop_assert!(l.weight.max_element() <= 1.0 + 1e-12);
            prop_assert!((l.direction.length() - 1.0).abs() < 1e-12 && l.direction.z > 0.0);
            prop_assert_eq!(b.eval(wi, l.direction), Rgb::ZERO);
        }
    }
}
