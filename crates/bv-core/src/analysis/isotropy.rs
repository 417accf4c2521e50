//! Isotropy: an isotropic BRDF depends on `wi` and `wo` only through θi, θo
//! and φi − φo, so rotating both about the normal by a common angle leaves it
//! unchanged .

use super::PairSample;
use super::directions::stream_seed;
use crate::{Brdf, sampling};
use glam::DVec3;
use rand::Rng;
use serde::Serialize;
use std::f64::consts::PI;

/// What the isotropy check found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Isotropy {
    /// Number of pairs compared (each against one random common rotation).
    pub pairs: usize,
    /// `max |f(Rz wi, Rz wo) − f(wi, wo)| / max f` over the set and channels.
    pub max_rel_change: f64,
    /// Threshold of the verdict.
    pub threshold: f64,
    /// The unrotated pair with the largest change; `f_swapped` holds the
    /// value after rotation.
    pub worst: Option<PairSample>,
    /// Rotation angle of the worst pair (degrees).
    pub worst_rotation_deg: f64,
    /// Verdict: `max_rel_change ≤ threshold`.
    pub isotropic: bool,
}

/// Rotation about the normal (+z) by `a` radians.
fn rotate_z(w: DVec3, a: f64) -> DVec3 {
    let (s, c) = a.sin_cos();
    DVec3::new(c * w.x - s * w.y, s * w.x + c * w.y, w.z)
}

/// Compares `f` at each pair with `f` after rotating both directions about the
/// normal by a fixed-seed random angle.
pub fn check(brdf: &dyn Brdf, pairs: &[(DVec3, DVec3)], threshold: f64, seed: u64) -> Isotropy {
    let mut rng = sampling::rng(stream_seed(seed, 0x1505));
    let mut max_f = 0.0f64;
    let mut max_diff = 0.0f64;
    let mut worst = None;
    let mut worst_rotation_deg = 0.0;
    let mut compared = 0;
    for &(a, b) in pairs {
        let angle = rng.random_range(0.0..2.0 * PI);
        let f0 = brdf.eval(a, b);
        let f1 = brdf.eval(rotate_z(a, angle), rotate_z(b, angle));
        if !f0.is_finite() || !f1.is_finite() {
            continue;
        }
        compared += 1;
        max_f = max_f.max(f0.max_element()).max(f1.max_element());
        let d = (f0 - f1).abs().max_element();
        if d > max_diff || worst.is_none() {
            max_diff = max_diff.max(d);
            worst = Some(PairSample::new(a, b, f0, f1));
            worst_rotation_deg = angle.to_degrees();
        }
    }
    let max_rel_change = if max_f > 0.0 { max_diff / max_f } else { 0.0 };
    Isotropy {
        pairs: compared,
        max_rel_change,
        threshold,
        worst,
        worst_rotation_deg,
        isotropic: max_rel_change <= threshold,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::directions::upper_pairs;
    use crate::models::lambert::Lambert;
    use crate::{Claims, Rgb};

    /// A fibre-like model that depends on the tangent component of `wi`.
    #[derive(Debug)]
    struct Fibre;
    impl Brdf for Fibre {
        fn id(&self) -> &'static str {
            "fibre"
        }
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            if wi.z <= 0.0 || wo.z <= 0.0 {
                return Rgb::ZERO;
            }
            Rgb::splat((1.0 - wi.x * wi.x).sqrt() * (1.0 - wo.x * wo.x).sqrt())
        }
        fn claims(&self) -> Claims {
            Claims {
                reciprocal: true,
                energy_conserving: true,
                isotropic: false,
            }
        }
    }

    /// Depends on φi − φo only (through wi·wo): isotropic.
    #[derive(Debug)]
    struct PhaseOnly;
    impl Brdf for PhaseOnly {
        fn id(&self) -> &'static str {
            "phase-only"
        }
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            if wi.z <= 0.0 || wo.z <= 0.0 {
                return Rgb::ZERO;
            }
            Rgb::splat(1.0 + wi.dot(wo))
        }
        fn claims(&self) -> Claims {
            Claims {
                reciprocal: true,
                energy_conserving: false,
                isotropic: true,
            }
        }
    }

    #[test]
    fn isotropic_models_pass() {
        let pairs = upper_pairs(2000, 4);
        let r = check(&Lambert::new(Rgb::splat(0.3)), &pairs, 1e-6, 1);
        assert_eq!(r.max_rel_change, 0.0);
        assert!(r.isotropic);
        let r = check(&PhaseOnly, &pairs, 1e-6, 1);
        // Rounding only: wi·wo is invariant up to a few ulps.
        assert!(r.max_rel_change < 1e-14, "{}", r.max_rel_change);
        assert!(r.isotropic);
    }

    #[test]
    fn anisotropic_model_is_detected() {
        let r = check(&Fibre, &upper_pairs(2000, 4), 1e-6, 1);
        assert!(!r.isotropic);
        // f ∈ [0, 1]; rotating a pair along x (f ≈ 0) onto y (f ≈ 1) changes it by
        // nearly 1.
        assert!(r.max_rel_change > 0.5, "{}", r.max_rel_change);
    }
}
