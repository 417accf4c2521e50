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
/// to it. Rows are evaluated in parallel for large grids; the trigonometry comes
/// from per-row and per-column tables, so the cost is the model's evaluations
/// plus a few vector operations per vertex.
pub fn build(brdf: &dyn Brdf, wi: DVec3, opts: &LobeOptions) -> LobeMesh {
    let n_theta = opts.n_theta.max(2);
    let n_phi = opts.n_phi.max(3);
    let full = brdf.transmits();
    let rows = n_theta + 1;
    let count = rows * n_phi;
    let parallel = count >= 4096;

    let theta_max = if full { PI } else { FRAC_PI_2 };
    let ring: Vec<(f64, f64)> = (0..rows)
        .map(|i| frame::sin_cos_theta(theta_max * i as f64 / n_theta as f64))
        .collect();
    let column: Vec<(f64, f64)> = (0..n_phi)
        .map(|j| (2.0 * PI * j as f64 / n_phi as f64).sin_cos())
        .collect();
    let dir = |i: usize, j: usize| {
        let (st, ct) = ring[i];
        let (sp, cp) = column[j];
        DVec3::new(st * cp, st * sp, ct)
    };

    let mut values = vec![[0f32; 3]; count];
    let mut positions = vec![[0f32; 3]; count];
    let fill_row = |i: usize, (vals, pos): (&mut [[f32; 3]], &mut [[f32; 3]])| {
        for j in 0..n_phi {
            let wo = dir(i, j);
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
    if parallel {
        values
            .par_chunks_mut(n_phi)
            .zip(positions.par_chunks_mut(n_phi))
            .enumerate()
            .for_each(|(i, rows)| fill_row(i, rows));
    } else {
        let rows = values.chunks_mut(n_phi).zip(positions.chunks_mut(n_phi));
        for (i, rows) in rows.enumerate() {
            fill_row(i, rows);
        }
    }

    let indices = grid_indices(n_theta, n_phi, parallel);
    let normals = grid_normals(&positions, n_theta, n_phi, parallel, |i, j| {
        dir(i, j).as_vec3()
    });
    let max_value = values
        .iter()
        .map(|v| mean_rgb(Vec3::from_array(*v).as_dvec3()))
        .fold(0.0, f64::max);
    let max_radius = positions
        .iter()
        .map(|p| Vec3::from_array(*p).length_squared())
        .fold(0.0f32, f32::max)
        .sqrt() as f64;

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

/// Two triangles per grid cell; the φ seam wraps. θ grows away from the pole
/// and φ counter-clockwise about +z, so `(a, c, d)` faces outwards.
fn grid_indices(n_theta: usize, n_phi: usize, parallel: bool) -> Vec<u32> {
    let mut indices = vec![0u32; n_theta * n_phi * 6];
    let row = |i: usize, out: &mut [u32]| {
        for j in 0..n_phi {
            let j1 = (j + 1) % n_phi;
            let a = (i * n_phi + j) as u32;
            let b = (i * n_phi + j1) as u32;
            let c = ((i + 1) * n_phi + j) as u32;
            let d = ((i + 1) * n_phi + j1) as u32;
            out[j * 6..j * 6 + 6].copy_from_slice(&[a, c, d, a, d, b]);
        }
    };
    if parallel {
        indices
            .par_chunks_mut(n_phi * 6)
            .enumerate()
            .for_each(|(i, out)| row(i, out));
    } else {
        for (i, out) in indices.chunks_mut(n_phi * 6).enumerate() {
            row(i, out);
        }
    }
    indices
}

/// Smooth normals from the grid: the cross product of the central differences
/// along θ and along φ (`∂P/∂θ × ∂P/∂φ` points outwards, as `sinθ e_r` does on a
/// sphere). On a pole ring, where `∂P/∂φ` vanishes, the normal is the sum of the
/// fan of triangles around it. A vertex with no area around it (a collapsed
/// lobe) gets its grid direction, so shading never sees a NaN.
fn grid_normals(
    positions: &[[f32; 3]],
    n_theta: usize,
    n_phi: usize,
    parallel: bool,
    fallback: impl Fn(usize, usize) -> Vec3 + Sync,
) -> Vec<[f32; 3]> {
    let p = |i: usize, j: usize| Vec3::from_array(positions[i * n_phi + j]);
    let fan = |i: usize, next: usize| {
        let c = p(i, 0);
        (0..n_phi)
            .map(|j| (p(next, j) - c).cross(p(next, (j + 1) % n_phi) - c))
            .sum::<Vec3>()
    };
    // Pole rows: the north pole (row 0) always; the south pole on a full sphere
    // (its fan winds the other way round).
    let north = fan(0, 1);
    let south = -fan(n_theta, n_theta - 1);
    let is_pole = |i: usize| {
        let (x, y) = (positions[i * n_phi][0], positions[i * n_phi][1]);
        x == 0.0 && y == 0.0 && (0..n_phi).all(|j| p(i, j) == p(i, 0))
    };
    let north_is_pole = is_pole(0);
    let south_is_pole = is_pole(n_theta);
    let normal_row = |i: usize, out: &mut [[f32; 3]]| {
        for (j, o) in out.iter_mut().enumerate() {
            let n = if i == 0 && north_is_pole {
                north
            } else if i == n_theta && south_is_pole {
                south
            } else {
                let up = if i == 0 { p(0, j) } else { p(i - 1, j) };
                let down = if i == n_theta { p(i, j) } else { p(i + 1, j) };
                let left = p(i, (j + n_phi - 1) % n_phi);
                let right = p(i, (j + 1) % n_phi);
                (down - up).cross(right - left)
            };
            let l = n.length();
            *o = if l > 1e-20 && l.is_finite() {
                (n / l).to_array()
            } else {
                fallback(i, j).to_array()
            };
        }
    };
    let mut normals = vec![[0f32; 3]; positions.len()];
    if parallel {
        normals
            .par_chunks_mut(n_phi)
            .enumerate()
            .for_each(|(i, out)| normal_row(i, out));
    } else {
        for (i, out) in normals.chunks_mut(n_phi).enumerate() {
            normal_row(i, out);
        }
    }
    normals
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
    fn normals_point_outwards_including_the_pole() {
        let b = Lambert::new(Rgb::splat(0.5));
        for (n_theta, n_phi) in [(8, 16), (64, 128)] {
            let opts = LobeOptions {
                n_theta,
                n_phi,
                ..LobeOptions::default()
            };
            let m = build(&b, DVec3::Z, &opts);
            assert!(Vec3::from_array(m.normals[0]).dot(Vec3::Z) > 0.999_999);
            // Every ring strictly between the pole and the horizon is on the
            // sphere of radius 1/(2π): its normal is the radial direction.
            for i in 1..n_theta - 1 {
                for j in 0..n_phi {
                    let n = Vec3::from_array(m.normals[i * n_phi + j]);
                    let d = m.direction(i, j).as_vec3();
                    assert!(n.dot(d) > 0.99, "ring {i} column {j}: {n} vs {d}");
                }
            }
        }
    }

    #[test]
    fn the_horizon_ring_is_in_the_surface() {
        // Ward divides by √cos θo: a horizon ring a hair above the surface would
        // be thousands of 1/sr; in the surface it is 0 (SPEC §1).
        let b = crate::ModelSpec::new("ward").unwrap().build().unwrap();
        let m = build(b.as_ref(), DVec3::Z, &LobeOptions::default());
        let k = m.n_theta * m.n_phi;
        assert!(m.values[k..].iter().all(|v| *v == [0.0; 3]));
        assert!(m.max_value < 10.0, "{}", m.max_value);
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
