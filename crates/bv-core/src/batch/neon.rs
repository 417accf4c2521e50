//! [`Lanes`] on AArch64: NEON (Advanced SIMD, 4 lanes), part of the
//! architecture's baseline, so its types need no run-time check: every
//! AArch64 CPU that runs Rust's `aarch64-*` targets has it.

use super::LaneTask;
use super::lanes::{Lanes, mask_ops, vector_ops, wide_pair};
use std::arch::aarch64::*;

/// Four f32 lanes in a 128-bit NEON register.
#[derive(Clone, Copy, Debug)]
pub(super) struct Neon(float32x4_t);
/// A comparison result of [`Neon`]: all-ones or all-zeros per lane.
#[derive(Clone, Copy, Debug)]
pub(super) struct NeonMask(uint32x4_t);
/// The lanes of [`Neon`] in f64: lanes 0–1, then 2–3.
#[derive(Clone, Copy, Debug)]
pub(super) struct NeonWide([float64x2_t; 2]);

vector_ops!(Neon, f32, vaddq_f32, vsubq_f32, vmulq_f32, vdivq_f32, |x| {
    Neon(unsafe { vnegq_f32(x.0) })
});
mask_ops!(
    NeonMask,
    vandq_u32,
    vorrq_u32,
    |x| NeonMask(unsafe { vmvnq_u32(x.0) }),
    // SAFETY: NEON is baseline on AArch64.
    any | x | unsafe { vmaxvq_u32(x.0) } != 0,
    all | x | unsafe { vminvq_u32(x.0) } != 0
);

impl From<f32> for Neon {
    #[inline(always)]
    fn from(x: f32) -> Self {
        // SAFETY: NEON is baseline on AArch64.
        Self(unsafe { vdupq_n_f32(x) })
    }
}

wide_pair!(
    NeonWide,
    Neon,
    float64x2_t,
    vaddq_f64,
    vsubq_f64,
    vmulq_f64,
    vdupq_n_f64,
    vsqrtq_f64,
    vminnmq_f64,
    |x| NeonWide(unsafe { [vnegq_f64(x.0[0]), vnegq_f64(x.0[1])] })
);

impl Lanes for Neon {
    type Mask = NeonMask;
    type Wide = NeonWide;
    const LANES: usize = 4;

