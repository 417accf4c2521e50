//! Opening the files of file-backed models from the GUI.
//!
//! Every way of opening a file (the "Load…" dialog, a file dropped on the
//! window, a path typed into a BRDF's file field, `bv --open`) becomes a
//! [`Command::OpenFile`](super::Command::OpenFile), which starts a [`Loader`]
//! job: the file is read on a background thread by its model's file format
//! ([`bv_core::model::FileFormat`], through the format's cache), with the
//! bytes read published for a progress bar. Which model reads a file is
//! [`file_model_for`]: the one whose format lists its extension. Only when
//! the data has been read and validated does the job turn into the state
//! change (a new BRDF of that model, or a new path for an existing one); the
//! BRDF is then built from the cache at once. A file the reader refuses changes
//! nothing: its message goes to an error dialog, and everything already
//! loaded stays as it was.

use super::platform::{self, Instant};
use bv_core::model::{FileData, FileFormat, ModelInfo};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, mpsc};
use std::time::Duration;

/// The catalogue's file-backed model that reads `path`, with its file
/// parameter's id and format: the first whose format lists the file's
/// extension, else the first file-backed model (a table saved under another
/// name). `None` when no model reads files.
pub fn file_model_for(
    path: &Path,
) -> Option<(&'static ModelInfo, &'static str, &'static dyn FileFormat)> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let catalogue = bv_core::catalogue();
    let backed = || {
        catalogue
            .iter()
            .filter_map(|m| m.file_param().map(|(d, f)| (*m, d.id, f)))
    };
    backed()
        .find(|(_, _, f)| f.extensions().contains(&ext.as_str()))
        .or_else(|| backed().next())
}

/// Where loaded data goes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LoadTarget {
    /// A new BRDF of the model that reads the file ([`file_model_for`]).
    New,
    /// The path parameter `param` of the BRDF with id `brdf`.
    Into {
        /// BRDF id.
        brdf: u64,
        /// Its path parameter.
        param: String,
    },
}

/// One file being read.
#[derive(Debug)]
pub struct LoadJob {
    /// The file.
    pub path: PathBuf,
    /// Where the table goes.
    pub target: LoadTarget,
    /// When the read started.
    pub started: Instant,
    read: Arc<AtomicU64>,
    total: Arc<AtomicU64>,
    done: Arc<AtomicBool>,
    rx: mpsc::Receiver<Result<Arc<dyn FileData>, String>>,
}

impl LoadJob {
    /// `(bytes read, file size)` so far (the size is 0 until the file is open).
    pub fn progress(&self) -> (u64, u64) {
        (
            self.read.load(Ordering::Relaxed),
            self.total.load(Ordering::Relaxed),
        )
    }

    /// The file name, for messages.
    pub fn name(&self) -> String {
        file_name(&self.path)
    }
}

/// A finished read.
#[derive(Debug)]
pub struct Finished {
    /// The file.
    pub path: PathBuf,
    /// Where the table goes.
    pub target: LoadTarget,
    /// The data, or the reader's message.
    pub result: Result<Arc<dyn FileData>, String>,
    /// How long the read took.
    pub elapsed: Duration,
    /// The file size.
    pub bytes: u64,
}

/// A file that could not be opened: what the error dialog shows.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoadError {
    /// The file.
    pub path: String,
    /// The reader's message.
    pub message: String,
}

/// The background reads in flight.
#[derive(Debug, Default)]
pub struct Loader {
    jobs: Vec<LoadJob>,
}

impl Loader {
    /// Starts reading `path` on a background thread.
    pub fn start(&mut self, path: PathBuf, target: LoadTarget) {
        let read = Arc::new(AtomicU64::new(0));
        let total = Arc::new(AtomicU64::new(0));
        let done = Arc::new(AtomicBool::new(false));
        let (tx, rx) = mpsc::channel();
        let (r, t, d, p) = (read.clone(), total.clone(), done.clone(), path.clone());
        let tx2 = tx.clone();
        let spawned = platform::spawn("bv load", move || {
            let result = match file_model_for(&p) {
                Some((_, _, format)) => format
                    .load(&p, &mut |a, b| {
                        t.store(b, Ordering::Relaxed);
                        r.store(a, Ordering::Relaxed);
                    })
                    .map_err(|e| e.to_string()),
                None => Err("no model of this bv reads files".to_string()),
            };
            // The receiver is gone only if the viewer closed meanwhile.
            let _ = tx.send(result);
            d.store(true, Ordering::Release);
        });
        if let Err(e) = spawned {
            // No thread: report it like a failed read.
            let _ = tx2.send(Err(format!("cannot start a reading thread: {e}")));
            done.store(true, Ordering::Release);
        }
        self.jobs.push(LoadJob {
            path,
            target,
            started: Instant::now(),
            read,
            total,
            done,
            rx,
        });
    }

