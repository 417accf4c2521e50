//! Figures out of bv (issue 6): the views drawn offscreen to PNG at any
//! resolution ([`offscreen`], [`render_view`], [`render_window`]), the 2D
//! plots as SVG ([`svg`], [`view_svg`]), and lobe meshes as OBJ/PLY
//! ([`mesh`]). `bv render` and the viewer's screenshot dialog both go
//! through here, so a figure from the command line and one from the window
//! are drawn by the same code.

pub mod mesh;
pub mod offscreen;
pub mod svg;

use crate::app::runtime::Runtime;
use crate::app::state::{AppState, Theme};
use crate::app::viewer::{Viewer, build_scene};
use crate::views::{Scene, ViewEntry};
use anyhow::{Context as _, Result};
use eframe::egui;
pub use offscreen::{Frame, Offscreen};
use std::path::Path;

/// Margin around a view in a figure, in points.
pub const FIGURE_MARGIN: f32 = 4.0;

/// The scene of a figure: the state's drawn BRDFs, not interacting.
fn figure_scene<'a>(state: &'a AppState, runtime: &Runtime, transparent: bool) -> Scene<'a> {
    let mut scene = build_scene(state, runtime, false);
    scene.figure = true;
    scene.transparent = transparent;
    scene
}

/// Whether figures of `state` use the dark theme.
pub fn is_dark(state: &AppState) -> bool {
    state.theme == Theme::Dark
}

/// Draws one view of `state` alone, filling a `frame.size` image (no title
/// bar or toolbar, no hover readouts).
pub fn render_view(
    off: &mut Offscreen,
    state: &AppState,
    entry: &ViewEntry,
    frame: Frame,
) -> Result<image::RgbaImage> {
    let mut runtime = Runtime::default();
    runtime.sync(state);
    let mut view = (entry.make)();
    off.render(frame, |ui| {
        let scene = figure_scene(state, &runtime, frame.transparent);
        let fill = if frame.transparent {
            egui::Color32::TRANSPARENT
        } else {
            ui.visuals().panel_fill
        };
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE.fill(fill).inner_margin(FIGURE_MARGIN))
            .show(ui, |ui| {
                let mut ignored = Vec::new();
                view.ui(ui, &scene, &mut ignored);
            });
    })
}

/// Draws the whole viewer window showing `state`.
pub fn render_window(
    off: &mut Offscreen,
    state: &AppState,
    frame: Frame,
) -> Result<image::RgbaImage> {
    // The window's albedo view computes in the background; a figure shows
    // the finished curves, so compute them first (they are cached).
    {
        let mut runtime = Runtime::default();
        runtime.sync(state);
        let scene = figure_scene(state, &runtime, false);
        for b in &scene.brdfs {
            crate::views::albedo::curve_now(&scene, b);
        }
    }
    let mut viewer = Viewer::new(state.clone());
    viewer.figure = true;
    off.render(frame, |ui| viewer.ui(ui))
}

/// One view of `state` as SVG (`None` if the view has no vector form).
pub fn view_svg(
    state: &AppState,
    entry: &ViewEntry,
    size: [f32; 2],
    transparent: bool,
) -> Option<String> {
    let mut runtime = Runtime::default();
    runtime.sync(state);
    let scene = figure_scene(state, &runtime, transparent);
    let mut view = (entry.make)();
    view.svg(&scene, size, is_dark(state))
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
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    bv_core::fsio::create_parent_dirs(path)?;
    bv_core::fsio::write_atomic(path, |f| f.write_all(bytes))?;
    Ok(())
}

/// Whether an image has more than one colour (a blank render is one colour).
pub fn is_blank(img: &image::RgbaImage) -> bool {
    let mut px = img.pixels();
    match px.next() {
        Some(first) => px.all(|p| p == first),
        None => true,
    }
}
