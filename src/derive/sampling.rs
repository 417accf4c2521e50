//! Sampling histograms: the directions ωo that a BRDF's own sampler draws
//! (`Brdf::sample`) for the current light, binned over equal-solid-angle
//! cells of the outgoing hemisphere, or of the whole sphere for a model that
//! transmits (`bv_core::analysis::sample_histogram`),
//! beside what the sampler's density (`Brdf::pdf`) integrates to over each
//! bin, with Pearson's χ² verdict (the test PBRT-v4 and Mitsuba run on every
//! sampler). Computed as a job in steps of a few thousand evaluations (a
//! browser page keeps drawing) and cached by the BRDF's revision and ωi.

use super::jobs::{self, Shown, Slots, Waker};
use crate::session::frame::{Scene, SceneBrdf};
use bv_core::analysis::sample_histogram::{HistogramJob, HistogramOptions, SampleHistogram};
use glam::DVec3;
use std::sync::Arc;
use std::time::Duration;

/// Bins in `cos θ`: 10 rings of equal solid angle.
pub const N_THETA: usize = 10;
/// Bins in φ.
pub const N_PHI: usize = 24;
/// Draws for the histogram: enough that every bin a sampler visits has tens
/// of draws, and quick (tens of milliseconds for an analytic model).
pub const SAMPLES: usize = 100_000;
/// Directions shown as points.
pub const POINTS: usize = 1_500;
/// The p-value below which the sampler is called inconsistent with its
/// density (a 1 % test, as in PBRT-v4's and Mitsuba's χ² sampling tests).
pub const SIGNIFICANCE: f64 = 0.01;

/// What a histogram was computed for: BRDF revision, ωi (θ, φ bits).
pub type Key = (u64, u64, u64);

/// The histogram options this view uses.
pub fn options() -> HistogramOptions {
    options_for(false)
}

/// The options for a reflection-only model (the upper hemisphere) or, with
/// `whole_sphere`, for a transmitting one (issue 33): twice the rows over
/// `z ∈ [−1, 1]`, so that each hemisphere keeps the [`N_THETA`] rings of
/// the same solid angle as a reflection-only model's, rows `N_THETA..` below
/// the surface (nearest the horizon first).
pub fn options_for(whole_sphere: bool) -> HistogramOptions {
    HistogramOptions {
        n_theta: if whole_sphere { 2 * N_THETA } else { N_THETA },
        n_phi: N_PHI,
        samples: SAMPLES,
        seed: 1,
        max_points: POINTS,
        whole_sphere,
        ..HistogramOptions::default()
    }
}

/// A histogram, or why there is none.
pub type Outcome = Arc<Result<SampleHistogram, String>>;

/// Draws or density evaluations per step of the background job: a few
/// milliseconds of an analytic model in a browser page, where a step must
/// fit in a slice of a frame.
const WORK_PER_STEP: usize = 8192;

/// One step of the histogram's computation (`job` holds it between steps).
fn step(job: &mut Option<HistogramJob>, brdf: &dyn bv_core::Brdf, wi: DVec3) -> Option<Outcome> {
    let j = match job {
        Some(j) => j,
        None => match HistogramJob::new(wi, &options_for(brdf.transmits())) {
            Ok(j) => job.insert(j),
            Err(e) => return Some(Arc::new(Err(e.to_string()))),
        },
    };
    j.step(brdf, WORK_PER_STEP).map(|h| Arc::new(Ok(h)))
}

/// The verdict line of a histogram.
pub fn verdict(h: &SampleHistogram) -> String {
    let c = &h.chi2;
    let sign = if c.p_value >= SIGNIFICANCE {
        "passed: the draws follow the pdf"
    } else {
        "FAILED: the draws do not follow the pdf"
    };
    let mut s = format!(
        "χ² = {} with {} degrees of freedom, p = {}: {sign} (1 % test)",
        bv_core::text::fmt_value(c.statistic),
        c.dof,
        bv_core::text::fmt_value(c.p_value),
    );
    if c.impossible > 0 {
        s.push_str(&format!("; {} draws where the pdf is 0", c.impossible));
    }
    s
}

