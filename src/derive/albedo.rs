//! Directional albedo curves: `ρhd(θi) = ∫ f cos θo dωo` (plus the weights
//! of delta lobes) against θi, with error bands, and the bihemispherical
//! albedo ρhh. For a transmitting model the curve covers light from both
//! sides (θi 0°..88° above, 92°..180° below) and carries its parts: ρR (what
//! leaves on the light's side) and ρT (what crosses the surface), whose sum
//! is ρhd; below 1 for a non-absorbing dielectric, the sum shows what a
//! single-scattering microfacet BSDF loses (the white furnace test; Walter
//! et al. 2007 §5.2, Heitz 2016 for the missing multiple scattering). They are `bv_core::analysis::albedo`'s, the estimators
//! `bv check` reports: deterministic Gauss–Kronrod quadrature for analytic
//! models (band: its error estimate), Monte Carlo for measured ones (band:
//! ±3 standard errors).
//!
//! Under the albedo view's *furnace* switch (`plots.albedo.furnace`) the
//! curve is that of the BRDF's microfacet lobe in a white furnace
//! ([`bv_core::Brdf::furnace`]: F = 1, kd = 0, ks = 1): `E(μ)`, whose
//! shortfall `1 − E(μ)` is the energy single scattering loses (Kulla & Conty
//! 2017), and which a model with `multiscatter = kulla-conty` brings to 1.
//! BRDFs that are not microfacet models have no such curve.
//!
//! A curve costs up to [`N_THETA`] × some 10⁵ evaluations plus ρhh, so it is
//! a job in steps of a few θi (with progress), cached by (build revision, φi):
//! the albedo view, figures, `bv render` and `bv slice` share it.

use super::jobs::{self, Shown, Slots, Steps, Waker};
use crate::session::frame::{Scene, SceneBrdf};
use bv_core::analysis::albedo::{
    AlbedoOptions, AlbedoParts, Estimate, rho_hd_auto, rho_hd_parts_auto, rho_hh_auto, theta_grid,
};
use bv_core::analysis::directions::stream_seed;
use bv_core::{Brdf, mean_rgb};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// θi samples above the surface: 0°, 2°, …, 88° (90° is left out: no light
/// arrives there). A transmitting model has as many below: 92°, …, 180°.
pub const N_THETA: usize = 45;
/// Evaluations per θi.
pub const SAMPLES: usize = 4096;
/// Evaluations for ρhh.
pub const RHH_SAMPLES: usize = 32768;
/// Seed of the estimates (fixed: the same BRDF always gives the same curve).
pub const SEED: u64 = 0x0062_7661_6c62;
/// Half-width of a Monte Carlo error band in standard errors (±3σ covers the
/// true value with about 99 % probability for these 16-replica estimates); a
/// quadrature's band is its error estimate.
pub const BAND_SIGMAS: f64 = 3.0;

/// The estimators' settings (quadrature for analytic models).
fn options(seed: u64) -> AlbedoOptions {
    AlbedoOptions {
        samples: SAMPLES,
        seed,
        ..AlbedoOptions::default()
    }
}

/// One finished curve.
#[derive(Debug, Clone, PartialEq)]
pub struct AlbedoData {
    /// θi in degrees, ascending (above 90° the light is below the surface,
    /// for a transmitting model).
    pub theta_deg: Vec<f64>,
    /// ρhd at each θi (ρR + ρT for a transmitting model).
    pub rho: Vec<Estimate>,
    /// For a transmitting model, ρR at each θi; empty otherwise.
    pub reflected: Vec<Estimate>,
    /// For a transmitting model, ρT at each θi; empty otherwise.
    pub transmitted: Vec<Estimate>,
    /// ρhh.
    pub rho_hh: Estimate,
}

