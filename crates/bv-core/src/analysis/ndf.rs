//! D normalisation: a microfacet distribution must satisfy
//! `∫ D(h) cos θh dωh = 1` (the projected microfacet area equals the
//! macro-surface area; Walter et al. 2007, eq. 4; SPEC §2).
//!
//! Computed as `∫₀^{2π} ∫₀^{π/2} D(θ, φ) cos θ sin θ dθ dφ` by nested global
//! adaptive Gauss–Kronrod (7/15) quadrature. The θ axis starts from
//! geometrically shrinking panels towards θ = 0 (down to 1e-4 rad), so a lobe
//! of width α = 0.001 is resolved from the first pass; the φ axis starts from
//! eight panels with breaks at the axes, where anisotropic lobes peak. The
//! error estimate is the usual `|K15 − G7|` per panel (pessimistic for smooth
//! integrands), plus the inner integrals' errors carried through the outer
//! rule's weights.

use crate::Ndf;
use crate::frame;
use glam::DVec3;
use serde::Serialize;
use std::cmp::Ordering;
use std::collections::BinaryHeap;
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

/// Kronrod nodes (non-negative half) of the 15-point rule, and weights.
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
/// Gauss 7-point weights, at the odd Kronrod nodes (XGK[1], XGK[3], XGK[5], 0).
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// One GK15 panel of an integrand returning `(value, error of the value)`:
/// `(K15, |K15 − G7| + Σ wK · error)`.
fn gk15(f: &mut impl FnMut(f64) -> (f64, f64), a: f64, b: f64) -> (f64, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let mut k = 0.0;
    let mut g = 0.0;
    let mut inner = 0.0;
    for i in 0..8 {
        let pts: &[f64] = if i == 7 {
            &[c]
        } else {
            &[c - h * XGK[i], c + h * XGK[i]]
        };
        for &x in pts {
            let (v, e) = f(x);
            k += WGK[i] * v;
            inner += WGK[i] * e;
            if i % 2 == 1 {
                g += WG[i / 2] * v;
            }
        }
    }
    (k * h, ((k - g) * h).abs() + inner * h)
}

#[derive(Debug, Clone, Copy)]
struct Panel {
    a: f64,
    b: f64,
    value: f64,
    error: f64,
}

impl PartialEq for Panel {
    fn eq(&self, o: &Self) -> bool {
        self.error.total_cmp(&o.error) == Ordering::Equal
    }
}
impl Eq for Panel {}
impl PartialOrd for Panel {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Panel {
    fn cmp(&self, o: &Self) -> Ordering {
        self.error.total_cmp(&o.error)
    }
}

/// Global adaptive GK15 over the panels between consecutive `breaks`: bisects
/// the panel with the largest error until the total error is at most
/// `rel_tol · |value|` or `max_panels` panels exist. Returns
/// `(value, error, evaluations)`.
fn adaptive(
    f: &mut impl FnMut(f64) -> (f64, f64),
    breaks: &[f64],
    rel_tol: f64,
    max_panels: usize,
) -> (f64, f64, usize) {
    let mut heap = BinaryHeap::new();
    let mut evals = 0;
    for w in breaks.windows(2) {
        let (value, error) = gk15(f, w[0], w[1]);
        evals += 15;
        heap.push(Panel {
            a: w[0],
            b: w[1],
            value,
            error,
        });
    }
    loop {
        let value: f64 = heap.iter().map(|p| p.value).sum();
        let error: f64 = heap.iter().map(|p| p.error).sum();
        let done = error <= rel_tol * value.abs() || !error.is_finite();
        if done || heap.len() >= max_panels {
            return (value, error, evals);
        }
        let Some(p) = heap.pop() else {
            return (value, error, evals);
        };
        let m = 0.5 * (p.a + p.b);
        if m <= p.a || m >= p.b {
            // Cannot bisect further in floating point: keep the panel and stop.
            heap.push(p);
            let value: f64 = heap.iter().map(|p| p.value).sum();
            let error: f64 = heap.iter().map(|p| p.error).sum();
            return (value, error, evals);
        }
        for (a, b) in [(p.a, m), (m, p.b)] {
            let (value, error) = gk15(f, a, b);
            evals += 15;
            heap.push(Panel { a, b, value, error });
        }
    }
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
    let mut evals = 0usize;
    let mut outer = |phi: f64| {
        let mut inner = |theta: f64| {
            let h = frame::from_spherical(theta, phi);
            // dω = sin θ dθ dφ.
            (g(h) * theta.sin(), 0.0)
        };
        let (v, e, n) = adaptive(&mut inner, &theta_breaks, rel_tol * 0.1, inner_panels);
        evals += n;
        (v, e)
    };
    let (value, error, _) = adaptive(&mut outer, &phi_breaks, rel_tol, outer_panels);
    Quadrature {
        value,
        error,
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
