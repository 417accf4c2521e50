//! The CPU evaluator of a file model: bv-interp, an f64 interpreter over the
//! same naga module the GPU port is written from, so that both evaluate one
//! translation of the user's code. Parameters are set as the module-scope
//! globals the wrapper of the GPU port sets ([`crate::port::param_global`]);
//! the model function is called in bv's frame (N = +z, X = +x, Y = +y,
//! L = ωi, V = ωo).
//!
//! Every call is bounded by the interpreter's [`Limits`] (steps, call depth,
//! memory): an endless loop ends with an error, never a hang. An evaluator is
//! probed when it is built, at the normal and at 32 pairs spread over the
//! hemisphere, so that a shader that does not finish (or that the
//! interpreter cannot run) somewhere is a clear build error, and the probe
//! times it ([`Brdf::eval_cost`]) so that an analysis can refuse a model too
//! slow for it before it starts.
//!
//! A later evaluation that fails anyway reads as 0 in [`Brdf::eval`] and is
//! counted, with the first reason, in [`Brdf::health`], which every analysis
//! reads after computing: an error, never a silent 0. [`Brdf::try_eval`]
//! returns the error itself. Under [`Brdf::limit_time`], evaluations past
//! the deadline (or after a failure) fail at once, so that an analysis of a
//! model that is too slow ends in bounded time.
//!
//! Values are handled as the built-in models and the GPU port handle them:
//! 0 below the horizon (the Explorer draws only the upper hemisphere), and
//! a NaN or infinite channel (a division by a vanishing cosine) reads as 0
//! and is counted in [`Brdf::health`], so that `bv check` reports it.
//! Negative values are kept, so that `bv check` reports them.
//!
//! A file with a usable `isFunc` section ([`crate::sampler`]) samples with
//! it: `sample` calls the file's `sampleBRDF` and `pdf` its `pdfBRDF`, in
//! the same frame, the fixed direction as V and the drawn one as L. A draw
//! that fails, is not finite or is not a direction reads as no direction;
//! a density that fails or is not a finite non-negative number reads as 0.

use crate::compile::Compiled;
use crate::error::{Result, UserError};
use crate::port;
use crate::sampler::{PDF_FN, SAMPLE_FN, Sampler};
use bv_core::params::ParamKind;
use bv_core::{Brdf, Claims, ParamDecl, Params, Rgb};
use bv_interp::{InterpError, Limits, Program, Value};
use glam::{DVec2, DVec3};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Duration;
use web_time::Instant;

/// A file's module and declaration, ready to be given parameter values.
#[derive(Debug, Clone)]
pub struct FileProgram {
    module: naga::Module,
    /// The module of the file's sampler, if it has a usable one.
    sampler: Option<naga::Module>,
    decls: &'static [ParamDecl],
    file: String,
}

/// An interpreter's message in the user's terms: bv's internal names for
/// the model's function and parameters become the user's.
fn user_terms(message: &str) -> String {
    message
        .replace(&format!("`{}`", port::BRDF_FN), "the BRDF function")
        .replace(&format!("`{SAMPLE_FN}`"), "the isFunc section")
}

fn interp_error(file: &str, e: &InterpError) -> UserError {
    model_error(file, user_terms(&e.to_string()))
}

fn model_error(file: &str, reason: String) -> UserError {
    UserError::Model {
        file: file.to_string(),
        reason: format!("on the CPU: {reason}"),
    }
}

/// An evaluation error in the user's terms, with the directions it
/// happened at.
fn at_pair(e: &InterpError, wi: DVec3, wo: DVec3) -> String {
    format!(
        "{} (at L = {}, V = {})",
        user_terms(&e.to_string()),
        fmt_dir(wi),
        fmt_dir(wo)
    )
}

fn fmt_dir(w: DVec3) -> String {
    format!("({:.4}, {:.4}, {:.4})", w.x, w.y, w.z)
}

/// [`FileBrdf::deadline_ns`] when no deadline is set.
const NO_DEADLINE: u64 = u64::MAX;

impl FileProgram {
    /// The program of a compiled file; fails if the interpreter cannot run
    /// the module (a feature it lacks).
    pub fn new(c: &Compiled, file: &str) -> Result<Self> {
        Program::new(c.module.clone()).map_err(|e| interp_error(file, &e))?;
        let sampler = match &c.sampler {
            Sampler::Ready(m) => {
                Program::new((**m).clone()).map_err(|e| interp_error(file, &e))?;
                Some((**m).clone())
            }
            Sampler::None | Sampler::Unused(_) => None,
        };
        Ok(Self {
            module: c.module.clone(),
            sampler,
            decls: c.decls,
            file: file.to_string(),
        })
    }

