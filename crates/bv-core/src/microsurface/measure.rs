//! The virtual gonioreflectometer's measurements, each with its error:
//! the surface's NDF and slope variance against the model's D, masking G1
//! against Smith's closed form, and the BRDF and ρhd split into single and
//! multiple bounces.
//!
//! Error bars: every ray is an independent draw (its start point on the tile
//! is uniform and its batch has its own random stream), so a measured mean
//! of per-ray contributions `X` has standard error `√((⟨X²⟩ − ⟨X⟩²)/n)`
//! (binomial for the G1 escape fraction). They are errors *for this surface*:
//! a different seed draws a different surface, whose NDF differs from the
//! model's by the finite-size fluctuation the NDF numbers show. The BRDF and
//! ρ also carry `*_sigma_surface`, the standard error from the spread of the
//! estimates of 4 × 4 start tiles, which holds that fluctuation too (on a
//! 256² Beckmann surface at α = 0.5 the per-bin ray-noise z-scores against
//! Cook–Torrance had a spread of 3.9, not 1: the surface, not the rays,
//! dominated). Between two surfaces of different seeds the tiles' σ gives
//! z-scores of RMS 1.0–1.15 (the test `surface_error_bars_…`): about 10 %
//! small, since rays cross tile borders and the tiles are not quite
//! independent.

use super::surface::{Surface, mix_seed};
use super::trace::{FacetId, SimFresnel, Walk, walk};
use crate::error::{BvError, Result};
use crate::microfacet::{Geometry, Microfacet};
use crate::quadrature::gauss_legendre;
use glam::DVec3;
use rand::Rng;
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};
use std::sync::Arc;

/// Rays per batch: the unit of parallel work, of progress and of the random
/// streams (batch b draws from stream `mix(seed, b)`, so the result does not
/// depend on the number of threads).
pub const BATCH: usize = 4096;
/// The tile is cut into `TILES × TILES` start tiles for the surface-aware
/// error bars (see [`Gonio::single_sigma_surface`]).
pub const TILES: usize = 4;
/// Most rays one measurement accepts: 2³⁴, or what a 32-bit `usize` (wasm32)
/// holds.
pub const MAX_RAYS: usize = if usize::BITS >= 64 {
    1 << (34 % usize::BITS)
} else {
    usize::MAX
};

/// Slope statistics of a surface's triangles (per unit projected area: every
/// triangle has the same projected area).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlopeStats {
    /// ⟨sx²⟩ (Beckmann's target: αx²/2).
    pub var_x: f64,
    /// ⟨sy²⟩ (Beckmann's target: αy²/2).
    pub var_y: f64,
    /// ⟨sx sy⟩ (0 for an axis-aligned distribution).
    pub cov_xy: f64,
}

/// The second moments of the triangles' slopes.
pub fn slope_stats(s: &Surface) -> SlopeStats {
    let (mut xx, mut yy, mut xy) = (0.0, 0.0, 0.0);
    s.for_each_slope(|sx, sy| {
        xx += sx * sx;
        yy += sy * sy;
        xy += sx * sy;
    });
    let n = s.facet_count() as f64;
    SlopeStats {
        var_x: xx / n,
        var_y: yy / n,
        cov_xy: xy / n,
    }
}

/// The projected-area histogram of the facet normals against the model: bins
/// uniform in θm over `[0, theta_max]` and in φm, plus one bin for
/// everything steeper.
#[derive(Debug, Clone, PartialEq)]
pub struct NdfHistogram {
    /// θ bins.
    pub n_theta: usize,
    /// φ bins.
    pub n_phi: usize,
    /// Upper edge of the last θ bin (radians).
    pub theta_max: f64,
    /// Share of the projected area in each bin (row-major θ, φ), then the
    /// steeper-than-`theta_max` share last.
    pub measured: Vec<f64>,
    /// `∫_bin D(m) cos θm dωm` of the model for the same bins (and 1 − their
    /// sum last): the share the model predicts.
    pub expected: Vec<f64>,
}

impl NdfHistogram {
    /// `Σ |measured − expected|` over all bins: the L1 (twice the total
    /// variation) distance of the two distributions of normals, 0 for a
    /// perfect match, 2 at most.
    pub fn rel_error(&self) -> f64 {
        self.measured
            .iter()
            .zip(&self.expected)
            .map(|(m, e)| (m - e).abs())
            .sum()
    }

