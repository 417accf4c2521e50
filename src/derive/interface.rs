//! The marks a plane-of-incidence plot draws for a model of an interface
//! between two media ([`bv_core::Brdf::interface_eta`]): the refracted
//! direction, the critical angle, total internal reflection and Snell's
//! window, in the polar view's signed in-plane angles (see
//! [`super::slices::plane_direction`]: 0 is the normal +z, positive angles
//! lean to the mirror side, |angle| > 90° is below the surface).
//!
//! Every number is `bv_core::optics`'s (Snell's law `ηi sin θi = ηt sin θt`,
//! the critical angle `asin(ηt/ηi)`); this module only places them in the
//! plane.

use bv_core::optics;
use std::f64::consts::{FRAC_PI_2, PI};

/// Where the refracted ray, the critical angle and Snell's window lie in the
/// plane of incidence, for light at `θi ∈ [0°, 180°]` (above 90° the light is
/// below the surface, inside the medium of index `η`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InterfaceMarks {
    /// `η = η_below / η_above` of the interface.
    pub eta: f64,
    /// Whether the light is below the surface (θi > 90°).
    pub light_below: bool,
    /// Refraction angle θt from the normal on the far side (radians), `None`
    /// under total internal reflection or with the light in the surface.
    pub theta_t: Option<f64>,
    /// The refracted direction as a signed in-plane angle (it leaves on the
    /// side away from the light: `π − θt` below the surface for light above,
    /// `+θt` above it for light below). `None` when `theta_t` is.
    pub refracted: Option<f64>,
    /// Critical angle `θc = asin(1/η)` (η > 1) or `asin(η)` (η < 1), measured
    /// from the normal on the denser side; `None` for η = 1 (no interface
    /// optically).
    pub critical: Option<f64>,
    /// Whether the denser medium is below the surface (η > 1).
    pub dense_below: bool,
    /// The signed in-plane angle of the normal on the denser side: `π`
    /// (straight down) when `dense_below`, else 0. Snell's window is the cone
    /// of half-angle `critical` around it: the only directions in the dense
    /// medium that the other medium's light refracts into, and the only
    /// incidence directions from the dense side that are not totally
    /// reflected.
    pub window_axis: f64,
    /// Whether the light is on the denser side beyond the critical angle
    /// (total internal reflection: no refracted ray).
    pub tir: bool,
}

impl InterfaceMarks {
    /// The marks for light at `theta_i` (radians, from +z; values outside
    /// [0, π] are clamped) across an interface of relative index `eta`.
    /// `None` for an index that is not finite and positive (no marks rather
    /// than NaN in a view).
    pub fn new(theta_i: f64, eta: f64) -> Option<Self> {
        if !(eta.is_finite() && eta > 0.0 && theta_i.is_finite()) {
            return None;
        }
        let theta_i = theta_i.clamp(0.0, PI);
        let light_below = theta_i > FRAC_PI_2;
        // The angle from the normal on the light's own side, and the indices
        // of the medium the light is in and of the one it enters.
        let (from_normal, eta_i, eta_t) = if light_below {
            (PI - theta_i, eta, 1.0)
        } else {
            (theta_i, 1.0, eta)
        };
        // Light exactly in the surface (θi = 90°) has no refracted ray: it
        // grazes the interface and belongs to neither side.
        let grazing = (theta_i - FRAC_PI_2).abs() < 1e-12;
        let theta_t = if grazing {
            None
        } else {
            optics::refraction_angle(from_normal, eta_i, eta_t)
        };
        let refracted = theta_t.map(|t| if light_below { t } else { PI - t });
        let dense_below = eta > 1.0;
        let critical = if dense_below {
            optics::critical_angle(eta, 1.0)
        } else {
            optics::critical_angle(1.0, eta)
        };
        let light_dense = light_below == dense_below;
        let tir = !grazing && light_dense && critical.is_some_and(|c| from_normal > c);
        Some(Self {
            eta,
            light_below,
            theta_t,
            refracted,
            critical,
            dense_below,
            window_axis: if dense_below { PI } else { 0.0 },
            tir,
        })
    }

