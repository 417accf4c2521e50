//! Branch-free lane math for the batch kernels, generic over [`Lanes`].
//!
//! Every function here is straight-line vector arithmetic (multiplies,
//! adds, `sqrt`, `min`/`max`, selects and the two bit-level steps of
//! [`Lanes`]), marked `#[inline(always)]`, so that it compiles into the
//! kernel's code for each instruction set; a call into libm would leave the
//! vector registers. Accuracies are stated against the exact function and
//! are checked in the tests below (on the scalar path, whose operations are
//! the same IEEE operations as every vector path's) and, end to end on every
//! path, by the batch parity test.

use super::lanes::{LaneMask, Lanes, WideLanes};

/// ln 2 split for Cody–Waite range reduction: `HI` has its low 12 bits zero, so
/// `n · HI` is exact for |n| ≤ 2¹².
const LN2_HI: f32 = 0.693_145_75;
const LN2_LO: f32 = 1.428_606_8e-6;
const LOG2E: f32 = std::f32::consts::LOG2_E;

/// `eˣ`, relative error ≲ 2e-7 on [−87, 88]; 0 below −87.3 (the f32 normal
/// range ends there), +∞ above 88.7.
#[inline(always)]
pub fn exp<V: Lanes>(x: V) -> V {
    let xc = x.clamp(-87.0, 88.0);
    // n = round(x / ln 2), r = x − n ln 2 ∈ [−ln2/2, ln2/2].
    let nf = (xc * LOG2E).round();
    let r = xc - nf * LN2_HI - nf * LN2_LO;
    // Taylor series to r⁷ (|r| ≤ 0.347: the r⁸/8! remainder is < 3e-9).
    let p = poly(
        r,
        &[
            1.0,
            1.0,
            0.5,
            1.0 / 6.0,
            1.0 / 24.0,
            1.0 / 120.0,
            1.0 / 720.0,
            1.0 / 5040.0,
        ],
    );
    let v = p * V::pow2i(nf);
    let v = x.lt(V::splat(-87.3)).select(V::splat(0.0), v);
    x.gt(V::splat(88.7)).select(V::splat(f32::INFINITY), v)
}

/// `c[0] + x (c[1] + x (c[2] + …))` by Horner's rule, each step one
/// [`Lanes::mul_add`].
#[inline(always)]
fn poly<V: Lanes>(x: V, c: &[f32]) -> V {
    let mut acc = V::splat(c[c.len() - 1]);
    for &k in c[..c.len() - 1].iter().rev() {
        acc = acc.mul_add(x, V::splat(k));
    }
    acc
}

/// `2s (1 + s²/3 + s⁴/5 + s⁶/7 + s⁸/9)`, the series of `2 atanh s` for
/// `|s| ≤ 0.1716`: next term < 2e-9.
#[inline(always)]
fn atanh2<V: Lanes>(s: V) -> V {
    let s2 = s * s;
    s * poly(s2, &[1.0, 1.0 / 3.0, 1.0 / 5.0, 1.0 / 7.0, 1.0 / 9.0]) * 2.0
}

/// Natural logarithm for positive normal `x`, relative error ≲ 2e-7 (and
/// accurate relative to `ln x` itself near `x = 1`, where it matters for
/// `pow` with large exponents). Non-positive `x` gives −∞.
#[inline(always)]
pub fn ln<V: Lanes>(x: V) -> V {
    let (base, num, den) = ln_reduced(x);
    finish_ln(x, base + atanh2(num / den))
}

/// `ln x = e ln 2 + 2 atanh((m − 1)/(m + 1))` with `x = m · 2ᵉ` and
/// `m ∈ [√½, √2)` (then the ratio's `|s| ≤ 0.1716`), as
/// `(e ln 2, m − 1, m + 1)`: the division is left to the caller, so that
/// [`ln_near_one`] divides once for both of its forms.
#[inline(always)]
fn ln_reduced<V: Lanes>(x: V) -> (V, V, V) {
    let (e, m) = x.exponent_mantissa();
    let big = m.gt(V::splat(std::f32::consts::SQRT_2));
    let m = big.select(m * 0.5, m);
    let e = big.select(e + 1.0, e);
    (e * std::f32::consts::LN_2, m - 1.0, m + 1.0)
}

