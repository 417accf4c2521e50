//! Derived results computed off the UI thread and kept until their inputs
//! change: the caller asks for the result of a key; it gets the latest
//! finished one at once (perhaps for an older key, which it may show marked as
//! stale) and a job starts when nothing has been computed or is being computed
//! for that key. At most one job runs per slot; a request that arrives while
//! one runs replaces any waiting one, so a slider drag computes the first and
//! the last position, not every one.
//!
//! Jobs are written as steps ([`Steps`]): a step is a bounded slice of the
//! work, so that a browser page draws between steps
//! ([`platform::spawn_steps`]), a job reports its progress after each one,
//! and a cancelled job ([`Slots::cancel`]) stops at the next step boundary.
//!
//! The slots of the process live in one store ([`slots`]): the window's
//! views, offscreen figures, `bv render` and tests asking for the same key
//! share one job and one result.

use crate::session::platform::{self, Instant};
use std::any::{Any, TypeId};
use std::collections::{HashMap, VecDeque};
use std::sync::{Arc, LazyLock, Mutex, MutexGuard};
use std::time::Duration;

/// A job in steps: each [`Steps::step`] does a bounded slice of the work and
/// gives the value once it is finished ([`platform::spawn_steps`] runs it).
/// A closure `FnMut() -> Option<V>` is a job without progress.
pub trait Steps<V>: Send + 'static {
    /// Does the next slice of the work; the value once the job is finished.
    fn step(&mut self) -> Option<V>;

    /// Steps done and steps in all, where the job knows them.
    fn progress(&self) -> Option<(usize, usize)> {
        None
    }
}

impl<V, F: FnMut() -> Option<V> + Send + 'static> Steps<V> for F {
    fn step(&mut self) -> Option<V> {
        self()
    }
}

type Job<V> = Box<dyn Steps<V>>;

/// How a finished or progressing job tells whoever shows its result: a
/// repaint request in the window (`None`: now; `Some(d)`: within `d`), nothing
/// for a figure or a script.
#[derive(Clone)]
pub struct Waker(Arc<dyn Fn(Option<Duration>) + Send + Sync>);

impl Waker {
    /// A waker calling `wake`.
    pub fn new(wake: impl Fn(Option<Duration>) + Send + Sync + 'static) -> Self {
        Self(Arc::new(wake))
    }

    /// A waker that tells nobody (figures, the command line, tests).
    pub fn none() -> Self {
        Self::new(|_| {})
    }

    /// Asks for the result to be shown now.
    pub fn wake(&self) {
        (self.0)(None);
    }

    /// Asks to be asked again within `d` (polling a running job's progress).
    pub fn wake_after(&self, d: Duration) {
        (self.0)(Some(d));
    }
}

impl std::fmt::Debug for Waker {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Waker")
    }
}

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
    /// Progress of the running job, (steps done, steps in all).
    progress: Option<(usize, usize)>,
    /// Raised by [`Slots::cancel`]; the running job stops at its next step.
    cancel: bool,
    last_use: u64,
}

impl<K, V> Slot<K, V> {
    fn new(now: u64) -> Self {
        Self {
            running: None,
            waiting: None,
            done: None,
            progress: None,
            cancel: false,
            last_use: now,
        }
    }
}

struct Inner<K, V> {
    slots: HashMap<u64, Slot<K, V>>,
    /// The last finished results of any slot, newest last, found by key
    /// (a slider back where it was, another window or test with the same
    /// BRDF): at most `keep`.
    recent: VecDeque<Arc<Done<K, V>>>,
    keep: usize,
    clock: u64,
    /// Results computed (jobs finished and values computed by callers).
    computed: u64,
    /// Steps run by jobs, all slots together.
    steps: u64,
}

/// Derived results of one kind, in slots keyed by a `u64` (a BRDF id, a pair
/// of ids), each holding the latest result and at most one running job.
pub struct Slots<K, V> {
    inner: Mutex<Inner<K, V>>,
}

impl<K, V> Default for Slots<K, V> {
    fn default() -> Self {
        Self {
            inner: Mutex::new(Inner {
                slots: HashMap::new(),
                recent: VecDeque::new(),
                keep: DEFAULT_KEEP,
                clock: 0,
                computed: 0,
                steps: 0,
            }),
        }
    }
}

