//! Interface optics for the lecture's "Snell's law", "Optical manhole" and
//! "Fresnel reflection" slides: refraction angles, critical and Brewster
//! angles, the radiance scaling across an interface, polarised Fresnel
//! reflectances of dielectrics and conductors, the normal-incidence inverses,
//! and data for a 2D Snell diagram and a Fresnel colour strip.
//!
//! Conventions: angles in radians from the interface normal; `eta_i` is the
//! index of the medium the light comes from, `eta_t` the one it enters
//! (absolute indices, so "from either side" is a swap of the two). For a
//! conductor `eta + i k` is its complex index relative to the incident medium.
//! `Rs` is the reflectance of the s (perpendicular, TE) polarisation, `Rp` of
//! the p (parallel, TM) one; unpolarised light has `R = (Rs + Rp)/2`.

use crate::{BvError, Result, Rgb, fresnel};
use glam::DVec2;
use std::f64::consts::FRAC_PI_2;

fn check_indices(eta_i: f64, eta_t: f64) -> Result<()> {
    for (name, v) in [("eta_i", eta_i), ("eta_t", eta_t)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(BvError::BadValue {
                param: name.to_string(),
                reason: format!("a refractive index must be finite and positive, got {v}"),
            });
        }
    }
    Ok(())
}

/// Refraction angle θt from Snell's law `ηi sin θi = ηt sin θt` (seed,
/// "Snell's Law"), or `None` beyond the critical angle (total internal
/// reflection) and for non-physical indices. `theta_i` is taken modulo sign
/// (|θi| ≤ π/2 is expected).
pub fn refraction_angle(theta_i: f64, eta_i: f64, eta_t: f64) -> Option<f64> {
    check_indices(eta_i, eta_t).ok()?;
    let s = eta_i / eta_t * theta_i.abs().sin();
    if s > 1.0 || !s.is_finite() {
        None
    } else {
        Some(s.asin())
    }
}

/// Critical angle `θc = asin(ηt/ηi)` beyond which light going from the denser
/// medium `eta_i` into `eta_t` is totally reflected; `None` when `ηt ≥ ηi`
/// (every angle transmits).
pub fn critical_angle(eta_i: f64, eta_t: f64) -> Option<f64> {
    check_indices(eta_i, eta_t).ok()?;
    if eta_t >= eta_i {
        None
    } else {
        Some((eta_t / eta_i).asin())
    }
}

/// Brewster's angle `θB = atan(ηt/ηi)`, where the reflected p polarisation
/// vanishes (the reflected and refracted rays are then perpendicular).
pub fn brewster_angle(eta_i: f64, eta_t: f64) -> f64 {
    (eta_t / eta_i).atan()
}

/// Scale of radiance carried across the interface from `eta_i` into
/// `eta_t`: `(ηt/ηi)²` (radiance over η² is invariant along a ray; PBRT
/// 3rd ed. §8.2.3 and the seed's transmission term `ηo²/ηi²`).
pub fn radiance_scale(eta_i: f64, eta_t: f64) -> f64 {
    let r = eta_t / eta_i;
    r * r
}

/// Half-angle of Snell's window (the "optical manhole"): seen from inside a
/// medium of index `n` under a flat surface to a medium of index 1, the whole
/// outside hemisphere is squeezed into a cone of half-angle `asin(1/n)`,
/// i.e. the critical angle (48.6° for water, n = 4/3). `None` for `n ≤ 1`.
pub fn snell_window_half_angle(n: f64) -> Option<f64> {
    critical_angle(n, 1.0)
}

/// Fresnel reflectances of one interface at one angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FresnelWeights {
    /// Reflectance of the s (perpendicular) polarisation, `|r⊥|²`.
    pub rs: f64,
    /// Reflectance of the p (parallel) polarisation, `|r∥|²`.
    pub rp: f64,
    /// Unpolarised reflectance `(Rs + Rp)/2`.
    pub r: f64,
    /// Transmitted fraction of the flux `1 − R` (for a conductor: absorbed).
    pub t: f64,
    /// Whether the light is totally internally reflected (dielectric only).
    pub tir: bool,
}

