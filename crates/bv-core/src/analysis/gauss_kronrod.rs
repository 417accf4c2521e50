//! Global adaptive Gauss–Kronrod (7/15) quadrature on one axis, the building
//! block of the deterministic integrals ([`super::ndf`], [`super::quadrature`]).
//!
//! The 15-point Kronrod rule extends the 7-point Gauss rule (Kronrod 1965;
//! QUADPACK's `qk15`, Piessens et al. 1983): both are evaluated from the same
//! 15 values, and `|K15 − G7|` is the error estimate of a panel. It is
//! pessimistic for smooth integrands (K15 is usually far more accurate than
//! G7), which is what an honest error bar wants.
//!
//! An axis is a list of [`Segment`]s, each mapping `u ∈ [0, 1]` onto `[a, b]`
//! either linearly or with a square-law grading at one or both ends. The
//! grading removes `√(x − a)`-type endpoint behaviour (an integration domain
//! whose width shrinks like a square root, a `√cos θ` factor at the horizon):
//! with `x = a + (b − a) u²`, `√(x − a) dx` becomes a polynomial in `u`, on
//! which Gauss rules converge fast again. Panels are bisected in `u`.

use crate::Rgb;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Kronrod nodes (non-negative half) of the 15-point rule.
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
/// Kronrod weights for [`XGK`].
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
/// Gauss 7-point weights, at the odd Kronrod nodes (XGK[1], XGK[3], XGK[5], 0).
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// Evaluations of one panel.
pub const PANEL_EVALS: usize = 15;

/// An integrand: `(value, error of the value)` at abscissae, a panel's
/// nodes at a time ([`PANEL_EVALS`] of a Kronrod panel, 7 of the
/// verification's Gauss rule), so that an integrand can hand them to a
/// model in one call ([`crate::Brdf::eval_many`]). Any
/// `FnMut(f64) -> (T, T)` is one, node by node; [`Batched`] wraps a
/// closure that takes the nodes together.
pub trait Integrand<T> {
    /// `out[k] = f(xs[k])` for every `k` (`xs` and `out` have one length).
    fn at(&mut self, xs: &[f64], out: &mut [(T, T)]);
}

impl<T, F: FnMut(f64) -> (T, T)> Integrand<T> for F {
    #[inline]
    fn at(&mut self, xs: &[f64], out: &mut [(T, T)]) {
        for (x, o) in xs.iter().zip(out) {
            *o = self(*x);
        }
    }
}

/// An integrand written for a panel's nodes at once: a closure
/// `(xs, out)` that fills `out[k]` with `f(xs[k])`.
pub struct Batched<F>(pub F);

impl<T, F: FnMut(&[f64], &mut [(T, T)])> Integrand<T> for Batched<F> {
    #[inline]
    fn at(&mut self, xs: &[f64], out: &mut [(T, T)]) {
        (self.0)(xs, out)
    }
}

/// What an integrand may return: a scalar or a linear-RGB triple.
pub trait Value:
    Copy + Default + std::ops::Add<Output = Self> + std::ops::Mul<f64, Output = Self>
{
    /// Component-wise absolute value.
    fn abs(self) -> Self;
    /// The largest component (the panel priority).
    fn max_component(self) -> f64;
}

impl Value for f64 {
    fn abs(self) -> Self {
        f64::abs(self)
    }
    fn max_component(self) -> f64 {
        self
    }
}

impl Value for Rgb {
    fn abs(self) -> Self {
        Rgb::abs(self)
    }
    fn max_component(self) -> f64 {
        self.max_element()
    }
}

/// How a segment maps `u ∈ [0, 1]` onto `[a, b]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Grading {
    /// `x = a + (b − a) u`.
    Linear,
    /// `x = a + (b − a) u²`: dense at `a`.
    Start,
    /// `x = b − (b − a)(1 − u)²`: dense at `b`.
    End,
    /// `x = a + (b − a)(1 − cos πu)/2`: dense at both ends.
    Both,
}

/// One piece of an integration axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Start.
    pub a: f64,
    /// End (`b > a`).
    pub b: f64,
    /// The map from `u` to `x`.
    pub grading: Grading,
}

