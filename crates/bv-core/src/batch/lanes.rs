//! The vector types the batch kernels are written against.
//!
//! A kernel's lane code is generic over [`Lanes`], a vector of `f32` lanes
//! with the arithmetic operators, comparisons that give a [`LaneMask`],
//! selects, and the few bit-level steps that `exp` and `ln` need. The same
//! source is compiled once per instruction set: `f32` itself (one lane, the
//! scalar fallback), AVX2 + FMA (8 lanes), AVX-512 (16), NEON (4) and wasm
//! `simd128` (4), see [`super::isa`]. Because every operation is a vector
//! operation by construction, no kernel depends on the compiler's
//! auto-vectoriser deciding that a loop is worth it.
//!
//! Where a kernel needs f64 for accuracy (a cosine near 1 that is raised to
//! a power of 10⁴), [`Lanes::Wide`] holds the same lanes as f64.
//!
//! Semantics shared by every implementation, so that a kernel gives the same
//! answer on every path up to the rounding of its own operations:
//! - `+ − × ÷` and `sqrt` are IEEE-754 single precision, correctly rounded
//!   (no fused multiply-add is formed behind the kernel's back: only
//!   [`Lanes::mul_add`] asks for one, and it is fused where the instruction
//!   set has the instruction, two roundings elsewhere);
//! - comparisons are ordered: any comparison with a NaN is false;
//! - `a.min(b)` and `a.max(b)` return `b` when `a` is NaN (as
//!   `f32::min`/`max` do; a NaN `b` is not specified);
//! - [`Lanes::round`] rounds half to even;
//! - [`Lanes::rsqrt`] is the one approximate operation (within 2⁻²¹
//!   relative, not the same bits on every path): for the lobe mesh's
//!   normals, never for a model's value.

use std::fmt::Debug;
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

/// A per-lane truth value, from a comparison of [`Lanes`].
pub trait LaneMask:
    Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self>
{
    /// Whether any lane is true: for a kernel that skips the work of a
    /// case no lane of the vector is in (a branch on the whole vector, not
    /// a select per lane).
    fn any(self) -> bool;

    /// Whether every lane is true.
    fn all(self) -> bool;

    /// `a` in the lanes where the mask is true, `b` elsewhere.
    #[inline(always)]
    fn select<V: Lanes<Mask = Self>>(self, a: V, b: V) -> V {
        V::select(self, a, b)
    }
}