/// The histograms of the process (slot: BRDF id).
pub fn slots() -> Arc<Slots<Key, Outcome>> {
    jobs::slots("sample histogram")
}

/// What a histogram of `b` under the scene's light is keyed by.
pub fn key_of(scene: &Scene<'_>, b: &SceneBrdf) -> Key {
    (
        b.revision,
        scene.incident.theta_deg.to_bits(),
        scene.incident.phi_deg.to_bits(),
    )
}

/// The histogram of `b` for this frame: computed now for a figure, else the
/// latest finished one while a job computes it.
pub fn histogram(waker: &Waker, scene: &Scene<'_>, b: &SceneBrdf) -> Shown<Key, Outcome> {
    let wi = scene.wi();
    let brdf = b.brdf.clone();
    let mut job = None;
    slots().for_frame(
        waker,
        b.id,
        key_of(scene, b),
        scene.figure,
        Duration::from_millis(50),
        move || step(&mut job, brdf.as_ref(), wi),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The view's histogram, computed in its background job's steps.
    fn compute(brdf: &dyn bv_core::Brdf, wi: DVec3) -> Outcome {
        let mut job = None;
        jobs::run_to_end(|| step(&mut job, brdf, wi))
    }

    /// The steps of the background job add up to the one-shot histogram of
    /// bv-core (same draws, same bins, same χ²), though the job takes
    /// `SAMPLES / WORK_PER_STEP` and more steps.
    #[test]
    fn the_stepped_histogram_is_the_one_shot_one() {
        let ct = bv_core::ModelSpec::new("cook-torrance")
            .unwrap()
            .build()
            .unwrap();
        let wi = DVec3::new(0.5, -0.2, 0.8).normalize();
        let mut job = None;
        let mut steps = 0;
        let stepped = jobs::run_to_end(|| {
            steps += 1;
            step(&mut job, ct.as_ref(), wi)
        });
        assert!(steps > SAMPLES / WORK_PER_STEP, "{steps} steps");
        let once =
            bv_core::analysis::sample_histogram::sample_histogram(ct.as_ref(), wi, &options())
                .unwrap();
        assert_eq!(stepped.as_ref().as_ref().unwrap(), &once);
    }

    /// Lambert's cosine sampler matches its density; a sampler that draws
    /// uniformly while claiming the cosine density is rejected.
    #[test]
    fn the_verdict_tells_a_good_sampler_from_a_bad_one() {
        let lambert = bv_core::ModelSpec::new("lambert").unwrap().build().unwrap();
        let wi = DVec3::new(0.3, 0.1, 0.95).normalize();
        let good = compute(lambert.as_ref(), wi);
        let good = good.as_ref().as_ref().unwrap();
        assert!(good.chi2.p_value >= SIGNIFICANCE, "{}", verdict(good));
        assert!(verdict(good).contains("passed"));

        #[derive(Debug)]
        struct Liar;
        impl bv_core::Brdf for Liar {
            fn id(&self) -> &'static str {
                "uniform sampler claiming the cosine density"
            }
            fn eval(&self, _wi: DVec3, _wo: DVec3) -> bv_core::Rgb {
                bv_core::Rgb::splat(std::f64::consts::FRAC_1_PI)
            }
            fn claims(&self) -> bv_core::Claims {
                bv_core::Claims {
                    reciprocal: true,
                    energy_conserving: true,
                    isotropic: true,
                }
            }
            fn sample(&self, _wi: DVec3, u: glam::DVec2) -> Option<DVec3> {
                // Uniform over the hemisphere: z uniform in (0, 1].
                let z = 1.0 - u.x;
                let s = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * PI * u.y;
                Some(DVec3::new(s * phi.cos(), s * phi.sin(), z))
            }
        }
        let bad = compute(&Liar, wi);
        let bad = bad.as_ref().as_ref().unwrap();
        assert!(bad.chi2.p_value < 1e-6, "{}", verdict(bad));
        assert!(verdict(bad).contains("FAILED"));
    }
}