    /// The measured D averaged over bin `b` (`share / ∫_bin cos θ dω`), and
    /// the model's, for the θ–φ bins.
    pub fn d_values(&self, b: usize) -> (f64, f64) {
        let c = self.bin_cos_integral(b / self.n_phi);
        (self.measured[b] / c, self.expected[b] / c)
    }

    fn bin_cos_integral(&self, t: usize) -> f64 {
        let dt = self.theta_max / self.n_theta as f64;
        let (a, b) = (t as f64 * dt, (t + 1) as f64 * dt);
        // ∫ cos θ sin θ dθ dφ over the bin.
        (TAU / self.n_phi as f64) * 0.5 * (b.sin().powi(2) - a.sin().powi(2))
    }
}

/// The NDF histogram of `s` (θ bins up to `atan(4 α_max)`, at most 89°).
pub fn ndf_histogram(s: &Surface, n_theta: usize, n_phi: usize) -> NdfHistogram {
    let o = s.options();
    let theta_max = (4.0 * o.alpha_x.max(o.alpha_y))
        .atan()
        .min(89f64.to_radians());
    let bins = n_theta * n_phi;
    let mut measured = vec![0.0; bins + 1];
    s.for_each_slope(|sx, sy| {
        let m = DVec3::new(-sx, -sy, 1.0).normalize();
        let theta = m.z.clamp(-1.0, 1.0).acos();
        let t = (theta / theta_max * n_theta as f64) as usize;
        if t >= n_theta {
            measured[bins] += 1.0;
        } else {
            let phi = m.y.atan2(m.x).rem_euclid(TAU);
            let p = ((phi / TAU * n_phi as f64) as usize).min(n_phi - 1);
            measured[t * n_phi + p] += 1.0;
        }
    });
    let total = s.facet_count() as f64;
    for v in measured.iter_mut() {
        *v /= total;
    }
    let mf = s.microfacet();
    let gl = gauss_legendre(12);
    let dt = theta_max / n_theta as f64;
    let dp = TAU / n_phi as f64;
    let mut expected = vec![0.0; bins + 1];
    for t in 0..n_theta {
        for p in 0..n_phi {
            let mut sum = 0.0;
            for &(xt, wt) in &gl {
                let th = (t as f64 + 0.5 + 0.5 * xt) * dt;
                for &(xp, wp) in &gl {
                    let ph = (p as f64 + 0.5 + 0.5 * xp) * dp;
                    let m = DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                    sum += wt * wp * mf.d(m) * th.cos() * th.sin();
                }
            }
            expected[t * n_phi + p] = sum * 0.25 * dt * dp;
        }
    }
    expected[bins] = (1.0 - expected[..bins].iter().sum::<f64>()).max(0.0);
    NdfHistogram {
        n_theta,
        n_phi,
        theta_max,
        measured,
        expected,
    }
}

/// A direction from polar angles (radians).
pub fn direction(theta: f64, phi: f64) -> DVec3 {
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

// ---------------------------------------------------------------- G1

/// One masking measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct G1Point {
    /// θ of the direction (radians).
    pub theta: f64,
    /// φ of the direction (radians).
    pub phi: f64,
    /// Escape fraction of rays leaving front-facing surface points.
    pub measured: f64,
    /// Its binomial standard error.
    pub sigma: f64,
    /// Smith's `1/(1 + Λ)` for the model's D.
    pub smith: f64,
    /// `cos θ / ((1/A) Σ A_facet ⟨ω, m⟩⁺)`: what the masking identity (Heitz
    /// 2014, eq. 2) gives with *this surface's* facets in place of D (no
    /// rays; it separates an NDF mismatch from a masking one).
    pub identity: f64,
    /// Rays traced.
    pub rays: usize,
    /// Rays lost to numerical failure (not counted either way).
    pub lost: usize,
}

