//! Real spherical harmonics up to order 16, and the projection of a BRDF lobe
//! onto them.
//!
//! The lobe `g(wo) = f(wi, wo)` (times `cos θo` on request) at a fixed `wi` is
//! a function on the outgoing hemisphere; it is extended by 0 to the sphere
//! (reflection models) and projected, `c_lm = ∫ g Y_lm dω`, then rebuilt as
//! `ĝ = Σ_{l ≤ L} c_lm Y_lm`. The lecturer's point: ĝ is the best L2
//! approximation of order L, and a sharp lobe of angular width σ needs
//! `L ≳ 1/σ`: its high frequencies are lost. Even Lambert is not band-limited
//! here, because the extension by 0 jumps at the horizon (and with the cosine
//! factor it still has a kink there); its coefficients decay slowly and the
//! rebuilt lobe rings (Gibbs).
//!
//! Basis: orthonormal real SH without the Condon–Shortley phase,
//! `Y_l0 = K_l0 P_l(z)`, `Y_lm = √2 K_lm P_l^m(z) cos mφ`,
//! `Y_l,−m = √2 K_lm P_l^m(z) sin mφ` (m > 0). Index `l(l + 1) + m`.

use crate::quadrature::gauss_legendre;
use crate::{Brdf, BvError, Result, Rgb, mean_rgb};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Highest order supported.
pub const MAX_ORDER: usize = 16;
/// Most quadrature rings accepted.
pub const MAX_RINGS: usize = 1024;

/// Number of coefficients of an order-`order` expansion, `(L + 1)²`.
pub const fn num_coeffs(order: usize) -> usize {
    (order + 1) * (order + 1)
}

/// Evaluates all real SH of order ≤ `order` at the unit direction `w` into
/// `out[..num_coeffs(order)]`.
///
/// Stable recurrences on normalised associated Legendre functions with the
/// `sin^m θ` factor taken out (so nothing is divided by sin θ and nothing
/// grows like a factorial): `P̄_mm = √((2m+1)/(2m)) P̄_{m−1,m−1}`,
/// `P̄_{m+1,m} = √(2m+3) z P̄_mm`,
/// `P̄_lm = a_lm (z P̄_{l−1,m} − b_lm P̄_{l−2,m})` with
/// `a_lm = √((4l² − 1)/(l² − m²))`, `b_lm = √(((l−1)² − m²)/(4(l−1)² − 1))`;
/// `sin^m θ (cos mφ, sin mφ)` is `(x + iy)^m`, built by complex multiplication.
///
/// # Panics
/// If `out` is shorter than `num_coeffs(order)` (a programming error).
pub fn eval_basis(order: usize, w: DVec3, out: &mut [f64]) {
    let (x, y, z) = (w.x, w.y, w.z);
    let mut pmm = 0.5 / PI.sqrt(); // Y_00 = 1/(2√π)
    let (mut cm, mut sm) = (1.0f64, 0.0f64); // (x + iy)^m
    let sqrt2 = std::f64::consts::SQRT_2;
    for m in 0..=order {
        if m > 0 {
            let mf = m as f64;
            pmm *= ((2.0 * mf + 1.0) / (2.0 * mf)).sqrt();
            (cm, sm) = (cm * x - sm * y, cm * y + sm * x);
        }
        let mut set = |l: usize, p: f64| {
            let base = l * (l + 1);
            if m == 0 {
                out[base] = p;
            } else {
                out[base + m] = sqrt2 * p * cm;
                out[base - m] = sqrt2 * p * sm;
            }
        };
        set(m, pmm);
        if m == order {
            break;
        }
        let mut p0 = pmm;
        let mut p1 = z * (2.0 * m as f64 + 3.0).sqrt() * pmm;
        set(m + 1, p1);
        for l in m + 2..=order {
            let (lf, mf) = (l as f64, m as f64);
            let a = ((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf)).sqrt();
            let b = (((lf - 1.0) * (lf - 1.0) - mf * mf) / (4.0 * (lf - 1.0) * (lf - 1.0) - 1.0))
                .sqrt();
            let p2 = a * (z * p1 - b * p0);
            set(l, p2);
            p0 = p1;
            p1 = p2;
        }
    }
}