impl Segment {
    /// A linear segment.
    pub fn linear(a: f64, b: f64) -> Self {
        Self {
            a,
            b,
            grading: Grading::Linear,
        }
    }

    /// `(x(u), dx/du)`.
    #[inline]
    pub fn at(&self, u: f64) -> (f64, f64) {
        let w = self.b - self.a;
        match self.grading {
            Grading::Linear => (self.a + w * u, w),
            Grading::Start => (self.a + w * u * u, 2.0 * w * u),
            Grading::End => {
                let v = 1.0 - u;
                (self.b - w * v * v, 2.0 * w * v)
            }
            Grading::Both => {
                let (s, c) = (std::f64::consts::PI * u).sin_cos();
                (
                    self.a + w * 0.5 * (1.0 - c),
                    w * 0.5 * std::f64::consts::PI * s,
                )
            }
        }
    }
}

/// Segments between consecutive sorted `breaks`, linear inside, graded at the
/// first break when `grade_start` and at the last when `grade_end`. Breaks
/// closer than `1e-12` (relative to the span) are merged.
pub fn segments(breaks: &[f64], grade_start: bool, grade_end: bool) -> Vec<Segment> {
    let mut out = Vec::new();
    segments_into(breaks, grade_start, grade_end, &mut Vec::new(), &mut out);
    out
}

/// [`segments`] into `out` (cleared first), with `scratch` for the sorted
/// breaks: for a caller that cuts many axes in a row (the albedo
/// quadrature's rings, hundreds per ρhd) and keeps both vectors, so that no
/// axis allocates.
pub fn segments_into(
    breaks: &[f64],
    grade_start: bool,
    grade_end: bool,
    scratch: &mut Vec<f64>,
    out: &mut Vec<Segment>,
) {
    out.clear();
    let b = scratch;
    b.clear();
    b.extend(breaks.iter().copied().filter(|x| x.is_finite()));
    b.sort_by(f64::total_cmp);
    let span = match (b.first(), b.last()) {
        (Some(&lo), Some(&hi)) => hi - lo,
        _ => return,
    };
    let eps = 1e-12 * span.max(f64::MIN_POSITIVE);
    b.dedup_by(|x, y| (*x - *y).abs() <= eps);
    let n = b.len().saturating_sub(1);
    out.extend((0..n).map(|k| {
        let first = grade_start && k == 0;
        let last = grade_end && k + 1 == n;
        let grading = match (first, last) {
            (true, true) => Grading::Both,
            (true, false) => Grading::Start,
            (false, true) => Grading::End,
            (false, false) => Grading::Linear,
        };
        Segment {
            a: b[k],
            b: b[k + 1],
            grading,
        }
    }));
}

/// The `N` nodes `(x, dx/du)` of a symmetric rule on segment `s` about
/// `u = c` with half-width `h`, in the order the rules sum them: `c ∓ h·a(i)`
/// for each abscissa `a(i)`, `i < N / 2`, then the centre.
fn nodes<const N: usize>(
    s: &Segment,
    c: f64,
    h: f64,
    a: impl Fn(usize) -> f64,
) -> ([f64; N], [f64; N]) {
    let mut xs = [0.0; N];
    let mut jacs = [0.0; N];
    for i in 0..N / 2 {
        (xs[2 * i], jacs[2 * i]) = s.at(c - h * a(i));
        (xs[2 * i + 1], jacs[2 * i + 1]) = s.at(c + h * a(i));
    }
    (xs[N - 1], jacs[N - 1]) = s.at(c);
    (xs, jacs)
}

