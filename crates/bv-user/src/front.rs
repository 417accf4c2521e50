//! The front end: a file's GLSL `shader` section (Disney's BRDF Explorer) or
//! native `wgsl` section, wrapped in a generated prelude, to one validated
//! `naga::Module`.
//!
//! # The generated GLSL
//!
//! The Explorer compiles the section as `#version 410` with each parameter a
//! loose `uniform` of its name. bv declares each parameter instead as a
//! module-scope (private) global of its name, `float n;`, `bool b;`,
//! `vec3 c;`, so that the GPU wrapper and the CPU interpreter set them the
//! same way, before every evaluation; then the user's text; then an empty
//! `void main() {}` (naga's GLSL front end wants an entry point, which is
//! dropped again).
//!
//! # Leniencies
//!
//! Real files rely on GLSL 4.1's implicit conversions and on redefinitions
//! that a strict compiler could refuse. naga's GLSL front end (30) accepts
//! them as the Explorer's driver did, which the tests hold it to, file by
//! file (`tests/data/brdf/lenient_*.brdf`):
//! - int literals where a float is wanted (`1-f0`, `pow(x,5)`,
//!   `clamp(1-u,0,1)`) are converted as GLSL 4.1 §4.1.10 converts them;
//! - a user function with a built-in's signature (`reflect`, with the
//!   opposite sign of the built-in, `smoothstep`) overrides the built-in;
//! - a global with a non-constant initialiser (`float PI = 3.14159;`) is a
//!   private global initialised once;
//! - a local that shadows the function its initialiser calls
//!   (`float G = G(a,b)*G(c,d);`) is in scope only after its declarator;
//! - bool parameters in conditions and ternaries are `bool`s.
//!
//! The one rewrite bv makes, on a copy (the user's file is never edited): a
//! `#version` line in the section is blanked, since the prelude must start
//! with bv's own; line numbers are kept.

use crate::error::{Place, Result, UserError};
use crate::source_map::SourceMap;
use bv_core::user::brdf_file::{BrdfFile, FileParam, FileParamKind, Language};
use naga::{Handle, Module, ScalarKind, TypeInner, VectorSize};

/// A file's shader as one validated module.
#[derive(Debug, Clone)]
pub struct Translated {
    /// The module (entry points removed).
    pub module: Module,
    /// The model's function: `BRDF(L, V, N, X, Y)` (GLSL) or
    /// `brdf(wi, wo, n, x, y)` (WGSL).
    pub brdf: Handle<naga::Function>,
    /// The private global of each declared parameter, in declaration order.
    pub globals: Vec<Handle<naga::GlobalVariable>>,
}

/// The name of the model's function in each language.
pub fn brdf_name(language: Language) -> &'static str {
    match language {
        Language::Glsl => "BRDF",
        Language::Wgsl => "brdf",
    }
}

pub(crate) fn glsl_type(kind: &FileParamKind) -> &'static str {
    match kind {
        FileParamKind::Float { .. } => "float",
        FileParamKind::Bool { .. } => "bool",
        FileParamKind::Color { .. } => "vec3",
    }
}

fn wgsl_type(kind: &FileParamKind) -> &'static str {
    match kind {
        FileParamKind::Float { .. } => "f32",
        FileParamKind::Bool { .. } => "bool",
        FileParamKind::Color { .. } => "vec3<f32>",
    }
}