    /// The two signed in-plane angles of the edges of Snell's window (the
    /// critical angle on either side of the dense side's normal), or `None`
    /// without a critical angle.
    pub fn window_edges(&self) -> Option<[f64; 2]> {
        let c = self.critical?;
        Some(if self.dense_below {
            [-(PI - c), PI - c]
        } else {
            [-c, c]
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::derive::slices::plane_direction;
    use bv_core::frame;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn critical_angle_is_the_closed_form() {
        for eta in [1.33, 1.5, 2.42] {
            let m = InterfaceMarks::new(0.3, eta).unwrap();
            // asin(1/η): 48.75° for water, 41.81° for glass, 24.41° for diamond.
            assert!(close(m.critical.unwrap(), (1.0 / eta).asin()));
            assert!(m.dense_below);
            assert_eq!(
                m.window_edges().unwrap(),
                [-(PI - m.critical.unwrap()), PI - m.critical.unwrap()]
            );
        }
        let m = InterfaceMarks::new(0.3, 1.0 / 1.5).unwrap();
        assert!(close(m.critical.unwrap(), (1.0f64 / 1.5).asin()));
        assert!(!m.dense_below);
        assert_eq!(InterfaceMarks::new(0.3, 1.0).unwrap().critical, None);
    }

    #[test]
    fn refracted_direction_obeys_snell_and_matches_bv_core() {
        let phi_i = 0.4;
        for eta in [1.33, 1.5, 2.42, 0.8] {
            for deg in [
                0.0, 10.0, 30.0, 60.0, 89.0, 91.0, 120.0, 150.0, 170.0, 180.0,
            ] {
                let ti = f64::to_radians(deg);
                let m = InterfaceMarks::new(ti, eta).unwrap();
                let wi = frame::from_spherical(ti, phi_i);
                match (m.refracted, frame::refract(wi, eta)) {
                    (Some(a), Some(t)) => {
                        let wo = plane_direction(a, phi_i);
                        assert!((wo - t).length() < 1e-9, "{eta} {deg}: {wo} vs {t}");
                        // Snell's law with the indices of either side.
                        let (ni, nt) = if deg > 90.0 { (eta, 1.0) } else { (1.0, eta) };
                        let si = ti.sin();
                        let st = m.theta_t.unwrap().sin();
                        assert!((ni * si - nt * st).abs() < 1e-12);
                        assert!(!m.tir);
                    }
                    (None, None) => assert!(m.tir, "{eta} {deg}"),
                    (a, t) => panic!("{eta} {deg}: marks {a:?}, bv-core {t:?}"),
                }
            }
        }
    }

    #[test]
    fn total_internal_reflection_beyond_the_critical_angle_from_inside() {
        // Glass: θc = 41.81°; light inside at 40° from −z refracts, at 45° not.
        let inside = |deg: f64| InterfaceMarks::new((180.0 - deg).to_radians(), 1.5).unwrap();
        assert!(!inside(40.0).tir && inside(40.0).refracted.is_some());
        assert!(inside(45.0).tir && inside(45.0).refracted.is_none());
        // From outside there is never TIR into the denser medium.
        assert!(!InterfaceMarks::new(89.0f64.to_radians(), 1.5).unwrap().tir);
    }

    #[test]
    fn bad_input_gives_no_marks_and_the_horizon_no_ray() {
        assert!(InterfaceMarks::new(0.3, f64::NAN).is_none());
        assert!(InterfaceMarks::new(0.3, 0.0).is_none());
        assert!(InterfaceMarks::new(f64::NAN, 1.5).is_none());
        let m = InterfaceMarks::new(FRAC_PI_2, 1.5).unwrap();
        assert_eq!(m.refracted, None);
        assert!(!m.tir);
        assert!(m.critical.unwrap().is_finite());
    }
}
