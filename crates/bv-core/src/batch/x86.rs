//! [`Lanes`] on x86-64: AVX2 + FMA (8 lanes) and AVX-512F (16 lanes), and
//! the tasks compiled for each (the kernels' loops are the batch module's
//! `IsaLoops` methods, which say why).
//!
//! Soundness: every type here wraps a register whose instructions need the
//! CPU feature named in its doc. A value of the type is made only inside a
//! function compiled with that feature (`IsaLoops::run_avx2` and
//! `run_avx512`, [`task_avx2`], [`task_avx512`]), which the dispatchers
//! ([`super::run`], [`super::run_task`]) call only after
//! [`super::Isa::is_available`] saw the feature; the types are private to
//! the batch module, so no other code can make one.

use super::LaneTask;
use super::lanes::{Lanes, mask_ops, vector_ops, wide_pair};
use std::arch::x86_64::*;

// ---------------------------------------------------------------------------
// AVX2 + FMA.

/// Eight f32 lanes in a 256-bit register (AVX2 + FMA; see the module doc).
#[derive(Clone, Copy, Debug)]
pub(super) struct Avx2(__m256);
/// A comparison result of [`Avx2`]: all-ones or all-zeros per lane.
#[derive(Clone, Copy, Debug)]
pub(super) struct Avx2Mask(__m256);
/// The lanes of [`Avx2`] in f64: lanes 0–3, then 4–7.
#[derive(Clone, Copy, Debug)]
pub(super) struct Avx2Wide([__m256d; 2]);

vector_ops!(
    Avx2,
    f32,
    _mm256_add_ps,
    _mm256_sub_ps,
    _mm256_mul_ps,
    _mm256_div_ps,
    |x| Avx2(unsafe { _mm256_xor_ps(x.0, _mm256_set1_ps(-0.0)) })
);
mask_ops!(
    Avx2Mask,
    _mm256_and_ps,
    _mm256_or_ps,
    |x| Avx2Mask(unsafe { _mm256_xor_ps(x.0, _mm256_castsi256_ps(_mm256_set1_epi32(-1))) }),
    // The lanes' sign bits, one bit each.
    any | x | unsafe { _mm256_movemask_ps(x.0) } != 0,
    all | x | unsafe { _mm256_movemask_ps(x.0) } == 0xff
);
wide_pair!(
    Avx2Wide,
    Avx2,
    __m256d,
    _mm256_add_pd,
    _mm256_sub_pd,
    _mm256_mul_pd,
    _mm256_set1_pd,
    _mm256_sqrt_pd,
    _mm256_min_pd,
    |x| Avx2Wide(unsafe {
        let s = _mm256_set1_pd(-0.0);
        [_mm256_xor_pd(x.0[0], s), _mm256_xor_pd(x.0[1], s)]
    })
);

impl From<f32> for Avx2 {
    #[inline(always)]
    fn from(x: f32) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe { _mm256_set1_ps(x) })
    }
}

/// An ordered comparison of two [`Avx2`] as a mask.
macro_rules! avx2_cmp {
    ($a:expr, $b:expr, $op:ident) => {
        // SAFETY: see the module doc.
        Avx2Mask(unsafe { _mm256_cmp_ps::<$op>($a.0, $b.0) })
    };
}

impl Lanes for Avx2 {
    type Mask = Avx2Mask;
    type Wide = Avx2Wide;
    const LANES: usize = 8;

