//! Smooth dielectric interface: delta reflection with the exact dielectric
//! Fresnel term plus delta transmission `(ηo²/ηi²)(1 − F) δ(wo − T(wi))/|cosθi|`
//! (the seed's "ideal specular" summary; PBRT 3rd ed. §8.2).

use crate::fresnel;
use crate::model::{Build, DeltaPort, GpuPort, ModelInfo};
use crate::params::decl::{Applies, FloatSpec, ParamDecl, ParamKind};
use crate::params::value::Params;
use crate::{Brdf, Claims, DeltaKind, DeltaLobe, FresnelTerm, Result, Rgb, frame};
use glam::DVec3;

/// Parameter declaration.
pub const PARAMS: &[ParamDecl] = &[ParamDecl {
    id: "eta",
    label: "η",
    doc: "Relative index ηt/ηi of the medium below the surface (−z) to the one above",
    kind: ParamKind::Float(FloatSpec::log(0.01, 10.0, 1.5, 0.25, 4.0)),
    applies: Applies::Always,
}];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "glass",
    name: "Glass",
    summary: "Smooth dielectric: Fresnel-weighted mirror reflection and refraction",
    citation: "Seed lecture, ideal specular summary; PBRT 3rd ed. §8.2",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: Some(
        GpuPort::new(
            "bv::models::glass",
            "shaders/models/glass.wgsl",
            include_str!("../../../../shaders/models/glass.wgsl"),
        )
        .with_delta(DeltaPort::Refraction),
    ),
};

/// A smooth dielectric interface of relative index `eta`.
#[derive(Debug, Clone)]
pub struct Glass {
    eta: f64,
}

impl Glass {
    /// An interface with relative index `eta = ηt/ηi` (−z side over +z side).
    pub fn new(eta: f64) -> Self {
        Self { eta }
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    Ok(Box::new(Glass::new(p.float("eta")?)))
}

impl Brdf for Glass {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn batch_kernel(&self) -> Option<&dyn crate::batch::Kernel> {
        Some(&crate::batch::Zero)
    }

    fn fresnel_term(&self) -> Option<FresnelTerm> {
        Some(FresnelTerm {
            fresnel: crate::fresnel::Fresnel::Dielectric {
                eta: Rgb::splat(self.eta),
            },
            source: "exact dielectric (glass)".into(),
        })
    }

    /// Zero at every finite pair: all the energy is in the delta lobes.
    fn eval(&self, _wi: DVec3, _wo: DVec3) -> Rgb {
        Rgb::ZERO
    }

    fn claims(&self) -> Claims {
        Claims {
            // Reflection is reciprocal, but transmitted radiance is scaled by
            // (ηo/ηi)², so f(wi, wo) = (ηo/ηi)⁴ f(wo, wi) through the interface;
            // only the generalised form f(wi, wo)/ηo² = f(wo, wi)/ηi² holds
            // (Veach 1997, §5.2). Strictly reciprocal only without an interface.
            reciprocal: self.eta == 1.0,
            // Reflected and transmitted flux fractions F and 1 − F sum to 1.
            energy_conserving: true,
            isotropic: true,
        }
    }

    fn transmits(&self) -> bool {
        true
    }

    /// `eta` is the index below over the one above, as for
    /// `rough-dielectric`: the views mark its refracted ray, critical angle
    /// and Snell's window, and the reciprocity check uses the generalised
    /// form (Veach 1997, eq. 5.14).
    fn interface_eta(&self) -> Option<f64> {
        Some(self.eta)
    }

