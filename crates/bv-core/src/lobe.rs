//! Lobe meshes: the surface `r(wo) · wo` over the outgoing
//! hemisphere (the whole sphere for transmitting models), where `r` is `f` or
//! `f · cos θo`, on a linear or logarithmic scale. The 3D view and the headless
//! export draw this mesh; it carries a per-vertex value for colouring.

use crate::batch::{self, Isa, LaneMask, LaneTask, Lanes, Out};
use crate::{Brdf, DeltaLobe, frame};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::{Arc, Mutex, OnceLock};

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
    /// Per-vertex radius `r` (scaled): `positions[k]` is `radii[k]` times
    /// the vertex's grid direction ([`LobeMesh::direction`]). Empty for a
    /// mesh not built on the lobe grid.
    pub radii: Vec<f32>,
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

/// What a lobe mesh of one resolution shares across calls: the grid's
/// directions (f32 lanes, for the batch evaluator and the fallback normals)
/// and the triangle list. Only `f` changes when a slider moves.
#[derive(Debug)]
struct Grid {
    /// Vertex directions as structure-of-arrays lanes (x, y, z).
    dirs: [Vec<f32>; 3],
    /// The triangle list.
    indices: Vec<u32>,
}

/// Grids built so far, keyed by `(n_theta, n_phi, full sphere)`. A viewer
/// uses a handful of resolutions; the cache is emptied if it ever holds more
/// than [`GRID_CACHE_MAX`], so memory stays bounded.
fn grid(n_theta: usize, n_phi: usize, full: bool) -> Arc<Grid> {
    static CACHE: OnceLock<Mutex<GridCache>> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    let key = (n_theta, n_phi, full);
    // A panic elsewhere while holding the lock leaves a usable map.
    if let Some(g) = cache.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return g.clone();
    }
    let rows = n_theta + 1;
    let count = rows * n_phi;
    let theta_max = if full { PI } else { FRAC_PI_2 };
    let ring: Vec<(f64, f64)> = (0..rows)
        .map(|i| frame::sin_cos_theta(theta_max * i as f64 / n_theta as f64))
        .collect();
    let column: Vec<(f64, f64)> = (0..n_phi)
        .map(|j| (2.0 * PI * j as f64 / n_phi as f64).sin_cos())
        .collect();
    let mut dirs = [
        Vec::with_capacity(count),
        Vec::with_capacity(count),
        Vec::with_capacity(count),
    ];
    for &(st, ct) in &ring {
        for &(sp, cp) in &column {
            dirs[0].push((st * cp) as f32);
            dirs[1].push((st * sp) as f32);
            dirs[2].push(ct as f32);
        }
    }
    let g = Arc::new(Grid {
        dirs,
        indices: grid_indices(n_theta, n_phi, count >= 4096),
    });
    let mut map = cache.lock().unwrap_or_else(|e| e.into_inner());
    if map.len() >= GRID_CACHE_MAX {
        map.clear();
    }
    map.insert(key, g.clone());
    g
}

/// Grids by `(n_theta, n_phi, full sphere)`.
type GridCache = HashMap<(usize, usize, bool), Arc<Grid>>;

/// Most grid resolutions kept at once.
const GRID_CACHE_MAX: usize = 16;

/// Builds the lobe of `brdf` for light from `wi`. Resolution below 2×3 is raised
/// to it. The direction grid and the triangle list of each resolution are built
/// once and reused; the values come from the batch evaluator
/// ([`crate::batch::eval`]: the model's f32 SIMD kernel, or its `eval`), rows
/// in parallel for large grids, so the cost is the model's evaluations plus a
/// few vector operations per vertex. [`build_into`] also reuses the buffers of
/// a previous mesh.
pub fn build(brdf: &dyn Brdf, wi: DVec3, opts: &LobeOptions) -> LobeMesh {
    let mut mesh = LobeMesh::default();
    build_into(brdf, wi, opts, &mut mesh);
    mesh
}

