//! [`Lanes`] on wasm32 with `simd128` (4 lanes). WebAssembly has no
//! run-time feature detection: a module that uses SIMD instructions only
//! validates in an engine that has them, so this path exists only in builds
//! compiled with `-C target-feature=+simd128` (the web build's
//! `.cargo/config.toml` sets it; every current browser with WebGPU has
//! SIMD).

use super::LaneTask;
use super::lanes::{Lanes, mask_ops, vector_ops, wide_pair};
use std::arch::wasm32::*;

/// Four f32 lanes in a `v128`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Simd128(v128);
/// A comparison result of [`Simd128`]: all-ones or all-zeros per lane.
#[derive(Clone, Copy, Debug)]
pub(super) struct Simd128Mask(v128);
/// The lanes of [`Simd128`] in f64: lanes 0–1, then 2–3.
#[derive(Clone, Copy, Debug)]
pub(super) struct Simd128Wide([v128; 2]);

// The operations are safe functions on wasm32; the `unsafe` blocks the
// macros write around them are unused.
#[allow(unused_unsafe)]
mod ops {
    use super::*;
    vector_ops!(
        Simd128,
        f32,
        f32x4_add,
        f32x4_sub,
        f32x4_mul,
        f32x4_div,
        |x| Simd128(f32x4_neg(x.0))
    );
    mask_ops!(
        Simd128Mask,
        v128_and,
        v128_or,
        |x| Simd128Mask(v128_not(x.0)),
        any | x | v128_any_true(x.0),
        all | x | i32x4_all_true(x.0)
    );
    wide_pair!(
        Simd128Wide,
        Simd128,
        v128,
        f64x2_add,
        f64x2_sub,
        f64x2_mul,
        f64x2_splat,
        f64x2_sqrt,
        min_f64x2,
        |x| Simd128Wide([f64x2_neg(x.0[0]), f64x2_neg(x.0[1])])
    );
}

/// The smaller per lane, `b` where `a` is NaN (pmin(b, a) = a < b ? a : b).
#[inline(always)]
fn min_f64x2(a: v128, b: v128) -> v128 {
    f64x2_pmin(b, a)
}

impl From<f32> for Simd128 {
    #[inline(always)]
    fn from(x: f32) -> Self {
        Self(f32x4_splat(x))
    }
}

impl Lanes for Simd128 {
    type Mask = Simd128Mask;
    type Wide = Simd128Wide;
    const LANES: usize = 4;

    #[inline(always)]
    fn splat(x: f32) -> Self {
        Self::from(x)
    }
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        let s = &s[..4];
        // SAFETY: `s` holds 4 floats (16 bytes); v128_load is unaligned.
        Self(unsafe { v128_load(s.as_ptr().cast()) })
    }
    #[inline(always)]
    fn store(self, s: &mut [f32]) {
        let s = &mut s[..4];
        // SAFETY: `s` has room for 4 floats (16 bytes); unaligned store.
        unsafe { v128_store(s.as_mut_ptr().cast(), self.0) }
    }
    #[inline(always)]
    fn store3(a: Self, b: Self, c: Self, out: &mut [[f32; 3]]) {
        let s = out[..4].as_flattened_mut();
        let (a, b, c) = (a.0, b.0, c.0);
        // [a0 b0 c0 a1] [b1 c1 a2 b2] [c2 a3 b3 c3]; indices 4–7 name the
        // second operand's lanes.
        let ab = i32x4_shuffle::<0, 4, 1, 5>(a, b);
        let v0 = i32x4_shuffle::<0, 1, 4, 2>(ab, c);
        let bc = i32x4_shuffle::<1, 5, 2, 6>(b, c);
        let v1 = i32x4_shuffle::<0, 1, 6, 2>(bc, a);
        let ab3 = i32x4_shuffle::<3, 7, 3, 7>(a, b);
        let v2 = i32x4_shuffle::<2, 4, 5, 3>(c, ab3);
        // SAFETY: `s` has room for 12 floats (48 bytes); unaligned stores.
        unsafe {
            v128_store(s.as_mut_ptr().cast(), v0);
            v128_store(s[4..].as_mut_ptr().cast(), v1);
            v128_store(s[8..].as_mut_ptr().cast(), v2);
        }
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        // simd128 has no fused multiply-add (relaxed-simd's `relaxed_madd`
        // may or may not fuse, and is not enabled for the web build).
        Self(f32x4_add(f32x4_mul(self.0, b.0), c.0))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(f32x4_sqrt(self.0))
    }
    #[inline(always)]
    fn rsqrt(self) -> Self {
        // simd128 has no estimate.
        Self(f32x4_div(f32x4_splat(1.0), f32x4_sqrt(self.0)))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Self(f32x4_abs(self.0))
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        // pmin(a, b) = b < a ? b : a; as pmin(o, self): self < o ? self : o,
        // which is `o` when `self` is NaN, as on the other paths.
        Self(f32x4_pmin(o.0, self.0))
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        // pmax(a, b) = a < b ? b : a; as pmax(o, self): o < self ? self : o.
        Self(f32x4_pmax(o.0, self.0))
    }
    #[inline(always)]
    fn round(self) -> Self {
        Self(f32x4_nearest(self.0))
    }
    #[inline(always)]
    fn lt(self, o: Self) -> Simd128Mask {
        Simd128Mask(f32x4_lt(self.0, o.0))
    }
    #[inline(always)]
    fn le(self, o: Self) -> Simd128Mask {
        Simd128Mask(f32x4_le(self.0, o.0))
    }
    #[inline(always)]
    fn gt(self, o: Self) -> Simd128Mask {
        Simd128Mask(f32x4_gt(self.0, o.0))
    }
    #[inline(always)]
    fn ge(self, o: Self) -> Simd128Mask {
        Simd128Mask(f32x4_ge(self.0, o.0))
    }
    #[inline(always)]
    fn eq(self, o: Self) -> Simd128Mask {
        Simd128Mask(f32x4_eq(self.0, o.0))
    }
    #[inline(always)]
    fn select(m: Simd128Mask, a: Self, b: Self) -> Self {
        Self(v128_bitselect(a.0, b.0, m.0))
    }
    #[inline(always)]
    fn pow2i(n: Self) -> Self {
        let i = i32x4_add(i32x4_trunc_sat_f32x4(n.0), i32x4_splat(127));
        Self(i32x4_shl(i, 23))
    }
    #[inline(always)]
    fn exponent_mantissa(self) -> (Self, Self) {
        let bits = self.0;
        let e = i32x4_sub(
            v128_and(u32x4_shr(bits, 23), u32x4_splat(0xff)),
            i32x4_splat(127),
        );
        let m = v128_or(
            v128_and(bits, u32x4_splat(0x007f_ffff)),
            u32x4_splat(0x3f80_0000),
        );
        (Self(f32x4_convert_i32x4(e)), Self(m))
    }
    #[inline(always)]
    fn widen(self) -> Simd128Wide {
        let hi = i32x4_shuffle::<2, 3, 2, 3>(self.0, self.0);
        Simd128Wide([f64x2_promote_low_f32x4(self.0), f64x2_promote_low_f32x4(hi)])
    }
    #[inline(always)]
    fn narrow(w: Simd128Wide) -> Self {
        let lo = f32x4_demote_f64x2_zero(w.0[0]);
        let hi = f32x4_demote_f64x2_zero(w.0[1]);
        Self(i32x4_shuffle::<0, 1, 4, 5>(lo, hi))
    }
}

/// `task` in `simd128` code.
pub(super) fn task_simd128<T: LaneTask>(task: T) -> T::Output {
    task.run::<Simd128>()
}
