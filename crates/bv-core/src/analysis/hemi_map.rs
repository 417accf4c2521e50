//! The lobe's shape seen from above (LECTURE.md N4): for a fixed `wi`, the
//! shown value of `f(wi, ·)` (mean of r, g, b, optionally × cos θo) over
//! the outgoing hemisphere on Lambert's azimuthal equal-area disc (the
//! parameterisation of [`super::reciprocity_map`]: centre the normal, rim
//! the horizon, equal areas equal solid angles), its peak, and the contour
//! where it falls to a fraction of the peak. Phong's lobe is a circle about
//! the mirror direction there, Blinn-Phong's an ellipse narrowed out of the
//! plane of incidence, and an anisotropic lobe turns with its tangent.

use super::reciprocity_map::disc_to_hemisphere;
use crate::{Brdf, mean_rgb};
use glam::{DVec2, DVec3};

/// Most pixels per side accepted.
pub const MAX_SIZE: usize = 2048;

/// A map of the shown value over the outgoing hemisphere.
#[derive(Debug, Clone, PartialEq)]
pub struct HemiMap {
    /// Pixels per side (the image is square).
    pub size: usize,
    /// Row-major values, top row first (`+y` up); `None` outside the disc.
    pub values: Vec<Option<f64>>,
    /// The largest value.
    pub peak: f64,
    /// Where it is (pixel centre, disc coordinates).
    pub peak_at: DVec2,
    /// Values that were not finite (drawn as 0).
    pub non_finite: usize,
}

/// The disc coordinates of the centre of pixel `(i, j)` of a `size`² map.
pub fn pixel_centre(size: usize, i: usize, j: usize) -> DVec2 {
    let s = 2.0 / size as f64;
    DVec2::new(-1.0 + (i as f64 + 0.5) * s, 1.0 - (j as f64 + 0.5) * s)
}

/// `f(wi, ·)` (× cos θo with `cosine`) on a `size`² equal-area map
/// (`size` clamped to 8..=[`MAX_SIZE`]).
pub fn hemi_map(brdf: &dyn Brdf, wi: DVec3, size: usize, cosine: bool) -> HemiMap {
    let size = size.clamp(8, MAX_SIZE);
    let mut values = Vec::with_capacity(size * size);
    let (mut peak, mut peak_at, mut non_finite) = (0.0, DVec2::ZERO, 0);
    for j in 0..size {
        for i in 0..size {
            let p = pixel_centre(size, i, j);
            let Some(wo) = disc_to_hemisphere(p) else {
                values.push(None);
                continue;
            };
            let mut v = mean_rgb(brdf.eval(wi, wo));
            if cosine {
                v *= wo.z;
            }
            if !v.is_finite() {
                non_finite += 1;
                v = 0.0;
            }
            let v = v.max(0.0);
            if v > peak {
                peak = v;
                peak_at = p;
            }
            values.push(Some(v));
        }
    }
    HemiMap {
        size,
        values,
        peak,
        peak_at,
        non_finite,
    }
}

impl HemiMap {
    /// The value at pixel `(i, j)` (0 outside the disc).
    fn at(&self, i: usize, j: usize) -> f64 {
        self.values[j * self.size + i].unwrap_or(0.0)
    }