    /// The reads in flight.
    pub fn jobs(&self) -> &[LoadJob] {
        &self.jobs
    }

    /// Whether anything is being read.
    pub fn busy(&self) -> bool {
        !self.jobs.is_empty()
    }

    /// Removes and returns the reads that have finished.
    pub fn poll(&mut self) -> Vec<Finished> {
        let mut done = Vec::new();
        let mut i = 0;
        while i < self.jobs.len() {
            let outcome = match self.jobs[i].rx.try_recv() {
                Ok(r) => Some(r),
                Err(mpsc::TryRecvError::Empty) => None,
                Err(mpsc::TryRecvError::Disconnected) => Some(Err(
                    "the reading thread stopped without an answer".to_string(),
                )),
            };
            match outcome {
                Some(result) => {
                    let job = self.jobs.remove(i);
                    let bytes = job.progress().1;
                    done.push(Finished {
                        elapsed: job.started.elapsed(),
                        path: job.path,
                        target: job.target,
                        result,
                        bytes,
                    });
                }
                None => i += 1,
            }
        }
        done
    }

    /// Waits (up to `timeout`) until every read has finished and returns
    /// whether they all did; for tests and scripted drivers (the results are
    /// then picked up by [`Self::poll`]).
    pub fn wait(&self, timeout: Duration) -> bool {
        let t0 = Instant::now();
        loop {
            if self.jobs.iter().all(|j| j.done.load(Ordering::Acquire)) {
                return true;
            }
            if t0.elapsed() >= timeout {
                return false;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }
}

/// The last component of a path, for labels and messages.
pub fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// `12.3 / 35.0 MB`.
pub fn progress_text(read: u64, total: u64) -> String {
    if total == 0 {
        return "opening…".to_string();
    }
    format!("{:.1} / {:.1} MB", read as f64 / 1e6, total as f64 / 1e6)
}

#[cfg(test)]
mod tests {
    use super::*;
    use bv_core::measured::merl::{self, MerlDims, tabulate};

    fn wait_done(l: &mut Loader) -> Vec<Finished> {
        let t0 = Instant::now();
        let mut out = Vec::new();
        while out.is_empty() && t0.elapsed() < Duration::from_secs(30) {
            out = l.poll();
            std::thread::sleep(Duration::from_millis(2));
        }
        out
    }

    #[test]
    fn reads_in_the_background_and_reports_errors() {
        let dir = std::env::temp_dir().join(format!("bv-loader-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let good = dir.join("l.binary");
        let lambert = bv_core::ModelSpec::new("lambert").unwrap().build().unwrap();
        tabulate(lambert.as_ref(), MerlDims::new(4, 4, 8).unwrap())
            .unwrap()
            .write(&good)
            .unwrap();
        let mut l = Loader::default();
        l.start(good.clone(), LoadTarget::New);
        assert!(l.busy());
        let done = wait_done(&mut l);
        assert_eq!(done.len(), 1);
        assert!(done[0].result.is_ok());
        assert_eq!(done[0].bytes, MerlDims::new(4, 4, 8).unwrap().file_len());
        assert!(!l.busy());
        // The table is now in the cache the model builds from.
        assert!(merl::is_cached(&good));

        let bad = dir.join("bad.binary");
        std::fs::write(&bad, [1u8, 2, 3]).unwrap();
        l.start(bad, LoadTarget::New);
        let done = wait_done(&mut l);
        let err = done[0].result.as_ref().unwrap_err();
        assert!(
            err.contains("bad.binary") && err.contains("too short"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_or_a_device_is_refused_at_once_not_waited_on() {
        let dir = std::env::temp_dir().join(format!("bv-loader-fifo-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("pipe.binary");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        let mut l = Loader::default();
        l.start(fifo, LoadTarget::New);
        l.start(PathBuf::from("/dev/zero"), LoadTarget::New);
        // Opening a FIFO without O_NONBLOCK would wait for a writer forever.
        assert!(l.wait(Duration::from_secs(10)), "a read is still blocked");
        let mut errors: Vec<String> = l
            .poll()
            .into_iter()
            .map(|f| f.result.unwrap_err())
            .collect();
        errors.sort();
        assert!(errors[0].contains("/dev/zero") && errors[0].contains("character device"));
        assert!(errors[1].contains("pipe.binary") && errors[1].contains("FIFO"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn texts() {
        assert_eq!(progress_text(0, 0), "opening…");
        assert_eq!(progress_text(12_300_000, 34_992_012), "12.3 / 35.0 MB");
        assert_eq!(file_name(Path::new("/x/gold.binary")), "gold.binary");
    }
}
