//! Batch evaluation in f32 lanes: structure-of-arrays directions in, per
//! channel values out, with the instruction set chosen at run time.
//!
//! # Design
//!
//! A model opts in by giving [`crate::Brdf::batch_kernel`] a [`Kernel`], which
//! it defines in its own module next to its f64 `eval` (one model, one unit).
//! Most kernels implement [`LaneKernel`] instead, one lane's evaluation as
//! straight-line f32 code, and get [`Kernel`] through [`run`]. A model without a
//! kernel is evaluated by [`eval`] through its scalar f64 `eval`, one lane at a
//! time, so every caller can use the batch path for every model. The f64 `eval`
//! stays the reference: the parity test (`tests/batch_parity.rs`) holds each
//! kernel within 1e-4 relative or 1e-6 absolute of it.
//!
//! # Why `pulp`'s dispatch with auto-vectorised lane loops
//!
//! [`run`] hands the lane loop to `pulp::Arch::dispatch`, which detects the
//! CPU once (AVX-512 "x86-64-v4", AVX2 + FMA "x86-64-v3", or none) and calls
//! the loop inside a function compiled with those target features; the loop
//! body is inlined there and LLVM vectorises it to 16 (AVX-512) or 8 (AVX2)
//! f32 lanes. `pulp` is maintained (it is the SIMD layer of `faer`), was
//! already in the dependency tree, and its dispatch is safe code. Writing the
//! kernels against `pulp`'s explicit `Simd` vector API, or `wide`'s fixed-width
//! types, would fix one width and make every model's kernel a second,
//! unreadable copy of its formulas; with plain f32 loops the kernel reads like
//! the f64 code it ports, and the same source compiles to every width.
//! (`multiversion` would do the dispatch equally well but is not yet a
//! dependency.) The rule that makes this work: kernel code must be
//! branch-free (selects written as `if` on values) and call only the inline
//! math of [`math`], never libm.

pub mod math;

use crate::Brdf;
use glam::DVec3;

/// Directions of a batch as structure-of-arrays f32 lanes: `wi[c][i]` is
/// component `c` (x, y, z) of lane `i`'s incident direction.
#[derive(Debug, Clone, Copy)]
pub struct Dirs<'a> {
    /// Incident directions (towards the light), x, y and z arrays.
    pub wi: [&'a [f32]; 3],
    /// Outgoing directions (towards the viewer), x, y and z arrays.
    pub wo: [&'a [f32]; 3],
}

impl Dirs<'_> {
    /// Lanes in the batch (the shortest of the six arrays).
    pub fn len(&self) -> usize {
        self.wi
            .iter()
            .chain(&self.wo)
            .map(|a| a.len())
            .min()
            .unwrap_or(0)
    }

    /// Whether the batch is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Output of a batch: `rgb[c][i]` is channel `c` of `f` at lane `i`.
#[derive(Debug)]
pub struct Out<'a> {
    /// Red, green and blue arrays.
    pub rgb: [&'a mut [f32]; 3],
}

impl Out<'_> {
    /// Lanes that fit (the shortest of the three arrays).
    pub fn len(&self) -> usize {
        self.rgb.iter().map(|a| a.len()).min().unwrap_or(0)
    }

    /// Whether there is no room at all.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Lanes among the first `n` of `rgb` where some channel is NaN or infinite.
/// A branch-free pass, compiled in the optimised core so that callers built
/// without optimisation (`bv bench` in a debug build) do not spend more time
/// counting than evaluating.
pub fn count_non_finite(rgb: [&[f32]; 3], n: usize) -> usize {
    let n = n.min(rgb[0].len()).min(rgb[1].len()).min(rgb[2].len());
    let (r, g, b) = (&rgb[0][..n], &rgb[1][..n], &rgb[2][..n]);
    // |x| < ∞ is false for NaN and ±∞; summing 0/1 keeps the loop vectorisable.
    (0..n)
        .map(|i| {
            let ok = r[i].abs() < f32::INFINITY
                && g[i].abs() < f32::INFINITY
                && b[i].abs() < f32::INFINITY;
            usize::from(!ok)
        })
        .sum()
}

/// Owned structure-of-arrays direction pairs.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PairBuf {
    /// Incident directions, x, y and z arrays.
    pub wi: [Vec<f32>; 3],
    /// Outgoing directions, x, y and z arrays.
    pub wo: [Vec<f32>; 3],
}

