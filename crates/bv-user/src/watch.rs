//! Hot reload: the open `.brdf` files are watched with the OS's change
//! notifications (the `notify` crate: inotify, FSEvents, ReadDirectoryChanges),
//! not by polling. A change recompiles the file and replaces its catalogue
//! entry under the same id; a file that no longer compiles is reported with
//! its place and leaves the last working entry in the catalogue.
//!
//! The folder of each file is watched rather than the file: editors save by
//! writing a new file and renaming it over the old one, which ends a watch on
//! the file itself.

use crate::error::{Result, UserError};
use bv_core::ModelInfo;
use notify::Watcher as _;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, channel};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How long a file must stay quiet before it is read again: an editor's save
/// is several writes, and reading between them would see half a file.
pub const SETTLE: Duration = Duration::from_millis(60);

/// What a reload gave.
#[derive(Debug, Clone)]
pub enum Reload {
    /// The file compiled; its new catalogue entry (same id as before).
    Loaded {
        /// The file (canonical).
        path: PathBuf,
        /// The new entry.
        info: &'static ModelInfo,
    },
    /// The file does not compile; the entry of its last working version
    /// stays in the catalogue.
    Failed {
        /// The file (canonical).
        path: PathBuf,
        /// Why, with file, line and column where there is a place.
        error: UserError,
    },
}

type Waker = Arc<Mutex<Option<Box<dyn Fn() + Send>>>>;

/// Watches `.brdf` files and reloads them when they change.
pub struct Watcher {
    inner: notify::RecommendedWatcher,
    /// Notifications with the time each arrived (on the watcher's thread,
    /// so a change is quiet for [`SETTLE`] counted from the save itself, not
    /// from the frame that next looks).
    events: Receiver<(Instant, notify::Result<notify::Event>)>,
    files: BTreeSet<PathBuf>,
    dirs: BTreeSet<PathBuf>,
    /// Files changed and when they last did.
    dirty: BTreeMap<PathBuf, Instant>,
    waker: Waker,
}

impl std::fmt::Debug for Watcher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Watcher")
            .field("files", &self.files)
            .finish_non_exhaustive()
    }
}

impl Watcher {
    /// A watcher of no files yet.
    pub fn new() -> Result<Self> {
        let (tx, events) = channel();
        let waker: Waker = Arc::new(Mutex::new(None));
        let wake = waker.clone();
        let inner = notify::recommended_watcher(move |e| {
            // The receiver is gone only when the watcher is dropped.
            let _ = tx.send((Instant::now(), e));
            if let Ok(w) = wake.lock()
                && let Some(w) = w.as_ref()
            {
                w();
            }
        })
        .map_err(|e| UserError::Read {
            file: "(file watcher)".into(),
            reason: e.to_string(),
        })?;
        Ok(Self {
            inner,
            events,
            files: BTreeSet::new(),
            dirs: BTreeSet::new(),
            dirty: BTreeMap::new(),
            waker,
        })
    }

    /// Called (on the watcher's thread) whenever something changed, e.g. to
    /// ask a window for a frame so that [`Watcher::poll`] runs soon.
    pub fn set_waker(&mut self, wake: impl Fn() + Send + 'static) {
        if let Ok(mut w) = self.waker.lock() {
            *w = Some(Box::new(wake));
        }
    }

    /// Starts watching `path` (nothing if it is watched already).
    pub fn watch(&mut self, path: &Path) -> Result<()> {
        let canon = crate::catalogue::canonical(path)?;
        if self.files.contains(&canon) {
            return Ok(());
        }
        let dir = canon.parent().map(Path::to_path_buf).unwrap_or_default();
        if !self.dirs.contains(&dir) {
            self.inner
                .watch(&dir, notify::RecursiveMode::NonRecursive)
                .map_err(|e| UserError::Read {
                    file: path.display().to_string(),
                    reason: format!("cannot watch its folder: {e}"),
                })?;
            self.dirs.insert(dir);
        }
        self.files.insert(canon);
        Ok(())
    }

    /// Whether `path` is watched.
    pub fn is_watched(&self, path: &Path) -> bool {
        crate::catalogue::canonical(path).is_ok_and(|c| self.files.contains(&c))
    }

    /// How long until the next changed file has been quiet for [`SETTLE`]
    /// (call [`Watcher::poll`] then); `None` when no change waits.
    pub fn settles_in(&self) -> Option<Duration> {
        self.dirty
            .values()
            .map(|t| SETTLE.saturating_sub(t.elapsed()))
            .min()
    }

    /// Takes the notifications that arrived and reloads every watched file
    /// that changed and has been quiet for [`SETTLE`]. Never blocks.
    pub fn poll(&mut self) -> Vec<Reload> {
        let now = Instant::now();
        while let Ok((at, event)) = self.events.try_recv() {
            let Ok(event) = event else { continue };
            if matches!(event.kind, notify::EventKind::Access(_)) {
                continue;
            }
            for p in event.paths {
                if self.files.contains(&p) {
                    self.dirty.insert(p, at);
                }
            }
        }
        let ready: Vec<PathBuf> = self
            .dirty
            .iter()
            .filter(|(_, t)| now.duration_since(**t) >= SETTLE)
            .map(|(p, _)| p.clone())
            .collect();
        ready
            .into_iter()
            .filter_map(|path| {
                self.dirty.remove(&path);
                // A file removed for a moment (a save by rename) reloads
                // when it is back.
                if !path.exists() {
                    return None;
                }
                Some(match crate::catalogue::load(&path) {
                    Ok(info) => Reload::Loaded { path, info },
                    Err(error) => Reload::Failed { path, error },
                })
            })
            .collect()
    }
}
