//! Deterministic quadrature of the directional albedo
//! `ρhd(wi) = ∫ f(wi, wo) |cos θo| dωo` and of `ρhh`, with an error estimate.
//!
//! # Parameterisation
//! The reflected hemisphere is integrated over the half vector `h` (Walter et
//! al. 2007, eq. 14: `dωo = 4 |wo·h| dωh`), since almost every lobe of the
//! catalogue is a function of `h` peaked at the normal: microfacet `D(h)`,
//! Blinn's `(n·h)^e`, Ward's and Ashikhmin–Shirley's elliptical lobes, and the
//! Phong lobe about the mirror direction, which is `h = n`. With
//! `h = (sin θh cos φh, sin θh sin φh, cos θh)` and `wo = 2 (wi·h) h − wi`,
//!
//! `ρhd = ∫∫ f(wi, wo) cos θo · 4 (wi·h) sin θh dφh dθh`
//!
//! over the `h` whose `wo` lies above the horizon. For `θh < 90°` that set is
//! exactly the arc `cos(φh − φi) > c₀(θh)` with
//! `c₀ = −cos θi cos 2θh / (sin 2θh sin θi)`: the whole circle for
//! `θh ≤ (90° − θi)/2`, shrinking to nothing at `θh = (90° + θi)/2`. The
//! inner integral runs over that arc exactly, so the horizon is never a
//! discontinuity inside a panel; its ends are graded (see
//! [`super::gauss_kronrod`]) because the integrand and the arc width behave
//! like square roots there.
//!
//! # Rule
//! Nested global adaptive Gauss–Kronrod 7/15 in θh (outer) and φh (inner).
//! θh starts from a panel graded quadratically towards the normal (its first
//! nodes lie within 10⁻⁴ rad of it, inside every lobe of `α ≥ 0.01` or
//! exponent ≤ 10⁴, whose widths in h are ≥ 0.005 rad, so bisection finds and
//! resolves them) and from panels graded geometrically (down to 2·10⁻⁴ rad)
//! about each narrow peak a model reports through [`Brdf::peaks`]. φh starts with breaks at the plane of incidence,
//! at the tangent axes for anisotropic models and at the peaks' azimuths. The
//! error is `|K15 − G7|` per panel plus the inner integrals' errors carried
//! through the outer weights: an upper-bound style estimate, not a standard
//! error. Transmitting models add the lower hemisphere in polar coordinates
//! about their refracted peak (see [`transmitted`]). Delta lobes add their
//! exact weights.
//!
//! # Less work for the same answer
//! - An isotropic model symmetric about the plane of incidence (tested at 24
//!   points before it is relied on, since isotropy does not imply it and a
//!   claim may be wrong) is integrated over one side of the plane, doubled.
//! - The kinks a model names ([`Brdf::kinks`]: Oren-Nayar's clamps,
//!   V-groove's `min`) are located on each inner circle by regula falsi and
//!   become panel breaks, instead of a cloud of bisections about each.
//! - A model that names a pole on the light's side ([`Brdf::pole`]: Hapke's
//!   opposition surge, a cusp at `wo = wi`; Banks' fibre, on whose rings
//!   `f` is constant) is integrated there in polar coordinates about it, by
//!   the rule of the transmitted part (see [`transmitted`]) on the model's
//!   mirror image: each ring about the pole is then smooth, where over the
//!   half vector Hapke's cusp is a 2-D feature at `h = wi` that both axes
//!   must bisect towards and Banks' cone a ridge across every circle.
//! - A transmitting model may name cones outside which its transmitted part
//!   is zero ([`Brdf::transmission_support`]: the rough dielectric's cone
//!   past which no facet refracts, and the plane past which that facet
//!   would face down). Their crossings with each ring (and the rings that
//!   touch them) are breaks in closed form, and the arcs and rings outside
//!   are skipped without an evaluation: a third of the rough dielectric's
//!   evaluations, and more for light from below.
//! - The inner integrands hand a panel's nodes to the model in one call
//!   ([`Brdf::eval_many_with_half`], [`Brdf::eval_many`]), whose loop is
//!   compiled for the model: the same values bit for bit as one call per
//!   node through `&dyn Brdf`, at about 0.8 of a GGX Cook-Torrance curve's
//!   time.

use super::directions::below;
use super::estimate::{AlbedoParts, Estimate, Method};
use super::gauss_kronrod::{self, Segment};
use crate::{Brdf, Cone, DeltaKind, Rgb, frame};
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Accuracy and work limits of the quadrature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadratureOptions {
    /// Target absolute error of each ρhd value (default 2e-6, five times
    /// inside the 1e-5 that the reports promise).
    pub abs_tol: f64,
    /// Panel budget of the outer (θh) axis (default 200).
    pub outer_panels: usize,
    /// Panel budget of each inner (φh) axis (default 100).
    pub inner_panels: usize,
    /// Verify the outer (θh) axis at a second resolution of every final
    /// panel (default on; see [`gauss_kronrod::integrate`]): honest errors
    /// across kinks in θh (Cook-Torrance's V-groove G at `θh = 30°` for
    /// normal incidence), at about 1.7 times the work.
    pub verify: bool,
}

impl Default for QuadratureOptions {
    fn default() -> Self {
        Self {
            abs_tol: 2e-6,
            outer_panels: 200,
            inner_panels: 100,
            verify: true,
        }
    }
}

/// The smallest θh panel at a peak (radians).
const FINEST: f64 = 2e-4;

/// Nodes an inner integrand hands to the model in one call: a Kronrod
/// panel's (more, from a caller that passes more, go in turns).
const NODES: usize = gauss_kronrod::PANEL_EVALS;

/// Breaks graded geometrically about `centre` (`centre ± FINEST · 2^k`),
/// inside `[lo, hi]`.
fn graded_about(centre: f64, lo: f64, hi: f64, out: &mut Vec<f64>) {
    out.push(centre.clamp(lo, hi));
    let mut d = FINEST;
    while d < hi - lo {
        for x in [centre - d, centre + d] {
            if x > lo && x < hi {
                out.push(x);
            }
        }
        d *= 2.0;
    }
}

/// `(sin x, cos x)` to within a few 1e-16 absolute for `|x| ≤ 1e5` (std's
/// beyond): the inner integrands' azimuths, where libm's `sincos` was a
/// tenth to a sixth of a curve's time (perf, Cook-Torrance and the rough
/// dielectric). Cody–Waite reduction by π/2 with fdlibm's two-part constant
/// (`x − k·PIO2_1` is exact for `|k| < 2²⁰`: `PIO2_1` has 33 significant
/// bits), then fdlibm's minimax kernels `__kernel_sin` / `__kernel_cos`
/// (Sun Microsystems 1993; error below 1 ulp on `[−π/4, π/4]`), inlined.
// fdlibm's constants as published (they round to the intended f64s).
#[allow(clippy::excessive_precision)]
#[inline]
fn sin_cos(x: f64) -> (f64, f64) {
    const PIO2_1: f64 = 1.570_796_326_734_125_614_17;
    const PIO2_1T: f64 = 6.077_100_506_506_192_249_32e-11;
    const S: [f64; 6] = [
        -1.666_666_666_666_663_243_48e-1,
        8.333_333_333_322_489_461_24e-3,
        -1.984_126_982_985_794_931_34e-4,
        2.755_731_370_707_006_767_89e-6,
        -2.505_076_025_340_686_341_95e-8,
        1.589_690_995_211_550_102_21e-10,
    ];
    const C: [f64; 6] = [
        4.166_666_666_666_660_190_37e-2,
        -1.388_888_888_887_410_957_49e-3,
        2.480_158_728_947_672_941_78e-5,
        -2.755_731_435_139_066_330_35e-7,
        2.087_572_321_298_174_827_90e-9,
        -1.135_964_755_778_819_482_65e-11,
    ];
    if x.is_nan() || x.abs() > 1e5 {
        return x.sin_cos();
    }
    // Round to nearest by the 1.5·2⁵² shift (exact for |x·2/π| < 2⁵¹;
    // `f64::round` is a libm call).
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    let k = (x * std::f64::consts::FRAC_2_PI + SHIFT) - SHIFT;
    let r = (x - k * PIO2_1) - k * PIO2_1T;
    let z = r * r;
    let ps = S[0] + z * (S[1] + z * (S[2] + z * (S[3] + z * (S[4] + z * S[5]))));
    let s = r + r * z * ps;
    let pc = C[0] + z * (C[1] + z * (C[2] + z * (C[3] + z * (C[4] + z * C[5]))));
    let c = 1.0 - 0.5 * z + z * z * pc;
    match (k as i64).rem_euclid(4) {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// Wraps an angle to `(c − π, c + π]`.
fn wrap_near(phi: f64, c: f64) -> f64 {
    let mut d = (phi - c) % TAU;
    if d > PI {
        d -= TAU;
    } else if d <= -PI {
        d += TAU;
    }
    c + d
}

/// The panels of a polar axis from its sorted `breaks`, graded towards the
/// pole (0), from `theta_full` upwards (where the arc below the horizon
/// starts to shrink like a square root) and towards `theta_end` (where it
/// closes): the reflected part's θh and the transmitted part's θ.
fn polar_segments(breaks: &[f64], theta_full: f64, theta_end: f64) -> Vec<Segment> {
    breaks
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let start = a == 0.0 || (a == theta_full && theta_full > 0.0);
            let end = b == theta_end;
            let grading = match (start, end) {
                (true, true) => gauss_kronrod::Grading::Both,
                (true, false) => gauss_kronrod::Grading::Start,
                (false, true) => gauss_kronrod::Grading::End,
                (false, false) => gauss_kronrod::Grading::Linear,
            };
            Segment { a, b, grading }
        })
        .collect()
}

