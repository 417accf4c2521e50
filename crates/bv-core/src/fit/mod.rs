//! Fitting a model's free parameters to a target BRDF (measured data, a user
//! file, another model): nonlinear least squares over a fixed set of
//! direction pairs ([`samples`]), with one of two cited error metrics
//! ([`metric`]), by Levenberg–Marquardt ([`lm`]) from several deterministic
//! starts.
//!
//! - **Unknowns.** Each free float parameter is one unknown; each free
//!   colour parameter is three (one per channel), and all three channels'
//!   residuals are fitted together, so shared parameters (roughness, an
//!   exponent) are fitted to all channels at once. An alias (`alpha` for
//!   `alpha_x = alpha_y`) is one unknown that sets every parameter it stands
//!   for.
//! - **Ranges.** The optimiser works on unbounded `t`; a parameter is
//!   `lo + (hi − lo) σ(t)` (σ the logistic function) over its declared range,
//!   or the same in `ln x` for parameters declared logarithmic (roughness,
//!   exponents; a declared minimum of 0 is replaced by `max · 1e-6` there). So
//!   every value the fit tries, and the one it returns, is inside the
//!   declared range, whatever the target.
//! - **Evaluation.** Model and target are evaluated through
//!   [`crate::batch::eval`]: the model's f32 kernel where it has one,
//!   its f64 `eval` otherwise, in parallel over chunks of pairs. Pairs where
//!   the target is not finite or negative (invalid cells of measured data)
//!   are left out.
//! - **Starts.** Start 0 is the given spec's values; the others are points
//!   of an additive recurrence (Roberts' R_d sequence) in the middle 80 % of
//!   each unknown's σ range. The best result wins.
//! - **Conditioning.** Parameters that only scale the same thing together
//!   cannot all be recovered: Cook-Torrance's `ks` with a dielectric
//!   Fresnel's `eta` (the data fixes `ks F0(η)`, the angular shape of F
//!   barely), `alpha2` while `weight2` is 0 (no effect at all). The fit
//!   still returns a point of lowest error (a zero column of the Jacobian
//!   leaves its unknown where it is); fix such parameters with `-p` for
//!   meaningful values. Roughness, exponents, `ks` and `kd` of one lobe
//!   over a diffuse base are well conditioned (`tests/fit.rs`).
//! - **Cancel and progress.** An `AtomicBool` is read before every Jacobian
//!   and every trial step; the progress callback hears every iteration.

pub mod lm;
pub mod metric;
pub mod samples;

pub use metric::Metric;
pub use samples::{SampleOptions, SampleSet};

use crate::batch::{self, Out};
use crate::params::decl::{ParamDecl, ParamKind};
use crate::params::value::{ModelSpec, ParamValue};
use crate::{Brdf, BvError, Result};
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::AtomicBool;

/// How a fit runs.
#[derive(Debug, Clone)]
pub struct FitOptions {
    /// The error to minimise.
    pub metric: Metric,
    /// The direction pairs compared.
    pub samples: SampleOptions,
    /// Starting points (at least 1).
    pub starts: usize,
    /// Levenberg–Marquardt iterations per start, at most.
    pub max_iterations: usize,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            metric: Metric::Ngan,
            samples: SampleOptions::default(),
            starts: 4,
            max_iterations: 60,
        }
    }
}

/// One report of a running fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitProgress {
    /// Which start (0-based) is running.
    pub start: usize,
    /// How many starts there are.
    pub starts: usize,
    /// Iterations done in this start.
    pub iteration: usize,
    /// The metric's error at this start's current point.
    pub error: f64,
}

/// The error over the pairs of one band of incident angles.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ThetaResidual {
    /// Lower edge of the band, degrees.
    pub theta_i_min: f64,
    /// Upper edge of the band, degrees.
    pub theta_i_max: f64,
    /// The metric's error over the band's pairs (0 when it has none).
    pub error: f64,
    /// Pairs in the band.
    pub samples: usize,
}

/// What a fit found.
#[derive(Debug, Clone)]
pub struct FitResult {
    /// The model with the fitted values (fixed parameters as given).
    pub spec: ModelSpec,
    /// The metric used.
    pub metric: Metric,
    /// Its error at the fitted values.
    pub error: f64,
    /// Its error at the first start (the given values), for comparison.
    pub initial_error: f64,
    /// The error per 10° band of θi, up to the sample set's grazing cut.
    pub residuals: Vec<ThetaResidual>,
    /// The unknowns, as `name` or `name[channel]`.
    pub unknowns: Vec<String>,
    /// Iterations over all starts.
    pub iterations: usize,
    /// Batch evaluations of the model over the sample set.
    pub evaluations: usize,
    /// Pairs compared.
    pub pairs: usize,
    /// Whether the fit was cancelled (the result is the best so far).
    pub cancelled: bool,
}

