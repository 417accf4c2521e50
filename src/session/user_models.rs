//! User BRDF files (`.brdf`) as models: the one place the application turns
//! "a model id or a path ending in `.brdf`" into a catalogue entry. The work
//! (compiling, registering, watching) is bv-user's; installing its resolver
//! makes every lookup by id (`--model`, `bv eval`'s `"model"`, scene files,
//! mixes, `check`/`render`/`slice`/`tabulate`/`bench`) accept a path too.

use super::state::AppState;
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

    /// Whether a change waits to settle (poll again after
    /// [`bv_user::watch::SETTLE`]).
    pub fn pending(&self) -> bool {
        self.watcher.as_ref().is_some_and(|w| w.pending())
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
