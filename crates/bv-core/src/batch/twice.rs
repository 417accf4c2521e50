//! [`Twice`]: two vectors of an instruction set's [`Lanes`] as one, each
//! operation applied to both halves, so that a kernel's code carries two
//! independent dependency chains side by side.
//!
//! # Why
//! A kernel with a transcendental in it is one long chain: Phong's lobe on
//! AVX2 is a conversion to f64, a dot product, a division (`ln`), a
//! polynomial of five steps, another of eight (`exp`) and a second
//! division, about 150 cycles of latency for 150 instructions (Zen 3). The
//! core's out-of-order window (256 entries) holds little more than one
//! iteration of such a loop, so it overlapped less than two vectors and
//! ran at about 90 cycles per vector where its instructions need about 40.
//! Written once against `Twice<V>`, the same kernel issues each operation
//! for two vectors back to back: the second chain fills the first one's
//! waits without the window having to find it. Both halves compute exactly
//! what `V` would have, lane for lane (the results are the same bits).
//!
//! The price is registers: every value takes two. A kernel that already
//! kept more than half of the 16 AVX2 registers live spills more, and one
//! that branches on whole vectors ([`super::LaneMask::any`]) finds fewer
//! uniform ones. So `Twice` is used where it measured faster: on AVX2 and
//! AVX-512 ([`super::Isa::twice`]), for the kernels whose
//! [`super::LaneKernel::TWICE`] is left true; the remainder of a batch runs
//! one vector at a time. AVX-512 has 32 registers, so the doubled values
//! spill less there: on an Intel Xeon (Sapphire Rapids class) criterion's
//! `batch/*/avx512x16` went 1.1 to 1.3 times faster for Phong, the
//! modified Phong, Blinn-Phong, Cook-Torrance, Disney, Oren-Nayar and
//! Lambert, with no kernel slower beyond that machine's noise.

use super::lanes::{LaneMask, Lanes, WideLanes};
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

/// Two vectors of `V` (the first holds lanes `0..V::LANES`).
#[derive(Debug, Clone, Copy)]
pub struct Twice<V>(pub V, pub V);

/// The mask of a comparison of [`Twice`].
#[derive(Debug, Clone, Copy)]
pub struct TwiceMask<M>(M, M);

/// The f64 lanes of a [`Twice`].
#[derive(Debug, Clone, Copy)]
pub struct TwiceWide<W>(W, W);

impl<M: LaneMask> BitAnd for TwiceMask<M> {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, o: Self) -> Self {
        Self(self.0 & o.0, self.1 & o.1)
    }
}
impl<M: LaneMask> BitOr for TwiceMask<M> {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, o: Self) -> Self {
        Self(self.0 | o.0, self.1 | o.1)
    }
}
impl<M: LaneMask> Not for TwiceMask<M> {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        Self(!self.0, !self.1)
    }
}
impl<M: LaneMask> LaneMask for TwiceMask<M> {
    #[inline(always)]
    fn any(self) -> bool {
        (self.0 | self.1).any()
    }
    #[inline(always)]
    fn all(self) -> bool {
        (self.0 & self.1).all()
    }
}

/// The arithmetic of a pair type `$t<$p>` (`Twice`, `TwiceWide`), each
/// half by itself: `$t op $t` for the first list of operators, `$t op
/// $scalar` for the second, and `-$t`.
macro_rules! halves_ops {
    ($t:ident<$p:ident: $bound:ident>, $scalar:ty;
     [$($tr:ident $f:ident),*]; [$($str:ident $sf:ident),*]) => {
        $(impl<$p: $bound> $tr for $t<$p> {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: Self) -> Self {
                Self(self.0.$f(o.0), self.1.$f(o.1))
            }
        })*
        $(impl<$p: $bound> $str<$scalar> for $t<$p> {
            type Output = Self;
            #[inline(always)]
            fn $sf(self, o: $scalar) -> Self {
                Self(self.0.$sf(o), self.1.$sf(o))
            }
        })*
        impl<$p: $bound> Neg for $t<$p> {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                Self(-self.0, -self.1)
            }
        }
    };
}
halves_ops!(Twice<V: Lanes>, f32; [Add add, Sub sub, Mul mul, Div div]; [Add add, Sub sub, Mul mul, Div div]);
halves_ops!(TwiceWide<W: WideLanes>, f64; [Add add, Sub sub, Mul mul]; [Add add, Mul mul]);