/// Measures masking G1(ω) for each `theta` (radians) at azimuth `phi`.
///
/// Definition (Heitz 2014, JCGT 3(2), eq. 2 and §3): G1(ω) is the share of
/// the microsurface's area projected onto ω, counting only front-facing
/// facets (`⟨ω, m⟩ > 0`), that is visible from ω. It is measured as it
/// reads: points are drawn on the front-facing triangles with probability
/// proportional to `A_facet ⟨ω, m⟩` (a triangle by its weight, a point
/// uniformly on it), and a ray is traced from each towards ω; G1 is the
/// fraction that escape. Binomial error `√(p(1 − p)/n)`.
pub fn measure_g1(
    s: &Surface,
    thetas: &[f64],
    phi: f64,
    rays: usize,
    seed: u64,
) -> Result<Vec<G1Point>> {
    check_rays(rays)?;
    let mut out = Vec::with_capacity(thetas.len());
    for (k, &theta) in thetas.iter().enumerate() {
        if !(0.0..PI / 2.0).contains(&theta) {
            return Err(BvError::Invalid(format!(
                "masking angle {:.3}° must be in [0°, 90°)",
                theta.to_degrees()
            )));
        }
        out.push(g1_at(s, theta, phi, rays, mix_seed(seed, 1000 + k as u64)));
    }
    Ok(out)
}

fn check_rays(rays: usize) -> Result<()> {
    if rays == 0 || rays > MAX_RAYS {
        return Err(BvError::Invalid(format!(
            "ray count {rays} must be in [1, {MAX_RAYS}]"
        )));
    }
    Ok(())
}

fn g1_at(s: &Surface, theta: f64, phi: f64, rays: usize, seed: u64) -> G1Point {
    let w = direction(theta, phi);
    let n = s.size();
    // Weight of a triangle: true area ∝ 1/m.z (equal projected areas) times
    // ⟨ω, m⟩⁺. Cumulative sums in a fixed order.
    let mut cdf = Vec::with_capacity(s.facet_count());
    let mut acc = 0.0;
    for j in 0..n {
        for i in 0..n {
            for t in 0..2 {
                let m = s.facet(i, j, t).normal();
                acc += w.dot(m).max(0.0) / m.z;
                cdf.push(acc);
            }
        }
    }
    let identity = w.z / (acc / s.facet_count() as f64);
    let smith = s.microfacet().g1(w);
    let batches = rays.div_ceil(BATCH);
    let counts: Vec<(usize, usize)> = (0..batches)
        .into_par_iter()
        .map(|b| {
            let count = BATCH.min(rays - b * BATCH);
            let mut rng = crate::sampling::rng(mix_seed(seed, b as u64));
            let (mut esc, mut lost) = (0usize, 0usize);
            for _ in 0..count {
                let x = rng.random::<f64>() * acc;
                let idx = cdf.partition_point(|&c| c <= x).min(cdf.len() - 1);
                let (i, j, t) = ((idx / 2) % n, idx / 2 / n, idx % 2);
                let p = point_on(s, (i, j, t), rng.random(), rng.random());
                match walk(s, p, w, Some((i, j, t)), SimFresnel::None, 0, None) {
                    Walk::Left { .. } => esc += 1,
                    Walk::Dropped => {}
                    Walk::Lost => lost += 1,
                }
            }
            (esc, lost)
        })
        .collect();
    let (esc, lost) = counts
        .iter()
        .fold((0, 0), |(e, l), &(e2, l2)| (e + e2, l + l2));
    let used = (rays - lost).max(1);
    let p = esc as f64 / used as f64;
    G1Point {
        theta,
        phi,
        measured: p,
        sigma: (p * (1.0 - p) / used as f64).sqrt(),
        smith,
        identity,
        rays,
        lost,
    }
}

/// A uniform point on triangle `id` from two uniforms (the unit square
/// folded onto the triangle's half of the cell).
fn point_on(s: &Surface, (i, j, t): FacetId, mut a: f64, mut b: f64) -> DVec3 {
    if Surface::main_diagonal(i, j) {
        if (t == 0) != (a >= b) {
            std::mem::swap(&mut a, &mut b);
        }
    } else if (t == 0) != (a + b <= 1.0) {
        a = 1.0 - a;
        b = 1.0 - b;
    }
    let (dx, dy) = s.cell();
    let f = s.facet(i, j, t);
    let (u, v) = (a * dx, b * dy);
    DVec3::new(
        i as f64 * dx + u,
        j as f64 * dy + v,
        f.a + f.sx * u + f.sy * v,
    )
}

// ------------------------------------------------------- gonioreflectometer