    #[inline(always)]
    fn splat(x: f32) -> Self {
        Self::from(x)
    }
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        let s = &s[..8];
        // SAFETY: `s` holds 8 floats; unaligned load; see the module doc.
        Self(unsafe { _mm256_loadu_ps(s.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, s: &mut [f32]) {
        let s = &mut s[..8];
        // SAFETY: `s` has room for 8 floats; see the module doc.
        unsafe { _mm256_storeu_ps(s.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn store3(a: Self, b: Self, c: Self, out: &mut [[f32; 3]]) {
        let s = out[..8].as_flattened_mut();
        // See `store3_lanes`: one lane permutation per output vector
        // applied to a, b and c, then two blends by the input each place
        // is from (immediates, hence one call per output vector).
        let (a, b, c) = (a.0, b.0, c.0);
        // SAFETY: see the module doc.
        let v = unsafe {
            [
                avx2_store3_part::<{ STORE3_OF_A8[0] as i32 }, { STORE3_OF_B8[0] as i32 }>(
                    a,
                    b,
                    c,
                    &STORE3_LANE8[0],
                ),
                avx2_store3_part::<{ STORE3_OF_A8[1] as i32 }, { STORE3_OF_B8[1] as i32 }>(
                    a,
                    b,
                    c,
                    &STORE3_LANE8[1],
                ),
                avx2_store3_part::<{ STORE3_OF_A8[2] as i32 }, { STORE3_OF_B8[2] as i32 }>(
                    a,
                    b,
                    c,
                    &STORE3_LANE8[2],
                ),
            ]
        };
        for (chunk, v) in s.chunks_exact_mut(8).zip(v) {
            // SAFETY: `chunk` has room for 8 floats; see the module doc.
            unsafe { _mm256_storeu_ps(chunk.as_mut_ptr(), v) }
        }
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        // SAFETY: see the module doc (the kernel is compiled with `fma`).
        Self(unsafe { _mm256_fmadd_ps(self.0, b.0, c.0) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe { _mm256_sqrt_ps(self.0) })
    }
    #[inline(always)]
    fn rsqrt(self) -> Self {
        // SAFETY: see the module doc.
        // The estimate is good to 1.5 · 2⁻¹².
        rsqrt_step(self, Self(unsafe { _mm256_rsqrt_ps(self.0) }))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0) })
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        // minps returns its second operand when either is NaN.
        // SAFETY: see the module doc.
        Self(unsafe { _mm256_min_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe { _mm256_max_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn round(self) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe {
            _mm256_round_ps::<{ _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC }>(self.0)
        })
    }
    #[inline(always)]
    fn lt(self, o: Self) -> Avx2Mask {
        avx2_cmp!(self, o, _CMP_LT_OQ)
    }
    #[inline(always)]
    fn le(self, o: Self) -> Avx2Mask {
        avx2_cmp!(self, o, _CMP_LE_OQ)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> Avx2Mask {
        avx2_cmp!(self, o, _CMP_GT_OQ)
    }
    #[inline(always)]
    fn ge(self, o: Self) -> Avx2Mask {
        avx2_cmp!(self, o, _CMP_GE_OQ)
    }
    #[inline(always)]
    fn eq(self, o: Self) -> Avx2Mask {
        avx2_cmp!(self, o, _CMP_EQ_OQ)
    }
    #[inline(always)]
    fn select(m: Avx2Mask, a: Self, b: Self) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe { _mm256_blendv_ps(b.0, a.0, m.0) })
    }
    #[inline(always)]
    fn pow2i(n: Self) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe {
            let i = _mm256_add_epi32(_mm256_cvtps_epi32(n.0), _mm256_set1_epi32(127));
            _mm256_castsi256_ps(_mm256_slli_epi32::<23>(i))
        })
    }
    #[inline(always)]
    fn exponent_mantissa(self) -> (Self, Self) {
        // SAFETY: see the module doc.
        unsafe {
            let bits = _mm256_castps_si256(self.0);
            let e = _mm256_sub_epi32(
                _mm256_and_si256(_mm256_srli_epi32::<23>(bits), _mm256_set1_epi32(0xff)),
                _mm256_set1_epi32(127),
            );
            let m = _mm256_or_si256(
                _mm256_and_si256(bits, _mm256_set1_epi32(0x007f_ffff)),
                _mm256_set1_epi32(0x3f80_0000),
            );
            (Self(_mm256_cvtepi32_ps(e)), Self(_mm256_castsi256_ps(m)))
        }
    }
    #[inline(always)]
    fn widen(self) -> Avx2Wide {
        // SAFETY: see the module doc.
        unsafe {
            let lo = _mm256_castps256_ps128(self.0);
            let hi = _mm256_extractf128_ps::<1>(self.0);
            Avx2Wide([_mm256_cvtps_pd(lo), _mm256_cvtps_pd(hi)])
        }
    }
    #[inline(always)]
    fn narrow(w: Avx2Wide) -> Self {
        // SAFETY: see the module doc.
        unsafe {
            let lo = _mm256_cvtpd_ps(w.0[0]);
            let hi = _mm256_cvtpd_ps(w.0[1]);
            Self(_mm256_set_m128(hi, lo))
        }
    }
}

/// `task` in AVX2 + FMA code.
///
/// # Safety
/// The CPU must have AVX2 and FMA.
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn task_avx2<T: LaneTask>(task: T) -> T::Output {
    task.run::<Avx2>()
}

/// One Newton step for `1/√x` from the estimate `y`:
/// `y (3/2 − x/2 · y²)`, which squares `y`'s relative error (both paths'
/// [`Lanes::rsqrt`]).
#[inline(always)]
fn rsqrt_step<V: Lanes>(x: V, y: V) -> V {
    y * (V::splat(1.5) - (x * 0.5) * y * y)
}

// ---------------------------------------------------------------------------
// `store3`'s tables, shared by both widths.

/// For vectors of `W` lanes: the input lane that place `p` of output vector
/// `k` takes, `(Wk + p) / 3`, from input `(Wk + p) mod 3` (see
/// [`store3_from`]): the interleaved `[a0, b0, c0, a1, …]` cut into three
/// vectors.
const fn store3_lanes<const W: usize>() -> [[i32; W]; 3] {
    let mut t = [[0; W]; 3];
    let mut k = 0;
    while k < 3 {
        let mut p = 0;
        while p < W {
            t[k][p] = ((W * k + p) / 3) as i32;
            p += 1;
        }
        k += 1;
    }
    t
}
/// The places (bit `p`) of output vector `k` that come from input `i`,
/// those with `(Wk + p) mod 3 = i`, for vectors of `W ≤ 16` lanes.
const fn store3_from<const W: usize>(i: usize) -> [u16; 3] {
    let mut t = [0u16; 3];
    let mut k = 0;
    while k < 3 {
        let mut p = 0;
        while p < W {
            if (W * k + p) % 3 == i {
                t[k] |= 1 << p;
            }
            p += 1;
        }
        k += 1;
    }
    t
}
/// [`store3_lanes`] for [`Avx2`].
const STORE3_LANE8: [[i32; 8]; 3] = store3_lanes::<8>();
/// [`store3_from`] the first input, for [`Avx2`].
const STORE3_OF_A8: [u16; 3] = store3_from::<8>(0);
/// [`store3_from`] the second input, for [`Avx2`].
const STORE3_OF_B8: [u16; 3] = store3_from::<8>(1);
/// [`store3_lanes`] for [`Avx512`].
const STORE3_LANE16: [[i32; 16]; 3] = store3_lanes::<16>();
/// [`store3_from`] the first input, for [`Avx512`].
const STORE3_OF_A16: [u16; 3] = store3_from::<16>(0);
/// [`store3_from`] the second input, for [`Avx512`].
const STORE3_OF_B16: [u16; 3] = store3_from::<16>(1);

/// One output vector of [`Avx2`]'s `store3`: `a`, `b` and `c` permuted by
/// `lanes`, then the places in `FROM_A` taken from `a`, those in `FROM_B`
/// from `b` (blend immediates), the rest from `c`.
///
/// # Safety
/// The CPU must have AVX2 (see the module doc).
#[inline(always)]
unsafe fn avx2_store3_part<const FROM_A: i32, const FROM_B: i32>(
    a: __m256,
    b: __m256,
    c: __m256,
    lanes: &[i32; 8],
) -> __m256 {
    // SAFETY: `lanes` holds 8 i32 (unaligned load); the caller has AVX2.
    unsafe {
        let idx = _mm256_loadu_si256(lanes.as_ptr().cast());
        _mm256_blend_ps::<FROM_B>(
            _mm256_blend_ps::<FROM_A>(
                _mm256_permutevar8x32_ps(c, idx),
                _mm256_permutevar8x32_ps(a, idx),
            ),
            _mm256_permutevar8x32_ps(b, idx),
        )
    }
}

// ---------------------------------------------------------------------------
// AVX-512F.

/// Sixteen f32 lanes in a 512-bit register (AVX-512F; see the module doc).
#[derive(Clone, Copy, Debug)]
pub(super) struct Avx512(__m512);
/// A comparison result of [`Avx512`]: one bit per lane.
#[derive(Clone, Copy, Debug)]
pub(super) struct Avx512Mask(__mmask16);
/// The lanes of [`Avx512`] in f64: lanes 0–7, then 8–15.
#[derive(Clone, Copy, Debug)]
pub(super) struct Avx512Wide([__m512d; 2]);

/// `&` and `|` of two bit masks (plain integer operations; the `unsafe` of
/// [`mask_ops`] has nothing to guard here).
#[inline(always)]
unsafe fn and16(a: __mmask16, b: __mmask16) -> __mmask16 {
    a & b
}
#[inline(always)]
unsafe fn or16(a: __mmask16, b: __mmask16) -> __mmask16 {
    a | b
}

vector_ops!(
    Avx512,
    f32,
    _mm512_add_ps,
    _mm512_sub_ps,
    _mm512_mul_ps,
    _mm512_div_ps,
    |x| Avx512(unsafe {
        _mm512_castsi512_ps(_mm512_xor_si512(
            _mm512_castps_si512(x.0),
            _mm512_set1_epi32(i32::MIN),
        ))
    })
);
mask_ops!(
    Avx512Mask,
    and16,
    or16,
    |x| Avx512Mask(!x.0),
    any | x | x.0 != 0,
    all | x | x.0 == 0xffff
);
wide_pair!(
    Avx512Wide,
    Avx512,
    __m512d,
    _mm512_add_pd,
    _mm512_sub_pd,
    _mm512_mul_pd,
    _mm512_set1_pd,
    _mm512_sqrt_pd,
    _mm512_min_pd,
    |x| Avx512Wide(unsafe {
        let s = _mm512_set1_pd(-0.0);
        [xor512_pd(x.0[0], s), xor512_pd(x.0[1], s)]
    })
);

/// `a ^ b` of two f64 registers (AVX-512F has the integer form only).
#[inline(always)]
unsafe fn xor512_pd(a: __m512d, b: __m512d) -> __m512d {
    // SAFETY: the caller is in AVX-512F code (see the module doc).
    unsafe {
        _mm512_castsi512_pd(_mm512_xor_si512(
            _mm512_castpd_si512(a),
            _mm512_castpd_si512(b),
        ))
    }
}

impl From<f32> for Avx512 {
    #[inline(always)]
    fn from(x: f32) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe { _mm512_set1_ps(x) })
    }
}

