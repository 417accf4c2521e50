//! Branch-free f32 lane math for the batch kernels.
//!
//! Every function here is straight-line arithmetic on `f32` (bit casts,
//! multiplies, adds, `sqrt`, `min`/`max` and selects written as `if` on
//! values), marked `#[inline(always)]`, so that inside a kernel loop compiled
//! for AVX-512 or AVX2 LLVM vectorises the whole evaluation; a call into libm
//! would stop that. Accuracies are stated against the exact function and are
//! checked in the tests below and, end to end, by the batch parity test.

/// ln 2 split for Cody–Waite range reduction: `HI` has its low 12 bits zero, so
/// `n · HI` is exact for |n| ≤ 2¹².
const LN2_HI: f32 = 0.693_145_75;
const LN2_LO: f32 = 1.428_606_8e-6;
const LOG2E: f32 = std::f32::consts::LOG2_E;
/// 1.5 · 2²³: adding it rounds a float of magnitude < 2²² to an integer, whose
/// value then sits in the low mantissa bits.
const ROUND_MAGIC: f32 = 12_582_912.0;

/// `eˣ`, relative error ≲ 2e-7 on [−87, 88]; 0 below −87.3 (the f32 normal
/// range ends there), +∞ above 88.7.
#[inline(always)]
pub fn exp(x: f32) -> f32 {
    let xc = x.clamp(-87.0, 88.0);
    // n = round(x / ln 2), r = x − n ln 2 ∈ [−ln2/2, ln2/2].
    let t = xc * LOG2E + ROUND_MAGIC;
    let n = (t.to_bits() as i32).wrapping_sub(ROUND_MAGIC.to_bits() as i32);
    let nf = t - ROUND_MAGIC;
    let r = xc - nf * LN2_HI - nf * LN2_LO;
    // Taylor series to r⁷ (|r| ≤ 0.347: the r⁸/8! remainder is < 3e-9).
    let p = 1.0
        + r * (1.0
            + r * (0.5
                + r * (1.0 / 6.0
                    + r * (1.0 / 24.0
                        + r * (1.0 / 120.0 + r * (1.0 / 720.0 + r * (1.0 / 5040.0)))))));
    let scale = f32::from_bits(((n + 127) as u32) << 23);
    let v = p * scale;
    if x < -87.3 {
        0.0
    } else if x > 88.7 {
        f32::INFINITY
    } else {
        v
    }
}

/// Natural logarithm for positive normal `x`, relative error ≲ 2e-7 (and
/// accurate relative to `ln x` itself near `x = 1`, where it matters for
/// `pow` with large exponents). Non-positive `x` gives −∞.
#[inline(always)]
pub fn ln(x: f32) -> f32 {
    let bits = x.to_bits();
    let mut e = ((bits >> 23) & 0xff) as i32 - 127;
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    // m ∈ [√½, √2): then s = (m − 1)/(m + 1) has |s| ≤ 0.1716.
    let big = m > std::f32::consts::SQRT_2;
    m = if big { m * 0.5 } else { m };
    e = if big { e + 1 } else { e };
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    // ln m = 2 atanh s = 2s (1 + s²/3 + s⁴/5 + s⁶/7 + s⁸/9); next term < 2e-9.
    let poly = 1.0 + s2 * (1.0 / 3.0 + s2 * (1.0 / 5.0 + s2 * (1.0 / 7.0 + s2 * (1.0 / 9.0))));
    let v = e as f32 * std::f32::consts::LN_2 + 2.0 * s * poly;
    if x > 0.0 { v } else { f32::NEG_INFINITY }
}

/// `ln x` given both `x` and `y = 1 − x` (each accurate to f32 rounding),
/// accurate relative to the result also near `x = 1`, where `ln x` from a
/// rounded `x` would lose every digit: `2 atanh(−y/(2 − y))` by the series of
/// [`ln`] for `y < 0.29` (`|s| ≤ 0.17`), [`ln`]`(x)` otherwise.
#[inline(always)]
pub fn ln_near_one(x: f32, y: f32) -> f32 {
    let s = -y / (2.0 - y);
    let s2 = s * s;
    let poly = 1.0 + s2 * (1.0 / 3.0 + s2 * (1.0 / 5.0 + s2 * (1.0 / 7.0 + s2 * (1.0 / 9.0))));
    let small = 2.0 * s * poly;
    if y < 0.29 { small } else { ln(x) }
}

