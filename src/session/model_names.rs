//! How file models are named in saved state: a user `.brdf` model is saved
//! by its path (its catalogue id names it only in the process that loaded
//! it), and a scene file writes the paths under its folder relative to it
//! and reads relative paths against it, so that a folder of a scene and its
//! files moves as a whole.
//!
//! The state's serde calls [`model_names_for_save`] and
//! [`model_names_for_load`] on every spec; a scene file sets its folder for
//! the duration of one read or write with [`with_scene_dir`]. The folder
//! travels beside serde rather than through it (serde has no context
//! argument, and deserialising the scene from its text keeps the line and
//! column of every error); it is scoped to the call and to the thread.
//! This module is a leaf of the session: it knows the user files (bv-user)
//! and paths, nothing of the state or the scene format.

use std::cell::RefCell;
use std::path::{Path, PathBuf};

thread_local! {
    /// The folder of the scene file being read or written on this thread:
    /// the model paths of its specs are relative to it.
    static SCENE_DIR: RefCell<Option<PathBuf>> = const { RefCell::new(None) };
}

/// Runs `body` with the model paths of every spec it reads or writes
/// (through the state's serde: [`model_names_for_save`],
/// [`model_names_for_load`]) taken relative to the scene folder `dir`, so a
/// folder holding a scene and its `.brdf` files can move as a whole, and a
/// scene opened from another current directory finds its files. Nested
/// calls restore the outer folder.
pub fn with_scene_dir<R>(dir: &Path, body: impl FnOnce() -> R) -> R {
    struct Restore(Option<PathBuf>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let old = self.0.take();
            SCENE_DIR.with(|d| *d.borrow_mut() = old);
        }
    }
    let old = SCENE_DIR.with(|d| d.borrow_mut().replace(dir.to_path_buf()));
    let _restore = Restore(old);
    body()
}

fn scene_dir() -> Option<PathBuf> {
    SCENE_DIR.with(|d| d.borrow().clone())
}

/// Applies `f` to the `model` of every spec in a spec's JSON form: the spec
/// itself (`{"model", "params"}`) and every mix component inside its
/// parameters (`{"weight", "model", "params"}`), at any depth.
fn map_model_names(v: &mut serde_json::Value, f: &dyn Fn(&str) -> Option<String>) {
    match v {
        serde_json::Value::Object(m) => {
            let spec_like = m.get("model").is_some_and(serde_json::Value::is_string)
                && m.keys()
                    .all(|k| matches!(k.as_str(), "model" | "params" | "weight"));
            if spec_like
                && let Some(serde_json::Value::String(name)) = m.get_mut("model")
                && let Some(new) = f(name)
            {
                *name = new;
            }
            for (_, x) in m.iter_mut() {
                map_model_names(x, f);
            }
        }
        serde_json::Value::Array(items) => {
            for x in items {
                map_model_names(x, f);
            }
        }
        _ => {}
    }
}

/// A spec's JSON as it is saved: every file model (mix components
/// included) named by its path, which a later run can open (its catalogue
/// id names it only in the process that loaded it). Inside
/// [`with_scene_dir`] a path under the scene's folder is written relative
/// to it, any other path absolute.
pub fn model_names_for_save(v: &mut serde_json::Value) {
    let dir = scene_dir();
    map_model_names(v, &|id| {
        let path = bv_user::path_of(id)?.display().to_string();
        Some(match &dir {
            Some(d) => portable_in(d, &path),
            None => path,
        })
    });
}

/// A spec's JSON as it is read: inside [`with_scene_dir`], every relative
/// model path (a `.brdf` file, or a measured file named by its extension,
/// mix components included) is taken relative to the scene's folder, not
/// the current directory.
pub fn model_names_for_load(v: &mut serde_json::Value) {
    let Some(dir) = scene_dir() else {
        return;
    };
    map_model_names(v, &|name| {
        (bv_user::is_file_name(name) || bv_core::registry::file_model(name).is_some())
            .then(|| resolve_in(&dir, name))
    });
}

/// `p` (from a scene file in `base`) as a path usable from here.
pub fn resolve_in(base: &Path, p: &str) -> String {
    let path = Path::new(p);
    if path.is_absolute() || base.as_os_str().is_empty() {
        return p.to_string();
    }
    base.join(path).display().to_string()
}

/// `p` (relative to the current directory, or absolute) as it is written
/// into a scene file in `dir`: relative to `dir` when it lies inside it, so
/// that a folder of a scene and its tables can be moved as a whole.
pub fn portable_in(dir: &Path, p: &str) -> String {
    let (Ok(abs), Ok(absolute_dir)) = (std::path::absolute(p), std::path::absolute(dir)) else {
        return p.to_string();
    };
    // A file model's path is canonical (symlinks resolved); the folder is
    // compared in both forms.
    let canonical_dir = std::fs::canonicalize(dir).ok();
    for d in std::iter::once(absolute_dir).chain(canonical_dir) {
        if let Ok(rel) = abs.strip_prefix(&d)
            && !rel.as_os_str().is_empty()
        {
            return rel.display().to_string();
        }
    }
    abs.display().to_string()
}
