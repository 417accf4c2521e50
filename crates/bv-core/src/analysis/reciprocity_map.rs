//! Where a model breaks Helmholtz reciprocity, as an image: for a fixed `wi`,
//! `|f(wi, wo) − f(wo, wi)| / max f` over the outgoing hemisphere (the seed's
//! "BRDF Property 2"; the classical Phong of the lecture is the example that
//! fails it).
//!
//! # Parameterisation
//! The map is a `width × height` image of the square `[−1, 1]²`; pixel
//! `(i, j)` (column `i` from the left, row `j` from the top) has its centre at
//! `x = −1 + (i + ½)·2/width`, `y = 1 − (j + ½)·2/height` (so `+y` is up, as
//! the hemisphere is seen from above with the tangent `+x` to the right).
//! Inside the unit disc, `(x, y)` is lifted to the hemisphere by Lambert's
//! azimuthal equal-area projection: with `r² = x² + y²`,
//! `wo = (x √(2 − r²), y √(2 − r²), 1 − r²)`. So the disc's rim is the
//! horizon, its centre the normal, the azimuth is preserved (φ = atan2(y, x))
//! and every pixel covers the same solid angle (`2π / π` per unit of disc
//! area, i.e. `2 · (2/width)(2/height)` sr). Pixels outside the disc hold
//! `None`.

use crate::Brdf;
use glam::{DVec2, DVec3};

/// The direction of a point of the unit disc under the equal-area lift (see
/// the module docs); `None` outside the closed disc.
pub fn disc_to_hemisphere(p: DVec2) -> Option<DVec3> {
    let r2 = p.length_squared();
    if r2 > 1.0 || !r2.is_finite() {
        return None;
    }
    let s = (2.0 - r2).sqrt();
    Some(DVec3::new(p.x * s, p.y * s, 1.0 - r2))
}

/// The inverse of [`disc_to_hemisphere`] for a unit `w` with `w.z ≥ 0`:
/// `r = √(1 − z)` along `w`'s azimuth.
pub fn hemisphere_to_disc(w: DVec3) -> DVec2 {
    let r = (1.0 - w.z).clamp(0.0, 1.0).sqrt();
    let l = (w.x * w.x + w.y * w.y).sqrt();
    if l > 0.0 {
        DVec2::new(w.x, w.y) * (r / l)
    } else {
        DVec2::ZERO
    }
}

/// The largest relative difference of the map and where it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Worst {
    /// `|f(wi,wo) − f(wo,wi)| / max_f` there (largest channel).
    pub value: f64,
    /// Pixel column.
    pub i: usize,
    /// Pixel row.
    pub j: usize,
    /// The outgoing direction of that pixel.
    pub wo: DVec3,
}

/// The reciprocity error of one model at one `wi` over the outgoing
/// hemisphere, on the equal-area disc of the module docs.
#[derive(Debug, Clone, PartialEq)]
pub struct ReciprocityMap {
    /// Image width (pixels).
    pub width: usize,
    /// Image height (pixels).
    pub height: usize,
    /// The fixed incident direction.
    pub wi: DVec3,
    /// Row-major values `values[j * width + i]`: the largest channel of
    /// `|f(wi,wo) − f(wo,wi)|` divided by `max_f`; `None` outside the disc
    /// and where either value is not finite.
    pub values: Vec<Option<f64>>,
    /// Largest finite channel of `f(wi, wo)` and `f(wo, wi)` over the map
    /// (1/sr).
    pub max_f: f64,
    /// Largest value (`None` when there is no pixel inside the disc).
    pub worst: Option<Worst>,
    /// Pixels inside the disc where either order was not finite.
    pub non_finite: usize,
}

impl ReciprocityMap {
    /// The outgoing direction at the centre of pixel `(i, j)`, `None` outside
    /// the disc.
    pub fn direction(&self, i: usize, j: usize) -> Option<DVec3> {
        pixel_direction(self.width, self.height, i, j)
    }

    /// The value at pixel `(i, j)`.
    pub fn at(&self, i: usize, j: usize) -> Option<f64> {
        self.values.get(j * self.width + i).copied().flatten()
    }
}

fn pixel_direction(width: usize, height: usize, i: usize, j: usize) -> Option<DVec3> {
    let x = -1.0 + (i as f64 + 0.5) * 2.0 / width as f64;
    let y = 1.0 - (j as f64 + 0.5) * 2.0 / height as f64;
    disc_to_hemisphere(DVec2::new(x, y))
}