    /// An evaluator for parameter values `p` (validated by the spec against
    /// the file's declaration).
    pub fn build(&self, id: &'static str, p: &Params) -> Result<FileBrdf> {
        let values = self.values(p)?;
        let program = self.program(&self.module, &values, false)?;
        let sampler = match &self.sampler {
            Some(m) => Some(Arc::new(self.program(m, &values, true)?)),
            None => None,
        };
        let born = Instant::now();
        let mut b = FileBrdf {
            id,
            program: Arc::new(program),
            sampler,
            limits: Limits::default(),
            claims: Claims {
                reciprocal: false,
                energy_conserving: false,
                isotropic: false,
            },
            cost: Duration::ZERO,
            born,
            deadline_ns: AtomicU64::new(NO_DEADLINE),
            failed: AtomicU64::new(0),
            non_finite: AtomicU64::new(0),
            first_failure: OnceLock::new(),
        };
        // The probe: the normal, then pairs over the hemisphere (a shader
        // that loops only away from the normal fails here, not in an
        // analysis hours later).
        let pairs: Vec<(DVec3, DVec3)> = std::iter::once((DVec3::Z, DVec3::Z))
            .chain(probe_pairs())
            .collect();
        let start = Instant::now();
        let values = pairs
            .iter()
            .map(|&(wi, wo)| {
                b.call_brdf(wi, wo)
                    .map_err(|e| model_error(&self.file, at_pair(&e, wi, wo)))
            })
            .collect::<Result<Vec<Rgb>>>()?;
        b.cost = start.elapsed() / pairs.len() as u32;
        if b.sampler.is_some() {
            // The sampler and its density run too, so that one the
            // interpreter cannot finish is a build error, not silence.
            for &(wi, wo) in &pairs {
                b.try_sample(wi, DVec2::new(wo.x.abs(), wo.y.abs()))
                    .map_err(|e| model_error(&self.file, at_pair(&e, wi, wo)))?;
                b.try_pdf(wi, wo)
                    .map_err(|e| model_error(&self.file, at_pair(&e, wi, wo)))?;
            }
        }
        // The claims compare with the probe's values (the normal excepted):
        // a build, which every slider drag makes, evaluates each pair once.
        b.claims = b.observed_claims(&values[1..]);
        Ok(b)
    }

    /// The value of each declared parameter, validated by the spec.
    fn values(&self, p: &Params) -> Result<Vec<Value>> {
        let bad = |e: bv_core::BvError| UserError::Model {
            file: self.file.clone(),
            reason: e.to_string(),
        };
        self.decls
            .iter()
            .map(|d| {
                Ok(match d.kind {
                    ParamKind::Float(_) => Value::f(p.float(d.id).map_err(bad)?),
                    ParamKind::Bool { .. } => Value::Bool(p.bool(d.id).map_err(bad)?),
                    ParamKind::Color(_) => {
                        let c = p.color(d.id).map_err(bad)?;
                        Value::vec3(c.x, c.y, c.z)
                    }
                    _ => {
                        return Err(UserError::Model {
                            file: self.file.clone(),
                            reason: format!("internal: parameter `{}` has no file kind", d.id),
                        });
                    }
                })
            })
            .collect()
    }

    /// A program of `module` with the parameters' globals set. In the
    /// sampler's module (`lenient`) a parameter that the code never reads
    /// may be gone; it is skipped.
    fn program(&self, module: &naga::Module, values: &[Value], lenient: bool) -> Result<Program> {
        let mut program = Program::new(module.clone()).map_err(|e| interp_error(&self.file, &e))?;
        for (k, v) in values.iter().enumerate() {
            match program.set_global(&port::param_global(k), v.clone()) {
                Ok(()) => {}
                Err(InterpError::UnknownGlobal(_)) if lenient => {}
                Err(e) => return Err(interp_error(&self.file, &e)),
            }
        }
        Ok(program)
    }
}

/// A file model with its parameter values, evaluated by the interpreter.
pub struct FileBrdf {
    id: &'static str,
    program: Arc<Program>,
    /// The file's sampler (`isFunc`), if it has a usable one.
    sampler: Option<Arc<Program>>,
    limits: Limits,
    claims: Claims,
    /// Mean time of one evaluation in the build's probe.
    cost: Duration,
    /// When the evaluator was built: the origin of `deadline_ns`.
    born: Instant,
    /// The deadline of [`Brdf::limit_time`], in nanoseconds after `born`
    /// ([`NO_DEADLINE`]: none). An atomic, read on every evaluation by
    /// every thread of an analysis without a lock.
    deadline_ns: AtomicU64,
    /// Evaluations that failed, and that returned a non-finite channel.
    failed: AtomicU64,
    non_finite: AtomicU64,
    /// Why the first failed evaluation failed.
    first_failure: OnceLock<String>,
}

