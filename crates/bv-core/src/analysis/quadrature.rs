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
//! error. Transmitting models add the lower hemisphere in `(cos θo, φo)`.
//! Delta lobes add their exact weights.

use super::directions::below;
use super::estimate::{AlbedoParts, Estimate, Method};
use super::gauss_kronrod::{self, Segment};
use crate::{Brdf, DeltaKind, Rgb, frame};
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
    /// Verify the outer (θh) axis by one more bisection of every panel
    /// (default on; see [`gauss_kronrod::integrate`]): honest errors across
    /// kinks in θh (Cook-Torrance's V-groove G at `θh = 30°` for normal
    /// incidence), at twice the work.
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
    let upper = reflected(brdf, wi, cos_ti, sin_ti, theta_i, phi_i, opts);
    let reflected = quad_estimate(
        upper.value + delta_r,
        upper.error,
        upper.evaluations,
        upper.converged,
    );
    let transmitted = if transmits {
        let lower = transmitted(brdf, wi, opts);
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
    let mut segs = Vec::with_capacity(breaks.len());
    for w in breaks.windows(2) {
        let (a, b) = (w[0], w[1]);
        let start = a == 0.0 || (a == theta_full && theta_full > 0.0);
        let end = b == theta_end;
        let grading = match (start, end) {
            (true, true) => gauss_kronrod::Grading::Both,
            (true, false) => gauss_kronrod::Grading::Start,
            (false, true) => gauss_kronrod::Grading::End,
            (false, false) => gauss_kronrod::Grading::Linear,
        };
        segs.push(Segment { a, b, grading });
    }
    let anisotropic = !brdf.claims().isotropic;
    let mut fixed_phis: Vec<f64> = Vec::new();
    if anisotropic {
        fixed_phis.extend([0.0, FRAC_PI_2, PI, -FRAC_PI_2]);
    }
    fixed_phis.extend(peaks.iter().map(|&(_, p)| p));
    let inner_tol = 0.2 * opts.abs_tol / theta_end.max(1e-3);
    let mut inner_evals = 0usize;
    let mut outer = |theta_h: f64| -> (Rgb, Rgb) {
        let psi = arc_half_width(cos_ti, sin_ti, theta_h);
        if psi <= 0.0 {
            return (Rgb::ZERO, Rgb::ZERO);
        }
        let (sh, ch) = theta_h.sin_cos();
        let mut inner = |phi: f64| -> (Rgb, Rgb) {
            let (sp, cp) = phi.sin_cos();
            let h = DVec3::new(sh * cp, sh * sp, ch);
            let c = wi.dot(h);
            let wo = 2.0 * c * h - wi;
            if wo.z <= 0.0 || c <= 0.0 {
                return (Rgb::ZERO, Rgb::ZERO);
            }
            let wo = wo.normalize();
            (brdf.eval(wi, wo) * (wo.z * 4.0 * c * sh), Rgb::ZERO)
        };
        let full = psi >= PI;
        let (lo, hi) = (phi_i - psi, phi_i + psi);
        let mut br = vec![lo, phi_i, hi];
        for &p in &fixed_phis {
            let p = wrap_near(p, phi_i);
            if p > lo && p < hi {
                br.push(p);
            }
        }
        let segs = gauss_kronrod::segments(&br, !full, !full);
        let r =
            gauss_kronrod::integrate(&mut inner, &segs, inner_tol, 0.0, opts.inner_panels, false);
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

/// The transmitted part, over the polar angle `θ'` of `wo` from −z and its
/// azimuth φo: `wo = (sin θ' cos φo, sin θ' sin φo, −cos θ')`,
/// `∫∫ f cos θ' sin θ' dφo dθ'`. θ' is graded geometrically (down to
/// [`FINEST`]) about each peak the model names below the surface
/// ([`Brdf::peaks`]: a rough dielectric's refracted direction) and φo about
/// the peak's azimuth, as the reflected part is graded about its peaks, so a
/// lobe as narrow as α = 0.001 is resolved; a peak at the pole is a cap that
/// the grading at θ' = 0 resolves. For a model of an interface
/// ([`Brdf::interface_eta`]) θ' also breaks where the generalised half
/// vector `ηi wi + ηo wo` of Walter et al. 2007 (eq. 16) turns horizontal,
/// `cos θ' = ηi cos θi / ηo`: a microfacet BTDF whose D does not vanish at
/// the horizon (GGX) drops to 0 across that circle, and a panel edge there
/// keeps the rule's error estimate honest.
fn transmitted(
    brdf: &dyn Brdf,
    wi: DVec3,
    opts: &QuadratureOptions,
) -> gauss_kronrod::Integral<Rgb> {
    let peaks: Vec<(f64, f64)> = brdf
        .peaks(wi)
        .into_iter()
        .filter(|p| p.is_finite() && p.z < 0.0)
        .filter_map(|p| {
            let p = p.try_normalize()?;
            Some(((-p.z).clamp(-1.0, 1.0).acos(), p.y.atan2(p.x)))
        })
        .collect();
    let mut breaks = vec![0.0, FRAC_PI_2];
    for &(t, _) in &peaks {
        graded_about(t, 0.0, FRAC_PI_2, &mut breaks);
    }
    if let Some(eta) = brdf.interface_eta() {
        // wi is above here: ηi = 1, ηo = η.
        let c = wi.z / eta;
        if c.is_finite() && c > 0.0 && c < 1.0 {
            breaks.push(c.acos());
        }
    }
    breaks.retain(|&x| (0.0..=FRAC_PI_2).contains(&x));
    breaks.sort_by(f64::total_cmp);
    breaks.dedup_by(|a, b| (*a - *b).abs() <= 1e-14);
    let mut segs = Vec::with_capacity(breaks.len());
    let last = breaks.len().saturating_sub(2);
    for (k, w) in breaks.windows(2).enumerate() {
        let grading = match (k == 0, k == last) {
            (true, true) => gauss_kronrod::Grading::Both,
            (true, false) => gauss_kronrod::Grading::Start,
            (false, true) => gauss_kronrod::Grading::End,
            (false, false) => gauss_kronrod::Grading::Linear,
        };
        segs.push(Segment {
            a: w[0],
            b: w[1],
            grading,
        });
    }
    let anisotropic = !brdf.claims().isotropic;
    // The azimuth the inner integrals centre on: the peak's, or wi's
    // opposite (where a refracted lobe lies).
    let phi_c = peaks.first().map_or(wi.y.atan2(wi.x) + PI, |&(_, p)| p);
    // Breaks at the peaks' azimuths (and the tangent axes of an anisotropic
    // model), the panels on either side of φc graded towards it (their first
    // Kronrod nodes lie within 1e-4 rad of it, inside any lobe of α ≥ 0.001),
    // the rest left to bisection, as the reflected part's are.
    let mut phi_breaks = vec![phi_c - PI, phi_c, phi_c + PI];
    for &(_, p) in peaks.iter().skip(1) {
        phi_breaks.push(wrap_near(p, phi_c));
    }
    if anisotropic {
        for a in [0.0, FRAC_PI_2, PI, -FRAC_PI_2] {
            phi_breaks.push(wrap_near(a, phi_c));
        }
    }
    phi_breaks.retain(|&x| x >= phi_c - PI && x <= phi_c + PI);
    phi_breaks.sort_by(f64::total_cmp);
    phi_breaks.dedup_by(|a, b| (*a - *b).abs() <= 1e-12);
    let inner_segs: Vec<Segment> = phi_breaks
        .windows(2)
        .map(|w| Segment {
            a: w[0],
            b: w[1],
            grading: if w[1] == phi_c {
                gauss_kronrod::Grading::End
            } else if w[0] == phi_c {
                gauss_kronrod::Grading::Start
            } else {
                gauss_kronrod::Grading::Linear
            },
        })
        .collect();
    let inner_tol = 0.2 * opts.abs_tol / FRAC_PI_2;
    let mut inner_evals = 0usize;
    let mut outer = |theta: f64| -> (Rgb, Rgb) {
        let (st, ct) = theta.sin_cos();
        if ct <= 0.0 {
            return (Rgb::ZERO, Rgb::ZERO);
        }
        let mut inner = |phi: f64| -> (Rgb, Rgb) {
            let (sp, cp) = phi.sin_cos();
            let wo = DVec3::new(st * cp, st * sp, -ct);
            (brdf.eval(wi, wo) * (ct * st), Rgb::ZERO)
        };
        let r = gauss_kronrod::integrate(
            &mut inner,
            &inner_segs,
            inner_tol,
            0.0,
            opts.inner_panels,
            false,
        );
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