/// How far outside a model's [`Cone`] a part of a ring must lie (in
/// `wo·axis − cos_half`) to be skipped: a kink root that [`kink_roots`]
/// placed at an arc's break is within 1e-12 of the cone, on either side,
/// and `f` falls to 0 at the cone (see `RoughDielectric::kinks`), so what a
/// margin this small leaves out is far below any tolerance.
const CONE_MARGIN: f64 = 1e-9;

/// One of a model's [`Brdf::transmission_support`] cones on the rings of
/// [`transmitted`]: with `wo(θ, ψ) = cos θ p − sin θ (cos ψ e₁ + sin ψ e₂)`,
/// `wo·axis − cos_half = A cos θ − sin θ (B cos ψ + C sin ψ) − cos_half`
/// (`A = p·axis`, `B = e₁·axis`, `C = e₂·axis`): where a ring crosses the
/// cone, and which rings touch it, in closed form. A part of a ring is
/// skipped only when all of it lies outside, whether or not a kink search
/// found the cone there.
#[derive(Debug, Clone, Copy)]
struct ConeOnRings {
    a: f64,
    b: f64,
    c: f64,
    cos_half: f64,
    /// `√(B² + C²)`, the ring's reach across the axis.
    r: f64,
    /// Where `B cos ψ + C sin ψ = r cos(ψ − ψ₀)` is largest.
    psi0: f64,
}

impl ConeOnRings {
    fn new(cone: Cone, p: DVec3, e1: DVec3, e2: DVec3) -> Option<Self> {
        let ok = cone.axis.is_finite()
            && (cone.axis.length() - 1.0).abs() < 1e-9
            && cone.cos_half.is_finite();
        let (a, b, c) = (p.dot(cone.axis), e1.dot(cone.axis), e2.dot(cone.axis));
        ok.then_some(Self {
            a,
            b,
            c,
            cos_half: cone.cos_half,
            r: b.hypot(c),
            psi0: c.atan2(b),
        })
    }

    /// `wo·axis − cos_half` at `ψ` on the ring of `(sin θ, cos θ)`.
    fn at(&self, st: f64, ct: f64, psi: f64) -> f64 {
        let (sp, cp) = psi.sin_cos();
        self.a * ct - st * (self.b * cp + self.c * sp) - self.cos_half
    }

    /// Whether the arc `[lo, hi]` (`hi − lo ≤ 2π`) of the ring of
    /// `(sin θ ≥ 0, cos θ)` lies outside the cone, up to [`CONE_MARGIN`].
    fn outside(&self, st: f64, ct: f64, lo: f64, hi: f64) -> bool {
        // The point nearest the axis (ψ₀ + π), at its first turn after lo.
        let near = self.psi0 + PI;
        let near = near + ((lo - near) / TAU).ceil() * TAU;
        let most = if near <= hi {
            self.a * ct + st * self.r - self.cos_half
        } else {
            self.at(st, ct, lo).max(self.at(st, ct, hi))
        };
        most <= CONE_MARGIN
    }

    /// Where the ring of `(sin θ, cos θ)` crosses the cone inside
    /// `(lo, hi)`: `r cos(ψ − ψ₀) = (A cos θ − cos_half)/sin θ`.
    fn crossings(&self, st: f64, ct: f64, lo: f64, hi: f64, out: &mut Vec<f64>) {
        let den = st * self.r;
        let q = (self.a * ct - self.cos_half) / den;
        // (No crossing for a ring of radius 0 or one wholly on one side,
        // nor for NaN.)
        if den <= 0.0 || q.is_nan() || q.abs() >= 1.0 {
            return;
        }
        let d = q.acos();
        for x in [self.psi0 + d, self.psi0 - d] {
            let x = x + ((lo - x) / TAU).ceil() * TAU;
            if x > lo && x < hi {
                insert_break(out, x);
            }
        }
    }

    /// The polar angles in `(0, end)` of the rings that touch the cone
    /// (`A cos θ ± r sin θ = cos_half`), where the part of a ring inside it
    /// appears or vanishes: kinks of the outer integrand.
    fn tangent_rings(&self, end: f64, out: &mut Vec<f64>) {
        let rho = self.a.hypot(self.r);
        if rho <= 0.0 || rho.is_nan() || self.cos_half.abs() >= rho {
            return;
        }
        let (d, g) = (self.r.atan2(self.a), (self.cos_half / rho).acos());
        for t in [d + g, d - g, g - d, -d - g] {
            if t > 0.0 && t < end {
                insert_break(out, t);
            }
        }
    }
}

/// Adds the break `x` unless one lies within 1e-9 of it already: a kink
/// root that the search placed to 1e-12 is kept, and no sliver of a panel
/// is left between the two.
fn insert_break(breaks: &mut Vec<f64>, x: f64) {
    if breaks.iter().all(|&b| (b - x).abs() > 1e-9) {
        breaks.push(x);
    }
}

/// The inner (azimuthal) integrals of one part, ring after ring: their
/// tolerance and panel budget, and the vectors each ring fills (its sorted
/// breaks, its segments), kept from ring to ring (a ρhd curve integrates
/// hundreds of rings per angle, each of which allocated them).
struct Arcs {
    tol: f64,
    panels: usize,
    sorted: Vec<f64>,
    segs: Vec<Segment>,
}

impl Arcs {
    fn new(tol: f64, panels: usize) -> Self {
        Self {
            tol,
            panels,
            sorted: Vec::new(),
            segs: Vec::new(),
        }
    }

    /// One ring's integral over the arc cut at `breaks`: graded at the
    /// arc's ends unless it is the `full` circle, and with `half` only the
    /// side from the plane of incidence, doubled (to half the tolerance).
    fn integral(
        &mut self,
        f: &mut impl gauss_kronrod::Integrand<Rgb>,
        breaks: &[f64],
        full: bool,
        half: bool,
    ) -> gauss_kronrod::Integral<Rgb> {
        self.integral_where(f, breaks, full, half, |_| true)
    }

    /// [`Arcs::integral`] over the segments between `breaks` that `keep`
    /// keeps (the others are known to be zero; each keeps the grading it
    /// has among all of them).
    fn integral_where(
        &mut self,
        f: &mut impl gauss_kronrod::Integrand<Rgb>,
        breaks: &[f64],
        full: bool,
        half: bool,
        keep: impl Fn(&Segment) -> bool,
    ) -> gauss_kronrod::Integral<Rgb> {
        let segs = &mut self.segs;
        gauss_kronrod::segments_into(breaks, !full && !half, !full, &mut self.sorted, segs);
        segs.retain(keep);
        if segs.is_empty() {
            return gauss_kronrod::Integral {
                value: Rgb::ZERO,
                error: Rgb::ZERO,
                evaluations: 0,
                converged: true,
            };
        }
        let (tol, scale) = if half {
            (0.5 * self.tol, 2.0)
        } else {
            (self.tol, 1.0)
        };
        let mut r = gauss_kronrod::integrate(f, segs, tol, 0.0, self.panels, false);
        r.value *= scale;
        r.error *= scale;
        r
    }
}

