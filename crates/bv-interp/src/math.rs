//! The scalar operations of WGSL and GLSL, evaluated in f64 on cells.
//!
//! Integers arrive as exact `f64` cells; the integer operations convert to
//! `i32`/`u32`, wrap like WGSL (two's complement, shifts by the low five
//! bits), and convert back. Division follows WGSL's rules for the cases GLSL
//! leaves undefined: `x / 0 == x`, `x % 0 == 0`, `i32::MIN / -1 == i32::MIN`.

/// A one-operand componentwise operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Un {
    FNeg,
    INeg,
    Not,
    BitNotI,
    BitNotU,
    Abs,
    IAbs,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Asinh,
    Acosh,
    Atanh,
    Radians,
    Degrees,
    Ceil,
    Floor,
    Round,
    Fract,
    Trunc,
    Exp,
    Exp2,
    Log,
    Log2,
    Sqrt,
    InverseSqrt,
    Sign,
    Saturate,
    IsNan,
    IsInf,
    CountOneBits,
    CountLeadingZeros,
    CountTrailingZeros,
    ReverseBitsI,
    ReverseBitsU,
    FirstLeadingBitI,
    FirstLeadingBitU,
    FirstTrailingBitI,
    FirstTrailingBitU,
    /// Float to `i32`, saturating (NaN to 0), as WGSL `i32(f)`.
    F2I,
    /// Float to `u32`, saturating.
    F2U,
    /// `u32` bits as `i32`.
    U2I,
    /// `i32` bits as `u32`.
    I2U,
    /// Anything to `bool` (`x != 0`).
    ToBool,
    /// The bits of an `f32` as `i32` (`bitcast<i32>(f)`).
    FBitsI,
    /// The bits of an `f32` as `u32`.
    FBitsU,
    /// 32 integer bits as an `f32`.
    BitsF,
}

/// A two-operand componentwise operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Bin {
    FAdd,
    FSub,
    FMul,
    FDiv,
    FRem,
    IAdd,
    ISub,
    IMul,
    IDiv,
    IRem,
    UAdd,
    USub,
    UMul,
    UDiv,
    URem,
    AndI,
    OrI,
    XorI,
    AndU,
    OrU,
    XorU,
    ShlI,
    ShlU,
    ShrI,
    ShrU,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    LAnd,
    LOr,
    Min,
    Max,
    Pow,
    Atan2,
    Step,
    Ldexp,
}

/// A three-operand componentwise operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Tern {
    Clamp,
    Mix,
    Fma,
    SmoothStep,
    ExtractBitsI,
    ExtractBitsU,
}

/// The 32 bits of an integer cell (an `i32` or a `u32`: their non-negative
/// values share bits).
#[inline]
pub(crate) fn bits(x: f64) -> u32 {
    if x < 0.0 { x as i32 as u32 } else { x as u32 }
}

#[inline]
fn si(b: u32) -> f64 {
    f64::from(b as i32)
}

#[inline]
fn ui(b: u32) -> f64 {
    f64::from(b)
}

#[inline]
fn b(x: bool) -> f64 {
    if x { 1.0 } else { 0.0 }
}

/// `x · 2^e` without the premature overflow of `2^e` (C's `ldexp`).
pub(crate) fn ldexp(x: f64, e: f64) -> f64 {
    let mut e = e.clamp(-2300.0, 2300.0) as i32;
    let mut x = x;
    while e > 1000 {
        x *= 2f64.powi(1000);
        e -= 1000;
    }
    while e < -1000 {
        x *= 2f64.powi(-1000);
        e += 1000;
    }
    x * 2f64.powi(e)
}

/// `(fraction, exponent)` with `x = fraction · 2^exponent` and
/// `0.5 ≤ |fraction| < 1` (both 0 for 0; non-finite `x` gives `(x, 0)`).
pub(crate) fn frexp(x: f64) -> (f64, f64) {
    if x == 0.0 || !x.is_finite() {
        return (x, 0.0);
    }
    // Scale subnormals into the normal range so the exponent field is exact.
    let (x, bias) = if x.abs() < f64::MIN_POSITIVE {
        (x * 2f64.powi(64), -64)
    } else {
        (x, 0)
    };
    let bitsx = x.to_bits();
    let exp = ((bitsx >> 52) & 0x7ff) as i64 - 1022;
    let frac = f64::from_bits((bitsx & !(0x7ff << 52)) | (1022 << 52));
    (frac, (exp + bias) as f64)
}