/// GLSL 4.50's keywords, reserved words and type names (§3.6), and the
/// names bv's generated code uses: none can name a parameter, which bv
/// declares as a global of that name.
const GLSL_RESERVED: &[&str] = &[
    "attribute",
    "const",
    "uniform",
    "varying",
    "buffer",
    "shared",
    "coherent",
    "volatile",
    "restrict",
    "readonly",
    "writeonly",
    "atomic_uint",
    "layout",
    "centroid",
    "flat",
    "smooth",
    "noperspective",
    "patch",
    "sample",
    "break",
    "continue",
    "do",
    "for",
    "while",
    "switch",
    "case",
    "default",
    "if",
    "else",
    "subroutine",
    "in",
    "out",
    "inout",
    "float",
    "double",
    "int",
    "void",
    "bool",
    "true",
    "false",
    "invariant",
    "precise",
    "discard",
    "return",
    "mat2",
    "mat3",
    "mat4",
    "dmat2",
    "dmat3",
    "dmat4",
    "mat2x2",
    "mat2x3",
    "mat2x4",
    "dmat2x2",
    "dmat2x3",
    "dmat2x4",
    "mat3x2",
    "mat3x3",
    "mat3x4",
    "dmat3x2",
    "dmat3x3",
    "dmat3x4",
    "mat4x2",
    "mat4x3",
    "mat4x4",
    "dmat4x2",
    "dmat4x3",
    "dmat4x4",
    "vec2",
    "vec3",
    "vec4",
    "ivec2",
    "ivec3",
    "ivec4",
    "bvec2",
    "bvec3",
    "bvec4",
    "dvec2",
    "dvec3",
    "dvec4",
    "uint",
    "uvec2",
    "uvec3",
    "uvec4",
    "lowp",
    "mediump",
    "highp",
    "precision",
    "sampler1D",
    "sampler2D",
    "sampler3D",
    "samplerCube",
    "struct",
    "common",
    "partition",
    "active",
    "asm",
    "class",
    "union",
    "enum",
    "typedef",
    "template",
    "this",
    "resource",
    "goto",
    "inline",
    "noinline",
    "public",
    "static",
    "extern",
    "external",
    "interface",
    "long",
    "short",
    "half",
    "fixed",
    "unsigned",
    "superp",
    "input",
    "output",
    "hvec2",
    "hvec3",
    "hvec4",
    "fvec2",
    "fvec3",
    "fvec4",
    "filter",
    "sizeof",
    "cast",
    "namespace",
    "using",
    "main",
    "BRDF",
];

/// WGSL's keywords, reserved words and predeclared types that a `var`
/// cannot be named (WGSL §15.1, §15.2), and bv's own names.
const WGSL_RESERVED: &[&str] = &[
    "alias",
    "break",
    "case",
    "const",
    "const_assert",
    "continue",
    "continuing",
    "default",
    "diagnostic",
    "discard",
    "else",
    "enable",
    "false",
    "fn",
    "for",
    "if",
    "let",
    "loop",
    "override",
    "requires",
    "return",
    "struct",
    "switch",
    "true",
    "var",
    "while",
    "f32",
    "f16",
    "i32",
    "u32",
    "bool",
    "vec2",
    "vec3",
    "vec4",
    "mat2x2",
    "mat3x3",
    "mat4x4",
    "array",
    "ptr",
    "atomic",
    "sampler",
    "texture_2d",
    "NULL",
    "Self",
    "abstract",
    "active",
    "as",
    "asm",
    "async",
    "await",
    "become",
    "cast",
    "catch",
    "class",
    "co_await",
    "co_return",
    "co_yield",
    "coherent",
    "const_cast",
    "do",
    "dynamic_cast",
    "enum",
    "export",
    "extends",
    "extern",
    "external",
    "final",
    "finally",
    "friend",
    "from",
    "fxgroup",
    "get",
    "goto",
    "impl",
    "implements",
    "import",
    "inline",
    "instanceof",
    "interface",
    "layout",
    "macro",
    "match",
    "mod",
    "module",
    "move",
    "mut",
    "mutable",
    "namespace",
    "new",
    "nil",
    "noexcept",
    "noinline",
    "null",
    "package",
    "private",
    "protected",
    "public",
    "pub",
    "readonly",
    "ref",
    "reinterpret_cast",
    "resource",
    "restrict",
    "self",
    "shared",
    "sizeof",
    "static",
    "static_assert",
    "static_cast",
    "super",
    "template",
    "this",
    "throw",
    "trait",
    "try",
    "type",
    "typedef",
    "typeid",
    "typename",
    "typeof",
    "union",
    "unless",
    "unsafe",
    "use",
    "using",
    "virtual",
    "void",
    "volatile",
    "where",
    "with",
    "writeonly",
    "yield",
    "brdf",
];