/// What the gonioreflectometer measures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GonioOptions {
    /// Incident θ (radians, [0, 90°)).
    pub theta_i: f64,
    /// Incident φ (radians).
    pub phi_i: f64,
    /// Rays to trace.
    pub rays: usize,
    /// Seed of the rays' random streams.
    pub seed: u64,
    /// Fresnel factor per bounce.
    pub fresnel: SimFresnel,
    /// Bounce cap (rays still on the surface after it are dropped, counted).
    pub max_bounces: u32,
    /// Outgoing bins uniform in cos θo.
    pub n_theta: usize,
    /// Outgoing bins uniform in φo.
    pub n_phi: usize,
}

impl GonioOptions {
    /// Defaults: F = 1, 64 bounces, 18 × 36 equal-solid-angle bins.
    pub fn new(theta_i: f64, rays: usize, seed: u64) -> Self {
        Self {
            theta_i,
            phi_i: 0.0,
            rays,
            seed,
            fresnel: SimFresnel::None,
            max_bounces: 64,
            n_theta: 18,
            n_phi: 36,
        }
    }

    fn validate(&self) -> Result<()> {
        check_rays(self.rays)?;
        if !(self.theta_i.is_finite() && (0.0..PI / 2.0).contains(&self.theta_i)) {
            return Err(BvError::Invalid(format!(
                "incident θ {:.3}° must be in [0°, 90°)",
                self.theta_i.to_degrees()
            )));
        }
        if !self.phi_i.is_finite() {
            return Err(BvError::Invalid("incident φ must be finite".into()));
        }
        if !(1..=1024).contains(&self.n_theta) || !(1..=1024).contains(&self.n_phi) {
            return Err(BvError::Invalid(format!(
                "outgoing bins must be 1..=1024 per axis, got {} × {}",
                self.n_theta, self.n_phi
            )));
        }
        if self.max_bounces == 0 || self.max_bounces > 10_000 {
            return Err(BvError::Invalid(format!(
                "bounce cap {} must be in [1, 10000]",
                self.max_bounces
            )));
        }
        if let SimFresnel::Conductor { eta, k } = self.fresnel
            && !(eta.is_finite() && eta > 0.0 && k.is_finite() && k >= 0.0)
        {
            return Err(BvError::Invalid(format!(
                "conductor index η = {eta}, k = {k}: need η > 0, k ≥ 0"
            )));
        }
        Ok(())
    }

    /// Bin of an outgoing direction (row-major cos θ, φ), `None` below the horizon.
    pub fn bin_of(&self, w: DVec3) -> Option<usize> {
        if w.z <= 0.0 {
            return None;
        }
        let t = (((1.0 - w.z) * self.n_theta as f64) as usize).min(self.n_theta - 1);
        let phi = w.y.atan2(w.x).rem_euclid(TAU);
        let p = ((phi / TAU * self.n_phi as f64) as usize).min(self.n_phi - 1);
        Some(t * self.n_phi + p)
    }

    /// Bin `b`'s bounds: (cos θ high, cos θ low, φ low, φ high).
    pub fn bin_bounds(&self, b: usize) -> (f64, f64, f64, f64) {
        let (t, p) = (b / self.n_phi, b % self.n_phi);
        let dz = 1.0 / self.n_theta as f64;
        let dp = TAU / self.n_phi as f64;
        (
            1.0 - t as f64 * dz,
            1.0 - (t + 1) as f64 * dz,
            p as f64 * dp,
            (p + 1) as f64 * dp,
        )
    }

    /// `∫_bin cos θ dω` (the projected solid angle that turns a bin's
    /// share of the flux into a mean BRDF value).
    pub fn bin_cos_integral(&self, b: usize) -> f64 {
        let (hi, lo, p0, p1) = self.bin_bounds(b);
        (p1 - p0) * 0.5 * (hi * hi - lo * lo)
    }
}

