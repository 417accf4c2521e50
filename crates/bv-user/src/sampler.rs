//! A file's own importance sampler: the `isFunc` section.
//!
//! # The convention
//!
//! Disney's BRDF Explorer inserts a file's `isFunc` section into its IBL
//! shader next to the `shader` section, and its default (what a file without
//! one gets) declares the function
//!
//! ```glsl
//! vec3 sampleBRDF(float u, float v, vec3 normal, vec3 tangent, vec3 bitangent,
//!                 out vec3 wi, out float pdf)
//! ```
//!
//! drawing the light direction `wi` from the uniform point `(u, v)` and
//! reporting its solid-angle density `pdf`. (The Explorer's BRDF importance
//! sampling was never finished, so this signature is all the format fixes;
//! it has no view direction.) bv accepts that signature, and also one with
//! the fixed direction after `u, v`, for lobes that follow the viewer:
//!
//! ```glsl
//! vec3 sampleBRDF(float u, float v, vec3 V, vec3 N, vec3 X, vec3 Y,
//!                 out vec3 L, out float pdf)
//! ```
//!
//! The returned value is ignored.
//!
//! # The density
//!
//! A sampler's density is needed at any direction, not only at the ones it
//! draws (the sampling view integrates it over bins, multiple importance
//! sampling weighs other strategies' draws with it), and the out `pdf`
//! gives it only at the draw. So bv uses a file's sampler only when the
//! section also defines the density as a function,
//!
//! ```glsl
//! float pdfBRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)
//! ```
//!
//! (a bv extension, in the arguments of `BRDF`). Without it the density of
//! an arbitrary sampler cannot be recovered (that would mean inverting the
//! map from `(u, v)`), and the model keeps bv's default sampler: the
//! catalogue entry's summary says so. The sampler runs on the CPU (the
//! interpreter, within its step budget); GPU views keep the default.

use crate::error::{Result, UserError};
use crate::front;
use crate::source_map::SourceMap;
use bv_core::user::brdf_file::{BrdfFile, Language};
use naga::{Module, ScalarKind, TypeInner};

/// The wrapper bv generates around the file's `sampleBRDF`:
/// `vec4 bvxsample(u, v, V, N, X, Y)` returns `(L, pdf)`.
pub const SAMPLE_FN: &str = "bvxsample";

/// The file's density function, `pdfBRDF(L, V, N, X, Y)`.
pub const PDF_FN: &str = "pdfBRDF";

/// What a file's `isFunc` section gives the model. A section that does not
/// compile is an error; one without `sampleBRDF` (what the Explorer would
/// replace by its default) or without `pdfBRDF` is [`Sampler::Unused`].
#[derive(Debug, Clone)]
pub enum Sampler {
    /// No `isFunc` section: the default sampler.
    None,
    /// A sampler and its density: the module (parameters renamed as in the
    /// model's module), with [`SAMPLE_FN`] and [`PDF_FN`].
    Ready(Box<Module>),
    /// A sampler without a density function: not used (the reason says
    /// why).
    Unused(String),
}

fn is_float(module: &Module, ty: naga::Handle<naga::Type>) -> bool {
    matches!(
        module.types[ty].inner,
        TypeInner::Scalar(naga::Scalar {
            kind: ScalarKind::Float,
            ..
        })
    )
}

fn is_vec3(module: &Module, ty: naga::Handle<naga::Type>) -> bool {
    matches!(
        module.types[ty].inner,
        TypeInner::Vector {
            size: naga::VectorSize::Tri,
            scalar: naga::Scalar {
                kind: ScalarKind::Float,
                ..
            }
        }
    )
}

/// Parses generated GLSL, mapping an error into the `isFunc` section.
fn parse(src: &str, map: &SourceMap) -> Result<Module> {
    let mut fe = naga::front::glsl::Frontend::default();
    let options = naga::front::glsl::Options::from(naga::ShaderStage::Fragment);
    let mut module = fe.parse(&options, src).map_err(|errors| {
        let place = errors
            .errors
            .first()
            .and_then(|e| map.place_of_span(e.meta, src))
            .unwrap_or_else(|| map.place(0, 1));
        UserError::Compile {
            place,
            reason: front::glsl_reason(&errors),
        }
    })?;
    module.entry_points.clear();
    front::validate(&module, map, src)?;
    Ok(module)
}