    fn deltas(&self, wi: DVec3) -> Vec<DeltaLobe> {
        let reflection = |w: f64| DeltaLobe {
            direction: frame::reflect(wi),
            weight: Rgb::splat(w),
            radiance_scale: Rgb::splat(w),
            kind: DeltaKind::Reflection,
        };
        let Some(t) = frame::refract(wi, self.eta) else {
            // Total internal reflection: Snell's law has no solution.
            return vec![reflection(1.0)];
        };
        // F is the same from either side of the path (Stokes); `dielectric`
        // swaps the indices for light from inside (wi.z < 0).
        let f = fresnel::dielectric(wi.z, self.eta);
        // Indices on the incident and the outgoing side.
        let (eta_i, eta_o) = if wi.z >= 0.0 {
            (1.0, self.eta)
        } else {
            (self.eta, 1.0)
        };
        let ratio = eta_o / eta_i;
        vec![
            reflection(f),
            DeltaLobe {
                direction: t,
                weight: Rgb::splat(1.0 - f),
                // Radiance is concentrated into a smaller solid angle entering a
                // denser medium (seed: ηo²/ηi² (1 − F)).
                radiance_scale: Rgb::splat(ratio * ratio * (1.0 - f)),
                kind: DeltaKind::Transmission,
            },
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;
    use crate::frame::from_spherical;
    use proptest::prelude::*;
    use serde_json::json;
    use std::f64::consts::PI;

    fn glass(eta: f64) -> Box<dyn Brdf> {
        ModelSpec::from_json("glass", &json!({ "eta": eta }))
            .unwrap()
            .build()
            .unwrap()
    }

    #[test]
    fn normal_incidence_from_outside() {
        // F(0) = ((1.5 − 1)/(1.5 + 1))² = 0.04; transmission 0.96 straight down,
        // radiance × 1.5² · 0.96 = 2.16.
        let b = glass(1.5);
        assert!(b.transmits());
        let l = b.deltas(DVec3::Z);
        assert_eq!(l.len(), 2);
        assert_eq!(l[0].kind, DeltaKind::Reflection);
        assert!((l[0].weight.x - 0.04).abs() < 1e-15);
        assert_eq!(l[0].direction, DVec3::Z);
        assert_eq!(l[1].kind, DeltaKind::Transmission);
        assert!((l[1].weight.x - 0.96).abs() < 1e-15);
        assert!((l[1].radiance_scale.x - 2.16).abs() < 1e-14);
        assert!((l[1].direction - (-DVec3::Z)).length() < 1e-15);
        // From inside, normal incidence: the same F, radiance × 0.96/2.25.
        let l = b.deltas(-DVec3::Z);
        assert!((l[0].weight.x - 0.04).abs() < 1e-15);
        assert!((l[1].radiance_scale.x - 0.96 / 2.25).abs() < 1e-15);
        assert!((l[1].direction - DVec3::Z).length() < 1e-15);
    }

    #[test]
    fn total_internal_reflection_inside_water() {
        // Critical angle asin(3/4) = 48.59°; light arriving from inside beyond it
        // is reflected entirely (back into the water).
        let b = glass(4.0 / 3.0);
        let crit = 0.75f64.asin();
        let inside = |th: f64| from_spherical(PI - th, 0.3);
        let l = b.deltas(inside(crit + 0.01));
        assert_eq!(l.len(), 1);
        assert_eq!(l[0].weight, Rgb::ONE);
        assert!(l[0].direction.z < 0.0);
        let l = b.deltas(inside(crit - 0.01));
        assert_eq!(l.len(), 2);
        assert!(l[0].weight.x < 1.0 && l[1].direction.z > 0.0);
        // From outside there is never TIR for η > 1.
        assert_eq!(b.deltas(from_spherical(1.5, 0.0)).len(), 2);
        // η < 1 (the denser medium above): TIR from outside.
        assert_eq!(glass(0.5).deltas(from_spherical(1.0, 0.0)).len(), 1);
    }

    #[test]
    fn path_reversal_keeps_fresnel_and_scales_radiance_inversely() {
        // Following the transmitted ray back (wi' = t) returns to wi with the
        // same transmittance 1 − F (Stokes relations), and the radiance scales
        // multiply to 1 over 1 − F squared.
        let b = glass(1.7);
        for th in [0.1, 0.6, 1.2, 1.5] {
            let wi = from_spherical(th, 1.1);
            let l = b.deltas(wi);
            let back = b.deltas(l[1].direction);
            assert_eq!(back.len(), 2);
            assert!((back[1].direction - wi).length() < 1e-12);
            assert!((back[1].weight.x - l[1].weight.x).abs() < 1e-12);
            let prod = back[1].radiance_scale.x * l[1].radiance_scale.x;
            assert!((prod - l[1].weight.x.powi(2)).abs() < 1e-12);
        }
    }

    #[test]
    fn reports_its_interface_index() {
        assert_eq!(glass(1.5).interface_eta(), Some(1.5));
        assert_eq!(glass(0.75).interface_eta(), Some(0.75));
    }

    #[test]
    fn claims() {
        assert!(glass(1.5).claims().energy_conserving);
        assert!(!glass(1.5).claims().reciprocal);
        assert!(glass(1.0).claims().reciprocal);
        assert_eq!(glass(1.5).eval(DVec3::Z, -DVec3::Z), Rgb::ZERO);
    }

    proptest! {
        #[test]
        fn weights_sum_to_one_on_both_sides(
            eta in 0.01f64..10.0,
            z in prop_oneof![1e-6f64..1e-3, 1e-3f64..1.0], phi in -PI..PI, below in any::<bool>(),
        ) {
            let b = glass(eta);
            let z = if below { -z } else { z };
            let wi = from_spherical(z.acos(), phi);
            let l = b.deltas(wi);
            let sum: f64 = l.iter().map(|x| x.weight.x).sum();
            prop_assert!((sum - 1.0).abs() < 1e-12, "{sum}");
            for x in &l {
                prop_assert!(x.weight.is_finite() && x.weight.min_element() >= 0.0);
                prop_assert!(x.radiance_scale.is_finite() && x.radiance_scale.min_element() >= 0.0);
                prop_assert!((x.direction.length() - 1.0).abs() < 1e-9);
                match x.kind {
                    DeltaKind::Reflection => prop_assert!(x.direction.z * wi.z >= 0.0),
                    DeltaKind::Transmission => {
                        prop_assert!(x.direction.z * wi.z <= 0.0);
                        // Snell: η_i sinθi = η_o sinθo.
                        let (ei, eo) = if wi.z >= 0.0 { (1.0, eta) } else { (eta, 1.0) };
                        let si = (wi.x * wi.x + wi.y * wi.y).sqrt();
                        let so = (x.direction.x.powi(2) + x.direction.y.powi(2)).sqrt();
                        prop_assert!((ei * si - eo * so).abs() < 1e-9 * ei.max(eo));
                    }
                }
            }
        }
    }
}
