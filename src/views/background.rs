//! Results computed off the UI thread and kept until their inputs change (SH
//! projections, tabulated-versus-analytic errors): the UI asks every frame for
//! the result of a key; it gets the latest finished one at once (perhaps for an
//! older key, which it may show marked as stale) and a job starts when nothing
//! has been computed or is being computed for that key. At most one job runs
//! per slot; a request that arrives while one runs replaces any waiting one,
//! so a slider drag computes the first and the last position, not every one.
//!
//! The slots live in egui's context memory ([`shared`]), so that two views
//! (the 3D lobe and the polar plot) asking for the same key share one job and
//! one result without any other plumbing.

use crate::session::platform::{self, Instant};
use eframe::egui;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

/// A job in steps: each call does a bounded slice of the work and gives the
/// value once it is finished ([`platform::spawn_steps`] runs it).
type Job<V> = Box<dyn FnMut() -> Option<V> + Send>;

/// A one-shot computation as a job of one step.
pub fn once<V>(
    compute: impl FnOnce() -> V + Send + 'static,
) -> impl FnMut() -> Option<V> + Send + 'static {
    let mut compute = Some(compute);
    move || compute.take().map(|f| f())
}

/// Runs a job of steps to its end on the calling thread (figures, tests).
pub fn run_to_end<V>(mut step: impl FnMut() -> Option<V>) -> V {
    loop {
        if let Some(v) = step() {
            return v;
        }
    }
}

/// A finished result.
#[derive(Debug)]
pub struct Done<K, V> {
    /// What it was computed for.
    pub key: K,
    /// The value.
    pub value: V,
    /// How long the job took.
    pub elapsed: Duration,
}

struct Slot<K, V> {
    running: Option<K>,
    waiting: Option<(K, Job<V>)>,
    done: Option<Arc<Done<K, V>>>,
    last_use: u64,
}

struct Inner<K, V> {
    slots: HashMap<u64, Slot<K, V>>,
    clock: u64,
}

/// Background slots keyed by a `u64` (a BRDF id, a pair of ids).
pub struct Slots<K, V> {
    inner: Mutex<Inner<K, V>>,
}

impl<K, V> Default for Slots<K, V> {
    fn default() -> Self {
        Self {
            inner: Mutex::new(Inner {
                slots: HashMap::new(),
                clock: 0,
            }),
        }
    }
}

impl<K, V> std::fmt::Debug for Slots<K, V> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Slots").finish_non_exhaustive()
    }
}

/// Slots not asked for in this many requests are dropped (removed BRDFs).
const FORGET_AFTER: u64 = 2000;