/// Whether azimuth `p` lies in the plane of incidence at azimuth `phi_i`
/// (on either side of the normal).
fn in_plane(p: f64, phi_i: f64) -> bool {
    let d = (wrap_near(p, phi_i) - phi_i).abs();
    d < 1e-9 || (d - PI).abs() < 1e-9
}

/// Whether `f(wi, ·)` takes the same values at outgoing directions and at
/// their mirror images through the plane of incidence (azimuth `phi_i`), at
/// 24 directions of a fixed spiral over the hemisphere above the surface
/// (below it with `below`), to 1e-12 relative: the test [`reflected`] and
/// [`transmitted`] make before they integrate one side of the plane.
fn mirror_symmetric(brdf: &dyn Brdf, wi: DVec3, phi_i: f64, below: bool) -> bool {
    const POINTS: usize = 24;
    let golden = PI * (3.0 - 5f64.sqrt());
    (0..POINTS).all(|k| {
        let z = 1.0 - (k as f64 + 0.5) / POINTS as f64;
        let r = (1.0 - z * z).max(0.0).sqrt();
        // Relative to the plane of incidence, mirrored: φi ± d.
        let d = 0.37 + golden * k as f64;
        let z = if below { -z } else { z };
        let at = |a: f64| DVec3::new(r * a.cos(), r * a.sin(), z);
        let (p, q) = (brdf.eval(wi, at(phi_i + d)), brdf.eval(wi, at(phi_i - d)));
        let scale = p.abs().max(q.abs()).max_element();
        scale.is_finite() && (p - q).abs().max_element() <= 1e-12 * scale
    })
}

/// Points of the scan over an arc in which the kinks' sign changes are
/// looked for (a kink crossing the arc twice within one step is missed and
/// left to the verified bisection). Four: the catalogue's kinks cross each
/// half arc at most once (V-groove's and Oren-Nayar's are linear in
/// `cos(φh − φi)`, the rough dielectric's cones monotone along each side of
/// a ring), and 4, 2 and the former 8 gave the same evaluations for every
/// model's 90-angle curve, where the scan at 8 was a tenth of
/// Cook-Torrance's time (perf); 4 keeps a margin for kinks that turn.
const KINK_SCAN: usize = 4;

/// Points of the scan along the plane of incidence in θh for the outer
/// breaks where a kink's roots appear on the circles (see [`reflected`]).
const OUTER_KINK_SCAN: usize = 32;

/// The most scan points [`kink_roots`] takes.
const MAX_SCAN: usize = OUTER_KINK_SCAN;