/// The parameters a fit frees when none are named: every float and colour
/// parameter that applies under the spec's current choices.
pub fn default_free(spec: &ModelSpec) -> Vec<&'static str> {
    spec.model()
        .params
        .iter()
        .filter(|d| matches!(d.kind, ParamKind::Float(_) | ParamKind::Color(_)))
        .filter(|d| d.applies_to(spec.params()))
        .map(|d| d.id)
        .collect()
}

/// One free parameter (or alias) and where its unknowns sit in `t`.
#[derive(Debug, Clone)]
struct Free {
    name: String,
    decl: &'static ParamDecl,
    channels: usize,
    map: Map,
}

/// A bounded map from `t ∈ ℝ` to a parameter value.
#[derive(Debug, Clone, Copy)]
struct Map {
    lo: f64,
    hi: f64,
    log: bool,
    min: f64,
    max: f64,
}

fn sigmoid(t: f64) -> f64 {
    1.0 / (1.0 + (-t).exp())
}

impl Map {
    fn new(min: f64, max: f64, log: bool) -> Self {
        let log = log && max > 0.0;
        let (lo, hi) = if log {
            (min.max(max * 1e-6).ln(), max.ln())
        } else {
            (min, max)
        };
        Map {
            lo,
            hi,
            log,
            min,
            max,
        }
    }

    fn value(&self, t: f64) -> f64 {
        let y = self.lo + (self.hi - self.lo) * sigmoid(t);
        let x = if self.log { y.exp() } else { y };
        // Rounding of exp/ln may step just outside the range.
        x.clamp(self.min, self.max)
    }

    fn param(&self, x: f64) -> f64 {
        let y = if self.log {
            x.max(self.lo.exp()).ln()
        } else {
            x
        };
        let s = ((y - self.lo) / (self.hi - self.lo)).clamp(1e-6, 1.0 - 1e-6);
        if s.is_finite() {
            (s / (1.0 - s)).ln()
        } else {
            0.0
        }
    }
}

fn free_params(spec: &ModelSpec, names: &[&str]) -> Result<Vec<Free>> {
    let info = spec.model();
    let mut out: Vec<Free> = Vec::new();
    for &name in names {
        let name = name.trim();
        let decl = match info.param(name) {
            Ok(d) => d,
            Err(e) => match info.alias(name) {
                Some(a) => info.param(a.sets.first().copied().unwrap_or(name))?,
                None => return Err(e),
            },
        };
        let (channels, map) = match decl.kind {
            ParamKind::Float(f) => (1, Map::new(f.min, f.max, f.log)),
            ParamKind::Color(c) => (3, Map::new(c.min, c.max, false)),
            _ => {
                return Err(BvError::BadValue {
                    param: name.to_string(),
                    reason: "only float and colour parameters can be fitted".into(),
                });
            }
        };
        if !(map.lo.is_finite() && map.hi.is_finite() && map.hi > map.lo) {
            return Err(BvError::BadValue {
                param: name.to_string(),
                reason: "its declared range is empty or unbounded: it cannot be fitted".into(),
            });
        }
        if !decl.applies_to(spec.params()) {
            return Err(BvError::BadValue {
                param: name.to_string(),
                reason: format!(
                    "does not apply with these values ({})",
                    decl.applies_text().unwrap_or_default()
                ),
            });
        }
        if out.iter().any(|f| f.name == name) {
            continue;
        }
        out.push(Free {
            name: name.to_string(),
            decl,
            channels,
            map,
        });
    }
    Ok(out)
}

/// The free values of `spec` as `t`.
fn to_t(spec: &ModelSpec, free: &[Free]) -> Result<Vec<f64>> {
    let mut t = Vec::new();
    for f in free {
        match spec.params().get(f.decl.id)? {
            ParamValue::Float(x) => t.push(f.map.param(*x)),
            ParamValue::Color(c) => t.extend(c.iter().map(|x| f.map.param(*x))),
            _ => {}
        }
    }
    Ok(t)
}

/// `base` with the free values set from `t`.
fn from_t(base: &ModelSpec, free: &[Free], t: &[f64]) -> Result<ModelSpec> {
    let mut spec = base.clone();
    let mut k = 0;
    for f in free {
        let v = if f.channels == 3 {
            ParamValue::Color([
                f.map.value(t[k]),
                f.map.value(t[k + 1]),
                f.map.value(t[k + 2]),
            ])
        } else {
            ParamValue::Float(f.map.value(t[k]))
        };
        k += f.channels;
        spec.set(&f.name, v)?;
    }
    Ok(spec)
}

/// Pairs per parallel chunk of a batch evaluation.
const CHUNK: usize = 2048;