/// Sums over rays (all per ray, divided by the count at the end).
#[derive(Debug, Clone, PartialEq, Default)]
struct Tally {
    rays: usize,
    dropped: usize,
    lost: usize,
    single: Vec<f64>,
    single_sq: Vec<f64>,
    multiple: Vec<f64>,
    multiple_sq: Vec<f64>,
    s1: f64,
    s1_sq: f64,
    sm: f64,
    sm_sq: f64,
    st_sq: f64,
    bounces: Vec<u64>,
    /// Per start tile ([`TILES`]² of them): rays, single and multiple sums
    /// per bin (tile-major), and the ρ sums.
    tile_rays: Vec<usize>,
    tile_single: Vec<f64>,
    tile_multiple: Vec<f64>,
    tile_s1: Vec<f64>,
    tile_sm: Vec<f64>,
}

impl Tally {
    fn new(bins: usize) -> Self {
        Self {
            single: vec![0.0; bins],
            single_sq: vec![0.0; bins],
            multiple: vec![0.0; bins],
            multiple_sq: vec![0.0; bins],
            bounces: vec![0; 17],
            tile_rays: vec![0; TILES * TILES],
            tile_single: vec![0.0; TILES * TILES * bins],
            tile_multiple: vec![0.0; TILES * TILES * bins],
            tile_s1: vec![0.0; TILES * TILES],
            tile_sm: vec![0.0; TILES * TILES],
            ..Default::default()
        }
    }

    fn add(&mut self, o: &Tally) {
        self.rays += o.rays;
        self.dropped += o.dropped;
        self.lost += o.lost;
        for (a, b) in [
            (&mut self.single, &o.single),
            (&mut self.single_sq, &o.single_sq),
            (&mut self.multiple, &o.multiple),
            (&mut self.multiple_sq, &o.multiple_sq),
        ] {
            for (x, y) in a.iter_mut().zip(b) {
                *x += y;
            }
        }
        self.s1 += o.s1;
        self.s1_sq += o.s1_sq;
        self.sm += o.sm;
        self.sm_sq += o.sm_sq;
        self.st_sq += o.st_sq;
        for (x, y) in self.bounces.iter_mut().zip(&o.bounces) {
            *x += y;
        }
        for (x, y) in self.tile_rays.iter_mut().zip(&o.tile_rays) {
            *x += y;
        }
        for (a, b) in [
            (&mut self.tile_single, &o.tile_single),
            (&mut self.tile_multiple, &o.tile_multiple),
            (&mut self.tile_s1, &o.tile_s1),
            (&mut self.tile_sm, &o.tile_sm),
        ] {
            for (x, y) in a.iter_mut().zip(b) {
                *x += y;
            }
        }
    }
}

/// A finished gonioreflectometer measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct Gonio {
    /// What was measured.
    pub opts: GonioOptions,
    /// Rays traced.
    pub rays: usize,
    /// Rays still bouncing at the cap (their energy is missing from ρ).
    pub dropped: usize,
    /// Rays lost to numerical failure of the traversal.
    pub lost: usize,
    /// Mean BRDF of single-bounce light per bin (1/sr), row-major (cos θ, φ).
    pub single: Vec<f64>,
    /// Its standard error.
    pub single_sigma: Vec<f64>,
    /// Mean BRDF of light that bounced twice or more, per bin.
    pub multiple: Vec<f64>,
    /// Its standard error.
    pub multiple_sigma: Vec<f64>,
    /// ρhd(θi) of single-bounce light.
    pub rho_single: f64,
    /// Its standard error.
    pub rho_single_sigma: f64,
    /// ρhd(θi) of multiple-bounce light.
    pub rho_multiple: f64,
    /// Its standard error.
    pub rho_multiple_sigma: f64,
    /// Standard error of the total ρhd (single + multiple).
    pub rho_sigma: f64,
    /// Standard error of [`Gonio::single`] from the spread of the
    /// [`TILES`]² start tiles' estimates: it holds the ray noise *and* the
    /// surface's own fluctuation (each tile is a nearly independent piece of
    /// surface when the tile is much wider than the correlation length), so
    /// it is the error bar against the *model*; `single_sigma` is the one
    /// for this surface.
    pub single_sigma_surface: Vec<f64>,
    /// The same for [`Gonio::multiple`].
    pub multiple_sigma_surface: Vec<f64>,
    /// The same for `rho_single`.
    pub rho_single_sigma_surface: f64,
    /// The same for `rho_multiple`.
    pub rho_multiple_sigma_surface: f64,
    /// Rays that left after 1, 2, … 16 bounces (index = bounces, the last
    /// counts 16 and more).
    pub bounce_counts: Vec<u64>,
}

