//! What differs between the desktop and the browser, in one place.
//!
//! A page compiled to `wasm32-unknown-unknown` has no threads, and its
//! `std::time::Instant` panics: the clock comes from the browser
//! (`performance.now()`, through `web-time`), and work that runs on a worker
//! thread on the desktop is queued and run between frames ([`spawn`],
//! [`spawn_steps`], [`run_pending`]). A long job is written as steps, each a
//! bounded slice of the work: the desktop's thread runs them in a loop; the
//! page runs them in turns of 50–250 ms scheduled as tasks of their own,
//! between which the browser handles input and draws frames, so the page
//! keeps drawing its progress indication and answering while a job runs. Everything else (the file system,
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

/// A job in steps, handed to [`spawn_steps`]: each call does a bounded slice
/// of the work and returns `true` once the job is finished (it hands its
/// result on itself, through a channel or a shared slot).
#[cfg(target_arch = "wasm32")]
type Steps = Box<dyn FnMut() -> bool + Send + 'static>;

/// Runs `job` off the UI: on a thread named `name` on the desktop; in the
/// browser, queued for [`run_pending`] (a page has no threads to spawn), where
/// it runs whole between two frames. Long work should use [`spawn_steps`].
/// The error is the operating system's refusal of a thread.
pub fn spawn(name: &str, job: impl FnOnce() + Send + 'static) -> std::io::Result<()> {
    let mut job = Some(job);
    spawn_steps(name, move || {
        if let Some(job) = job.take() {
            job();
        }
        true
    })
}

/// Runs `step` off the UI until it returns `true`: on the desktop in a loop
/// on a thread named `name`; in the browser in turns of [`run_pending`]
/// scheduled between the page's tasks, so that a job of many steps spans
/// many frames and the page keeps drawing (and answering) meanwhile. The
/// error is the operating system's refusal of a thread.
#[cfg(not(target_arch = "wasm32"))]
pub fn spawn_steps(
    name: &str,
    mut step: impl FnMut() -> bool + Send + 'static,
) -> std::io::Result<()> {
    std::thread::Builder::new()
        .name(name.to_string())
        .spawn(move || while !step() {})
        .map(|_| ())
}

/// Runs `step` off the UI until it returns `true`: on the desktop in a loop
/// on a thread named `name`; in the browser in turns of [`run_pending`]
/// scheduled between the page's tasks, so that a job of many steps spans
/// many frames and the page keeps drawing (and answering) meanwhile.
#[cfg(target_arch = "wasm32")]
pub fn spawn_steps(name: &str, step: impl FnMut() -> bool + Send + 'static) -> std::io::Result<()> {
    let _ = name;
    let mut q = queue();
    if q.is_empty() {
        web_sys::console::info_1(&"bv: background work started".into());
    }
    q.push_back(Box::new(step));
    drop(q);
    schedule_pump();
    Ok(())
}

/// How long one turn of the page's job pump runs steps before it yields to
/// the browser (which then handles input and draws a frame if one is due).
#[cfg(target_arch = "wasm32")]
const PUMP_SLICE: std::time::Duration = std::time::Duration::from_millis(50);

/// The longest turn of the pump, whatever the frames cost.
#[cfg(target_arch = "wasm32")]
const MAX_PUMP_SLICE: std::time::Duration = std::time::Duration::from_millis(250);

/// How long the page's last frame took to build, microseconds.
#[cfg(target_arch = "wasm32")]
static FRAME_COST_US: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// Tells the job pump how long the page's last frame took (its turns are
/// at least as long, up to a quarter of a second); nothing on the desktop.
pub fn set_frame_cost(cost: std::time::Duration) {
    #[cfg(target_arch = "wasm32")]
    FRAME_COST_US.store(
        u64::try_from(cost.as_micros()).unwrap_or(u64::MAX),
        std::sync::atomic::Ordering::Relaxed,
    );
    #[cfg(not(target_arch = "wasm32"))]
    let _ = cost;
}