/// [`build`] into an existing mesh, reusing its buffers: when a slider moves
/// and the resolution stays, nothing is allocated and the triangle list is
/// not rewritten (it is taken as the one an earlier call wrote), so only the
/// values, positions and normals are computed.
pub fn build_into(brdf: &dyn Brdf, wi: DVec3, opts: &LobeOptions, mesh: &mut LobeMesh) {
    build_with(brdf, wi, opts, mesh, batch::isa());
}

/// [`build_into`] with the instruction set `isa` (replaced by
/// [`Isa::best`] where this CPU lacks it) for the evaluation and the
/// per-vertex passes, for tests and benchmarks that compare the paths.
pub fn build_with(brdf: &dyn Brdf, wi: DVec3, opts: &LobeOptions, mesh: &mut LobeMesh, isa: Isa) {
    let n_theta = opts.n_theta.max(2);
    let n_phi = opts.n_phi.max(3);
    let full = brdf.transmits();
    let rows = n_theta + 1;
    let count = rows * n_phi;
    let parallel = count >= 4096;
    let grid = grid(n_theta, n_phi, full);
    let wi32 = [wi.x as f32, wi.y as f32, wi.z as f32];

    let same_grid = mesh.n_theta == n_theta
        && mesh.n_phi == n_phi
        && mesh.full_sphere == full
        && mesh.indices.len() == grid.indices.len();
    let mut values = std::mem::take(&mut mesh.values);
    let mut positions = std::mem::take(&mut mesh.positions);
    let mut radii = std::mem::take(&mut mesh.radii);
    let mut normals = std::mem::take(&mut mesh.normals);
    let mut indices = std::mem::take(&mut mesh.indices);
    values.resize(count, [0.0; 3]);
    positions.resize(count, [0.0; 3]);
    radii.resize(count, 0.0);
    normals.resize(count, [0.0; 3]);
    // The triangle list depends on the resolution only; a mesh of the same
    // resolution already holds it (callers do not edit it).
    if !same_grid {
        indices.clear();
        indices.extend_from_slice(&grid.indices);
    }
    // Rows per task: enough lanes per batch call to fill the vectors.
    let band = (2048 / n_phi).max(1);
    // An isotropic model's lobe is symmetric about the plane of incidence;
    // where that plane maps grid columns onto grid columns (see
    // `mirror_axis`), half of each ring is evaluated and mirrored.
    let mirror = mirror_axis(brdf, wi, n_phi);
    // Every pair shares `wi`: a kernel with a form for that computes the
    // terms of `wi` alone once (see `batch::Kernel::at_wi`).
    let at_wi = brdf.batch_kernel().and_then(|k| k.at_wi(wi32));
    let fill = |first_row: usize, ((vals, pos), rad): BandOut<'_>| {
        let start = first_row * n_phi;
        let n = vals.len();
        let wo = [
            &grid.dirs[0][start..start + n],
            &grid.dirs[1][start..start + n],
            &grid.dirs[2][start..start + n],
        ];
        SCRATCH.with_borrow_mut(|scratch| {
            let ([wx, wy, wz], [r, g, b]) = scratch.band(wi32, n);
            let eval = |at: std::ops::Range<usize>, [r, g, b]: [&mut [f32]; 3]| {
                let dirs = batch::Dirs {
                    wi: [&wx[at.clone()], &wy[at.clone()], &wz[at.clone()]],
                    wo: [&wo[0][at.clone()], &wo[1][at.clone()], &wo[2][at.clone()]],
                };
                let mut out = Out {
                    rgb: [&mut r[at.clone()], &mut g[at.clone()], &mut b[at]],
                };
                match &at_wi {
                    Some(k) => k.eval(isa, &dirs, &mut out),
                    None => {
                        batch::eval_with(brdf, isa, &dirs, &mut out);
                    }
                }
            };
            match mirror {
                None => eval(0..n, [r, g, b]),
                Some(m) => {
                    // Per ring: the columns `first .. first + half` (mod
                    // n_phi, so one or two runs), then the rest copied from
                    // their mirror images `m − j`.
                    let half = (n_phi / 2 + 2).min(n_phi);
                    let first = m / 2;
                    for ring in (0..n).step_by(n_phi) {
                        let end = first + half;
                        eval(ring + first..ring + end.min(n_phi), [r, g, b]);
                        if end > n_phi {
                            eval(ring..ring + end - n_phi, [r, g, b]);
                        }
                        // Columns `first + half ..` round to `first`, each
                        // from its mirror column, one step back each time
                        // (no division per column: this runs per vertex).
                        let mut j = (first + half) % n_phi;
                        let mut from = (m + n_phi - j) % n_phi;
                        for _ in half..n_phi {
                            debug_assert!((from + n_phi - first) % n_phi < half);
                            r[ring + j] = r[ring + from];
                            g[ring + j] = g[ring + from];
                            b[ring + j] = b[ring + from];
                            j = if j + 1 == n_phi { 0 } else { j + 1 };
                            from = if from == 0 { n_phi - 1 } else { from - 1 };
                        }
                    }
                }
            }
            post_band([&r[..], &g[..], &b[..]], wo, vals, pos, rad, opts, isa)
        })
    };
    let both_max = |a: (f32, f32), b: (f32, f32)| (a.0.max(b.0), a.1.max(b.1));
    let (max_mean, max_r2) = if parallel {
        values
            .par_chunks_mut(band * n_phi)
            .zip(positions.par_chunks_mut(band * n_phi))
            .zip(radii.par_chunks_mut(band * n_phi))
            .enumerate()
            .map(|(b, rows)| fill(b * band, rows))
            .reduce(|| (0.0, 0.0), both_max)
    } else {
        fill(0, ((&mut values[..], &mut positions[..]), &mut radii[..]))
    };

    grid_normals(
        &positions,
        &radii,
        &mut normals,
        n_theta,
        n_phi,
        band,
        parallel,
        &grid.dirs,
        isa,
    );
    let max_value = max_mean as f64;
    let max_radius = max_r2.sqrt() as f64;

    *mesh = LobeMesh {
        positions,
        radii,
        normals,
        values,
        indices,
        n_theta,
        n_phi,
        full_sphere: full,
        max_value,
        max_radius,
        deltas: brdf.deltas(wi),
    };
}

