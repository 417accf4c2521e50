//! A `.brdf` file's text to everything bv needs of it: the declaration of
//! its parameters, the module the CPU interprets and the WGSL the GPU runs.

use crate::error::{Place, Result, UserError};
use crate::front::{self, Translated};
use crate::{port, safety};
use bv_core::ParamDecl;
use bv_core::user::brdf_file::{self, BrdfFile};

/// A compiled file.
#[derive(Debug, Clone)]
pub struct Compiled {
    /// The parsed container.
    pub file: BrdfFile,
    /// The parameters as bv declares them (leaked: they live as long as the
    /// catalogue entry).
    pub decls: &'static [ParamDecl],
    /// The module with bv's names ([`port::renamed`]): the model function
    /// is [`port::BRDF_FN`], parameter `k` the global [`port::param_global`].
    pub module: naga::Module,
    /// The module as WGSL (before the loop guards and the wrapper).
    pub wgsl: String,
    /// The file's own sampler (its `isFunc` section), if it has a usable one.
    pub sampler: crate::sampler::Sampler,
}

/// The container parser's error, placed when its message starts with
/// `line N, column M: `.
fn container_error(message: &str, name: &str) -> UserError {
    let message = message.strip_prefix("invalid input: ").unwrap_or(message);
    let placed = message.strip_prefix("line ").and_then(|rest| {
        let (line, rest) = rest.split_once(", column ")?;
        let (column, reason) = rest.split_once(": ")?;
        Some((line.parse().ok()?, column.parse().ok()?, reason))
    });
    match placed {
        Some((line, column, reason)) => UserError::Compile {
            place: Place {
                file: name.to_string(),
                line,
                column,
            },
            reason: reason.to_string(),
        },
        None => UserError::Container {
            file: name.to_string(),
            reason: message.to_string(),
        },
    }
}

/// Compiles the text of a `.brdf` file; `name` is the file name errors
/// carry.
pub fn compile(text: &str, name: &str) -> Result<Compiled> {
    let file = brdf_file::parse(text).map_err(|e| container_error(&e.to_string(), name))?;
    front::check_param_names(&file, name)?;
    // Bounded before any compiler sees the text (see `bounds`).
    let mut sections = vec![&file.source];
    sections.extend(file.is_func.as_ref());
    crate::bounds::check(file.language, &sections, name)?;
    // naga is a large compiler fed hostile text: should it panic on a file
    // that passed the bounds, that file is refused, and bv goes on.
    let compiled = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let t: Translated = front::translate(&file, name)?;
        front::check_signature(&t, &file, name)?;
        safety::check(&t.module, name)?;
        let module = port::renamed(&t, name)?;
        let wgsl = port::emit(&module, name)?;
        let sampler = crate::sampler::compile(&file, name)?;
        Ok((module, wgsl, sampler))
    }));
    let (module, wgsl, sampler) = match compiled {
        Ok(result) => result?,
        Err(panic) => {
            let what = panic
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("no message");
            return Err(UserError::Model {
                file: name.to_string(),
                reason: format!(
                    "the shader compiler (naga) failed on this file: {what}; please report it \
                     with the file"
                ),
            });
        }
    };
    let decls: Vec<ParamDecl> = file.params.iter().map(|p| p.to_decl()).collect();
    Ok(Compiled {
        file,
        decls: Box::leak(decls.into_boxed_slice()),
        module,
        wgsl,
        sampler,
    })
}
