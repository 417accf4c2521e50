//! Batch evaluation in f32 lanes: structure-of-arrays directions in, per
//! channel values out, with the instruction set chosen at run time.
//!
//! # Design
//!
//! A model opts in by giving [`crate::Brdf::batch_kernel`] a [`Kernel`], which
//! it defines in its own module next to its f64 `eval` (one model, one unit).
//! Most kernels implement [`LaneKernel`]: one generic function, `lane<V:
//! Lanes>`, that evaluates a vector of lanes with the operators and methods
//! of [`Lanes`] and reads like the f64 formulas it ports. [`run`] compiles
//! it once per instruction set ([`Isa`]: AVX-512 with 16 lanes, AVX2 + FMA
//! with 8, NEON and wasm `simd128` with 4, and `f32` itself as the scalar
//! fallback) and calls the copy for the instruction set chosen at run time
//! ([`isa`]: the widest this CPU has, or `BV_ISA`'s). On AVX2 and AVX-512
//! the copy steps two vectors at a time ([`Twice`]): a kernel with a transcendental
//! is one long dependency chain, and two chains side by side keep the core
//! busy where one left it waiting. A model without a
//! kernel is evaluated by [`eval`] through its scalar f64 `eval`, one lane at
//! a time, so every caller can use the batch path for every model. The f64
//! `eval` stays the reference: the parity test (`tests/batch_parity.rs`)
//! holds each kernel, on every instruction set this machine has, within
//! 1e-4 relative or 1e-6 absolute of it. Work around the kernels that is
//! worth vectors too (the lobe mesh's per-vertex pass and normals) is a
//! [`LaneTask`], compiled per instruction set by [`run_task`] the same way.
//!
//! # Why explicit vectors, and why our own
//!
//! The kernels used to be scalar f32 loops left to LLVM's auto-vectoriser
//! inside `pulp`'s dispatch. On AVX-512 it vectorised most of them; on an
//! AVX2-only CPU it gave up on all but the simplest (Lambert, Oren-Nayar,
//! Hapke), and most models ran at scalar speed or below, with nothing to
//! say so. Written against [`Lanes`], a kernel is vector code by
//! construction: there is no loop for the compiler to give up on.
//!
//! The vector type is this module's own ([`lanes`], with one file per
//! architecture) rather than a crate's, because each candidate lacked
//! something the kernels need: `pulp` 0.22's generic `Simd` trait has no
//! float-to-integer conversion or rounding (`exp` and `ln` need both) and
//! no NEON implementation; `fearless_simd` 0.4 has no AVX-512 (an AVX-512
//! machine would drop to 8 lanes, half of what the auto-vectorised kernels
//! had there); `wide` fixes the instruction set at compile time, so one
//! binary cannot dispatch at run time. The whole surface is about thirty
//! operations, each one intrinsic per architecture, with the same
//! semantics everywhere (see [`lanes`]); the parity test runs every path.

pub mod isa;
pub mod lanes;
pub mod math;
#[cfg(target_arch = "aarch64")]
mod neon;
pub mod twice;
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
mod wasm;
#[cfg(target_arch = "x86_64")]
mod x86;

pub use isa::{Isa, IsaError};
pub use lanes::{LaneMask, Lanes, WideLanes};
pub use twice::Twice;

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
    /// Evaluates the batch with the instruction set `isa` (an instruction
    /// set this CPU lacks is replaced by [`Isa::best`]).
    fn eval(&self, isa: Isa, dirs: &Dirs<'_>, out: &mut Out<'_>);

    /// This kernel for pairs that all share the incident direction `wi` (a
    /// lobe: one light, a mesh of viewers), with the terms of `wi` alone
    /// computed once rather than in every lane; `None` (the default) where
    /// the kernel has no such form. The kernel returned reads only the
    /// outgoing directions of its `dirs`. The parity test holds it to
    /// [`crate::Brdf::eval`] as it holds [`Kernel::eval`].
    fn at_wi(&self, wi: [f32; 3]) -> Option<Box<dyn Kernel + '_>> {
        let _ = wi;
        None
    }
}