/// Compiles the file's `isFunc` section (with its `shader` section before
/// it, as the Explorer inserts both, so that it can call the shader's
/// functions); `name` is the file name errors carry.
pub fn compile(file: &BrdfFile, name: &str) -> Result<Sampler> {
    let Some(section) = &file.is_func else {
        return Ok(Sampler::None);
    };
    let model_error = |reason: String| UserError::Model {
        file: name.to_string(),
        reason,
    };
    if file.language != Language::Glsl {
        return Err(model_error(
            "an `isFunc` section is GLSL and needs a GLSL `shader` section".into(),
        ));
    }
    let mut head = String::from("#version 450\n");
    for p in &file.params {
        head.push_str(&format!("{} {};\n", front::glsl_type(&p.kind), p.name));
    }
    let shader = front::lenient_copy(&file.source.text);
    head.push_str(&shader);
    head.push('\n');
    let user = front::lenient_copy(&section.text);
    let map = SourceMap {
        file: name.to_string(),
        prelude_lines: head.lines().count(),
        user_lines: user.lines().count().max(1),
        first_line: section.first_line,
    };
    let body = format!("{head}{user}\n");

    // First the user's code alone, to learn which signature it chose.
    let plain = parse(&format!("{body}void main() {{}}\n"), &map)?;
    let find = |m: &Module, want: &str| {
        m.functions
            .iter()
            .find(|(_, f)| f.name.as_deref() == Some(want))
            .map(|(_, f)| f.clone())
    };
    let Some(sample) = find(&plain, "sampleBRDF") else {
        // What the Explorer does with such a section: its default sampler.
        return Ok(Sampler::Unused(
            "its isFunc section defines no `sampleBRDF(float u, float v, vec3 N, vec3 X, \
             vec3 Y, out vec3 L, out float pdf)`"
                .into(),
        ));
    };
    let with_view = match sample.arguments.len() {
        7 => false,
        8 => true,
        n => {
            return Err(model_error(format!(
                "`sampleBRDF` takes {n} arguments; it takes (u, v, N, X, Y, out L, out pdf), \
                 or (u, v, V, N, X, Y, out L, out pdf)"
            )));
        }
    };
    let Some(pdf) = find(&plain, PDF_FN) else {
        return Ok(Sampler::Unused(
            "its isFunc section defines no `float pdfBRDF(vec3 L, vec3 V, vec3 N, vec3 X, \
             vec3 Y)`, without which the density of its draws is unknown"
                .into(),
        ));
    };
    let pdf_ok = pdf.arguments.len() == 5
        && pdf.arguments.iter().all(|a| is_vec3(&plain, a.ty))
        && pdf.result.as_ref().is_some_and(|r| is_float(&plain, r.ty));
    if !pdf_ok {
        return Err(model_error(
            "`pdfBRDF` must take five vec3 arguments (L, V, N, X, Y) and return a float".into(),
        ));
    }

    let view = if with_view { "V, " } else { "" };
    let wrapper = format!(
        "vec4 {SAMPLE_FN}(float u, float v, vec3 V, vec3 N, vec3 X, vec3 Y)\n\
         {{\n    vec3 L = vec3(0.0);\n    float pdf = 0.0;\n    \
         sampleBRDF(u, v, {view}N, X, Y, L, pdf);\n    return vec4(L, pdf);\n}}\n\
         void main() {{}}\n"
    );
    let mut module = parse(&format!("{body}{wrapper}"), &map)?;
    crate::safety::check(&module, name)?;
    for (_, g) in module.global_variables.iter_mut() {
        if let Some(k) = file
            .params
            .iter()
            .position(|p| g.name.as_deref() == Some(p.name.as_str()))
        {
            g.name = Some(crate::port::param_global(k));
        }
    }
    Ok(Sampler::Ready(Box::new(module)))
}