/// The computation of an [`AlbedoData`] in steps: a few θi per step (as
/// many as there are worker threads, computed in parallel; one in a browser
/// page, where a step must fit in a slice of a frame), then ρhh.
#[derive(Debug)]
pub struct AlbedoJob {
    phi_i: f64,
    thetas: Vec<f64>,
    rho: Vec<AlbedoParts>,
    per_step: usize,
    /// Whether the BRDF transmits: decided at the first step (the job is
    /// made before it sees the BRDF); `None` until then.
    transmits: Option<bool>,
}

impl AlbedoJob {
    /// A job for the curve at azimuth `phi_i` (radians) computing
    /// `per_step` θi per step (at least one).
    pub fn new(phi_i: f64, per_step: usize) -> Self {
        Self {
            phi_i,
            thetas: theta_grid(N_THETA),
            rho: Vec::with_capacity(N_THETA),
            per_step: per_step.max(1),
            transmits: None,
        }
    }

    /// Steps finished (of [`Self::steps`]).
    pub fn done(&self) -> usize {
        self.rho.len()
    }

    /// Steps in all: one per θi and one for ρhh ([`STEPS`] for a
    /// reflection-only model, [`N_THETA`] more for a transmitting one).
    pub fn steps(&self) -> usize {
        self.thetas.len() + 1
    }

    /// Computes the next θi of `brdf` (or, once all are done, ρhh) and
    /// returns the curve once it is complete. `brdf` must be the same at
    /// every step.
    pub fn step(&mut self, brdf: &dyn Brdf) -> Option<AlbedoData> {
        let transmits = *self.transmits.get_or_insert_with(|| {
            let t = brdf.transmits();
            if t {
                // Light from below: the mirror images of the angles above
                // through the surface, ascending (92°, …, 180°).
                let below: Vec<f64> = self.thetas.iter().rev().map(|t| PI - t).collect();
                self.thetas.extend(below);
            }
            t
        });
        let k0 = self.rho.len();
        if k0 < self.thetas.len() {
            let k1 = (k0 + self.per_step).min(self.thetas.len());
            let phi_i = self.phi_i;
            let part: Vec<AlbedoParts> = self.thetas[k0..k1]
                .par_iter()
                .enumerate()
                .map(|(j, &t)| {
                    let o = options(stream_seed(SEED, (k0 + j) as u64));
                    if transmits {
                        // θi above 90° is a light inside the medium (issue 33).
                        rho_hd_parts_auto(brdf, bv_core::frame::from_spherical(t, phi_i), &o)
                    } else {
                        let total = rho_hd_auto(brdf, t, phi_i, &o);
                        AlbedoParts {
                            total,
                            reflected: total,
                            transmitted: total,
                        }
                    }
                })
                .collect();
            self.rho.extend(part);
            return None;
        }
        let rho_hh = rho_hh_auto(brdf, RHH_SAMPLES, &options(SEED));
        let parts = std::mem::take(&mut self.rho);
        let split = |f: fn(&AlbedoParts) -> Estimate| {
            if transmits {
                parts.iter().map(f).collect()
            } else {
                Vec::new()
            }
        };
        Some(AlbedoData {
            theta_deg: self.thetas.iter().map(|t| t.to_degrees()).collect(),
            rho: parts.iter().map(|p| p.total).collect(),
            reflected: split(|p| p.reflected),
            transmitted: split(|p| p.transmitted),
            rho_hh,
        })
    }
}

/// ρhd of `brdf` at one θi (radians; above 90° the light is below the
/// surface, for a transmitting model) and azimuth `phi_i`, with the curve's
/// estimators and the seed of stream `k` (`bv slice --curve albedo` on any
/// grid, the Python module's `Model.albedo`).
pub fn rho_hd_at(brdf: &dyn Brdf, theta_i: f64, phi_i: f64, k: u64) -> Estimate {
    let o = options(stream_seed(SEED, k));
    if brdf.transmits() {
        rho_hd_parts_auto(brdf, bv_core::frame::from_spherical(theta_i, phi_i), &o).total
    } else {
        rho_hd_auto(brdf, theta_i, phi_i, &o)
    }
}

