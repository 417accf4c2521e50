//! The virtual gonioreflectometer's readings for the polar view's *gonio*
//! overlay (LECTURE.md N8): photons from the primary BRDF's own sampler
//! counted by a detector swept through the plane of incidence
//! (`bv_core::analysis::gonio`) — a job in batches with progress, cached per
//! BRDF and light, cancellable like every job.

use super::jobs::{self, Shown, Slots, Steps, Waker};
use crate::session::frame::Scene;
use bv_core::Brdf;
use bv_core::analysis::gonio::{self, Detector, GonioSetup, Reading, Tally};
use std::sync::Arc;
use std::time::Duration;

/// Batches of photons per measurement (2¹⁸ each: 4 M photons, a few per
/// cent on a diffuse reading at a 1.5° aperture).
pub const BATCHES: u64 = 16;

/// What a measurement depends on: the BRDF's revision, θi and φi (bits).
pub type Key = (u64, u64, u64);

/// A finished measurement.
#[derive(Debug, Clone)]
pub struct Measurement {
    /// The setup it used.
    pub setup: GonioSetup,
    /// One reading per detector stop, in order of angle.
    pub readings: Vec<Reading>,
    /// Photons sent.
    pub photons: u64,
    /// Photons the sampler did not place.
    pub failed: u64,
}

/// The measurements of the process (slot: BRDF id).
pub fn slots() -> Arc<Slots<Key, Arc<Measurement>>> {
    jobs::slots("gonioreflectometer")
}

/// The job: two batches per step (one per core), merged in batch order so
/// that the result does not depend on the threads.
struct Job {
    brdf: Arc<dyn Brdf>,
    setup: GonioSetup,
    detectors: Vec<Detector>,
    tally: Tally,
    next: u64,
}

impl Steps<Arc<Measurement>> for Job {
    fn step(&mut self) -> Option<Arc<Measurement>> {
        let (a, b) = (self.next, self.next + 1);
        let (brdf, setup, det) = (self.brdf.as_ref(), &self.setup, &self.detectors);
        let (ta, tb) = rayon::join(
            || gonio::measure_batch(brdf, setup, det, a),
            || gonio::measure_batch(brdf, setup, det, b),
        );
        self.tally.merge(&ta);
        self.tally.merge(&tb);
        self.next += 2;
        (self.next >= BATCHES).then(|| {
            Arc::new(Measurement {
                setup: self.setup,
                readings: self.tally.readings(&self.detectors),
                photons: self.tally.photons,
                failed: self.tally.failed,
            })
        })
    }

    fn progress(&self) -> Option<(usize, usize)> {
        Some((self.next as usize, BATCHES as usize))
    }
}

/// The setup for a scene: its light, the whole circle for a transmitting
/// BRDF. `None` with the light at or below the horizon (the instrument's
/// arm stays above the sample).
pub fn setup_for(scene: &Scene<'_>, brdf: &dyn Brdf) -> Option<GonioSetup> {
    let theta = scene.incident.theta_deg;
    if !(0.0..89.5).contains(&theta) {
        return None;
    }
    let mut s = GonioSetup::new(theta.to_radians(), scene.incident.phi_deg.to_radians());
    s.whole_circle = brdf.transmits();
    s.validate().ok()?;
    Some(s)
}

/// The readings for the scene's primary BRDF, or `None` with the overlay
/// off, no BRDF or the light below the horizon: computed now for a figure,
/// else the latest finished one while a job measures.
pub fn request(waker: &Waker, scene: &Scene<'_>) -> Option<Shown<Key, Arc<Measurement>>> {
    if !scene.state.plots.gonio {
        return None;
    }
    let b = scene.primary()?;
    let setup = setup_for(scene, b.brdf.as_ref())?;
    let key = (
        b.revision,
        scene.incident.theta_deg.to_bits(),
        scene.incident.phi_deg.to_bits(),
    );
    let detectors = setup.detectors();
    let n = detectors.len();
    Some(slots().for_frame(
        waker,
        b.id,
        key,
        scene.figure,
        Duration::from_millis(100),
        Job {
            brdf: b.brdf.clone(),
            setup,
            detectors,
            tally: Tally::new(n),
            next: 0,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use bv_core::ModelSpec;

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
        let detectors = setup.detectors();
        let mut job = Job {
            brdf: brdf.clone(),
            tally: Tally::new(detectors.len()),
            setup,
            detectors,
            next: 0,
        };
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