/// The Phong lobe `clamped_pow(R(wo)·wi, e)` of `phong` and
/// `modified-phong`, with `R(wo) = (−wo.x, −wo.y, wo.z)`. The cosine is
/// formed in f64 and the lobe taken from `1 − R(wo)·wi` ([`pow_1m`]): with
/// exponents up to 10⁴ an f32 cosine's rounding alone would move the peak
/// value by 10⁻³.
#[inline(always)]
pub fn mirror_lobe(wi: [f32; 3], wo: [f32; 3], e: f32) -> f32 {
    let [ix, iy, iz] = wi.map(f64::from);
    let [ox, oy, oz] = wo.map(f64::from);
    let x = -ox * ix + -oy * iy + oz * iz;
    pow_1m(x as f32, (1.0 - x) as f32, e)
}

/// `clamped_pow(x, e)` of the Phong-type models, given `x` and `y = 1 − x`:
/// `x^e` for `0 < x ≤ 1` (1 for `x ≥ 1`), 0 for `x ≤ 0`, with `x⁰ = 1` for
/// `x > 0`. Passing `1 − x` keeps large exponents accurate near the peak.
#[inline(always)]
pub fn pow_1m(x: f32, y: f32, e: f32) -> f32 {
    let y = y.max(0.0);
    let v = exp(e * ln_near_one(x, y));
    if x <= 0.0 {
        0.0
    } else if e == 0.0 {
        1.0
    } else {
        v
    }
}

/// An RGB triple in f32.
#[inline]
pub fn rgb(v: crate::Rgb) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// `xʸ` for `x ≥ 0`, as `exp(y ln x)`; `0ʸ = 0` for `y > 0` and `x⁰ = 1`.
#[inline(always)]
pub fn pow(x: f32, y: f32) -> f32 {
    let v = exp(y * ln(x));
    if y == 0.0 {
        1.0
    } else if x > 0.0 {
        v
    } else {
        0.0
    }
}