impl AlbedoData {
    /// Computes the curve of `brdf` for light at azimuth `phi_i` (radians),
    /// counting finished steps in `progress` ([`AlbedoJob::steps`] in all); `None` when
    /// `cancel` was raised.
    pub fn compute(
        brdf: &dyn Brdf,
        phi_i: f64,
        progress: &AtomicUsize,
        cancel: &AtomicBool,
    ) -> Option<Self> {
        // Every θi in one parallel step: the one-shot computation.
        let mut job = AlbedoJob::new(phi_i, N_THETA);
        loop {
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            let d = job.step(brdf);
            progress.store(job.done() + usize::from(d.is_some()), Ordering::Relaxed);
            if d.is_some() {
                return d;
            }
        }
    }

    /// The plotted value (channel mean) and its band half-width at sample `k`.
    pub fn mean_and_band(&self, k: usize) -> (f64, f64) {
        let e = &self.rho[k];
        (mean_rgb(e.value), mean_rgb(e.allowance(BAND_SIGMAS)))
    }

    /// Whether the curve carries ρR and ρT (a transmitting model).
    pub fn has_parts(&self) -> bool {
        !self.transmitted.is_empty() && self.transmitted.len() == self.rho.len()
    }

    /// The (θi in degrees, channel mean) points of one series: the total
    /// ρhd, or a part ([`Self::reflected`], [`Self::transmitted`]).
    pub fn series(&self, of: &[Estimate]) -> Vec<[f64; 2]> {
        self.theta_deg
            .iter()
            .zip(of)
            .map(|(t, e)| [*t, mean_rgb(e.value)])
            .collect()
    }

    /// Whether some channel exceeds 1 by more than its error band somewhere.
    pub fn exceeds_one(&self) -> bool {
        self.excess_over_one().is_some()
    }

    /// By how much the curve exceeds 1 beyond its error band at most (over
    /// θi and channels), `None` where it never does: a model that is 1 up
    /// to a tabulated approximation's error (Kulla–Conty's compensation in
    /// the furnace) says by how little.
    pub fn excess_over_one(&self) -> Option<f64> {
        let m = self
            .rho
            .iter()
            .flat_map(|e| {
                let band = e.allowance(BAND_SIGMAS);
                (0..3).map(move |c| e.value[c] - band[c] - 1.0)
            })
            .fold(f64::NEG_INFINITY, f64::max);
        (m > 1e-9).then_some(m)
    }

    /// How the numbers were computed, for the legend: `quadrature` or
    /// `monte carlo`.
    pub fn method(&self) -> &'static str {
        self.rho.first().map_or("quadrature", |e| e.method.name())
    }
}

/// Steps of a computation of a reflection-only model (one per θi, one for
/// ρhh; see [`AlbedoJob::steps`]).
pub const STEPS: usize = N_THETA + 1;

/// What a curve is keyed by: the BRDF's build revision (a turned surface
/// has its own), φi's bits, whether it is the furnace curve and whether it
/// is the swapped integral ρdh.
pub type Key = (u64, u64, bool, bool);

/// Which of a BRDF's curves: its ρhd, or (`plots.albedo.swapped`, LECTURE
/// N12) its hemispherical-directional reflectance ρdh, the ρhd of the BRDF
/// with light and view exchanged (`bv_core::swapped::Swapped`), which has
/// its own slot beside the BRDF's (`slot_of`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Which {
    /// ρhd (or E under the furnace switch).
    Hd,
    /// ρdh = ∫ f(ωi, ωo) cos θi dωi against θo.
    Dh,
}

/// The slot bit of a swapped curve (a BRDF id is far below it).
const SWAPPED_SLOT: u64 = 1 << 62;

fn slot_of(b: &SceneBrdf, which: Which) -> u64 {
    match which {
        Which::Hd => b.id,
        Which::Dh => b.id | SWAPPED_SLOT,
    }
}