    /// The contour where the value crosses `level` (marching squares over
    /// the pixel centres, crossings placed by linear interpolation), as line
    /// segments in disc coordinates. The saddle cases are resolved by the
    /// cell's mean.
    pub fn contour(&self, level: f64) -> Vec<[DVec2; 2]> {
        let n = self.size;
        let mut out = Vec::new();
        if n < 2 || !level.is_finite() {
            return out;
        }
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                // Corners counter-clockwise from the top left:
                // a (i, j), b (i+1, j), c (i+1, j+1), d (i, j+1).
                let pa = pixel_centre(n, i, j);
                let pb = pixel_centre(n, i + 1, j);
                let pc = pixel_centre(n, i + 1, j + 1);
                let pd = pixel_centre(n, i, j + 1);
                let (a, b, c, d) = (
                    self.at(i, j),
                    self.at(i + 1, j),
                    self.at(i + 1, j + 1),
                    self.at(i, j + 1),
                );
                let cross = |p: DVec2, q: DVec2, u: f64, v: f64| {
                    let t = ((level - u) / (v - u)).clamp(0.0, 1.0);
                    p + (q - p) * t
                };
                let above = [a >= level, b >= level, c >= level, d >= level];
                // Edges: ab (top), bc (right), cd (bottom), da (left).
                let mut pts: Vec<DVec2> = Vec::with_capacity(4);
                if above[0] != above[1] {
                    pts.push(cross(pa, pb, a, b));
                }
                if above[1] != above[2] {
                    pts.push(cross(pb, pc, b, c));
                }
                if above[2] != above[3] {
                    pts.push(cross(pc, pd, c, d));
                }
                if above[3] != above[0] {
                    pts.push(cross(pd, pa, d, a));
                }
                match pts.len() {
                    2 => out.push([pts[0], pts[1]]),
                    4 => {
                        // A saddle: the crossings pair up around the corners
                        // on the side the cell's mean is on.
                        let centre_above = (a + b + c + d) / 4.0 >= level;
                        if centre_above == above[0] {
                            out.push([pts[0], pts[1]]);
                            out.push([pts[2], pts[3]]);
                        } else {
                            out.push([pts[0], pts[3]]);
                            out.push([pts[1], pts[2]]);
                        }
                    }
                    _ => {}
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;
    use crate::analysis::reciprocity_map::hemisphere_to_disc;
    use serde_json::json;

    fn model(id: &str, p: serde_json::Value) -> Box<dyn Brdf> {
        ModelSpec::from_json(id, &p).unwrap().build().unwrap()
    }

    /// Lambert's map is flat inside the disc and empty outside; × cos θo it
    /// peaks at the centre.
    #[test]
    fn a_diffuse_map_is_flat_and_peaks_at_the_normal_with_the_cosine() {
        let f = model("lambert", json!({"albedo": 0.5}));
        let wi = DVec3::Z;
        let m = hemi_map(f.as_ref(), wi, 64, false);
        let inside: Vec<f64> = m.values.iter().flatten().copied().collect();
        let outside = m.values.iter().filter(|v| v.is_none()).count();
        // π/4 of the square is disc.
        let frac = inside.len() as f64 / (64.0 * 64.0);
        assert!((frac - std::f64::consts::FRAC_PI_4).abs() < 0.02, "{frac}");
        assert_eq!(inside.len() + outside, 64 * 64);
        assert!(
            inside
                .iter()
                .all(|v| (v - 0.5 / std::f64::consts::PI).abs() < 1e-12)
        );
        let c = hemi_map(f.as_ref(), wi, 64, true);
        assert!(c.peak_at.length() < 2.0 / 64.0 * 1.5, "{}", c.peak_at);
    }

    /// Classical Phong's lobe is a cone about the mirror direction: its half
    /// maximum contour's points all lie at the same angle from ωr, the
    /// angle where cos^e falls to ½ (the 1/cos θi factor is constant over
    /// ωo), within a pixel's angle.
    #[test]
    fn phongs_half_maximum_contour_is_a_circle_about_the_mirror_direction() {
        let e = 40.0;
        let f = model("phong", json!({"kd": 0.0, "ks": 1.0, "e": e}));
        let ti = 30f64.to_radians();
        let wi = DVec3::new(ti.sin(), 0.0, ti.cos());
        let wr = DVec3::new(-wi.x, -wi.y, wi.z);
        let m = hemi_map(f.as_ref(), wi, 400, false);
        assert!((m.peak_at - hemisphere_to_disc(wr)).length() < 0.02);
        let half = 0.5f64.powf(1.0 / e).acos();
        let segs = m.contour(0.5 * m.peak);
        assert!(segs.len() > 50, "{}", segs.len());
        for s in &segs {
            for p in s {
                let w = disc_to_hemisphere(*p).unwrap().normalize();
                let a = w.dot(wr).clamp(-1.0, 1.0).acos();
                assert!(
                    (a - half).abs() < 0.01,
                    "{} vs {}",
                    a.to_degrees(),
                    half.to_degrees()
                );
            }
        }
    }

    /// The contour of a level above everything is empty; a map with a
    /// non-finite value counts it and draws it as 0.
    #[test]
    fn contours_and_bad_values() {
        let f = model("lambert", json!({}));
        let m = hemi_map(f.as_ref(), DVec3::Z, 32, false);
        assert!(m.contour(10.0).is_empty());
        assert!(m.contour(f64::NAN).is_empty());
        assert_eq!(m.non_finite, 0);
    }
}