/// Adds to `out` the parameters in `(lo, hi)` (an azimuth on a circle, or
/// θh along the plane of incidence) where a kink of the model
/// ([`Brdf::kinks`]) changes sign along the directions `dir(φ)` (`None`
/// where there is no direction), looked for at `scan` steps, each to within 1e-12 rad by the Illinois
/// variant of regula falsi (superlinear, and it keeps the root bracketed):
/// panel breaks, so that no Gauss–Kronrod panel straddles a kink.
/// `guess(x0, x1, f0, f1)` proposes the first point inside a bracket (NaN:
/// none, the plain regula falsi step): the secant in a variable in which the
/// caller's kinks are closer to linear.
fn kink_roots(
    kinks: &[crate::Kink<'_>],
    dir: impl Fn(f64) -> Option<DVec3>,
    guess: impl Fn(f64, f64, f64, f64) -> f64,
    lo: f64,
    hi: f64,
    scan: usize,
    out: &mut Vec<f64>,
) {
    if kinks.is_empty() || hi - lo <= 0.0 {
        return;
    }
    // The scan's directions, on the stack (this runs once per inner
    // integral).
    let scan = scan.min(MAX_SCAN);
    let step = (hi - lo) / scan as f64;
    let mut xs = [0.0; MAX_SCAN + 1];
    let mut dirs = [None; MAX_SCAN + 1];
    for (k, (x, d)) in xs.iter_mut().zip(&mut dirs).enumerate().take(scan + 1) {
        *x = lo + step * k as f64;
        *d = dir(*x);
    }
    // An arc's ends lie on the horizon, where rounding can put the
    // direction just below it (`None`): the scan's first or last step would
    // then be skipped, and with it a kink that crosses the arc there (V-groove's
    // `2 (n·h)(n·wo) = wo·h`, near the horizon at every grazing θi), which
    // bisection then chased at 5 to 15 times the work. Such an end is moved
    // inside by a millionth of a step.
    for (k, inward) in [(0, 1e-6 * step), (scan, -1e-6 * step)] {
        if dirs[k].is_none() {
            xs[k] += inward;
            dirs[k] = dir(xs[k]);
        }
    }
    // Each kink at the scan's points once (neighbouring steps share one).
    let mut vals = [f64::NAN; MAX_SCAN + 1];
    for kink in kinks {
        let value = |phi: f64| dir(phi).map(kink);
        for (v, d) in vals.iter_mut().zip(&dirs).take(scan + 1) {
            *v = d.map_or(f64::NAN, kink);
        }
        for k in 0..scan {
            let (mut fa, mut fb) = (vals[k], vals[k + 1]);
            if !(fa.is_finite() && fb.is_finite()) || (fa > 0.0) == (fb > 0.0) {
                continue;
            }
            let (mut x0, mut x1) = (xs[k], xs[k + 1]);
            // A value this small is a root to rounding (for a kink that is
            // close to linear in the parameter or in `guess`'s variable).
            let small = 1e-14 * fa.abs().max(fb.abs());
            // Which end was kept last time (Illinois halves its value).
            let mut kept = 0i8;
            for it in 0..100 {
                if x1 - x0 <= 1e-12 {
                    break;
                }
                let mut m = if it == 0 {
                    guess(x0, x1, fa, fb)
                } else {
                    f64::NAN
                };
                if !(m > x0 && m < x1) {
                    m = x1 - fb * (x1 - x0) / (fb - fa);
                }
                if !(m > x0 && m < x1) {
                    m = 0.5 * (x0 + x1);
                }
                let Some(fm) = value(m).filter(|v| v.is_finite()) else {
                    break;
                };
                if fm.abs() <= small {
                    x0 = m;
                    x1 = m;
                    break;
                }
                if (fm > 0.0) == (fa > 0.0) {
                    x0 = m;
                    fa = fm;
                    if kept == 1 {
                        fb *= 0.5;
                    }
                    kept = 1;
                } else {
                    x1 = m;
                    fb = fm;
                    if kept == -1 {
                        fa *= 0.5;
                    }
                    kept = -1;
                }
            }
            let x = 0.5 * (x0 + x1);
            if x > lo && x < hi {
                out.push(x);
            }
        }
    }
}

/// The first guess of [`kink_roots`] on a circle of θh: the secant in
/// `t = cos(φh − φi)`. There `c = wi·h = cos θh cos θi + sin θh sin θi t`
/// and `wo = 2c h − wi`, so V-groove's kinks (`2 hz wo.z − c`,
/// `2 hz wi.z − c`, `wo.z − wi.z`, up to the positive factor `|wi + wo|`)
/// and Oren-Nayar's clamps are linear in `t`, and the secant lands on the
/// root to rounding in one step (where it took the Illinois steps in φ
/// about seven). `t` is monotone where `φh − φi` keeps its sign; NaN (no
/// guess) across it.
fn cos_secant(phi_i: f64) -> impl Fn(f64, f64, f64, f64) -> f64 {
    move |x0: f64, x1: f64, f0: f64, f1: f64| {
        let (d0, d1) = (x0 - phi_i, x1 - phi_i);
        // An end at the plane of incidence may land a rounding on its other
        // side (a scan point `lo + k·step` = φi + 2e-16): that is no sign
        // change of `φh − φi`.
        let across = d0 * d1 < 0.0 && d0.abs().min(d1.abs()) > 1e-12;
        if across || d0.abs() > PI || d1.abs() > PI {
            return f64::NAN;
        }
        let (t0, t1) = (sin_cos(d0).1, sin_cos(d1).1);
        let t = t0 - f0 * (t1 - t0) / (f1 - f0);
        let d = t.clamp(-1.0, 1.0).acos();
        phi_i + if d0 + d1 >= 0.0 { d } else { -d }
    }
}

/// The kinks' roots along the outer axis `0..theta_end` (a curve through
/// the pole, `along`), as outer panel breaks: [`kink_roots`] with no first
/// guess (plain regula falsi) and the outer scan.
fn outer_kink_roots(
    kinks: &[crate::Kink<'_>],
    along: impl Fn(f64) -> Option<DVec3>,
    theta_end: f64,
    breaks: &mut Vec<f64>,
) {
    kink_roots(
        kinks,
        along,
        no_guess,
        0.0,
        theta_end,
        OUTER_KINK_SCAN,
        breaks,
    );
}

/// No first guess for [`kink_roots`]: plain regula falsi.
fn no_guess(_: f64, _: f64, _: f64, _: f64) -> f64 {
    f64::NAN
}

/// Half-width of the arc of φh − φi whose `wo` is above the horizon, for
/// `θh ∈ [0, 90°)`; π for the whole circle.
fn arc_half_width(cos_ti: f64, sin_ti: f64, theta_h: f64) -> f64 {
    let (s2, c2) = (2.0 * theta_h).sin_cos();
    let num = -cos_ti * c2;
    let den = s2 * sin_ti;
    if den <= 0.0 {
        // Normal incidence (or θh = 0): whole circle while cos 2θh > 0.
        return if num < 0.0 { PI } else { 0.0 };
    }
    let c0 = num / den;
    if c0 <= -1.0 {
        PI
    } else if c0 >= 1.0 {
        0.0
    } else {
        c0.acos()
    }
}

/// ρhd for light from the unit direction `wi` by quadrature (see the module
/// docs), with the delta lobes' weights added.
pub fn rho_hd_dir(brdf: &dyn Brdf, wi: DVec3, opts: &QuadratureOptions) -> Estimate {
    rho_hd_parts_dir(brdf, wi, opts).total
}

/// ρhd split into its reflected part ρR (directions on `wi`'s side) and its
/// transmitted part ρT (the other side; 0 for a model that does not
/// transmit), each with its delta lobes' weights and its error estimate;
/// `total` is their sum. Light from below the surface (`wi.z < 0`) is
/// integrated for a transmitting model as the mirror image of the model
/// through the surface plane lit from above; for a reflection model it sees
/// nothing.
pub fn rho_hd_parts_dir(brdf: &dyn Brdf, wi: DVec3, opts: &QuadratureOptions) -> AlbedoParts {
    let transmits = brdf.transmits();
    if transmits && wi.z < 0.0 {
        return rho_hd_parts_dir(&Flipped(brdf), below(wi), opts);
    }
    let deltas = brdf.deltas(wi);
    let delta = |kind: DeltaKind| -> Rgb {
        deltas
            .iter()
            .filter(|d| d.kind == kind)
            .map(|d| d.weight)
            .sum()
    };
    let (delta_r, delta_t) = (delta(DeltaKind::Reflection), delta(DeltaKind::Transmission));
    let cos_ti = wi.z.clamp(-1.0, 1.0);
    if cos_ti <= 0.0 || !wi.is_finite() {
        return AlbedoParts::new(
            quad_estimate(delta_r, Rgb::ZERO, 0, true),
            quad_estimate(delta_t, Rgb::ZERO, 0, true),
        );
    }
    let sin_ti = (1.0 - cos_ti * cos_ti).max(0.0).sqrt();
    let theta_i = cos_ti.acos();
    let phi_i = if sin_ti > 0.0 { wi.y.atan2(wi.x) } else { 0.0 };
    // A model that names a pole on wi's side (Hapke's cusp at wo = wi,
    // Banks' fibre) is integrated in polar coordinates about it, by the rule
    // of the transmitted part applied to the model's mirror image through
    // the surface ([`AboutPole`]).
    let pole = brdf
        .pole(wi)
        .filter(|c| c.is_finite() && c.z >= 0.0)
        .and_then(DVec3::try_normalize);
    let upper = match pole {
        Some(pole) => transmitted(&AboutPole(brdf), wi, Some(below(pole)), opts),
        None => reflected(brdf, wi, cos_ti, sin_ti, theta_i, phi_i, opts),
    };
    let reflected = quad_estimate(
        upper.value + delta_r,
        upper.error,
        upper.evaluations,
        upper.converged,
    );
    let transmitted = if transmits {
        let lower = transmitted(brdf, wi, None, opts);
        quad_estimate(
            lower.value + delta_t,
            lower.error,
            lower.evaluations,
            lower.converged,
        )
    } else {
        quad_estimate(delta_t, Rgb::ZERO, 0, true)
    };
    AlbedoParts::new(reflected, transmitted)
}

/// The mirror image of a transmitting model through the surface plane
/// (`z → −z` for every direction): light from below the original is light
/// from above the image.
#[derive(Debug)]
struct Flipped<'a>(&'a dyn Brdf);

impl Brdf for Flipped<'_> {
    fn id(&self) -> &'static str {
        self.0.id()
    }
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.0.eval(below(wi), below(wo))
    }
    fn claims(&self) -> crate::Claims {
        self.0.claims()
    }
    fn transmits(&self) -> bool {
        true
    }
    fn deltas(&self, wi: DVec3) -> Vec<crate::DeltaLobe> {
        let mut d = self.0.deltas(below(wi));
        for l in &mut d {
            l.direction = below(l.direction);
        }
        d
    }
    fn peaks(&self, wi: DVec3) -> Vec<DVec3> {
        self.0.peaks(below(wi)).into_iter().map(below).collect()
    }
    fn pole(&self, wi: DVec3) -> Option<DVec3> {
        self.0.pole(below(wi)).map(below)
    }
    fn kinks(&self, wi: DVec3) -> Vec<crate::Kink<'_>> {
        self.0
            .kinks(below(wi))
            .into_iter()
            .map(|k| -> crate::Kink<'_> { Box::new(move |wo| k(below(wo))) })
            .collect()
    }
    fn transmission_support(&self, wi: DVec3) -> Vec<Cone> {
        // A mirror keeps dot products: wo·axis = below(wo)·below(axis).
        let mut cones = self.0.transmission_support(below(wi));
        for c in &mut cones {
            c.axis = below(c.axis);
        }
        cones
    }
}

/// A reflection model seen through the surface plane on the outgoing side
/// only (`wo → −wo.z`): its reflected hemisphere becomes the lower one, which
/// [`transmitted`] integrates in polar coordinates about the mirror image of
/// the model's [`Brdf::pole`]. The peaks and the kinks on `wi`'s side are
/// mirrored with it.
#[derive(Debug)]
struct AboutPole<'a>(&'a dyn Brdf);

impl Brdf for AboutPole<'_> {
    fn id(&self) -> &'static str {
        self.0.id()
    }
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.0.eval(wi, below(wo))
    }
    fn claims(&self) -> crate::Claims {
        self.0.claims()
    }
    fn transmits(&self) -> bool {
        true
    }
    fn peaks(&self, wi: DVec3) -> Vec<DVec3> {
        let up = self.0.peaks(wi).into_iter().filter(|p| p.z > 0.0);
        up.map(below).collect()
    }
    fn kinks(&self, wi: DVec3) -> Vec<crate::Kink<'_>> {
        self.0
            .kinks(wi)
            .into_iter()
            .map(|k| -> crate::Kink<'_> { Box::new(move |wo| k(below(wo))) })
            .collect()
    }
}

fn quad_estimate(value: Rgb, error: Rgb, samples: usize, converged: bool) -> Estimate {
    Estimate {
        value,
        std_error: error,
        samples,
        rejected: 0,
        method: Method::Quadrature { converged },
    }
}