/// Where a lobe lives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Domain {
    /// The outgoing hemisphere `z > 0` (reflection); 0 below.
    Hemisphere,
    /// The whole sphere (transmitting models).
    Sphere,
}

/// A quadrature over a domain: `n_theta` Gauss–Legendre rings in `z = cos θ`
/// times `2 n_theta` equally spaced azimuths (exact for band-limited
/// integrands of degree below `2 n_theta` on the sphere).
#[derive(Debug, Clone)]
struct Quadrature {
    rings: Vec<(f64, f64)>, // (z, weight including the φ step)
    n_phi: usize,
}

impl Quadrature {
    fn new(domain: Domain, n_theta: usize) -> Self {
        let n_phi = 2 * n_theta;
        let dphi = 2.0 * PI / n_phi as f64;
        let (lo, hi) = match domain {
            Domain::Hemisphere => (0.0, 1.0),
            Domain::Sphere => (-1.0, 1.0),
        };
        let half = 0.5 * (hi - lo);
        let rings = gauss_legendre(n_theta)
            .into_iter()
            .map(|(x, w)| (lo + half * (x + 1.0), w * half * dphi))
            .collect();
        Self { rings, n_phi }
    }

    fn direction(&self, z: f64, j: usize) -> DVec3 {
        let s = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * (j as f64 + 0.5) / self.n_phi as f64;
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    }
}

/// A lobe projected onto real SH of order ≤ `order`.
#[derive(Debug, Clone, PartialEq)]
pub struct ShLobe {
    /// Highest order L.
    pub order: usize,
    /// `c_lm` per channel, index `l(l + 1) + m`.
    pub coeffs: Vec<Rgb>,
    /// The domain the lobe was defined on (and the error measured over).
    pub domain: Domain,
    /// Relative L2 error of the reconstruction over the domain, on the channel
    /// mean: `‖ĝ − g‖ / ‖g‖` (0 for a lobe that vanishes).
    pub rel_l2_error: f64,
    /// Quadrature rings used (`2×` as many azimuths).
    pub n_theta: usize,
}

impl ShLobe {
    /// The reconstruction `ĝ(w) = Σ c_lm Y_lm(w)` of what was projected (`f`,
    /// or `f cos θo` when projected with the cosine). May be negative where
    /// the truncation rings.
    pub fn eval(&self, w: DVec3) -> Rgb {
        let mut y = [0.0f64; num_coeffs(MAX_ORDER)];
        eval_basis(self.order, w, &mut y);
        self.coeffs
            .iter()
            .zip(&y)
            .fold(Rgb::ZERO, |acc, (c, &b)| acc + *c * b)
    }

    /// Energy per band `Σ_m |c_lm|²` on the channel mean, l = 0..=L: how a
    /// lecturer shows where a lobe's frequencies lie.
    pub fn band_energy(&self) -> Vec<f64> {
        (0..=self.order)
            .map(|l| {
                (l * l..(l + 1) * (l + 1))
                    .map(|i| mean_rgb(self.coeffs[i]).powi(2))
                    .sum()
            })
            .collect()
    }
}

fn check_args(order: usize, n_theta: usize) -> Result<usize> {
    if order > MAX_ORDER {
        return Err(BvError::Invalid(format!(
            "SH order {order} is above the supported {MAX_ORDER}"
        )));
    }
    if n_theta > MAX_RINGS {
        return Err(BvError::Invalid(format!(
            "{n_theta} quadrature rings requested; at most {MAX_RINGS}"
        )));
    }
    // Fewer rings than L + 1 cannot even integrate the basis exactly.
    Ok(n_theta.max(order + 1))
}

/// Projects an arbitrary function on `domain` (0 outside it) onto SH of order
/// ≤ `order` with `n_theta` quadrature rings, and measures the relative L2
/// error of the reconstruction over the domain with the same quadrature.
/// Non-finite values of `g` count as 0.
pub fn project_fn(
    g: impl Fn(DVec3) -> Rgb + Sync,
    domain: Domain,
    order: usize,
    n_theta: usize,
) -> Result<ShLobe> {
    let mut job = ProjectJob::new(domain, order, n_theta)?;
    loop {
        if let Some(lobe) = job.step(&g, usize::MAX) {
            return Ok(lobe);
        }
    }
}

