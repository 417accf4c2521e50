//! Importance sampling made visible: draw directions with a model's own
//! sampler, bin them on the outgoing hemisphere, integrate the model's
//! density over each bin, and compare the two with Pearson's χ² test (the
//! test Mitsuba and PBRT-v4 run on every sampler). A sampler whose `pdf`
//! does not describe what it draws is rejected with a tiny p-value.
//!
//! # Bins
//! `n_theta × n_phi` bins of equal solid angle on the upper hemisphere: bin
//! `(t, p)` holds the directions with `z = cos θ ∈ [1 − (t+1)/n_theta,
//! 1 − t/n_theta]` and `φ ∈ [2π p/n_phi, 2π (p+1)/n_phi)` (φ = atan2(y, x)
//! taken into `[0, 2π)`). Row `t = 0` is the cap around the normal. On the
//! equal-area disc of [`super::reciprocity_map`] (`r = √(1 − z)`) bin
//! `(t, p)` is the annulus sector `r ∈ [√(t/n_theta), √((t+1)/n_theta)]`, so
//! a view can draw the histogram as a disc with equal-area cells.
//!
//! Draws that fail (`sample` returns `None`) or land on or below the horizon
//! form one more cell, "no direction", whose expected count is what the
//! density leaves unaccounted for over the hemisphere.

use super::chi2::{ChiSquare, chi_square};
use crate::quadrature::gauss_legendre;
use crate::{Brdf, BvError, Result, sampling};
use glam::DVec3;
use std::f64::consts::PI;

/// Most bins per axis accepted.
pub const MAX_BINS: usize = 1024;
/// Most draws accepted.
pub const MAX_SAMPLES: usize = 100_000_000;

/// What to draw and how to bin it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HistogramOptions {
    /// Bins in `cos θ`.
    pub n_theta: usize,
    /// Bins in φ.
    pub n_phi: usize,
    /// Number of draws.
    pub samples: usize,
    /// Seed of the uniform points fed to the sampler.
    pub seed: u64,
    /// How many of the drawn directions to return for a scatter plot.
    pub max_points: usize,
    /// Gauss–Legendre points per axis inside each bin.
    pub quadrature_order: usize,
    /// Cells whose expected count is below this are pooled (5 is the rule of
    /// thumb for Pearson's test).
    pub min_expected: f64,
    /// Bin the whole sphere instead of the upper hemisphere (for a
    /// transmitting model's sampler): the `n_theta` rows then split
    /// `z ∈ [−1, 1]` into bands of equal solid angle, row 0 the cap about +z
    /// and the last the cap about −z. Default: the upper hemisphere.
    pub whole_sphere: bool,
}

impl Default for HistogramOptions {
    fn default() -> Self {
        Self {
            n_theta: 10,
            n_phi: 20,
            samples: 100_000,
            seed: 1,
            max_points: 2_000,
            quadrature_order: 6,
            min_expected: 5.0,
            whole_sphere: false,
        }
    }
}

/// A histogram of sampled directions against the model's density.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleHistogram {
    /// Bins in `cos θ` (rows).
    pub n_theta: usize,
    /// Bins in φ (columns).
    pub n_phi: usize,
    /// Draws made.
    pub samples: usize,
    /// Drawn directions per bin, row-major `observed[t * n_phi + p]`.
    pub observed: Vec<u64>,
    /// `samples · ∫_bin pdf dω` per bin, same layout.
    pub expected: Vec<f64>,
    /// Draws that gave no direction above the horizon.
    pub failed: u64,
    /// `samples · (1 − ∫ pdf dω)`, clamped at 0: the failures the density
    /// predicts.
    pub expected_failed: f64,
    /// `∫ pdf dω` over the hemisphere by the bins' quadrature (1 for a
    /// sampler that never fails; a value above 1 means the density or the
    /// quadrature is off).
    pub pdf_mass: f64,
    /// The first `max_points` directions drawn (above the horizon).
    pub points: Vec<DVec3>,
    /// Pearson's test over the bins and the "no direction" cell.
    pub chi2: ChiSquare,
    /// Whether the bins cover the whole sphere ([`HistogramOptions::whole_sphere`]).
    pub whole_sphere: bool,
}

impl SampleHistogram {
    /// The bin `(t, p)` of a direction above the horizon (anywhere but on
    /// the horizon for a whole-sphere histogram).
    pub fn bin_of(&self, w: DVec3) -> Option<(usize, usize)> {
        bin_of(w, self.n_theta, self.n_phi, self.whole_sphere)
    }
}