/// The column `m` (in `0..n_phi`) such that column `j` of a ring mirrors
/// column `m − j (mod n_phi)` across the plane of incidence, when `brdf`
/// promises isotropy (a catalogue formula's claim: a file's observed claims
/// are not trusted with this) and ωi's azimuth is a multiple of half a
/// column step, π / n_phi (light in the xz-plane, φi = 0, is the common
/// case). Then `f(ωi, ωo)` depends on φo only through |φo − φi|, and column
/// `j`'s azimuth 2πj/n_phi mirrors to 2φi − 2πj/n_phi = 2π(m − j)/n_phi.
fn mirror_axis(brdf: &dyn Brdf, wi: DVec3, n_phi: usize) -> Option<usize> {
    if !(brdf.claims_declared() && brdf.claims().isotropic) {
        return None;
    }
    // At normal incidence every plane through the normal is one.
    if wi.x == 0.0 && wi.y == 0.0 {
        return Some(0);
    }
    let s = wi.y.atan2(wi.x) * n_phi as f64 / PI;
    let m = s.round();
    if (s - m).abs() > 1e-9 || !m.is_finite() {
        return None;
    }
    Some(m.rem_euclid(n_phi as f64) as usize % n_phi)
}

/// One band's values, positions and radii, as the parallel iterator zips them.
type BandOut<'a> = ((&'a mut [[f32; 3]], &'a mut [[f32; 3]]), &'a mut [f32]);

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
/// lobe) gets its grid direction, so shading never sees a NaN. Rows are
/// handed out `band` at a time when `parallel`.
#[allow(clippy::too_many_arguments)]
fn grid_normals(
    positions: &[[f32; 3]],
    radii: &[f32],
    normals: &mut [[f32; 3]],
    n_theta: usize,
    n_phi: usize,
    band: usize,
    parallel: bool,
    dirs: &[Vec<f32>; 3],
    isa: Isa,
) {
    let p = |i: usize, j: usize| Vec3::from_array(positions[i * n_phi + j]);
    let fan = |i: usize, next: usize| {
        let c = p(i, 0);
        (0..n_phi)
            .map(|j| (p(next, j) - c).cross(p(next, if j + 1 == n_phi { 0 } else { j + 1 }) - c))
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
    let row = |i: usize| &positions[i * n_phi..(i + 1) * n_phi];
    let normal_row = |i: usize, out: &mut [[f32; 3]]| {
        let pole = if i == 0 && north_is_pole {
            Some(north)
        } else if i == n_theta && south_is_pole {
            Some(south)
        } else {
            None
        };
        let fb = |j: usize| {
            let k = i * n_phi + j;
            [dirs[0][k], dirs[1][k], dirs[2][k]]
        };
        // A vertex with no area around it gets its grid direction.
        let unit = |n: [f32; 3], j: usize| {
            let l2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
            let l = l2.sqrt();
            let inv = 1.0 / l;
            if l > 1e-20 && l < f32::INFINITY {
                [n[0] * inv, n[1] * inv, n[2] * inv]
            } else {
                fb(j)
            }
        };
        if let Some(n) = pole {
            for (j, o) in out.iter_mut().enumerate() {
                *o = unit(n.to_array(), j);
            }
            return;
        }
        // Central differences along θ (rows; one-sided at the first and last
        // rows) and φ (columns; the seam wraps): (down − up) × (right − left).
        let i_up = if i == 0 { 0 } else { i - 1 };
        let i_down = if i == n_theta { i } else { i + 1 };
        let (up, down, cur) = (row(i_up), row(i_down), row(i));
        let normal = |j: usize, left: usize, right: usize| {
            let a = sub(down[j], up[j]);
            let b = sub(cur[right], cur[left]);
            unit(cross(a, b), j)
        };
        out[0] = normal(0, n_phi - 1, 1 % n_phi);
        // The interior columns in vectors (see `InteriorNormals`).
        batch::run_task(
            isa,
            InteriorNormals {
                radii,
                dirs: [&dirs[0][..], &dirs[1][..], &dirs[2][..]],
                up: i_up * n_phi,
                cur: i * n_phi,
                down: i_down * n_phi,
                out: &mut *out,
            },
        );
        out[n_phi - 1] = normal(n_phi - 1, n_phi - 2, 0);
    };
    let rows_of = |first: usize, out: &mut [[f32; 3]]| {
        for (r, o) in out.chunks_mut(n_phi).enumerate() {
            normal_row(first + r, o);
        }
    };
    if parallel {
        normals
            .par_chunks_mut(band * n_phi)
            .enumerate()
            .for_each(|(b, out)| rows_of(b * band, out));
    } else {
        rows_of(0, normals);
    }
}

thread_local! {
    /// Per-thread buffers of a band, grown once and reused by every later
    /// lobe.
    static SCRATCH: std::cell::RefCell<Scratch> = Default::default();
}

/// A thread's buffers for one band: ωi's lanes (x, y, z) and the values
/// (r, g, b).
#[derive(Default)]
struct Scratch {
    wi: [Vec<f32>; 3],
    /// The bits of the direction every lane of `wi` holds (`None` before
    /// the first fill).
    wi_holds: Option<[u32; 3]>,
    rgb: [Vec<f32>; 3],
}

impl Scratch {
    /// A band of `n` lanes: ωi's, each holding `wi`, and the values'.
    /// Every band of a lobe shares `wi`, so its lanes are written when `wi`
    /// changes and when they grow, not per band: a 128 × 256 lobe's 17
    /// bands rewrote 400 kB of them per build, on a pass that is bound by
    /// memory traffic (on the Xeon a lobe of the zero kernel took 5 ns per
    /// vertex, single threaded, with the effective L2 about 1 MB).
    #[allow(clippy::type_complexity)]
    fn band(&mut self, wi: [f32; 3], n: usize) -> ([&mut [f32]; 3], [&mut [f32]; 3]) {
        let bits = wi.map(f32::to_bits);
        let moved = self.wi_holds != Some(bits);
        self.wi_holds = Some(bits);
        for (v, x) in self.wi.iter_mut().zip(wi) {
            if moved {
                v.fill(x);
            }
            if v.len() < n {
                v.resize(n, x);
            }
        }
        let lanes = self.wi.each_mut().map(|v| &mut v[..n]);
        let rgb = self.rgb.each_mut().map(|v| {
            v.resize(n, 0.0);
            &mut v[..n]
        });
        (lanes, rgb)
    }
}

/// Values, positions, radii and the band's largest mean and squared radius
/// from the evaluated `rgb` of directions `wo` (see [`PostBand`]; the log
/// scale is applied after it, per vertex in f64).
fn post_band(
    rgb: [&[f32]; 3],
    wo: [&[f32]; 3],
    vals: &mut [[f32; 3]],
    pos: &mut [[f32; 3]],
    radii: &mut [f32],
    opts: &LobeOptions,
    isa: Isa,
) -> (f32, f32) {
    let (max_mean, mut max_r2) = batch::run_task(
        isa,
        PostBand {
            rgb,
            wo,
            vals: &mut *vals,
            pos: &mut *pos,
            radii: &mut *radii,
            cosine: opts.cosine,
        },
    );
    // The log scale's ln(1 + f) is f64 in `RadiusScale::apply`: its radii
    // replace the linear ones (the channel means) here.
    if let RadiusScale::Log = opts.scale {
        max_r2 = 0.0;
        for (k, p) in pos.iter_mut().enumerate() {
            let mean = (vals[k][0] + vals[k][1] + vals[k][2]) * (1.0 / 3.0);
            let rad = opts.scale.apply(mean.max(0.0) as f64) as f32;
            *p = [wo[0][k] * rad, wo[1][k] * rad, wo[2][k] * rad];
            radii[k] = rad;
            max_r2 = max_r2.max(rad * rad);
        }
    }
    (max_mean, max_r2)
}

/// The per-vertex pass after evaluation, over one band of rows: the cosine
/// factor if asked, non-finite values shown as 0, the channel mean as the
/// (linear) radius, and the band's largest mean and squared radius.
/// Written against [`Lanes`] (a [`LaneTask`]): LLVM left the same pass as a
/// scalar loop scalar on AVX2 (a third of a Lambert lobe's time there).
struct PostBand<'a> {
    rgb: [&'a [f32]; 3],
    wo: [&'a [f32]; 3],
    vals: &'a mut [[f32; 3]],
    pos: &'a mut [[f32; 3]],
    radii: &'a mut [f32],
    cosine: bool,
}

impl LaneTask for PostBand<'_> {
    type Output = (f32, f32);

    #[inline(always)]
    fn run<V: Lanes>(mut self) -> (f32, f32) {
        let n = self.vals.len().min(self.pos.len()).min(self.radii.len());
        let whole = n - n % V::LANES;
        let (mut mm, mut mr) = (V::splat(0.0), V::splat(0.0));
        let mut k = 0;
        while k < whole {
            self.lanes::<V>(k, &mut mm, &mut mr);
            k += V::LANES;
        }
        // The remainder one lane at a time.
        let (mut m1, mut r1) = (0f32, 0f32);
        while k < n {
            self.lanes::<f32>(k, &mut m1, &mut r1);
            k += 1;
        }
        let mut a = [[0f32; 16]; 2];
        mm.store(&mut a[0]);
        mr.store(&mut a[1]);
        let lanes = V::LANES;
        (
            a[0][..lanes].iter().fold(m1, |x, &y| x.max(y)),
            a[1][..lanes].iter().fold(r1, |x, &y| x.max(y)),
        )
    }
}

impl PostBand<'_> {
    /// Vertices `k .. k + V::LANES`; the running maxima per lane in `mm`
    /// (means) and `mr` (squared radii).
    #[inline(always)]
    fn lanes<V: Lanes>(&mut self, k: usize, mm: &mut V, mr: &mut V) {
        // No closures here: a closure is not compiled with the instruction
        // set of the function it is in, and LLVM left the vector intrinsics
        // inside them as calls (3× slower than the scalar loop).
        let zero = V::splat(0.0);
        let wo = [
            load_at::<V>(self.wo[0], k),
            load_at::<V>(self.wo[1], k),
            load_at::<V>(self.wo[2], k),
        ];
        let c = if self.cosine {
            wo[2].abs()
        } else {
            V::splat(1.0)
        };
        let f = [
            load_at::<V>(self.rgb[0], k) * c,
            load_at::<V>(self.rgb[1], k) * c,
            load_at::<V>(self.rgb[2], k) * c,
        ];
        // A model bug must not poison the whole mesh: show it as 0 here;
        // the property analysis reports non-finite values loudly.
        let finite = f[0].is_finite() & f[1].is_finite() & f[2].is_finite();
        let f = [
            V::select(finite, f[0], zero),
            V::select(finite, f[1], zero),
            V::select(finite, f[2], zero),
        ];
        let mean = (f[0] + f[1] + f[2]) * (1.0 / 3.0);
        let mean = V::select(mean.gt(zero), mean, zero);
        let p = [wo[0] * mean, wo[1] * mean, wo[2] * mean];
        let r2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
        *mm = V::select(mean.gt(*mm), mean, *mm);
        *mr = V::select(r2.gt(*mr), r2, *mr);
        mean.store(&mut self.radii[k..]);
        // The mesh's arrays are [x, y, z] per vertex.
        V::store3(f[0], f[1], f[2], &mut self.vals[k..]);
        V::store3(p[0], p[1], p[2], &mut self.pos[k..]);
    }
}

