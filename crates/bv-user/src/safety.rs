//! What a user's shader may not do, checked on the module before it reaches
//! either evaluator. The file size and the parameter count are bounded by
//! the container parser; time on the CPU by the interpreter's step budget,
//! on the GPU by the loop guards of [`crate::port`]; recursion is refused by
//! the front ends (see [`crate::port`]). What is left is memory: an array a shader declares
//! lives in every GPU invocation's private memory (and the interpreter's
//! stack), so its size is bounded here.

use crate::error::{Result, UserError};

/// Largest type (an array, a struct of arrays) a shader may declare, in
/// bytes: 64 KiB, far above what a BRDF needs (a few lookup tables).
pub const MAX_TYPE_BYTES: u32 = 64 << 10;

/// Refuses a module whose types are too large.
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
    Ok(())
}