/// An ordered comparison of two [`Avx512`] as a bit mask.
macro_rules! avx512_cmp {
    ($a:expr, $b:expr, $op:ident) => {
        // SAFETY: see the module doc.
        Avx512Mask(unsafe { _mm512_cmp_ps_mask::<$op>($a.0, $b.0) })
    };
}

impl Lanes for Avx512 {
    type Mask = Avx512Mask;
    type Wide = Avx512Wide;
    const LANES: usize = 16;

    #[inline(always)]
    fn splat(x: f32) -> Self {
        Self::from(x)
    }
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        let s = &s[..16];
        // SAFETY: `s` holds 16 floats; unaligned load; see the module doc.
        Self(unsafe { _mm512_loadu_ps(s.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, s: &mut [f32]) {
        let s = &mut s[..16];
        // SAFETY: `s` has room for 16 floats; see the module doc.
        unsafe { _mm512_storeu_ps(s.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn store3(a: Self, b: Self, c: Self, out: &mut [[f32; 3]]) {
        let s = out[..16].as_flattened_mut();
        // See `store3_lanes`.
        // SAFETY: `s` has room for 48 floats; see the module doc.
        unsafe {
            for (k, chunk) in s.chunks_exact_mut(16).enumerate() {
                let idx = _mm512_loadu_si512(STORE3_LANE16[k].as_ptr().cast());
                let v = _mm512_mask_blend_ps(
                    STORE3_OF_B16[k],
                    _mm512_mask_blend_ps(
                        STORE3_OF_A16[k],
                        _mm512_permutexvar_ps(idx, c.0),
                        _mm512_permutexvar_ps(idx, a.0),
                    ),
                    _mm512_permutexvar_ps(idx, b.0),
                );
                _mm512_storeu_ps(chunk.as_mut_ptr(), v);
            }
        }
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe { _mm512_fmadd_ps(self.0, b.0, c.0) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe { _mm512_sqrt_ps(self.0) })
    }
    #[inline(always)]
    fn rsqrt(self) -> Self {
        // SAFETY: see the module doc.
        // The estimate is good to 2⁻¹⁴.
        rsqrt_step(self, Self(unsafe { _mm512_rsqrt14_ps(self.0) }))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe { _mm512_abs_ps(self.0) })
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        // vminps returns its second operand when either is NaN.
        // SAFETY: see the module doc.
        Self(unsafe { _mm512_min_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe { _mm512_max_ps(self.0, o.0) })
    }
    #[inline(always)]
    fn round(self) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe {
            _mm512_roundscale_ps::<{ _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC }>(self.0)
        })
    }
    #[inline(always)]
    fn lt(self, o: Self) -> Avx512Mask {
        avx512_cmp!(self, o, _CMP_LT_OQ)
    }
    #[inline(always)]
    fn le(self, o: Self) -> Avx512Mask {
        avx512_cmp!(self, o, _CMP_LE_OQ)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> Avx512Mask {
        avx512_cmp!(self, o, _CMP_GT_OQ)
    }
    #[inline(always)]
    fn ge(self, o: Self) -> Avx512Mask {
        avx512_cmp!(self, o, _CMP_GE_OQ)
    }
    #[inline(always)]
    fn eq(self, o: Self) -> Avx512Mask {
        avx512_cmp!(self, o, _CMP_EQ_OQ)
    }
    #[inline(always)]
    fn select(m: Avx512Mask, a: Self, b: Self) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe { _mm512_mask_blend_ps(m.0, b.0, a.0) })
    }
    #[inline(always)]
    fn pow2i(n: Self) -> Self {
        // SAFETY: see the module doc.
        Self(unsafe {
            let i = _mm512_add_epi32(_mm512_cvtps_epi32(n.0), _mm512_set1_epi32(127));
            _mm512_castsi512_ps(_mm512_slli_epi32::<23>(i))
        })
    }
    #[inline(always)]
    fn exponent_mantissa(self) -> (Self, Self) {
        // SAFETY: see the module doc.
        unsafe {
            let bits = _mm512_castps_si512(self.0);
            let e = _mm512_sub_epi32(
                _mm512_and_si512(_mm512_srli_epi32::<23>(bits), _mm512_set1_epi32(0xff)),
                _mm512_set1_epi32(127),
            );
            let m = _mm512_or_si512(
                _mm512_and_si512(bits, _mm512_set1_epi32(0x007f_ffff)),
                _mm512_set1_epi32(0x3f80_0000),
            );
            (Self(_mm512_cvtepi32_ps(e)), Self(_mm512_castsi512_ps(m)))
        }
    }
    #[inline(always)]
    fn widen(self) -> Avx512Wide {
        // SAFETY: see the module doc.
        unsafe {
            let lo = _mm512_castps512_ps256(self.0);
            let hi = _mm256_castpd_ps(_mm512_extractf64x4_pd::<1>(_mm512_castps_pd(self.0)));
            Avx512Wide([_mm512_cvtps_pd(lo), _mm512_cvtps_pd(hi)])
        }
    }
    #[inline(always)]
    fn narrow(w: Avx512Wide) -> Self {
        // SAFETY: see the module doc.
        unsafe {
            let lo = _mm512_castps256_ps512(_mm512_cvtpd_ps(w.0[0]));
            let hi = _mm256_castps_pd(_mm512_cvtpd_ps(w.0[1]));
            Self(_mm512_castpd_ps(_mm512_insertf64x4::<1>(
                _mm512_castps_pd(lo),
                hi,
            )))
        }
    }
}

/// `task` in AVX-512F code.
///
/// # Safety
/// The CPU must have AVX-512F, AVX2 and FMA.
#[target_feature(enable = "avx512f,avx2,fma")]
pub(super) unsafe fn task_avx512<T: LaneTask>(task: T) -> T::Output {
    task.run::<Avx512>()
}

#[cfg(test)]
mod tests {
    use super::{
        STORE3_LANE8, STORE3_LANE16, STORE3_OF_A8, STORE3_OF_A16, STORE3_OF_B8, STORE3_OF_B16,
    };

    /// Checks `store3`'s tables for vectors of `W` lanes through the
    /// instructions' definitions: permute(idx, v)[p] = v[idx[p]],
    /// blend(k, x, y)[p] = y[p] where bit p of k is set, else x[p].
    fn check_tables<const W: usize>(lanes: &[[i32; W]; 3], of_a: &[u16; 3], of_b: &[u16; 3]) {
        let input = |i: usize| -> [f32; W] { std::array::from_fn(|l| (3 * l + i) as f32) };
        let (a, b, c) = (input(0), input(1), input(2));
        for k in 0..3 {
            for (p, &l) in lanes[k].iter().enumerate() {
                let l = l as usize;
                let from_a = of_a[k] >> p & 1 == 1;
                let from_b = of_b[k] >> p & 1 == 1;
                let v = if from_b {
                    b[l]
                } else if from_a {
                    a[l]
                } else {
                    c[l]
                };
                // Place Wk + p of the interleaved output holds Wk + p.
                assert_eq!(v, (W * k + p) as f32, "{W} lanes: vector {k}, place {p}");
                assert!(!(from_a && from_b));
            }
        }
    }

    #[test]
    fn avx512_store3_tables_interleave() {
        // The AVX-512 path runs only where the CPU has it; its tables are
        // checked everywhere (and the AVX2 path's, which it shares the
        // builders with).
        check_tables(&STORE3_LANE16, &STORE3_OF_A16, &STORE3_OF_B16);
        check_tables(&STORE3_LANE8, &STORE3_OF_A8, &STORE3_OF_B8);
    }
}
