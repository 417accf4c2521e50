//! Figures written to files: the kind an output path names, PNGs of a view,
//! the window or a slide, SVGs of the 2D plots, lobe meshes, each written
//! atomically. `bv render` and the window's export dialog both write through
//! here, so a figure saved from either is the same file.

use super::{Frame, Offscreen, WindowUi};
use crate::session::state::AppState;
use crate::views::{REGISTRY, ViewEntry};
use anyhow::{Context as _, Result, bail};
use std::path::Path;

/// What an output file holds, by its extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A raster image.
    Png,
    /// A vector image (2D plots).
    Svg,
    /// Lobe meshes as Wavefront OBJ.
    Obj,
    /// The primary lobe mesh as PLY with colours.
    Ply,
}

impl Kind {
    /// The kind `path`'s extension names, in any case (`X.PNG` is a PNG: a
    /// folder of that name would surprise everyone).
    pub fn of(path: &Path) -> Option<Kind> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") => Some(Kind::Png),
            Some("svg") => Some(Kind::Svg),
            Some("obj") => Some(Kind::Obj),
            Some("ply") => Some(Kind::Ply),
            _ => None,
        }
    }
}

/// The views that have a vector form (the 2D plots).
pub fn svg_views() -> Vec<&'static ViewEntry> {
    REGISTRY
        .iter()
        .filter(|e| super::view_svg(&AppState::default(), e, [200.0, 150.0], false).is_some())
        .collect()
}

/// Draws view `e` of `state` offscreen and saves it as a PNG at `path`.
pub fn write_view_png(
    off: &mut Offscreen,
    state: &AppState,
    e: &ViewEntry,
    frame: Frame,
    path: &Path,
) -> Result<()> {
    let img = super::render_view(off, state, e, frame)
        .with_context(|| format!("drawing the {} view", e.id))?;
    save_png(&img, path)
}

/// Writes view `e` of `state` as an SVG of `size` points at `path`; a view
/// without a vector form is an error naming those that have one.
pub fn write_view_svg(
    state: &AppState,
    e: &ViewEntry,
    size: [f32; 2],
    transparent: bool,
    path: &Path,
) -> Result<()> {
    let Some(svg) = super::view_svg(state, e, size, transparent) else {
        let ids: Vec<&str> = svg_views().iter().map(|v| v.id).collect();
        bail!(
            "the {} view has no vector form; write a .png (SVG: {})",
            e.id,
            ids.join(", ")
        );
    };
    write_file(path, svg.as_bytes())
}

/// Writes the lobe meshes of `state`'s drawn BRDFs: all of them as OBJ, or
/// the primary one as PLY (`ply`). Returns how many meshes were written.
pub fn write_mesh(state: &AppState, ply: bool, path: &Path) -> Result<usize> {
    let meshes = super::mesh::lobe_meshes(state);
    let Some(first) = meshes.first() else {
        bail!("no BRDF is drawn: nothing to export");
    };
    let (text, n) = if ply {
        (super::mesh::to_ply(state, first), 1)
    } else {
        (super::mesh::to_obj(state, &meshes), meshes.len())
    };
    write_file(path, text.as_bytes())?;
    Ok(n)
}

/// Draws `window` (the whole window showing `state`: the viewer, a slide)
/// offscreen and saves it as a PNG at `path`; a blank image is an error
/// (something failed to draw without saying so).
pub fn write_window_png(
    off: &mut Offscreen,
    state: &AppState,
    frame: Frame,
    window: Box<dyn WindowUi>,
    path: &Path,
) -> Result<()> {
    let img = super::render_ui(off, state, frame, window)?;
    if is_blank(&img) {
        bail!("the image came out blank");
    }
    save_png(&img, path)
}

/// Saves a PNG, creating missing parent folders; written through a temporary
/// file so that a failed write leaves no half image behind.
pub fn save_png(img: &image::RgbaImage, path: &Path) -> Result<()> {
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .context("encoding the PNG")?;
    write_file(path, &bytes)
}

/// Writes a file atomically, creating missing parent folders. FIFOs,
/// devices, directories and read-only files are refused and a symlink is
/// written through to its target ([`bv_core::fsio::write_atomic`]); the
/// error names the file once and says why.
///
/// In a browser page the file becomes a download named by `path`'s file
/// name (the page has no file system to write to).
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    #[cfg(target_arch = "wasm32")]
    {
        let name = path
            .file_name()
            .map_or_else(|| "bv-figure".into(), |n| n.to_string_lossy().into_owned());
        crate::session::platform::download(&name, bytes)
            .map_err(|e| anyhow::anyhow!("the browser refused the download of {name}: {e}"))
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        bv_core::fsio::create_parent_dirs(path)?;
        bv_core::fsio::write_atomic(path, |f| f.write_all(bytes))?;
        Ok(())
    }
}

/// Whether an image has more than one colour (a blank render is one colour).
pub fn is_blank(img: &image::RgbaImage) -> bool {
    let mut px = img.pixels();
    match px.next() {
        Some(first) => px.all(|p| p == first),
        None => true,
    }
}