/// −∞ where `x` is not positive, `v` elsewhere.
#[inline(always)]
fn finish_ln<V: Lanes>(x: V, v: V) -> V {
    x.gt(V::splat(0.0)).select(v, V::splat(f32::NEG_INFINITY))
}

/// `ln x` given both `x` and `y = 1 − x` (each accurate to f32 rounding),
/// accurate relative to the result also near `x = 1`, where `ln x` from a
/// rounded `x` would lose every digit: `2 atanh(−y/(2 − y))` by the series of
/// [`ln`] for `y < 0.29` (`|s| ≤ 0.17`), [`ln`]`(x)` otherwise. The two
/// forms share one division and one series: the lanes pick their ratio
/// before it (a division is 10 cycles' latency on Zen 3, and the Phong
/// lobes' chain runs through this).
#[inline(always)]
pub fn ln_near_one<V: Lanes>(x: V, y: V) -> V {
    let (base, num, den) = ln_reduced(x);
    let near = y.lt(V::splat(0.29));
    let num = near.select(-y, num);
    let den = near.select(V::splat(2.0) - y, den);
    let base = near.select(V::splat(0.0), base);
    finish_ln(x, base + atanh2(num / den))
}

/// The Phong lobe `clamped_pow(R(wo)·wi, e)` of `phong` and
/// `modified-phong`, with `R(wo) = (−wo.x, −wo.y, wo.z)`. The cosine is
/// formed in f64 lanes and the lobe taken from `1 − R(wo)·wi` ([`pow_1m`]):
/// with exponents up to 10⁴ an f32 cosine's rounding alone would move the
/// peak value by 10⁻³.
#[inline(always)]
pub fn mirror_lobe<V: Lanes>(wi: [V; 3], wo: [V; 3], e: f32) -> V {
    let [ix, iy, iz] = widen3(wi);
    let [ox, oy, oz] = widen3(wo);
    let x = -ox * ix - oy * iy + oz * iz;
    pow_1m(V::narrow(x), V::narrow(x.one_minus()), e)
}

/// `clamped_pow(x, e)` of the Phong-type models, given `x` and `y = 1 − x`:
/// `x^e` for `0 < x ≤ 1` (1 for `x ≥ 1`), 0 for `x ≤ 0`, with `x⁰ = 1` for
/// `x > 0`. Passing `1 − x` keeps large exponents accurate near the peak.
#[inline(always)]
pub fn pow_1m<V: Lanes>(x: V, y: V, e: f32) -> V {
    pow_1m_lanes(x, y, V::splat(e))
}

/// [`pow_1m`] with an exponent that varies per lane.
#[inline(always)]
pub fn pow_1m_lanes<V: Lanes>(x: V, y: V, e: V) -> V {
    let y = y.max(V::splat(0.0));
    let v = exp(ln_near_one(x, y) * e);
    let v = e.eq(V::splat(0.0)).select(V::splat(1.0), v);
    x.le(V::splat(0.0)).select(V::splat(0.0), v)
}

/// An RGB triple in f32.
#[inline]
pub fn rgb(v: crate::Rgb) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// `xʸ` for `x ≥ 0`, as `exp(y ln x)`; `0ʸ = 0` for `y > 0` and `x⁰ = 1`.
#[inline(always)]
pub fn pow<V: Lanes>(x: V, y: V) -> V {
    let v = exp(y * ln(x));
    let v = x.gt(V::splat(0.0)).select(v, V::splat(0.0));
    y.eq(V::splat(0.0)).select(V::splat(1.0), v)
}

/// `erfc x` (Numerical Recipes' `erfcc`, a Chebyshev fit with fractional
/// error < 1.2e-7 for every x; Press et al., *Numerical Recipes* 2nd ed.
/// §6.2), with the exponential from [`exp`].
#[inline(always)]
pub fn erfc<V: Lanes>(x: V) -> V {
    let z = x.abs();
    let t = V::splat(1.0) / (z * 0.5 + 1.0);
    let c = poly(
        t,
        &[
            -1.265_512_2,
            1.000_023_7,
            0.374_091_96,
            0.096_784_18,
            -0.186_288_06,
            0.278_868_07,
            -1.135_204,
            1.488_515_9,
            -0.822_152_23,
            0.170_872_77,
        ],
    );
    let ans = t * exp(c - z * z);
    x.ge(V::splat(0.0)).select(ans, V::splat(2.0) - ans)
}

