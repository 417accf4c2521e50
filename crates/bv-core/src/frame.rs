//! The local shading frame and the direction algebra every model uses.
//!
//! Normal `n = +z`, tangent `t = +x`, bitangent `b = +y`. Both `wi` (towards the
//! light) and `wo` (towards the viewer) point away from the surface. θ is measured
//! from +z, φ from +x towards +y.

use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};

/// The surface normal of the local frame.
pub const NORMAL: DVec3 = DVec3::Z;
/// The tangent (the *u* direction of anisotropic models, the fibre of Banks).
pub const TANGENT: DVec3 = DVec3::X;
/// The bitangent (*v* direction).
pub const BITANGENT: DVec3 = DVec3::Y;

/// `(sin θ, cos θ)`, exact at the horizon θ = π/2 and at θ = π. `cos(π/2)` in
/// floating point is 6e-17, not 0: a direction meant to lie in the surface would
/// then be just above it, where a model with a 1/cos θ factor (Ward, Phong)
/// returns thousands instead of the 0.
#[inline]
pub fn sin_cos_theta(theta: f64) -> (f64, f64) {
    if theta == FRAC_PI_2 {
        (1.0, 0.0)
    } else if theta == PI {
        (0.0, -1.0)
    } else {
        theta.sin_cos()
    }
}

/// Unit direction from polar angle `theta` and azimuth `phi` (radians); exactly
/// in the surface for θ = π/2 (see [`sin_cos_theta`]).
#[inline]
pub fn from_spherical(theta: f64, phi: f64) -> DVec3 {
    let (st, ct) = sin_cos_theta(theta);
    let (sp, cp) = phi.sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}

/// Polar angle θ ∈ [0, π] and azimuth φ ∈ (−π, π] of a unit direction.
#[inline]
pub fn to_spherical(w: DVec3) -> (f64, f64) {
    // atan2 rather than acos(z): acos loses half the digits near the poles
    // (θ ≈ √(2(1 − z))), exactly where MERL's √θh index mapping is steepest.
    let theta = (w.x * w.x + w.y * w.y).sqrt().atan2(w.z);
    let phi = w.y.atan2(w.x);
    (theta, phi)
}

/// cos θ of a direction in the local frame.
#[inline]
pub fn cos_theta(w: DVec3) -> f64 {
    w.z
}

/// sin² θ, computed from x and y so that it stays accurate near the normal.
#[inline]
pub fn sin2_theta(w: DVec3) -> f64 {
    w.x * w.x + w.y * w.y
}

/// tan² θ (infinite at the horizon).
#[inline]
pub fn tan2_theta(w: DVec3) -> f64 {
    sin2_theta(w) / (w.z * w.z)
}

/// (cos² φ, sin² φ) of a direction; (1, 0) on the normal, where φ is undefined.
#[inline]
pub fn cos2_sin2_phi(w: DVec3) -> (f64, f64) {
    let s2 = sin2_theta(w);
    if s2 <= 0.0 {
        (1.0, 0.0)
    } else {
        (w.x * w.x / s2, w.y * w.y / s2)
    }
}

/// Mirror direction about the normal: `R(w) = 2 (w·n) n − w` .
#[inline]
pub fn reflect(w: DVec3) -> DVec3 {
    DVec3::new(-w.x, -w.y, w.z)
}

/// Mirror direction of `w` about an arbitrary unit axis `m`.
#[inline]
pub fn reflect_about(w: DVec3, m: DVec3) -> DVec3 {
    2.0 * w.dot(m) * m - w
}

/// Half vector `normalize(wi + wo)`; `None` when the two are opposite.
#[inline]
pub fn half_vector(wi: DVec3, wo: DVec3) -> Option<DVec3> {
    let h = wi + wo;
    let l2 = h.length_squared();
    if l2 > 1e-24 && l2.is_finite() {
        // One division and three products (not three divisions): this sits on
        // every microfacet model's hot path.
        Some(h * (1.0 / l2.sqrt()))
    } else {
        None
    }
}