/// The reflected part, over the half vector.
fn reflected(
    brdf: &dyn Brdf,
    wi: DVec3,
    cos_ti: f64,
    sin_ti: f64,
    theta_i: f64,
    phi_i: f64,
    opts: &QuadratureOptions,
) -> gauss_kronrod::Integral<Rgb> {
    let theta_full = 0.5 * (FRAC_PI_2 - theta_i);
    let theta_end = 0.5 * (FRAC_PI_2 + theta_i);
    // Peaks away from the mirror direction, as half vectors.
    let peaks: Vec<(f64, f64)> = brdf
        .peaks(wi)
        .into_iter()
        .filter(|p| p.is_finite() && p.z > 0.0)
        .filter_map(|p| {
            let h = (wi + p.normalize()).try_normalize()?;
            Some((h.z.clamp(-1.0, 1.0).acos(), h.y.atan2(h.x)))
        })
        // A peak at the mirror direction (a Lafortune lobe `(−1, −1, 1)`)
        // has its half vector at the normal, which the square-law grading of
        // the first panel resolves already: geometric breaks there would be
        // a dozen panels of inner integrals for nothing, and its azimuth
        // (rounding's) a break on every circle.
        .filter(|&(t, _)| t > FINEST)
        .collect();
    let mut breaks = vec![0.0, theta_end];
    if theta_full > 0.0 && theta_full < theta_end {
        breaks.push(theta_full);
    }
    for &(t, _) in &peaks {
        graded_about(t, 0.0, theta_end, &mut breaks);
    }
    breaks.retain(|&x| (0.0..=theta_end).contains(&x));
    breaks.sort_by(f64::total_cmp);
    breaks.dedup_by(|a, b| (*a - *b).abs() <= 1e-14);
    // Segments: square-law grading at the normal (the mirror lobe: the
    // first Kronrod nodes of a panel [0, w] lie at 1.8e-5 w and 6.5e-4 w,
    // inside any lobe the contract covers, so bisection finds it), at
    // θ_full from above and towards the end (square-root points of the arc
    // width).
    // Where a kink's curve on the hemisphere crosses the plane of incidence,
    // a pair of its roots appears on (or leaves) the circles of θh: there
    // the inner integral has a kink of its own in θh, which bisection and
    // verification would otherwise chase (V-groove's `2 (n·h)(n·wi) = wi·h`
    // at θh = 90° − θi, its and Oren-Nayar's `θo = θi` at θh = θi). Those θh
    // are found as the inner roots are, along the plane on both sides of the
    // normal, and become outer breaks. A crossing elsewhere (a kink that is
    // not symmetric about the plane) is left to bisection.
    let kinks = brdf.kinks(wi);
    if !kinks.is_empty() {
        for side in [0.0, PI] {
            let (sp, cp) = (phi_i + side).sin_cos();
            let along = |theta_h: f64| {
                let (sh, ch) = sin_cos(theta_h);
                let h = DVec3::new(sh * cp, sh * sp, ch);
                let wo = 2.0 * wi.dot(h) * h - wi;
                (wo.z > 0.0).then_some(wo)
            };
            outer_kink_roots(&kinks, along, theta_end, &mut breaks);
        }
        breaks.sort_by(f64::total_cmp);
        breaks.dedup_by(|a, b| (*a - *b).abs() <= 1e-14);
    }
    let segs = polar_segments(&breaks, theta_full, theta_end);
    let anisotropic = !brdf.claims().isotropic;
    let mut fixed_phis: Vec<f64> = Vec::new();
    if anisotropic {
        fixed_phis.extend([0.0, FRAC_PI_2, PI, -FRAC_PI_2]);
    }
    fixed_phis.extend(peaks.iter().map(|&(_, p)| p));
    // An isotropic model is in practice also symmetric about the plane of
    // incidence (a function of θi, θo and |φo − φi|: every model built from
    // dot products with n, wi, wo and h is), and then the inner integral is
    // twice its half on one side of the plane, if no peak lies off it.
    // Isotropy does not imply that symmetry, and a claim may be wrong (bv
    // check exists to catch such models), so it is also tested at points
    // spread over the hemisphere before it is relied on.
    let half = !anisotropic
        && peaks.iter().all(|&(t, p)| t < 1e-9 || in_plane(p, phi_i))
        && mirror_symmetric(brdf, wi, phi_i, false);
    let inner_tol = 0.2 * opts.abs_tol / theta_end.max(1e-3);
    let mut inner_evals = 0usize;
    let (mut br, mut arcs) = (Vec::new(), Arcs::new(inner_tol, opts.inner_panels));
    let mut outer = |theta_h: f64| -> (Rgb, Rgb) {
        let psi = arc_half_width(cos_ti, sin_ti, theta_h);
        if psi <= 0.0 {
            return (Rgb::ZERO, Rgb::ZERO);
        }
        let (sh, ch) = sin_cos(theta_h);
        // A panel's nodes at a time (see the module docs): those whose `wo`
        // is above the horizon go to the model in one call.
        let mut inner = gauss_kronrod::Batched(|phis: &[f64], out: &mut [(Rgb, Rgb)]| {
            for (phis, out) in phis.chunks(NODES).zip(out.chunks_mut(NODES)) {
                let mut wos = [DVec3::ZERO; NODES];
                let mut hs = [DVec3::ZERO; NODES];
                let mut at = [0usize; NODES];
                let mut weight = [0.0; NODES];
                let mut m = 0;
                for (k, &phi) in phis.iter().enumerate() {
                    out[k] = (Rgb::ZERO, Rgb::ZERO);
                    let (sp, cp) = sin_cos(phi);
                    let h = DVec3::new(sh * cp, sh * sp, ch);
                    let c = wi.dot(h);
                    let wo = 2.0 * c * h - wi;
                    if wo.z <= 0.0 || c <= 0.0 {
                        continue;
                    }
                    // `|wo|² = 4c² |h|² − 4c (wi·h) + |wi|² = 1` for unit
                    // `h` and `wi`: `wo` is unit to a few ulp without a
                    // normalisation (a square root and a division per
                    // evaluation), and `h` is its half vector with `wi`,
                    // which a model built from `h` takes instead of
                    // normalising `wi + wo` again.
                    wos[m] = wo;
                    hs[m] = h;
                    at[m] = k;
                    weight[m] = wo.z * 4.0 * c * sh;
                    m += 1;
                }
                let mut vals = [Rgb::ZERO; NODES];
                brdf.eval_many_with_half(wi, &wos[..m], &hs[..m], &mut vals[..m]);
                for j in 0..m {
                    out[at[j]].0 = vals[j] * weight[j];
                }
            }
        });
        let full = psi >= PI;
        let (lo, hi) = (if half { phi_i } else { phi_i - psi }, phi_i + psi);
        br.clear();
        br.extend([lo, phi_i, hi]);
        for &p in &fixed_phis {
            let p = wrap_near(p, phi_i);
            if p > lo && p < hi {
                br.push(p);
            }
        }
        let dir = |phi: f64| {
            let (sp, cp) = sin_cos(phi);
            let h = DVec3::new(sh * cp, sh * sp, ch);
            // Unit to a few ulp, as in `inner`.
            let wo = 2.0 * wi.dot(h) * h - wi;
            (wo.z > 0.0).then_some(wo)
        };
        kink_roots(&kinks, dir, cos_secant(phi_i), lo, hi, KINK_SCAN, &mut br);
        let r = arcs.integral(&mut inner, &br, full, half);
        inner_evals += r.evaluations;
        (r.value, r.error)
    };
    let mut r = gauss_kronrod::integrate(
        &mut outer,
        &segs,
        opts.abs_tol,
        0.0,
        opts.outer_panels,
        opts.verify,
    );
    r.evaluations = inner_evals;
    r
}