/// Height in `z` of a row of bins: 1, or 2 on the whole sphere.
fn z_span(whole_sphere: bool) -> f64 {
    if whole_sphere { 2.0 } else { 1.0 }
}

fn bin_of(w: DVec3, n_theta: usize, n_phi: usize, whole_sphere: bool) -> Option<(usize, usize)> {
    if w.z.is_nan() || (w.z <= 0.0 && !whole_sphere) || w.z == 0.0 || !w.is_finite() {
        return None;
    }
    let t =
        (((1.0 - w.z.min(1.0)) / z_span(whole_sphere) * n_theta as f64) as usize).min(n_theta - 1);
    let phi = w.y.atan2(w.x).rem_euclid(2.0 * PI);
    let p = ((phi / (2.0 * PI) * n_phi as f64) as usize).min(n_phi - 1);
    Some((t, p))
}

/// Draws `opts.samples` directions from `brdf.sample(wo, ·)` and tests them
/// against `brdf.pdf(wo, ·)`. bv's samplers draw the second argument given
/// the first, so `wo` here is the fixed direction (in a renderer, the one
/// towards the viewer) and the histogram is over the sampled one.
pub fn sample_histogram(
    brdf: &dyn Brdf,
    wo: DVec3,
    opts: &HistogramOptions,
) -> Result<SampleHistogram> {
    let mut job = HistogramJob::new(wo, opts)?;
    loop {
        if let Some(h) = job.step(brdf, usize::MAX) {
            return Ok(h);
        }
    }
}

/// [`sample_histogram`] in steps of bounded work, for a caller that cannot
/// block for the whole computation (a browser page without threads runs a
/// few steps per frame). The draws come from one random stream kept between
/// steps and the bins are integrated one at a time, so the result does not
/// depend on how the work is cut.
#[derive(Debug, Clone)]
pub struct HistogramJob {
    wo: DVec3,
    opts: HistogramOptions,
    rng: sampling::BvRng,
    drawn: usize,
    observed: Vec<u64>,
    failed: u64,
    points: Vec<DVec3>,
    gl: Vec<(f64, f64)>,
    /// `∫_bin pdf dω` of the bins integrated so far, row-major.
    mass: Vec<f64>,
}

impl HistogramJob {
    /// A job for [`sample_histogram`]`(·, wo, opts)`; the options are checked
    /// here.
    pub fn new(wo: DVec3, opts: &HistogramOptions) -> Result<Self> {
        let HistogramOptions {
            n_theta,
            n_phi,
            samples,
            ..
        } = *opts;
        if n_theta == 0 || n_phi == 0 || n_theta > MAX_BINS || n_phi > MAX_BINS {
            return Err(BvError::Invalid(format!(
                "histogram bins must be 1..={MAX_BINS} per axis, got {n_theta} × {n_phi}"
            )));
        }
        if samples == 0 || samples > MAX_SAMPLES {
            return Err(BvError::Invalid(format!(
                "sample count must be 1..={MAX_SAMPLES}, got {samples}"
            )));
        }
        if opts.quadrature_order == 0 || opts.quadrature_order > 64 {
            return Err(BvError::Invalid(format!(
                "quadrature order must be 1..=64, got {}",
                opts.quadrature_order
            )));
        }
        Ok(Self {
            wo,
            opts: *opts,
            rng: sampling::rng(opts.seed),
            drawn: 0,
            observed: vec![0u64; n_theta * n_phi],
            failed: 0,
            points: Vec::with_capacity(opts.max_points.min(samples)),
            gl: gauss_legendre(opts.quadrature_order),
            mass: Vec::with_capacity(n_theta * n_phi),
        })
    }

    /// The share of the work done, in `[0, 1]`.
    pub fn progress(&self) -> f64 {
        let bins = self.observed.len();
        let q2 = self.gl.len() * self.gl.len();
        let total = self.opts.samples + bins * q2;
        (self.drawn + self.mass.len() * q2) as f64 / total as f64
    }

