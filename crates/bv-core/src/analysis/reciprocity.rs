//! Helmholtz reciprocity: `f(wi, wo) = f(wo, wi)` for a physically based
//! reflection model . Measured as the largest channel difference
//! between the two orders, relative to the largest `f` seen over the set, so
//! that a value is meaningful whatever the model's scale.
//!
//! A model of an interface between two media ([`Brdf::interface_eta`])
//! carries radiance across it, compressed or spread by `(ηo/ηi)²`; its BSDF
//! obeys the generalised form `f(wi, wo)/ηo² = f(wo, wi)/ηi²` instead, with
//! ηi, ηo the indices on the sides of `wi` and `wo` (Veach 1997, §5.2,
//! eq. 5.14). For such a model both orders are divided by the square of the
//! index on their viewer's side before they are compared (and `max_f` is
//! the largest of these scaled values), so that a BTDF missing the η² factor
//! is reported non-reciprocal. On one side of the interface both indices are
//! the same and the form is the ordinary one.

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

/// `1/η²` of the medium on `w`'s side of an interface of relative index
/// `eta` (below over above); 1 without an interface.
fn inv_eta2(eta: Option<f64>, w: DVec3) -> f64 {
    match eta {
        Some(e) if w.z < 0.0 => 1.0 / (e * e),
        _ => 1.0,
    }
}

/// Compares `f(wi, wo)` with `f(wo, wi)` over `pairs` (in the generalised
/// form for an interface, see the module docs). Pairs where either value
/// is not finite are skipped (the positivity check counts them).
pub fn check(brdf: &dyn Brdf, pairs: &[(DVec3, DVec3)], threshold: f64) -> Reciprocity {
    let eta = brdf.interface_eta();
    let mut max_f = 0.0f64;
    let mut max_diff = 0.0f64;
    let mut worst = None;
    let mut compared = 0;
    for &(a, b) in pairs {
        // f(a → b)/η_b² and f(b → a)/η_a² (both 1 on one side).
        let fab = brdf.eval(a, b) * inv_eta2(eta, b);
        let fba = brdf.eval(b, a) * inv_eta2(eta, a);
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

    /// The rough dielectric's pairs on the whole sphere: above, across the
    /// surface (both orders, the check swaps) and below.
    fn sphere_pairs() -> Vec<(DVec3, DVec3)> {
        use crate::analysis::directions::{lower_pairs, transmission_pairs};
        let mut p = upper_pairs(1000, 4);
        p.extend(transmission_pairs(1000, 4));
        p.extend(lower_pairs(1000, 4));
        p
    }

    fn rough_dielectric(eta: f64) -> Box<dyn Brdf> {
        crate::ModelSpec::from_json(
            "rough-dielectric",
            &serde_json::json!({"alpha": 0.3, "eta": eta}),
        )
        .unwrap()
        .build()
        .unwrap()
    }

    /// A BTDF with its interface's η² handled wrongly: `Strip` forgets to
    /// tell the check about the interface, `Drop` divides the transmitted
    /// value by ηo² (Walter's eq. 21 without its ηo², the importance form:
    /// symmetric in the plain sense, wrong for radiance).
    #[derive(Debug)]
    struct Wrong(Box<dyn Brdf>, bool);
    impl Brdf for Wrong {
        fn id(&self) -> &'static str {
            "wrong-btdf"
        }
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            let f = self.0.eval(wi, wo);
            // ηo² is η² where the viewer is below (and 1 above).
            match (self.1, self.0.interface_eta()) {
                (true, Some(eta)) if wo.z < 0.0 && wi.z > 0.0 => f / (eta * eta),
                _ => f,
            }
        }
        fn claims(&self) -> Claims {
            self.0.claims()
        }
        fn transmits(&self) -> bool {
            true
        }
        fn interface_eta(&self) -> Option<f64> {
            if self.1 { self.0.interface_eta() } else { None }
        }
    }

    #[test]
    fn a_btdf_is_reciprocal_in_the_generalised_form() {
        for eta in [1.5, 0.6] {
            let b = rough_dielectric(eta);
            let r = check(b.as_ref(), &sphere_pairs(), 1e-6);
            assert!(r.reciprocal, "η {eta}: {r:?}");
            assert!(r.max_rel_err < 1e-9, "{}", r.max_rel_err);
            assert_eq!(r.pairs, 3000);
        }
    }

    #[test]
    fn a_btdf_without_the_eta_squared_factor_is_caught() {
        let pairs = sphere_pairs();
        // Eq. 21 without ηo²: f(wi, wo)/ηo² and f(wo, wi)/ηi² then differ
        // by (ηo/ηi)² across the interface.
        let r = check(&Wrong(rough_dielectric(1.5), true), &pairs, 1e-6);
        assert!(!r.reciprocal, "{r:?}");
        assert!(r.max_rel_err > 0.1, "{}", r.max_rel_err);
        let w = r.worst.unwrap();
        assert!((w.wi.z > 0.0) != (w.wo.z > 0.0), "{w:?}");
        // The correct BTDF compared in the plain form (no interface declared)
        // is not reciprocal either: the η² factor is what the generalised
        // form accounts for.
        let r = check(&Wrong(rough_dielectric(1.5), false), &pairs, 1e-6);
        assert!(!r.reciprocal && r.max_rel_err > 0.1, "{r:?}");
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
