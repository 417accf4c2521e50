//! Slices of a BRDF evaluated directly from the built evaluator (no mesh in
//! between, so a plot's hover readout is the model's exact value): the plane
//! of incidence and the half/difference-angle slices the plots, overlays,
//! figures and `bv slice` draw or print.

use bv_core::frame::{self, HalfDiff};
use bv_core::{Brdf, Rgb};
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};

/// The outgoing direction at signed angle `theta_s` (radians) in the plane of
/// incidence of light at azimuth `phi_i`: positive angles lean to the mirror
/// side (azimuth φi + π), negative ones towards the light. |θs| > π/2 goes below
/// the surface (transmission).
pub fn plane_direction(theta_s: f64, phi_i: f64) -> DVec3 {
    let mut w = if theta_s >= 0.0 {
        frame::from_spherical(theta_s, phi_i + PI)
    } else {
        frame::from_spherical(-theta_s, phi_i)
    };
    // cos(π/2) is 6e-17, not 0: at the horizon a model with 1/cos θo would
    // return an enormous value for a direction that is meant to lie in the
    // surface (where reflection models are 0 by convention).
    if (theta_s.abs() - FRAC_PI_2).abs() < 1e-12 {
        w.z = 0.0;
    }
    w
}

/// The signed in-plane angle of the light itself: it sits on the negative side.
pub fn incident_signed_angle(theta_i: f64) -> f64 {
    -theta_i
}

/// The value a curve shows: `f` (channel mean) or `f cos θo`.
pub fn shown_value(f: Rgb, wo: DVec3, cosine: bool) -> f64 {
    let v = bv_core::mean_rgb(f);
    let v = if cosine { v * wo.z.abs() } else { v };
    if v.is_finite() { v.max(0.0) } else { 0.0 }
}

/// One sampled point of a slice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Abscissa in radians (signed θo, θh or θd).
    pub x: f64,
    /// The shown value (see [`shown_value`]), 1/sr.
    pub value: f64,
    /// The full RGB value of `f` (without cosine).
    pub rgb: Rgb,
}

/// How far short of the horizon a reflection curve stops: the horizon itself
/// is 0 by convention, and a curve that drops to it draws a misleading wall.
pub const HORIZON_GAP: f64 = 1e-3;

/// `f` in the plane of incidence at `n + 1` signed angles spanning the upper
/// half (−90°..90°, stopping [`HORIZON_GAP`] short of the horizon) or, for
/// transmitting models, the whole circle.
pub fn plane_of_incidence(
    brdf: &dyn Brdf,
    theta_i: f64,
    phi_i: f64,
    n: usize,
    cosine: bool,
) -> Vec<Sample> {
    let wi = frame::from_spherical(theta_i, phi_i);
    let span = if brdf.transmits() {
        PI
    } else {
        FRAC_PI_2 - HORIZON_GAP
    };
    let n = n.max(2);
    (0..=n)
        .map(|k| {
            let x = -span + 2.0 * span * k as f64 / n as f64;
            let wo = plane_direction(x, phi_i);
            let rgb = brdf.eval(wi, wo);
            Sample {
                x,
                value: shown_value(rgb, wo, cosine),
                rgb,
            }
        })
        .collect()
}

/// The exact value at one signed in-plane angle (the hover readout).
pub fn plane_value(brdf: &dyn Brdf, theta_i: f64, phi_i: f64, x: f64, cosine: bool) -> Sample {
    let wi = frame::from_spherical(theta_i, phi_i);
    let wo = plane_direction(x, phi_i);
    let rgb = brdf.eval(wi, wo);
    Sample {
        x,
        value: shown_value(rgb, wo, cosine),
        rgb,
    }
}

/// Which half/difference angle varies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HalfDiffAxis {
    /// θh varies, θd fixed.
    ThetaH,
    /// θd varies, θh fixed.
    ThetaD,
}

/// The azimuth of the difference vector used for half/difference slices: 90°,
/// the usual choice for MERL-style plots (it keeps wi and wo on either side of
/// the plane containing h and the normal).
pub const PHI_D: f64 = FRAC_PI_2;