/// [`project_fn`] in steps of a bounded number of quadrature rings, for a
/// caller that cannot block for the whole projection (a browser page
/// without threads runs a few steps per frame). The rings of one step are
/// summed in parallel and the steps' sums added up; the result differs from
/// the one-shot projection only by the order of the additions.
#[derive(Debug, Clone)]
pub struct ProjectJob {
    q: Quadrature,
    order: usize,
    domain: Domain,
    /// Rings done: the coefficients' pass, then as many again for the error.
    rings_done: usize,
    coeffs: Vec<Rgb>,
    /// The squared error and the squared norm summed so far.
    err: (f64, f64),
}

impl ProjectJob {
    /// A job for [`project_fn`]`(·, domain, order, n_theta)`; the order and
    /// ring count are checked here.
    pub fn new(domain: Domain, order: usize, n_theta: usize) -> Result<Self> {
        let n_theta = check_args(order, n_theta)?;
        Ok(Self {
            q: Quadrature::new(domain, n_theta),
            order,
            domain,
            rings_done: 0,
            coeffs: vec![Rgb::ZERO; num_coeffs(order)],
            err: (0.0, 0.0),
        })
    }

    /// The job of [`project`]`(brdf, ·, order, ·, n_theta)`: its steps take
    /// [`lobe_fn`]`(brdf, wi, cosine)`.
    pub fn for_brdf(brdf: &dyn Brdf, order: usize, n_theta: usize) -> Result<Self> {
        Self::new(brdf_domain(brdf), order, n_theta)
    }

    /// The share of the work done, in `[0, 1]`.
    pub fn progress(&self) -> f64 {
        self.rings_done as f64 / (2 * self.q.rings.len()) as f64
    }

