//! The direction pairs the point-wise checks (positivity, reciprocity,
//! isotropy) evaluate: a fixed-seed mix of uniform pairs and of the places
//! where models break: near the mirror direction (sharp lobes), near the
//! incident direction (retro-reflection), at grazing angles and on the normal.

use crate::frame;
use crate::sampling::{self, BvRng};
use glam::DVec3;
use rand::Rng;
use std::f64::consts::PI;

/// Derives an independent stream seed from a base seed and an index
/// (SplitMix64 finaliser), so that parallel work is repeatable.
pub fn stream_seed(seed: u64, index: u64) -> u64 {
    let mut z = seed ^ index.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A uniform direction on the upper hemisphere.
fn uniform_upper(rng: &mut BvRng) -> DVec3 {
    sampling::uniform_hemisphere(sampling::uniform2(rng))
}

/// An upper-hemisphere direction with `cos θ` log-uniform in `[1e-6, 0.05]`:
/// the grazing band where `1/cos θ` factors and `tan θ` overflow.
fn grazing(rng: &mut BvRng) -> DVec3 {
    let z = 10f64.powf(rng.random_range(-6.0..(0.05f64).log10()));
    let phi = rng.random_range(0.0..2.0 * PI);
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// `w` tilted by `angle` in a random plane through it, folded back above the
/// horizon.
fn perturb(w: DVec3, angle: f64, rng: &mut BvRng) -> DVec3 {
    let (t, b) = sampling::basis(w);
    let phi = rng.random_range(0.0..2.0 * PI);
    let (s, c) = angle.sin_cos();
    let mut v = (w * c + (t * phi.cos() + b * phi.sin()) * s).normalize();
    if v.z < 0.0 {
        v.z = -v.z;
    }
    if v.z == 0.0 {
        v.z = 1e-6;
        v = v.normalize();
    }
    v
}

/// `count` fixed-seed pairs `(wi, wo)` of unit directions, both with
/// `z > 0`: 45 % uniform, 20 % near the mirror direction (offset angle
/// log-uniform in 1e-5..0.5 rad), 10 % near the incident direction, 20 % with
/// one or both directions grazing (`cos θ` down to 1e-6), 5 % with one of them
/// on the normal.
pub fn upper_pairs(count: usize, seed: u64) -> Vec<(DVec3, DVec3)> {
    let mut rng = sampling::rng(stream_seed(seed, 0x5EED));
    let mut out = Vec::with_capacity(count);
    for k in 0..count {
        let pair = match k % 20 {
            0..=8 => (uniform_upper(&mut rng), uniform_upper(&mut rng)),
            9..=12 => {
                let wi = uniform_upper(&mut rng);
                let angle = 10f64.powf(rng.random_range(-5.0..(0.5f64).log10()));
                (wi, perturb(frame::reflect(wi), angle, &mut rng))
            }
            13 | 14 => {
                let wi = uniform_upper(&mut rng);
                let angle = 10f64.powf(rng.random_range(-5.0..(0.5f64).log10()));
                (wi, perturb(wi, angle, &mut rng))
            }
            15 => (grazing(&mut rng), uniform_upper(&mut rng)),
            16 => (uniform_upper(&mut rng), grazing(&mut rng)),
            17 => (grazing(&mut rng), grazing(&mut rng)),
            18 => {
                // Grazing mirror pair: where Fresnel and shadowing terms are
                // at their most extreme.
                let wi = grazing(&mut rng);
                (wi, frame::reflect(wi))
            }
            _ => {
                if rng.random::<bool>() {
                    (DVec3::Z, uniform_upper(&mut rng))
                } else {
                    (uniform_upper(&mut rng), DVec3::Z)
                }
            }
        };
        out.push(pair);
    }
    out
}

/// `count` fixed-seed pairs with `wi` above and `wo` below the surface, for the
/// positivity check of transmitting models.
pub fn transmission_pairs(count: usize, seed: u64) -> Vec<(DVec3, DVec3)> {
    let mut rng = sampling::rng(stream_seed(seed, 0x7AA5));
    (0..count)
        .map(|k| {
            let wi = if k % 5 == 4 {
                grazing(&mut rng)
            } else {
                uniform_upper(&mut rng)
            };
            let mut wo = if k % 5 == 3 {
                grazing(&mut rng)
            } else {
                uniform_upper(&mut rng)
            };
            wo.z = -wo.z;
            (wi, wo)
        })
        .collect()
}

/// The mirror image of a direction through the surface plane (`z → −z`).
pub fn below(w: DVec3) -> DVec3 {
    DVec3::new(w.x, w.y, -w.z)
}

/// `count` fixed-seed pairs with both directions below the surface: the
/// mirror images of [`upper_pairs`] (their own seed stream), for the
/// point-wise checks of transmitting models, whose light may come from
/// inside.
pub fn lower_pairs(count: usize, seed: u64) -> Vec<(DVec3, DVec3)> {
    upper_pairs(count, stream_seed(seed, 0xB10))
        .into_iter()
        .map(|(a, b)| (below(a), below(b)))
        .collect()
}

/// θ and φ of a direction in degrees, for reports.
pub fn angles_deg(w: DVec3) -> [f64; 2] {
    let (t, p) = frame::to_spherical(w);
    [t.to_degrees(), p.to_degrees()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_are_unit_and_above_the_horizon() {
        let pairs = upper_pairs(4000, 3);
        assert_eq!(pairs.len(), 4000);
        let mut min_z = 1.0f64;
        for &(a, b) in &pairs {
            for w in [a, b] {
                assert!((w.length() - 1.0).abs() < 1e-12, "{w}");
                assert!(w.z > 0.0, "{w}");
                min_z = min_z.min(w.z);
            }
        }
        // The grazing band is really visited.
        assert!(min_z < 1e-5, "{min_z}");
        for &(a, b) in &transmission_pairs(100, 3) {
            assert!(a.z > 0.0 && b.z < 0.0);
            assert!((a.length() - 1.0).abs() < 1e-12 && (b.length() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn stream_seeds_differ() {
        let s: std::collections::HashSet<u64> = (0..1000).map(|i| stream_seed(7, i)).collect();
        assert_eq!(s.len(), 1000);
    }
}