/// One GK15 panel `[u0, u1]` of segment `s` for an integrand returning
/// `(value, error of the value)`: `(K15, |K15 − G7| + Σ wK · error)`.
fn panel<T: Value>(f: &mut impl Integrand<T>, s: &Segment, u0: f64, u1: f64) -> (T, T) {
    let c = 0.5 * (u0 + u1);
    let h = 0.5 * (u1 - u0);
    let (xs, jacs) = nodes::<PANEL_EVALS>(s, c, h, |i| XGK[i]);
    let mut vals = [(T::default(), T::default()); PANEL_EVALS];
    f.at(&xs, &mut vals);
    let mut k = T::default();
    let mut g = T::default();
    let mut inner = T::default();
    for (n, ((v, e), jac)) in vals.into_iter().zip(jacs).enumerate() {
        let i = if n + 1 == PANEL_EVALS { 7 } else { n / 2 };
        let (v, e) = (v * jac, e * jac.abs());
        k = k + v * WGK[i];
        inner = inner + e * WGK[i];
        if i % 2 == 1 {
            g = g + v * WG[i / 2];
        }
    }
    let value = k * h;
    let diff = (k + g * -1.0) * h;
    (value, diff.abs() + inner * h.abs())
}

/// A panel in the work queue, ordered by its largest error component.
#[derive(Debug, Clone, Copy)]
struct Panel<T> {
    seg: usize,
    u0: f64,
    u1: f64,
    value: T,
    error: T,
}