/// Refraction of `w` (pointing away from the surface, on either side) through the
/// interface with relative index `eta = ηt/ηi` measured from the +z side to the
/// −z side. Returns the transmitted direction (pointing away from the surface on
/// the other side) or `None` under total internal reflection.
///
/// Snell's law in vector form, from the seed's derivation `T = μI + γN`.
pub fn refract(w: DVec3, eta: f64) -> Option<DVec3> {
    // Indices on w's side and on the far side.
    let (eta_i, eta_t) = if w.z >= 0.0 { (1.0, eta) } else { (eta, 1.0) };
    let mu = eta_i / eta_t;
    let cos_i = w.z.abs();
    let sin2_t = mu * mu * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let sign = if w.z >= 0.0 { 1.0 } else { -1.0 };
    // Tangential part flips sign with the incoming direction, normal part goes to the other side.
    let t = DVec3::new(-mu * w.x, -mu * w.y, -sign * cos_t);
    Some(t.normalize())
}

/// Rusinkiewicz (1998) half/difference angles of a direction pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfDiff {
    /// Polar angle of the half vector, [0, π/2].
    pub theta_h: f64,
    /// Azimuth of the half vector.
    pub phi_h: f64,
    /// Polar angle of `wi` in the half-vector frame, [0, π/2].
    pub theta_d: f64,
    /// Azimuth of `wi` in the half-vector frame, (−π, π].
    pub phi_d: f64,
}

fn rotate_z(v: DVec3, a: f64) -> DVec3 {
    let (s, c) = a.sin_cos();
    DVec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
}

fn rotate_y(v: DVec3, a: f64) -> DVec3 {
    let (s, c) = a.sin_cos();
    DVec3::new(c * v.x + s * v.z, v.y, -s * v.x + c * v.z)
}

/// Half/difference angles of `(wi, wo)` : θh, φh are the angles of
/// `h`; θd, φd those of `wi` after rotating by −φh about z and −θh about y.
/// `None` when `wi = −wo`.
pub fn to_half_diff(wi: DVec3, wo: DVec3) -> Option<HalfDiff> {
    let h = half_vector(wi, wo)?;
    let (theta_h, phi_h) = to_spherical(h);
    let d = rotate_y(rotate_z(wi, -phi_h), -theta_h);
    let (theta_d, phi_d) = to_spherical(d);
    Some(HalfDiff {
        theta_h,
        phi_h,
        theta_d,
        phi_d,
    })
}

/// Inverse of [`to_half_diff`]: the `(wi, wo)` pair of given half/difference angles.
pub fn from_half_diff(hd: HalfDiff) -> (DVec3, DVec3) {
    let d = from_spherical(hd.theta_d, hd.phi_d);
    let wi = rotate_z(rotate_y(d, hd.theta_h), hd.phi_h);
    let h = from_spherical(hd.theta_h, hd.phi_h);
    let wo = reflect_about(wi, h);
    (wi, wo)
}

/// Checks a user-given direction: finite, normalised when within 1e-3 of unit
/// length , refused otherwise.
pub fn checked_direction(name: &str, v: [f64; 3]) -> crate::Result<DVec3> {
    let w = DVec3::from_array(v);
    if !w.is_finite() {
        return Err(crate::BvError::BadDirection {
            name: name.to_string(),
            reason: format!("{v:?} is not finite"),
        });
    }
    let len = w.length();
    if (len - 1.0).abs() > 1e-3 {
        return Err(crate::BvError::BadDirection {
            name: name.to_string(),
            reason: format!(
                "{v:?} has length {}, not 1 (tolerance 1e-3)",
                if len < 1e6 {
                    format!("{len:.6}")
                } else {
                    crate::error::fmt_num(len)
                }
            ),
        });
    }
    Ok(w / len)
}

/// Angle in degrees of a unit direction's θ, for reports.
pub fn theta_deg(w: DVec3) -> f64 {
    to_spherical(w).0.to_degrees()
}

/// Clamps an angle to the open upper hemisphere range used by sliders: [0, π/2).
pub fn clamp_theta(theta: f64) -> f64 {
    theta.clamp(0.0, FRAC_PI_2 - 1e-6)
}

