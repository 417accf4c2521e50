//! GPU errors as values. wgpu reports a validation or out-of-memory error
//! (a buffer over the device's limit, a texture too large) not as a `Result`
//! but to an error scope, or, when no scope captures it, to the device's
//! uncaptured-error handler, whose default panics. bv never lets it panic:
//!
//! - [`scoped`] runs GPU work inside validation, out-of-memory and internal
//!   error scopes and turns what they capture into an `Err` (every headless
//!   and offscreen path goes through it);
//! - [`watch`] installs an uncaptured-error handler on a device (every device
//!   bv opens or is handed by eframe) that records the error in an
//!   [`ErrorLog`] instead of panicking; a caller compares the log's count
//!   before and after its work ([`ErrorLog::since`]).
//!
//! Limits of a device are checked before a resource is made
//! ([`check_buffer`], [`check_texture`]), so that the message names the size
//! asked for and the limit rather than wgpu's internal wording.
//!
//! [`no_gpu_message`] is what a user is told when no adapter can be opened
//! (by the window or by a headless device).

use anyhow::{Result, bail};
use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::sync::{Arc, Mutex, OnceLock};

/// What the handler of one device has recorded.
#[derive(Debug, Default)]
struct Log {
    count: u64,
    last: Option<String>,
}

/// The uncaptured errors of one device (shared by every clone of the device
/// and every [`watch`] of it).
#[derive(Debug, Clone, Default)]
pub struct ErrorLog {
    inner: Arc<Mutex<Log>>,
}

impl ErrorLog {
    /// How many uncaptured errors the device has reported so far.
    pub fn count(&self) -> u64 {
        self.inner.lock().map_or(0, |l| l.count)
    }

    /// The last uncaptured error, if any arrived after the log stood at
    /// `count` (see [`ErrorLog::count`]).
    pub fn since(&self, count: u64) -> Option<String> {
        let l = self.inner.lock().ok()?;
        if l.count > count {
            l.last.clone()
        } else {
            None
        }
    }

    fn record(&self, message: String) {
        if let Ok(mut l) = self.inner.lock() {
            l.count += 1;
            l.last = Some(message);
        }
    }
}

/// Logs by device: keyed by the device's hash (its identity, not a clone of
/// it, so that the registry keeps no device alive).
fn registry() -> &'static Mutex<HashMap<u64, ErrorLog>> {
    static LOGS: OnceLock<Mutex<HashMap<u64, ErrorLog>>> = OnceLock::new();
    LOGS.get_or_init(Default::default)
}

fn device_key(device: &wgpu::Device) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    device.hash(&mut h);
    h.finish()
}

/// Installs on `device` an uncaptured-error handler that records errors in
/// the returned log instead of panicking (wgpu's default). Calling it again
/// for the same device re-installs the handler and returns the same log, so
/// the GUI and an offscreen renderer sharing its device see one log.
pub fn watch(device: &wgpu::Device) -> ErrorLog {
    let key = device_key(device);
    let log = match registry().lock() {
        Ok(mut m) => m.entry(key).or_default().clone(),
        // A panic elsewhere while holding the lock: a log of our own still
        // keeps the handler from panicking.
        Err(_) => ErrorLog::default(),
    };
    let sink = log.clone();
    device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
        sink.record(describe(&e));
    }));
    log
}

/// One line for a wgpu error: its description with the "Caused by" chain
/// folded onto the line (wgpu's text spans several indented lines).
pub fn describe(e: &wgpu::Error) -> String {
    let text = match e {
        wgpu::Error::OutOfMemory { source } => format!("out of GPU memory ({source})"),
        other => other.to_string(),
    };
    let parts: Vec<&str> = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && *l != "Caused by:")
        .collect();
    parts.join(": ")
}