impl PairBuf {
    /// The pairs rounded to f32.
    pub fn from_pairs(pairs: &[(DVec3, DVec3)]) -> Self {
        let mut b = Self::default();
        for &(wi, wo) in pairs {
            b.push(wi, wo);
        }
        b
    }

    /// Appends one pair (rounded to f32).
    pub fn push(&mut self, wi: DVec3, wo: DVec3) {
        for c in 0..3 {
            self.wi[c].push(wi[c] as f32);
            self.wo[c].push(wo[c] as f32);
        }
    }

    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.wi[0].len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// A view of pairs `range`.
    pub fn dirs(&self, range: std::ops::Range<usize>) -> Dirs<'_> {
        fn s(v: &[Vec<f32>; 3], r: std::ops::Range<usize>) -> [&[f32]; 3] {
            [&v[0][r.clone()], &v[1][r.clone()], &v[2][r]]
        }
        Dirs {
            wi: s(&self.wi, range.clone()),
            wo: s(&self.wo, range),
        }
    }

    /// Pair `i` as f64 vectors (exactly the f32 values).
    pub fn pair(&self, i: usize) -> (DVec3, DVec3) {
        let v = |a: &[Vec<f32>; 3]| DVec3::new(a[0][i] as f64, a[1][i] as f64, a[2][i] as f64);
        (v(&self.wi), v(&self.wo))
    }
}

/// A model's batch evaluator: fills `out` with `f` at every lane of `dirs`
/// (the first `min(dirs.len(), out.len())` lanes).
pub trait Kernel: Send + Sync + std::fmt::Debug {
    /// Evaluates the batch.
    fn eval(&self, dirs: &Dirs<'_>, out: &mut Out<'_>);
}

/// One lane of a kernel, as straight-line f32 code (see the module doc for
/// the rules that let it vectorise). Implementors get [`Kernel`] for free.
pub trait LaneKernel: Send + Sync + std::fmt::Debug {
    /// `f(wi, wo)` per channel for one lane.
    fn lane(&self, wi: math::V3, wo: math::V3) -> [f32; 3];
}

impl<K: LaneKernel> Kernel for K {
    fn eval(&self, dirs: &Dirs<'_>, out: &mut Out<'_>) {
        run(self, dirs, out);
    }
}

/// The kernel of a delta model (mirror, glass): `f = 0` at every finite pair
/// (all of its energy is in its delta lobes, which no pair hits).
#[derive(Debug, Clone, Copy, Default)]
pub struct Zero;

impl LaneKernel for Zero {
    #[inline(always)]
    fn lane(&self, _wi: math::V3, _wo: math::V3) -> [f32; 3] {
        [0.0; 3]
    }
}

/// Runs `k` over every lane, compiled for the best instruction set this CPU
/// has (see the module doc).
#[inline]
pub fn run<K: LaneKernel + ?Sized>(k: &K, dirs: &Dirs<'_>, out: &mut Out<'_>) {
    struct Op<'k, 'd, 'o, 'p, K: ?Sized> {
        k: &'k K,
        dirs: &'d Dirs<'d>,
        out: &'o mut Out<'p>,
    }
    impl<K: LaneKernel + ?Sized> pulp::WithSimd for Op<'_, '_, '_, '_, K> {
        type Output = ();
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, _simd: S) -> Self::Output {
            lanes(self.k, self.dirs, self.out);
        }
    }
    pulp::Arch::new().dispatch(Op { k, dirs, out });
}