/// `erfc x` (Numerical Recipes' `erfcc`, a Chebyshev fit with fractional
/// error < 1.2e-7 for every x; Press et al., *Numerical Recipes* 2nd ed.
/// §6.2), with the exponential from [`exp`].
#[inline(always)]
pub fn erfc(x: f32) -> f32 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_2
        + t * (1.000_023_7
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_204
                                + t * (1.488_515_9 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let ans = t * exp(poly);
    if x >= 0.0 { ans } else { 2.0 - ans }
}

/// `erf x = 1 − erfc x` (absolute error < 1.2e-7).
#[inline(always)]
pub fn erf(x: f32) -> f32 {
    1.0 - erfc(x)
}

/// `atan2(y, x)` for `y ≥ 0`, `x ≥ 0` (the first quadrant: the polar angle
/// of a direction above the horizon from its `√(x² + y²)` and `z`), in
/// `[0, π/2]`; relative error ≲ 3e-7. Cephes' `atanf` (Moshier 1989): the
/// ratio is reduced to `|t| ≤ tan(π/8)` by `atan t = π/4 + atan((t−1)/(t+1))`
/// or `π/2 − atan(1/t)`, written here so that the whole reduction costs one
/// division; then an odd degree-9 minimax polynomial. `(0, 0)` gives 0.
#[inline(always)]
pub fn atan2_first_quadrant(y: f32, x: f32) -> f32 {
    // tan(3π/8) = 1 + √2 and tan(π/8) = √2 − 1.
    let big = y > 2.414_213_5 * x;
    let mid = y > 0.414_213_57 * x;
    let (num, den, base) = if big {
        (-x, y, std::f32::consts::FRAC_PI_2)
    } else if mid {
        (y - x, y + x, std::f32::consts::FRAC_PI_4)
    } else {
        (y, x, 0.0)
    };
    let t = num / den;
    let t = if den > 0.0 { t } else { 0.0 };
    let z = t * t;
    let p =
        (((8.053_744_5e-2 * z - 1.387_768_6e-1) * z + 1.997_771_1e-1) * z - 3.333_295e-1) * z * t
            + t;
    base + p
}

/// A 3-vector of lanes' worth of one direction.
pub type V3 = [f32; 3];

/// Dot product.
#[inline(always)]
pub fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    #[test]
    fn atan2_first_quadrant_matches_f64() {
        // Every reduction branch, its boundaries, the axes and tiny ratios.
        let mut worst = 0f64;
        for i in 0..=20_000 {
            let a = std::f64::consts::FRAC_PI_2 * i as f64 / 20_000.0;
            for r in [1.0f64, 1e-3, 37.0] {
                let (y, x) = ((r * a.sin()) as f32, (r * a.cos()) as f32);
                let want = (y as f64).atan2(x as f64);
                let got = super::atan2_first_quadrant(y, x) as f64;
                let err = (got - want).abs() / want.max(1e-30);
                if want > 0.0 {
                    worst = worst.max(err);
                } else {
                    assert_eq!(got, 0.0);
                }
            }
        }
        assert!(worst < 3e-7, "worst relative error {worst:e}");
        assert_eq!(super::atan2_first_quadrant(0.0, 0.0), 0.0);
        assert_eq!(
            super::atan2_first_quadrant(1.0, 0.0),
            std::f32::consts::FRAC_PI_2
        );
        let tiny = super::atan2_first_quadrant(1e-30, 1.0) as f64;
        assert!((tiny - 1e-30).abs() < 1e-36, "{tiny:e}");
    }

    use super::*;

    fn rel(a: f32, b: f64) -> f64 {
        ((a as f64) - b).abs() / b.abs().max(1e-300)
    }

    #[test]
    fn exp_matches_f64() {
        let mut worst = 0.0f64;
        for i in 0..=200_000 {
            let x = -87.0 + 175.0 * i as f32 / 200_000.0;
            worst = worst.max(rel(exp(x), (x as f64).exp()));
        }
        assert!(worst < 3e-7, "exp: worst relative error {worst}");
        assert_eq!(exp(-100.0), 0.0);
        assert_eq!(exp(100.0), f32::INFINITY);
        assert_eq!(exp(0.0), 1.0);
    }

    #[test]
    fn ln_and_pow_match_f64() {
        let mut worst = 0.0f64;
        for i in 1..=200_000 {
            let x = (i as f32 / 200_000.0) * 4.0;
            let want = (x as f64).ln();
            if want != 0.0 {
                worst = worst.max(rel(ln(x), want));
            }
        }
        assert!(worst < 3e-7, "ln: worst relative error {worst}");
        assert_eq!(ln(0.0), f32::NEG_INFINITY);
        // Large exponents near 1: the case of a sharp Phong lobe.
        for (x, y) in [(0.9999f32, 1e4f32), (0.5, 3.0), (0.99, 500.0), (1.0, 1e4)] {
            let want = (x as f64).powf(y as f64);
            assert!(rel(pow(x, y), want) < 2e-5, "{x}^{y}");
        }
        assert_eq!(pow(0.0, 2.0), 0.0);
        assert_eq!(pow(0.0, 0.0), 1.0);
    }

    #[test]
    fn erfc_matches_libm() {
        // Relative error, scaled by 1 + x²: rounding x² to f32 (relative
        // 6e-8) alone moves exp(−x²) by 6e-8 x². And absolute error below
        // 4e-7 (half an f32 ulp at 2 plus the fit), all Beckmann's Λ needs.
        let mut worst = 0.0f64;
        for i in 0..=100_000 {
            let x = -5.0 + 14.0 * i as f32 / 100_000.0;
            let want = libm::erfc(x as f64);
            if want > 1e-37 {
                let r = rel(erfc(x), want) / (1.0 + (x as f64).powi(2));
                worst = worst.max(r);
            }
            assert!((erfc(x) as f64 - want).abs() < 4e-7, "erfc({x})");
        }
        assert!(
            worst < 5e-7,
            "erfc: worst relative error {worst} (scaled by 1 + x²)"
        );
        assert!((erf(1.0) as f64 - 0.842_700_792_949_714_9).abs() < 2e-7);
    }
}