/// Whether a turn of the pump is scheduled.
#[cfg(target_arch = "wasm32")]
static PUMP_SCHEDULED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Schedules a turn of the job pump as a task of its own (`setTimeout 0`),
/// unless one is scheduled. The pump runs outside the frames, so that the
/// jobs get the time the page does not spend drawing, and the page draws
/// only when something asks for a frame (a progress bar, input), not once
/// per slice of work.
#[cfg(target_arch = "wasm32")]
fn schedule_pump() {
    use std::sync::atomic::Ordering;
    use wasm_bindgen::JsCast as _;
    if PUMP_SCHEDULED.swap(true, Ordering::AcqRel) {
        return;
    }
    let turn = wasm_bindgen::closure::Closure::once_into_js(|| {
        PUMP_SCHEDULED.store(false, Ordering::Release);
        // At least as long as the page's last frame took to build: with
        // slow frames (a software renderer) the jobs still get half the time.
        let frame = std::time::Duration::from_micros(FRAME_COST_US.load(Ordering::Relaxed));
        if run_pending(frame.clamp(PUMP_SLICE, MAX_PUMP_SLICE)) {
            schedule_pump();
        } else {
            let (steps, longest) = take_step_stats();
            web_sys::console::info_1(
                &format!(
                    "bv: background work finished ({steps} steps, the longest {} ms)",
                    longest.as_millis()
                )
                .into(),
            );
        }
    });
    let scheduled = web_sys::window().is_some_and(|w| {
        w.set_timeout_with_callback_and_timeout_and_arguments_0(turn.unchecked_ref(), 0)
            .is_ok()
    });
    if !scheduled {
        // No timer: the frames' own calls of `run_pending` still run the jobs.
        PUMP_SCHEDULED.store(false, Ordering::Release);
    }
}

#[cfg(target_arch = "wasm32")]
fn queue() -> std::sync::MutexGuard<'static, std::collections::VecDeque<Steps>> {
    static QUEUE: std::sync::Mutex<std::collections::VecDeque<Steps>> =
        std::sync::Mutex::new(std::collections::VecDeque::new());
    // A job that panicked poisons nothing the queue relies on.
    QUEUE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Runs steps of the queued jobs, in turn, for about `budget` (at least one
/// step, if any job is queued) and says whether jobs are left (the caller
/// asks for another frame). On the desktop jobs run on threads and nothing
/// is ever queued.
pub fn run_pending(budget: std::time::Duration) -> bool {
    #[cfg(target_arch = "wasm32")]
    {
        let t0 = Instant::now();
        loop {
            // The lock is released while the step runs: a job may queue more.
            let Some(mut job) = queue().pop_front() else {
                return false;
            };
            let t = Instant::now();
            let finished = job();
            let took = t.elapsed();
            {
                let mut st = step_stats();
                st.0 += 1;
                st.1 = st.1.max(took);
            }
            if !finished {
                // Unfinished: to the back, so that jobs take turns.
                queue().push_back(job);
            }
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

#[cfg(target_arch = "wasm32")]
fn step_stats() -> std::sync::MutexGuard<'static, (u64, std::time::Duration)> {
    static STATS: std::sync::Mutex<(u64, std::time::Duration)> =
        std::sync::Mutex::new((0, std::time::Duration::ZERO));
    STATS.lock().unwrap_or_else(|e| e.into_inner())
}

/// The steps [`run_pending`] ran since the last call and the longest of
/// them (what a page reports when its background work is done); nothing on
/// the desktop.
pub fn take_step_stats() -> (u64, std::time::Duration) {
    #[cfg(target_arch = "wasm32")]
    {
        std::mem::take(&mut *step_stats())
    }
    #[cfg(not(target_arch = "wasm32"))]
    (0, std::time::Duration::ZERO)
}

/// How many jobs are queued for [`run_pending`] (always 0 on the desktop).
pub fn pending() -> usize {
    #[cfg(target_arch = "wasm32")]
    {
        queue().len()
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        0
    }
}

/// The media type of a file name's extension, for a download.
#[cfg(any(target_arch = "wasm32", test))]
fn media_type(name: &str) -> &'static str {
    let ext = name
        .rsplit_once('.')
        .map_or("", |(_, e)| e)
        .to_ascii_lowercase();
    match ext.as_str() {
        "png" => "image/png",
        "svg" => "image/svg+xml",
        "toml" => "application/toml",
        "obj" | "ply" => "model/obj",
        _ => "application/octet-stream",
    }
}

/// Offers `bytes` to the user as a download named `name`: what saving a file
/// is in a page (a Blob behind an object URL, clicked through an `<a
/// download>`). Logs `bv: downloaded NAME (N bytes)` to the console.
#[cfg(target_arch = "wasm32")]
pub fn download(name: &str, bytes: &[u8]) -> Result<(), String> {
    use wasm_bindgen::JsCast as _;
    let js = |e: wasm_bindgen::JsValue| format!("{e:?}");
    let parts = js_sys::Array::of1(&js_sys::Uint8Array::from(bytes));
    let options = web_sys::BlobPropertyBag::new();
    options.set_type(media_type(name));
    let blob =
        web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &options).map_err(js)?;
    let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(js)?;
    let anchor = web_sys::window()
        .and_then(|w| w.document())
        .ok_or("the page has no document")?
        .create_element("a")
        .map_err(js)?
        .dyn_into::<web_sys::HtmlAnchorElement>()
        .map_err(|_| "not an anchor".to_string())?;
    anchor.set_href(&url);
    anchor.set_download(name);
    anchor.click();
    // The click has started the download; the URL is not needed after it.
    web_sys::Url::revoke_object_url(&url).map_err(js)?;
    web_sys::console::info_1(&format!("bv: downloaded {name} ({} bytes)", bytes.len()).into());
    Ok(())
}

/// A file the user picked in the page's file chooser: its name and bytes, or
/// why they could not be read.
pub type Picked = (String, Result<Vec<u8>, String>);

/// The files picked and not yet taken, and what to wake when more arrive.
#[cfg(target_arch = "wasm32")]
type PickedFiles = (Vec<Picked>, Option<Box<dyn Fn() + Send>>);

#[cfg(target_arch = "wasm32")]
fn picked() -> std::sync::MutexGuard<'static, PickedFiles> {
    static PICKED: std::sync::Mutex<PickedFiles> = std::sync::Mutex::new((Vec::new(), None));
    PICKED.lock().unwrap_or_else(|e| e.into_inner())
}