/// `brdf` at every pair of `set`, channel-major.
pub fn evaluate(brdf: &dyn Brdf, set: &SampleSet) -> [Vec<f32>; 3] {
    let n = set.len();
    let mut rgb = [vec![0.0f32; n], vec![0.0f32; n], vec![0.0f32; n]];
    let [r, g, b] = &mut rgb;
    r.par_chunks_mut(CHUNK)
        .zip(g.par_chunks_mut(CHUNK))
        .zip(b.par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(i, ((r, g), b))| {
            let start = i * CHUNK;
            let dirs = set.pairs.dirs(start..start + r.len());
            let mut out = Out { rgb: [r, g, b] };
            batch::eval(brdf, &dirs, &mut out);
        });
    rgb
}

/// The prepared comparison: pairs, weights and the target's transformed values.
struct Problem {
    set: SampleSet,
    metric: Metric,
    sqrt_w: Vec<f64>,
    target_g: [Vec<f64>; 3],
    max_theta_deg: f64,
}

impl Problem {
    fn new(target: &dyn Brdf, samples: &SampleOptions, metric: Metric) -> Result<Self> {
        let all = SampleSet::new(samples);
        let t = evaluate(target, &all);
        let keep: Vec<bool> = (0..all.len())
            .map(|k| (0..3).all(|c| t[c][k].is_finite() && t[c][k] >= 0.0))
            .collect();
        let set = all.retain(&keep);
        if set.is_empty() {
            return Err(BvError::BadValue {
                param: "target".into(),
                reason: "the target has no finite, non-negative value at any sample pair".into(),
            });
        }
        let mut target_g: [Vec<f64>; 3] = Default::default();
        for (c, tg) in target_g.iter_mut().enumerate() {
            *tg = (0..all.len())
                .filter(|&k| keep[k])
                .map(|k| t[c][k] as f64)
                .zip(&set.cos_i)
                .map(|(f, ci)| metric.transform(f * ci))
                .collect();
        }
        let total: f64 = 3.0 * set.weight.iter().sum::<f64>();
        let sqrt_w = set.weight.iter().map(|w| (w / total).sqrt()).collect();
        Ok(Problem {
            set,
            metric,
            sqrt_w,
            target_g,
            max_theta_deg: samples.max_theta_deg,
        })
    }

    fn m(&self) -> usize {
        3 * self.set.len()
    }

    fn residuals(&self, brdf: &dyn Brdf, out: &mut [f64]) {
        let f = evaluate(brdf, &self.set);
        metric::residuals(
            self.metric,
            &f,
            &self.target_g,
            &self.set.cos_i,
            &self.sqrt_w,
            out,
        );
    }

    /// The error per 10° band of θi, from a residual vector (bands up to
    /// the grazing cut).
    fn bands(&self, r: &[f64]) -> Vec<ThetaResidual> {
        let n = self.set.len();
        let bands = ((self.max_theta_deg / 10.0).ceil() as usize).clamp(1, 9);
        let mut sum = vec![0.0; bands];
        let mut w = vec![0.0; bands];
        let mut count = vec![0usize; bands];
        for k in 0..n {
            let deg = self.set.cos_i[k].clamp(-1.0, 1.0).acos().to_degrees();
            let b = ((deg / 10.0) as usize).min(bands - 1);
            sum[b] += (0..3).map(|c| r[c * n + k].powi(2)).sum::<f64>();
            w[b] += 3.0 * self.sqrt_w[k].powi(2);
            count[b] += 1;
        }
        (0..bands)
            .map(|b| ThetaResidual {
                theta_i_min: 10.0 * b as f64,
                theta_i_max: 10.0 * (b + 1) as f64,
                error: if w[b] > 0.0 {
                    (sum[b] / w[b]).sqrt()
                } else {
                    0.0
                },
                samples: count[b],
            })
            .collect()
    }
}

/// The metric's error of `model` against `target` over the sample set of
/// `samples`, and per 10° band of θi.
pub fn error(
    model: &dyn Brdf,
    target: &dyn Brdf,
    samples: &SampleOptions,
    metric: Metric,
) -> Result<(f64, Vec<ThetaResidual>)> {
    let p = Problem::new(target, samples, metric)?;
    let mut r = vec![0.0; p.m()];
    p.residuals(model, &mut r);
    Ok((r.iter().map(|x| x * x).sum::<f64>().sqrt(), p.bands(&r)))
}

