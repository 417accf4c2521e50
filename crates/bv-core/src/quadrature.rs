//! Gauss–Legendre quadrature, the one implementation bv-core uses: nodes and
//! weights on [−1, 1] ([`gauss_legendre`]) and composite integration over an
//! interval ([`integrate`]). The microfacet normalisations, the SH
//! projections' rings and the sampling histograms' bin integrals all take
//! their nodes from here.

use std::f64::consts::PI;

/// Gauss–Legendre nodes and weights on [−1, 1], exact for polynomials of
/// degree ≤ 2n − 1: Newton iteration on `P_n` from Tricomi's initial guess
/// `cos(π (i + 3/4) / (n + 1/2))` (the leading term of Tricomi's expansion),
/// `P_n` and `P_n'` by the three-term recurrence, weights
/// `2 / ((1 − x²) P_n'(x)²)`. Newton converges quadratically from that
/// guess; it stops when a step is below 1e-15 (the nodes are then exact to
/// the last bit or two).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0f64, x);
            for k in 2..=n {
                let kf = k as f64;
                (p0, p1) = (p1, ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf);
            }
            // n ≥ 1 here: P_n = p1, P_{n−1} = p0 (P_0 = 1 when n = 1).
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-15 {
                break;
            }
        }
        out.push((x, 2.0 / ((1.0 - x * x) * dp * dp)));
    }
    out
}

/// Integral of `f` over `[a, b]` by composite Gauss–Legendre (`panels` equal
/// panels of `gl` nodes each).
pub fn integrate(f: impl Fn(f64) -> f64, a: f64, b: f64, panels: usize, gl: &[(f64, f64)]) -> f64 {
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for p in 0..panels {
        let lo = a + p as f64 * h;
        for &(x, w) in gl {
            sum += w * f(lo + 0.5 * h * (x + 1.0));
        }
    }
    sum * 0.5 * h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_three_points() {
        // Nodes 0, ±√(3/5), weights 8/9, 5/9 (hand-derived from P3 = (5x³ − 3x)/2).
        let mut g = gauss_legendre(3);
        g.sort_by(|a, b| a.0.total_cmp(&b.0));
        let r = (0.6f64).sqrt();
        let want = [(-r, 5.0 / 9.0), (0.0, 8.0 / 9.0), (r, 5.0 / 9.0)];
        for (a, b) in g.iter().zip(want) {
            assert!((a.0 - b.0).abs() < 1e-14 && (a.1 - b.1).abs() < 1e-14);
        }
        // 64 nodes integrate x^126 exactly: 2/127.
        let s: f64 = gauss_legendre(64)
            .iter()
            .map(|(x, w)| w * x.powi(126))
            .sum();
        assert!((s - 2.0 / 127.0).abs() < 1e-13, "{s}");
    }

    #[test]
    fn one_node_is_the_midpoint_rule_and_panels_add_up() {
        assert_eq!(gauss_legendre(1), vec![(0.0, 2.0)]);
        assert!(gauss_legendre(0).is_empty());
        // ∫₀^π sin = 2 by 4 panels of 8 nodes.
        let s = integrate(f64::sin, 0.0, PI, 4, &gauss_legendre(8));
        assert!((s - 2.0).abs() < 1e-14, "{s}");
    }
}