/// The pair of directions at half/difference angles (φh = 0, φd = 90°).
pub fn half_diff_pair(theta_h: f64, theta_d: f64) -> (DVec3, DVec3) {
    frame::from_half_diff(HalfDiff {
        theta_h,
        phi_h: 0.0,
        theta_d,
        phi_d: PHI_D,
    })
}

/// `f` along θh ∈ [0°, 90°) at fixed θd, or along θd at fixed θh. Pairs where
/// either direction is below the horizon give the model's value there (0 for
/// reflection models).
pub fn half_diff_slice(
    brdf: &dyn Brdf,
    axis: HalfDiffAxis,
    fixed: f64,
    n: usize,
    cosine: bool,
) -> Vec<Sample> {
    let n = n.max(2);
    (0..=n)
        .map(|k| {
            // Stop just short of 90°, where wi or wo reach the horizon.
            let x = (FRAC_PI_2 - 1e-4) * k as f64 / n as f64;
            half_diff_value(brdf, axis, fixed, x, cosine)
        })
        .collect()
}

/// The exact value at one point of a half/difference slice.
pub fn half_diff_value(
    brdf: &dyn Brdf,
    axis: HalfDiffAxis,
    fixed: f64,
    x: f64,
    cosine: bool,
) -> Sample {
    let (th, td) = match axis {
        HalfDiffAxis::ThetaH => (x, fixed),
        HalfDiffAxis::ThetaD => (fixed, x),
    };
    let (wi, wo) = half_diff_pair(th, td);
    let rgb = brdf.eval(wi, wo);
    Sample {
        x,
        value: shown_value(rgb, wo, cosine),
        rgb,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_directions_lie_in_the_plane_of_incidence() {
        let phi_i = 0.7;
        let wi = frame::from_spherical(0.5, phi_i);
        let n = DVec3::Z;
        let plane_normal = wi.cross(n).normalize();
        for &x in &[-1.4, -0.3, 0.0, 0.4, 1.5] {
            let wo = plane_direction(x, phi_i);
            assert!(wo.dot(plane_normal).abs() < 1e-12);
            assert!((frame::to_spherical(wo).0 - f64::abs(x)).abs() < 1e-12);
        }
        // The horizon is exactly in the surface.
        assert_eq!(plane_direction(FRAC_PI_2, phi_i).z, 0.0);
        assert_eq!(plane_direction(-FRAC_PI_2, phi_i).z, 0.0);
        // The mirror direction is at +θi.
        let r = plane_direction(0.5, phi_i);
        assert!((r - frame::reflect(wi)).length() < 1e-12);
        // The light itself is at −θi.
        assert!((plane_direction(incident_signed_angle(0.5), phi_i) - wi).length() < 1e-12);
    }

    #[test]
    fn lambert_slices_are_flat() {
        let b = bv_core::ModelSpec::new("lambert").unwrap().build().unwrap();
        let f = 0.5 / PI;
        let s = plane_of_incidence(b.as_ref(), 0.3, 0.0, 32, false);
        assert_eq!(s.len(), 33);
        // The curve stops just short of the horizon, where the model is 0.
        assert!((s[0].x + FRAC_PI_2 - HORIZON_GAP).abs() < 1e-12);
        for p in &s {
            assert!((p.value - f).abs() < 1e-12);
        }
        let c = plane_of_incidence(b.as_ref(), 0.3, 0.0, 32, true);
        for p in &c {
            assert!((p.value - f * p.x.cos()).abs() < 1e-12);
        }
        let h = half_diff_slice(b.as_ref(), HalfDiffAxis::ThetaH, 0.2, 16, false);
        // θh + θd < 90° keeps both directions above the horizon (for φd = 90°,
        // cos θo = cos θh cos θd, so it is enough that both are below 90°).
        for p in &h[..15] {
            assert!((p.value - f).abs() < 1e-12, "{p:?}");
        }
    }

    #[test]
    fn half_diff_pair_matches_its_angles() {
        let (wi, wo) = half_diff_pair(0.4, 0.3);
        let hd = frame::to_half_diff(wi, wo).unwrap();
        assert!((hd.theta_h - 0.4).abs() < 1e-12);
        assert!((hd.theta_d - 0.3).abs() < 1e-12);
        assert!((hd.phi_d - PHI_D).abs() < 1e-12);
    }
}
