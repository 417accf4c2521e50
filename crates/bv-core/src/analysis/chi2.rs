//! Pearson's χ² goodness-of-fit test of observed counts against expected
//! counts, with the usual pooling of cells whose expected count is small
//! (as in the χ² sampling tests of Mitsuba and PBRT-v4: cells below the
//! threshold are gathered into one pooled cell), and its p-value from the
//! regularised upper incomplete gamma function.

/// The outcome of a χ² test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChiSquare {
    /// Pearson's statistic `Σ (O − E)² / E` over the cells after pooling
    /// (+∞ when a cell with `E = 0` was observed).
    pub statistic: f64,
    /// Degrees of freedom: cells after pooling minus one.
    pub dof: usize,
    /// `P(χ²_dof ≥ statistic)`: small values reject the hypothesis that the
    /// counts follow the expected distribution. 1 when `dof = 0`.
    pub p_value: f64,
    /// How many of the input cells went into the pooled cell.
    pub pooled_cells: usize,
    /// Observed counts in cells whose expected count is exactly 0.
    pub impossible: u64,
}

/// Pearson's χ² test of `observed` against `expected` (same length).
/// Cells are visited in increasing order of `E`; cells with `E < min_expected`
/// (5 is the textbook choice) are added to a pooled cell until the pool
/// reaches `min_expected`, and the pool counts as one cell. Counts seen
/// where `E = 0` make the statistic infinite and the p-value 0: the sampler
/// produced something its density says is impossible.
pub fn chi_square(observed: &[u64], expected: &[f64], min_expected: f64) -> ChiSquare {
    let mut order: Vec<usize> = (0..observed.len().min(expected.len())).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut stat, mut cells) = (0.0, 0usize);
    let (mut pool_o, mut pool_e, mut pooled) = (0.0, 0.0, 0usize);
    let mut impossible = 0u64;
    for &i in &order {
        let (o, e) = (observed[i] as f64, expected[i].max(0.0));
        if e == 0.0 {
            impossible += observed[i];
        } else if e < min_expected || (pool_e > 0.0 && pool_e < min_expected) {
            pool_o += o;
            pool_e += e;
            pooled += 1;
        } else {
            stat += (o - e) * (o - e) / e;
            cells += 1;
        }
    }
    if pool_e > 0.0 {
        stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        cells += 1;
    }
    let dof = cells.saturating_sub(1);
    if impossible > 0 {
        return ChiSquare {
            statistic: f64::INFINITY,
            dof,
            p_value: 0.0,
            pooled_cells: pooled,
            impossible,
        };
    }
    ChiSquare {
        statistic: stat,
        dof,
        p_value: if dof == 0 {
            1.0
        } else {
            chi_square_sf(stat, dof as f64)
        },
        pooled_cells: pooled,
        impossible,
    }
}

/// Survival function of the χ² distribution with `dof` degrees of freedom,
/// `P(X ≥ x) = Q(dof/2, x/2)`.
pub fn chi_square_sf(x: f64, dof: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    gamma_q(0.5 * dof, 0.5 * x)
}

/// `ln Γ(x)` for `x > 0` (Lanczos, g = 7, 9 terms; relative error ~1e-15).
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x) Γ(1 − x) = π / sin(πx).
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularised upper incomplete gamma function `Q(a, x) = Γ(a, x)/Γ(a)`:
/// the series for `P = 1 − Q` when `x < a + 1`, Lentz's continued fraction
/// for `Q` otherwise (Numerical Recipes, 3rd ed., §6.2).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if a.is_nan() || a <= 0.0 || x.is_nan() {
        return f64::NAN;
    }
    if x <= 0.0 {
        return 1.0;
    }
    if x.is_infinite() {
        return 0.0;
    }
    let lead = a * x.ln() - x - ln_gamma(a);
    if x < a + 1.0 {
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * lead.exp()).max(0.0)
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (lead.exp() * h).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ln_gamma_at_integers_and_half() {
        // Γ(n) = (n − 1)!, Γ(½) = √π.
        let mut fact = 1.0f64;
        for n in 1..20 {
            assert!((ln_gamma(n as f64) - fact.ln()).abs() < 1e-13, "{n}");
            fact *= n as f64;
        }
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-14);
        assert!((ln_gamma(0.1) - 9.513_507_698_668_732f64.ln()).abs() < 1e-13);
    }

    #[test]
    fn survival_function_closed_forms() {
        for x in [0.01, 0.5, 1.0, 3.84, 10.0, 40.0, 200.0] {
            // dof 2: P(X ≥ x) = e^{−x/2}.
            let p2 = chi_square_sf(x, 2.0);
            let want = (-0.5 * x).exp();
            assert!((p2 - want).abs() <= 1e-12 * want, "{x}: {p2} vs {want}");
            // dof 1: erfc(√(x/2)).
            let p1 = chi_square_sf(x, 1.0);
            let want = libm::erfc((0.5 * x).sqrt());
            assert!((p1 - want).abs() <= 1e-12 * want, "{x}: {p1} vs {want}");
            // dof 4: e^{−x/2}(1 + x/2).
            let p4 = chi_square_sf(x, 4.0);
            let want = (-0.5 * x).exp() * (1.0 + 0.5 * x);
            assert!((p4 - want).abs() <= 1e-12 * want, "{x}: {p4} vs {want}");
        }
        // The 95 % point of χ²₁ is 3.841.
        assert!((chi_square_sf(3.841_458_820_694_124, 1.0) - 0.05).abs() < 1e-12);
        assert_eq!(chi_square_sf(0.0, 3.0), 1.0);
    }

    #[test]
    fn pearson_statistic_and_pooling() {
        // Hand example: O = (10, 20, 30), E = (20, 20, 20):
        // χ² = 100/20 + 0 + 100/20 = 10, dof 2, p = e^{−5}.
        let r = chi_square(&[10, 20, 30], &[20.0, 20.0, 20.0], 5.0);
        assert!((r.statistic - 10.0).abs() < 1e-14 && r.dof == 2);
        assert!((r.p_value - (-5.0f64).exp()).abs() < 1e-15);
        // Small cells pool: E = (1, 2, 3, 50), O = (0, 4, 3, 49). Sorted, 1 and 2
        // go to the pool (3 < 5), then 3 joins it (pool 3 < 5): pool O = 7,
        // E = 6; χ² = 1/6 + 1/50, dof 1.
        let r = chi_square(&[0, 4, 3, 49], &[1.0, 2.0, 3.0, 50.0], 5.0);
        assert_eq!(r.pooled_cells, 3);
        assert_eq!(r.dof, 1);
        assert!((r.statistic - (1.0 / 6.0 + 1.0 / 50.0)).abs() < 1e-14);
        // A count where nothing is expected rejects outright.
        let r = chi_square(&[3, 10], &[0.0, 13.0], 5.0);
        assert_eq!(r.p_value, 0.0);
        assert_eq!(r.impossible, 3);
    }
}
