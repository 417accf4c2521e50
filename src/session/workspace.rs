//! The live session of one window: the state, its built evaluators, the
//! commands waiting to be applied, the background reads of measured tables,
//! the hot reload of user files, and the messages they leave. Applying
//! commands is this module's job; the window (`app::Viewer`) draws, turns
//! input into commands, and shows what [`Workspace::apply`] asks of it (the
//! help overlay, the file dialog). Nothing here draws.

use super::command::Command;
use super::loader::{self, LoadError, LoadTarget, Loader};
use super::reload::{ReloadEvent, Reloader};
use super::runtime::Runtime;
use super::state::AppState;

/// What applying commands asks of the window, which owns the overlays.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Asks {
    /// Times the help overlay was toggled (an odd count flips it).
    pub toggle_help: usize,
    /// A file dialog to open a table or a `.brdf` file was asked for.
    pub open_dialog: bool,
}

/// The live session: state, evaluators, waiting commands, reads, reloads.
#[derive(Default)]
pub struct Workspace {
    /// The current state (what is saved).
    pub state: AppState,
    /// The evaluators built from it ([`Workspace::sync`]).
    pub runtime: Runtime,
    /// The last status message (refused values, unknown models, reloads).
    pub status: Option<String>,
    /// The background reads of file-backed models.
    pub loader: Loader,
    /// Reads and reloads that failed, shown one at a time.
    pub load_errors: Vec<LoadError>,
    /// What the last finished read was ("read gold.binary (33.6 MB) in …").
    pub last_load: Option<String>,
    pending: Vec<Command>,
    reloader: Reloader,
    reloader_woken: bool,
}

impl Workspace {
    /// A session showing `state`.
    pub fn new(state: AppState) -> Self {
        Self {
            state: state.sanitised(),
            ..Self::default()
        }
    }

    /// Replaces the whole state (a scene or a slide was opened); waiting
    /// commands, which were meant for the old one, are dropped.
    pub fn replace_state(&mut self, state: AppState) {
        self.state = state.sanitised();
        self.pending.clear();
    }

    /// Queues a command, applied by the next [`Workspace::apply_pending`].
    pub fn push(&mut self, c: Command) {
        self.pending.push(c);
    }

    /// Applies the queued commands.
    pub fn apply_pending(&mut self) -> Asks {
        let cmds = std::mem::take(&mut self.pending);
        self.apply(cmds)
    }

    /// Applies `cmds` to the state in order: messages go to the status line,
    /// file reads start in the background, and what only the window can do
    /// is returned.
    pub fn apply(&mut self, cmds: Vec<Command>) -> Asks {
        let mut asks = Asks::default();
        for c in cmds {
            let r = c.apply(&mut self.state);
            asks.toggle_help += usize::from(r.toggle_help);
            if let Some(m) = r.message {
                self.status = Some(m);
            }
            if let Some((path, target)) = r.open {
                self.loader.start(path.into(), target);
            }
            asks.open_dialog |= r.open_dialog;
        }
        asks
    }

    /// Rebuilds the evaluators of what changed.
    pub fn sync(&mut self) {
        self.runtime.sync(&self.state);
    }

    /// Applies the reads that have finished: a valid table becomes a BRDF (or
    /// a BRDF's new file), a refused one an entry of the error list.
    pub fn finish_loads(&mut self) -> Asks {
        let mut asks = Asks::default();
        for done in self.loader.poll() {
            let path = std::fs::canonicalize(&done.path).unwrap_or(done.path.clone());
            let text = path.display().to_string();
            match done.result {
                Ok(_) => {
                    self.last_load = Some(format!(
                        "read {} ({:.1} MB) in {:.2} s",
                        loader::file_name(&path),
                        done.bytes as f64 / 1e6,
                        done.elapsed.as_secs_f64()
                    ));
                    let value = bv_core::ParamValue::Text(text);
                    let cmd = match done.target {
                        LoadTarget::Into { brdf, param } => {
                            Command::SetParam { brdf, param, value }
                        }
                        LoadTarget::New => {
                            let Some((model, param, _)) = loader::file_model_for(&path) else {
                                self.status = Some("no model of this bv reads files".into());
                                continue;
                            };
                            let mut spec = bv_core::ModelSpec::defaults(model);
                            if let Err(e) = spec.set(param, value) {
                                self.status = Some(e.to_string());
                                continue;
                            }
                            Command::AddSpec(spec)
                        }
                    };
                    let a = self.apply(vec![cmd]);
                    asks.toggle_help += a.toggle_help;
                    asks.open_dialog |= a.open_dialog;
                }
                Err(message) => self.load_errors.push(LoadError {
                    path: text,
                    message,
                }),
            }
        }
        asks
    }

    /// Waits (up to `timeout`) for the background reads and applies them; for
    /// tests and scripted drivers. Returns whether all finished.
    pub fn wait_for_loads(&mut self, timeout: std::time::Duration) -> bool {
        let ok = self.loader.wait(timeout);
        self.finish_loads();
        ok
    }

    /// Applies saved edits of the user BRDF files drawn: the status line
    /// says which file reloaded, the error list holds a file that no longer
    /// compiles (with file, line and column) while its last working version
    /// stays drawn. `wake` is called from the watcher's thread when a file
    /// changes (set once). Returns whether anything changed, and how long
    /// until a saved change settles (look again then).
    pub fn reload_user_files(
        &mut self,
        wake: impl Fn() + Send + 'static,
    ) -> (bool, Option<std::time::Duration>) {
        let mut changed = false;
        for ev in self.reloader.update(&mut self.state) {
            match ev {
                ReloadEvent::Reloaded { path } => {
                    self.load_errors.retain(|e| e.path != path);
                    self.status = Some(format!("reloaded {path}"));
                }
                ReloadEvent::Failed { path, message } => {
                    self.load_errors.retain(|e| e.path != path);
                    self.load_errors.push(LoadError { path, message });
                }
            }
            changed = true;
        }
        if !self.reloader_woken {
            self.reloader.set_waker(wake);
            self.reloader_woken = true;
        }
        (changed, self.reloader.settles_in())
    }
}