    /// Sums `g` over the next `rings` quadrature rings (at least one) and
    /// returns the projection once both passes are done. `g` must be the same
    /// function at every step.
    pub fn step(&mut self, g: &(impl Fn(DVec3) -> Rgb + Sync), rings: usize) -> Option<ShLobe> {
        let n = self.q.rings.len();
        let nc = num_coeffs(self.order);
        let order = self.order;
        let q = &self.q;
        let sample = |w: DVec3| {
            let v = g(w);
            if v.is_finite() { v } else { Rgb::ZERO }
        };
        if self.rings_done < n {
            // Pass 1: coefficients, one partial sum per ring, in parallel.
            let end = self.rings_done.saturating_add(rings.max(1)).min(n);
            let part = q.rings[self.rings_done..end]
                .par_iter()
                .map(|&(z, wt)| {
                    let mut acc = vec![Rgb::ZERO; nc];
                    let mut y = [0.0f64; num_coeffs(MAX_ORDER)];
                    for j in 0..q.n_phi {
                        let w = q.direction(z, j);
                        let v = sample(w) * wt;
                        eval_basis(order, w, &mut y);
                        for (a, &b) in acc.iter_mut().zip(&y[..nc]) {
                            *a += v * b;
                        }
                    }
                    acc
                })
                .reduce(
                    || vec![Rgb::ZERO; nc],
                    |mut a, b| {
                        for (x, y) in a.iter_mut().zip(b) {
                            *x += y;
                        }
                        a
                    },
                );
            for (x, y) in self.coeffs.iter_mut().zip(part) {
                *x += y;
            }
            self.rings_done = end;
            return None;
        }
        // Pass 2: error over the domain.
        let mut lobe = ShLobe {
            order,
            coeffs: self.coeffs.clone(),
            domain: self.domain,
            rel_l2_error: 0.0,
            n_theta: n,
        };
        let r0 = self.rings_done - n;
        let end = r0.saturating_add(rings.max(1)).min(n);
        let (e, nn) = q.rings[r0..end]
            .par_iter()
            .map(|&(z, wt)| {
                let (mut e, mut n) = (0.0, 0.0);
                for j in 0..q.n_phi {
                    let w = q.direction(z, j);
                    let v = mean_rgb(sample(w));
                    let r = mean_rgb(lobe.eval(w));
                    e += wt * (r - v) * (r - v);
                    n += wt * v * v;
                }
                (e, n)
            })
            .reduce(|| (0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
        self.err.0 += e;
        self.err.1 += nn;
        self.rings_done = n + end;
        if end < n {
            return None;
        }
        let (err2, norm2) = self.err;
        lobe.rel_l2_error = if norm2 > 0.0 {
            (err2 / norm2).sqrt()
        } else {
            0.0
        };
        Some(lobe)
    }
}

/// The function [`project`] projects: `f(wi, ·)`, or `f(wi, ·) cos θo` when
/// `cosine` (for [`ProjectJob::step`]).
pub fn lobe_fn(brdf: &dyn Brdf, wi: DVec3, cosine: bool) -> impl Fn(DVec3) -> Rgb + Sync + '_ {
    move |wo| lobe_value(brdf, wi, wo, cosine)
}

/// The hemisphere, or the sphere for a transmitting model.
fn brdf_domain(brdf: &dyn Brdf) -> Domain {
    if brdf.transmits() {
        Domain::Sphere
    } else {
        Domain::Hemisphere
    }
}

/// The lobe of `brdf` at `wi` (`f`, or `f cos θo` when `cosine`), projected
/// onto SH of order ≤ `order` (0–16) with `n_theta` quadrature rings. The
/// domain is the hemisphere, or the sphere for a transmitting model.
pub fn project(
    brdf: &dyn Brdf,
    wi: DVec3,
    order: usize,
    cosine: bool,
    n_theta: usize,
) -> Result<ShLobe> {
    project_fn(lobe_fn(brdf, wi, cosine), brdf_domain(brdf), order, n_theta)
}

fn lobe_value(brdf: &dyn Brdf, wi: DVec3, wo: DVec3, cosine: bool) -> Rgb {
    let f = brdf.eval(wi, wo);
    if cosine { f * wo.z.abs() } else { f }
}

/// Relative L2 difference `‖a − b‖ / ‖b‖` of two lobes at `wi` over the
/// hemisphere (the sphere if `b` transmits), on the channel mean: e.g. a
/// tabulated model `a` against the analytic model `b` it came from.
pub fn relative_l2(
    a: &dyn Brdf,
    b: &dyn Brdf,
    wi: DVec3,
    cosine: bool,
    n_theta: usize,
) -> Result<f64> {
    let n_theta = check_args(0, n_theta)?;
    let domain = if b.transmits() || a.transmits() {
        Domain::Sphere
    } else {
        Domain::Hemisphere
    };
    let q = Quadrature::new(domain, n_theta);
    let (e, n) = q
        .rings
        .par_iter()
        .map(|&(z, wt)| {
            let (mut e, mut n) = (0.0, 0.0);
            for j in 0..q.n_phi {
                let w = q.direction(z, j);
                let va = mean_rgb(lobe_value(a, wi, w, cosine));
                let vb = mean_rgb(lobe_value(b, wi, w, cosine));
                if va.is_finite() && vb.is_finite() {
                    e += wt * (va - vb) * (va - vb);
                    n += wt * vb * vb;
                }
            }
            (e, n)
        })
        .reduce(|| (0.0, 0.0), |x, y| (x.0 + y.0, x.1 + y.1));
    Ok(if n > 0.0 { (e / n).sqrt() } else { 0.0 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::lambert::Lambert;
    use crate::{Claims, frame};

    fn basis(order: usize, w: DVec3) -> Vec<f64> {
        let mut y = vec![0.0; num_coeffs(order)];
        eval_basis(order, w, &mut y);
        y
    }

    #[test]
    fn a_projection_in_steps_of_one_ring_is_the_one_shot_projection() {
        // A lobe with a peak: x³-weighted cosine power; any smooth g will do,
        // the sums are the same ones in another order.
        let g = |w: DVec3| Rgb::new(w.z.max(0.0).powi(8), (w.x * w.z).abs(), 0.3);
        let once = project_fn(g, Domain::Hemisphere, 6, 24).unwrap();
        let mut job = ProjectJob::new(Domain::Hemisphere, 6, 24).unwrap();
        let mut steps = 0;
        let stepped = loop {
            steps += 1;
            assert!(job.progress() < 1.0 || steps > 48);
            if let Some(l) = job.step(&g, 1) {
                break l;
            }
        };
        // One ring a step: both passes over 24 rings.
        assert_eq!(steps, 48);
        assert_eq!((stepped.order, stepped.n_theta), (once.order, once.n_theta));
        for (a, b) in stepped.coeffs.iter().zip(&once.coeffs) {
            assert!((*a - *b).abs().max_element() < 1e-12, "{a:?} vs {b:?}");
        }
        assert!((stepped.rel_l2_error - once.rel_l2_error).abs() < 1e-12);
        // And Lambert's ρ/π projects onto Y00 alone over the sphere: the
        // closed form c00 = 2√π ρ/π, independent of how the work is cut.
        let lambert = |_: DVec3| Rgb::splat(0.5 / PI);
        let mut job = ProjectJob::new(Domain::Sphere, 2, 8).unwrap();
        let l = loop {
            if let Some(l) = job.step(&lambert, 3) {
                break l;
            }
        };
        assert!((l.coeffs[0].x - 2.0 * PI.sqrt() * 0.5 / PI).abs() < 1e-12);
        assert!(l.coeffs[1..].iter().all(|c| c.abs().max_element() < 1e-12));
    }

    #[test]
    fn low_order_basis_by_hand() {
        // Closed forms (e.g. Sloan 2008, "Stupid SH tricks", without the
        // Condon–Shortley sign): Y00 = 1/(2√π), Y1,{−1,0,1} = √(3/4π)(y, z, x),
        // Y20 = √(5/16π)(3z² − 1), Y2,2 = √(15/16π)(x² − y²), Y2,−2 = √(15/4π) xy,
        // Y2,1 = √(15/4π) xz, Y2,−1 = √(15/4π) yz.
        let w = DVec3::new(0.3, -0.4, 0.2).normalize();
        let (x, y, z) = (w.x, w.y, w.z);
        let c1 = (3.0 / (4.0 * PI)).sqrt();
        let c2 = (15.0 / (4.0 * PI)).sqrt();
        let want = [
            0.5 / PI.sqrt(),
            c1 * y,
            c1 * z,
            c1 * x,
            c2 * x * y,
            c2 * y * z,
            (5.0 / (16.0 * PI)).sqrt() * (3.0 * z * z - 1.0),
            c2 * x * z,
            (15.0 / (16.0 * PI)).sqrt() * (x * x - y * y),
        ];
        let got = basis(2, w);
        for (i, (a, b)) in got.iter().zip(want).enumerate() {
            assert!((a - b).abs() < 1e-14, "{i}: {a} vs {b}");
        }
    }

    #[test]
    fn basis_is_orthonormal_up_to_order_16() {
        let q = Quadrature::new(Domain::Sphere, MAX_ORDER + 2);
        let nc = num_coeffs(MAX_ORDER);
        let mut gram = vec![0.0f64; nc * nc];
        let mut y = vec![0.0; nc];
        for &(z, wt) in &q.rings {
            for j in 0..q.n_phi {
                eval_basis(MAX_ORDER, q.direction(z, j), &mut y);
                for a in 0..nc {
                    for b in 0..nc {
                        gram[a * nc + b] += wt * y[a] * y[b];
                    }
                }
            }
        }
        for a in 0..nc {
            for b in 0..nc {
                let want = if a == b { 1.0 } else { 0.0 };
                assert!((gram[a * nc + b] - want).abs() < 1e-11, "{a} {b}");
            }
        }
    }

    /// A transmitting test BRDF whose lobe is a given function on the sphere.
    #[derive(Debug)]
    struct SphereFn(fn(DVec3) -> f64);
    impl Brdf for SphereFn {
        fn id(&self) -> &'static str {
            "sphere-fn-test"
        }
        fn eval(&self, _wi: DVec3, wo: DVec3) -> Rgb {
            Rgb::splat((self.0)(wo))
        }
        fn claims(&self) -> Claims {
            Claims {
                reciprocal: false,
                energy_conserving: false,
                isotropic: false,
            }
        }
        fn transmits(&self) -> bool {
            true
        }
    }

    #[test]
    fn a_low_order_sh_function_is_reproduced() {
        // g = 1 + 0.5 z + 0.3 xy = 2√π Y00 + 0.5√(4π/3) Y10 + 0.3√(4π/15) Y2,−2.
        let b = SphereFn(|w| 1.0 + 0.5 * w.z + 0.3 * w.x * w.y);
        for order in [2usize, 5, 16] {
            let lobe = project(&b, DVec3::Z, order, false, 24).unwrap();
            assert_eq!(lobe.domain, Domain::Sphere);
            let mut want = vec![0.0; num_coeffs(order)];
            want[0] = 2.0 * PI.sqrt();
            want[2] = 0.5 * (4.0 * PI / 3.0).sqrt();
            want[4] = 0.3 * (4.0 * PI / 15.0).sqrt();
            for (i, (c, w)) in lobe.coeffs.iter().zip(&want).enumerate() {
                assert!((c.x - w).abs() < 1e-12, "L={order} i={i}: {} vs {w}", c.x);
            }
            assert!(lobe.rel_l2_error < 1e-12, "{}", lobe.rel_l2_error);
            let w = DVec3::new(0.48, 0.6, 0.64);
            assert!((lobe.eval(w).x - (1.0 + 0.32 + 0.3 * 0.288)).abs() < 1e-12);
        }
    }

    #[test]
    fn lambert_coefficients_match_legendre_integrals() {
        // g = ρ/π on the hemisphere (0 below), zonal: c_l0 = (ρ/π) 2π √((2l+1)/4π)
        // ∫₀¹ P_l dx, with ∫₀¹ P_l = 1, 1/2, 0, −1/8 for l = 0..3. With the
        // cosine, ∫₀¹ x P_l = 1/2, 1/3, 1/8, 0, −1/48 (Ramamoorthi & Hanrahan
        // 2001's clamped cosine: A0 = π, A1 = 2π/3, A2 = π/4, A3 = 0).
        let b = Lambert::new(Rgb::splat(1.0));
        let wi = frame::from_spherical(0.6, 1.0);
        let plain = project(&b, wi, 4, false, 64).unwrap();
        let cos = project(&b, wi, 4, true, 64).unwrap();
        let k = |l: usize| 2.0 * ((2 * l + 1) as f64 / (4.0 * PI)).sqrt();
        let ip = [1.0, 0.5, 0.0, -0.125];
        let ixp = [0.5, 1.0 / 3.0, 0.125, 0.0, -1.0 / 48.0];
        for l in 0..=4 {
            for m in -(l as i64)..=l as i64 {
                let i = (l * (l + 1)) as i64 + m;
                let (pw, cw) = if m == 0 {
                    (if l < 4 { k(l) * ip[l] } else { 0.0 }, k(l) * ixp[l])
                } else {
                    (0.0, 0.0)
                };
                if l < 4 {
                    // ∫₀¹ P_4 = 0 too (even l > 0), but the step's quadrature in
                    // z is exact only for the polynomial part; keep to l < 4.
                    assert!(
                        (plain.coeffs[i as usize].x - pw).abs() < 1e-9,
                        "plain {l} {m}"
                    );
                }
                assert!((cos.coeffs[i as usize].x - cw).abs() < 1e-9, "cos {l} {m}");
            }
        }
    }

    #[test]
    fn lambert_is_not_band_limited_on_the_hemisphere() {
        // Extended by 0 below the horizon, f = ρ/π is a step (coefficients decay
        // like l^(−3/2)), f cos θ a kink (l^(−5/2)): neither reaches 0 error at
        // L = 16, and the kink converges faster than the step.
        let b = Lambert::new(Rgb::splat(0.8));
        let err = |order, cosine| {
            project(&b, DVec3::Z, order, cosine, 96)
                .unwrap()
                .rel_l2_error
        };
        let (step16, kink16) = (err(16, false), err(16, true));
        assert!(step16 > 0.05 && kink16 > 1e-3, "{step16} {kink16}");
        assert!(kink16 < step16, "{kink16} {step16}");
        assert!(err(4, false) > step16 && err(4, true) > kink16);
    }

    #[test]
    fn smooth_lobe_error_falls_fast_with_order() {
        // A von Mises–Fisher lobe exp(κ(w·r − 1)), κ = 4, on the sphere: its
        // coefficients fall faster than exponentially, and the full-sphere L2
        // error of an orthogonal projection never grows with L.
        let b = SphereFn(|w| (4.0 * (w.dot(DVec3::new(0.6, 0.0, 0.8)) - 1.0)).exp());
        let errs: Vec<f64> = [0usize, 1, 2, 4, 8, 16]
            .iter()
            .map(|&l| project(&b, DVec3::Z, l, false, 48).unwrap().rel_l2_error)
            .collect();
        for w in errs.windows(2) {
            assert!(w[1] <= w[0] + 1e-12, "{errs:?}");
        }
        assert!(errs[5] < 1e-8, "{errs:?}");
        assert!(errs[1] > 0.1, "{errs:?}");
    }

    /// Normalised Phong lobe `(e+2)/(2π) max(0, R(wo)·wi)^e` (Lewis 1994).
    #[derive(Debug)]
    struct Phong(f64);
    impl Brdf for Phong {
        fn id(&self) -> &'static str {
            "phong-test"
        }
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            if wi.z <= 0.0 || wo.z <= 0.0 {
                return Rgb::ZERO;
            }
            let c = frame::reflect(wo).dot(wi).max(0.0);
            Rgb::splat((self.0 + 2.0) / (2.0 * PI) * c.powf(self.0))
        }
        fn claims(&self) -> Claims {
            Claims {
                reciprocal: true,
                energy_conserving: true,
                isotropic: true,
            }
        }
    }

