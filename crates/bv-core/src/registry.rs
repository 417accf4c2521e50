//! The model catalogue: the built-in models (one line each in
//! [`crate::models::BUILT_IN`]) and the models registered at run time (user
//! files), in presentation order. Everything that lists or finds models goes
//! through here, so nothing may assume the set is fixed at compile time:
//! [`revision`] changes whenever a model is registered, and caches built from
//! the catalogue (the generated shader dispatch) key on it.

use crate::model::ModelInfo;
use crate::{BvError, Result, models};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, LazyLock, OnceLock, RwLock};

/// A snapshot of the catalogue.
pub type Catalogue = Arc<Vec<&'static ModelInfo>>;

static CATALOGUE: LazyLock<RwLock<Catalogue>> =
    LazyLock::new(|| RwLock::new(Arc::new(models::BUILT_IN.to_vec())));

static REVISION: AtomicU64 = AtomicU64::new(0);

/// Every model, in catalogue order (built-ins first, then run-time models in
/// the order they were first registered).
pub fn catalogue() -> Catalogue {
    match CATALOGUE.read() {
        Ok(c) => c.clone(),
        // A writer cannot panic while holding the lock (it only swaps an
        // Arc), but a poisoned lock still holds a consistent catalogue.
        Err(poisoned) => poisoned.into_inner().clone(),
    }
}

/// Changes whenever the catalogue does.
pub fn revision() -> u64 {
    REVISION.load(Ordering::Acquire)
}

/// Turns a name that no catalogue entry has as its id into a model, or says
/// it is not one of its names (`Ok(None)`): the application installs one
/// that opens user files by path (a name ending in `.brdf`), which bv-core
/// cannot compile itself.
pub type Resolver = fn(&str) -> Result<Option<&'static ModelInfo>>;

static RESOLVER: OnceLock<Resolver> = OnceLock::new();

/// Installs the [`Resolver`] every [`find`] falls back on. Only the first
/// call installs one; returns whether this one did.
pub fn set_resolver(resolver: Resolver) -> bool {
    RESOLVER.set(resolver).is_ok()
}

/// The model with id `id`, or the model the installed [`Resolver`] makes of
/// the name (a user file's path).
pub fn find(id: &str) -> Result<&'static ModelInfo> {
    let c = catalogue();
    if let Some(m) = c.iter().copied().find(|m| m.id == id) {
        return Ok(m);
    }
    if let Some(resolve) = RESOLVER.get()
        && let Some(m) = resolve(id)?
    {
        return Ok(m);
    }
    Err(BvError::UnknownModel {
        id: id.to_string(),
        known: c.iter().map(|m| m.id).collect::<Vec<_>>().join(", "),
    })
}

/// The file-backed model whose file format declares the extension of
/// `name` (`a/steel.bsdf`, `gold.binary`), with its file parameter's id:
/// how a path stands for a model wherever a model id is taken (`--model`,
/// `bv eval`'s `"model"`, scene files). `None` when `name` is a catalogue id
/// or its extension is no format's.
pub fn file_model(name: &str) -> Option<(&'static ModelInfo, &'static str)> {
    let c = catalogue();
    if c.iter().any(|m| m.id == name) {
        return None;
    }
    let ext = std::path::Path::new(name)
        .extension()?
        .to_string_lossy()
        .to_ascii_lowercase();
    c.iter().find_map(|m| {
        let (decl, format) = m.file_param()?;
        format
            .extensions()
            .contains(&ext.as_str())
            .then_some((*m, decl.id))
    })
}

/// Adds a model built at run time to the catalogue, or replaces the run-time
/// model with the same id (a reloaded file), keeping its place. Returns the
/// catalogue entry. A built-in id cannot be replaced.
///
/// Entries live for the rest of the process: specs made from a replaced
/// entry keep pointing at it (and compare unequal to specs of the new one,
/// so that their evaluators are rebuilt). Each registration costs the size of
/// one declaration, which a user's edits of one file do not make large.
pub fn register(info: ModelInfo) -> Result<&'static ModelInfo> {
    if info.id.is_empty() || info.id.chars().any(|c| c.is_whitespace()) {
        return Err(BvError::Invalid(format!(
            "model id `{}` is empty or contains white space",
            info.id
        )));
    }
    if models::BUILT_IN.iter().any(|m| m.id == info.id) {
        return Err(BvError::Invalid(format!(
            "`{}` is a built-in model and cannot be replaced",
            info.id
        )));
    }
    let leaked: &'static ModelInfo = Box::leak(Box::new(info));
    let mut guard = match CATALOGUE.write() {
        Ok(g) => g,
        Err(poisoned) => poisoned.into_inner(),
    };
    let mut next: Vec<&'static ModelInfo> = guard.as_ref().clone();
    match next.iter_mut().find(|m| m.id == leaked.id) {
        Some(slot) => *slot = leaked,
        None => next.push(leaked),
    }
    *guard = Arc::new(next);
    REVISION.fetch_add(1, Ordering::AcqRel);
    Ok(leaked)
}