impl<T: Value> PartialEq for Panel<T> {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl<T: Value> Eq for Panel<T> {}
impl<T: Value> PartialOrd for Panel<T> {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl<T: Value> Ord for Panel<T> {
    fn cmp(&self, o: &Self) -> Ordering {
        self.error
            .max_component()
            .total_cmp(&o.error.max_component())
    }
}

/// The result of [`integrate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Integral<T> {
    /// The integral.
    pub value: T,
    /// Its estimated absolute error (per component).
    pub error: T,
    /// Integrand evaluations.
    pub evaluations: usize,
    /// Whether the tolerance was met (else the panel budget ran out).
    pub converged: bool,
}

/// Global adaptive GK15 over `segments`: bisects the panel with the largest
/// error until the total error is at most `abs_tol + rel_tol · |value|` in
/// every component, or `max_panels` panels exist.
///
/// With `verify`, every final panel is then checked at a second resolution
/// (see [`verified`]: G7 on its halves, and K15 on its halves where that
/// check finds it suspect). `|K15 − G7|` alone can understate the error of a
/// panel that holds a kink (a `min` or `max` in the integrand,
/// Cook-Torrance's V-groove G): there both rules are wrong by similar
/// amounts. The difference between two resolutions measures the coarser
/// one's real error. It costs 14 to 44 evaluations per final panel (the
/// bisection of every panel it replaced cost 30, and missed more kinks in
/// `verification_covers_a_kink_almost_anywhere`).
pub fn integrate<T: Value>(
    f: &mut impl Integrand<T>,
    segments: &[Segment],
    abs_tol: f64,
    rel_tol: f64,
    max_panels: usize,
    verify: bool,
) -> Integral<T> {
    let mut heap = BinaryHeap::with_capacity(segments.len() * 2);
    let mut evaluations = 0;
    // Running sums, recomputed exactly before returning.
    let mut value = T::default();
    let mut error = T::default();
    for (i, s) in segments.iter().enumerate() {
        let (v, e) = panel(f, s, 0.0, 1.0);
        evaluations += PANEL_EVALS;
        value = value + v;
        error = error + e;
        heap.push(Panel {
            seg: i,
            u0: 0.0,
            u1: 1.0,
            value: v,
            error: e,
        });
    }
    let total = |heap: &BinaryHeap<Panel<T>>| {
        heap.iter().fold((T::default(), T::default()), |(v, e), p| {
            (v + p.value, e + p.error)
        })
    };
    let mut converged = false;
    loop {
        // Met when error ≤ tol in every component: compare the worst excess.
        let tol = value.abs() * rel_tol;
        let met = (error + tol * -1.0).max_component() <= abs_tol;
        let stuck = !error.max_component().is_finite();
        if met || stuck || heap.len() >= max_panels {
            // The running sums drift by rounding: confirm on exact ones.
            let (v, e) = total(&heap);
            let tol = v.abs() * rel_tol;
            converged = (e + tol * -1.0).max_component() <= abs_tol;
            if converged || stuck || heap.len() >= max_panels {
                break;
            }
            value = v;
            error = e;
        }
        let Some(p) = heap.pop() else {
            break;
        };
        let m = 0.5 * (p.u0 + p.u1);
        if m <= p.u0 || m >= p.u1 {
            // No room to bisect in floating point: keep the panel and stop.
            heap.push(p);
            break;
        }
        value = value + p.value * -1.0;
        error = error + p.error * -1.0;
        let s = segments[p.seg];
        for (u0, u1) in [(p.u0, m), (m, p.u1)] {
            let (v, e) = panel(f, &s, u0, u1);
            evaluations += PANEL_EVALS;
            value = value + v;
            error = error + e;
            heap.push(Panel {
                seg: p.seg,
                u0,
                u1,
                value: v,
                error: e,
            });
        }
    }
    if verify && error.max_component().is_finite() {
        return verified(f, segments, heap, evaluations, converged, abs_tol);
    }
    let (value, error) = total(&heap);
    Integral {
        value,
        error,
        evaluations,
        converged,
    }
}

/// The 7-point Gauss rule on the panel `[u0, u1]` of segment `s` (its nodes
/// are the odd Kronrod nodes): `(G7, Σ wG · error)`.
fn gauss7<T: Value>(f: &mut impl Integrand<T>, s: &Segment, u0: f64, u1: f64) -> (T, T) {
    let c = 0.5 * (u0 + u1);
    let h = 0.5 * (u1 - u0);
    let (xs, jacs) = nodes::<GAUSS7_EVALS>(s, c, h, |i| XGK[2 * i + 1]);
    let mut vals = [(T::default(), T::default()); GAUSS7_EVALS];
    f.at(&xs, &mut vals);
    let mut g = T::default();
    let mut inner = T::default();
    for (n, ((v, e), jac)) in vals.into_iter().zip(jacs).enumerate() {
        let w = WG[if n + 1 == GAUSS7_EVALS { 3 } else { n / 2 }];
        g = g + v * (jac * w);
        inner = inner + e * (jac.abs() * w);
    }
    (g * h, inner * h.abs())
}

/// Evaluations of [`gauss7`].
const GAUSS7_EVALS: usize = 7;

/// The verification pass of [`integrate`]: each final panel is checked
/// against the 7-point Gauss rule on its two halves (14 evaluations), and
/// re-integrated by K15 on both halves (30 more) only when the check finds
/// it suspect.
///
/// On a panel where the integrand is smooth the composite G7 of the halves
/// is about 2¹³ times more accurate than the panel's own G7, so it differs
/// from K15 by a small fraction of `|K15 − G7|`. Where it differs by more
/// than [`SUSPECT`] of that, the panel holds something the polynomial rules
/// do not see (a kink: both K15 and G7 wrong by similar amounts), and it
/// gets the full treatment: the sum of K15 over the halves, with their
/// `|K15 − G7|` plus `|K15(panel) − K15(halves)|` (the coarser rule's real
/// error, which bounds the finer one's in practice). An unsuspected panel
/// keeps its K15 with the error `|K15 − G7| + |K15 − G7(halves)|` plus the
/// check's inner errors. A kink hides from this only if three different
/// rules (K15 and G7 on the panel, G7 on its halves) agree by chance.
#[allow(clippy::too_many_arguments)]
fn verified<T: Value>(
    f: &mut impl Integrand<T>,
    segments: &[Segment],
    heap: BinaryHeap<Panel<T>>,
    mut evaluations: usize,
    converged: bool,
    abs_tol: f64,
) -> Integral<T> {
    let n = heap.len().max(1) as f64;
    // Rounding noise: a check below this is no evidence of a kink.
    let floor = 1e-6 * abs_tol / n;
    let mut value = T::default();
    let mut error = T::default();
    for p in heap {
        let m = 0.5 * (p.u0 + p.u1);
        if m <= p.u0 || m >= p.u1 {
            value = value + p.value;
            error = error + p.error;
            continue;
        }
        let s = segments[p.seg];
        let (gl, el) = gauss7(f, &s, p.u0, m);
        let (gr, er) = gauss7(f, &s, m, p.u1);
        evaluations += 2 * GAUSS7_EVALS;
        let check = (p.value + (gl + gr) * -1.0).abs();
        let c = check.max_component();
        if c <= SUSPECT * p.error.max_component() || c <= floor {
            value = value + p.value;
            error = error + p.error + check + el + er;
            continue;
        }
        let (vl, ell) = panel(f, &s, p.u0, m);
        let (vr, err) = panel(f, &s, m, p.u1);
        evaluations += 2 * PANEL_EVALS;
        let fine = vl + vr;
        value = value + fine;
        error = error + ell + err + (p.value + fine * -1.0).abs();
    }
    Integral {
        value,
        error,
        evaluations,
        converged,
    }
}

/// The share of a panel's `|K15 − G7|` above which its check against G7 on
/// the halves marks it suspect (see [`verified`]): a smooth panel's check
/// is about 2⁻¹³ of it.
const SUSPECT: f64 = 0.25;

#[cfg(test)]
mod tests {
    use super::*;

