//! Lobe meshes (issue 2, item 7): the surface `r(wo) · wo` over the outgoing
//! hemisphere (the whole sphere for transmitting models), where `r` is `f` or
//! `f · cos θo`, on a linear or logarithmic scale. The 3D view and the headless
//! export draw this mesh; it carries a per-vertex value for colouring.

use crate::{Brdf, DeltaLobe, Rgb, frame, mean_rgb};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

/// How a value becomes a radius.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum RadiusScale {
    /// `r = v`.
    #[default]
    Linear,
    /// `r = ln(1 + v)`: monotone, linear near 0, and keeps a sharp peak and a
    /// dim diffuse floor on one screen without a free parameter.
    Log,
}

impl RadiusScale {
    /// The radius of a (non-negative) value.
    #[inline]
    pub fn apply(self, v: f64) -> f64 {
        match self {
            RadiusScale::Linear => v,
            RadiusScale::Log => v.ln_1p(),
        }
    }
}

/// What to build.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobeOptions {
    /// Rings from the pole to the horizon (to the south pole on a full sphere).
    pub n_theta: usize,
    /// Vertices around each ring.
    pub n_phi: usize,
    /// Multiply by `cos θo` (the reflected radiance of a unit irradiance).
    pub cosine: bool,
    /// Linear or logarithmic radius.
    pub scale: RadiusScale,
}

impl Default for LobeOptions {
    fn default() -> Self {
        Self {
            n_theta: 64,
            n_phi: 128,
            cosine: false,
            scale: RadiusScale::Linear,
        }
    }
}

/// A triangle mesh of a lobe, ready to upload (f32, indexed).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LobeMesh {
    /// Vertex positions `r · wo` (local frame, +z the normal).
    pub positions: Vec<[f32; 3]>,
    /// Smooth vertex normals (area-weighted face normals).
    pub normals: Vec<[f32; 3]>,
    /// Per-vertex value before scaling: `f` or `f cos θo`, per channel.
    pub values: Vec<[f32; 3]>,
    /// Triangle list, counter-clockwise seen from outside.
    pub indices: Vec<u32>,
    /// Rings in the grid (`n_theta + 1` rows of vertices).
    pub n_theta: usize,
    /// Vertices per ring.
    pub n_phi: usize,
    /// Whether the mesh covers the whole sphere.
    pub full_sphere: bool,
    /// Largest channel-mean value over the vertices (unscaled).
    pub max_value: f64,
    /// Largest radius (scaled), for framing the camera.
    pub max_radius: f64,
    /// The model's delta lobes for this incident direction.
    pub deltas: Vec<DeltaLobe>,
}

impl LobeMesh {
    /// The direction of grid vertex `(i, j)`.
    pub fn direction(&self, i: usize, j: usize) -> DVec3 {
        grid_direction(i, j, self.n_theta, self.n_phi, self.full_sphere)
    }
}

fn grid_direction(i: usize, j: usize, n_theta: usize, n_phi: usize, full: bool) -> DVec3 {
    let theta_max = if full { PI } else { FRAC_PI_2 };
    let theta = theta_max * i as f64 / n_theta as f64;
    let phi = 2.0 * PI * j as f64 / n_phi as f64;
    frame::from_spherical(theta, phi)
}

/// Builds the lobe of `brdf` for light from `wi`. Resolution below 2×3 is raised
/// to it. Evaluation runs in parallel over rings for large grids.
pub fn build(brdf: &dyn Brdf, wi: DVec3, opts: &LobeOptions) -> LobeMesh {
    let n_theta = opts.n_theta.max(2);
    let n_phi = opts.n_phi.max(3);
    let full = brdf.transmits();
    let rows = n_theta + 1;
    let count = rows * n_phi;

    let mut values = vec![[0f32; 3]; count];
    let mut positions = vec![[0f32; 3]; count];
    let fill_row = |i: usize, vals: &mut [[f32; 3]], pos: &mut [[f32; 3]]| {
        for j in 0..n_phi {
            let wo = grid_direction(i, j, n_theta, n_phi, full);
            let mut f: Rgb = brdf.eval(wi, wo);
            if opts.cosine {
                f *= wo.z.abs();
            }
            // A model bug must not poison the whole mesh: show it as 0 here; the
            // property analysis reports non-finite values loudly.
            if !f.is_finite() {
                f = Rgb::ZERO;
            }
            let r = opts.scale.apply(mean_rgb(f).max(0.0));
            vals[j] = f.as_vec3().to_array();
            pos[j] = (wo * r).as_vec3().to_array();
        }
    };
    if count >= 4096 {
        values
            .par_chunks_mut(n_phi)
            .zip(positions.par_chunks_mut(n_phi))
            .enumerate()
            .for_each(|(i, (v, p))| fill_row(i, v, p));
    } else {
        for (i, (v, p)) in values
            .chunks_mut(n_phi)
            .zip(positions.chunks_mut(n_phi))
            .enumerate()
        {
            fill_row(i, v, p);
        }
    }

    // Two triangles per grid cell; the φ seam wraps.
    let mut indices = Vec::with_capacity(n_theta * n_phi * 6);
    for i in 0..n_theta {
        for j in 0..n_phi {
            let j1 = (j + 1) % n_phi;
            let a = (i * n_phi + j) as u32;
            let b = (i * n_phi + j1) as u32;
            let c = ((i + 1) * n_phi + j) as u32;
            let d = ((i + 1) * n_phi + j1) as u32;
            // θ grows away from the pole and φ counter-clockwise about +z, so
            // (a, c, d) faces outwards.
            indices.extend_from_slice(&[a, c, d, a, d, b]);
        }
    }

    let normals = vertex_normals(&positions, &indices, &grid_fallback(n_theta, n_phi, full));
    let max_value = values
        .iter()
        .map(|v| mean_rgb(Vec3::from_array(*v).as_dvec3()))
        .fold(0.0, f64::max);
    let max_radius = positions
        .iter()
        .map(|p| Vec3::from_array(*p).length() as f64)
        .fold(0.0, f64::max);

    LobeMesh {
        positions,
        normals,
        values,
        indices,
        n_theta,
        n_phi,
        full_sphere: full,
        max_value,
        max_radius,
        deltas: brdf.deltas(wi),
    }
}

