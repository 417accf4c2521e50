//! The virtual gonioreflectometer's readings for the polar view's *gonio*
//! overlay (LECTURE.md N8): a detector swept through the plane of incidence
//! (`bv_core::analysis::gonio`) counts what the specimen scatters — photons
//! from the primary BRDF's own sampler, or (`plots.gonio_surface`, issue 29)
//! rays traced on a simulated microsurface with the BRDF's slopes, split
//! into single and multiple bounces. A job in batches with progress, cached
//! per BRDF, specimen and light, cancellable like every job.

use super::jobs::{self, Shown, Slots, Steps, Waker};
use crate::session::frame::Scene;
use bv_core::Brdf;
use bv_core::analysis::gonio::{self, Detector, GonioSetup, Reading, SurfaceTally, Tally};
use bv_core::microsurface::{SlopeDistribution, Surface, SurfaceOptions};
use std::sync::Arc;
use std::time::Duration;

/// Batches of photons per measurement (2¹⁸ each: 4 M photons, a few per
/// cent on a diffuse reading at a 1.5° aperture).
pub const BATCHES: u64 = 16;

/// Side of the simulated surface (1024²: 16 times the facets of the
/// microsurface view's patch, so that the surface's own randomness, which
/// dominates a 2.5° detector's error, stays at a few per cent).
pub const SURFACE_SIZE: usize = 1024;
/// Bounces followed before a ray is dropped (counted).
pub const MAX_BOUNCES: u32 = 64;

/// The specimen under the detector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Specimen {
    /// The model itself, through its sampler.
    Model,
    /// A simulated surface with these slopes (F = 1).
    Surface(SlopeDistribution, f64, f64),
}

/// What a measurement depends on: the BRDF's revision, θi and φi (bits),
/// and the specimen (distribution, αx and αy bits for a surface).
pub type Key = (u64, u64, u64, Option<(SlopeDistribution, u64, u64)>);

/// A finished measurement.
#[derive(Debug, Clone)]
pub struct Measurement {
    /// The setup it used.
    pub setup: GonioSetup,
    /// What was measured.
    pub specimen: Specimen,
    /// One reading per detector stop, in order of angle (everything that
    /// left a surface).
    pub readings: Vec<Reading>,
    /// For a surface, the single bounces alone.
    pub single: Option<Vec<Reading>>,
    /// Photons (rays) sent.
    pub photons: u64,
    /// Photons the sampler did not place, or rays lost or dropped.
    pub failed: u64,
}

/// The measurements of the process (slot: BRDF id).
pub fn slots() -> Arc<Slots<Key, Arc<Measurement>>> {
    jobs::slots("gonioreflectometer")
}

/// The job: two batches per step (one per core), merged in batch order so
/// that the result does not depend on the threads; a surface specimen is
/// generated in the first step.
struct Job {
    brdf: Arc<dyn Brdf>,
    setup: GonioSetup,
    specimen: Specimen,
    detectors: Vec<Detector>,
    surface: Option<Surface>,
    tally: Tally,
    surface_tally: SurfaceTally,
    next: u64,
}

impl Job {
    fn new(brdf: Arc<dyn Brdf>, setup: GonioSetup, specimen: Specimen) -> Self {
        let detectors = setup.detectors();
        let n = detectors.len();
        Self {
            brdf,
            setup,
            specimen,
            detectors,
            surface: None,
            tally: Tally::new(n),
            surface_tally: SurfaceTally::new(n),
            next: 0,
        }
    }

    fn finish(&self) -> Arc<Measurement> {
        let (readings, single, photons, failed) = match self.specimen {
            Specimen::Model => (
                self.tally.readings(&self.detectors),
                None,
                self.tally.photons,
                self.tally.failed,
            ),
            Specimen::Surface(..) => {
                let (total, single) = self.surface_tally.readings(&self.detectors);
                let t = &self.surface_tally;
                (
                    total,
                    Some(single),
                    t.total.photons,
                    t.total.failed + t.dropped,
                )
            }
        };
        Arc::new(Measurement {
            setup: self.setup,
            specimen: self.specimen,
            readings,
            single,
            photons,
            failed,
        })
    }
}

impl Steps<Arc<Measurement>> for Job {
    fn step(&mut self) -> Option<Arc<Measurement>> {
        let (a, b) = (self.next, self.next + 1);
        match self.specimen {
            Specimen::Model => {
                let (brdf, setup, det) = (self.brdf.as_ref(), &self.setup, &self.detectors);
                let (ta, tb) = rayon::join(
                    || gonio::measure_batch(brdf, setup, det, a),
                    || gonio::measure_batch(brdf, setup, det, b),
                );
                self.tally.merge(&ta);
                self.tally.merge(&tb);
            }
            Specimen::Surface(dist, ax, ay) => {
                let Some(surface) = &self.surface else {
                    // A surface that cannot be made (the specimen's α is
                    // clamped to the generator's range, so this is not
                    // expected) ends the job with no readings rather
                    // than a panic.
                    let opts = SurfaceOptions::new(dist, ax, ay, SURFACE_SIZE, self.setup.seed);
                    match Surface::generate(&opts) {
                        Ok(s) => self.surface = Some(s),
                        Err(_) => self.next = BATCHES,
                    }
                    return (self.next >= BATCHES).then(|| self.finish());
                };
                let (setup, det) = (&self.setup, &self.detectors);
                let (ta, tb) = rayon::join(
                    || gonio::measure_surface_batch(surface, setup, det, a, MAX_BOUNCES),
                    || gonio::measure_surface_batch(surface, setup, det, b, MAX_BOUNCES),
                );
                self.surface_tally.merge(&ta);
                self.surface_tally.merge(&tb);
            }
        }
        self.next += 2;
        (self.next >= BATCHES).then(|| self.finish())
    }

