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

use crate::compile::Compiled;
use crate::error::{Result, UserError};
use crate::port;
use bv_core::params::ParamKind;
use bv_core::{Brdf, Claims, ParamDecl, Params, Rgb};
use bv_interp::{InterpError, Limits, Program, Value};
use glam::DVec3;
use std::sync::Arc;

/// A file's module and declaration, ready to be given parameter values.
#[derive(Debug, Clone)]
pub struct FileProgram {
    module: naga::Module,
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
        Ok(Self {
            module: c.module.clone(),
            decls: c.decls,
            file: file.to_string(),
        })
    }

    /// An evaluator for parameter values `p` (validated by the spec against
    /// the file's declaration).
    pub fn build(&self, id: &'static str, p: &Params) -> Result<FileBrdf> {
        let mut program =
            Program::new(self.module.clone()).map_err(|e| interp_error(&self.file, &e))?;
        let bad = |e: bv_core::BvError| UserError::Model {
            file: self.file.clone(),
            reason: e.to_string(),
        };
        for (k, d) in self.decls.iter().enumerate() {
            let v = match d.kind {
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
            };
            program
                .set_global(&port::param_global(k), v)
                .map_err(|e| interp_error(&self.file, &e))?;
        }
        let mut b = FileBrdf {
            id,
            program: Arc::new(program),
            limits: Limits::default(),
            claims: Claims {
                reciprocal: false,
                energy_conserving: false,
                isotropic: false,
            },
        };
        b.try_eval(DVec3::Z, DVec3::Z)
            .map_err(|e| interp_error(&self.file, &e))?;
        b.claims = b.observed_claims();
        Ok(b)
    }
}

/// A file model with its parameter values, evaluated by the interpreter.
pub struct FileBrdf {
    id: &'static str,
    program: Arc<Program>,
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

    /// What a probe observed when the evaluator was built (see
    /// `observed_claims`); `bv check` measures what the file does.
    fn claims(&self) -> Claims {
        self.claims
    }
}
