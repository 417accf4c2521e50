//! The GPU port of a translated file: the module written back to WGSL with
//! naga's WGSL back end, wrapped as a bv shader module whose
//! `fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32>` reads the
//! parameters from bv's parameter buffer (offsets from bv-core's
//! `gpu_layout` of the same declaration) into the private globals, then
//! calls the model's function in bv's frame: N = +z, X = +x, Y = +y,
//! L = ωi, V = ωo (BRDF Explorer's convention, f without the cosine).
//!
//! # Bounded time on the GPU
//!
//! WGSL cannot express an unbounded loop that a driver will stop, and a GPU
//! that runs one hangs the device (the watchdog resets it). Every `loop` of
//! the emitted WGSL (GLSL's `for`, `while` and `do` all become one) gets a
//! guard at the top of its body: one per-invocation counter shared by all
//! loops, and a `break` once it passes [`MAX_GPU_ITERATIONS`]; the value an
//! aborted evaluation returns is meaningless but finite time is kept.
//! Recursion never reaches the GPU: GLSL's front end refuses a call to a
//! function not yet defined, and naga's validator refuses recursion in WGSL.

use crate::error::{Result, UserError};
use crate::front::Translated;
use bv_core::ParamDecl;
use bv_core::params::{GpuSlot, gpu_layout};
use std::fmt::Write as _;

/// Most loop iterations (all loops together) one GPU evaluation may run.
pub const MAX_GPU_ITERATIONS: u32 = 1 << 16;

/// Name of the model function in the emitted module.
pub const BRDF_FN: &str = "bvxbrdf";

/// Name of the private global that parameter `k` (0-based) is renamed to:
/// `bvxp` and base-26 letters, which naga's WGSL namer keeps unchanged (no
/// trailing digit, no `__`, no keyword).
pub fn param_global(k: usize) -> String {
    let mut letters = Vec::new();
    let mut k = k;
    loop {
        letters.push(b'a' + (k % 26) as u8);
        k /= 26;
        if k == 0 {
            break;
        }
        k -= 1;
    }
    letters.reverse();
    format!("bvxp{}", String::from_utf8_lossy(&letters))
}

/// Names the wrapper uses, which a user's function or global is renamed
/// away from.
const RESERVED: &[&str] = &["eval", "pf", "prgb", "pu", "params", "bvx_steps"];

/// The module with bv's names: the model's function [`BRDF_FN`], the
/// parameters' globals [`param_global`], user names that collide with the
/// wrapper's prefixed with `user_`. Names starting with `bvx` are refused.
pub fn renamed(t: &Translated, file: &str) -> Result<naga::Module> {
    let mut m = t.module.clone();
    let refuse = |name: &str| -> Result<()> {
        if name.starts_with("bvx") {
            return Err(UserError::Model {
                file: file.to_string(),
                reason: format!("`{name}`: names starting with `bvx` are reserved for bv"),
            });
        }
        Ok(())
    };
    for (h, f) in m.functions.iter_mut() {
        if let Some(name) = &f.name {
            refuse(name)?;
            if h == t.brdf {
                f.name = Some(BRDF_FN.to_string());
            } else if RESERVED.contains(&name.as_str()) {
                f.name = Some(format!("user_{name}"));
            }
        }
    }
    for (h, g) in m.global_variables.iter_mut() {
        if let Some(name) = &g.name {
            refuse(name)?;
            if let Some(k) = t.globals.iter().position(|x| *x == h) {
                g.name = Some(param_global(k));
            } else if RESERVED.contains(&name.as_str()) {
                g.name = Some(format!("user_{name}"));
            }
        }
    }
    Ok(m)
}

/// WGSL of a module (validated again: renaming cannot break it, but the
/// back end wants the analysis).
pub fn emit(module: &naga::Module, file: &str) -> Result<String> {
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(module)
    .map_err(|e| UserError::Model {
        file: file.to_string(),
        reason: format!("internal: the renamed module does not validate: {e}"),
    })?;
    naga::back::wgsl::write_string(module, &info, naga::back::wgsl::WriterFlags::empty())
        .map(|w| polyfill_names(&w))
        .map_err(|e| UserError::Model {
            file: file.to_string(),
            reason: format!("cannot write the shader as WGSL: {e}"),
        })
}