fn grid_fallback(n_theta: usize, n_phi: usize, full: bool) -> Vec<Vec3> {
    (0..=n_theta)
        .flat_map(|i| (0..n_phi).map(move |j| grid_direction(i, j, n_theta, n_phi, full).as_vec3()))
        .collect()
}

/// Area-weighted vertex normals; a vertex with no area around it (a collapsed
/// lobe) gets its grid direction, so shading never sees a NaN.
fn vertex_normals(positions: &[[f32; 3]], indices: &[u32], fallback: &[Vec3]) -> Vec<[f32; 3]> {
    let mut acc = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let (a, b, c) = (t[0] as usize, t[1] as usize, t[2] as usize);
        let pa = Vec3::from_array(positions[a]);
        let n = (Vec3::from_array(positions[b]) - pa).cross(Vec3::from_array(positions[c]) - pa);
        acc[a] += n;
        acc[b] += n;
        acc[c] += n;
    }
    acc.iter()
        .zip(fallback)
        .map(|(n, f)| {
            let l = n.length();
            if l > 1e-20 && l.is_finite() {
                (*n / l).to_array()
            } else {
                f.to_array()
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::lambert::Lambert;

    #[test]
    fn lambert_lobe_is_a_hemisphere_of_radius_f() {
        let b = Lambert::new(Rgb::splat(0.5));
        let m = build(&b, DVec3::Z, &LobeOptions::default());
        assert_eq!(m.positions.len(), 65 * 128);
        assert_eq!(m.indices.len(), 64 * 128 * 6);
        let f = 0.5 / PI;
        // Every ring above the horizon lies on the sphere of radius f.
        for i in 0..64 {
            for j in 0..128 {
                let p = Vec3::from_array(m.positions[i * 128 + j]);
                assert!((p.length() as f64 - f).abs() < 1e-6);
            }
        }
        // The horizon ring is where f switches to 0 (wo.z = 0 is not above it).
        assert!((m.max_value - f).abs() < 1e-6);
        // Normals of a sphere point outward.
        let n = Vec3::from_array(m.normals[10 * 128 + 5]);
        let p = Vec3::from_array(m.positions[10 * 128 + 5]).normalize();
        assert!(n.dot(p) > 0.99);
    }

    #[test]
    fn cosine_and_log_scales() {
        let b = Lambert::new(Rgb::splat(1.0));
        let opts = LobeOptions {
            cosine: true,
            scale: RadiusScale::Log,
            ..LobeOptions::default()
        };
        let m = build(&b, DVec3::Z, &opts);
        // At the pole r = ln(1 + 1/π).
        let p = Vec3::from_array(m.positions[0]);
        assert!((p.length() as f64 - (1.0 / PI).ln_1p()).abs() < 1e-6);
        // Ring i at θ: r = ln(1 + cos θ / π).
        let i = 32;
        let theta = FRAC_PI_2 * i as f64 / 64.0;
        let r = Vec3::from_array(m.positions[i * 128]).length() as f64;
        assert!((r - (theta.cos() / PI).ln_1p()).abs() < 1e-6);
    }

    #[test]
    fn tiny_resolution_is_raised() {
        let b = Lambert::new(Rgb::splat(0.5));
        let m = build(
            &b,
            DVec3::Z,
            &LobeOptions {
                n_theta: 0,
                n_phi: 0,
                ..LobeOptions::default()
            },
        );
        assert_eq!(m.n_theta, 2);
        assert_eq!(m.n_phi, 3);
        assert!(m.normals.iter().all(|n| n.iter().all(|x| x.is_finite())));
    }
}