impl<K, V> std::fmt::Debug for Slots<K, V> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Slots").finish_non_exhaustive()
    }
}

/// Finished results a kind keeps beyond each slot's latest, by default.
pub const DEFAULT_KEEP: usize = 16;

/// Slots not asked for in this many requests are dropped (removed BRDFs).
const FORGET_AFTER: u64 = 2000;

/// What a caller shows in one frame: the latest result (perhaps of an older
/// key) and whether a job still runs.
#[derive(Debug)]
pub struct Shown<K, V> {
    /// The latest finished result, if any.
    pub done: Option<Arc<Done<K, V>>>,
    /// Whether `done` is of another key than the one asked for.
    pub stale: bool,
    /// Whether a job of the slot runs or waits.
    pub busy: bool,
    /// The running job's progress, (steps done, steps in all).
    pub progress: Option<(usize, usize)>,
}

impl<K, V: Clone> Shown<K, V> {
    /// The latest value and whether it is stale.
    pub fn value(&self) -> Option<(V, bool)> {
        self.done.as_ref().map(|d| (d.value.clone(), self.stale))
    }
}

impl<K, V> Inner<K, V>
where
    K: PartialEq,
{
    /// A finished result of `key` among the recent ones.
    fn recent(&self, key: &K) -> Option<Arc<Done<K, V>>> {
        self.recent.iter().rev().find(|d| d.key == *key).cloned()
    }

    /// Remembers a finished result (newest last, the oldest dropped).
    fn remember(&mut self, done: &Arc<Done<K, V>>) {
        self.recent.retain(|d| d.key != done.key);
        self.recent.push_back(done.clone());
        while self.recent.len() > self.keep {
            self.recent.pop_front();
        }
    }
}