/// Opens the browser's file chooser for files with `extensions` (without
/// the dot; several may be chosen); the files chosen are read and handed out
/// by [`take_picked`], and the waker set with [`set_picked_waker`] runs.
/// On the desktop nothing happens (its dialogs are drawn in the window).
pub fn pick_files(extensions: &[&str]) {
    #[cfg(target_arch = "wasm32")]
    {
        use wasm_bindgen::JsCast as _;
        use wasm_bindgen::closure::Closure;
        let Some(doc) = web_sys::window().and_then(|w| w.document()) else {
            return;
        };
        let Ok(input) = doc
            .create_element("input")
            .map(|e| e.unchecked_into::<web_sys::HtmlInputElement>())
        else {
            return;
        };
        input.set_type("file");
        input.set_multiple(true);
        let accept: Vec<String> = extensions.iter().map(|e| format!(".{e}")).collect();
        input.set_accept(&accept.join(","));
        let target = input.clone();
        let on_change = Closure::once_into_js(move || {
            let Some(files) = target.files() else { return };
            for k in 0..files.length() {
                let Some(file) = files.get(k) else { continue };
                wasm_bindgen_futures::spawn_local(async move {
                    let name = file.name();
                    let bytes = wasm_bindgen_futures::JsFuture::from(file.array_buffer())
                        .await
                        .map(|b| js_sys::Uint8Array::new(&b).to_vec())
                        .map_err(|e| format!("{e:?}"));
                    let mut g = picked();
                    g.0.push((name, bytes));
                    if let Some(wake) = &g.1 {
                        wake();
                    }
                });
            }
        });
        input.set_onchange(Some(on_change.unchecked_ref()));
        input.click();
        web_sys::console::info_1(&"bv: file chooser opened".into());
    }
    #[cfg(not(target_arch = "wasm32"))]
    let _ = extensions;
}

/// The files picked in the browser's file chooser since the last call.
pub fn take_picked() -> Vec<Picked> {
    #[cfg(target_arch = "wasm32")]
    {
        std::mem::take(&mut picked().0)
    }
    #[cfg(not(target_arch = "wasm32"))]
    Vec::new()
}

/// What runs when picked files are ready (a repaint request).
pub fn set_picked_waker(wake: impl Fn() + Send + 'static) {
    #[cfg(target_arch = "wasm32")]
    {
        picked().1 = Some(Box::new(wake));
    }
    #[cfg(not(target_arch = "wasm32"))]
    let _ = wake;
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

    #[test]
    fn downloads_get_the_media_type_of_their_extension() {
        assert_eq!(media_type("bv-window.PNG"), "image/png");
        assert_eq!(media_type("scene.toml"), "application/toml");
        assert_eq!(media_type("plot.svg"), "image/svg+xml");
        assert_eq!(media_type("noext"), "application/octet-stream");
    }

    #[test]
    fn a_stepped_job_runs_every_step_once_and_in_order() {
        let (tx, rx) = std::sync::mpsc::channel();
        let mut k = 0;
        spawn_steps("bv test", move || {
            k += 1;
            let _ = tx.send(k);
            k == 5
        })
        .unwrap();
        assert!(!run_pending(std::time::Duration::from_millis(1)));
        let got: Vec<i32> = rx.iter().collect();
        assert_eq!(got, [1, 2, 3, 4, 5]);
        assert_eq!(pending(), 0);
    }
}