/// A vector of f32 lanes (see the module doc).
pub trait Lanes:
    Copy
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f32, Output = Self>
    + Sub<f32, Output = Self>
    + Mul<f32, Output = Self>
    + Div<f32, Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + From<f32>
{
    /// The result of a comparison.
    type Mask: LaneMask;
    /// The same lanes in f64.
    type Wide: WideLanes<Narrow = Self>;
    /// Lanes per vector.
    const LANES: usize;

    /// Every lane `x`.
    fn splat(x: f32) -> Self;
    /// The first [`Self::LANES`] values of `s` (which must hold that many).
    fn load(s: &[f32]) -> Self;
    /// Writes the lanes to the first [`Self::LANES`] places of `s`.
    fn store(self, s: &mut [f32]);
    /// Writes `[a, b, c]` of lane `l` to `out[l]`, for the first
    /// [`Self::LANES`] places of `out`: a mesh's `[x, y, z]` vertices from
    /// structure-of-arrays lanes, interleaved in registers. (Through lane
    /// buffers, LLVM stored them a float at a time: a third of a Lambert
    /// lobe's time on AVX2.)
    fn store3(a: Self, b: Self, c: Self, out: &mut [[f32; 3]]);

    /// `self · b + c` per lane, rounded once where the instruction set has
    /// a fused multiply-add (AVX2 + FMA, AVX-512, NEON) and twice where it
    /// has not (wasm `simd128`, and the scalar fallback, which is built for
    /// any CPU: there `f32::mul_add` would be a software `fmaf`). For the
    /// dependency chains of [`super::math`]'s polynomials, whose error
    /// bounds hold for either rounding: one instruction of 4 cycles'
    /// latency where a multiply and an add take 6 (Zen 3), and the exp in a
    /// Phong kernel is a chain of seven.
    fn mul_add(self, b: Self, c: Self) -> Self;
    /// `√x` per lane.
    fn sqrt(self) -> Self;
    /// `1/√x` per lane for finite `x` ≥ `f32::MIN_POSITIVE`, within 2⁻²¹
    /// relative: the instruction set's estimate refined by Newton's method
    /// where it has one (no divider), `1/√x` rounded twice where it has not.
    /// Unspecified for other `x`: a caller selects those lanes away.
    fn rsqrt(self) -> Self;
    /// `|x|` per lane.
    fn abs(self) -> Self;
    /// The smaller of the two per lane (`o` where `self` is NaN).
    fn min(self, o: Self) -> Self;
    /// The larger of the two per lane (`o` where `self` is NaN).
    fn max(self, o: Self) -> Self;
    /// Rounded to the nearest integer, half to even.
    fn round(self) -> Self;

    /// `self < o` per lane.
    fn lt(self, o: Self) -> Self::Mask;
    /// `self ≤ o` per lane.
    fn le(self, o: Self) -> Self::Mask;
    /// `self > o` per lane.
    fn gt(self, o: Self) -> Self::Mask;
    /// `self ≥ o` per lane.
    fn ge(self, o: Self) -> Self::Mask;
    /// `self == o` per lane.
    fn eq(self, o: Self) -> Self::Mask;
    /// `a` where `m` is true, `b` elsewhere.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;

    /// `2ⁿ` for lanes holding integers `n` in [−126, 127] (a normal float
    /// built from its exponent bits).
    fn pow2i(n: Self) -> Self;
    /// `(e, m)` with `x = m · 2ᵉ`, `m ∈ [1, 2)`, for positive normal `x`:
    /// the unbiased exponent as a float and the mantissa (unspecified for
    /// other `x`).
    fn exponent_mantissa(self) -> (Self, Self);

    /// The lanes widened exactly to f64.
    fn widen(self) -> Self::Wide;
    /// f64 lanes rounded to f32.
    fn narrow(w: Self::Wide) -> Self;

    /// Clamped to `[lo, hi]` (`lo` where NaN).
    #[inline(always)]
    fn clamp(self, lo: f32, hi: f32) -> Self {
        self.max(Self::splat(lo)).min(Self::splat(hi))
    }
    /// Whether each lane is finite (not NaN or ±∞).
    #[inline(always)]
    fn is_finite(self) -> Self::Mask {
        self.abs().lt(Self::splat(f32::INFINITY))
    }
}

/// The f64 lanes of a [`Lanes`] type, for the few steps that need them.
pub trait WideLanes:
    Copy
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Neg<Output = Self>
    + Mul<f64, Output = Self>
    + Add<f64, Output = Self>
{
    /// The f32 lanes these widen.
    type Narrow: Lanes<Wide = Self>;
    /// Every lane `x`.
    fn splat(x: f64) -> Self;
    /// `√x` per lane.
    fn sqrt(self) -> Self;
    /// The smaller of the two per lane.
    fn min(self, o: Self) -> Self;
    /// `1 − x`, written out for readability at call sites.
    #[inline(always)]
    fn one_minus(self) -> Self {
        -self + 1.0
    }
}

// ---------------------------------------------------------------------------
// The scalar fallback: one lane, `f32` itself.

impl LaneMask for bool {
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
    #[inline(always)]
    fn all(self) -> bool {
        self
    }
}

impl Lanes for f32 {
    type Mask = bool;
    type Wide = f64;
    const LANES: usize = 1;

