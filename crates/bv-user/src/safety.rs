//! What a user's shader may not do, checked on the module before it reaches
//! either evaluator. The file size and the parameter count are bounded by
//! the container parser; time on the CPU by the interpreter's step budget,
//! on the GPU by the loop guards of [`crate::port`]; recursion is refused by
//! the front ends (see [`crate::port`]). What is left is memory: an array a shader declares
//! lives in every GPU invocation's private memory (and the interpreter's
//! stack), so its size is bounded here: per type, and for all variables of
//! the module together (module-scope and every function's locals), since
//! many arrays each within the per-type limit are as large as one past it.
//! (The text's size, nesting and expression size are bounded before this,
//! by [`crate::bounds`].)

use crate::error::{Result, UserError};

/// Largest type (an array, a struct of arrays) a shader may declare, in
/// bytes: 64 KiB, far above what a BRDF needs (a few lookup tables).
pub const MAX_TYPE_BYTES: u32 = 64 << 10;

/// Most bytes of variables a shader may declare in all: every module-scope
/// variable and every local of every function (recursion is refused, so a
/// call chain holds each function's locals at most once).
pub const MAX_MODEL_BYTES: u64 = 256 << 10;

/// Refuses a module whose types are too large, or whose variables are too
/// large together.
pub fn check(module: &naga::Module, file: &str) -> Result<()> {
    let mut layouter = naga::proc::Layouter::default();
    layouter
        .update(module.to_ctx())
        .map_err(|e| UserError::Model {
            file: file.to_string(),
            reason: format!("a type is too large to lay out: {e}"),
        })?;
    for (h, ty) in module.types.iter() {
        let size = layouter[h].size;
        if size > MAX_TYPE_BYTES {
            return Err(UserError::Model {
                file: file.to_string(),
                reason: format!(
                    "{} of {size} bytes is declared; at most {MAX_TYPE_BYTES} bytes per type are allowed",
                    match ty.inner {
                        naga::TypeInner::Array { .. } => "an array",
                        naga::TypeInner::Struct { .. } => "a struct",
                        _ => "a type",
                    }
                ),
            });
        }
    }
    let size = |ty: naga::Handle<naga::Type>| u64::from(layouter[ty].size);
    let globals: u64 = module
        .global_variables
        .iter()
        .map(|(_, g)| size(g.ty))
        .sum();
    let locals: u64 = module
        .functions
        .iter()
        .flat_map(|(_, f)| f.local_variables.iter().map(|(_, v)| size(v.ty)))
        .sum();
    let total = globals + locals;
    if total > MAX_MODEL_BYTES {
        return Err(UserError::Model {
            file: file.to_string(),
            reason: format!(
                "the shader's variables take {total} bytes in all ({globals} at module scope, \
                 {locals} in functions); at most {MAX_MODEL_BYTES} bytes are allowed"
            ),
        });
    }
    Ok(())
}