    #[test]
    fn sharp_lobes_lose_their_high_frequencies() {
        // cosᵉα ≈ exp(−e α²/2): a Gaussian of width 1/√e whose zonal
        // coefficients go like exp(−l²/(2e)) (heat kernel). Its energy
        // Σ (2l+1) c_l² ∝ ∫ 2l exp(−l²/e) dl puts a fraction 1 − exp(−L²/e) in
        // the bands up to L: for e = 1000, L = 16, 23%, so the relative L2
        // error is about √0.77 ≈ 0.88. A broad lobe about the normal (e = 4)
        // is cos⁴θ, which vanishes to fourth order at the horizon, so even its
        // zero extension is smooth (C³) and L = 16 captures it almost exactly.
        let sharp = project(&Phong(1000.0), DVec3::Z, 16, false, 256).unwrap();
        assert!(sharp.rel_l2_error > 0.75, "{}", sharp.rel_l2_error);
        assert!(sharp.rel_l2_error < 0.95, "{}", sharp.rel_l2_error);
        // The reconstruction misses the peak (e+2)/(2π) by a wide margin.
        let peak = 1002.0 / (2.0 * PI);
        assert!(sharp.eval(DVec3::Z).x < 0.5 * peak);
        let broad = project(&Phong(4.0), DVec3::Z, 16, false, 128).unwrap();
        assert!(broad.rel_l2_error < 1e-3, "{}", broad.rel_l2_error);
        // Band energies of the sharp lobe are still large at l = 16.
        let e = sharp.band_energy();
        assert!(e[16] > 0.5 * e[1], "{e:?}");
    }

    #[test]
    fn arguments_are_checked() {
        let b = Lambert::new(Rgb::splat(0.5));
        assert!(project(&b, DVec3::Z, 17, false, 32).is_err());
        assert!(project(&b, DVec3::Z, 2, false, MAX_RINGS + 1).is_err());
        // Too few rings are raised to L + 1.
        assert_eq!(project(&b, DVec3::Z, 8, false, 1).unwrap().n_theta, 9);
        // Identical models differ by 0.
        assert_eq!(relative_l2(&b, &b, DVec3::Z, true, 16).unwrap(), 0.0);
    }
}