/// A kernel's lanes: `f(wi, wo)` per channel for a vector of lanes, as
/// straight-line code on [`Lanes`] (selects instead of branches on lane
/// values; branches on the kernel's own constants are fine).
/// Implementors get [`Kernel`] for free, compiled for every instruction set.
pub trait LaneKernel: Send + Sync + std::fmt::Debug {
    /// `f(wi, wo)` per channel for each lane of `wi` and `wo`.
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3];

    /// Whether an instruction set that runs kernels two vectors at a time
    /// ([`Twice`], see [`twice`]: AVX2 and AVX-512) does so for this one. True unless
    /// the kernel measured slower that way (a kernel that branches on
    /// whole vectors sees fewer uniform ones at twice the width, and one
    /// with many live values spills more).
    const TWICE: bool = true;
}

impl<K: LaneKernel> Kernel for K {
    fn eval(&self, isa: Isa, dirs: &Dirs<'_>, out: &mut Out<'_>) {
        run(self, isa, dirs, out);
    }
}

/// The kernel of a delta model (mirror, glass): `f = 0` at every finite pair
/// (all of its energy is in its delta lobes, which no pair hits).
#[derive(Debug, Clone, Copy, Default)]
pub struct Zero;

impl LaneKernel for Zero {
    #[inline(always)]
    fn lane<V: Lanes>(&self, _wi: [V; 3], _wo: [V; 3]) -> [V; 3] {
        [V::splat(0.0); 3]
    }
}