impl<V: Lanes> AddAssign for Twice<V> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
impl<V: Lanes> SubAssign for Twice<V> {
    #[inline(always)]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}
impl<V: Lanes> MulAssign for Twice<V> {
    #[inline(always)]
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}
impl<V: Lanes> From<f32> for Twice<V> {
    #[inline(always)]
    fn from(x: f32) -> Self {
        Self::splat(x)
    }
}

impl<V: Lanes> Lanes for Twice<V> {
    type Mask = TwiceMask<V::Mask>;
    type Wide = TwiceWide<V::Wide>;
    const LANES: usize = 2 * V::LANES;

    #[inline(always)]
    fn splat(x: f32) -> Self {
        let v = V::splat(x);
        Self(v, v)
    }
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        Self(V::load(s), V::load(&s[V::LANES..]))
    }
    #[inline(always)]
    fn store(self, s: &mut [f32]) {
        let (lo, hi) = s.split_at_mut(V::LANES);
        self.0.store(lo);
        self.1.store(hi);
    }
    #[inline(always)]
    fn store3(a: Self, b: Self, c: Self, out: &mut [[f32; 3]]) {
        let (lo, hi) = out.split_at_mut(V::LANES);
        V::store3(a.0, b.0, c.0, lo);
        V::store3(a.1, b.1, c.1, hi);
    }
    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        Self(self.0.mul_add(b.0, c.0), self.1.mul_add(b.1, c.1))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(self.0.sqrt(), self.1.sqrt())
    }
    #[inline(always)]
    fn rsqrt(self) -> Self {
        Self(self.0.rsqrt(), self.1.rsqrt())
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Self(self.0.abs(), self.1.abs())
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Self(self.0.min(o.0), self.1.min(o.1))
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Self(self.0.max(o.0), self.1.max(o.1))
    }
    #[inline(always)]
    fn round(self) -> Self {
        Self(self.0.round(), self.1.round())
    }
    #[inline(always)]
    fn lt(self, o: Self) -> Self::Mask {
        TwiceMask(self.0.lt(o.0), self.1.lt(o.1))
    }
    #[inline(always)]
    fn le(self, o: Self) -> Self::Mask {
        TwiceMask(self.0.le(o.0), self.1.le(o.1))
    }
    #[inline(always)]
    fn gt(self, o: Self) -> Self::Mask {
        TwiceMask(self.0.gt(o.0), self.1.gt(o.1))
    }
    #[inline(always)]
    fn ge(self, o: Self) -> Self::Mask {
        TwiceMask(self.0.ge(o.0), self.1.ge(o.1))
    }
    #[inline(always)]
    fn eq(self, o: Self) -> Self::Mask {
        TwiceMask(self.0.eq(o.0), self.1.eq(o.1))
    }
    #[inline(always)]
    fn select(m: Self::Mask, a: Self, b: Self) -> Self {
        Self(V::select(m.0, a.0, b.0), V::select(m.1, a.1, b.1))
    }
    #[inline(always)]
    fn pow2i(n: Self) -> Self {
        Self(V::pow2i(n.0), V::pow2i(n.1))
    }
    #[inline(always)]
    fn exponent_mantissa(self) -> (Self, Self) {
        let (e0, m0) = self.0.exponent_mantissa();
        let (e1, m1) = self.1.exponent_mantissa();
        (Self(e0, e1), Self(m0, m1))
    }
    #[inline(always)]
    fn widen(self) -> Self::Wide {
        TwiceWide(self.0.widen(), self.1.widen())
    }
    #[inline(always)]
    fn narrow(w: Self::Wide) -> Self {
        Self(V::narrow(w.0), V::narrow(w.1))
    }
}

impl<W: WideLanes> WideLanes for TwiceWide<W> {
    type Narrow = Twice<W::Narrow>;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        let v = W::splat(x);
        Self(v, v)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(self.0.sqrt(), self.1.sqrt())
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Self(self.0.min(o.0), self.1.min(o.1))
    }
}
