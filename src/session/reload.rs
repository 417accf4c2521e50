//! Hot reload of user `.brdf` files: the files the state draws are watched,
//! and a saved file's new model replaces the old one in every BRDF that uses
//! it (bv-user compiles it; the state keeps the values of the parameters the
//! new version still declares).

use super::state::AppState;

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