/// Refuses a parameter whose name the shader language reserves (`float`,
/// `in`, `return`, `mat3`, …): bv declares each parameter as a variable of
/// its name, and the compiler's complaint about that generated line would
/// name internal tokens. Names starting `gl_` (GLSL) or `__` (WGSL) are
/// reserved too.
pub fn check_param_names(file: &BrdfFile, name: &str) -> Result<()> {
    let (words, language) = match file.language {
        Language::Glsl => (GLSL_RESERVED, "GLSL"),
        Language::Wgsl => (WGSL_RESERVED, "WGSL"),
    };
    for p in &file.params {
        let reserved = words.contains(&p.name.as_str())
            || match file.language {
                Language::Glsl => p.name.starts_with("gl_") || p.name.contains("__"),
                Language::Wgsl => p.name.starts_with("__"),
            };
        if reserved {
            return Err(UserError::Compile {
                place: Place {
                    file: name.to_string(),
                    line: p.line,
                    column: 1,
                },
                reason: format!(
                    "parameter `{}` has a name that {language} reserves (a keyword, a type or bv's own); rename it",
                    p.name
                ),
            });
        }
    }
    Ok(())
}

/// The user's section with `#version` lines blanked (the one rewrite; see
/// the module docs).
pub(crate) fn lenient_copy(text: &str) -> String {
    text.lines()
        .map(|l| {
            if l.trim_start().starts_with("#version") {
                ""
            } else {
                l
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The generated source and how it maps onto the file.
fn generate(file: &BrdfFile, name: &str) -> (String, SourceMap) {
    let mut src = String::new();
    let mut lines = 0;
    match file.language {
        Language::Glsl => {
            src.push_str("#version 450\n");
            lines += 1;
            for p in &file.params {
                src.push_str(&format!("{} {};\n", glsl_type(&p.kind), p.name));
                lines += 1;
            }
        }
        Language::Wgsl => {
            for p in &file.params {
                src.push_str(&format!(
                    "var<private> {}: {};\n",
                    p.name,
                    wgsl_type(&p.kind)
                ));
                lines += 1;
            }
        }
    }
    let user = lenient_copy(&file.source.text);
    let user_lines = user.lines().count().max(1);
    src.push_str(&user);
    if file.language == Language::Glsl {
        src.push_str("\nvoid main() {}\n");
    } else {
        src.push('\n');
    }
    let map = SourceMap {
        file: name.to_string(),
        prelude_lines: lines,
        user_lines,
        first_line: file.source.first_line,
    };
    (src, map)
}

/// The first three of naga's GLSL errors, joined: the reason shown to the
/// user (the place is the first error's).
pub(crate) fn glsl_reason(errors: &naga::front::glsl::ParseErrors) -> String {
    errors
        .errors
        .iter()
        .take(3)
        .map(|e| e.kind.to_string())
        .collect::<Vec<_>>()
        .join("; ")
}

fn compile_error(map: &SourceMap, place: Option<Place>, reason: String) -> UserError {
    UserError::Compile {
        place: place.unwrap_or_else(|| map.place(0, 1)),
        reason,
    }
}

/// Parses and validates the file's shader; `name` is the file name errors
/// carry.
pub fn translate(file: &BrdfFile, name: &str) -> Result<Translated> {
    let (src, map) = generate(file, name);
    let mut module = match file.language {
        Language::Glsl => {
            let mut fe = naga::front::glsl::Frontend::default();
            let options = naga::front::glsl::Options::from(naga::ShaderStage::Fragment);
            fe.parse(&options, &src).map_err(|errors| {
                let first = errors.errors.first();
                let place = first.and_then(|e| map.place_of_span(e.meta, &src));
                compile_error(&map, place, glsl_reason(&errors))
            })?
        }
        Language::Wgsl => naga::front::wgsl::parse_str(&src).map_err(|e| {
            let place = e
                .labels()
                .next()
                .and_then(|(span, _)| map.place_of_span(span, &src));
            let label = e.labels().next().map(|(_, l)| l.to_string());
            let reason = match label {
                Some(l) if !l.is_empty() => format!("{} ({l})", e.message()),
                _ => e.message().to_string(),
            };
            compile_error(&map, place, reason)
        })?,
    };
    module.entry_points.clear();
    validate(&module, &map, &src)?;
    let want = brdf_name(file.language);
    let brdf = find_brdf(&module, want).ok_or_else(|| UserError::Model {
        file: name.to_string(),
        reason: format!(
            "the shader defines no `{}` function",
            match file.language {
                Language::Glsl => "vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)",
                Language::Wgsl =>
                    "fn brdf(wi: vec3f, wo: vec3f, n: vec3f, x: vec3f, y: vec3f) -> vec3f",
            }
        ),
    })?;
    let globals = file
        .params
        .iter()
        .map(|p| find_global(&module, p, name))
        .collect::<Result<Vec<_>>>()?;
    Ok(Translated {
        module,
        brdf,
        globals,
    })
}

/// Validates a module, mapping the first error's span to the user's file.
pub fn validate(module: &Module, map: &SourceMap, src: &str) -> Result<naga::valid::ModuleInfo> {
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(module)
    .map_err(|e| {
        let place = e
            .spans()
            .next()
            .and_then(|(span, _)| map.place_of_span(*span, src));
        let mut reason = e.as_inner().to_string();
        let mut source: Option<&dyn std::error::Error> = std::error::Error::source(e.as_inner());
        while let Some(s) = source {
            reason.push_str(": ");
            reason.push_str(&s.to_string());
            source = s.source();
        }
        compile_error(
            map,
            place,
            recursion_reason(&reason, module).unwrap_or(reason),
        )
    })
}

/// naga's message for a function that calls one declared after it
/// (`[0] of kind "naga::ir::Function" depends on [1] of kind …`), which a
/// GLSL file can only write with a prototype and mutual recursion, in the
/// user's terms.
fn recursion_reason(reason: &str, module: &Module) -> Option<String> {
    const KIND: &str = "of kind \"naga::ir::Function\" depends on [";
    let at = reason.find(KIND)?;
    let before = &reason[..at];
    let start = before.rfind('[')? + 1;
    let caller: usize = before[start..before[start..].find(']')? + start]
        .parse()
        .ok()?;
    let after = &reason[at + KIND.len()..];
    let callee: usize = after[..after.find(']')?].parse().ok()?;
    let name = |k: usize| {
        module
            .functions
            .iter()
            .nth(k)
            .and_then(|(_, f)| f.name.clone())
            .unwrap_or_else(|| format!("function {k}"))
    };
    Some(format!(
        "`{}` and `{}` call each other: recursion (a function calling itself, directly or \
         through others) is not supported, since a GPU cannot run it",
        name(caller),
        name(callee)
    ))
}

fn is_vec3f(module: &Module, ty: Handle<naga::Type>) -> bool {
    matches!(
        module.types[ty].inner,
        TypeInner::Vector {
            size: VectorSize::Tri,
            scalar: naga::Scalar {
                kind: ScalarKind::Float,
                width: 4
            }
        }
    )
}

/// The model's function: named `want`, five `vec3` arguments, a `vec3`
/// result. A function of that name with another signature is reported.
fn find_brdf(module: &Module, want: &str) -> Option<Handle<naga::Function>> {
    module
        .functions
        .iter()
        .find(|(_, f)| f.name.as_deref() == Some(want))
        .map(|(h, _)| h)
}

/// Checks the model function's signature.
pub fn check_signature(t: &Translated, file: &BrdfFile, name: &str) -> Result<()> {
    let f = &t.module.functions[t.brdf];
    let args_ok = f.arguments.len() == 5 && f.arguments.iter().all(|a| is_vec3f(&t.module, a.ty));
    let result_ok = f.result.as_ref().is_some_and(|r| is_vec3f(&t.module, r.ty));
    if args_ok && result_ok {
        return Ok(());
    }
    Err(UserError::Model {
        file: name.to_string(),
        reason: format!(
            "`{}` must take five vec3 arguments (L, V, N, X, Y) and return a vec3; it takes {} argument(s){}",
            brdf_name(file.language),
            f.arguments.len(),
            if result_ok {
                ""
            } else {
                " and does not return a vec3"
            }
        ),
    })
}

fn find_global(module: &Module, p: &FileParam, name: &str) -> Result<Handle<naga::GlobalVariable>> {
    module
        .global_variables
        .iter()
        .find(|(_, g)| g.name.as_deref() == Some(p.name.as_str()))
        .map(|(h, _)| h)
        .ok_or_else(|| UserError::Model {
            file: name.to_string(),
            reason: format!(
                "parameter `{}` (line {}) is shadowed by a global of the same name in the shader",
                p.name, p.line
            ),
        })
}