    /// Does about `work` evaluations (draws, or density evaluations inside
    /// the bins; at least one draw or one bin) and returns the histogram once
    /// everything is done.
    pub fn step(&mut self, brdf: &dyn Brdf, work: usize) -> Option<SampleHistogram> {
        let HistogramOptions {
            n_theta,
            n_phi,
            samples,
            ..
        } = self.opts;
        if self.drawn < samples {
            let n = work.clamp(1, samples - self.drawn);
            for _ in 0..n {
                let u = sampling::uniform2(&mut self.rng);
                match brdf
                    .sample(self.wo, u)
                    .and_then(|w| bin_of(w, n_theta, n_phi, self.opts.whole_sphere).map(|b| (w, b)))
                {
                    Some((w, (t, p))) => {
                        self.observed[t * n_phi + p] += 1;
                        if self.points.len() < self.opts.max_points {
                            self.points.push(w);
                        }
                    }
                    None => self.failed += 1,
                }
            }
            self.drawn += n;
            return None;
        }
        let bins = n_theta * n_phi;
        if self.mass.len() < bins {
            let q2 = self.gl.len() * self.gl.len();
            let n = (work / q2).clamp(1, bins - self.mass.len());
            for _ in 0..n {
                let k = self.mass.len();
                self.mass.push(self.bin_mass(brdf, k / n_phi, k % n_phi));
            }
            if self.mass.len() < bins {
                return None;
            }
        }
        Some(self.finish())
    }

    /// `∫_bin pdf dω = ∫∫ pdf dz dφ` (dω = dz dφ) over bin `(t, p)`,
    /// Gauss–Legendre in each.
    fn bin_mass(&self, brdf: &dyn Brdf, t: usize, p: usize) -> f64 {
        let dz = z_span(self.opts.whole_sphere) / self.opts.n_theta as f64;
        let dphi = 2.0 * PI / self.opts.n_phi as f64;
        let z_hi = 1.0 - t as f64 * dz;
        let phi_lo = p as f64 * dphi;
        let mut sum = 0.0;
        for &(xz, wz) in &self.gl {
            let z = z_hi - 0.5 * dz * (xz + 1.0);
            let s = (1.0 - z * z).max(0.0).sqrt();
            for &(xp, wp) in &self.gl {
                let phi = phi_lo + 0.5 * dphi * (xp + 1.0);
                let w = DVec3::new(s * phi.cos(), s * phi.sin(), z);
                let v = brdf.pdf(self.wo, w);
                if v.is_finite() && v > 0.0 {
                    sum += wz * wp * v;
                }
            }
        }
        sum * 0.25 * dz * dphi
    }

