//! User BRDF files (`.brdf`) as models: the one place the application turns
//! "a model id or a path ending in `.brdf`" into a catalogue entry. The work
//! (compiling, registering, watching) is bv-user's; installing its resolver
//! makes every lookup by id (`--model`, `bv eval`'s `"model"`, scene files,
//! mixes, `check`/`render`/`slice`/`tabulate`/`bench`) accept a path too.

use anyhow::{Context as _, Result};
use bv_core::ModelInfo;
use std::path::Path;

/// Makes every model lookup accept a `.brdf` path (idempotent).
pub fn install() {
    bv_user::install();
}

/// Whether `name` names a user file rather than a catalogue id.
pub fn is_file(name: &str) -> bool {
    bv_user::is_file_name(name)
}

/// The path of the file a model id was loaded from, if it is a file model:
/// what scene files and the saved session name it by.
pub fn path_of(id: &str) -> Option<String> {
    bv_user::path_of(id).map(|p| p.display().to_string())
}

/// The catalogue entry a model name stands for: a catalogue id, or the path
/// of a `.brdf` file (compiled and registered, or the entry of an unchanged
/// earlier load).
pub fn resolve(name: &str) -> Result<&'static ModelInfo> {
    install();
    if is_file(name) {
        return bv_user::open(Path::new(name)).with_context(|| format!("cannot open `{name}`"));
    }
    Ok(bv_core::find(name)?)
}
