//! The microsurface view's result: a small simulated surface
//! (`bv_core::microsurface`), a few ray paths traced on it from the scene's
//! light, masking G1 at θi against Smith and the gonioreflectometer's ρhd
//! (single and multiple bounces) — a job in steps (generate, paths, batches
//! of rays, G1) with progress, cached by what it depends on.

use super::jobs::{self, Shown, Slots, Steps, Waker};
use crate::session::frame::Scene;
use crate::session::state::MicrosurfaceSettings;
use bv_core::microsurface::measure::{self, G1Point, Gonio, GonioJob, GonioOptions, NdfHistogram};
use bv_core::microsurface::trace::{Walk, walk};
use bv_core::microsurface::{SimFresnel, SlopeDistribution, Surface, SurfaceOptions};
use glam::DVec3;
use std::sync::Arc;
use std::time::Duration;

/// Grid side of the view's surface (128²: generated in milliseconds, and
/// wide enough, at 4 cells of correlation, for a few per cent on ρ).
pub const SIZE: usize = 128;
/// Rays for ρhd in the window and in figures.
pub const RAYS: usize = 200_000;
/// Ray paths drawn.
pub const PATHS: usize = 12;

/// What a result was computed for: distribution, αx and αy (bits), θi and
/// φi (bits).
pub type Key = (SlopeDistribution, u64, u64, u64, u64);

/// Roughness range of the view's specimens (a 128² surface at 4 cells of
/// correlation resolves these; see `SIZE`).
pub const ALPHA_RANGE: std::ops::RangeInclusive<f64> = 0.05..=1.5;

/// The surface the view simulates for a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Specimen {
    /// Slope distribution.
    pub distribution: SlopeDistribution,
    /// Roughness along x, in [`ALPHA_RANGE`].
    pub alpha_x: f64,
    /// Roughness along y, in [`ALPHA_RANGE`].
    pub alpha_y: f64,
    /// The BRDF it was taken from (its label), or `None` for the view's
    /// own settings.
    pub from: Option<String>,
}

impl Specimen {
    /// `GGX α 0.30` or `Beckmann αx 0.20, αy 0.50`.
    pub fn describe(&self) -> String {
        let d = self.distribution.label();
        if self.alpha_x == self.alpha_y {
            format!("{d} α {:.2}", self.alpha_x)
        } else {
            format!("{d} αx {:.2}, αy {:.2}", self.alpha_x, self.alpha_y)
        }
    }
}

/// The scene's specimen: the selected BRDF's distribution and roughness
/// when the settings say so and it names them (`bv_core::Ndf::slopes`),
/// else the settings' own (α clamped to [`ALPHA_RANGE`], 0.5 when not
/// finite).
pub fn specimen(scene: &Scene<'_>) -> Specimen {
    specimen_with(scene, &scene.state.plots.microsurface)
}

/// The specimen `set` gives for a scene (see [`specimen`]).
pub fn specimen_with(scene: &Scene<'_>, set: &MicrosurfaceSettings) -> Specimen {
    let clamp = |a: f64| {
        if a.is_finite() {
            a.clamp(*ALPHA_RANGE.start(), *ALPHA_RANGE.end())
        } else {
            0.5
        }
    };
    if set.from_model
        && let Some(b) = scene.primary()
        && let Some((d, ax, ay)) = b.brdf.ndf().and_then(|n| n.slopes())
        && let Some(distribution) = SlopeDistribution::from_distribution(d)
    {
        return Specimen {
            distribution,
            alpha_x: clamp(ax),
            alpha_y: clamp(ay),
            from: Some(b.label.clone()),
        };
    }
    let a = clamp(set.alpha);
    Specimen {
        distribution: set.distribution,
        alpha_x: a,
        alpha_y: a,
        from: None,
    }
}

/// A finished simulation for the view.
#[derive(Debug, Clone)]
pub struct Simulation {
    /// The surface.
    pub surface: Arc<Surface>,
    /// Ray paths from the light (points visited, the last the exit point),
    /// with their outgoing direction.
    pub paths: Vec<(Vec<DVec3>, DVec3)>,
    /// ρhd, BRDF bins, single and multiple.
    pub gonio: Gonio,
    /// Masking at the light's direction against Smith.
    pub g1: G1Point,
    /// ρhd of the single-scattering Cook–Torrance model with the same D,
    /// height-correlated Smith G and F = 1 (bin quadrature).
    pub analytic_rho: f64,
}