impl Gonio {
    /// Total ρhd(θi).
    pub fn rho(&self) -> f64 {
        self.rho_single + self.rho_multiple
    }

    /// The analytic single-bounce Cook–Torrance BRDF `F D G / (4 cos θi cos θo)`
    /// (G = Smith height-correlated, F at ⟨ωi, h⟩) averaged over bin `b`
    /// with weight cos θo, by Gauss–Legendre in cos θo and φo.
    pub fn analytic_single(&self, mf: &Microfacet, b: usize) -> f64 {
        let o = &self.opts;
        let wi = direction(o.theta_i, o.phi_i);
        let (hi, lo, p0, p1) = o.bin_bounds(b);
        let gl = gauss_legendre(8);
        let mut sum = 0.0;
        for &(xz, wz) in &gl {
            let z = 0.5 * (hi + lo) + 0.5 * (hi - lo) * xz;
            for &(xp, wp) in &gl {
                let ph = 0.5 * (p0 + p1) + 0.5 * (p1 - p0) * xp;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let wo = DVec3::new(r * ph.cos(), r * ph.sin(), z);
                let h = (wi + wo).normalize();
                let f = o.fresnel.eval(wi.dot(h))
                    * mf.d(h)
                    * mf.g(Geometry::SmithCorrelated, wi, wo, h)
                    / (4.0 * wi.z * wo.z);
                sum += wz * wp * f * z;
            }
        }
        sum * 0.25 * (hi - lo) * (p1 - p0) / o.bin_cos_integral(b)
    }
}

/// The gonioreflectometer as a job in steps: each [`GonioJob::step`] traces
/// a few batches (in parallel) and adds them in batch order, so the result
/// is the same for any thread count and any step sizes. Cancelling is not
/// calling `step` again.
#[derive(Debug, Clone)]
pub struct GonioJob {
    surface: Arc<Surface>,
    opts: GonioOptions,
    next: usize,
    batches: usize,
    tally: Tally,
}

impl GonioJob {
    /// A job measuring `surface` as `opts` says (checked here).
    pub fn new(surface: Arc<Surface>, opts: GonioOptions) -> Result<Self> {
        opts.validate()?;
        Ok(Self {
            surface,
            batches: opts.rays.div_ceil(BATCH),
            tally: Tally::new(opts.n_theta * opts.n_phi),
            opts,
            next: 0,
        })
    }

    /// Batches done and in all.
    pub fn progress(&self) -> (usize, usize) {
        (self.next, self.batches)
    }

    /// Traces up to `batches` more batches (at least one); the measurement
    /// once all are done.
    pub fn step(&mut self, batches: usize) -> Option<Gonio> {
        let end = (self.next + batches.max(1)).min(self.batches);
        let s = &*self.surface;
        let o = &self.opts;
        let parts: Vec<Tally> = (self.next..end)
            .into_par_iter()
            .map(|b| run_batch(s, o, b))
            .collect();
        for p in &parts {
            self.tally.add(p);
        }
        self.next = end;
        (self.next == self.batches).then(|| self.finish())
    }

    /// Runs every remaining batch.
    pub fn run(mut self) -> Gonio {
        loop {
            if let Some(g) = self.step(64) {
                return g;
            }
        }
    }

    /// The measurement from the batches done so far (for a progressive view).
    pub fn partial(&self) -> Option<Gonio> {
        (self.tally.rays > 0).then(|| self.finish())
    }

