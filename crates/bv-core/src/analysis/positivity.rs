//! Positivity: a BRDF is a density of scattered radiance, so it must be finite
//! and non-negative everywhere .

use super::PairSample;
use crate::{Brdf, Rgb};
use glam::DVec3;
use serde::Serialize;

/// What the positivity check found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Positivity {
    /// Number of `f` evaluations (each an RGB triple).
    pub evaluations: usize,
    /// Smallest finite channel value seen (1/sr).
    pub min_f: f64,
    /// Evaluations with at least one negative channel.
    pub negative: usize,
    /// Evaluations with at least one NaN or infinite channel.
    pub non_finite: usize,
    /// Where the smallest value (or the first non-finite one) was found.
    pub worst: Option<PairSample>,
    /// Verdict: no negative and no non-finite value.
    pub ok: bool,
}

/// Evaluates `f` over `pairs` in both orders (`f(wi, wo)` and `f(wo, wi)`) and
/// over `extra` (e.g. transmission pairs) in the given order.
pub fn check(brdf: &dyn Brdf, pairs: &[(DVec3, DVec3)], extra: &[(DVec3, DVec3)]) -> Positivity {
    let mut out = Positivity {
        evaluations: 0,
        min_f: f64::INFINITY,
        negative: 0,
        non_finite: 0,
        worst: None,
        ok: true,
    };
    let mut first_bad: Option<PairSample> = None;
    let mut visit = |wi: DVec3, wo: DVec3| {
        // The value as the model computed it: a model that reads NaN as 0
        // in `eval` (a user's shader) shows it here. An evaluation that
        // fails goes through `eval`, which records it in the model's
        // health for the caller to report.
        let f: Rgb = match brdf.try_eval(wi, wo) {
            Ok(f) => f,
            Err(_) => brdf.eval(wi, wo),
        };
        out.evaluations += 1;
        if !f.is_finite() {
            out.non_finite += 1;
            if first_bad.is_none() {
                first_bad = Some(PairSample::new(wi, wo, f, f));
            }
            return;
        }
        let m = f.min_element();
        if m < 0.0 {
            out.negative += 1;
        }
        if m < out.min_f {
            out.min_f = m;
            out.worst = Some(PairSample::new(wi, wo, f, f));
        }
    };
    for &(a, b) in pairs {
        visit(a, b);
        visit(b, a);
    }
    for &(a, b) in extra {
        visit(a, b);
    }
    if first_bad.is_some() {
        out.worst = first_bad;
    }
    if !out.min_f.is_finite() {
        // Nothing finite at all (or nothing evaluated).
        out.min_f = f64::NAN;
    }
    out.ok = out.non_finite == 0 && out.negative == 0 && out.evaluations > 0;
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Claims;
    use crate::analysis::directions::upper_pairs;
    use crate::models::lambert::Lambert;

    /// A deliberately broken model: negative below 30° and NaN at the normal.
    #[derive(Debug)]
    struct Broken;
    impl Brdf for Broken {
        fn id(&self) -> &'static str {
            "broken"
        }
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            if wi == DVec3::Z {
                return Rgb::splat(f64::NAN);
            }
            Rgb::new(wo.z - 0.5, 0.1, 0.1) + Rgb::splat(0.0 * wi.z)
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
    fn lambert_is_positive() {
        let p = check(&Lambert::new(Rgb::splat(0.5)), &upper_pairs(1000, 1), &[]);
        assert!(p.ok);
        assert_eq!(p.evaluations, 2000);
        assert!((p.min_f - 0.5 / std::f64::consts::PI).abs() < 1e-15);
    }

    #[test]
    fn negative_and_nan_values_are_caught() {
        let pairs = upper_pairs(1000, 1);
        let p = check(&Broken, &pairs, &[]);
        assert!(!p.ok);
        assert!(p.negative > 0);
        // Pairs with wi on the normal exist in the set (5 % have one end there).
        assert!(p.non_finite > 0);
        // min f = min over wo of (wo.z − 0.5); grazing wo make it close to −0.5.
        assert!(p.min_f < -0.49 && p.min_f >= -0.5, "{}", p.min_f);
        assert!(p.worst.is_some());
    }
}