/// Fits the parameters `free` of `model` (ids or aliases; the others keep
/// `model`'s values) to `target`. See the module documentation for what
/// is fitted and how. Errors: an unknown or unfittable parameter, a target
/// without valid values, a model that fails to build.
pub fn fit(
    model: &ModelSpec,
    free: &[&str],
    target: &dyn Brdf,
    opts: &FitOptions,
    cancel: &AtomicBool,
    progress: &mut dyn FnMut(&FitProgress),
) -> Result<FitResult> {
    let free = free_params(model, free)?;
    let unknowns: Vec<String> = free
        .iter()
        .flat_map(|f| {
            (0..f.channels).map(move |c| {
                if f.channels == 1 {
                    f.name.clone()
                } else {
                    format!("{}[{c}]", f.name)
                }
            })
        })
        .collect();
    let problem = Problem::new(target, &opts.samples, opts.metric)?;
    let m = problem.m();
    let mut residual_fn = |t: &[f64], r: &mut [f64]| -> Result<()> {
        let spec = from_t(model, &free, t)?;
        let brdf = spec.build()?;
        problem.residuals(brdf.as_ref(), r);
        Ok(())
    };
    let t0 = to_t(model, &free)?;
    let p = t0.len();
    let lm_opts = lm::LmOptions {
        max_iterations: opts.max_iterations,
        rel_tol: 1e-9,
        step: 1e-4,
    };
    let starts = opts.starts.max(1);
    let mut best: Option<lm::LmOutcome> = None;
    let (mut iterations, mut evaluations) = (0, 0);
    let mut initial_error = f64::NAN;
    let mut cancelled = false;
    for s in 0..starts {
        let start = if s == 0 {
            t0.clone()
        } else {
            start_point(s, p)
        };
        let mut report = |iteration: usize, cost: f64| {
            progress(&FitProgress {
                start: s,
                starts,
                iteration,
                error: (2.0 * cost).sqrt(),
            });
        };
        let out = lm::minimise(&start, m, &mut residual_fn, &lm_opts, cancel, &mut report)?;
        if s == 0 {
            let mut r = vec![0.0; m];
            residual_fn(&t0, &mut r)?;
            initial_error = r.iter().map(|x| x * x).sum::<f64>().sqrt();
        }
        iterations += out.iterations;
        evaluations += out.evaluations;
        cancelled = out.cancelled;
        if best.as_ref().is_none_or(|b| out.cost < b.cost) {
            best = Some(out);
        }
        if cancelled {
            break;
        }
    }
    let t = best.map(|b| b.t).unwrap_or(t0);
    let spec = from_t(model, &free, &t)?;
    let mut r = vec![0.0; m];
    problem.residuals(spec.build()?.as_ref(), &mut r);
    Ok(FitResult {
        spec,
        metric: opts.metric,
        error: r.iter().map(|x| x * x).sum::<f64>().sqrt(),
        initial_error,
        residuals: problem.bands(&r),
        unknowns,
        iterations,
        evaluations,
        pairs: problem.set.len(),
        cancelled,
    })
}

/// Start `s ≥ 1` of `p` unknowns: Roberts' additive recurrence (the R_d
/// sequence, the generalised golden ratio φ_d with φ_d^(d+1) = φ_d + 1),
/// mapped to σ ∈ [0.1, 0.9] of each unknown's range.
fn start_point(s: usize, p: usize) -> Vec<f64> {
    let d = p.max(1) as f64;
    // φ_d by fixed-point iteration.
    let mut phi = 2.0f64;
    for _ in 0..30 {
        phi = (1.0 + phi).powf(1.0 / (d + 1.0));
    }
    (0..p)
        .map(|j| {
            let a = phi.powi(-(j as i32 + 1));
            let u = (0.5 + a * s as f64).fract();
            let sgm = 0.1 + 0.8 * u;
            (sgm / (1.0 - sgm)).ln()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maps_stay_in_range_and_invert() {
        for map in [
            Map::new(0.0, 10000.0, true),
            Map::new(0.001, 2.0, true),
            Map::new(0.0, 1.0, false),
        ] {
            for t in [-1e6, -50.0, -3.0, 0.0, 2.0, 50.0, 1e6, f64::MAX] {
                let x = map.value(t);
                assert!((map.min..=map.max).contains(&x), "{t} → {x}");
            }
            for x in [0.05, 0.3, 0.9] {
                let back = map.value(map.param(x));
                assert!((back - x).abs() < 1e-9 * x.max(1.0), "{x} → {back}");
            }
            // A value on a bound (or below a log map's floor, max · 1e-6)
            // starts just inside it: σ is kept within [1e-6, 1 − 1e-6].
            for x in [map.min, map.max] {
                let back = map.value(map.param(x));
                let span = if map.log { map.max } else { map.max - map.min };
                assert!((back - x).abs() <= 2e-5 * span, "{x} → {back}");
            }
        }
    }

    #[test]
    fn start_points_differ_and_are_bounded() {
        let a = start_point(1, 3);
        let b = start_point(2, 3);
        assert_ne!(a, b);
        for t in a.iter().chain(&b) {
            let s = sigmoid(*t);
            assert!((0.0999..=0.9001).contains(&s));
        }
    }
}
