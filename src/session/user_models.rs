//! User BRDF files (`.brdf`) as models: the one place the application turns
//! "a model id or a path ending in `.brdf`" into a catalogue entry. The work
//! (compiling, registering, watching) is bv-user's; installing its resolver
//! makes every lookup by id (`--model`, `bv eval`'s `"model"`, scene files,
//! mixes, `check`/`render`/`slice`/`tabulate`/`bench`) accept a path too.

use super::state::AppState;
use anyhow::{Context as _, Result};
use bv_core::ModelInfo;
use std::cell::RefCell;
use std::path::{Path, PathBuf};

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
        let path = path_of(id)?;
        Some(match &dir {
            Some(d) => super::scene_file::portable_in(d, &path),
            None => path,
        })
    });
}

/// A spec's JSON as it is read: inside [`with_scene_dir`], every relative
/// `.brdf` path (mix components included) is taken relative to the scene's
/// folder, not the current directory.
pub fn model_names_for_load(v: &mut serde_json::Value) {
    let Some(dir) = scene_dir() else {
        return;
    };
    map_model_names(v, &|name| {
        is_file(name).then(|| super::scene_file::resolve_in(&dir, name))
    });
}

/// What a reload did, for the window to show.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ReloadEvent {
    /// The file was saved and compiled; the BRDFs of it were rebuilt with the
    /// values of the parameters that still exist.
    Reloaded {
        /// The file.
        path: String,
    },
    /// The file was saved but does not compile; the last working version
    /// stays drawn.
    Failed {
        /// The file.
        path: String,
        /// The error, with file, line and column.
        message: String,
    },
}

/// Hot reload of the user files the state draws: watches every file model
/// of the state (however it was opened: `--model`, a scene, the dialog, a
/// drop) and applies reloads to the state.
#[derive(Debug, Default)]
pub struct Reloader {
    watcher: Option<bv_user::watch::Watcher>,
    /// Why watching is impossible, said once.
    unavailable: Option<String>,
}

impl Reloader {
    /// `wake` runs on the watcher's thread when a file changes (ask the
    /// window for a frame).
    pub fn set_waker(&mut self, wake: impl Fn() + Send + 'static) {
        if let Some(w) = self.watcher_mut() {
            w.set_waker(wake);
        }
    }

    fn watcher_mut(&mut self) -> Option<&mut bv_user::watch::Watcher> {
        // A browser page has no files to watch (and notify's polling
        // watcher reads the clock std has no source for there).
        if cfg!(target_arch = "wasm32") {
            return None;
        }
        if self.watcher.is_none() && self.unavailable.is_none() {
            match bv_user::watch::Watcher::new() {
                Ok(w) => self.watcher = Some(w),
                Err(e) => self.unavailable = Some(e.to_string()),
            }
        }
        self.watcher.as_mut()
    }

    /// How long until a saved change has settled (update again then);
    /// `None` when none waits.
    pub fn settles_in(&self) -> Option<std::time::Duration> {
        self.watcher.as_ref().and_then(|w| w.settles_in())
    }

    /// Watches the state's file models and applies the reloads that are
    /// ready: every BRDF of a reloaded file gets the new model, keeping the
    /// values of the parameters the new version still declares.
    pub fn update(&mut self, state: &mut AppState) -> Vec<ReloadEvent> {
        let paths: Vec<std::path::PathBuf> = state
            .brdfs
            .iter()
            .filter_map(|b| bv_user::path_of(b.spec.id()))
            .collect();
        if paths.is_empty() && self.watcher.is_none() {
            return Vec::new();
        }
        let Some(w) = self.watcher_mut() else {
            return Vec::new();
        };
        let mut events = Vec::new();
        for p in paths {
            if !w.is_watched(&p)
                && let Err(e) = w.watch(&p)
            {
                events.push(ReloadEvent::Failed {
                    path: p.display().to_string(),
                    message: e.to_string(),
                });
            }
        }
        for r in w.poll() {
            match r {
                bv_user::watch::Reload::Loaded { path, info } => {
                    for b in &mut state.brdfs {
                        if b.spec.id() == info.id {
                            b.spec = super::command::carry_over(&b.spec, info);
                        }
                    }
                    events.push(ReloadEvent::Reloaded {
                        path: path.display().to_string(),
                    });
                }
                bv_user::watch::Reload::Failed { path, error } => {
                    events.push(ReloadEvent::Failed {
                        path: path.display().to_string(),
                        message: error.to_string(),
                    });
                }
            }
        }
        events
    }
}
