//! Sampling helpers shared by the models and the analysis: warps from the unit
//! square to directions, and a fixed-seed random source.

use glam::{DVec2, DVec3};
use rand::{Rng, SeedableRng};
use std::f64::consts::{FRAC_1_PI, PI};

/// The deterministic generator used wherever bv draws random numbers
/// (benchmark pairs, Monte Carlo estimates), so that every run is repeatable.
pub type BvRng = rand_pcg::Pcg64Mcg;

/// A generator from a seed.
pub fn rng(seed: u64) -> BvRng {
    BvRng::seed_from_u64(seed)
}

/// A uniform point in [0,1)².
pub fn uniform2(rng: &mut BvRng) -> DVec2 {
    DVec2::new(rng.random::<f64>(), rng.random::<f64>())
}

/// Cosine-weighted direction on the upper hemisphere (Malley's method: a
/// concentric disc sample lifted to the hemisphere).
pub fn cosine_hemisphere(u: DVec2) -> DVec3 {
    let d = concentric_disc(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    DVec3::new(d.x, d.y, z)
}

/// Density of [`cosine_hemisphere`]: cos θ / π above the horizon, 0 below.
pub fn cosine_hemisphere_pdf(w: DVec3) -> f64 {
    if w.z > 0.0 { w.z * FRAC_1_PI } else { 0.0 }
}

/// Uniform direction on the upper hemisphere.
pub fn uniform_hemisphere(u: DVec2) -> DVec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Shirley–Chiu concentric map from the unit square to the unit disc.
pub fn concentric_disc(u: DVec2) -> DVec2 {
    let o = 2.0 * u - DVec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return DVec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, PI / 4.0 * (o.y / o.x))
    } else {
        (o.y, PI / 2.0 - PI / 4.0 * (o.x / o.y))
    };
    DVec2::new(r * theta.cos(), r * theta.sin())
}

/// Orthonormal basis `(t, b)` around a unit `n` (Duff et al. 2017), for
/// sampling lobes centred on an arbitrary axis.
pub fn basis(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// Direction around `axis` with density `(e+1)/(2π) cos^e α` over the
/// hemisphere centred on the axis (α the angle to it): the Phong lobe warp.
pub fn power_cosine(axis: DVec3, e: f64, u: DVec2) -> DVec3 {
    let cos_a = u.x.powf(1.0 / (e + 1.0));
    let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    let (t, b) = basis(axis);
    (t * (sin_a * phi.cos()) + b * (sin_a * phi.sin()) + axis * cos_a).normalize()
}

/// Density of [`power_cosine`] at `w`.
pub fn power_cosine_pdf(axis: DVec3, e: f64, w: DVec3) -> f64 {
    let c = axis.dot(w);
    if c <= 0.0 {
        0.0
    } else {
        (e + 1.0) / (2.0 * PI) * c.powf(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_samples_are_on_the_hemisphere() {
        let mut r = rng(1);
        for _ in 0..1000 {
            let w = cosine_hemisphere(uniform2(&mut r));
            assert!((w.length() - 1.0).abs() < 1e-12 && w.z >= 0.0);
        }
    }

    #[test]
    fn power_cosine_pdf_matches_sampler() {
        // E[g/pdf] = ∫ g over the axis hemisphere for g = (axis·w)² z: a smooth
        // integrand whose integral we get by quadrature below.
        let axis = DVec3::new(0.3, -0.2, 0.9).normalize();
        let mut r = rng(7);
        let n = 200_000;
        let mut sum = 0.0;
        for _ in 0..n {
            let w = power_cosine(axis, 3.0, uniform2(&mut r));
            let g = axis.dot(w).powi(2);
            sum += g / power_cosine_pdf(axis, 3.0, w);
        }
        let est = sum / n as f64;
        // ∫ cos²α dω over a hemisphere = 2π/3.
        assert!((est - 2.0 * PI / 3.0).abs() < 0.02, "{est}");
    }

    #[test]
    fn basis_is_orthonormal() {
        for n in [DVec3::Z, -DVec3::Z, DVec3::new(0.6, 0.0, 0.8), DVec3::X] {
            let (t, b) = basis(n);
            assert!(t.dot(b).abs() < 1e-12 && t.dot(n).abs() < 1e-12 && b.dot(n).abs() < 1e-12);
            assert!((t.length() - 1.0).abs() < 1e-12 && (b.length() - 1.0).abs() < 1e-12);
        }
    }
}