/// The lane loop itself, inlined into each instruction set's copy.
#[inline(always)]
fn lanes<K: LaneKernel + ?Sized>(k: &K, dirs: &Dirs<'_>, out: &mut Out<'_>) {
    let n = dirs.len().min(out.len());
    let [ix, iy, iz] = dirs.wi.map(|a| &a[..n]);
    let [ox, oy, oz] = dirs.wo.map(|a| &a[..n]);
    let [r, g, b] = &mut out.rgb;
    let (r, g, b) = (&mut r[..n], &mut g[..n], &mut b[..n]);
    for i in 0..n {
        let f = k.lane([ix[i], iy[i], iz[i]], [ox[i], oy[i], oz[i]]);
        r[i] = f[0];
        g[i] = f[1];
        b[i] = f[2];
    }
}

/// Which path a batch took.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dispatch {
    /// Whether the model's own kernel ran (`false`: the scalar f64 fallback).
    pub kernel: bool,
    /// The instruction set the kernel ran with (`"scalar"` for the fallback).
    pub isa: &'static str,
    /// f32 lanes per vector of that instruction set.
    pub lanes: usize,
}

/// The instruction set [`run`] dispatches to on this CPU and its f32 lanes:
/// `("avx512", 16)`, `("avx2+fma", 8)` or `("scalar", 1)`.
pub fn isa() -> (&'static str, usize) {
    #[cfg(any(target_arch = "x86_64", target_arch = "x86"))]
    {
        match pulp::Arch::new() {
            pulp::Arch::V4(_) => ("avx512", 16),
            pulp::Arch::V3(_) => ("avx2+fma", 8),
            _ => ("scalar", 1),
        }
    }
    #[cfg(not(any(target_arch = "x86_64", target_arch = "x86")))]
    {
        ("portable", 1)
    }
}

/// Evaluates `brdf` on every lane of `dirs` into `out`: through its kernel if
/// it has one, otherwise through its f64 `eval`, lane by lane. Lanes beyond
/// `min(dirs.len(), out.len())` are left untouched.
pub fn eval(brdf: &dyn Brdf, dirs: &Dirs<'_>, out: &mut Out<'_>) -> Dispatch {
    if let Some(k) = brdf.batch_kernel() {
        k.eval(dirs, out);
        let (isa, lanes) = isa();
        return Dispatch {
            kernel: true,
            isa,
            lanes,
        };
    }
    scalar(brdf, dirs, out);
    Dispatch {
        kernel: false,
        isa: "scalar",
        lanes: 1,
    }
}

/// The fallback: `brdf.eval` at each lane (directions widened exactly to f64).
pub fn scalar(brdf: &dyn Brdf, dirs: &Dirs<'_>, out: &mut Out<'_>) {
    let n = dirs.len().min(out.len());
    for i in 0..n {
        let v = |a: &[&[f32]; 3]| DVec3::new(a[0][i] as f64, a[1][i] as f64, a[2][i] as f64);
        let f = brdf.eval(v(&dirs.wi), v(&dirs.wo));
        for c in 0..3 {
            out.rgb[c][i] = f[c] as f32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn count_non_finite_counts_lanes_not_channels() {
        let r = [0.0, f32::NAN, 1.0, f32::MAX, -f32::MAX, 1e-42, 0.0];
        let g = [0.0, f32::NAN, f32::INFINITY, 0.0, 0.0, 0.0, 0.0];
        let b = [0.0, 0.0, 0.0, f32::NEG_INFINITY, 0.0, -0.0, f32::NAN];
        // Lanes 1, 2, 3 and 6 each hold at least one NaN or infinity.
        assert_eq!(count_non_finite([&r, &g, &b], 7), 4);
        // Only the first n lanes are looked at, and n is clipped to the arrays.
        assert_eq!(count_non_finite([&r, &g, &b], 2), 1);
        assert_eq!(count_non_finite([&r, &g, &b], 100), 4);
        assert_eq!(count_non_finite([&r[..0], &g, &b], 7), 0);
    }
}
