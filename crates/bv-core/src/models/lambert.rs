//! Lambert: the ideal diffuse reflector, `f = albedo / π`.

use crate::batch::{Kernel, LaneKernel, LaneMask, Lanes, math};
use crate::model::{Build, GpuPort, ModelInfo};
use crate::params::decl::{Applies, ColorSpec, ParamDecl, ParamKind};
use crate::params::value::Params;
use crate::{Brdf, Claims, Result, Rgb};
use glam::DVec3;
use std::f64::consts::FRAC_1_PI;

/// Parameter declaration.
pub const PARAMS: &[ParamDecl] = &[ParamDecl {
    id: "albedo",
    label: "albedo",
    doc: "Directional-hemispherical reflectance ρ (the BRDF is ρ/π)",
    kind: ParamKind::Color(ColorSpec::unit_range([0.5, 0.5, 0.5])),
    applies: Applies::Always,
}];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "lambert",
    name: "Lambert",
    summary: "Ideal diffuse reflection: the same radiance in every direction",
    citation: "Lambert 1760; PBRT 3rd ed. §8.3",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: Some(GpuPort::new(
        "bv::models::lambert",
        "shaders/models/lambert.wgsl",
        include_str!("../../../../shaders/models/lambert.wgsl"),
    )),
};

/// Lambertian reflector.
#[derive(Debug, Clone)]
pub struct Lambert {
    /// ρ / π, precomputed.
    f: Rgb,
    albedo: Rgb,
    kernel: LambertLanes,
}

/// [`Lambert`]'s f32 batch kernel: `ρ/π` above the horizon.
#[derive(Debug, Clone, Copy)]
struct LambertLanes {
    f: [f32; 3],
}

impl LaneKernel for LambertLanes {
    #[inline(always)]
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        let above = wi[2].gt(V::splat(0.0)) & wo[2].gt(V::splat(0.0));
        math::channels!(|c| above.select(V::splat(self.f[c]), V::splat(0.0)))
    }
}

impl Lambert {
    /// A Lambertian reflector of the given albedo.
    pub fn new(albedo: Rgb) -> Self {
        Self {
            f: albedo * FRAC_1_PI,
            albedo,
            kernel: LambertLanes {
                f: math::rgb(albedo * FRAC_1_PI),
            },
        }
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    Ok(Box::new(Lambert::new(p.color("albedo")?)))
}

impl Brdf for Lambert {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        self.f
    }

    fn batch_kernel(&self) -> Option<&dyn Kernel> {
        Some(&self.kernel)
    }

    fn claims(&self) -> Claims {
        Claims {
            reciprocal: true,
            energy_conserving: self.albedo.max_element() <= 1.0,
            isotropic: true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;

    #[test]
    fn value_is_albedo_over_pi() {
        let b = ModelSpec::from_json("lambert", &serde_json::json!({"albedo": 0.5}))
            .unwrap()
            .build()
            .unwrap();
        let f = b.eval(DVec3::Z, DVec3::new(0.6, 0.0, 0.8));
        assert!((f.x - 0.5 / std::f64::consts::PI).abs() < 1e-15);
        assert_eq!(b.eval(DVec3::Z, DVec3::new(0.6, 0.0, -0.8)), Rgb::ZERO);
    }
}