/// Wraps an azimuth into (−π, π].
pub fn wrap_phi(phi: f64) -> f64 {
    let mut p = (phi + PI).rem_euclid(2.0 * PI) - PI;
    if p <= -PI {
        p += 2.0 * PI;
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn spherical_round_trip() {
        for &(t, p) in &[(0.3, 0.2), (1.2, -2.0), (0.01, 3.0), (1.5, 1.0)] {
            let w = from_spherical(t, p);
            let (t2, p2) = to_spherical(w);
            assert!((t - t2).abs() < 1e-12 && (p - p2).abs() < 1e-12);
        }
    }

    #[test]
    fn horizon_is_exactly_in_the_surface() {
        assert_eq!(from_spherical(FRAC_PI_2, 0.3).z, 0.0);
        assert_eq!(from_spherical(PI, 0.3), DVec3::new(0.0, 0.0, -1.0));
    }

    #[test]
    fn reflect_is_seed_law_for_inward_vector() {
        // Seed: R = I − 2 (I·N) N for I pointing into the surface; ours takes w = −I.
        let w = from_spherical(0.7, 0.4);
        let i = -w;
        let seed = i - 2.0 * i.dot(NORMAL) * NORMAL;
        assert!(close(reflect(w), seed));
        // φr = (φi + π) mod 2π and θr = θi.
        let (tr, pr) = to_spherical(reflect(w));
        assert!((tr - 0.7).abs() < 1e-12);
        assert!((wrap_phi(pr - 0.4 - PI)).abs() < 1e-12);
    }

    #[test]
    fn half_diff_of_mirror_pair_has_zero_theta_h() {
        let wi = from_spherical(0.6, 1.0);
        let hd = to_half_diff(wi, reflect(wi)).unwrap();
        assert!(hd.theta_h.abs() < 1e-7);
        assert!((hd.theta_d - 0.6).abs() < 1e-12);
    }

    #[test]
    fn half_diff_round_trip() {
        for &(a, b) in &[
            ((0.3, 0.1), (0.9, 2.0)),
            ((1.4, -1.0), (0.2, 0.5)),
            ((0.5, 0.0), (0.5, 3.0)),
        ] {
            let wi = from_spherical(a.0, a.1);
            let wo = from_spherical(b.0, b.1);
            let hd = to_half_diff(wi, wo).unwrap();
            let (wi2, wo2) = from_half_diff(hd);
            assert!(close(wi, wi2), "{wi} {wi2}");
            assert!(close(wo, wo2), "{wo} {wo2}");
        }
    }

    #[test]
    fn refraction_obeys_snell_and_tir() {
        let eta = 1.5;
        let w = from_spherical(0.8, 0.3);
        let t = refract(w, eta).unwrap();
        assert!(t.z < 0.0);
        let sin_i = 0.8f64.sin();
        let sin_t = (t.x * t.x + t.y * t.y).sqrt();
        assert!((sin_i - eta * sin_t).abs() < 1e-12);
        // Back through: inside to outside returns the original direction.
        let back = refract(t, eta).unwrap();
        assert!(close(back, w));
        // Water critical angle: asin(1/1.333...) = 48.59°.
        let crit = (1.0f64 / (4.0 / 3.0)).asin();
        assert!((crit.to_degrees() - 48.59).abs() < 0.01);
        let inside_below = from_spherical(PI - (crit - 0.01), 0.0);
        let inside_above = from_spherical(PI - (crit + 0.01), 0.0);
        assert!(refract(inside_below, 4.0 / 3.0).is_some());
        assert!(refract(inside_above, 4.0 / 3.0).is_none());
    }

    #[test]
    fn checked_direction_normalises_and_refuses() {
        let w = checked_direction("wi", [0.0, 0.0, 1.0005]).unwrap();
        assert!((w.length() - 1.0).abs() < 1e-15);
        assert!(checked_direction("wi", [0.0, 0.0, 1.01]).is_err());
        assert!(checked_direction("wi", [f64::NAN, 0.0, 1.0]).is_err());
    }
}
