//! D normalisation: a microfacet distribution must satisfy
//! `∫ D(h) cos θh dωh = 1` (the projected microfacet area equals the
//! macro-surface area; Walter et al. 2007, eq. 4).
//!
//! Computed as `∫₀^{2π} ∫₀^{π/2} D(θ, φ) cos θ sin θ dθ dφ` by nested global
//! adaptive Gauss–Kronrod (7/15) quadrature. The θ axis starts from
//! geometrically shrinking panels towards θ = 0 (down to 1e-4 rad), so a lobe
//! of width α = 0.001 is resolved from the first pass; the φ axis starts from
//! eight panels with breaks at the axes, where anisotropic lobes peak. The
//! error estimate is the usual `|K15 − G7|` per panel (pessimistic for smooth
//! integrands), plus the inner integrals' errors carried through the outer
//! rule's weights.

use super::gauss_kronrod;
use crate::Ndf;
use crate::frame;
use glam::DVec3;
use serde::Serialize;
use std::f64::consts::{FRAC_PI_2, PI};

/// Result of a quadrature.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Quadrature {
    /// The integral.
    pub value: f64,
    /// Estimated absolute error.
    pub error: f64,
    /// Integrand evaluations used.
    pub evaluations: usize,
}

/// `∫ g(h) dωh` over the upper hemisphere for an integrand peaked at the
/// normal (see the module docs for the rule). `rel_tol` is the target relative
/// error of the outer integral; `max_evals` bounds the work (about).
pub fn integrate_hemisphere(
    g: impl Fn(DVec3) -> f64,
    rel_tol: f64,
    max_evals: usize,
) -> Quadrature {
    // θ breaks: 0, (π/2)·2^−k for k = 14..0 (the smallest panel is 9.6e-5 rad).
    let mut theta_breaks = vec![0.0];
    theta_breaks.extend((0..=14).rev().map(|k| FRAC_PI_2 / f64::from(1u32 << k)));
    let phi_breaks: Vec<f64> = (0..=8).map(|k| PI / 4.0 * k as f64).collect();
    // Panel budgets: inner rules are nested in outer ones, so split the budget.
    let inner_panels = 400usize;
    let outer_panels = (max_evals / (15 * 15 * 40)).clamp(8, 2000);
    let theta_segs = gauss_kronrod::segments(&theta_breaks, false, false);
    let phi_segs = gauss_kronrod::segments(&phi_breaks, false, false);
    let mut evals = 0usize;
    let mut outer = |phi: f64| {
        let mut inner = |theta: f64| {
            let h = frame::from_spherical(theta, phi);
            // dω = sin θ dθ dφ.
            (g(h) * theta.sin(), 0.0)
        };
        let r = gauss_kronrod::integrate(
            &mut inner,
            &theta_segs,
            0.0,
            rel_tol * 0.1,
            inner_panels,
            false,
        );
        evals += r.evaluations;
        (r.value, r.error)
    };
    let r = gauss_kronrod::integrate(&mut outer, &phi_segs, 0.0, rel_tol, outer_panels, false);
    Quadrature {
        value: r.value,
        error: r.error,
        evaluations: evals,
    }
}

/// `∫ D(h) cos θh dωh`, which is 1 for a normalised distribution.
pub fn normalisation(ndf: &dyn Ndf, rel_tol: f64, max_evals: usize) -> Quadrature {
    integrate_hemisphere(|h| ndf.d(h) * h.z, rel_tol, max_evals)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Anisotropic GGX (Walter et al. 2007 eq. 33; Heitz 2014 eq. 85).
    struct Ggx(f64, f64);
    impl Ndf for Ggx {
        fn d(&self, h: DVec3) -> f64 {
            if h.z <= 0.0 {
                return 0.0;
            }
            let (ax, ay) = (self.0, self.1);
            let c2 = h.z * h.z;
            let e = (h.x * h.x / (ax * ax) + h.y * h.y / (ay * ay)) / c2;
            1.0 / (PI * ax * ay * c2 * c2 * (1.0 + e).powi(2))
        }
    }

    /// Anisotropic Beckmann, optionally missing its 1/π as in the seed.
    struct Beckmann(f64, f64, bool);
    impl Ndf for Beckmann {
        fn d(&self, h: DVec3) -> f64 {
            if h.z <= 0.0 {
                return 0.0;
            }
            let (ax, ay) = (self.0, self.1);
            let c2 = h.z * h.z;
            let e = (h.x * h.x / (ax * ax) + h.y * h.y / (ay * ay)) / c2;
            let pi = if self.2 { 1.0 } else { PI };
            (-e).exp() / (pi * ax * ay * c2 * c2)
        }
    }

    fn check_one(ndf: &dyn Ndf, want: f64, what: &str) {
        let q = normalisation(ndf, 1e-9, 4_000_000);
        assert!(
            (q.value - want).abs() <= q.error.max(1e-12) * 10.0 && q.error < 1e-6,
            "{what}: {q:?}"
        );
        assert!(q.evaluations > 0);
    }

    #[test]
    fn ggx_and_beckmann_are_normalised_even_when_sharp() {
        // Both integrate to exactly 1 (derivation: substitute t = tan²θ).
        for (ax, ay) in [
            (0.5, 0.5),
            (0.001, 0.001),
            (0.001, 2.0),
            (2.0, 2.0),
            (0.05, 0.3),
        ] {
            check_one(&Ggx(ax, ay), 1.0, &format!("GGX {ax} {ay}"));
        }
        for (ax, ay) in [(0.5, 0.5), (0.001, 0.001), (0.001, 1.0), (0.05, 0.3)] {
            check_one(
                &Beckmann(ax, ay, false),
                1.0,
                &format!("Beckmann {ax} {ay}"),
            );
        }
    }

    #[test]
    fn the_seeds_beckmann_without_pi_is_caught() {
        // The seed's 1/(m² cos⁴α) integrates to π.
        check_one(&Beckmann(0.2, 0.2, true), PI, "seed Beckmann");
    }

    #[test]
    fn cosine_power_hemisphere_integrals() {
        // ∫ cos^n θ dω = 2π/(n+1).
        for n in [1.0, 4.0, 1000.0] {
            let q = integrate_hemisphere(|h| h.z.powf(n), 1e-10, 2_000_000);
            let want = 2.0 * PI / (n + 1.0);
            assert!((q.value - want).abs() < 1e-9 * want, "{n}: {q:?}");
            assert!(q.error >= (q.value - want).abs() * 0.1 || q.error < 1e-12);
        }
    }
}