    #[inline(always)]
    fn splat(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        s[0]
    }
    #[inline(always)]
    fn store(self, s: &mut [f32]) {
        s[0] = self;
    }
    #[inline(always)]
    fn store3(a: Self, b: Self, c: Self, out: &mut [[f32; 3]]) {
        out[0] = [a, b, c];
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        // Two roundings: see the trait doc.
        self * b + c
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn rsqrt(self) -> Self {
        1.0 / f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        // As the vector paths: `o` when `self` is NaN.
        if self < o { self } else { o }
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        if self > o { self } else { o }
    }
    #[inline(always)]
    fn round(self) -> Self {
        self.round_ties_even()
    }
    #[inline(always)]
    fn lt(self, o: Self) -> bool {
        self < o
    }
    #[inline(always)]
    fn le(self, o: Self) -> bool {
        self <= o
    }
    #[inline(always)]
    fn gt(self, o: Self) -> bool {
        self > o
    }
    #[inline(always)]
    fn ge(self, o: Self) -> bool {
        self >= o
    }
    #[inline(always)]
    fn eq(self, o: Self) -> bool {
        self == o
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m { a } else { b }
    }
    #[inline(always)]
    fn pow2i(n: Self) -> Self {
        f32::from_bits(((n as i32 + 127) as u32) << 23)
    }
    #[inline(always)]
    fn exponent_mantissa(self) -> (Self, Self) {
        let bits = self.to_bits();
        let e = ((bits >> 23) & 0xff) as i32 - 127;
        let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
        (e as f32, m)
    }
    #[inline(always)]
    fn widen(self) -> f64 {
        f64::from(self)
    }
    #[inline(always)]
    fn narrow(w: f64) -> Self {
        w as f32
    }
}

impl WideLanes for f64 {
    type Narrow = f32;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        if self < o { self } else { o }
    }
}

/// Implements the operators of a vector type whose field `.0` is the
/// register: `$add` etc. are the intrinsics, called in `unsafe` blocks
/// whose soundness is the type's invariant (it exists only where its
/// instruction set does; see each type's doc).
macro_rules! vector_ops {
    ($t:ident, $scalar:ty, $add:path, $sub:path, $mul:path, $div:path, |$x:ident| $neg:expr) => {
        impl std::ops::Add for $t {
            type Output = Self;
            #[inline(always)]
            fn add(self, o: Self) -> Self {
                // SAFETY: see the type's invariant.
                Self(unsafe { $add(self.0, o.0) })
            }
        }
        impl std::ops::Sub for $t {
            type Output = Self;
            #[inline(always)]
            fn sub(self, o: Self) -> Self {
                // SAFETY: see the type's invariant.
                Self(unsafe { $sub(self.0, o.0) })
            }
        }
        impl std::ops::Mul for $t {
            type Output = Self;
            #[inline(always)]
            fn mul(self, o: Self) -> Self {
                // SAFETY: see the type's invariant.
                Self(unsafe { $mul(self.0, o.0) })
            }
        }
        impl std::ops::Div for $t {
            type Output = Self;
            #[inline(always)]
            fn div(self, o: Self) -> Self {
                // SAFETY: see the type's invariant.
                Self(unsafe { $div(self.0, o.0) })
            }
        }
        impl std::ops::Neg for $t {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                let $x = self;
                $neg
            }
        }
        impl std::ops::Add<$scalar> for $t {
            type Output = Self;
            #[inline(always)]
            fn add(self, o: $scalar) -> Self {
                self + Self::from(o)
            }
        }
        impl std::ops::Sub<$scalar> for $t {
            type Output = Self;
            #[inline(always)]
            fn sub(self, o: $scalar) -> Self {
                self - Self::from(o)
            }
        }
        impl std::ops::Mul<$scalar> for $t {
            type Output = Self;
            #[inline(always)]
            fn mul(self, o: $scalar) -> Self {
                self * Self::from(o)
            }
        }
        impl std::ops::Div<$scalar> for $t {
            type Output = Self;
            #[inline(always)]
            fn div(self, o: $scalar) -> Self {
                self / Self::from(o)
            }
        }
        impl std::ops::AddAssign for $t {
            #[inline(always)]
            fn add_assign(&mut self, o: Self) {
                *self = *self + o;
            }
        }
        impl std::ops::SubAssign for $t {
            #[inline(always)]
            fn sub_assign(&mut self, o: Self) {
                *self = *self - o;
            }
        }
        impl std::ops::MulAssign for $t {
            #[inline(always)]
            fn mul_assign(&mut self, o: Self) {
                *self = *self * o;
            }
        }
    };
}
pub(crate) use vector_ops;