#[inline]
pub(crate) fn un(op: Un, x: f64) -> f64 {
    match op {
        Un::FNeg => -x,
        Un::INeg => si((x as i32).wrapping_neg() as u32),
        Un::Not => b(x == 0.0),
        Un::BitNotI => si(!bits(x)),
        Un::BitNotU => ui(!bits(x)),
        Un::Abs => x.abs(),
        Un::IAbs => si((x as i32).wrapping_abs() as u32),
        Un::Sin => x.sin(),
        Un::Cos => x.cos(),
        Un::Tan => x.tan(),
        Un::Asin => x.asin(),
        Un::Acos => x.acos(),
        Un::Atan => x.atan(),
        Un::Sinh => x.sinh(),
        Un::Cosh => x.cosh(),
        Un::Tanh => x.tanh(),
        Un::Asinh => x.asinh(),
        Un::Acosh => x.acosh(),
        Un::Atanh => x.atanh(),
        Un::Radians => x.to_radians(),
        Un::Degrees => x.to_degrees(),
        Un::Ceil => x.ceil(),
        Un::Floor => x.floor(),
        // WGSL `round` rounds halfway cases to even.
        Un::Round => x.round_ties_even(),
        // WGSL `fract(x) = x - floor(x)`.
        Un::Fract => x - x.floor(),
        Un::Trunc => x.trunc(),
        Un::Exp => x.exp(),
        Un::Exp2 => x.exp2(),
        Un::Log => x.ln(),
        Un::Log2 => x.log2(),
        Un::Sqrt => x.sqrt(),
        Un::InverseSqrt => 1.0 / x.sqrt(),
        Un::Sign => {
            if x > 0.0 {
                1.0
            } else if x < 0.0 {
                -1.0
            } else {
                x
            }
        }
        // min/max rather than `clamp`: a NaN becomes 0 (IEEE maxNum, as
        // GPU min/max behave) instead of staying NaN.
        #[allow(clippy::manual_clamp)]
        Un::Saturate => x.max(0.0).min(1.0),
        Un::IsNan => b(x.is_nan()),
        Un::IsInf => b(x.is_infinite()),
        Un::CountOneBits => ui(bits(x).count_ones()),
        Un::CountLeadingZeros => ui(bits(x).leading_zeros()),
        Un::CountTrailingZeros => ui(bits(x).trailing_zeros()),
        Un::ReverseBitsI => si(bits(x).reverse_bits()),
        Un::ReverseBitsU => ui(bits(x).reverse_bits()),
        Un::FirstLeadingBitI => {
            let v = if x < 0.0 { !bits(x) } else { bits(x) };
            if v == 0 {
                -1.0
            } else {
                ui(31 - v.leading_zeros())
            }
        }
        Un::FirstLeadingBitU => {
            let v = bits(x);
            if v == 0 {
                ui(u32::MAX)
            } else {
                ui(31 - v.leading_zeros())
            }
        }
        Un::FirstTrailingBitI => {
            let v = bits(x);
            if v == 0 { -1.0 } else { ui(v.trailing_zeros()) }
        }
        Un::FirstTrailingBitU => {
            let v = bits(x);
            if v == 0 {
                ui(u32::MAX)
            } else {
                ui(v.trailing_zeros())
            }
        }
        Un::F2I => f64::from(x as i32),
        Un::F2U => f64::from(x as u32),
        Un::U2I => si(bits(x)),
        Un::I2U => ui(bits(x)),
        Un::ToBool => b(x != 0.0),
        Un::FBitsI => si((x as f32).to_bits()),
        Un::FBitsU => ui((x as f32).to_bits()),
        Un::BitsF => f64::from(f32::from_bits(bits(x))),
    }
}

#[inline]
pub(crate) fn bin(op: Bin, x: f64, y: f64) -> f64 {
    match op {
        Bin::FAdd => x + y,
        Bin::FSub => x - y,
        Bin::FMul => x * y,
        Bin::FDiv => x / y,
        // WGSL's float `%` truncates like C's fmod.
        Bin::FRem => x % y,
        Bin::IAdd => si((x as i32).wrapping_add(y as i32) as u32),
        Bin::ISub => si((x as i32).wrapping_sub(y as i32) as u32),
        Bin::IMul => si((x as i32).wrapping_mul(y as i32) as u32),
        Bin::IDiv => {
            let (a, c) = (x as i32, y as i32);
            if c == 0 {
                x
            } else {
                f64::from(a.wrapping_div(c))
            }
        }
        Bin::IRem => {
            let (a, c) = (x as i32, y as i32);
            if c == 0 {
                0.0
            } else {
                f64::from(a.wrapping_rem(c))
            }
        }
        Bin::UAdd => ui(bits(x).wrapping_add(bits(y))),
        Bin::USub => ui(bits(x).wrapping_sub(bits(y))),
        Bin::UMul => ui(bits(x).wrapping_mul(bits(y))),
        Bin::UDiv => {
            if bits(y) == 0 {
                x
            } else {
                ui(bits(x) / bits(y))
            }
        }
        Bin::URem => {
            if bits(y) == 0 {
                0.0
            } else {
                ui(bits(x) % bits(y))
            }
        }
        Bin::AndI => si(bits(x) & bits(y)),
        Bin::OrI => si(bits(x) | bits(y)),
        Bin::XorI => si(bits(x) ^ bits(y)),
        Bin::AndU => ui(bits(x) & bits(y)),
        Bin::OrU => ui(bits(x) | bits(y)),
        Bin::XorU => ui(bits(x) ^ bits(y)),
        Bin::ShlI => si(bits(x).wrapping_shl(bits(y))),
        Bin::ShlU => ui(bits(x).wrapping_shl(bits(y))),
        Bin::ShrI => f64::from((x as i32).wrapping_shr(bits(y))),
        Bin::ShrU => ui(bits(x).wrapping_shr(bits(y))),
        Bin::Eq => b(x == y),
        Bin::Ne => b(x != y),
        Bin::Lt => b(x < y),
        Bin::Le => b(x <= y),
        Bin::Gt => b(x > y),
        Bin::Ge => b(x >= y),
        Bin::LAnd => b(x != 0.0 && y != 0.0),
        Bin::LOr => b(x != 0.0 || y != 0.0),
        Bin::Min => x.min(y),
        Bin::Max => x.max(y),
        Bin::Pow => x.powf(y),
        Bin::Atan2 => x.atan2(y),
        // WGSL `step(edge, x)` is 1 when `edge <= x`.
        Bin::Step => b(x <= y),
        Bin::Ldexp => ldexp(x, y),
    }
}