    fn finish(&self) -> Gonio {
        let t = &self.tally;
        let n = t.rays as f64;
        let mean_sigma = |s: f64, sq: f64| {
            let m = s / n;
            (m, ((sq / n - m * m).max(0.0) / n).sqrt())
        };
        let bins = self.opts.n_theta * self.opts.n_phi;
        let mut single = vec![0.0; bins];
        let mut single_sigma = vec![0.0; bins];
        let mut multiple = vec![0.0; bins];
        let mut multiple_sigma = vec![0.0; bins];
        for b in 0..bins {
            let c = self.opts.bin_cos_integral(b);
            let (m, s) = mean_sigma(t.single[b], t.single_sq[b]);
            single[b] = m / c;
            single_sigma[b] = s / c;
            let (m, s) = mean_sigma(t.multiple[b], t.multiple_sq[b]);
            multiple[b] = m / c;
            multiple_sigma[b] = s / c;
        }
        // Standard error of the mean from the spread of the tiles' means
        // (tiles without rays left out).
        let between = |sums: &[f64], b: usize, stride: usize, c: f64| {
            let means: Vec<f64> = t
                .tile_rays
                .iter()
                .enumerate()
                .filter(|(_, r)| **r > 0)
                .map(|(k, r)| sums[k * stride + b] / *r as f64 / c)
                .collect();
            let k = means.len() as f64;
            if k < 2.0 {
                return f64::INFINITY;
            }
            let m = means.iter().sum::<f64>() / k;
            (means.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (k * (k - 1.0))).sqrt()
        };
        let single_sigma_surface: Vec<f64> = (0..bins)
            .map(|b| between(&t.tile_single, b, bins, self.opts.bin_cos_integral(b)))
            .collect();
        let multiple_sigma_surface: Vec<f64> = (0..bins)
            .map(|b| between(&t.tile_multiple, b, bins, self.opts.bin_cos_integral(b)))
            .collect();
        let (rho_single, rho_single_sigma) = mean_sigma(t.s1, t.s1_sq);
        let (rho_multiple, rho_multiple_sigma) = mean_sigma(t.sm, t.sm_sq);
        let (_, rho_sigma) = mean_sigma(t.s1 + t.sm, t.st_sq);
        Gonio {
            opts: self.opts,
            rays: t.rays,
            dropped: t.dropped,
            lost: t.lost,
            single,
            single_sigma,
            multiple,
            multiple_sigma,
            rho_single,
            rho_single_sigma,
            rho_multiple,
            rho_multiple_sigma,
            rho_sigma,
            single_sigma_surface,
            multiple_sigma_surface,
            rho_single_sigma_surface: between(&t.tile_s1, 0, 1, 1.0),
            rho_multiple_sigma_surface: between(&t.tile_sm, 0, 1, 1.0),
            bounce_counts: t.bounces.clone(),
        }
    }
}

/// Batch `b`: rays from ωi entering the tile uniformly through the plane
/// above its highest point (a parallel beam's flux is uniform over any
/// horizontal plane, and the tile is periodic).
fn run_batch(s: &Surface, o: &GonioOptions, b: usize) -> Tally {
    let count = BATCH.min(o.rays - b * BATCH);
    let mut t = Tally::new(o.n_theta * o.n_phi);
    t.rays = count;
    let bins = o.n_theta * o.n_phi;
    let mut rng = crate::sampling::rng(mix_seed(o.seed, b as u64));
    let (dx, dy) = s.cell();
    let (wx, wy) = (dx * s.size() as f64, dy * s.size() as f64);
    let (_, hmax) = s.height_range();
    let d = -direction(o.theta_i, o.phi_i);
    for _ in 0..count {
        let (u, v) = (rng.random::<f64>(), rng.random::<f64>());
        let p = DVec3::new(u * wx, v * wy, hmax);
        let tile = ((v * TILES as f64) as usize).min(TILES - 1) * TILES
            + ((u * TILES as f64) as usize).min(TILES - 1);
        t.tile_rays[tile] += 1;
        match walk(s, p, d, None, o.fresnel, o.max_bounces, None) {
            Walk::Left {
                dir,
                bounces,
                weight,
            } => {
                t.bounces[(bounces as usize).min(16)] += 1;
                t.st_sq += weight * weight;
                let bin = o.bin_of(dir);
                if bounces <= 1 {
                    t.s1 += weight;
                    t.tile_s1[tile] += weight;
                    t.s1_sq += weight * weight;
                    if let Some(k) = bin {
                        t.single[k] += weight;
                        t.tile_single[tile * bins + k] += weight;
                        t.single_sq[k] += weight * weight;
                    }
                } else {
                    t.sm += weight;
                    t.tile_sm[tile] += weight;
                    t.sm_sq += weight * weight;
                    if let Some(k) = bin {
                        t.multiple[k] += weight;
                        t.tile_multiple[tile * bins + k] += weight;
                        t.multiple_sq[k] += weight * weight;
                    }
                }
            }
            Walk::Dropped => t.dropped += 1,
            Walk::Lost => t.lost += 1,
        }
    }
    t
}