/// Implements `&`, `|` and `!` of a mask type whose field `.0` is the
/// register (see [`vector_ops`] for the safety argument).
macro_rules! mask_ops {
    ($t:ident, $and:path, $or:path, |$x:ident| $not:expr,
     any |$a:ident| $any:expr, all |$b:ident| $all:expr) => {
        impl std::ops::BitAnd for $t {
            type Output = Self;
            #[inline(always)]
            fn bitand(self, o: Self) -> Self {
                // SAFETY: see the type's invariant.
                Self(unsafe { $and(self.0, o.0) })
            }
        }
        impl std::ops::BitOr for $t {
            type Output = Self;
            #[inline(always)]
            fn bitor(self, o: Self) -> Self {
                // SAFETY: see the type's invariant.
                Self(unsafe { $or(self.0, o.0) })
            }
        }
        impl std::ops::Not for $t {
            type Output = Self;
            #[inline(always)]
            fn not(self) -> Self {
                let $x = self;
                $not
            }
        }
        impl $crate::batch::lanes::LaneMask for $t {
            #[inline(always)]
            fn any(self) -> bool {
                let $a = self;
                $any
            }
            #[inline(always)]
            fn all(self) -> bool {
                let $b = self;
                $all
            }
        }
    };
}
pub(crate) use mask_ops;

/// Builds a `WideLanes` pair type: two f64 registers holding the lanes of
/// one f32 register, each operation applied to both halves.
macro_rules! wide_pair {
    ($t:ident, $narrow:ident, $reg:ty, $add:path, $sub:path, $mul:path, $set1:path,
     $sqrt:path, $min:path, |$x:ident| $neg:expr) => {
        impl std::ops::Add for $t {
            type Output = Self;
            #[inline(always)]
            fn add(self, o: Self) -> Self {
                // SAFETY: see the type's invariant.
                unsafe { Self([$add(self.0[0], o.0[0]), $add(self.0[1], o.0[1])]) }
            }
        }
        impl std::ops::Sub for $t {
            type Output = Self;
            #[inline(always)]
            fn sub(self, o: Self) -> Self {
                // SAFETY: see the type's invariant.
                unsafe { Self([$sub(self.0[0], o.0[0]), $sub(self.0[1], o.0[1])]) }
            }
        }
        impl std::ops::Mul for $t {
            type Output = Self;
            #[inline(always)]
            fn mul(self, o: Self) -> Self {
                // SAFETY: see the type's invariant.
                unsafe { Self([$mul(self.0[0], o.0[0]), $mul(self.0[1], o.0[1])]) }
            }
        }
        impl std::ops::Neg for $t {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                let $x = self;
                $neg
            }
        }
        impl std::ops::Mul<f64> for $t {
            type Output = Self;
            #[inline(always)]
            fn mul(self, o: f64) -> Self {
                self * <Self as $crate::batch::lanes::WideLanes>::splat(o)
            }
        }
        impl std::ops::Add<f64> for $t {
            type Output = Self;
            #[inline(always)]
            fn add(self, o: f64) -> Self {
                self + <Self as $crate::batch::lanes::WideLanes>::splat(o)
            }
        }
        impl $crate::batch::lanes::WideLanes for $t {
            type Narrow = $narrow;
            #[inline(always)]
            fn splat(x: f64) -> Self {
                // SAFETY: see the type's invariant.
                unsafe {
                    let v: $reg = $set1(x);
                    Self([v, v])
                }
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                // SAFETY: see the type's invariant.
                unsafe { Self([$sqrt(self.0[0]), $sqrt(self.0[1])]) }
            }
            #[inline(always)]
            fn min(self, o: Self) -> Self {
                // SAFETY: see the type's invariant.
                unsafe { Self([$min(self.0[0], o.0[0]), $min(self.0[1], o.0[1])]) }
            }
        }
    };
}

pub(crate) use wide_pair;