/// WGSL `extractBits`: `count` bits from `offset`, sign-extended for `i32`.
fn extract_bits(e: f64, offset: f64, count: f64, signed: bool) -> f64 {
    let o = bits(offset).min(32);
    let c = bits(count).min(32 - o);
    if c == 0 {
        return 0.0;
    }
    let v = bits(e) >> o;
    let v = if c == 32 { v } else { v & ((1u32 << c) - 1) };
    if signed {
        let shift = 32 - c;
        f64::from(((v << shift) as i32) >> shift)
    } else {
        ui(v)
    }
}

/// WGSL `insertBits`.
pub(crate) fn insert_bits(e: f64, new: f64, offset: f64, count: f64, signed: bool) -> f64 {
    let o = bits(offset).min(32);
    let c = bits(count).min(32 - o);
    if c == 0 {
        return e;
    }
    let mask = if c == 32 {
        u32::MAX
    } else {
        ((1u32 << c) - 1) << o
    };
    let v = (bits(e) & !mask) | (bits(new).wrapping_shl(o) & mask);
    if signed { si(v) } else { ui(v) }
}

#[inline]
pub(crate) fn tern(op: Tern, x: f64, y: f64, z: f64) -> f64 {
    match op {
        // WGSL `clamp(e, low, high) = min(max(e, low), high)`.
        Tern::Clamp => x.max(y).min(z),
        // WGSL `mix(e1, e2, e3) = e1 * (1 - e3) + e2 * e3`.
        Tern::Mix => x * (1.0 - z) + y * z,
        Tern::Fma => x.mul_add(y, z),
        Tern::SmoothStep => {
            #[allow(clippy::manual_clamp)]
            let t = ((z - x) / (y - x)).max(0.0).min(1.0);
            t * t * (3.0 - 2.0 * t)
        }
        Tern::ExtractBitsI => extract_bits(x, y, z, true),
        Tern::ExtractBitsU => extract_bits(x, y, z, false),
    }
}

/// The determinant of the `n`×`n` column-major matrix `m` (`n` ≤ 4), by
/// cofactor expansion along the first column.
pub(crate) fn determinant(m: &[f64], n: usize) -> f64 {
    match n {
        0 => 1.0,
        1 => m[0],
        2 => m[0] * m[3] - m[2] * m[1],
        _ => {
            let mut det = 0.0;
            for row in 0..n {
                let minor = minor(m, n, 0, row);
                let sign = if row % 2 == 0 { 1.0 } else { -1.0 };
                det += sign * m[row] * determinant(&minor[..(n - 1) * (n - 1)], n - 1);
            }
            det
        }
    }
}

/// The column-major `(n-1)`×`(n-1)` matrix left when column `col` and row
/// `row` are removed.
fn minor(m: &[f64], n: usize, col: usize, row: usize) -> [f64; 9] {
    let mut out = [0.0; 9];
    let mut k = 0;
    for c in (0..n).filter(|&c| c != col) {
        for r in (0..n).filter(|&r| r != row) {
            out[k] = m[c * n + r];
            k += 1;
        }
    }
    out
}

/// The inverse of the `n`×`n` column-major matrix `m` as the adjugate over
/// the determinant (what GLSL's `inverse` computes; undefined, here infinite
/// or NaN, for a singular matrix).
pub(crate) fn inverse(m: &[f64], n: usize, out: &mut [f64]) {
    let det = determinant(m, n);
    for col in 0..n {
        for row in 0..n {
            // inverse[col][row] = cofactor(row, col) / det (the transpose
            // of the cofactor matrix).
            let minor = minor(m, n, row, col);
            let sign = if (row + col) % 2 == 0 { 1.0 } else { -1.0 };
            out[col * n + row] = sign * determinant(&minor[..(n - 1) * (n - 1)], n - 1) / det;
        }
    }
}
