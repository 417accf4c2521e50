//! A fit as a background job: the window's *Fit…* panel asks for the fit of
//! a key (target, model, free parameters, metric), sees its progress
//! (start, iteration, error) while it runs, and gets the fitted spec when it
//! is done.
//!
//! Unlike the other derived results this is not a [`super::jobs::Slots`]
//! kind: [`bv_core::fit::fit`] is one call that reads its own cancel flag
//! before every Jacobian and trial step and reports every iteration through
//! a callback, so the job is that call on a thread, with the flag and the
//! last report shared here. Only one fit runs at a time (the panel's): a
//! request for another key cancels the running one (it stops within one
//! Levenberg–Marquardt step) and starts the new one; a cancelled fit leaves
//! no result. In a browser page the fit runs as one step of the page's job
//! pump, so the page waits for it (there is no thread to give it).

use super::jobs::Waker;
use crate::session::platform;
use bv_core::ModelSpec;
use bv_core::fit::{self, FitOptions, FitProgress, FitResult, Metric};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

/// What a fit depends on.
#[derive(Debug, Clone, PartialEq)]
pub struct FitKey {
    /// The BRDF fitted to (measured data, a user file, a model).
    pub target: ModelSpec,
    /// The model fitted, with the starting values of its free parameters
    /// and the values of the others.
    pub model: ModelSpec,
    /// The parameters fitted (ids or aliases).
    pub free: Vec<String>,
    /// The error minimised.
    pub metric: Metric,
}

/// Where the fit of the current key stands.
#[derive(Debug, Clone, Default)]
pub struct FitStatus {
    /// The key asked for last (`None` before any request or after a cancel).
    pub key: Option<FitKey>,
    /// Whether its fit runs.
    pub running: bool,
    /// The last report of the running fit.
    pub progress: Option<FitProgress>,
    /// The finished fit of `key`, or why it failed.
    pub result: Option<Result<FitResult, String>>,
}

#[derive(Default)]
struct Inner {
    status: FitStatus,
    /// The running fit's cancel flag.
    cancel: Option<Arc<AtomicBool>>,
    /// Bumped by every start and cancel: a fit only writes to the status
    /// while it is the current one.
    generation: u64,
    /// Fit threads still running, cancelled ones included.
    live: usize,
}

/// The fit job of a window's *Fit…* panel (or a test): at most one fit at
/// a time. Clones share the job.
#[derive(Default, Clone)]
pub struct FitJob {
    inner: Arc<Mutex<Inner>>,
}

impl std::fmt::Debug for FitJob {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FitJob").finish_non_exhaustive()
    }
}

impl FitJob {
    fn lock(&self) -> MutexGuard<'_, Inner> {
        // A poisoned lock means a fit panicked; the status is still whole.
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Starts the fit of `key` unless it is the key running or finished
    /// (a finished fit is not recomputed); a running fit of another key is
    /// cancelled. `waker` hears every progress report (at most every
    /// 50 ms) and the end.
    pub fn request(&self, key: FitKey, opts: FitOptions, waker: &Waker) {
        {
            let g = self.lock();
            if g.status.key.as_ref() == Some(&key)
                && (g.status.running || g.status.result.is_some())
            {
                return;
            }
        }
        self.start(key, opts, waker);
    }

    /// Starts the fit of `key` afresh, cancelling any running fit.
    pub fn start(&self, key: FitKey, opts: FitOptions, waker: &Waker) {
        let cancel = Arc::new(AtomicBool::new(false));
        let generation = {
            let mut g = self.lock();
            if let Some(c) = g.cancel.take() {
                c.store(true, Ordering::Relaxed);
            }
            g.generation += 1;
            g.live += 1;
            g.cancel = Some(cancel.clone());
            g.status = FitStatus {
                key: Some(key.clone()),
                running: true,
                progress: None,
                result: None,
            };
            g.generation
        };
        let me = self.clone();
        let w = waker.clone();
        let mut job = Some(move || me.run(generation, &key, &opts, &cancel, &w));
        let spawned = platform::spawn_steps("bv fit", move || {
            if let Some(f) = job.take() {
                f();
            }
            true
        });
        if let Err(e) = spawned {
            let mut g = self.lock();
            g.live -= 1;
            if g.generation == generation {
                g.status.running = false;
                g.status.result = Some(Err(format!("could not start the fit: {e}")));
                g.cancel = None;
            }
        }
    }

    /// The body of a fit (on its thread).
    fn run(
        &self,
        generation: u64,
        key: &FitKey,
        opts: &FitOptions,
        cancel: &AtomicBool,
        waker: &Waker,
    ) {
        let mut last = platform::Instant::now();
        let mut progress = |p: &FitProgress| {
            let mut g = self.lock();
            if g.generation == generation {
                g.status.progress = Some(*p);
            }
            drop(g);
            if last.elapsed() > Duration::from_millis(50) {
                last = platform::Instant::now();
                waker.wake();
            }
        };
        let free: Vec<&str> = key.free.iter().map(String::as_str).collect();
        // A panic inside a model must not leave the panel "running".
        let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            let target = key
                .target
                .build()
                .map_err(|e| format!("the target `{}`: {e}", key.target.id()))?;
            let opts = FitOptions {
                metric: key.metric,
                ..opts.clone()
            };
            fit::fit(
                &key.model,
                &free,
                target.as_ref(),
                &opts,
                cancel,
                &mut progress,
            )
            .map_err(|e| e.to_string())
        }))
        .unwrap_or_else(|_| Err("the fit failed (a model panicked)".to_string()));
        let mut g = self.lock();
        g.live -= 1;
        if g.generation == generation {
            g.status.running = false;
            g.cancel = None;
            match out {
                // A cancelled fit leaves no result.
                Ok(r) if r.cancelled => g.status.key = None,
                out => g.status.result = Some(out),
            }
        }
        drop(g);
        waker.wake();
    }

    /// Cancels the running fit (it stops within one step and leaves no
    /// result) and forgets the key.
    pub fn cancel(&self) {
        let mut g = self.lock();
        if let Some(c) = g.cancel.take() {
            c.store(true, Ordering::Relaxed);
        }
        g.generation += 1;
        g.status = FitStatus::default();
    }

    /// Where the fit stands.
    pub fn status(&self) -> FitStatus {
        self.lock().status.clone()
    }

    /// Fit threads still running, cancelled ones that have not yet reached
    /// their next step included.
    pub fn live(&self) -> usize {
        self.lock().live
    }

    /// Waits until no fit runs, cancelled ones included (tests): whether
    /// they stopped within `timeout`.
    pub fn wait_idle(&self, timeout: Duration) -> bool {
        let t0 = platform::Instant::now();
        loop {
            let g = self.lock();
            if g.live == 0 {
                return true;
            }
            drop(g);
            if t0.elapsed() > timeout {
                return false;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }
}

/// The name of a fitted BRDF: "Ward fit (Ngan 0.031)", after the model,
/// the metric (Ngan et al. 2005 or Löw et al. 2012's E2) and its error.
pub fn fitted_name(model_name: &str, r: &FitResult) -> String {
    let metric = match r.metric {
        Metric::Ngan => "Ngan",
        Metric::E2 => "E2",
    };
    format!("{model_name} fit ({metric} {:.3})", r.error)
}