/// Runs `k` over every lane with the instruction set `isa` (or
/// [`Isa::best`] if this CPU lacks it).
#[inline]
pub fn run<K: LaneKernel>(k: &K, isa: Isa, dirs: &Dirs<'_>, out: &mut Out<'_>) {
    let isa = if isa.is_available() { isa } else { Isa::best() };
    match isa {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `is_available` saw AVX-512F, AVX2 and FMA on this CPU.
        Isa::Avx512 => unsafe { k.run_avx512(dirs, out) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `is_available` saw AVX2 and FMA on this CPU.
        Isa::Avx2 => unsafe { k.run_avx2(dirs, out) },
        #[cfg(target_arch = "aarch64")]
        Isa::Neon => k.run_neon(dirs, out),
        #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
        Isa::Simd128 => k.run_simd128(dirs, out),
        _ => lanes_loop::<f32, K>(k, dirs, out),
    }
}

/// Each instruction set's copy of a [`LaneKernel`]'s loop, as methods of
/// the kernel's own type rather than generic functions of the
/// architecture's module.
///
/// Why methods: rustc puts the monomorphised copies of a generic *function*
/// in the codegen unit of the module that defines it, but those of a
/// *method* in the unit of its `Self` type's module. As functions of
/// `batch::x86`, every model's AVX2 and AVX-512 loop (244 copies, each with
/// its kernel inlined) was one codegen unit, a 62 MB object that LLVM
/// optimised on one core for minutes of every build of the core. As
/// methods they land with their models (`models::cook_torrance`, …) and
/// the build spreads them over every core. The code is the same.
trait IsaLoops: LaneKernel + Sized {
    /// [`path_loop`] in AVX2 + FMA code.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    unsafe fn run_avx2(&self, dirs: &Dirs<'_>, out: &mut Out<'_>);

    /// [`path_loop`] in AVX-512F code.
    ///
    /// # Safety
    /// The CPU must have AVX-512F, AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    unsafe fn run_avx512(&self, dirs: &Dirs<'_>, out: &mut Out<'_>);

    /// [`lanes_loop`] in NEON code (always there on AArch64).
    #[cfg(target_arch = "aarch64")]
    fn run_neon(&self, dirs: &Dirs<'_>, out: &mut Out<'_>);

    /// [`lanes_loop`] in `simd128` code (a build with the feature on).
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    fn run_simd128(&self, dirs: &Dirs<'_>, out: &mut Out<'_>);
}

impl<K: LaneKernel> IsaLoops for K {
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn run_avx2(&self, dirs: &Dirs<'_>, out: &mut Out<'_>) {
        path_loop::<x86::Avx2, K>(Isa::Avx2, self, dirs, out);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx2,fma")]
    unsafe fn run_avx512(&self, dirs: &Dirs<'_>, out: &mut Out<'_>) {
        path_loop::<x86::Avx512, K>(Isa::Avx512, self, dirs, out);
    }

    #[cfg(target_arch = "aarch64")]
    fn run_neon(&self, dirs: &Dirs<'_>, out: &mut Out<'_>) {
        lanes_loop::<neon::Neon, K>(self, dirs, out);
    }

    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    fn run_simd128(&self, dirs: &Dirs<'_>, out: &mut Out<'_>) {
        lanes_loop::<wasm::Simd128, K>(self, dirs, out);
    }
}

/// Work other than a model's kernel written once against [`Lanes`] (a lobe
/// mesh's per-vertex pass, its normals): [`run_task`] compiles `run` once
/// per instruction set, like a [`LaneKernel`], so the loop is vector code on
/// every CPU rather than whatever the auto-vectoriser makes of a scalar loop.
pub trait LaneTask {
    /// What the work returns.
    type Output;
    /// Does the work with vectors of `V` (whole vectors of `V::LANES`; a
    /// remainder is the task's to handle, e.g. through `f32`'s one lane).
    fn run<V: Lanes>(self) -> Self::Output;
}

/// Runs `task` with the instruction set `isa` (or [`Isa::best`] if this CPU
/// lacks it).
#[inline]
pub fn run_task<T: LaneTask>(isa: Isa, task: T) -> T::Output {
    let isa = if isa.is_available() { isa } else { Isa::best() };
    match isa {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `is_available` saw AVX-512F, AVX2 and FMA on this CPU.
        Isa::Avx512 => unsafe { x86::task_avx512(task) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `is_available` saw AVX2 and FMA on this CPU.
        Isa::Avx2 => unsafe { x86::task_avx2(task) },
        #[cfg(target_arch = "aarch64")]
        Isa::Neon => neon::task_neon(task),
        #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
        Isa::Simd128 => wasm::task_simd128(task),
        _ => task.run::<f32>(),
    }
}

/// The lane loop, inlined into each instruction set's copy: whole vectors of
/// `V::LANES`, then the remainder through one vector padded with the normal
/// direction (its lanes are computed and dropped).
#[inline(always)]
fn lanes_loop<V: Lanes, K: LaneKernel>(k: &K, dirs: &Dirs<'_>, out: &mut Out<'_>) {
    let n = dirs.len().min(out.len());
    let whole = whole_vectors::<V, K>(k, dirs, out, 0, n);
    padded_rest::<V, K>(k, dirs, out, whole, n);
}

/// The lane loop of the path `isa` (whose vector is `V`): two vectors per
/// step where [`Isa::twice`] and the kernel's [`LaneKernel::TWICE`] both
/// allow it ([`lanes_loop_twice`]), one otherwise ([`lanes_loop`]).
#[inline(always)]
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
fn path_loop<V: Lanes, K: LaneKernel>(isa: Isa, k: &K, dirs: &Dirs<'_>, out: &mut Out<'_>) {
    if K::TWICE && isa.twice() {
        lanes_loop_twice::<V, K>(k, dirs, out);
    } else {
        lanes_loop::<V, K>(k, dirs, out);
    }
}

/// [`lanes_loop`] through [`Twice`]`<V>` (two vectors per step, see
/// [`twice`]) while two whole vectors remain, then one `V` at a time, so
/// that the remainder pads at most `V::LANES − 1` lanes.
#[inline(always)]
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
fn lanes_loop_twice<V: Lanes, K: LaneKernel>(k: &K, dirs: &Dirs<'_>, out: &mut Out<'_>) {
    let n = dirs.len().min(out.len());
    let pairs = whole_vectors::<Twice<V>, K>(k, dirs, out, 0, n);
    let whole = whole_vectors::<V, K>(k, dirs, out, pairs, n);
    padded_rest::<V, K>(k, dirs, out, whole, n);
}

/// Lanes `from..` in whole vectors of `V` up to `n` (`from + V::LANES·m ≤
/// n`); returns where they end.
#[inline(always)]
fn whole_vectors<V: Lanes, K: LaneKernel>(
    k: &K,
    dirs: &Dirs<'_>,
    out: &mut Out<'_>,
    from: usize,
    n: usize,
) -> usize {
    let [ix, iy, iz] = first_n(dirs.wi, n);
    let [ox, oy, oz] = first_n(dirs.wo, n);
    let [r, g, b] = &mut out.rgb;
    let (r, g, b) = (&mut r[..n], &mut g[..n], &mut b[..n]);
    let whole = from + (n - from) / V::LANES * V::LANES;
    let mut i = from;
    while i < whole {
        let wi = [V::load(&ix[i..]), V::load(&iy[i..]), V::load(&iz[i..])];
        let wo = [V::load(&ox[i..]), V::load(&oy[i..]), V::load(&oz[i..])];
        let f = k.lane(wi, wo);
        f[0].store(&mut r[i..]);
        f[1].store(&mut g[i..]);
        f[2].store(&mut b[i..]);
        i += V::LANES;
    }
    whole
}

/// The lanes `whole..n` (fewer than `V::LANES`) through one vector padded
/// with the normal direction (its lanes are computed and dropped).
#[inline(always)]
fn padded_rest<V: Lanes, K: LaneKernel>(
    k: &K,
    dirs: &Dirs<'_>,
    out: &mut Out<'_>,
    whole: usize,
    n: usize,
) {
    // The widest vector a remainder goes through has 16 lanes.
    const { assert!(V::LANES <= 16) };
    let rest = n - whole;
    if rest == 0 {
        return;
    }
    let [ix, iy, iz] = first_n(dirs.wi, n);
    let [ox, oy, oz] = first_n(dirs.wo, n);
    let [r, g, b] = &mut out.rgb;
    let wi = [
        V::load(&padded(&ix[whole..], 0.0)),
        V::load(&padded(&iy[whole..], 0.0)),
        V::load(&padded(&iz[whole..], 1.0)),
    ];
    let wo = [
        V::load(&padded(&ox[whole..], 0.0)),
        V::load(&padded(&oy[whole..], 0.0)),
        V::load(&padded(&oz[whole..], 1.0)),
    ];
    let f = k.lane(wi, wo);
    let mut a = [[0f32; 16]; 3];
    f[0].store(&mut a[0]);
    f[1].store(&mut a[1]);
    f[2].store(&mut a[2]);
    r[whole..n].copy_from_slice(&a[0][..rest]);
    g[whole..n].copy_from_slice(&a[1][..rest]);
    b[whole..n].copy_from_slice(&a[2][..rest]);
}

/// The first `n` elements of each of three arrays.
///
/// A function of its own, not `array::map` with a closure in the generic
/// loops above: a closure written in a generic function is a new type in
/// each of its copies, and each such `map` was its own out-of-line copy of
/// std's `try_map` (about 1 700 of them, a codegen unit that took LLVM as
/// long as all the kernels together, to make code nothing called after
/// inlining).
#[inline]
fn first_n(a: [&[f32]; 3], n: usize) -> [&[f32]; 3] {
    [&a[0][..n], &a[1][..n], &a[2][..n]]
}

/// `src` (at most 16 values) followed by `fill` up to 16 lanes (a
/// function of its own for the reason [`first_n`] gives).
#[inline]
fn padded(src: &[f32], fill: f32) -> [f32; 16] {
    let mut a = [fill; 16];
    a[..src.len()].copy_from_slice(src);
    a
}

/// Which path a batch took.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dispatch {
    /// Whether the model's own kernel ran (`false`: the scalar f64 fallback).
    pub kernel: bool,
    /// The instruction set the kernel ran with ([`Isa::name`]; `"scalar"`
    /// for the fallback).
    pub isa: &'static str,
    /// f32 lanes per vector of that instruction set.
    pub lanes: usize,
}

/// The instruction set batches run with in this process ([`Isa::selected`]:
/// `BV_ISA`'s, or the widest this CPU has).
pub fn isa() -> Isa {
    Isa::selected()
}

/// Evaluates `brdf` on every lane of `dirs` into `out` with the process's
/// instruction set ([`isa`]): through its kernel if it has one, otherwise
/// through its f64 `eval`, lane by lane. Lanes beyond
/// `min(dirs.len(), out.len())` are left untouched.
pub fn eval(brdf: &dyn Brdf, dirs: &Dirs<'_>, out: &mut Out<'_>) -> Dispatch {
    eval_with(brdf, isa(), dirs, out)
}

/// [`eval`] with the instruction set `isa` (replaced by [`Isa::best`] where
/// this CPU lacks it), for tests and benchmarks that compare the paths.
pub fn eval_with(brdf: &dyn Brdf, isa: Isa, dirs: &Dirs<'_>, out: &mut Out<'_>) -> Dispatch {
    if let Some(k) = brdf.batch_kernel() {
        let isa = if isa.is_available() { isa } else { Isa::best() };
        k.eval(isa, dirs, out);
        return Dispatch {
            kernel: true,
            isa: isa.name(),
            lanes: isa.lanes(),
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
