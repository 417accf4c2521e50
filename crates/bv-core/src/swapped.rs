//! A BRDF with light and view exchanged, `f'(ωi, ωo) = f(ωo, ωi)`, so that
//! its directional albedo is the *hemispherical-directional* reflectance of
//! the original, `ρdh(ωo) = ∫ f(ωi, ωo) cos θi dωi` (LECTURE.md N12): the
//! light a viewer at ωo receives from a uniformly lit sky. By Helmholtz
//! reciprocity it equals ρhd(ωo) for every physical BRDF, so the two curves
//! coincide for reciprocal models and part for those that are not
//! (classical Phong's 1/cos θi; Lewis 1994).
//!
//! The albedo quadrature takes the original's peaks and kinks: the lobes of
//! the catalogue peak about the same mirror direction whichever of the two
//! directions is held (Phong's cosine lobe, a half-vector lobe, a Lafortune
//! lobe are symmetric in the pair), and the kinks only save work.

use crate::brdf::{Brdf, Claims, Kink};
use crate::{DeltaLobe, Rgb};
use glam::DVec3;
use std::sync::Arc;

/// `inner` with its two directions exchanged (see the module docs).
#[derive(Debug, Clone)]
pub struct Swapped(pub Arc<dyn Brdf>);

impl Brdf for Swapped {
    fn id(&self) -> &'static str {
        self.0.id()
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.0.eval(wo, wi)
    }

    /// Reciprocity and isotropy carry over; conservation of energy does not
    /// (it bounds ρhd, not ρdh), so it is not claimed.
    fn claims(&self) -> Claims {
        let c = self.0.claims();
        Claims {
            energy_conserving: false,
            ..c
        }
    }

    /// A mirror delta is symmetric in the pair: the same weight.
    fn deltas(&self, wi: DVec3) -> Vec<DeltaLobe> {
        self.0.deltas(wi)
    }

    fn transmits(&self) -> bool {
        self.0.transmits()
    }

    fn peaks(&self, wi: DVec3) -> Vec<DVec3> {
        self.0.peaks(wi)
    }

    fn kinks(&self, wi: DVec3) -> Vec<Kink<'_>> {
        self.0.kinks(wi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;
    use crate::analysis::quadrature::{QuadratureOptions, rho_hd_dir};
    use crate::{frame, mean_rgb};
    use serde_json::json;
    use std::f64::consts::PI;

    fn model(id: &str, p: serde_json::Value) -> Arc<dyn Brdf> {
        ModelSpec::from_json(id, &p)
            .unwrap()
            .build()
            .unwrap()
            .into()
    }

    /// ∫ f(ωi, ωo) cos θi dωi by a midpoint rule over (cos θ, φ) written
    /// here, for a smooth lobe.
    fn brute_rho_dh(f: &dyn Brdf, wo: DVec3) -> f64 {
        let (nt, np) = (600, 600);
        let mut s = 0.0;
        for i in 0..nt {
            let mu = (i as f64 + 0.5) / nt as f64;
            let st = (1.0 - mu * mu).sqrt();
            for j in 0..np {
                let p = (j as f64 + 0.5) / np as f64 * 2.0 * PI;
                let wi = DVec3::new(st * p.cos(), st * p.sin(), mu);
                s += mean_rgb(f.eval(wi, wo)) * mu;
            }
        }
        s * (1.0 / nt as f64) * (2.0 * PI / np as f64)
    }

    /// The swapped model's ρhd is the original's ρdh by brute force, for a
    /// reciprocal model and for classical Phong, whose ρdh differs from its
    /// ρhd (the 1/cos θi); and for a reciprocal model the two agree.
    #[test]
    fn swapped_albedo_is_the_hemispherical_directional_reflectance() {
        let opts = QuadratureOptions::default();
        for (id, p) in [
            ("cook-torrance", json!({"alpha": 0.4})),
            ("phong", json!({"e": 20.0})),
        ] {
            let f = model(id, p);
            let sw = Swapped(f.clone());
            for deg in [0.0, 30.0, 60.0, 80.0] {
                let wo = frame::from_spherical(f64::to_radians(deg), 0.3);
                let q = mean_rgb(rho_hd_dir(&sw, wo, &opts).value);
                let b = brute_rho_dh(f.as_ref(), wo);
                assert!((q - b).abs() < 2e-3 * b.max(0.1), "{id} {deg}°: {q} vs {b}");
                if f.claims().reciprocal {
                    let hd = mean_rgb(rho_hd_dir(f.as_ref(), wo, &opts).value);
                    assert!((q - hd).abs() < 1e-4, "{id} {deg}°: {q} vs {hd}");
                }
            }
        }
        // Classical Phong is not reciprocal: the curves part towards the
        // horizon, where its 1/cos θi meets the clipped lobe.
        let f = model("phong", json!({"e": 20.0, "kd": 0.0, "ks": 1.0}));
        let mut gap: f64 = 0.0;
        for deg in [0.0, 30.0, 60.0, 75.0, 85.0] {
            let wo = frame::from_spherical(f64::to_radians(deg), 0.0);
            let hd = mean_rgb(rho_hd_dir(f.as_ref(), wo, &opts).value);
            let dh = mean_rgb(rho_hd_dir(&Swapped(f.clone()), wo, &opts).value);
            gap = gap.max((hd - dh).abs());
        }
        assert!(gap > 0.01, "{gap}");
    }
}