/// Runs `work` inside out-of-memory, validation and internal error scopes of
/// `device` and returns its result, or an error naming `what` if wgpu
/// reported one meanwhile (a captured error wins over `work`'s own result:
/// the work's output is not to be trusted then).
///
/// Scopes are per thread: the GPU calls must be made by `work` on this
/// thread.
#[cfg(not(target_arch = "wasm32"))]
pub fn scoped<T>(device: &wgpu::Device, what: &str, work: impl FnOnce() -> Result<T>) -> Result<T> {
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let internal = device.push_error_scope(wgpu::ErrorFilter::Internal);
    let result = work();
    // Popped in reverse order of pushing.
    let errors = [
        pollster::block_on(internal.pop()),
        pollster::block_on(validation.pop()),
        pollster::block_on(oom.pop()),
    ];
    if let Some(e) = errors.into_iter().flatten().next() {
        return Err(anyhow::anyhow!("{what}: GPU error: {}", describe(&e)));
    }
    result
}

/// Runs `work`. In a browser an error scope's answer is a promise that only
/// settles once this frame has returned to the page, so it cannot be waited
/// for here: errors reach the device's uncaptured-error handler ([`watch`])
/// instead, which records them for the views to show.
#[cfg(target_arch = "wasm32")]
pub fn scoped<T>(device: &wgpu::Device, what: &str, work: impl FnOnce() -> Result<T>) -> Result<T> {
    let _ = (device, what);
    work()
}

/// What to tell a user whose machine has no GPU adapter wgpu can use.
pub fn no_gpu_message(detail: &str) -> String {
    format!(
        "no graphics adapter found ({detail}).\n\
         bv draws with wgpu (Vulkan, Metal, DirectX 12 or OpenGL). On a Linux machine without a GPU driver,\n\
         install Mesa's software Vulkan driver (lavapipe) and the Vulkan loader, then start bv again:\n\
         \x20   Debian/Ubuntu: sudo apt install mesa-vulkan-drivers libvulkan1\n\
         \x20   Fedora:        sudo dnf install mesa-vulkan-drivers vulkan-loader\n\
         \x20   Arch:          sudo pacman -S vulkan-swrast\n\
         WGPU_BACKEND=gl tries OpenGL instead. The command-line tools (`bv eval`, `bv check`, …) need no GPU."
    )
}

const MIB: f64 = 1024.0 * 1024.0;

/// Checks that a buffer of `bytes` fits `device`'s limits (a buffer bound
/// as storage also checks the binding limit); `what` names it for the user,
/// `hint` says what to change.
pub fn check_buffer(
    device: &wgpu::Device,
    what: &str,
    bytes: u64,
    storage: bool,
    hint: &str,
) -> Result<()> {
    let l = device.limits();
    let max = if storage {
        l.max_buffer_size.min(l.max_storage_buffer_binding_size)
    } else {
        l.max_buffer_size
    };
    if bytes > max {
        bail!(
            "{what} needs {:.1} MiB, this device allows at most {:.1} MiB{}{hint}",
            bytes as f64 / MIB,
            max as f64 / MIB,
            if hint.is_empty() { "" } else { "; " }
        );
    }
    Ok(())
}

/// Checks a `width`×`height` 2D texture against `device`'s largest side.
pub fn check_texture(device: &wgpu::Device, what: &str, width: u32, height: u32) -> Result<()> {
    let max = device.limits().max_texture_dimension_2d;
    if width == 0 || height == 0 {
        bail!("{what}: an image of {width}×{height} pixels is empty");
    }
    if width > max || height > max {
        bail!(
            "{what} of {width}×{height} pixels: this device allows at most {max} pixels on a side"
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn descriptions_fold_onto_one_line() {
        let e = wgpu::Error::Validation {
            source: "x".into(),
            description:
                "Validation Error\n\nCaused by:\n  In Device::create_buffer, label = 'a'\n    \
                          Buffer size 9 is greater than the maximum buffer size (8)\n"
                    .into(),
        };
        assert_eq!(
            super::describe(&e),
            "Validation Error: In Device::create_buffer, label = 'a': Buffer size 9 is greater \
             than the maximum buffer size (8)"
        );
    }
}
