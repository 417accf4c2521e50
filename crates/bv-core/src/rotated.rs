//! "If you turn an object around a point, does the shading change?" (seed,
//! "Surface Reflectance: isotropic vs. anisotropic"): a model with its
//! tangent frame turned about the normal by an angle. An isotropic model is
//! unchanged; an anisotropic one (Ward, Banks, Ashikhmin-Shirley) turns its
//! highlight with the frame.
//!
//! `f_rot(wi, wo) = f(R⁻¹ wi, R⁻¹ wo)` with `R` the rotation by `angle`
//! about `+z` (counter-clockwise seen from above, from `+x` towards `+y`).
//! Every method of [`Brdf`] is carried over through the same change of frame:
//! a rotation preserves solid angle, so densities carry over unchanged, and
//! sampled, delta and peak directions are rotated back by `R`.

use crate::{Brdf, Claims, DeltaLobe, Ndf, Rgb};
use glam::{DVec2, DVec3};
use std::sync::Arc;

/// A model seen through a tangent frame rotated by `angle` about the normal.
#[derive(Debug, Clone)]
pub struct Rotated {
    inner: Arc<dyn Brdf>,
    angle: f64,
    ndf: Option<RotatedNdf>,
}

/// The inner model's microfacet distribution in the rotated frame.
#[derive(Debug, Clone)]
struct RotatedNdf {
    inner: Arc<dyn Brdf>,
    cos: f64,
    sin: f64,
}

impl Ndf for RotatedNdf {
    fn d(&self, h: DVec3) -> f64 {
        self.inner
            .ndf()
            .map_or(0.0, |n| n.d(rotate(h, self.cos, -self.sin)))
    }

    /// The inner slopes when they are isotropic (a turn changes nothing);
    /// an anisotropic one turned is no longer aligned with x and y.
    fn slopes(&self) -> Option<(crate::microfacet::Distribution, f64, f64)> {
        let s = self.inner.ndf()?.slopes()?;
        (s.1 == s.2).then_some(s)
    }
}

#[inline]
fn rotate(w: DVec3, c: f64, s: f64) -> DVec3 {
    DVec3::new(c * w.x - s * w.y, s * w.x + c * w.y, w.z)
}

impl Rotated {
    /// `inner` with its tangent frame turned by `angle` radians about `+z`.
    pub fn new(inner: Arc<dyn Brdf>, angle: f64) -> Self {
        let (sin, cos) = angle.sin_cos();
        let ndf = inner.ndf().is_some().then(|| RotatedNdf {
            inner: inner.clone(),
            cos,
            sin,
        });
        Self { inner, angle, ndf }
    }

    /// The rotation angle (radians).
    pub fn angle(&self) -> f64 {
        self.angle
    }

    /// The model being rotated.
    pub fn inner(&self) -> &Arc<dyn Brdf> {
        &self.inner
    }

    /// `R w`: from the model's own frame to the rotated one.
    pub fn to_rotated(&self, w: DVec3) -> DVec3 {
        let (s, c) = self.angle.sin_cos();
        rotate(w, c, s)
    }

    /// `R⁻¹ w`: from the rotated frame to the model's own.
    pub fn to_inner(&self, w: DVec3) -> DVec3 {
        let (s, c) = self.angle.sin_cos();
        rotate(w, c, -s)
    }
}