    fn finish(&mut self) -> SampleHistogram {
        let HistogramOptions {
            n_theta,
            n_phi,
            samples,
            ..
        } = self.opts;
        let mut expected = std::mem::take(&mut self.mass);
        let pdf_mass: f64 = expected.iter().sum();
        let n = samples as f64;
        for e in &mut expected {
            *e *= n;
        }
        let expected_failed = (n * (1.0 - pdf_mass)).max(0.0);
        let observed = std::mem::take(&mut self.observed);
        let mut obs_all = observed.clone();
        obs_all.push(self.failed);
        let mut exp_all = expected.clone();
        exp_all.push(expected_failed);
        let chi2 = chi_square(&obs_all, &exp_all, self.opts.min_expected);
        SampleHistogram {
            n_theta,
            n_phi,
            samples,
            observed,
            expected,
            failed: self.failed,
            expected_failed,
            pdf_mass,
            points: std::mem::take(&mut self.points),
            chi2,
            whole_sphere: self.opts.whole_sphere,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::from_spherical;
    use crate::{Claims, ModelSpec, Rgb};
    use glam::DVec2;
    use serde_json::json;
    use std::sync::Arc;

    fn model(id: &str, p: serde_json::Value) -> Arc<dyn Brdf> {
        Arc::from(ModelSpec::from_json(id, &p).unwrap().build().unwrap())
    }

    fn opts(seed: u64) -> HistogramOptions {
        HistogramOptions {
            n_theta: 8,
            n_phi: 16,
            samples: 20_000,
            seed,
            ..Default::default()
        }
    }

    /// Samples its inner model's lobe but claims the cosine density.
    #[derive(Debug)]
    struct WrongPdf(Arc<dyn Brdf>);
    impl Brdf for WrongPdf {
        fn id(&self) -> &'static str {
            "wrong-pdf"
        }
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            self.0.eval(wi, wo)
        }
        fn claims(&self) -> Claims {
            self.0.claims()
        }
        fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
            self.0.sample(wi, u)
        }
        fn pdf(&self, _wi: DVec3, wo: DVec3) -> f64 {
            sampling::cosine_hemisphere_pdf(wo)
        }
    }

    #[test]
    fn the_histogram_in_small_steps_is_the_one_shot_histogram() {
        // The draws share one stream and the bins are integrated one at a
        // time whatever the step, so any cut gives the same numbers.
        let b = model("lambert", json!({"albedo": 0.5}));
        let wo = from_spherical(0.4, 1.0);
        let once = sample_histogram(b.as_ref(), wo, &opts(9)).unwrap();
        for work in [1, 37, 1000] {
            let mut job = HistogramJob::new(wo, &opts(9)).unwrap();
            let mut steps = 0;
            let h = loop {
                steps += 1;
                if let Some(h) = job.step(b.as_ref(), work) {
                    break h;
                }
            };
            assert!(steps > 20_000 / work, "{work}: {steps} steps");
            assert_eq!(h, once, "work {work}");
        }
        assert!(
            HistogramJob::new(
                wo,
                &HistogramOptions {
                    samples: 0,
                    ..opts(1)
                }
            )
            .is_err()
        );
    }

    #[test]
    fn lambert_cosine_bins_follow_closed_form() {
        // Cosine pdf z/π over a bin: ∫ z dz dφ / π, hand integral
        // (z_hi² − z_lo²)/2 · Δφ / π.
        let b = model("lambert", json!({"albedo": 0.5}));
        let h = sample_histogram(b.as_ref(), DVec3::Z, &opts(3)).unwrap();
        for t in 0..8 {
            let (hi, lo) = (1.0 - t as f64 / 8.0, 1.0 - (t + 1) as f64 / 8.0);
            let want = 20_000.0 * 0.5 * (hi * hi - lo * lo) * (2.0 * PI / 16.0) / PI;
            for p in 0..16 {
                assert!((h.expected[t * 16 + p] - want).abs() < 1e-9 * want);
            }
        }
        assert!((h.pdf_mass - 1.0).abs() < 1e-12);
        assert_eq!(h.failed, 0);
        assert_eq!(h.observed.iter().sum::<u64>(), 20_000);
        assert_eq!(h.points.len(), 2_000);
        assert!(h.bin_of(h.points[0]).is_some());
        assert_eq!(h.chi2.dof, 128 - 1);
    }

    fn p_values(b: &dyn Brdf, wo: DVec3) -> Vec<f64> {
        (0..20)
            .map(|s| {
                sample_histogram(b, wo, &opts(100 + s))
                    .unwrap()
                    .chi2
                    .p_value
            })
            .collect()
    }

    #[test]
    fn correct_samplers_pass() {
        let wo = from_spherical(0.5, 0.3);
        for b in [
            model("lambert", json!({"albedo": 0.7})),
            model(
                "cook-torrance",
                json!({"kd": 0.2, "ks": 0.8, "distribution": "ggx", "alpha": 0.3,
                       "geometry": "smith", "fresnel": "schlick", "f0": 0.04}),
            ),
        ] {
            let p = p_values(b.as_ref(), wo);
            assert!(p.iter().all(|&x| x > 1e-4), "{}: {p:?}", b.id());
            assert!(!p.iter().all(|&x| x > 0.99), "{}: {p:?}", b.id());
            // A p-value is uniform under the hypothesis: about half below ½.
            let below = p.iter().filter(|&&x| x < 0.5).count();
            assert!((3..=17).contains(&below), "{}: {p:?}", b.id());
        }
    }

    #[test]
    fn a_wrong_pdf_is_rejected() {
        let ct = model(
            "cook-torrance",
            json!({"kd": 0.0, "ks": 1.0, "distribution": "ggx", "alpha": 0.3,
                   "geometry": "smith", "fresnel": "none"}),
        );
        let wrong = WrongPdf(ct);
        let h = sample_histogram(&wrong, from_spherical(0.5, 0.3), &opts(7)).unwrap();
        assert!(h.chi2.p_value < 1e-6, "{:?}", h.chi2);
        assert!(h.chi2.statistic > 1e3);
    }

    #[test]
    fn bad_options_are_refused() {
        let b = model("lambert", json!({}));
        let mut o = opts(1);
        o.n_phi = 0;
        assert!(sample_histogram(b.as_ref(), DVec3::Z, &o).is_err());
        let mut o = opts(1);
        o.samples = 0;
        assert!(sample_histogram(b.as_ref(), DVec3::Z, &o).is_err());
    }
}
