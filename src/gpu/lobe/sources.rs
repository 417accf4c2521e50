//! The lobe's shaders (`lobe`, `lines`, `blit`) as WGSL, composed once per
//! process and, where threads exist, while the device is being opened.
//!
//! Composing them (naga_oil parses and validates the colour map module and
//! the three entries, then writes each back to WGSL) took about 8 ms of a
//! headless figure's start on a 2-core Xeon, after the device was open.
//! Opening the device took about 30 ms on the same machine, most of it the
//! Vulkan loader loading every installed driver, on one core. Composition
//! needs no device, so [`compose_in_background`] starts it on another
//! thread before the device is opened, and [`sources`] takes the result.
//! The three import only the colour map (`tests/shader_validation.rs`:
//! `the_lobe_shaders_leave_the_model_ports_unregistered`), never a model's
//! port, so a model registered later changes nothing of them and one
//! composition serves the whole process.

use crate::gpu::shaders::ShaderLibrary;
use anyhow::{Result, anyhow};
use std::sync::OnceLock;

/// The WGSL of the lobe renderer's entry shaders.
#[derive(Debug)]
pub(super) struct LobeSources {
    /// The mesh shader (`shaders/lobe.wgsl` with the colour map).
    pub(super) lobe: String,
    /// The screen-space lines (`shaders/lines.wgsl`).
    pub(super) lines: String,
    /// The copies into the pass (`shaders/blit.wgsl`: plain and FXAA).
    pub(super) blit: String,
}

/// The composed sources, or the composition's error as text (an
/// `anyhow::Error` is not `Sync`-cloneable into every caller).
static SOURCES: OnceLock<std::result::Result<LobeSources, String>> = OnceLock::new();

/// The lobe's shaders, composed on first call; a caller that arrives while
/// another thread composes waits for it.
pub(super) fn sources() -> Result<&'static LobeSources> {
    SOURCES
        .get_or_init(|| compose().map_err(|e| format!("{e:#}")))
        .as_ref()
        .map_err(|e| anyhow!("composing the lobe's shaders: {e}"))
}

fn compose() -> Result<LobeSources> {
    let mut library = ShaderLibrary::new()?;
    Ok(LobeSources {
        lobe: library.wgsl("lobe")?,
        lines: library.wgsl("lines")?,
        blit: library.wgsl("blit")?,
    })
}

/// Starts composing the lobe's shaders on a thread of their own, so that
/// the work overlaps the opening of a device; [`sources`] then waits for it
/// if it is not done. In a browser (no threads) this does nothing and the
/// first renderer composes them. A thread that cannot be spawned is no
/// error either: the shaders are then composed when first needed.
pub fn compose_in_background() {
    #[cfg(not(target_arch = "wasm32"))]
    {
        let spawned = std::thread::Builder::new()
            .name("bv lobe shaders".to_string())
            .spawn(|| {
                let _ = sources();
            });
        drop(spawned);
    }
}