/// θm bins of [`ndf`]'s histogram.
pub const NDF_BINS: usize = 16;

/// Grid side of the surface whose normals [`ndf`] counts: the drawn 128²
/// patch holds about (128/4)² independent slopes, and its histogram strays
/// 5–8 % from D at the peak; 512² holds 16 times more.
pub const NDF_SIZE: usize = 512;

/// What a facet-normal histogram was computed for: distribution, αx and αy
/// (bits). Not the light: the histogram does not depend on it.
pub type NdfKey = (SlopeDistribution, u64, u64);

/// The histograms of the process (one slot).
pub fn ndf_slots() -> Arc<Slots<NdfKey, Arc<NdfHistogram>>> {
    jobs::slots("microsurface NDF")
}

/// The facet normals' histogram of the specimen against D (the view's
/// *NDF* chart): [`NDF_BINS`] bins in θm, all azimuths together, of a
/// [`NDF_SIZE`]² surface with the specimen's statistics. Computed once
/// per specimen, only when asked for, and kept while the light moves.
pub fn ndf(
    waker: &Waker,
    scene: &Scene<'_>,
    specimen: &Specimen,
) -> Shown<NdfKey, Arc<NdfHistogram>> {
    let (ax, ay) = (specimen.alpha_x, specimen.alpha_y);
    let key = (specimen.distribution, ax.to_bits(), ay.to_bits());
    let opts = SurfaceOptions::new(specimen.distribution, ax, ay, NDF_SIZE, 1);
    ndf_slots().for_frame(
        waker,
        0,
        key,
        scene.figure,
        Duration::from_millis(50),
        move || {
            // A bad option cannot come from the view (it clamps α).
            let surface = Surface::generate(&opts).ok()?;
            Some(Arc::new(measure::ndf_histogram(&surface, NDF_BINS, 1)))
        },
    )
}

/// The simulations of the process (one slot).
pub fn slots() -> Arc<Slots<Key, Arc<Simulation>>> {
    jobs::slots("microsurface simulation")
}

enum Phase {
    Start,
    Rays(Arc<Surface>, Vec<(Vec<DVec3>, DVec3)>, Box<GonioJob>),
    Done,
}

/// The job: the surface and the paths in the first step, then the batches
/// of rays, then G1.
struct Job {
    opts: SurfaceOptions,
    wi: DVec3,
    phase: Phase,
}

impl Steps<Arc<Simulation>> for Job {
    fn step(&mut self) -> Option<Arc<Simulation>> {
        match std::mem::replace(&mut self.phase, Phase::Done) {
            Phase::Start => {
                // A bad option cannot come from the view (it clamps α); a
                // failure shows as no result rather than a panic.
                let surface = Arc::new(Surface::generate(&self.opts).ok()?);
                let paths = trace_paths(&surface, self.wi);
                let theta = self.wi.z.clamp(-1.0, 1.0).acos().min(89f64.to_radians());
                let mut g = GonioOptions::new(theta, RAYS, 1);
                g.phi_i = self.wi.y.atan2(self.wi.x);
                let job = GonioJob::new(Arc::clone(&surface), g).ok()?;
                self.phase = Phase::Rays(surface, paths, Box::new(job));
                None
            }
            Phase::Rays(surface, paths, mut job) => {
                let Some(gonio) = job.step(4) else {
                    self.phase = Phase::Rays(surface, paths, job);
                    return None;
                };
                let o = gonio.opts;
                let g1 = measure::measure_g1(&surface, &[o.theta_i], o.phi_i, 20_000, 2)
                    .ok()?
                    .pop()?;
                let mf = surface.microfacet();
                let analytic_rho = (0..o.n_theta * o.n_phi)
                    .map(|b| gonio.analytic_single(&mf, b) * o.bin_cos_integral(b))
                    .sum();
                Some(Arc::new(Simulation {
                    surface,
                    paths,
                    gonio,
                    g1,
                    analytic_rho,
                }))
            }
            Phase::Done => None,
        }
    }