/// naga's WGSL writer adds functions for what WGSL lacks (GLSL's
/// `inverse()` becomes `_naga_inverse_3x3_f32`); bv's shader composer
/// refuses identifiers that start with `_`, so they become `bvxnaga_…`
/// (user names never start with `bvx`: see [`renamed`]).
fn polyfill_names(wgsl: &str) -> String {
    const FROM: &str = "_naga_";
    let mut out = String::with_capacity(wgsl.len());
    let mut rest = wgsl;
    while let Some(k) = rest.find(FROM) {
        let starts_word = rest[..k]
            .chars()
            .next_back()
            .is_none_or(|c| !(c.is_ascii_alphanumeric() || c == '_'));
        out.push_str(&rest[..k]);
        out.push_str(if starts_word { "bvxnaga_" } else { FROM });
        rest = &rest[k + FROM.len()..];
    }
    out.push_str(rest);
    out
}

/// Puts the iteration guard at the top of every `loop` body (module docs).
pub fn guard_loops(wgsl: &str) -> String {
    let mut out = String::with_capacity(wgsl.len() + 256);
    for line in wgsl.lines() {
        out.push_str(line);
        out.push('\n');
        if line.trim() == "loop {" {
            let indent: String = line.chars().take_while(|c| c.is_whitespace()).collect();
            let _ = writeln!(
                out,
                "{indent}    bvx_steps = bvx_steps + 1u;\n{indent}    if (bvx_steps > {MAX_GPU_ITERATIONS}u) {{ break; }}"
            );
        }
    }
    out
}

/// The bv shader module of a file model: import path `module`, the user's
/// code, and the `eval` wrapper reading `decls` at their packed offsets.
pub fn bv_module(module_path: &str, user_wgsl: &str, decls: &[ParamDecl]) -> Result<String> {
    let layout = gpu_layout(decls);
    let mut out = String::new();
    let w = |e: std::fmt::Error| UserError::Model {
        file: module_path.to_string(),
        reason: format!("internal: {e}"),
    };
    writeln!(
        out,
        "// GENERATED by bv from a user's .brdf file.\n#define_import_path {module_path}\n#import bv::params::pf\n#import bv::params::prgb\n\nvar<private> bvx_steps: u32;\n"
    )
    .map_err(w)?;
    out.push_str(&guard_loops(user_wgsl));
    out.push_str(
        "\nfn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {\n    if (wi.z <= 0.0 || wo.z <= 0.0) {\n        return vec3<f32>(0.0);\n    }\n",
    );
    for (k, p) in layout.params.iter().enumerate() {
        let g = param_global(k);
        let line = match p.slot {
            GpuSlot::Float => format!("    {g} = pf(o + {}u);", p.offset),
            GpuSlot::Bool => format!("    {g} = pf(o + {}u) != 0.0;", p.offset),
            GpuSlot::Color => format!("    {g} = prgb(o + {}u);", p.offset),
            _ => {
                return Err(UserError::Model {
                    file: module_path.to_string(),
                    reason: format!("internal: parameter `{}` has no file kind", p.id),
                });
            }
        };
        writeln!(out, "{line}").map_err(w)?;
    }
    writeln!(
        out,
        "    bvx_steps = 0u;\n    let f = {BRDF_FN}(wi, wo, vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0));\n    // NaN and infinities (a division by a zero cosine) read as 0, as on the CPU.\n    let bad = (f != f) | (abs(f) > vec3<f32>(3.0e38));\n    return select(f, vec3<f32>(0.0), bad);\n}}"
    )
    .map_err(w)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameter_globals_are_distinct_and_kept_by_the_namer() {
        let names: Vec<String> = (0..800).map(param_global).collect();
        let set: std::collections::BTreeSet<&String> = names.iter().collect();
        assert_eq!(set.len(), names.len());
        assert_eq!(names[0], "bvxpa");
        assert_eq!(names[25], "bvxpz");
        assert_eq!(names[26], "bvxpaa");
        assert!(
            names
                .iter()
                .all(|n| !n.ends_with(|c: char| c.is_ascii_digit()))
        );
    }

    #[test]
    fn polyfills_get_names_the_composer_takes() {
        let w = polyfill_names(
            "fn _naga_inverse_3x3_f32() {}\nlet a = _naga_inverse_3x3_f32(m) + my_naga_x;",
        );
        assert_eq!(
            w,
            "fn bvxnaga_inverse_3x3_f32() {}\nlet a = bvxnaga_inverse_3x3_f32(m) + my_naga_x;"
        );
    }

    #[test]
    fn every_loop_gets_a_guard() {
        let src = "fn f() {\n    loop {\n        loop {\n        }\n    }\n}\n";
        let g = guard_loops(src);
        assert_eq!(g.matches("bvx_steps = bvx_steps + 1u;").count(), 2);
        assert_eq!(g.matches("break;").count(), 2);
    }
}