    fn plain(f: impl Fn(f64) -> f64) -> impl FnMut(f64) -> (f64, f64) {
        move |x| (f(x), 0.0)
    }

    #[test]
    fn nodes_taken_together_give_the_same_integral_bit_for_bit() {
        // The same kinked integrand node by node and through `Batched`
        // (which a caller uses to hand a panel's nodes to a model in one
        // call), adaptive and verified, on graded segments: every value,
        // error and count equal.
        let f = |x: f64| ((3.0 * x).sin() + (x - 0.3).abs(), 1e-9 * x);
        let segs = segments(&[0.0, 0.4, 1.0], true, true);
        for verify in [false, true] {
            let one = integrate(&mut |x| f(x), &segs, 1e-10, 0.0, 200, verify);
            let mut calls = 0;
            let mut batch = Batched(|xs: &[f64], out: &mut [(f64, f64)]| {
                calls += 1;
                for (x, o) in xs.iter().zip(out) {
                    *o = f(*x);
                }
            });
            let all = integrate(&mut batch, &segs, 1e-10, 0.0, 200, verify);
            assert_eq!(one, all, "verify {verify}");
            assert!(
                one.evaluations > 100 && calls * 7 <= one.evaluations,
                "{calls}"
            );
        }
    }

    #[test]
    fn polynomials_are_exact_and_errors_honest() {
        // K15 integrates degree 22 exactly, G7 degree 13: x^12 has no error.
        let r = integrate(
            &mut plain(|x| x.powi(12)),
            &[Segment::linear(0.0, 2.0)],
            1e-9,
            0.0,
            10,
            false,
        );
        assert!(
            (r.value - 2f64.powi(13) / 13.0).abs() < 1e-10,
            "{}",
            r.value
        );
        assert_eq!(r.evaluations, PANEL_EVALS);
        // A narrow Gaussian: ∫ e^{−x²/2σ²} = σ√(2π) over the whole line.
        let s = 1e-3;
        let br = [-1.0, -0.01, -0.001, 0.0, 0.001, 0.01, 1.0];
        let r = integrate(
            &mut plain(|x| (-x * x / (2.0 * s * s)).exp()),
            &segments(&br, false, false),
            1e-14,
            0.0,
            200,
            false,
        );
        let want = s * (2.0 * std::f64::consts::PI).sqrt();
        assert!(r.converged);
        assert!(
            (r.value - want).abs() <= r.error.max(1e-15),
            "{} {}",
            r.value,
            r.error
        );
    }