/// The transmitted part, in polar coordinates `(θ, ψ)` about `pole` when
/// given (a reflection model's [`Brdf::pole`], mirrored through the surface
/// by [`AboutPole`]; it may lie in the surface's plane), else about the
/// model's first peak below the surface `p` ([`Brdf::peaks`]: a rough
/// dielectric's refracted direction; the pole −z when it names none):
/// `wo = cos θ p − sin θ (cos ψ e₁ + sin ψ e₂)`, with `e₁` in the vertical
/// plane through `p` pointing up and `e₂ = p × e₁` horizontal, and
/// `ρT = ∫∫ f |cos θo| sin θ dψ dθ` over the part of that sphere below the
/// surface. The lobe is then a cap at `θ = 0` (graded as the reflected part
/// grades the normal, so a lobe as narrow as α = 0.001 is resolved) and
/// smooth in ψ, where the pole's coordinates would see it as a narrow
/// feature in both angles away from normal incidence. With `β` the angle of
/// `p` from −z, each ring `θ ≤ 90° − β` lies wholly below the surface; past
/// it the part below is the arc `cos ψ > −cos θ cos β / (sin θ sin β)` about
/// `ψ = 0`, which closes at `θ = 90° + β`. For a model of an interface
/// ([`Brdf::interface_eta`]) the rule also breaks where the generalised half
/// vector `ηi wi + ηo wo` of Walter et al. 2007 (eq. 16) turns horizontal,
/// `cos θo = −ηi cos θi / ηo`: a microfacet BTDF whose D does not vanish at
/// the horizon (GGX) drops to 0 across that circle. It crosses each ring at
/// azimuths found in closed form (inner breaks), and the rings that touch it
/// are outer breaks. Other peaks below add graded outer breaks and inner
/// breaks at their azimuths.
fn transmitted(
    brdf: &dyn Brdf,
    wi: DVec3,
    pole: Option<DVec3>,
    opts: &QuadratureOptions,
) -> gauss_kronrod::Integral<Rgb> {
    let below_peaks: Vec<DVec3> = brdf
        .peaks(wi)
        .into_iter()
        .filter(|p| p.is_finite() && p.z < 0.0)
        .filter_map(|p| p.try_normalize())
        .collect();
    let p = pole
        .or_else(|| below_peaks.first().copied())
        .unwrap_or(DVec3::NEG_Z);
    let phi_i = wi.y.atan2(wi.x);
    let up = DVec3::Z - p.z * p;
    let e1 = if up.length() > 1e-9 {
        up.normalize()
    } else {
        // p at the pole: e₁ (any horizontal) in the plane of incidence.
        let (s, c) = phi_i.sin_cos();
        DVec3::new(c, s, 0.0)
    };
    let e2 = p.cross(e1);
    // The model's cone outside which the transmitted part is zero: rings
    // and arcs out there are skipped.
    let cones: Vec<ConeOnRings> = brdf
        .transmission_support(wi)
        .into_iter()
        .filter_map(|c| ConeOnRings::new(c, p, e1, e2))
        .collect();
    let (sb, cb) = (e1.z.clamp(0.0, 1.0), (-p.z).clamp(0.0, 1.0));
    let beta = sb.atan2(cb);
    let theta_full = FRAC_PI_2 - beta;
    let theta_end = FRAC_PI_2 + beta;
    let at = |theta: f64, psi: f64| {
        let (st, ct) = sin_cos(theta);
        let (sp, cp) = sin_cos(psi);
        ct * p - st * (cp * e1 + sp * e2)
    };
    // The other peaks, as (θ, ψ) about p (the pole itself is graded
    // already).
    let others: Vec<(f64, f64)> = below_peaks
        .iter()
        .filter(|q| q.dot(p) < 1.0 - 1e-12)
        .map(|q| {
            let t = q.dot(p).clamp(-1.0, 1.0).acos();
            (t, (-q.dot(e2)).atan2(-q.dot(e1)))
        })
        .collect();
    // The interface's circle cos θo = −c.
    let interface = brdf.interface_eta().and_then(|eta| {
        let c = wi.z / eta;
        (c.is_finite() && c > 0.0 && c < 1.0).then_some(c)
    });
    let mut breaks = vec![0.0, theta_end];
    if theta_full > 0.0 && theta_full < theta_end {
        breaks.push(theta_full);
    }
    for &(t, _) in &others {
        graded_about(t, 0.0, theta_end, &mut breaks);
    }
    if let Some(c) = interface {
        let gamma = c.acos();
        breaks.extend([gamma + beta, gamma - beta, beta - gamma]);
    }
    // The rings where a kink's roots appear, along the great circle through
    // the pole and the vertical (ψ = 0 and ψ = π), as in [`reflected`]:
    // Banks' cone `αi + αo = 90°`, a ring about its fibre.
    let kinks = brdf.kinks(wi);
    for side in [0.0, PI] {
        let along = |theta: f64| {
            let wo = at(theta, side);
            (wo.z < 0.0).then_some(wo)
        };
        outer_kink_roots(&kinks, along, theta_end, &mut breaks);
    }
    for c in &cones {
        c.tangent_rings(theta_end, &mut breaks);
    }
    breaks.retain(|&x| (0.0..=theta_end).contains(&x));
    breaks.sort_by(f64::total_cmp);
    breaks.dedup_by(|a, b| (*a - *b).abs() <= 1e-14);
    let segs = polar_segments(&breaks, theta_full, theta_end);
    let anisotropic = !brdf.claims().isotropic;
    // One side of the plane of incidence, doubled, when the model is
    // symmetric about it (see `reflected`) and p lies in it.
    let half = !anisotropic
        && (p.z <= -1.0 + 1e-12 || in_plane(p.y.atan2(p.x), phi_i))
        && others.iter().all(|&(t, a)| t < 1e-9 || in_plane(a, 0.0))
        && mirror_symmetric(brdf, wi, phi_i, true);
    let inner_tol = 0.2 * opts.abs_tol / theta_end.max(1e-3);
    let mut inner_evals = 0usize;
    let (mut br, mut arcs) = (Vec::new(), Arcs::new(inner_tol, opts.inner_panels));
    let mut outer = |theta: f64| -> (Rgb, Rgb) {
        // The ring's sine and cosine, once: for its arc, its cones, its
        // directions (`at(theta, ·)` takes them from `sin_cos` too) and the
        // Jacobian.
        let (st, ct) = sin_cos(theta);
        // Half-width of the arc about ψ = 0 below the surface, where
        // cos θo = −cos θ cos β − sin θ sin β cos ψ < 0.
        let psi_max = if theta <= theta_full || sb * st <= 0.0 {
            PI
        } else {
            let c0 = -ct * cb / (st * sb);
            if c0 <= -1.0 {
                PI
            } else if c0 >= 1.0 {
                0.0
            } else {
                c0.acos()
            }
        };
        if psi_max <= 0.0 {
            return (Rgb::ZERO, Rgb::ZERO);
        }
        let full = psi_max >= PI;
        let (lo, hi) = (if half { 0.0 } else { -psi_max }, psi_max);
        let outside = |a: f64, b: f64| cones.iter().any(|c| c.outside(st, ct, a, b));
        if outside(lo, hi) {
            return (Rgb::ZERO, Rgb::ZERO);
        }
        let u = ct * p;
        let on_ring = |psi: f64| {
            let (sp, cp) = sin_cos(psi);
            u - st * (cp * e1 + sp * e2)
        };
        br.clear();
        br.extend([lo, 0.0, hi]);
        for &(_, a) in &others {
            let a = wrap_near(a, 0.0);
            if a > lo && a < hi {
                br.push(a);
            }
        }
        if let Some(c) = interface {
            // cos θo = −cos θ cos β − sin θ sin β cos ψ = −c.
            let den = st * sb;
            if den > 0.0 {
                let x = (c - ct * cb) / den;
                if x.abs() < 1.0 {
                    let a = x.acos();
                    for a in [a, -a] {
                        if a > lo && a < hi {
                            br.push(a);
                        }
                    }
                }
            }
        }
        kink_roots(
            &kinks,
            |psi| {
                let wo = on_ring(psi);
                (wo.z < 0.0).then_some(wo)
            },
            no_guess,
            lo,
            hi,
            KINK_SCAN,
            &mut br,
        );
        for c in &cones {
            c.crossings(st, ct, lo, hi, &mut br);
        }
        // A panel's nodes below the surface to the model in one call.
        let mut inner = gauss_kronrod::Batched(|psis: &[f64], out: &mut [(Rgb, Rgb)]| {
            for (psis, out) in psis.chunks(NODES).zip(out.chunks_mut(NODES)) {
                let mut wos = [DVec3::ZERO; NODES];
                let mut at = [0usize; NODES];
                let mut m = 0;
                for (k, &psi) in psis.iter().enumerate() {
                    out[k] = (Rgb::ZERO, Rgb::ZERO);
                    let wo = on_ring(psi);
                    if wo.z >= 0.0 {
                        continue;
                    }
                    wos[m] = wo;
                    at[m] = k;
                    m += 1;
                }
                let mut vals = [Rgb::ZERO; NODES];
                brdf.eval_many(wi, &wos[..m], &mut vals[..m]);
                for j in 0..m {
                    out[at[j]].0 = vals[j] * (-wos[j].z * st);
                }
            }
        });
        let r = arcs.integral_where(&mut inner, &br, full, half, |s| !outside(s.a, s.b));
        inner_evals += r.evaluations;
        (r.value, r.error)
    };
    let mut r = gauss_kronrod::integrate(
        &mut outer,
        &segs,
        opts.abs_tol,
        0.0,
        opts.outer_panels,
        opts.verify,
    );
    r.evaluations = inner_evals;
    r
}