impl std::fmt::Debug for FileBrdf {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FileBrdf").field("id", &self.id).finish()
    }
}

fn v3(w: DVec3) -> Value {
    Value::vec3(w.x, w.y, w.z)
}

impl FileBrdf {
    /// The value at a pair above the horizon (0 below it), or why there is
    /// none: the interpreter's error at these directions, or the time limit.
    fn checked(&self, wi: DVec3, wo: DVec3) -> Result<Rgb, String> {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Ok(Rgb::ZERO);
        }
        let deadline = self.deadline_ns.load(Ordering::Relaxed);
        if deadline != NO_DEADLINE {
            // Under a time limit, a failure ends the analysis: the rest fail
            // at once instead of each running to the step budget.
            if self.failed.load(Ordering::Acquire) > 0 {
                return Err("an earlier evaluation failed".into());
            }
            if u64::try_from(self.born.elapsed().as_nanos()).unwrap_or(u64::MAX) > deadline {
                return Err(format!(
                    "the model is too slow to analyse: it ran past the analysis's time \
                     budget ({} per evaluation when it was built)",
                    bv_core::text::fmt_duration(self.cost)
                ));
            }
        }
        self.call_brdf(wi, wo).map_err(|e| at_pair(&e, wi, wo))
    }

    /// f(wi, wo) as the shader returns it (no horizon test, no clamping).
    pub fn call_brdf(&self, wi: DVec3, wo: DVec3) -> Result<Rgb, InterpError> {
        let args = [v3(wi), v3(wo), v3(DVec3::Z), v3(DVec3::X), v3(DVec3::Y)];
        let out = self.program.call(port::BRDF_FN, &args, &self.limits)?;
        let [r, g, b] = out
            .as_vec3()
            .ok_or_else(|| InterpError::Invalid("the BRDF function returned no vec3".into()))?;
        Ok(Rgb::new(r, g, b))
    }

    /// The file's draw for fixed direction `v` and uniform point `u`:
    /// `(L, the pdf the file reported)`, as the sampler returns them
    /// (`None` without a sampler).
    pub fn try_sample(&self, v: DVec3, u: DVec2) -> Result<Option<(DVec3, f64)>, InterpError> {
        let Some(s) = &self.sampler else {
            return Ok(None);
        };
        let args = [
            Value::f(u.x),
            Value::f(u.y),
            v3(v),
            v3(DVec3::Z),
            v3(DVec3::X),
            v3(DVec3::Y),
        ];
        let out = s.call(SAMPLE_FN, &args, &self.limits)?;
        match out.as_vec() {
            Some(&[x, y, z, pdf]) => Ok(Some((DVec3::new(x, y, z), pdf))),
            _ => Err(InterpError::Invalid(
                "the sampler returned no (L, pdf)".into(),
            )),
        }
    }

    /// The file's `pdfBRDF(L, V, N, X, Y)` (`None` without a sampler).
    pub fn try_pdf(&self, v: DVec3, l: DVec3) -> Result<Option<f64>, InterpError> {
        let Some(s) = &self.sampler else {
            return Ok(None);
        };
        let args = [v3(l), v3(v), v3(DVec3::Z), v3(DVec3::X), v3(DVec3::Y)];
        let out = s.call(PDF_FN, &args, &self.limits)?;
        out.as_f()
            .map(Some)
            .ok_or_else(|| InterpError::Invalid("pdfBRDF returned no float".into()))
    }

    /// Whether the model samples with the file's own sampler.
    pub fn has_own_sampler(&self) -> bool {
        self.sampler.is_some()
    }
}

/// Pairs on which a build probes reciprocity and isotropy: a fixed spread
/// over the upper hemisphere (golden-angle azimuths).
fn probe_pairs() -> impl Iterator<Item = (DVec3, DVec3)> {
    (0..32).map(|k| {
        let k = f64::from(k);
        let d = |t: f64, p: f64| DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
        let ti = 0.05 + 1.4 * ((k * 0.618_034) % 1.0);
        let to = 0.05 + 1.4 * ((k * 0.414_214 + 0.3) % 1.0);
        (d(ti, k * 2.399_963), d(to, k * 2.399_963 + 1.0 + 0.1 * k))
    })
}