    #[test]
    fn square_root_ends_are_graded_away() {
        // ∫₀¹ √x (1 − x)^{3/2} dx = B(3/2, 5/2) = π/16.
        let f = |x: f64| x.max(0.0).sqrt() * (1.0 - x).max(0.0).powf(1.5);
        let want = std::f64::consts::PI / 16.0;
        let graded = integrate(
            &mut plain(f),
            &segments(&[0.0, 1.0], true, true),
            1e-13,
            0.0,
            50,
            false,
        );
        assert!(
            (graded.value - want).abs() < 1e-12,
            "{}",
            graded.value - want
        );
        assert!(graded.evaluations <= 10 * PANEL_EVALS);
        // A split axis: graded at the outer ends only, linear inside.
        let s = segments(&[0.0, 0.3, 1.0], true, true);
        assert_eq!(s[0].grading, Grading::Start);
        assert_eq!(s[1].grading, Grading::End);
        let r = integrate(&mut plain(f), &s, 1e-13, 0.0, 50, false);
        assert!((r.value - want).abs() < 1e-12);
        // Every map covers its segment with the right Jacobian: ∫ 1 = b − a.
        for g in [Grading::Linear, Grading::Start, Grading::End, Grading::Both] {
            let s = Segment {
                a: 0.5,
                b: 2.0,
                grading: g,
            };
            assert_eq!(s.at(0.0).0, 0.5);
            assert!((s.at(1.0).0 - 2.0).abs() < 1e-15);
            let r = integrate(&mut plain(|_| 1.0), &[s], 1e-14, 0.0, 4, false);
            assert!((r.value - 1.5).abs() < 1e-13, "{g:?}");
        }
    }

    #[test]
    fn verification_catches_a_kink() {
        // ∫₀¹ min(1, 2x) dx = 3/4, with the kink inside the only panel.
        let f = |x: f64| (2.0 * x).min(1.0) + 0.0 * x;
        let r = integrate(
            &mut plain(f),
            &[Segment::linear(0.0, 1.0)],
            1e-3,
            0.0,
            50,
            true,
        );
        assert!(
            (r.value - 0.75).abs() <= r.error,
            "{} ± {}",
            r.value,
            r.error
        );
    }

    #[test]
    fn verification_covers_a_kink_almost_anywhere() {
        // ∫₀¹ (|x − t| + eˣ) dx = (t² + (1 − t)²)/2 + e − 1, the kink swept
        // over 1999 positions in [0.01, 0.99] and three tolerances (5997
        // integrals). No rule sees a kink nearer a panel's end than its
        // outermost node (0.43% of the panel for K15): every value there is
        // of one smooth branch, and the stated error is ~0. So some misses
        // are inherent, at dyadic breaks. Measured: the check against G7 on
        // the halves (SUSPECT = 0.25) misses 142; re-integrating every final
        // panel by K15 on its halves (this function's rule before the check,
        // with a per-panel difference) missed 169, at 40% more evaluations.
        // The bound guards against a check that lets more through.
        let (mut misses, mut covered_err) = (0usize, 0.0f64);
        for tol in [1e-4, 1e-6, 1e-8] {
            for k in 1..2000 {
                let t = 0.01 + 0.98 * k as f64 / 2000.0 + 1e-4 * (k as f64).sin();
                let f = |x: f64| (x - t).abs() + x.exp();
                let want = 0.5 * (t * t + (1.0 - t) * (1.0 - t)) + std::f64::consts::E - 1.0;
                let r = integrate(
                    &mut plain(f),
                    &[Segment::linear(0.0, 1.0)],
                    tol,
                    0.0,
                    200,
                    true,
                );
                let real = (r.value - want).abs();
                if real > r.error {
                    misses += 1;
                } else {
                    covered_err = covered_err.max(real / r.error);
                }
            }
        }
        assert!(misses <= 145, "{misses} of 5997 kinks missed");
        // The bars are not vacuous where they hold: the real error reaches
        // a large share of them somewhere.
        assert!(covered_err > 0.1, "largest real/stated {covered_err:e}");
    }

    #[test]
    fn budget_exhaustion_is_reported() {
        // A jump is never resolved by bisection to 1e-16 in 3 panels.
        let r = integrate(
            &mut plain(|x| if x < 0.3 { 1.0 } else { 0.0 }),
            &[Segment::linear(0.0, 1.0)],
            1e-16,
            0.0,
            3,
            false,
        );
        assert!(!r.converged);
        assert!(
            (r.value - 0.3).abs() <= r.error,
            "{} ± {}",
            r.value,
            r.error
        );
    }
}