/// A job computing the curve of one BRDF in steps, with progress.
struct Run {
    job: AlbedoJob,
    brdf: Arc<dyn Brdf>,
}

impl Steps<Arc<AlbedoData>> for Run {
    fn step(&mut self) -> Option<Arc<AlbedoData>> {
        self.job.step(self.brdf.as_ref()).map(Arc::new)
    }

    fn progress(&self) -> Option<(usize, usize)> {
        Some((self.job.done(), self.job.steps()))
    }
}

/// The curves of the process (slot: BRDF id).
pub fn slots() -> Arc<Slots<Key, Arc<AlbedoData>>> {
    jobs::slots("albedo curve")
}

/// The key of `b`'s curve under the scene's light.
pub fn key_of(scene: &Scene<'_>, b: &SceneBrdf) -> Key {
    key_for(scene, b, Which::Hd)
}

fn key_for(scene: &Scene<'_>, b: &SceneBrdf, which: Which) -> Key {
    (
        b.revision,
        scene.incident.phi_deg.to_bits(),
        scene.state.plots.albedo.furnace,
        which == Which::Dh,
    )
}

/// Whether the scene's albedo view has a swapped curve of `b`: with the
/// switch on, outside the furnace, for a model that reflects only (for a
/// transmitting one reciprocity carries the η² factor of the whole-sphere
/// form, and the curve would not be the one the lecture means).
pub fn drawn_swapped(scene: &Scene<'_>, b: &SceneBrdf) -> bool {
    let a = scene.state.plots.albedo;
    a.swapped && !a.furnace && !b.brdf.transmits()
}

/// Whether the scene's albedo view has a curve of `b`: always, or under the
/// furnace switch when `b` is a microfacet model.
pub fn drawn(scene: &Scene<'_>, b: &SceneBrdf) -> bool {
    !scene.state.plots.albedo.furnace || b.brdf.furnace().is_some()
}

/// The BRDF whose curve is computed: `b`'s own, or its furnace lobe, or
/// `b` with its directions exchanged.
fn subject(scene: &Scene<'_>, b: &SceneBrdf, which: Which) -> Arc<dyn Brdf> {
    if which == Which::Dh {
        return Arc::new(bv_core::swapped::Swapped(b.brdf.clone()));
    }
    if scene.state.plots.albedo.furnace
        && let Some(f) = b.brdf.furnace()
    {
        return Arc::from(f);
    }
    b.brdf.clone()
}

fn run(scene: &Scene<'_>, b: &SceneBrdf, which: Which, per_step: usize) -> Run {
    Run {
        job: AlbedoJob::new(scene.incident.phi_deg.to_radians(), per_step),
        brdf: subject(scene, b, which),
    }
}

/// The curve of `b`, computed now (blocking) unless it is cached or a job
/// is computing it (then waited for): figures, `bv render`, scripts.
pub fn curve_now(scene: &Scene<'_>, b: &SceneBrdf) -> Arc<AlbedoData> {
    curve_now_of(scene, b, Which::Hd)
}

/// [`curve_now`] of either curve.
pub fn curve_now_of(scene: &Scene<'_>, b: &SceneBrdf, which: Which) -> Arc<AlbedoData> {
    // Every θi in one parallel step: the one-shot computation.
    let key = key_for(scene, b, which);
    let value = slots().now(slot_of(b, which), key, run(scene, b, which, N_THETA));
    value.value.clone()
}

/// The curve of `b` for this frame. A figure gets it computed now
/// ([`curve_now`]); the window gets the latest finished one (stale when
/// of older parameters) while a job computes the current one. Nothing
/// starts while the pointer drags a control (`scene.interacting`): a drag
/// computes the curve where it ends. (A job of an older key is not
/// cancelled: the slot is the BRDF's id, which another scene of the process
/// — a figure of a deck while the window shows its own — may share, and two
/// scenes cancelling each other's jobs would never finish one.)
pub fn curve(waker: &Waker, scene: &Scene<'_>, b: &SceneBrdf) -> Shown<Key, Arc<AlbedoData>> {
    curve_of(waker, scene, b, Which::Hd)
}