/// ρhd for light from polar angle `theta_i` and azimuth `phi_i` (radians).
pub fn rho_hd(brdf: &dyn Brdf, theta_i: f64, phi_i: f64, opts: &QuadratureOptions) -> Estimate {
    rho_hd_dir(brdf, frame::from_spherical(theta_i, phi_i), opts)
}

/// ρhh `= (1/π) ∫∫ f cos θi cos θo dωi dωo` by quadrature:
/// `∫₀¹ ⟨ρhd⟩_φi ds` with `s = sin² θi` (so `ds = 2 sin θi cos θi dθi`,
/// integrated as `∫₀¹ ⟨ρhd⟩ 2t dt` with `s = 1 − t²`), the
/// φi average by the trapezoid rule for anisotropic models (8 azimuths,
/// doubled up to 64 until two successive averages agree; their difference is
/// added to the error).
pub fn rho_hh(brdf: &dyn Brdf, opts: &QuadratureOptions) -> Estimate {
    let isotropic = brdf.claims().isotropic;
    // Each ρhd to the same tolerance as the whole: their errors average.
    let inner = *opts;
    let mut evaluations = 0;
    let mut converged = true;
    // s = 1 − t²: ρhd may grow like (1 − s)^(−1/4) at grazing (Ward's
    // 1/√cos θi), which 2t dt tames to t^(1/2), and the square-law grading
    // at t = 0 makes polynomial.
    let mut f = |t: f64| -> (Rgb, Rgb) {
        let s = 1.0 - t * t;
        let jac = 2.0 * t;
        let theta = s.clamp(0.0, 1.0).sqrt().asin();
        let mut one = |phi: f64| {
            let e = rho_hd(brdf, theta, phi, &inner);
            evaluations += e.samples;
            converged &= matches!(e.method, Method::Quadrature { converged: true });
            (e.value, e.std_error)
        };
        if isotropic {
            let (v, e) = one(0.0);
            return (v * jac, e * jac);
        }
        // The φi average by the trapezoid rule (spectrally accurate for a
        // smooth periodic function), doubling the azimuths from 8 until two
        // successive averages agree, at most 64.
        let mut values: Vec<(Rgb, Rgb)> = (0..8).map(|k| one(TAU * k as f64 / 8.0)).collect();
        let mean = |v: &[(Rgb, Rgb)]| {
            let n = v.len() as f64;
            let (s, e) = v
                .iter()
                .fold((Rgb::ZERO, Rgb::ZERO), |(s, e), x| (s + x.0, e + x.1));
            (s / n, e / n)
        };
        let mut prev = mean(&values.iter().step_by(2).copied().collect::<Vec<_>>()).0;
        loop {
            let (m, e) = mean(&values);
            let trap = (m - prev).abs();
            let n = values.len();
            if trap.max_element() <= opts.abs_tol || n >= 64 {
                return (m * jac, (e + trap) * jac);
            }
            prev = m;
            // The midpoints of the current azimuths, interleaved.
            let mids: Vec<(Rgb, Rgb)> = (0..n)
                .map(|k| one(TAU * (k as f64 + 0.5) / n as f64))
                .collect();
            values = values
                .into_iter()
                .zip(mids)
                .flat_map(|(a, b)| [a, b])
                .collect();
        }
    };
    let segs = gauss_kronrod::segments(&[0.0, 0.3, 1.0], true, false);
    let r = gauss_kronrod::integrate(&mut f, &segs, 5.0 * opts.abs_tol, 0.0, 20, false);
    quad_estimate(r.value, r.error, evaluations, converged && r.converged)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    #[test]
    fn a_kink_in_a_scan_step_that_ends_below_the_horizon_is_found() {
        // An arc whose end (φ = 1) lies on the horizon, where the direction
        // is `None` as rounding may make it; a kink at φ = 0.95, inside the
        // scan's last step [0.75, 1].
        let dir = |phi: f64| {
            let z = 1.0 - phi;
            (z > 0.0).then(|| DVec3::new((1.0 - z * z).sqrt(), 0.0, z))
        };
        let kinks: Vec<crate::Kink<'_>> = vec![Box::new(|wo: DVec3| wo.z - 0.05)];
        let mut out = Vec::new();
        kink_roots(&kinks, dir, no_guess, 0.0, 1.0, KINK_SCAN, &mut out);
        assert_eq!(out.len(), 1, "{out:?}");
        assert!((out[0] - 0.95).abs() < 1e-10, "{out:?}");
        // And at the arc's start.
        let dir = |phi: f64| {
            let z = phi;
            (z > 0.0).then(|| DVec3::new((1.0 - z * z).sqrt(), 0.0, z))
        };
        let mut out = Vec::new();
        kink_roots(&kinks, dir, no_guess, 0.0, 1.0, KINK_SCAN, &mut out);
        assert_eq!(out.len(), 1, "{out:?}");
        assert!((out[0] - 0.05).abs() < 1e-10, "{out:?}");
    }

    #[test]
    fn a_kink_linear_in_cos_dphi_is_found_in_one_step() {
        // A kink `cos(φ − φi) − 0.3` on a circle (linear in t = cos(φ − φi)),
        // both sides of φi: the scan's looks, then one step per root with
        // the secant in t (the plain regula falsi in φ takes several).
        let phi_i = 0.7;
        let calls = std::cell::Cell::new(0usize);
        let kinks: Vec<crate::Kink<'_>> = vec![Box::new(|wo: DVec3| {
            calls.set(calls.get() + 1);
            wo.x - 0.3
        })];
        let dir = |phi: f64| Some(DVec3::new((phi - phi_i).cos(), (phi - phi_i).sin(), 0.0));
        let mut out = Vec::new();
        let (lo, hi) = (phi_i - 3.0, phi_i + 3.0);
        kink_roots(&kinks, dir, cos_secant(phi_i), lo, hi, KINK_SCAN, &mut out);
        let root = 0.3f64.acos();
        assert_eq!(out.len(), 2, "{out:?}");
        assert!((out[0] - (phi_i - root)).abs() < 1e-12, "{out:?}");
        assert!((out[1] - (phi_i + root)).abs() < 1e-12, "{out:?}");
        // The scan looks at both ends of each step: 2 · KINK_SCAN.
        assert!(calls.get() <= 2 * KINK_SCAN + 2, "{} looks", calls.get());
    }

    /// A uniform direction on the sphere.
    fn sphere_dir(rng: &mut crate::sampling::BvRng) -> DVec3 {
        let u = crate::sampling::uniform2(rng);
        let z = 1.0 - 2.0 * u.x;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (s, c) = (TAU * u.y).sin_cos();
        DVec3::new(r * c, r * s, z)
    }

    /// Every catalogue model that needs no file, at its defaults.
    fn catalogue_at_defaults() -> Vec<(String, Arc<dyn Brdf>)> {
        crate::catalogue()
            .iter()
            .filter(|m| {
                !m.params
                    .iter()
                    .any(|d| matches!(d.kind, crate::params::ParamKind::Path { .. }))
            })
            .map(|m| {
                let b = crate::ModelSpec::new(m.id).unwrap().build().unwrap();
                (m.id.to_string(), Arc::from(b))
            })
            .collect()
    }

    /// The catalogue at its defaults, and the rough dielectric across its
    /// distributions, roughnesses, indices (below and above 1) and
    /// geometries, turned (`Rotated`) and seen from below (`Flipped`).
    fn transmitting_models() -> Vec<(String, Arc<dyn Brdf>)> {
        let mut out = catalogue_at_defaults();
        for p in [
            serde_json::json!({"eta": 1.5}),
            serde_json::json!({"eta": 0.66, "alpha_x": 0.05, "alpha_y": 0.05}),
            serde_json::json!({"eta": 1.02, "alpha_x": 0.8, "alpha_y": 0.8}),
            serde_json::json!({"eta": 4.0, "distribution": "beckmann", "alpha_x": 0.1, "alpha_y": 0.5}),
            serde_json::json!({"eta": 0.2, "geometry": "smith-correlated", "alpha_x": 0.3, "alpha_y": 0.3}),
        ] {
            let b: Arc<dyn Brdf> = crate::ModelSpec::from_json("rough-dielectric", &p)
                .unwrap()
                .build()
                .unwrap()
                .into();
            out.push((format!("rough-dielectric {p}"), b.clone()));
            out.push((
                format!("rotated {p}"),
                Arc::new(crate::rotated::Rotated::new(b, 0.7)),
            ));
        }
        out
    }

    #[test]
    fn f_is_zero_outside_every_cone_a_model_names_for_its_transmission() {
        // `transmission_support` is a claim the quadrature relies on without
        // looking: it skips what lies outside. Every model's cones against
        // `eval` at random pairs across the surface (and through Flipped,
        // the quadrature's view of light from below), and the cones must
        // cut something for the rough dielectric (else this proves nothing).
        let mut rng = crate::sampling::rng(11);
        for (name, b) in transmitting_models() {
            let flipped = Flipped(b.as_ref());
            for (view, m) in [("", b.as_ref()), (" flipped", &flipped as &dyn Brdf)] {
                let (mut cut, mut nonzero) = (0, 0);
                for _ in 0..300 {
                    let wi = sphere_dir(&mut rng);
                    let cones = m.transmission_support(wi);
                    for _ in 0..40 {
                        let mut wo = sphere_dir(&mut rng);
                        if wo.z * wi.z > 0.0 {
                            wo.z = -wo.z;
                        }
                        let f = m.eval(wi, wo);
                        nonzero += usize::from(f != Rgb::ZERO);
                        if cones.iter().any(|c| wo.dot(c.axis) <= c.cos_half) {
                            cut += 1;
                            assert_eq!(f, Rgb::ZERO, "{name}{view}: wi {wi} wo {wo} {cones:?}");
                        }
                    }
                }
                if name.starts_with("rough") || name.starts_with("rotated") {
                    assert!(
                        cut > 1000 && nonzero > 50,
                        "{name}{view}: {cut} cut, {nonzero} non-zero"
                    );
                }
            }
        }
    }

    /// `b` without its [`Brdf::transmission_support`], as the quadrature
    /// sees it otherwise.
    #[derive(Debug)]
    struct NoSupport<'a>(&'a dyn Brdf);

    impl Brdf for NoSupport<'_> {
        fn id(&self) -> &'static str {
            self.0.id()
        }
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            self.0.eval(wi, wo)
        }
        fn eval_with_half(&self, wi: DVec3, wo: DVec3, h: DVec3) -> Rgb {
            self.0.eval_with_half(wi, wo, h)
        }
        fn claims(&self) -> crate::Claims {
            self.0.claims()
        }
        fn transmits(&self) -> bool {
            self.0.transmits()
        }
        fn interface_eta(&self) -> Option<f64> {
            self.0.interface_eta()
        }
        fn deltas(&self, wi: DVec3) -> Vec<crate::DeltaLobe> {
            self.0.deltas(wi)
        }
        fn peaks(&self, wi: DVec3) -> Vec<DVec3> {
            self.0.peaks(wi)
        }
        fn pole(&self, wi: DVec3) -> Option<DVec3> {
            self.0.pole(wi)
        }
        fn kinks(&self, wi: DVec3) -> Vec<crate::Kink<'_>> {
            self.0.kinks(wi)
        }
    }

    #[test]
    fn a_transmission_support_spares_evaluations_and_keeps_the_value() {
        // The same albedo within the two stated errors with and without
        // the cones, from both sides and at grazing light, in fewer
        // evaluations (at least a fifth fewer over the set).
        let opts = QuadratureOptions::default();
        let (mut with, mut without) = (0, 0);
        for (name, b) in transmitting_models() {
            if !(name.starts_with("rough") || name.starts_with("rotated")) {
                continue;
            }
            for (t, phi) in [(0.0, 0.0), (0.6, 0.3), (1.2, 2.0), (1.55, -1.0)] {
                for side in [1.0, -1.0] {
                    let (st, ct) = f64::sin_cos(t);
                    let wi = DVec3::new(st * f64::cos(phi), st * f64::sin(phi), side * ct);
                    let a = rho_hd_dir(b.as_ref(), wi, &opts);
                    let c = rho_hd_dir(&NoSupport(b.as_ref()), wi, &opts);
                    let d = (a.value - c.value).abs().max_element();
                    let e = (a.std_error + c.std_error).max_element();
                    assert!(
                        d <= e,
                        "{name} wi {wi}: {} vs {} ({d:e} > {e:e})",
                        a.value,
                        c.value
                    );
                    with += a.samples;
                    without += c.samples;
                }
            }
        }
        assert!(
            5 * with < 4 * without,
            "{with} evaluations with the cones, {without} without"
        );
    }

    #[test]
    fn every_model_evaluates_many_pairs_as_it_evaluates_one() {
        // The quadrature's inner integrands call `eval_many` and
        // `eval_many_with_half` per panel; a model that overrides them must
        // return what `eval` and `eval_with_half` return, bit for bit (the
        // curves' values and errors were compared so when the calls were
        // batched). Every catalogue model at its defaults, and the rough
        // dielectric (which overrides both) in each of its distributions and
        // geometries, turned and seen from below; pairs on the whole sphere
        // (the transmitted part's below the surface).
        let mut rng = crate::sampling::rng(7);
        let mut sphere = || sphere_dir(&mut rng);
        for (id, b) in transmitting_models() {
            for _ in 0..8 {
                let wi = sphere();
                let wos: Vec<DVec3> = (0..15).map(|_| sphere()).collect();
                let hs: Vec<DVec3> = wos.iter().map(|&wo| (wi + wo).normalize()).collect();
                let mut many = vec![Rgb::ZERO; 15];
                b.eval_many(wi, &wos, &mut many);
                let mut half = vec![Rgb::ZERO; 15];
                b.eval_many_with_half(wi, &wos, &hs, &mut half);
                for k in 0..15 {
                    let same = |a: Rgb, b: Rgb| {
                        a.to_array().map(f64::to_bits) == b.to_array().map(f64::to_bits)
                    };
                    assert!(same(many[k], b.eval(wi, wos[k])), "{} eval_many at {k}", id);
                    assert!(
                        same(half[k], b.eval_with_half(wi, wos[k], hs[k])),
                        "{} eval_many_with_half at {k}",
                        id
                    );
                }
            }
        }
    }

    #[test]
    fn sin_cos_matches_std() {
        // Every quadrant, the octant edges (where the reduction switches),
        // multiples of π/2 (where r cancels), tiny and large arguments.
        let mut xs: Vec<f64> = (-40_000..=40_000).map(|k| k as f64 * 2.5e-4).collect();
        for k in -64..=64 {
            let q = k as f64 * FRAC_PI_2;
            xs.extend([q, q.next_up(), q.next_down(), q + 1e-9, q - 1e-9]);
            xs.push(k as f64 * std::f64::consts::FRAC_PI_4);
        }
        xs.extend([
            0.0, -0.0, 1e-300, 1e-8, 12_345.678, -99_999.9, 1e5, 3e5, 1e20,
        ]);
        for x in xs {
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            assert!(
                (s - s0).abs() <= 4e-16 && (c - c0).abs() <= 4e-16,
                "x = {x:e}: ({s:e}, {c:e}) vs ({s0:e}, {c0:e})"
            );
        }
        let (s, c) = sin_cos(f64::NAN);
        assert!(s.is_nan() && c.is_nan());
    }
}