impl<K, V> Slots<K, V>
where
    K: Clone + PartialEq + Send + Sync + 'static,
    V: Send + Sync + 'static,
{
    fn lock(&self) -> MutexGuard<'_, Inner<K, V>> {
        // A poisoned lock means a job panicked; the map itself is consistent.
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Slots that keep `keep` finished results beyond each slot's latest
    /// (fewer for large results: a factorisation holds a whole table).
    pub fn keeping(keep: usize) -> Self {
        let s = Self::default();
        s.lock().keep = keep;
        s
    }

    /// The latest finished result of `slot` (whatever its key), starting
    /// `compute` (a job in steps, see [`once`] for a single one) in the
    /// background if `key` is neither finished nor running. `waker` is woken
    /// when a job finishes (e.g. a repaint request).
    pub fn request(
        self: &Arc<Self>,
        slot: u64,
        key: K,
        compute: impl Steps<V>,
        waker: &Waker,
    ) -> Option<Arc<Done<K, V>>> {
        let mut g = self.lock();
        g.clock += 1;
        let now = g.clock;
        g.slots
            .retain(|_, s| s.running.is_some() || now.saturating_sub(s.last_use) < FORGET_AFTER);
        let recent = g.recent(&key);
        let s = g.slots.entry(slot).or_insert_with(|| Slot::new(now));
        s.last_use = now;
        if let Some(d) = recent
            && s.done.as_ref().is_none_or(|x| x.key != key)
        {
            // Computed before (for this slot or another): no job, and a
            // waiting one for an older key is moot.
            s.done = Some(d);
            s.waiting = None;
        }
        let have = s.done.as_ref().is_some_and(|d| d.key == key);
        let running = s.running.as_ref() == Some(&key);
        let mut start = None;
        if !have && !running {
            if s.running.is_some() {
                s.waiting = Some((key, Box::new(compute)));
            } else {
                s.running = Some(key.clone());
                s.waiting = None;
                s.progress = None;
                s.cancel = false;
                start = Some((key, Box::new(compute) as Job<V>));
            }
        } else if running {
            // The key asked for is on its way: a waiting older request is moot.
            s.waiting = None;
        }
        let done = s.done.clone();
        drop(g);
        if let Some((key, job)) = start {
            self.spawn(slot, key, job, waker.clone());
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
        g.computed += 1;
        g.remember(&done);
        let now = g.clock;
        let s = g.slots.entry(slot).or_insert_with(|| Slot::new(now));
        s.last_use = now;
        s.done = Some(done.clone());
        done
    }

    /// The latest finished result of `slot`, without starting anything.
    pub fn latest(&self, slot: u64) -> Option<Arc<Done<K, V>>> {
        self.lock().slots.get(&slot).and_then(|s| s.done.clone())
    }

    /// The finished result of `key` (in `slot`, or among the recent results
    /// of any slot), without starting anything.
    pub fn get(&self, slot: u64, key: &K) -> Option<Arc<Done<K, V>>> {
        let g = self.lock();
        g.slots
            .get(&slot)
            .and_then(|s| s.done.clone())
            .filter(|d| d.key == *key)
            .or_else(|| g.recent(key))
    }

    /// Whether a job of `slot` is running or waiting.
    pub fn busy(&self, slot: u64) -> bool {
        self.lock()
            .slots
            .get(&slot)
            .is_some_and(|s| s.running.is_some() || s.waiting.is_some())
    }

    /// The running job's progress in `slot`, (steps done, steps in all),
    /// where the job reports it.
    pub fn progress(&self, slot: u64) -> Option<(usize, usize)> {
        self.lock()
            .slots
            .get(&slot)
            .filter(|s| s.running.is_some())
            .and_then(|s| s.progress)
    }

    /// Cancels the job of `slot` (and forgets a waiting one): it stops before
    /// its next step and leaves the previous result in place.
    pub fn cancel(&self, slot: u64) {
        if let Some(s) = self.lock().slots.get_mut(&slot) {
            s.waiting = None;
            if s.running.is_some() {
                s.cancel = true;
            }
        }
    }

    /// How many results were computed in all (finished jobs and values
    /// computed by callers): a test's evidence that a result was computed
    /// once.
    pub fn computed(&self) -> u64 {
        self.lock().computed
    }

    /// How many job steps ran in all (a cancelled job's steps included).
    pub fn steps(&self) -> u64 {
        self.lock().steps
    }

    /// The result of `key`, computed here on the calling thread (all steps of
    /// `compute`) unless it is finished, or waited for when a job is already
    /// computing it (figures, the command line, scripts: they draw or print
    /// once, so they need the finished value).
    pub fn now(self: &Arc<Self>, slot: u64, key: K, compute: impl Steps<V>) -> Arc<Done<K, V>> {
        // A job of the window computing this very key: wait for it rather
        // than compute it twice (not in a browser page, whose jobs run
        // between frames on this thread).
        if !platform::WEB {
            loop {
                let (running, done) = {
                    let g = self.lock();
                    let s = g.slots.get(&slot);
                    (
                        s.is_some_and(|s| s.running.as_ref() == Some(&key)),
                        s.and_then(|s| s.done.clone())
                            .filter(|d| d.key == key)
                            .or_else(|| g.recent(&key)),
                    )
                };
                if let Some(d) = done {
                    return d;
                }
                if !running {
                    break;
                }
                std::thread::sleep(Duration::from_millis(2));
            }
        } else if let Some(d) = self.get(slot, &key) {
            return d;
        }
        let t0 = Instant::now();
        let mut compute = compute;
        let v = run_to_end(|| compute.step());
        self.insert(slot, key, v, t0.elapsed())
    }

    /// A caller's result for this frame. A figure (`now`) gets the result of
    /// `key`, computed here unless it is finished ([`Slots::now`]); a window
    /// frame gets the latest finished result (stale when it is of an older
    /// key) while `compute` runs in the background, with `waker` woken when
    /// the job ends and every `poll` while it runs.
    pub fn for_frame(
        self: &Arc<Self>,
        waker: &Waker,
        slot: u64,
        key: K,
        now: bool,
        poll: Duration,
        compute: impl Steps<V>,
    ) -> Shown<K, V> {
        if now {
            return Shown {
                done: Some(self.now(slot, key, compute)),
                stale: false,
                busy: false,
                progress: None,
            };
        }
        let done = self.request(slot, key.clone(), compute, waker);
        let busy = self.busy(slot);
        if busy {
            waker.wake_after(poll);
        }
        Shown {
            stale: done.as_ref().is_some_and(|d| d.key != key),
            done,
            busy,
            progress: self.progress(slot),
        }
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

    fn spawn(self: &Arc<Self>, slot: u64, key: K, mut job: Job<V>, waker: Waker) {
        let me = self.clone();
        let mut t0 = None;
        let step = move || {
            let t0 = *t0.get_or_insert_with(Instant::now);
            // A cancelled job stops here, before its next step.
            let cancelled = me.lock().slots.get(&slot).is_none_or(|s| s.cancel);
            let out = if cancelled {
                None
            } else {
                // A job that panics must not leave the slot "running" forever.
                let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| job.step()));
                let progress = job.progress();
                let mut g = me.lock();
                g.steps += 1;
                match r {
                    Ok(None) => {
                        // Whoever shows the progress polls it (`for_frame`
                        // asks to be called again while a job runs): a wake
                        // per step would ask for a frame per step.
                        if let Some(s) = g.slots.get_mut(&slot) {
                            s.progress = progress;
                        }
                        return false;
                    }
                    Ok(Some(value)) => Some(value),
                    Err(_) => None,
                }
            };
            let elapsed = t0.elapsed();
            let next = {
                let mut g = me.lock();
                if out.is_some() {
                    g.computed += 1;
                }
                let done = out.map(|value| {
                    Arc::new(Done {
                        key: key.clone(),
                        value,
                        elapsed,
                    })
                });
                if let Some(d) = &done {
                    g.remember(d);
                }
                match g.slots.get_mut(&slot) {
                    Some(s) => {
                        if let Some(d) = done {
                            s.done = Some(d);
                        }
                        s.cancel = false;
                        s.progress = None;
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
            waker.wake();
            if let Some((k, j)) = next {
                me.spawn(slot, k, j, waker.clone());
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

type Store = HashMap<(TypeId, &'static str), Arc<dyn Any + Send + Sync>>;

/// Every kind of derived result of the process, by name and type.
static STORE: LazyLock<Mutex<Store>> = LazyLock::new(Mutex::default);

/// The process's slots of type `Slots<K, V>` named `name`: the same object
/// for the window, figures, the command line and tests (keeping
/// [`DEFAULT_KEEP`] recent results).
pub fn slots<K, V>(name: &'static str) -> Arc<Slots<K, V>>
where
    K: Clone + PartialEq + Send + Sync + 'static,
    V: Send + Sync + 'static,
{
    slots_keeping(name, DEFAULT_KEEP)
}

/// [`slots`], keeping `keep` recent results when it makes them (the first
/// call for a name decides).
pub fn slots_keeping<K, V>(name: &'static str, keep: usize) -> Arc<Slots<K, V>>
where
    K: Clone + PartialEq + Send + Sync + 'static,
    V: Send + Sync + 'static,
{
    let mut store = STORE.lock().unwrap_or_else(|e| e.into_inner());
    let any = store
        .entry((TypeId::of::<Slots<K, V>>(), name))
        .or_insert_with(|| Arc::new(Slots::<K, V>::keeping(keep)))
        .clone();
    drop(store);
    // The entry was made with this very type (the key holds its TypeId).
    match any.downcast::<Slots<K, V>>() {
        Ok(s) => s,
        Err(_) => Arc::new(Slots::default()),
    }
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
        assert!(s.request(1, 1, job(1), &Waker::none()).is_none());
        // Same key while running: nothing new. Keys 2 and 3 while running:
        // only the last one waits.
        s.request(1, 1, job(1), &Waker::none());
        s.request(1, 2, job(2), &Waker::none());
        s.request(1, 3, job(3), &Waker::none());
        assert!(s.busy(1));
        drop(hold);
        assert!(s.wait_idle(Duration::from_secs(10)));
        assert_eq!(runs.load(Ordering::SeqCst), 2, "key 1, then key 3");
        let d = s.latest(1).unwrap();
        assert_eq!((d.key, d.value), (3, 30));
        // A finished key is returned without a new job.
        let d = s.request(1, 3, job(3), &Waker::none()).unwrap();
        assert_eq!(d.value, 30);
        assert!(!s.busy(1));
        assert_eq!(runs.load(Ordering::SeqCst), 2);
    }

    #[test]
    fn a_panicking_job_frees_its_slot() {
        let s: Arc<Slots<u32, u32>> = Arc::new(Slots::default());
        s.request(7, 1, once(|| panic!("boom")), &Waker::none());
        assert!(s.wait_idle(Duration::from_secs(10)));
        assert!(s.latest(7).is_none());
        s.request(7, 2, once(|| 5), &Waker::none());
        assert!(s.wait_idle(Duration::from_secs(10)));
        assert_eq!(s.latest(7).unwrap().value, 5);
    }

    /// A job of endless steps, each counted, which would run for ever.
    struct Endless {
        steps: Arc<AtomicUsize>,
    }

    impl Steps<u32> for Endless {
        fn step(&mut self) -> Option<u32> {
            self.steps.fetch_add(1, Ordering::SeqCst);
            std::thread::sleep(Duration::from_millis(1));
            None
        }
        fn progress(&self) -> Option<(usize, usize)> {
            Some((self.steps.load(Ordering::SeqCst), usize::MAX))
        }
    }

    #[test]
    fn a_cancelled_job_stops_within_one_step() {
        let s: Arc<Slots<u32, u32>> = Arc::new(Slots::default());
        let steps = Arc::new(AtomicUsize::new(0));
        s.request(
            3,
            1,
            Endless {
                steps: steps.clone(),
            },
            &Waker::none(),
        );
        let t0 = Instant::now();
        while steps.load(Ordering::SeqCst) < 5 && t0.elapsed() < Duration::from_secs(10) {
            std::thread::sleep(Duration::from_millis(1));
        }
        assert!(s.busy(3));
        assert!(s.progress(3).is_some_and(|(done, _)| done >= 1));
        s.cancel(3);
        let at_cancel = steps.load(Ordering::SeqCst);
        assert!(s.wait_idle(Duration::from_secs(10)), "the job did not stop");
        let after = steps.load(Ordering::SeqCst) - at_cancel;
        assert!(after <= 1, "{after} steps ran after the cancel");
        assert!(s.latest(3).is_none(), "a cancelled job leaves no result");
        assert_eq!(s.computed(), 0);
        // The slot works again.
        s.request(3, 2, once(|| 7), &Waker::none());
        assert!(s.wait_idle(Duration::from_secs(10)));
        assert_eq!(s.latest(3).unwrap().value, 7);
    }

    #[test]
    fn the_store_hands_out_one_object_per_name_and_type() {
        let a = slots::<u32, u32>("jobs test");
        let b = slots::<u32, u32>("jobs test");
        assert!(Arc::ptr_eq(&a, &b));
        let c = slots::<u32, u64>("jobs test");
        c.insert(1, 1, 9, Duration::ZERO);
        assert!(a.latest(1).is_none(), "another type is another store entry");
    }

    #[test]
    fn now_waits_for_the_job_computing_the_same_key() {
        let s: Arc<Slots<u32, u32>> = Arc::new(Slots::default());
        let gate = Arc::new(Mutex::new(()));
        let hold = gate.lock().unwrap();
        let g2 = gate.clone();
        s.request(
            1,
            5,
            once(move || {
                let _g = g2.lock();
                50
            }),
            &Waker::none(),
        );
        let s2 = s.clone();
        let figure = std::thread::spawn(move || s2.now(1, 5, once(|| 99)).value);
        std::thread::sleep(Duration::from_millis(20));
        drop(hold);
        assert_eq!(
            figure.join().unwrap(),
            50,
            "the job's value, not a second computation"
        );
        assert_eq!(s.computed(), 1);
    }

    #[test]
    fn a_key_computed_before_is_found_without_a_job() {
        let s: Arc<Slots<u32, u32>> = Arc::new(Slots::keeping(2));
        s.insert(1, 10, 100, Duration::ZERO);
        s.insert(1, 11, 110, Duration::ZERO);
        // Slot 1 shows key 11 now; key 10 is still remembered, also for
        // another slot, and asking for it starts nothing.
        let d = s
            .request(2, 10, once(|| panic!("no job")), &Waker::none())
            .unwrap();
        assert_eq!(d.value, 100);
        assert!(!s.busy(2));
        assert_eq!(s.get(1, &10).unwrap().value, 100);
        // The oldest of more than `keep` is forgotten.
        s.insert(3, 12, 120, Duration::ZERO);
        s.insert(3, 13, 130, Duration::ZERO);
        assert!(s.get(5, &10).is_none());
        assert_eq!(s.get(5, &13).unwrap().value, 130);
    }
}