/// `erf x = 1 − erfc x` (absolute error < 1.2e-7).
#[inline(always)]
pub fn erf<V: Lanes>(x: V) -> V {
    V::splat(1.0) - erfc(x)
}

/// `atan2(y, x)` for `y ≥ 0`, `x ≥ 0` (the first quadrant: the polar angle
/// of a direction above the horizon from its `√(x² + y²)` and `z`), in
/// `[0, π/2]`; relative error ≲ 3e-7. Cephes' `atanf` (Moshier 1989): the
/// ratio is reduced to `|t| ≤ tan(π/8)` by `atan t = π/4 + atan((t−1)/(t+1))`
/// or `π/2 − atan(1/t)`, written here so that the whole reduction costs one
/// division; then an odd degree-9 minimax polynomial. `(0, 0)` gives 0.
#[inline(always)]
pub fn atan2_first_quadrant<V: Lanes>(y: V, x: V) -> V {
    // tan(3π/8) = 1 + √2 and tan(π/8) = √2 − 1.
    let big = y.gt(x * 2.414_213_5);
    let mid = y.gt(x * 0.414_213_57);
    let num = big.select(-x, mid.select(y - x, y));
    let den = big.select(y, mid.select(y + x, x));
    let base = big.select(
        V::splat(std::f32::consts::FRAC_PI_2),
        mid.select(V::splat(std::f32::consts::FRAC_PI_4), V::splat(0.0)),
    );
    let t = den.gt(V::splat(0.0)).select(num / den, V::splat(0.0));
    let z = t * t;
    let p =
        (((z * 8.053_744_5e-2 - 1.387_768_6e-1) * z + 1.997_771_1e-1) * z - 3.333_295e-1) * z * t
            + t;
    base + p
}

/// A 3-vector of lanes' worth of one direction.
pub type V3<V = f32> = [V; 3];

/// Dot product.
#[inline(always)]
pub fn dot<V: Lanes>(a: [V; 3], b: [V; 3]) -> V {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a + b` per component.
#[inline(always)]
pub fn add3<V: Lanes>(a: [V; 3], b: [V; 3]) -> [V; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a − b` per component.
#[inline(always)]
pub fn sub3<V: Lanes>(a: [V; 3], b: [V; 3]) -> [V; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a × b`.
#[inline(always)]
pub fn cross<V: Lanes>(a: [V; 3], b: [V; 3]) -> [V; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Per-channel constants as lanes.
#[inline(always)]
pub fn splat3<V: Lanes>(c: [f32; 3]) -> [V; 3] {
    [V::splat(c[0]), V::splat(c[1]), V::splat(c[2])]
}

/// `a · s` per component.
#[inline(always)]
pub fn scale3<V: Lanes>(a: [V; 3], s: V) -> [V; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// The components widened to f64 lanes.
#[inline(always)]
pub fn widen3<V: Lanes>(a: [V; 3]) -> [V::Wide; 3] {
    [a[0].widen(), a[1].widen(), a[2].widen()]
}

/// `(1 − c)⁵` with `1 − c` clamped to [0, 1]: Schlick's Fresnel weight.
#[inline(always)]
pub fn schlick_weight<V: Lanes>(c: V) -> V {
    pow5((V::splat(1.0) - c).clamp(0.0, 1.0))
}

/// `x⁵`.
#[inline(always)]
pub fn pow5<V: Lanes>(x: V) -> V {
    let x2 = x * x;
    x2 * x2 * x
}

/// `a + (b − a) t`.
#[inline(always)]
pub fn lerp<V: Lanes>(a: V, b: V, t: V) -> V {
    a + (b - a) * t
}

/// `[e(0), e(1), e(2)]` for an expression `e` of the channel index: the
/// three channels written out. Lane code uses this instead of std's array
/// `map` and `from_fn` or a closure: those are not always inlined, and lane
/// code left out of line is compiled without the vector instruction set
/// (each vector operation then becomes a call).
macro_rules! channels {
    (|$c:ident| $e:expr) => {
        [
            {
                let $c = 0usize;
                $e
            },
            {
                let $c = 1usize;
                $e
            },
            {
                let $c = 2usize;
                $e
            },
        ]
    };
}
pub(crate) use channels;

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