/// Normals of one row's interior columns `1..n_phi − 1` from the rows above
/// and below (`(down − up) × (right − left)`, normalised; the grid direction
/// where that vanishes). The positions are rebuilt as radius × direction
/// from the structure-of-arrays `radii` and `dirs` (the same f32 products
/// that made the mesh's positions), so neighbours are whole vector loads.
struct InteriorNormals<'a> {
    radii: &'a [f32],
    dirs: [&'a [f32]; 3],
    /// First vertex of the row above, of this row, and of the row below.
    up: usize,
    cur: usize,
    down: usize,
    /// This row's normals.
    out: &'a mut [[f32; 3]],
}

impl LaneTask for InteriorNormals<'_> {
    type Output = ();

    #[inline(always)]
    fn run<V: Lanes>(mut self) {
        let n = self.out.len();
        if n < 3 {
            return;
        }
        let mut j = 1;
        while j + V::LANES < n {
            self.lanes::<V>(j);
            j += V::LANES;
        }
        while j + 1 < n {
            self.lanes::<f32>(j);
            j += 1;
        }
    }
}

impl InteriorNormals<'_> {
    /// Columns `j .. j + V::LANES` (all of them in `1..n_phi − 1`).
    #[inline(always)]
    fn lanes<V: Lanes>(&mut self, j: usize) {
        // No closures here (see `PostBand::lanes`).
        let (r, d) = (self.radii, self.dirs);
        let k = self.cur + j;
        let a = sub(
            position::<V>(r, d, self.down + j),
            position::<V>(r, d, self.up + j),
        );
        let b = sub(position::<V>(r, d, k + 1), position::<V>(r, d, k - 1));
        let c = cross(a, b);
        let l2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        // 1/|c| from the instruction set's estimate: a square root and a
        // division per vector shared one divider and took a third of this
        // pass on AVX2. A vector with a lane the estimate does not cover (a
        // subnormal or overflowed |c|²) takes the exact path, whose test is
        // the edge columns' (`grid_normals`).
        let fast = l2.ge(V::splat(f32::MIN_POSITIVE)) & l2.lt(V::splat(f32::INFINITY));
        let (inv, ok) = if fast.all() {
            (l2.rsqrt(), fast)
        } else {
            let l = l2.sqrt();
            let ok = l.gt(V::splat(1e-20)) & l.lt(V::splat(f32::INFINITY));
            (V::splat(1.0) / l, ok)
        };
        V::store3(
            V::select(ok, c[0] * inv, load_at::<V>(d[0], k)),
            V::select(ok, c[1] * inv, load_at::<V>(d[1], k)),
            V::select(ok, c[2] * inv, load_at::<V>(d[2], k)),
            &mut self.out[j..],
        );
    }
}