    fn progress(&self) -> Option<(usize, usize)> {
        Some((self.next as usize, BATCHES as usize))
    }
}

/// The setup for a scene: its light, the whole circle for a transmitting
/// BRDF measured through its sampler, a 2.5° aperture for a surface (its
/// error is mostly the surface's own, and a wider aperture sees more
/// facets). `None` with the light at or below the horizon (the
/// instrument's arm stays above the sample).
pub fn setup_for(scene: &Scene<'_>, brdf: &dyn Brdf, specimen: Specimen) -> Option<GonioSetup> {
    let theta = scene.incident.theta_deg;
    if !(0.0..89.5).contains(&theta) {
        return None;
    }
    let mut s = GonioSetup::new(theta.to_radians(), scene.incident.phi_deg.to_radians());
    match specimen {
        Specimen::Model => s.whole_circle = brdf.transmits(),
        Specimen::Surface(..) => s.aperture_deg = 2.5,
    }
    s.validate().ok()?;
    Some(s)
}

/// The specimen a scene asks for: the model, or with `plots.gonio_surface`
/// a surface with the primary BRDF's slopes (`None` when it names none:
/// the overlay then says so instead of measuring something else).
pub fn specimen(scene: &Scene<'_>, brdf: &dyn Brdf) -> Option<Specimen> {
    if !scene.state.plots.gonio_surface {
        return Some(Specimen::Model);
    }
    let (d, ax, ay) = brdf.ndf()?.slopes()?;
    let dist = SlopeDistribution::from_distribution(d)?;
    let r = super::microsurface::ALPHA_RANGE;
    let clamp = |a: f64| a.clamp(*r.start(), *r.end());
    Some(Specimen::Surface(dist, clamp(ax), clamp(ay)))
}

/// The readings for the scene's primary BRDF, or `None` with the overlay
/// off, no BRDF, a surface asked of a BRDF without slopes, or the light
/// below the horizon: computed now for a figure, else the latest finished
/// one while a job measures.
pub fn request(waker: &Waker, scene: &Scene<'_>) -> Option<Shown<Key, Arc<Measurement>>> {
    if !scene.state.plots.gonio {
        return None;
    }
    let b = scene.primary()?;
    let specimen = specimen(scene, b.brdf.as_ref())?;
    let setup = setup_for(scene, b.brdf.as_ref(), specimen)?;
    let key = (
        b.revision,
        scene.incident.theta_deg.to_bits(),
        scene.incident.phi_deg.to_bits(),
        match specimen {
            Specimen::Model => None,
            Specimen::Surface(d, ax, ay) => Some((d, ax.to_bits(), ay.to_bits())),
        },
    );
    Some(slots().for_frame(
        waker,
        b.id,
        key,
        scene.figure,
        Duration::from_millis(100),
        Job::new(b.brdf.clone(), setup, specimen),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use bv_core::ModelSpec;

    /// A surface specimen: generated, traced to the end, single bounces
    /// never above the total, nothing dropped at this roughness.
    #[test]
    fn the_surface_job_splits_single_from_total() {
        let brdf: Arc<dyn Brdf> = ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"distribution": "beckmann", "alpha": 0.5}),
        )
        .unwrap()
        .build()
        .unwrap()
        .into();
        let mut setup = GonioSetup::new(45f64.to_radians(), 0.0);
        setup.aperture_deg = 2.5;
        setup.batch = 1 << 14;
        let spec = Specimen::Surface(SlopeDistribution::Beckmann, 0.5, 0.5);
        let mut job = Job::new(brdf, setup, spec);
        let m = jobs::run_to_end(|| job.step());
        let single = m.single.as_ref().expect("single bounces");
        assert_eq!(m.photons, BATCHES * setup.batch as u64);
        assert_eq!(m.failed, 0);
        assert!(single.iter().zip(&m.readings).all(|(s, t)| s.f <= t.f));
        assert!(single.iter().zip(&m.readings).any(|(s, t)| s.f < t.f));
    }

    /// The job runs to its end with every photon counted, and its readings
    /// at the mirror stop of a glossy lobe lie within 5σ of the model's
    /// value there (the aperture mean differs from the point value by far
    /// less than the error at 1.5° for α = 0.3).
    #[test]
    fn the_job_measures_every_batch() {
        let brdf: Arc<dyn Brdf> = ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"alpha": 0.3, "kd": 0.1}),
        )
        .unwrap()
        .build()
        .unwrap()
        .into();
        let setup = GonioSetup::new(30f64.to_radians(), 0.0);
        let mut job = Job::new(brdf.clone(), setup, Specimen::Model);
        let m = jobs::run_to_end(|| job.step());
        assert_eq!(m.photons, BATCHES * setup.batch as u64);
        let r = m
            .readings
            .iter()
            .find(|r| (r.theta_s.to_degrees() - 30.0).abs() < 1e-9)
            .expect("a stop at the mirror direction");
        let exact = bv_core::mean_rgb(
            brdf.eval(setup.wi(), gonio::plane_direction(r.theta_s, setup.phi_i)),
        );
        assert!(
            (r.f - exact).abs() < 5.0 * r.sigma,
            "{} ± {} vs {exact}",
            r.f,
            r.sigma
        );
    }
}
