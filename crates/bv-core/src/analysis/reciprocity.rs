//! Helmholtz reciprocity: `f(wi, wo) = f(wo, wi)` for a physically based
//! reflection model . Measured as the largest channel difference
//! between the two orders, relative to the largest `f` seen over the set, so
//! that a value is meaningful whatever the model's scale.

use super::PairSample;
use crate::Brdf;
use glam::DVec3;
use serde::Serialize;

/// What the reciprocity check found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reciprocity {
    /// Number of `(wi, wo)` pairs compared (two evaluations each).
    pub pairs: usize,
    /// Largest finite channel value of `f` over the set (1/sr).
    pub max_f: f64,
    /// `max |f(wi,wo) − f(wo,wi)| / max_f` over the set and the channels (0 when
    /// `f` vanishes on the whole set).
    pub max_rel_err: f64,
    /// Threshold of the verdict.
    pub threshold: f64,
    /// The pair with the largest difference.
    pub worst: Option<PairSample>,
    /// Verdict: `max_rel_err ≤ threshold`.
    pub reciprocal: bool,
}

/// Compares `f(wi, wo)` with `f(wo, wi)` over `pairs`. Pairs where either value
/// is not finite are skipped (the positivity check counts them).
pub fn check(brdf: &dyn Brdf, pairs: &[(DVec3, DVec3)], threshold: f64) -> Reciprocity {
    let mut max_f = 0.0f64;
    let mut max_diff = 0.0f64;
    let mut worst = None;
    let mut compared = 0;
    for &(a, b) in pairs {
        let fab = brdf.eval(a, b);
        let fba = brdf.eval(b, a);
        if !fab.is_finite() || !fba.is_finite() {
            continue;
        }
        compared += 1;
        max_f = max_f.max(fab.max_element()).max(fba.max_element());
        let d = (fab - fba).abs().max_element();
        if d > max_diff || worst.is_none() {
            max_diff = max_diff.max(d);
            worst = Some(PairSample::new(a, b, fab, fba));
        }
    }
    let max_rel_err = if max_f > 0.0 { max_diff / max_f } else { 0.0 };
    Reciprocity {
        pairs: compared,
        max_f,
        max_rel_err,
        threshold,
        worst,
        reciprocal: max_rel_err <= threshold,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::directions::upper_pairs;
    use crate::models::lambert::Lambert;
    use crate::{Claims, Rgb};

    /// Seed-style Phong lobe with the `1/cos θi` factor: not reciprocal.
    #[derive(Debug)]
    struct OneOverCosI;
    impl Brdf for OneOverCosI {
        fn id(&self) -> &'static str {
            "one-over-cos-i"
        }
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            if wi.z <= 0.0 || wo.z <= 0.0 {
                return Rgb::ZERO;
            }
            Rgb::splat(0.1 * wo.z / wi.z.max(0.01))
        }
        fn claims(&self) -> Claims {
            Claims {
                reciprocal: false,
                energy_conserving: false,
                isotropic: true,
            }
        }
    }

    #[test]
    fn lambert_is_exactly_reciprocal() {
        let r = check(
            &Lambert::new(Rgb::new(0.2, 0.5, 0.9)),
            &upper_pairs(2000, 9),
            1e-6,
        );
        assert_eq!(r.max_rel_err, 0.0);
        assert!(r.reciprocal);
        assert_eq!(r.pairs, 2000);
    }

    #[test]
    fn a_non_reciprocal_model_is_detected() {
        let r = check(&OneOverCosI, &upper_pairs(2000, 9), 1e-6);
        assert!(!r.reciprocal);
        // f ranges up to 0.1 · 1 / 0.01 = 10; the swapped order of that pair is
        // 0.1 · 0.01 / 1, so the relative error approaches (10 − 0.001)/10.
        assert!(
            r.max_rel_err > 0.9 && r.max_rel_err <= 1.0,
            "{}",
            r.max_rel_err
        );
        let w = r.worst.unwrap();
        assert!((w.f - w.f_swapped).abs().max_element() > 1.0);
    }
}
