//! The CPU evaluator of a file model: bv-interp, an f64 interpreter over the
//! same naga module the GPU port is written from, so that both evaluate one
//! translation of the user's code. Parameters are set as the module-scope
//! globals the wrapper of the GPU port sets ([`crate::port::param_global`]);
//! the model function is called in bv's frame (N = +z, X = +x, Y = +y,
//! L = ωi, V = ωo).
//!
//! Every call is bounded by the interpreter's [`Limits`] (steps, call depth,
//! memory): an endless loop ends with an error, never a hang. An evaluator is
//! probed once when it is built (at normal incidence), so that a shader that
//! never finishes, or one the interpreter cannot run, is a clear build error;
//! a later evaluation that fails reads as 0.
//!
//! Values are handled as the built-in models and the GPU port handle them:
//! 0 below the horizon (the Explorer draws only the upper hemisphere), and
//! a NaN or infinite channel (a division by a vanishing cosine) reads as 0.
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
use std::sync::Arc;

/// A file's module and declaration, ready to be given parameter values.
#[derive(Debug, Clone)]
pub struct FileProgram {
    module: naga::Module,
    /// The module of the file's sampler, if it has a usable one.
    sampler: Option<naga::Module>,
    decls: &'static [ParamDecl],
    file: String,
}

fn interp_error(file: &str, e: &InterpError) -> UserError {
    UserError::Model {
        file: file.to_string(),
        reason: format!("on the CPU: {e}"),
    }
}

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
        };
        b.try_eval(DVec3::Z, DVec3::Z)
            .map_err(|e| interp_error(&self.file, &e))?;
        if b.sampler.is_some() {
            // The sampler and its density run once too, so that one the
            // interpreter cannot finish is a build error, not silence.
            b.try_sample(DVec3::Z, DVec2::splat(0.5))
                .map_err(|e| interp_error(&self.file, &e))?;
            b.try_pdf(DVec3::Z, DVec3::Z)
                .map_err(|e| interp_error(&self.file, &e))?;
        }
        b.claims = b.observed_claims();
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
    /// f(wi, wo) as the shader returns it (no horizon test, no clamping).
    pub fn try_eval(&self, wi: DVec3, wo: DVec3) -> Result<Rgb, InterpError> {
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
    fn observed_claims(&self) -> Claims {
        let same = |a: Rgb, b: Rgb| {
            (a - b).abs().max_element()
                <= 1e-7 * a.abs().max_element().max(b.abs().max_element()) + 1e-300
        };
        let mut reciprocal = true;
        let mut isotropic = true;
        for (wi, wo) in probe_pairs() {
            let f = self.eval(wi, wo);
            reciprocal &= same(f, self.eval(wo, wi));
            let turn = glam::DQuat::from_rotation_z(0.7);
            isotropic &= same(f, self.eval(turn * wi, turn * wo));
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
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        match self.try_eval(wi, wo) {
            Ok(f) => Rgb::from_array(f.to_array().map(|x| if x.is_finite() { x } else { 0.0 })),
            Err(_) => Rgb::ZERO,
        }
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
}