    fn progress(&self) -> Option<(usize, usize)> {
        match &self.phase {
            Phase::Rays(_, _, job) => Some(job.progress()),
            _ => None,
        }
    }
}

/// A few rays from the light aimed at the middle of the tile (where the
/// view draws), their paths recorded.
fn trace_paths(s: &Surface, wi: DVec3) -> Vec<(Vec<DVec3>, DVec3)> {
    let (dx, dy) = s.cell();
    let n = s.size();
    let (_, hmax) = s.height_range();
    let mut out = Vec::new();
    for k in 0..PATHS {
        // A fixed spread of targets (golden-ratio sequence) over the
        // central 16 × 16 cells. Each ray starts at the top of the tile's
        // heights on the line through its target, not straight above it: a
        // rough or steep surface's highest point lies far above the patch,
        // and a ray dropped from there at a low light travels many cells
        // (off the drawn patch) before it lands.
        let u = (k as f64 * 0.618_034).fract();
        let v = (k as f64 + 0.5) / PATHS as f64;
        let (i, j) = (
            n / 2 - 8 + (16.0 * u) as usize,
            n / 2 - 8 + (16.0 * v) as usize,
        );
        let target = DVec3::new(i as f64 * dx, j as f64 * dy, s.height(i, j));
        let p = target + wi * ((hmax - target.z) / wi.z.max(1e-3));
        let mut path = Vec::new();
        if let Walk::Left { dir, .. } = walk(s, p, -wi, None, SimFresnel::None, 64, Some(&mut path))
        {
            out.push((path, dir));
        }
    }
    out
}

/// The simulation for this frame's light: computed now for a figure, else
/// the latest finished one while a job computes it.
pub fn request(
    waker: &Waker,
    scene: &Scene<'_>,
    specimen: &Specimen,
) -> Shown<Key, Arc<Simulation>> {
    let wi = scene.wi();
    let wi = if wi.z > 0.017 {
        wi
    } else {
        // The gonioreflectometer takes light from above the horizon.
        DVec3::new(wi.x, wi.y, 0.017).normalize()
    };
    let (ax, ay) = (specimen.alpha_x, specimen.alpha_y);
    let key = (
        specimen.distribution,
        ax.to_bits(),
        ay.to_bits(),
        scene.incident.theta_deg.to_bits(),
        scene.incident.phi_deg.to_bits(),
    );
    let opts = SurfaceOptions::new(specimen.distribution, ax, ay, SIZE, 1);
    slots().for_frame(
        waker,
        0,
        key,
        scene.figure,
        Duration::from_millis(50),
        Job {
            opts,
            wi,
            phase: Phase::Start,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The view's job runs to its end: with F = 1 the surface returns all the
    /// light (ρ = 1 up to the dropped rays), its G1 at θi agrees with Smith
    /// within 3σ + 2 % (a Beckmann surface, where Smith is accurate), and
    /// the single-scattering model keeps less than the whole.
    #[test]
    fn the_job_finishes_with_consistent_numbers() {
        let wi = measure::direction(60f64.to_radians(), 0.4);
        let mut job = Job {
            opts: SurfaceOptions::new(SlopeDistribution::Beckmann, 0.6, 0.6, SIZE, 1),
            wi,
            phase: Phase::Start,
        };
        let sim = jobs::run_to_end(|| job.step());
        let g = &sim.gonio;
        assert_eq!(g.rays, RAYS);
        assert!((g.rho() - 1.0).abs() <= (g.dropped + g.lost) as f64 / RAYS as f64 + 1e-12);
        assert!(g.rho_multiple > 0.02, "{}", g.rho_multiple);
        assert!(sim.analytic_rho > 0.5 && sim.analytic_rho < 1.0);
        let p = &sim.g1;
        assert!(
            (p.measured - p.smith).abs() <= 3.0 * p.sigma + 0.02 * p.smith,
            "{} ± {} vs {}",
            p.measured,
            p.sigma,
            p.smith
        );
        assert!(!sim.paths.is_empty());
        assert!(
            sim.paths
                .iter()
                .all(|(path, dir)| path.len() >= 2 && dir.z > 0.0)
        );
    }
}