impl FresnelWeights {
    fn new(rs: f64, rp: f64, tir: bool) -> Self {
        let r = 0.5 * (rs + rp);
        Self {
            rs,
            rp,
            r,
            t: 1.0 - r,
            tir,
        }
    }
}

/// Reflectances of a dielectric interface for light from `eta_i` into
/// `eta_t` at incidence `theta_i`, from the seed's Fresnel equations
/// `r∥ = (ηt cosθi − ηi cosθt)/(ηt cosθi + ηi cosθt)`,
/// `r⊥ = (ηi cosθi − ηt cosθt)/(ηi cosθi + ηt cosθt)`. Under total internal
/// reflection `Rs = Rp = R = 1`, `T = 0`. Works from either side: swap the
/// indices. Non-physical indices give an error.
pub fn dielectric(theta_i: f64, eta_i: f64, eta_t: f64) -> Result<FresnelWeights> {
    check_indices(eta_i, eta_t)?;
    let ci = theta_i.abs().min(FRAC_PI_2).cos();
    let Some(tt) = refraction_angle(theta_i, eta_i, eta_t) else {
        return Ok(FresnelWeights::new(1.0, 1.0, true));
    };
    let ct = tt.cos();
    let r_par = (eta_t * ci - eta_i * ct) / (eta_t * ci + eta_i * ct);
    let r_perp = (eta_i * ci - eta_t * ct) / (eta_i * ci + eta_t * ct);
    if !(r_par.is_finite() && r_perp.is_finite()) {
        // Only at grazing incidence with equal indices (0/0): the limit of
        // every nearby index is total reflection.
        return Ok(FresnelWeights::new(1.0, 1.0, false));
    }
    Ok(FresnelWeights::new(r_perp * r_perp, r_par * r_par, false))
}

/// A complex number, just enough for the complex Fresnel equations.
#[derive(Debug, Clone, Copy)]
struct Complex {
    re: f64,
    im: f64,
}