/// The [`ReciprocityMap`] of `brdf` at `wi` on a `width × height` image. A
/// zero-sized image gives an empty map; `max_f = 0` (f vanishes everywhere)
/// gives 0 at every pixel.
pub fn reciprocity_map(brdf: &dyn Brdf, wi: DVec3, width: usize, height: usize) -> ReciprocityMap {
    let mut diffs = Vec::with_capacity(width * height);
    let mut max_f = 0.0f64;
    let mut non_finite = 0;
    for j in 0..height {
        for i in 0..width {
            let d = pixel_direction(width, height, i, j).and_then(|wo| {
                let a = brdf.eval(wi, wo);
                let b = brdf.eval(wo, wi);
                if a.is_finite() && b.is_finite() {
                    max_f = max_f.max(a.max_element()).max(b.max_element());
                    Some((a - b).abs().max_element())
                } else {
                    non_finite += 1;
                    None
                }
            });
            diffs.push(d);
        }
    }
    let scale = if max_f > 0.0 { 1.0 / max_f } else { 0.0 };
    let mut worst: Option<Worst> = None;
    let values: Vec<Option<f64>> = diffs
        .into_iter()
        .enumerate()
        .map(|(p, d)| {
            let v = d.map(|d| d * scale);
            if let Some(v) = v
                && worst.is_none_or(|w| v > w.value)
            {
                let (i, j) = (p % width, p / width);
                worst = pixel_direction(width, height, i, j).map(|wo| Worst { value: v, i, j, wo });
            }
            v
        })
        .collect();
    ReciprocityMap {
        width,
        height,
        wi,
        values,
        max_f,
        worst,
        non_finite,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;
    use crate::frame::from_spherical;
    use serde_json::json;

    fn model(id: &str, p: serde_json::Value) -> Box<dyn Brdf> {
        ModelSpec::from_json(id, &p).unwrap().build().unwrap()
    }

    #[test]
    fn equal_area_lift_round_trips_and_preserves_area() {
        for (x, y) in [(0.0, 0.0), (0.3, -0.4), (-0.99, 0.0), (0.6, 0.8)] {
            let w = disc_to_hemisphere(DVec2::new(x, y)).unwrap();
            assert!((w.length() - 1.0).abs() < 1e-15 && w.z >= 0.0);
            let p = hemisphere_to_disc(w);
            assert!((p - DVec2::new(x, y)).length() < 1e-15);
        }
        assert!(disc_to_hemisphere(DVec2::new(0.8, 0.8)).is_none());
        // The disc of radius r maps onto the cap z ≥ 1 − r², of solid angle
        // 2π r²: proportional to the disc's area π r².
        let r = 0.5f64;
        assert!((disc_to_hemisphere(DVec2::new(r, 0.0)).unwrap().z - (1.0 - r * r)).abs() < 1e-15);
    }

    #[test]
    fn reciprocal_models_give_zero_everywhere() {
        let wi = from_spherical(0.7, 0.4);
        for (id, p) in [
            ("lambert", json!({"albedo": [0.2, 0.5, 0.8]})),
            ("modified-phong", json!({"kd": 0.3, "ks": 0.5, "e": 40.0})),
        ] {
            let m = reciprocity_map(model(id, p).as_ref(), wi, 64, 64);
            assert!(m.max_f > 0.0);
            let inside = m.values.iter().filter(|v| v.is_some()).count();
            // The disc covers π/4 of the square.
            assert!((inside as f64 / 4096.0 - std::f64::consts::FRAC_PI_4).abs() < 0.02);
            assert!(m.values.iter().flatten().all(|&v| v <= 1e-12), "{id}");
            assert!(m.worst.unwrap().value <= 1e-12);
            assert_eq!(m.non_finite, 0);
        }
    }

    #[test]
    fn classical_phong_hand_values() {
        // kd = 0, e = 1, wi on the normal: f(wi, wo) = ks (R(wo)·wi)/cos θi
        // = ks cos θo, while f(wo, wi) = ks (R(wi)·wo)/cos θo = ks. So
        // |Δ| = ks (1 − cos θo), max f = ks, and the map is 1 − z = r²: zero
        // at the centre, largest at the rim pixel farthest from the centre.
        let b = model("phong", json!({"kd": 0.0, "ks": 0.4, "e": 1.0}));
        let n = 32;
        let m = reciprocity_map(b.as_ref(), DVec3::Z, n, n);
        assert!((m.max_f - 0.4).abs() < 1e-12, "{}", m.max_f);
        let mut r2_max = 0.0f64;
        for j in 0..n {
            for i in 0..n {
                let x = -1.0 + (i as f64 + 0.5) * 2.0 / n as f64;
                let y = 1.0 - (j as f64 + 0.5) * 2.0 / n as f64;
                let r2 = x * x + y * y;
                match m.at(i, j) {
                    Some(v) => {
                        assert!((v - r2).abs() < 1e-12, "({i},{j}): {v} vs {r2}");
                        r2_max = r2_max.max(r2);
                    }
                    None => assert!(r2 > 1.0),
                }
            }
        }
        let w = m.worst.unwrap();
        assert!((w.value - r2_max).abs() < 1e-12 && w.value > 0.9);

        // A general pair: kd = 0.1, ks = 0.5, e = 8, wi at 40°. At any pixel
        // |Δ| = ks lobe |1/cos θi − 1/cos θo| with lobe = max(0, R(wo)·wi)^e.
        let b = model("phong", json!({"kd": 0.1, "ks": 0.5, "e": 8.0}));
        let wi = from_spherical(40f64.to_radians(), 0.0);
        let m = reciprocity_map(b.as_ref(), wi, 48, 48);
        let mut checked = 0;
        for j in 0..48 {
            for i in 0..48 {
                let Some(wo) = m.direction(i, j) else {
                    assert!(m.at(i, j).is_none());
                    continue;
                };
                let lobe = (-wo.x * wi.x - wo.y * wi.y + wo.z * wi.z).max(0.0).powi(8);
                let hand = 0.5 * lobe * (1.0 / wi.z - 1.0 / wo.z).abs();
                let got = m.at(i, j).unwrap() * m.max_f;
                assert!(
                    (got - hand).abs() <= 1e-12 * hand.max(1.0),
                    "({i},{j}): {got} vs {hand}"
                );
                checked += 1;
            }
        }
        assert!(checked > 1500);
        // Nonzero away from the normal, zero where cos θo = cos θi.
        assert!(m.worst.unwrap().value > 0.1);
    }
}