impl<K, V> Slots<K, V>
where
    K: Clone + PartialEq + Send + Sync + 'static,
    V: Send + Sync + 'static,
{
    fn lock(&self) -> MutexGuard<'_, Inner<K, V>> {
        // A poisoned lock means a job panicked; the map itself is consistent.
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The latest finished result of `slot` (whatever its key), starting
    /// `compute` (a job in steps, see [`once`] for a single one) in the
    /// background if `key` is neither finished nor running. `notify` runs
    /// when a job finishes (e.g. a repaint request).
    pub fn request(
        self: &Arc<Self>,
        slot: u64,
        key: K,
        compute: impl FnMut() -> Option<V> + Send + 'static,
        notify: impl Fn() + Send + Sync + 'static,
    ) -> Option<Arc<Done<K, V>>> {
        let mut g = self.lock();
        g.clock += 1;
        let now = g.clock;
        g.slots
            .retain(|_, s| s.running.is_some() || now.saturating_sub(s.last_use) < FORGET_AFTER);
        let s = g.slots.entry(slot).or_insert_with(|| Slot {
            running: None,
            waiting: None,
            done: None,
            last_use: now,
        });
        s.last_use = now;
        let have = s.done.as_ref().is_some_and(|d| d.key == key);
        let running = s.running.as_ref() == Some(&key);
        let mut start = None;
        if !have && !running {
            if s.running.is_some() {
                s.waiting = Some((key, Box::new(compute)));
            } else {
                s.running = Some(key.clone());
                s.waiting = None;
                start = Some((key, Box::new(compute) as Job<V>));
            }
        } else if running {
            // The key asked for is on its way: a waiting older request is moot.
            s.waiting = None;
        }
        let done = s.done.clone();
        drop(g);
        if let Some((key, job)) = start {
            let notify: Arc<dyn Fn() + Send + Sync> = Arc::new(notify);
            self.spawn(slot, key, job, notify);
        }
        done
    }

    /// Stores a result computed by the caller (figures compute before they
    /// draw instead of waiting for a job).
    pub fn insert(&self, slot: u64, key: K, value: V, elapsed: Duration) -> Arc<Done<K, V>> {
        let done = Arc::new(Done {
            key,
            value,
            elapsed,
        });
        let mut g = self.lock();
        g.clock += 1;
        let now = g.clock;
        let s = g.slots.entry(slot).or_insert_with(|| Slot {
            running: None,
            waiting: None,
            done: None,
            last_use: now,
        });
        s.last_use = now;
        s.done = Some(done.clone());
        done
    }

    /// The latest finished result of `slot`, without starting anything.
    pub fn latest(&self, slot: u64) -> Option<Arc<Done<K, V>>> {
        self.lock().slots.get(&slot).and_then(|s| s.done.clone())
    }

    /// Whether a job of `slot` is running or waiting.
    pub fn busy(&self, slot: u64) -> bool {
        self.lock()
            .slots
            .get(&slot)
            .is_some_and(|s| s.running.is_some() || s.waiting.is_some())
    }

    /// A view's result for this frame and whether a job of `slot` still
    /// runs. A figure (`now`) gets the result of `key`, computed here (all
    /// steps of `compute`) unless it is finished; a window frame gets the latest finished result (with
    /// `true` when it is of an older key) while `compute` runs in the
    /// background, `ctx` asked for a frame when the job ends and every
    /// `poll` while it runs.
    pub fn for_frame(
        self: &Arc<Self>,
        ctx: &egui::Context,
        slot: u64,
        key: K,
        now: bool,
        poll: Duration,
        compute: impl FnMut() -> Option<V> + Send + 'static,
    ) -> (Option<(V, bool)>, bool)
    where
        V: Clone,
    {
        if now {
            if let Some(d) = self.latest(slot).filter(|d| d.key == key) {
                return (Some((d.value.clone(), false)), false);
            }
            let t0 = Instant::now();
            let v = run_to_end(compute);
            self.insert(slot, key, v.clone(), t0.elapsed());
            return (Some((v, false)), false);
        }
        let c = ctx.clone();
        let done = self.request(slot, key.clone(), compute, move || c.request_repaint());
        let busy = self.busy(slot);
        if busy {
            ctx.request_repaint_after(poll);
        }
        (done.map(|d| (d.value.clone(), d.key != key)), busy)
    }

    /// Waits until no job of any slot runs (tests and scripted drivers).
    pub fn wait_idle(&self, timeout: Duration) -> bool {
        let t0 = Instant::now();
        loop {
            let idle = self
                .lock()
                .slots
                .values()
                .all(|s| s.running.is_none() && s.waiting.is_none());
            if idle {
                return true;
            }
            if t0.elapsed() > timeout {
                return false;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    fn spawn(
        self: &Arc<Self>,
        slot: u64,
        key: K,
        mut job: Job<V>,
        notify: Arc<dyn Fn() + Send + Sync>,
    ) {
        let me = self.clone();
        let mut t0 = None;
        let step = move || {
            let t0 = *t0.get_or_insert_with(Instant::now);
            // A job that panics must not leave the slot "running" forever.
            let out = match std::panic::catch_unwind(std::panic::AssertUnwindSafe(&mut job)) {
                Ok(None) => return false,
                Ok(Some(value)) => Some(value),
                Err(_) => None,
            };
            let elapsed = t0.elapsed();
            let next = {
                let mut g = me.lock();
                let s = g.slots.get_mut(&slot);
                match s {
                    Some(s) => {
                        if let Some(value) = out {
                            s.done = Some(Arc::new(Done {
                                key: key.clone(),
                                value,
                                elapsed,
                            }));
                        }
                        match s.waiting.take() {
                            Some((k, j)) => {
                                s.running = Some(k.clone());
                                Some((k, j))
                            }
                            None => {
                                s.running = None;
                                None
                            }
                        }
                    }
                    None => None,
                }
            };
            notify();
            if let Some((k, j)) = next {
                me.spawn(slot, k, j, notify.clone());
            }
            true
        };
        if platform::spawn_steps("bv compute", step).is_err() {
            // No thread to be had: forget the job rather than block the UI.
            let mut g = self.lock();
            if let Some(s) = g.slots.get_mut(&slot) {
                s.running = None;
            }
        }
    }
}

/// The slots of type `Slots<K, V>` named `name`, shared through `ctx`'s memory.
pub fn shared<K, V>(ctx: &egui::Context, name: &str) -> Arc<Slots<K, V>>
where
    K: Clone + PartialEq + Send + Sync + 'static,
    V: Send + Sync + 'static,
{
    ctx.data_mut(|d| {
        d.get_temp_mut_or_insert_with(egui::Id::unique(("bv background", name)), || {
            Arc::new(Slots::<K, V>::default())
        })
        .clone()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    #[test]
    fn computes_once_per_key_and_keeps_the_last_request() {
        let s: Arc<Slots<u32, u32>> = Arc::new(Slots::default());
        let runs = Arc::new(AtomicUsize::new(0));
        let gate = Arc::new(Mutex::new(()));
        let hold = gate.lock().unwrap();
        let job = |v: u32| {
            let runs = runs.clone();
            let gate = gate.clone();
            once(move || {
                let _g = gate.lock();
                runs.fetch_add(1, Ordering::SeqCst);
                v * 10
            })
        };
        assert!(s.request(1, 1, job(1), || {}).is_none());
        // Same key while running: nothing new. Keys 2 and 3 while running:
        // only the last one waits.
        s.request(1, 1, job(1), || {});
        s.request(1, 2, job(2), || {});
        s.request(1, 3, job(3), || {});
        assert!(s.busy(1));
        drop(hold);
        assert!(s.wait_idle(Duration::from_secs(10)));
        assert_eq!(runs.load(Ordering::SeqCst), 2, "key 1, then key 3");
        let d = s.latest(1).unwrap();
        assert_eq!((d.key, d.value), (3, 30));
        // A finished key is returned without a new job.
        let d = s.request(1, 3, job(3), || {}).unwrap();
        assert_eq!(d.value, 30);
        assert!(!s.busy(1));
        assert_eq!(runs.load(Ordering::SeqCst), 2);
    }

    #[test]
    fn a_panicking_job_frees_its_slot() {
        let s: Arc<Slots<u32, u32>> = Arc::new(Slots::default());
        s.request(7, 1, once(|| panic!("boom")), || {});
        assert!(s.wait_idle(Duration::from_secs(10)));
        assert!(s.latest(7).is_none());
        s.request(7, 2, once(|| 5), || {});
        assert!(s.wait_idle(Duration::from_secs(10)));
        assert_eq!(s.latest(7).unwrap().value, 5);
    }
}