impl Complex {
    const fn new(re: f64, im: f64) -> Self {
        Self { re, im }
    }
    fn add(self, o: Self) -> Self {
        Self::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: Self) -> Self {
        Self::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: Self) -> Self {
        Self::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn norm2(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
    fn div(self, o: Self) -> Self {
        let d = o.norm2();
        Self::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    /// Principal square root (non-negative real part).
    fn sqrt(self) -> Self {
        let r = self.norm2().sqrt();
        let re = (0.5 * (r + self.re)).max(0.0).sqrt();
        let im = (0.5 * (r - self.re)).max(0.0).sqrt().copysign(self.im);
        Self::new(re, im)
    }
}

/// Reflectances of a conductor with complex relative index `eta + i k` at
/// incidence `theta_i`, from the exact complex Fresnel equations (Born & Wolf,
/// *Principles of Optics*, §14.2; the form of PBRT-v4's `FrComplex`):
/// `cos θt = √(1 − sin²θi / n²)`, `r⊥ = (cosθi − n cosθt)/(cosθi + n cosθt)`,
/// `r∥ = (n cosθi − cosθt)/(n cosθi + cosθt)`, `Rs = |r⊥|²`, `Rp = |r∥|²`.
/// `T = 1 − R` is the absorbed fraction. `k = 0` gives the dielectric.
pub fn conductor(theta_i: f64, eta: f64, k: f64) -> Result<FresnelWeights> {
    if !(eta.is_finite() && eta > 0.0) {
        return Err(BvError::BadValue {
            param: "eta".into(),
            reason: format!("must be finite and positive, got {eta}"),
        });
    }
    if !(k.is_finite() && k >= 0.0) {
        return Err(BvError::BadValue {
            param: "k".into(),
            reason: format!("must be finite and non-negative, got {k}"),
        });
    }
    let th = theta_i.abs().min(FRAC_PI_2);
    let (s, c) = th.sin_cos();
    let n = Complex::new(eta, k);
    let ci = Complex::new(c, 0.0);
    let cos_t = Complex::new(1.0, 0.0)
        .sub(Complex::new(s * s, 0.0).div(n.mul(n)))
        .sqrt();
    let r_perp = ci.sub(n.mul(cos_t)).div(ci.add(n.mul(cos_t)));
    let r_par = n.mul(ci).sub(cos_t).div(n.mul(ci).add(cos_t));
    let (rs, rp) = (r_perp.norm2(), r_par.norm2());
    if !(rs.is_finite() && rp.is_finite()) {
        // 0/0 only at grazing incidence with n = 1: the limit is 1.
        return Ok(FresnelWeights::new(1.0, 1.0, false));
    }
    // With k = 0 and η < 1 beyond the critical angle cos θt is imaginary and
    // |r| = 1 exactly: that is total internal reflection.
    let tir = k == 0.0 && eta < 1.0 && s > eta;
    Ok(FresnelWeights::new(rs.min(1.0), rp.min(1.0), tir))
}

/// Normal-incidence reflectance of a dielectric of relative index `eta`:
/// `F0 = ((η − 1)/(η + 1))²` (seed, "How to determine k or η", case k = 0).
pub fn dielectric_f0(eta: f64) -> f64 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

/// The inverse of [`dielectric_f0`] on `η ≥ 1`: `η = (1 + √F0)/(1 − √F0)`.
/// `F0` must lie in `[0, 1)`.
pub fn dielectric_eta_from_f0(f0: f64) -> Result<f64> {
    if !(0.0..1.0).contains(&f0) {
        return Err(BvError::BadValue {
            param: "f0".into(),
            reason: format!(
                "F0 = {f0}: a dielectric's normal-incidence reflectance lies in [0, 1)"
            ),
        });
    }
    Ok(fresnel::eta_from_f0(f0))
}

/// Normal-incidence reflectance of a conductor:
/// `F0 = ((η − 1)² + k²)/((η + 1)² + k²)`.
pub fn conductor_f0(eta: f64, k: f64) -> f64 {
    ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k)
}

/// The extinction coefficient `k ≥ 0` that gives normal-incidence
/// reflectance `f0` with real part `eta`: solving [`conductor_f0`] for k,
/// `k = √(((η + 1)² F0 − (η − 1)²)/(1 − F0))`. No real k exists when
/// `F0 < ((η − 1)/(η + 1))²` (the reflectance of the bare dielectric η is
/// already higher) or `F0 ≥ 1`: both are errors that say so.
pub fn conductor_k_from_f0(f0: f64, eta: f64) -> Result<f64> {
    if !(eta.is_finite() && eta > 0.0) {
        return Err(BvError::BadValue {
            param: "eta".into(),
            reason: format!("must be finite and positive, got {eta}"),
        });
    }
    if !(f0.is_finite() && f0 < 1.0) {
        return Err(BvError::BadValue {
            param: "f0".into(),
            reason: format!("F0 = {f0}: no finite k reaches a reflectance of 1 or more"),
        });
    }
    let floor = dielectric_f0(eta);
    let num = (eta + 1.0).powi(2) * f0 - (eta - 1.0).powi(2);
    if num < 0.0 {
        return Err(BvError::BadValue {
            param: "f0".into(),
            reason: format!(
                "F0 = {f0} is below {floor:.6}, the reflectance of η = {eta} with k = 0: no real k gives it"
            ),
        });
    }
    Ok((num / (1.0 - f0)).sqrt())
}

/// Schlick's approximation at incidence angle `theta`:
/// `F0 + (1 − F0)(1 − cos θ)⁵` (Schlick 1994, eq. 24; seed, "Fresnel
/// Reflection").
pub fn schlick(f0: f64, theta: f64) -> f64 {
    fresnel::schlick(f0, theta.abs().min(FRAC_PI_2).cos())
}

/// F(θ) per RGB channel at evenly spaced angles, exact and Schlick's, for a
/// colour strip (the seed's copper example: the colour shifts towards white
/// at grazing incidence).
#[derive(Debug, Clone, PartialEq)]
pub struct FresnelStrip {
    /// Angles θ_j = j/(n − 1) · π/2, j = 0..n (radians).
    pub theta: Vec<f64>,
    /// Exact unpolarised reflectance per channel (linear RGB).
    pub exact: Vec<Rgb>,
    /// Schlick's approximation with the exact F0 per channel.
    pub schlick: Vec<Rgb>,
}

/// The [`FresnelStrip`] of a conductor with per-channel `eta`, `k` sampled at
/// `n ≥ 2` angles from 0 to 90°.
pub fn conductor_strip(eta: Rgb, k: Rgb, n: usize) -> Result<FresnelStrip> {
    if n < 2 {
        return Err(BvError::Invalid(format!(
            "a Fresnel strip needs at least 2 angles, got {n}"
        )));
    }
    let f0 = Rgb::new(
        conductor_f0(eta.x, k.x),
        conductor_f0(eta.y, k.y),
        conductor_f0(eta.z, k.z),
    );
    let mut strip = FresnelStrip {
        theta: Vec::with_capacity(n),
        exact: Vec::with_capacity(n),
        schlick: Vec::with_capacity(n),
    };
    for j in 0..n {
        let th = j as f64 / (n - 1) as f64 * FRAC_PI_2;
        strip.theta.push(th);
        strip.exact.push(Rgb::new(
            conductor(th, eta.x, k.x)?.r,
            conductor(th, eta.y, k.y)?.r,
            conductor(th, eta.z, k.z)?.r,
        ));
        strip.schlick.push(Rgb::new(
            schlick(f0.x, th),
            schlick(f0.y, th),
            schlick(f0.z, th),
        ));
    }
    Ok(strip)
}

/// Everything a view needs to draw the plane of incidence of one ray at a
/// flat interface: the interface is the x axis, the incident medium is
/// `y > 0`, the normal is `+y`. Every direction points **away** from the hit
/// point at the origin (as `wi`/`wo` do elsewhere in bv), unit length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SnellDiagram {
    /// Incidence angle θi (radians).
    pub theta_i: f64,
    /// Index of the incident medium (above).
    pub eta_i: f64,
    /// Index of the other medium (below).
    pub eta_t: f64,
    /// Towards the light: `(−sin θi, cos θi)`.
    pub incident: DVec2,
    /// Mirror direction: `(sin θi, cos θi)`.
    pub reflected: DVec2,
    /// Refracted direction `(sin θt, −cos θt)`, `None` under total internal
    /// reflection.
    pub refracted: Option<DVec2>,
    /// Refraction angle θt, `None` under total internal reflection.
    pub theta_t: Option<f64>,
    /// Fresnel weights (R is the reflected ray's weight, T the refracted's).
    pub weights: FresnelWeights,
    /// Radiance factor of the refracted ray, `T (ηt/ηi)²` (0 under TIR).
    pub refracted_radiance: f64,
    /// Whether θi is beyond the critical angle.
    pub tir: bool,
    /// Incidence angles that are totally reflected, `[θc, π/2]`; `None` when
    /// `ηt ≥ ηi`.
    pub tir_range: Option<(f64, f64)>,
    /// Brewster's angle of this interface.
    pub brewster: f64,
}

/// The [`SnellDiagram`] for incidence `theta_i` (|θi| ≤ π/2; the sign is
/// ignored) from `eta_i` into `eta_t`.
pub fn snell_diagram(theta_i: f64, eta_i: f64, eta_t: f64) -> Result<SnellDiagram> {
    check_indices(eta_i, eta_t)?;
    let th = theta_i.abs().min(FRAC_PI_2);
    let weights = dielectric(th, eta_i, eta_t)?;
    let theta_t = refraction_angle(th, eta_i, eta_t);
    let (s, c) = th.sin_cos();
    Ok(SnellDiagram {
        theta_i: th,
        eta_i,
        eta_t,
        incident: DVec2::new(-s, c),
        reflected: DVec2::new(s, c),
        refracted: theta_t.map(|t| DVec2::new(t.sin(), -t.cos())),
        theta_t,
        weights,
        refracted_radiance: weights.t * radiance_scale(eta_i, eta_t),
        tir: theta_t.is_none(),
        tir_range: critical_angle(eta_i, eta_t).map(|c| (c, FRAC_PI_2)),
        brewster: brewster_angle(eta_i, eta_t),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn snell_hand_values() {
        // Air to glass at 30°: sin θt = 0.5/1.5 = 1/3.
        let t = refraction_angle(30f64.to_radians(), 1.0, 1.5).unwrap();
        assert!(close(t.sin(), 1.0 / 3.0, 1e-15));
        // Normal incidence goes straight through.
        assert_eq!(refraction_angle(0.0, 1.0, 1.5), Some(0.0));
        // Glass to air at 45°: sin θt = 1.5 · 0.7071 > 1, total reflection.
        assert_eq!(refraction_angle(45f64.to_radians(), 1.5, 1.0), None);
        assert_eq!(refraction_angle(0.3, -1.0, 1.5), None);
    }

    #[test]
    fn critical_and_brewster_angles() {
        // Glass (1.5) to air: asin(2/3) = 41.81°.
        let c = critical_angle(1.5, 1.0).unwrap();
        assert!(close(c.to_degrees(), 41.8103, 1e-4));
        assert_eq!(critical_angle(1.0, 1.5), None);
        // Just below θc it refracts (to nearly 90°), just above it does not.
        assert!(refraction_angle(c - 1e-6, 1.5, 1.0).unwrap() > 1.5);
        assert!(refraction_angle(c + 1e-6, 1.5, 1.0).is_none());
        // Brewster air→glass: atan(1.5) = 56.31°; at it Rp = 0 and the
        // reflected and refracted rays are perpendicular (θB + θt = 90°).
        let b = brewster_angle(1.0, 1.5);
        assert!(close(b.to_degrees(), 56.3099, 1e-4));
        let w = dielectric(b, 1.0, 1.5).unwrap();
        assert!(w.rp < 1e-30, "{}", w.rp);
        assert!(w.rs > 0.1);
        let tt = refraction_angle(b, 1.0, 1.5).unwrap();
        assert!(close(b + tt, FRAC_PI_2, 1e-15));
        // From inside the glass: atan(1/1.5), also Rp = 0.
        let bi = brewster_angle(1.5, 1.0);
        assert!(dielectric(bi, 1.5, 1.0).unwrap().rp < 1e-30);
        // Brewster from inside is below the critical angle (33.7° < 41.8°).
        assert!(bi < c);
    }

    #[test]
    fn water_snell_window_is_48_6_degrees() {
        let w = snell_window_half_angle(4.0 / 3.0).unwrap();
        // asin(3/4) = 48.590°.
        assert!(close(w.to_degrees(), 48.5904, 1e-4));
        assert!(close(w.sin(), 0.75, 1e-15));
        // A ray grazing the water surface from above refracts to exactly θc.
        let t = refraction_angle(FRAC_PI_2, 1.0, 4.0 / 3.0).unwrap();
        assert!(close(t, w, 1e-15));
        assert_eq!(snell_window_half_angle(1.0), None);
    }

    #[test]
    fn dielectric_hand_values_and_energy() {
        // Glass 1.5: F0 = 0.04 from both sides.
        let w = dielectric(0.0, 1.0, 1.5).unwrap();
        assert!(close(w.r, 0.04, 1e-16) && close(w.rs, 0.04, 1e-16) && close(w.rp, 0.04, 1e-16));
        assert!(close(dielectric(0.0, 1.5, 1.0).unwrap().r, 0.04, 1e-16));
        assert!(close(dielectric_f0(1.5), 0.04, 1e-16));
        // 60° air → glass: cos θt = √(2/3) (sin θt = 1/√3).
        let ct = (2.0f64 / 3.0).sqrt();
        let rs = ((0.5 - 1.5 * ct) / (0.5 + 1.5 * ct)).powi(2);
        let rp = ((1.5 * 0.5 - ct) / (1.5 * 0.5 + ct)).powi(2);
        let w = dielectric(60f64.to_radians(), 1.0, 1.5).unwrap();
        assert!(close(w.rs, rs, 1e-14) && close(w.rp, rp, 1e-14));
        // R + T = 1 and agreement with the core's unpolarised form, both sides.
        for i in 0..=90 {
            let th = (i as f64).to_radians();
            for (a, b, cos) in [(1.0, 1.5, th.cos()), (1.5, 1.0, -th.cos())] {
                let w = dielectric(th, a, b).unwrap();
                assert!(close(w.r + w.t, 1.0, 1e-15));
                assert!((0.0..=1.0).contains(&w.r));
                let core = fresnel::dielectric(cos, 1.5);
                assert!(close(w.r, core, 1e-12), "θ {i}° {a}→{b}: {} vs {core}", w.r);
            }
        }
        // Beyond the critical angle: R = 1, T = 0, flagged.
        let w = dielectric(60f64.to_radians(), 1.5, 1.0).unwrap();
        assert!(w.tir && w.r == 1.0 && w.t == 0.0);
        assert!(dielectric(0.2, 0.0, 1.5).is_err());
    }

    #[test]
    fn conductor_polarised_reflectances() {
        for (eta, k) in [(0.2, 3.9), (1.2, 7.0), (2.0, 0.5), (0.05, 4.0), (1.5, 0.0)] {
            // Normal incidence: Rs = Rp = ((η−1)² + k²)/((η+1)² + k²).
            let want = ((eta - 1.0f64).powi(2) + k * k) / ((eta + 1.0f64).powi(2) + k * k);
            let w = conductor(0.0, eta, k).unwrap();
            assert!(close(w.rs, want, 1e-14) && close(w.rp, want, 1e-14));
            assert!(close(conductor_f0(eta, k), want, 1e-15));
            // Grazing: R → 1.
            assert!(close(conductor(FRAC_PI_2, eta, k).unwrap().r, 1.0, 1e-12));
            assert!(conductor(FRAC_PI_2 - 1e-4, eta, k).unwrap().r > 0.99);
            // The mean matches the core's closed form (Lagarde 2013), which
            // shares no code with the complex arithmetic here.
            for i in 0..=90 {
                let th = (i as f64).to_radians();
                let w = conductor(th, eta, k).unwrap();
                let core = fresnel::conductor(th.cos(), eta, k);
                assert!(
                    close(w.r, core, 1e-12),
                    "η {eta} k {k} {i}°: {} vs {core}",
                    w.r
                );
                // Rp ≤ Rs for an absorbing interface from the incident side.
                assert!(w.rp <= w.rs + 1e-15);
            }
        }
        // k = 0 is the dielectric, polarisation by polarisation (60° hand values).
        let ct = (2.0f64 / 3.0).sqrt();
        let rs = ((0.5 - 1.5 * ct) / (0.5 + 1.5 * ct)).powi(2);
        let rp = ((1.5 * 0.5 - ct) / (1.5 * 0.5 + ct)).powi(2);
        let w = conductor(60f64.to_radians(), 1.5, 0.0).unwrap();
        assert!(close(w.rs, rs, 1e-14) && close(w.rp, rp, 1e-14));
        // A conductor's p reflectance has a minimum (the "principal angle"),
        // not a zero as at Brewster's angle: for aluminium-like η = 1.2,
        // k = 7 it is 0.706 near 81.8° (Python's complex arithmetic, by hand).
        let (min_rp, at) = (0..900)
            .map(|i| {
                let th = (i as f64 / 10.0).to_radians();
                (conductor(th, 1.2, 7.0).unwrap().rp, th.to_degrees())
            })
            .fold((1.0, 0.0), |a, b| if b.0 < a.0 { b } else { a });
        assert!(
            close(min_rp, 0.70635, 1e-5) && close(at, 81.8, 0.05),
            "{min_rp} at {at}"
        );
        assert!(conductor(0.3, 1.0, -1.0).is_err());
    }

    #[test]
    fn inverses_round_trip() {
        for eta in [1.0, 1.333, 1.5, 2.42, 4.0] {
            let f0 = dielectric_f0(eta);
            assert!(close(dielectric_eta_from_f0(f0).unwrap(), eta, 1e-12));
        }
        assert!(close(dielectric_eta_from_f0(0.04).unwrap(), 1.5, 1e-15));
        assert!(dielectric_eta_from_f0(1.0).is_err());
        assert!(dielectric_eta_from_f0(-0.1).is_err());
        for (eta, k) in [(0.2, 3.9), (1.2, 7.0), (2.0, 0.5), (1.5, 0.0)] {
            let f0 = conductor_f0(eta, k);
            let back = conductor_k_from_f0(f0, eta).unwrap();
            assert!(close(back, k, 1e-9), "η {eta}: k {k} → F0 {f0} → {back}");
        }
        // With η = 1 the seed's inverse k = 2√(F0/(1 − F0)) is recovered.
        for f0 in [0.1, 0.5, 0.9] {
            let k = conductor_k_from_f0(f0, 1.0).unwrap();
            assert!(close(k, 2.0 * (f0 / (1.0 - f0)).sqrt(), 1e-14));
        }
        // η = 2 has F0 ≥ 1/9 for every k: 0.05 is unreachable.
        let e = conductor_k_from_f0(0.05, 2.0).unwrap_err().to_string();
        assert!(e.contains("no real k") && e.contains("0.111111"), "{e}");
        assert!(conductor_k_from_f0(1.0, 0.5).is_err());
    }

    #[test]
    fn schlick_against_exact() {
        assert!(close(schlick(0.04, 0.0), 0.04, 1e-16));
        assert!(close(schlick(0.04, FRAC_PI_2), 1.0, 1e-15));
        // cos 60° = 1/2: 0.04 + 0.96/32.
        assert!(close(
            schlick(0.04, 60f64.to_radians()),
            0.04 + 0.96 / 32.0,
            1e-15
        ));
        // For glass Schlick is within 0.005 of the exact curve below 40° and
        // within 0.036 everywhere, its worst near 85° (hand evaluation of the
        // seed's formulas): the lecture's "approximated reflectance".
        let mut worst = (0.0, 0);
        for i in 0..=90 {
            let th = (i as f64).to_radians();
            let d = (schlick(0.04, th) - dielectric(th, 1.0, 1.5).unwrap().r).abs();
            if i < 40 {
                assert!(d < 0.005, "{i}°: {d}");
            }
            if d > worst.0 {
                worst = (d, i);
            }
        }
        assert!(close(worst.0, 0.03569, 1e-5) && worst.1 == 85, "{worst:?}");
    }

    #[test]
    fn copper_strip_whitens_at_grazing() {
        let eta = Rgb::from_array(fresnel::COPPER_ETA);
        let k = Rgb::from_array(fresnel::COPPER_K);
        let s = conductor_strip(eta, k, 10).unwrap();
        assert_eq!(s.theta.len(), 10);
        assert!(close(s.theta[9], FRAC_PI_2, 1e-15));
        // θ = 0 is F0 per channel (hand formula), θ = 90° is white.
        for (c, (e, kk)) in [(eta.x, k.x), (eta.y, k.y), (eta.z, k.z)]
            .into_iter()
            .enumerate()
        {
            let f0 = ((e - 1.0) * (e - 1.0) + kk * kk) / ((e + 1.0) * (e + 1.0) + kk * kk);
            assert!(close(s.exact[0][c], f0, 1e-14));
            assert!(close(s.schlick[0][c], f0, 1e-14));
            assert!(close(s.exact[9][c], 1.0, 1e-12));
        }
        // Copper is red at normal incidence (R > G > B).
        assert!(s.exact[0].x > s.exact[0].y && s.exact[0].y > s.exact[0].z);
        assert!(conductor_strip(eta, k, 1).is_err());
    }

    #[test]
    fn snell_diagram_geometry() {
        let d = snell_diagram(30f64.to_radians(), 1.0, 1.5).unwrap();
        assert!(close(d.incident.x, -0.5, 1e-15) && close(d.reflected.x, 0.5, 1e-15));
        let t = d.refracted.unwrap();
        // Tangential components obey Snell: ηi |sin θi| = ηt sin θt.
        assert!(close(1.5 * t.x, 0.5, 1e-15) && t.y < 0.0);
        assert!(close(t.length(), 1.0, 1e-15));
        assert!(!d.tir && d.tir_range.is_none());
        assert!(close(d.weights.r + d.weights.t, 1.0, 1e-15));
        assert!(close(d.refracted_radiance, d.weights.t * 2.25, 1e-15));
        // Water from below at 60°: beyond the 48.6° window, all reflected.
        let d = snell_diagram(60f64.to_radians(), 4.0 / 3.0, 1.0).unwrap();
        assert!(d.tir && d.refracted.is_none() && d.weights.r == 1.0);
        assert_eq!(d.refracted_radiance, 0.0);
        let (lo, hi) = d.tir_range.unwrap();
        assert!(close(lo.to_degrees(), 48.5904, 1e-4) && hi == FRAC_PI_2);
    }
}