    #[inline(always)]
    fn splat(x: f32) -> Self {
        Self::from(x)
    }
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        let s = &s[..4];
        // SAFETY: `s` holds 4 floats; NEON is baseline on AArch64.
        Self(unsafe { vld1q_f32(s.as_ptr()) })
    }
    #[inline(always)]
    fn store(self, s: &mut [f32]) {
        let s = &mut s[..4];
        // SAFETY: `s` has room for 4 floats; NEON is baseline on AArch64.
        unsafe { vst1q_f32(s.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn store3(a: Self, b: Self, c: Self, out: &mut [[f32; 3]]) {
        let s = out[..4].as_flattened_mut();
        // SAFETY: `s` has room for 12 floats; `vst3q_f32` is NEON's
        // three-way interleaving store; NEON is baseline on AArch64.
        unsafe { vst3q_f32(s.as_mut_ptr(), float32x4x3_t(a.0, b.0, c.0)) }
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        // `vfmaq_f32(c, a, b)` is `c + a·b`, fused.
        // SAFETY: NEON is baseline on AArch64.
        Self(unsafe { vfmaq_f32(c.0, self.0, b.0) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: NEON is baseline on AArch64.
        Self(unsafe { vsqrtq_f32(self.0) })
    }
    #[inline(always)]
    fn rsqrt(self) -> Self {
        // The estimate is good to about 2⁻⁸; each `vrsqrts` step, (3 − x·y²)/2,
        // squares the error.
        // SAFETY: NEON is baseline on AArch64.
        unsafe {
            let x = self.0;
            let mut y = vrsqrteq_f32(x);
            y = vmulq_f32(y, vrsqrtsq_f32(vmulq_f32(x, y), y));
            y = vmulq_f32(y, vrsqrtsq_f32(vmulq_f32(x, y), y));
            Self(y)
        }
    }
    #[inline(always)]
    fn abs(self) -> Self {
        // SAFETY: NEON is baseline on AArch64.
        Self(unsafe { vabsq_f32(self.0) })
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        // fminnm: IEEE minNum, the number when one operand is NaN.
        // SAFETY: NEON is baseline on AArch64.
        Self(unsafe { vminnmq_f32(self.0, o.0) })
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        // SAFETY: NEON is baseline on AArch64.
        Self(unsafe { vmaxnmq_f32(self.0, o.0) })
    }
    #[inline(always)]
    fn round(self) -> Self {
        // SAFETY: NEON is baseline on AArch64.
        Self(unsafe { vrndnq_f32(self.0) })
    }
    #[inline(always)]
    fn lt(self, o: Self) -> NeonMask {
        // SAFETY: NEON is baseline on AArch64.
        NeonMask(unsafe { vcltq_f32(self.0, o.0) })
    }
    #[inline(always)]
    fn le(self, o: Self) -> NeonMask {
        // SAFETY: NEON is baseline on AArch64.
        NeonMask(unsafe { vcleq_f32(self.0, o.0) })
    }
    #[inline(always)]
    fn gt(self, o: Self) -> NeonMask {
        // SAFETY: NEON is baseline on AArch64.
        NeonMask(unsafe { vcgtq_f32(self.0, o.0) })
    }
    #[inline(always)]
    fn ge(self, o: Self) -> NeonMask {
        // SAFETY: NEON is baseline on AArch64.
        NeonMask(unsafe { vcgeq_f32(self.0, o.0) })
    }
    #[inline(always)]
    fn eq(self, o: Self) -> NeonMask {
        // SAFETY: NEON is baseline on AArch64.
        NeonMask(unsafe { vceqq_f32(self.0, o.0) })
    }
    #[inline(always)]
    fn select(m: NeonMask, a: Self, b: Self) -> Self {
        // SAFETY: NEON is baseline on AArch64.
        Self(unsafe { vbslq_f32(m.0, a.0, b.0) })
    }
    #[inline(always)]
    fn pow2i(n: Self) -> Self {
        // SAFETY: NEON is baseline on AArch64.
        Self(unsafe {
            let i = vaddq_s32(vcvtnq_s32_f32(n.0), vdupq_n_s32(127));
            vreinterpretq_f32_s32(vshlq_n_s32::<23>(i))
        })
    }
    #[inline(always)]
    fn exponent_mantissa(self) -> (Self, Self) {
        // SAFETY: NEON is baseline on AArch64.
        unsafe {
            let bits = vreinterpretq_u32_f32(self.0);
            let e = vsubq_s32(
                vreinterpretq_s32_u32(vandq_u32(vshrq_n_u32::<23>(bits), vdupq_n_u32(0xff))),
                vdupq_n_s32(127),
            );
            let m = vorrq_u32(
                vandq_u32(bits, vdupq_n_u32(0x007f_ffff)),
                vdupq_n_u32(0x3f80_0000),
            );
            (Self(vcvtq_f32_s32(e)), Self(vreinterpretq_f32_u32(m)))
        }
    }
    #[inline(always)]
    fn widen(self) -> NeonWide {
        // SAFETY: NEON is baseline on AArch64.
        unsafe {
            NeonWide([
                vcvt_f64_f32(vget_low_f32(self.0)),
                vcvt_high_f64_f32(self.0),
            ])
        }
    }
    #[inline(always)]
    fn narrow(w: NeonWide) -> Self {
        // SAFETY: NEON is baseline on AArch64.
        Self(unsafe { vcvt_high_f32_f64(vcvt_f32_f64(w.0[0]), w.0[1]) })
    }
}

/// `task` in NEON code.
pub(super) fn task_neon<T: LaneTask>(task: T) -> T::Output {
    task.run::<Neon>()
}
