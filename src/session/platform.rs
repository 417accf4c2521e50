//! What differs between the desktop and the browser, in one place.
//!
//! A page compiled to `wasm32-unknown-unknown` has no threads, and its
//! `std::time::Instant` panics: the clock comes from the browser
//! (`performance.now()`, through `web-time`), and work that runs on a worker
//! thread on the desktop is queued and run between frames ([`spawn`],
//! [`run_pending`]), one job per slice of a frame, so the page keeps drawing
//! its progress indication between jobs. Everything else (the file system,
//! environment variables) simply reports an error in the browser, which the
//! callers already handle.

/// A monotonic clock: `std`'s on the desktop, the browser's on the web.
#[cfg(not(target_arch = "wasm32"))]
pub use std::time::Instant;
/// A monotonic clock: `std`'s on the desktop, the browser's on the web.
#[cfg(target_arch = "wasm32")]
pub use web_time::Instant;

/// Whether this build runs in a browser.
pub const WEB: bool = cfg!(target_arch = "wasm32");

/// A job handed to [`spawn`], waiting in the browser's queue.
#[cfg(target_arch = "wasm32")]
type Job = Box<dyn FnOnce() + Send + 'static>;

/// Runs `job` off the UI: on a thread named `name` on the desktop; in the
/// browser, queued for [`run_pending`] (a page has no threads to spawn).
/// The error is the operating system's refusal of a thread.
#[cfg(not(target_arch = "wasm32"))]
pub fn spawn(name: &str, job: impl FnOnce() + Send + 'static) -> std::io::Result<()> {
    std::thread::Builder::new()
        .name(name.to_string())
        .spawn(job)
        .map(|_| ())
}

/// Runs `job` off the UI: on a thread named `name` on the desktop; in the
/// browser, queued for [`run_pending`] (a page has no threads to spawn).
#[cfg(target_arch = "wasm32")]
pub fn spawn(name: &str, job: impl FnOnce() + Send + 'static) -> std::io::Result<()> {
    let _ = name;
    queue().push_back(Box::new(job));
    Ok(())
}

#[cfg(target_arch = "wasm32")]
fn queue() -> std::sync::MutexGuard<'static, std::collections::VecDeque<Job>> {
    static QUEUE: std::sync::Mutex<std::collections::VecDeque<Job>> =
        std::sync::Mutex::new(std::collections::VecDeque::new());
    // A job that panicked poisons nothing the queue relies on.
    QUEUE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Runs queued jobs for at most `budget` (at least one, if any is queued) and
/// says whether more are waiting (the caller asks for another frame). On the
/// desktop jobs run on threads and nothing is ever queued.
pub fn run_pending(budget: std::time::Duration) -> bool {
    #[cfg(target_arch = "wasm32")]
    {
        let t0 = Instant::now();
        loop {
            // The lock is released before the job runs: a job may queue more.
            let Some(job) = queue().pop_front() else {
                return false;
            };
            job();
            if t0.elapsed() >= budget {
                return !queue().is_empty();
            }
        }
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        let _ = budget;
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spawned_jobs_run_and_nothing_is_left_queued() {
        let (tx, rx) = std::sync::mpsc::channel();
        spawn("bv test", move || {
            let _ = tx.send(7);
        })
        .unwrap();
        assert!(!run_pending(std::time::Duration::from_millis(1)));
        assert_eq!(rx.recv_timeout(std::time::Duration::from_secs(10)), Ok(7));
    }
}