/// [`curve`] of either curve.
pub fn curve_of(
    waker: &Waker,
    scene: &Scene<'_>,
    b: &SceneBrdf,
    which: Which,
) -> Shown<Key, Arc<AlbedoData>> {
    let key = key_for(scene, b, which);
    let slot = slot_of(b, which);
    if scene.figure {
        return Shown {
            done: Some(slots().now(slot, key, run(scene, b, which, N_THETA))),
            stale: false,
            busy: false,
            progress: None,
        };
    }
    let slots = slots();
    let done = if scene.interacting {
        slots.latest(slot)
    } else {
        slots.request(
            slot,
            key,
            run(scene, b, which, rayon::current_num_threads()),
            waker,
        )
    };
    let busy = slots.busy(slot);
    if busy {
        waker.wake_after(std::time::Duration::from_millis(100));
    }
    Shown {
        stale: done.as_ref().is_some_and(|d| d.key != key),
        done,
        busy,
        progress: slots.progress(slot),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lambert_albedo_is_flat_at_its_albedo() {
        // ρhd of a Lambertian surface is its albedo at every θi (∫ a/π cos dω = a).
        let b = bv_core::ModelSpec::from_json("lambert", &serde_json::json!({"albedo": 0.6}))
            .unwrap()
            .build()
            .unwrap();
        let d = AlbedoData::compute(
            b.as_ref(),
            0.0,
            &AtomicUsize::new(0),
            &AtomicBool::new(false),
        )
        .unwrap();
        assert_eq!(d.rho.len(), N_THETA);
        for k in 0..N_THETA {
            let (v, band) = d.mean_and_band(k);
            assert!(
                (v - 0.6).abs() <= band.max(1e-9) + 1e-3,
                "{k}: {v} ± {band}"
            );
        }
        assert!((mean_rgb(d.rho_hh.value) - 0.6).abs() < 0.01);
        assert!(!d.exceeds_one());
    }

    /// A job of one θi per step (as in a browser page) gives the curve that
    /// bv-core's estimators give called one θi at a time here, and so the
    /// one-shot computation's.
    #[test]
    fn the_curve_in_steps_is_the_one_shot_curve() {
        let b = bv_core::ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"alpha": 0.3, "kd": 0.2}),
        )
        .unwrap()
        .build()
        .unwrap();
        let phi = 0.4;
        let mut job = AlbedoJob::new(phi, 1);
        let mut steps = 0;
        let stepped = loop {
            steps += 1;
            if let Some(d) = job.step(b.as_ref()) {
                break d;
            }
        };
        assert_eq!(steps, STEPS);
        let thetas = theta_grid(N_THETA);
        let by_hand: Vec<Estimate> = thetas
            .iter()
            .enumerate()
            .map(|(k, &t)| rho_hd_auto(b.as_ref(), t, phi, &options(stream_seed(SEED, k as u64))))
            .collect();
        assert_eq!(stepped.rho, by_hand);
        assert_eq!(
            stepped.rho_hh,
            rho_hh_auto(b.as_ref(), RHH_SAMPLES, &options(SEED))
        );
        let once = AlbedoData::compute(
            b.as_ref(),
            phi,
            &AtomicUsize::new(0),
            &AtomicBool::new(false),
        )
        .unwrap();
        assert_eq!(stepped, once);
    }

    #[test]
    fn cancelled_jobs_give_nothing() {
        let b = bv_core::ModelSpec::new("lambert").unwrap().build().unwrap();
        assert!(
            AlbedoData::compute(
                b.as_ref(),
                0.0,
                &AtomicUsize::new(0),
                &AtomicBool::new(true)
            )
            .is_none()
        );
    }
}