/// The lanes `a[k..k + V::LANES]`.
#[inline(always)]
fn load_at<V: Lanes>(a: &[f32], k: usize) -> V {
    V::load(&a[k..])
}

/// The positions `radius · direction` of vertices `k..k + V::LANES`.
#[inline(always)]
fn position<V: Lanes>(radii: &[f32], dirs: [&[f32]; 3], k: usize) -> [V; 3] {
    let r = load_at::<V>(radii, k);
    [
        load_at::<V>(dirs[0], k) * r,
        load_at::<V>(dirs[1], k) * r,
        load_at::<V>(dirs[2], k) * r,
    ]
}

#[inline(always)]
fn sub<V: Lanes>(a: [V; 3], b: [V; 3]) -> [V; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
fn cross<V: Lanes>(a: [V; 3], b: [V; 3]) -> [V; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Rgb;
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
        // be thousands of 1/sr; in the surface it is 0 .
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

    /// Grid direction `k` of `g`, in f64.
    fn grid_dir(g: &Grid, k: usize) -> DVec3 {
        DVec3::new(
            g.dirs[0][k] as f64,
            g.dirs[1][k] as f64,
            g.dirs[2][k] as f64,
        )
    }

    #[test]
    fn batch_values_match_eval_and_grids_are_reused() {
        // Values through the batch path (a kernel for cook-torrance, the
        // scalar fallback for glass) agree with `eval` at the grid directions,
        // and a second mesh of the same resolution reuses the cached grid.
        let wi = frame::from_spherical(0.7, 0.4);
        for (id, p) in [
            (
                "cook-torrance",
                serde_json::json!({"distribution": "ggx", "geometry": "smith", "alpha": 0.3,
                    "fresnel": "conductor", "eta": [0.2, 0.92, 1.1], "k": [3.9, 2.45, 2.14]}),
            ),
            ("glass", serde_json::json!({})),
        ] {
            let b = crate::ModelSpec::from_json(id, &p)
                .unwrap()
                .build()
                .unwrap();
            let opts = LobeOptions {
                n_theta: 24,
                n_phi: 40,
                ..LobeOptions::default()
            };
            let m = build(b.as_ref(), wi, &opts);
            let g = grid(24, 40, b.transmits());
            assert!(Arc::ptr_eq(&g, &grid(24, 40, b.transmits())));
            assert_eq!(m.indices, g.indices);
            let wi32 = wi.as_vec3().as_dvec3();
            for (k, v) in m.values.iter().enumerate() {
                let want = b.eval(wi32, grid_dir(&g, k));
                for c in 0..3 {
                    let tol = (1e-4 * want[c].abs()).max(1e-6);
                    assert!(
                        (v[c] as f64 - want[c]).abs() <= tol,
                        "{id} {k}: {v:?} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn every_lobe_sees_its_own_light_through_the_shared_scratch() {
        // The per-thread lanes of ωi are written only when ωi changes or
        // they grow (`Scratch::band`): lobes built one after another, with
        // the light moving, coming back, and the band growing from a
        // one-band mesh to a parallel one and shrinking again, each agree
        // with `eval` at its own ωi. Phong's lobe follows the mirror
        // direction, so a value computed for another light is far off.
        let b = crate::ModelSpec::from_json("phong", &serde_json::json!({"e": 40.0}))
            .unwrap()
            .build()
            .unwrap();
        let (a, c) = (
            frame::from_spherical(0.3, 0.2),
            frame::from_spherical(1.1, 2.0),
        );
        let (small, large) = ((6, 10), (64, 128));
        let mut mesh = LobeMesh::default();
        for (wi, (n_theta, n_phi)) in [(a, small), (c, small), (c, large), (a, large), (a, small)] {
            let opts = LobeOptions {
                n_theta,
                n_phi,
                ..LobeOptions::default()
            };
            build_into(b.as_ref(), wi, &opts, &mut mesh);
            let g = grid(n_theta, n_phi, false);
            let wi32 = wi.as_vec3().as_dvec3();
            for (k, v) in mesh.values.iter().enumerate() {
                let want = b.eval(wi32, grid_dir(&g, k))[0];
                let tol = (1e-4 * want.abs()).max(1e-6);
                assert!(
                    (v[0] as f64 - want).abs() <= tol,
                    "{n_theta}x{n_phi} at {wi}, vertex {k}: {} vs {want}",
                    v[0]
                );
            }
        }
    }

    #[test]
    fn isotropic_rings_are_mirrored_where_the_plane_of_incidence_maps_columns() {
        let ct = crate::ModelSpec::new("cook-torrance")
            .unwrap()
            .build()
            .unwrap();
        let n = 40;
        let at = |phi: f64| frame::from_spherical(0.5, phi);
        let step = PI / n as f64;
        assert_eq!(mirror_axis(ct.as_ref(), at(0.0), n), Some(0));
        assert_eq!(mirror_axis(ct.as_ref(), at(3.0 * step), n), Some(3));
        assert_eq!(mirror_axis(ct.as_ref(), at(-4.0 * step), n), Some(36));
        assert_eq!(mirror_axis(ct.as_ref(), at(PI), n), Some(0));
        assert_eq!(mirror_axis(ct.as_ref(), DVec3::Z, n), Some(0));
        assert_eq!(mirror_axis(ct.as_ref(), at(0.3), n), None);
        // Not for a model that is not isotropic, nor for a file's claims.
        let ward = crate::ModelSpec::from_json(
            "ward",
            &serde_json::json!({"alpha_x": 0.1, "alpha_y": 0.4}),
        )
        .unwrap()
        .build()
        .unwrap();
        assert_eq!(mirror_axis(ward.as_ref(), at(0.0), n), None);
        // A file's claims are observations, not promises.
        #[derive(Debug)]
        struct Observed;
        impl Brdf for Observed {
            fn id(&self) -> &'static str {
                "observed"
            }
            fn eval(&self, _wi: DVec3, _wo: DVec3) -> crate::Rgb {
                crate::Rgb::splat(0.1)
            }
            fn claims(&self) -> crate::Claims {
                crate::Claims {
                    reciprocal: true,
                    energy_conserving: true,
                    isotropic: true,
                }
            }
            fn claims_declared(&self) -> bool {
                false
            }
        }
        assert_eq!(mirror_axis(&Observed, at(0.0), n), None);
    }

    #[test]
    fn build_into_reuses_buffers_and_equals_build() {
        let ward = crate::ModelSpec::new("ward").unwrap().build().unwrap();
        let glass = crate::ModelSpec::new("glass").unwrap().build().unwrap();
        let wi = frame::from_spherical(0.5, 0.2);
        let opts = LobeOptions::default();
        let mut mesh = build(ward.as_ref(), wi, &opts);
        let ptr = mesh.values.as_ptr();
        let wi2 = frame::from_spherical(1.0, 0.2);
        build_into(ward.as_ref(), wi2, &opts, &mut mesh);
        assert_eq!(mesh.values.as_ptr(), ptr, "buffer reallocated");
        assert_eq!(mesh, build(ward.as_ref(), wi2, &opts));
        // A model covering the whole sphere, then a new resolution.
        build_into(glass.as_ref(), wi, &opts, &mut mesh);
        assert_eq!(mesh, build(glass.as_ref(), wi, &opts));
        let small = LobeOptions {
            n_theta: 5,
            n_phi: 7,
            ..opts
        };
        build_into(ward.as_ref(), wi, &small, &mut mesh);
        assert_eq!(mesh, build(ward.as_ref(), wi, &small));
        assert_eq!(mesh.positions.len(), 6 * 7);
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