impl Brdf for Rotated {
    /// The inner model's id: a rotated Ward is still Ward's formula.
    fn id(&self) -> &'static str {
        self.inner.id()
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.inner.eval(self.to_inner(wi), self.to_inner(wo))
    }

    /// Reciprocity, energy conservation and isotropy are all invariant
    /// under a common rotation of both directions.
    fn claims(&self) -> Claims {
        self.inner.claims()
    }

    fn claims_declared(&self) -> bool {
        self.inner.claims_declared()
    }

    fn deltas(&self, wi: DVec3) -> Vec<DeltaLobe> {
        self.inner
            .deltas(self.to_inner(wi))
            .into_iter()
            .map(|mut d| {
                d.direction = self.to_rotated(d.direction);
                d
            })
            .collect()
    }

    fn transmits(&self) -> bool {
        self.inner.transmits()
    }

    /// A turn about the normal keeps the two media and their indices.
    fn interface_eta(&self) -> Option<f64> {
        self.inner.interface_eta()
    }

    fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        self.inner
            .sample(self.to_inner(wi), u)
            .map(|w| self.to_rotated(w))
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        self.inner.pdf(self.to_inner(wi), self.to_inner(wo))
    }

    fn peaks(&self, wi: DVec3) -> Vec<DVec3> {
        self.inner
            .peaks(self.to_inner(wi))
            .into_iter()
            .map(|w| self.to_rotated(w))
            .collect()
    }

    fn pole(&self, wi: DVec3) -> Option<DVec3> {
        self.inner
            .pole(self.to_inner(wi))
            .map(|w| self.to_rotated(w))
    }

    fn kinks(&self, wi: DVec3) -> Vec<crate::Kink<'_>> {
        self.inner
            .kinks(self.to_inner(wi))
            .into_iter()
            .map(|k| -> crate::Kink<'_> { Box::new(move |wo| k(self.to_inner(wo))) })
            .collect()
    }

    fn transmission_support(&self, wi: DVec3) -> Vec<crate::Cone> {
        let mut cones = self.inner.transmission_support(self.to_inner(wi));
        for c in &mut cones {
            c.axis = self.to_rotated(c.axis);
        }
        cones
    }

    fn is_analytic(&self) -> bool {
        self.inner.is_analytic()
    }

    fn try_eval(&self, wi: DVec3, wo: DVec3) -> crate::Result<Rgb> {
        self.inner.try_eval(self.to_inner(wi), self.to_inner(wo))
    }

    fn health(&self) -> crate::EvalHealth {
        self.inner.health()
    }

    fn eval_cost(&self) -> Option<std::time::Duration> {
        self.inner.eval_cost()
    }

    fn limit_time(&self, budget: Option<std::time::Duration>) {
        self.inner.limit_time(budget);
    }

    fn ndf(&self) -> Option<&dyn Ndf> {
        self.ndf.as_ref().map(|n| n as &dyn Ndf)
    }

    /// The inner model's furnace lobe, turned the same way.
    fn furnace(&self) -> Option<Box<dyn Brdf>> {
        let f: Arc<dyn Brdf> = Arc::from(self.inner.furnace()?);
        Some(Box::new(Rotated::new(f, self.angle)))
    }

    // No batch kernel: the inner one would evaluate in the unrotated frame;
    // the default `eval_batch` goes through `eval`.

    /// The inner model's file data: a measured table is isotropic (the MERL
    /// layout ignores φh), so turning it changes nothing and views may upload
    /// the inner table as it is.
    fn file_data(&self) -> Option<Arc<dyn crate::model::FileData>> {
        self.inner.file_data()
    }

    /// A turn about the normal does not change the angle of incidence, so
    /// the Fresnel term is the inner model's.
    fn fresnel_term(&self) -> Option<crate::FresnelTerm> {
        self.inner.fresnel_term()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;
    use crate::analysis::directions::upper_pairs;
    use serde_json::json;
    use std::f64::consts::FRAC_PI_2;

    fn model(id: &str, p: serde_json::Value) -> Arc<dyn Brdf> {
        Arc::from(ModelSpec::from_json(id, &p).unwrap().build().unwrap())
    }

    fn max_rel_diff(a: &dyn Brdf, b: &dyn Brdf) -> f64 {
        let (mut d, mut m) = (0.0f64, 0.0f64);
        for (wi, wo) in upper_pairs(2000, 11) {
            let (fa, fb) = (a.eval(wi, wo), b.eval(wi, wo));
            d = d.max((fa - fb).abs().max_element());
            m = m.max(fa.max_element()).max(fb.max_element());
        }
        d / m
    }

    #[test]
    fn isotropic_models_do_not_change() {
        for b in [
            model("lambert", json!({"albedo": 0.6})),
            model(
                "cook-torrance",
                json!({"distribution": "ggx", "alpha": 0.3, "geometry": "smith"}),
            ),
        ] {
            let r = Rotated::new(b.clone(), 0.7);
            assert!(max_rel_diff(&r, b.as_ref()) < 1e-12, "{}", b.id());
            assert_eq!(r.claims(), b.claims());
        }
    }

    #[test]
    fn ward_turned_a_quarter_swaps_its_axes() {
        let ward = model(
            "ward",
            json!({"kd": 0.1, "ks": 0.3, "alpha_x": 0.1, "alpha_y": 0.4}),
        );
        let swapped = model(
            "ward",
            json!({"kd": 0.1, "ks": 0.3, "alpha_x": 0.4, "alpha_y": 0.1}),
        );
        // An anisotropic model changes when turned: with h tilted along the
        // tangent (tan θh = 0.15, φh = 0) Ward's specular exponent is
        // tan²θh/αx² = 2.25; turned by 0.6 rad, φh becomes −0.6 and it is
        // tan²θh (cos²0.6/αx² + sin²0.6/αy²) ≈ 1.58 (by hand).
        let h = DVec3::new(0.15, 0.0, 1.0).normalize();
        let wi = crate::frame::from_spherical(0.4, 0.0);
        let wo = crate::frame::reflect_about(wi, h);
        let spec = |b: &dyn Brdf| b.eval(wi, wo).x - 0.1 / std::f64::consts::PI;
        let turned = Rotated::new(ward.clone(), 0.6);
        let (c2, s2) = (0.6f64.cos().powi(2), 0.6f64.sin().powi(2));
        let want = (-(0.0225 * (c2 / 0.01 + s2 / 0.16)) + 2.25).exp();
        let ratio = spec(&turned) / spec(ward.as_ref());
        assert!(
            (ratio - want).abs() < 1e-9 * want && ratio > 1.9,
            "{ratio} vs {want}"
        );
        // ... and a quarter turn puts αy along the tangent: cos²φh ↔ sin²φh
        // in Ward's exponent.
        let r = Rotated::new(ward.clone(), FRAC_PI_2);
        assert!(max_rel_diff(&r, swapped.as_ref()) < 1e-9);
        // A half turn maps (x, y) → (−x, −y), which Ward's exponent does not see.
        let half = Rotated::new(ward.clone(), std::f64::consts::PI);
        assert!(max_rel_diff(&half, ward.as_ref()) < 1e-9);
    }

    #[test]
    fn sampling_and_density_follow_the_frame() {
        let ward = model(
            "ward",
            json!({"kd": 0.2, "ks": 0.5, "alpha_x": 0.1, "alpha_y": 0.4}),
        );
        let swapped = model(
            "ward",
            json!({"kd": 0.2, "ks": 0.5, "alpha_x": 0.4, "alpha_y": 0.1}),
        );
        let r = Rotated::new(ward.clone(), FRAC_PI_2);
        let mut rng = crate::sampling::rng(5);
        for (wi, wo) in upper_pairs(200, 3) {
            // The density of the rotated sampler is the swapped model's.
            let (a, b) = (r.pdf(wi, wo), swapped.pdf(wi, wo));
            assert!((a - b).abs() <= 1e-9 * b.max(1e-300), "{a} vs {b}");
            let u = crate::sampling::uniform2(&mut rng);
            if let Some(w) = r.sample(wi, u) {
                assert!((w.length() - 1.0).abs() < 1e-12);
                assert!(r.pdf(wi, w) > 0.0);
                // Drawn in the inner frame and turned back.
                let inner = ward.sample(r.to_inner(wi), u).unwrap();
                assert!((r.to_rotated(inner) - w).length() < 1e-15);
            }
        }
    }

    #[test]
    fn ndf_and_deltas_are_rotated() {
        let ct = model(
            "cook-torrance",
            json!({"distribution": "beckmann", "alpha_x": 0.1, "alpha_y": 0.5}),
        );
        let sw = model(
            "cook-torrance",
            json!({"distribution": "beckmann", "alpha_x": 0.5, "alpha_y": 0.1}),
        );
        let r = Rotated::new(ct, FRAC_PI_2);
        let h = DVec3::new(0.3, 0.1, 0.9).normalize();
        let (a, b) = (r.ndf().unwrap().d(h), sw.ndf().unwrap().d(h));
        assert!((a - b).abs() < 1e-12 * b, "{a} vs {b}");
        assert!(
            Rotated::new(model("lambert", json!({})), 1.0)
                .ndf()
                .is_none()
        );
        // A mirror's spike stays the mirror direction of wi in any frame.
        let m = Rotated::new(model("mirror", json!({})), 0.9);
        let wi = DVec3::new(0.3, -0.4, 0.866).normalize();
        let d = m.deltas(wi);
        assert_eq!(d.len(), 1);
        assert!((d[0].direction - crate::frame::reflect(wi)).length() < 1e-15);
    }
}