impl FileBrdf {
    /// What the file's values show on [`probe_pairs`] (relative 1e-7, below
    /// `bv check`'s 1e-6 threshold, above f64 rounding): a
    /// user's file states no claims, and reporting none would make, e.g.,
    /// `bv tabulate` warn that a Lambertian file is anisotropic. `bv check`
    /// measures the properties on far more pairs and says when it finds
    /// otherwise. Energy conservation is never claimed.
    /// `values` are f at [`probe_pairs`], in order.
    fn observed_claims(&self, values: &[Rgb]) -> Claims {
        let same = |a: Rgb, b: Rgb| {
            (a - b).abs().max_element()
                <= 1e-7 * a.abs().max_element().max(b.abs().max_element()) + 1e-300
        };
        let mut reciprocal = true;
        let mut isotropic = true;
        let value = |a: DVec3, b: DVec3| self.checked(a, b).unwrap_or(Rgb::ZERO);
        let turn = glam::DQuat::from_rotation_z(0.7);
        for ((wi, wo), &f) in probe_pairs().zip(values) {
            reciprocal &= same(f, value(wo, wi));
            isotropic &= same(f, value(turn * wi, turn * wo));
        }
        Claims {
            reciprocal,
            energy_conserving: false,
            isotropic,
        }
    }
}

impl Brdf for FileBrdf {
    fn id(&self) -> &'static str {
        self.id
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        match self.checked(wi, wo) {
            Ok(f) => {
                if !f.is_finite() {
                    self.non_finite.fetch_add(1, Ordering::Relaxed);
                }
                Rgb::from_array(f.to_array().map(|x| if x.is_finite() { x } else { 0.0 }))
            }
            Err(why) => {
                // The reason first: a thread that sees the count sees it.
                let _ = self.first_failure.set(why);
                self.failed.fetch_add(1, Ordering::Release);
                Rgb::ZERO
            }
        }
    }

    /// The shader's value, non-finite channels as they are; an error names
    /// the directions.
    fn try_eval(&self, wi: DVec3, wo: DVec3) -> bv_core::Result<Rgb> {
        self.checked(wi, wo).map_err(bv_core::BvError::Invalid)
    }

    fn health(&self) -> bv_core::EvalHealth {
        bv_core::EvalHealth {
            failed: self.failed.load(Ordering::Relaxed),
            non_finite: self.non_finite.load(Ordering::Relaxed),
            first_failure: self.first_failure.get().cloned(),
        }
    }

    fn eval_cost(&self) -> Option<Duration> {
        Some(self.cost)
    }

    fn limit_time(&self, budget: Option<Duration>) {
        let ns = budget.map_or(NO_DEADLINE, |b| {
            let at = self.born.elapsed().saturating_add(b);
            u64::try_from(at.as_nanos()).unwrap_or(NO_DEADLINE - 1)
        });
        self.deadline_ns.store(ns, Ordering::Relaxed);
    }

    /// A user's shader is not a closed form a quadrature may trust to its
    /// stated accuracy: its literals are f32 (π to 7 digits), and it may
    /// branch or cut off anywhere (`if (NdotL < 0) return vec3(0)`, a `pow`
    /// of a negative base that reads as 0). Adaptive quadrature spends its
    /// whole panel budget chasing such steps, millions of interpreted
    /// evaluations per albedo value (minutes for `bv check`); Monte Carlo
    /// gives an honest standard error at a fixed cost. `--albedo quadrature`
    /// still asks for the quadrature.
    fn is_analytic(&self) -> bool {
        false
    }

    fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        if self.sampler.is_none() {
            return Some(bv_core::sampling::cosine_hemisphere(u));
        }
        let (l, _) = self.try_sample(wi, u).ok()??;
        let len = l.length();
        // A direction, give or take the rounding of the shader's own
        // normalisation (f32 in the Explorer).
        if !l.is_finite() || (len - 1.0).abs() > 1e-3 {
            return None;
        }
        Some(l / len)
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if self.sampler.is_none() {
            return bv_core::sampling::cosine_hemisphere_pdf(wo);
        }
        if wo.z <= 0.0 {
            return 0.0;
        }
        match self.try_pdf(wi, wo) {
            Ok(Some(p)) if p.is_finite() && p >= 0.0 => p,
            _ => 0.0,
        }
    }

    /// What a probe observed when the evaluator was built (see
    /// `observed_claims`); `bv check` measures what the file does.
    fn claims(&self) -> Claims {
        self.claims
    }

    /// A `.brdf` file declares no claims: [`FileBrdf::claims`] is what a
    /// probe observed, so reports show "no claim" beside the measurements.
    fn claims_declared(&self) -> bool {
        false
    }
}
