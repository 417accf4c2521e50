//! Figures out of bv: the views drawn offscreen to PNG at any resolution
//! ([`offscreen`], [`render_view`], [`render_window`]), the 2D plots as SVG
//! ([`view_svg`], written by the views with `views::svg`), and lobe meshes as OBJ/PLY
//! ([`mesh`]). `bv render` and the viewer's screenshot dialog both go
//! through here, so a figure from the command line and one from the window
//! are drawn by the same code.

pub mod files;
pub mod mesh;
pub mod offscreen;

use crate::session::frame::figure_scene;
use crate::session::runtime::{self, Runtime};
use crate::session::state::{AppState, Theme};
use crate::views::ViewEntry;
use anyhow::{Context as _, Result, bail};
use eframe::egui;
pub use files::{is_blank, save_png, write_file};
pub use offscreen::{Frame, Offscreen, PendingFigure};
use std::path::Path;

/// Margin around a view in a figure, in points.
pub const FIGURE_MARGIN: f32 = 4.0;

/// Whether figures of `state` use the dark theme.
pub fn is_dark(state: &AppState) -> bool {
    state.theme == Theme::Dark
}

/// Fails when a drawn BRDF of `state` could not be built (a missing or
/// unreadable MERL file, a bad parameter in a scene): a figure without it
/// would be wrong, not merely incomplete.
pub fn check_brdfs(state: &AppState, runtime: &Runtime) -> Result<()> {
    for e in state.brdfs.iter().filter(|e| state.is_drawn(e)) {
        let name = crate::session::naming::display_name(state, e);
        match runtime.get(e.id) {
            Some(b) if b.brdf.is_some() => {}
            Some(b) => bail!(
                "BRDF {name}: {}",
                b.error.as_deref().unwrap_or("it could not be built")
            ),
            None => bail!("BRDF {name}: it could not be built"),
        }
    }
    Ok(())
}

/// Fails when evaluations of a drawn BRDF failed while the figure was
/// computed (a user's shader past its step budget): they read as 0, and a
/// figure of zeros would be wrong without saying so.
pub fn check_health(state: &AppState, runtime: &Runtime) -> Result<()> {
    for e in state.brdfs.iter().filter(|e| state.is_drawn(e)) {
        if let Some(b) = runtime.get(e.id).and_then(|b| b.brdf.as_ref())
            && let Some(err) = b.health().failure(b.id())
        {
            let name = crate::session::naming::display_name(state, e);
            bail!("BRDF {name}: {err}");
        }
    }
    Ok(())
}

/// A whole window's UI that figures can draw: the application hands one in
/// ([`MakeWindow`]), so that this module draws the window without knowing the
/// viewer.
pub trait WindowUi {
    /// Draws the whole window into `ui`.
    fn ui(&mut self, ui: &mut egui::Ui);
    /// An error one of its views showed in the last frame (a figure must not
    /// carry an error message in its pixels).
    fn error(&self) -> Option<String>;
}

/// Builds the window's UI showing `state`, drawn as a figure (slow work
/// finished before drawing, no hover readouts).
pub type MakeWindow = fn(&AppState) -> Box<dyn WindowUi>;

/// Builds the window's UI showing slide `index` of a deck in presentation
/// mode, drawn as a figure.
pub type MakeSlide = fn(&crate::session::deck::Deck, usize) -> Box<dyn WindowUi>;

/// Draws one view of `state` alone, filling a `frame.size` image (no title
/// bar or toolbar, no hover readouts). Fails, rather than drawing an
/// incomplete figure, when a drawn BRDF could not be built or the view met
/// an error (see [`check_brdfs`]).
pub fn render_view(
    off: &mut Offscreen,
    state: &AppState,
    entry: &ViewEntry,
    frame: Frame,
) -> Result<image::RgbaImage> {
    start_view(off, state, entry, frame)?.wait()
}

/// [`render_view`] without waiting for the image to be read back (a browser
/// page takes it in a later frame).
pub fn start_view(
    off: &mut Offscreen,
    state: &AppState,
    entry: &ViewEntry,
    frame: Frame,
) -> Result<PendingFigure> {
    let mut runtime = runtime::shared();
    runtime.sync(state);
    check_brdfs(state, &runtime)?;
    let mut view = (entry.make)();
    // A figure does not carry a note in its pixels: a light below the
    // surface with only reflecting models is an error here (issue 33).
    if !view.shows_light_below()
        && let Some(note) =
            crate::views::light_below_note(&figure_scene(state, &runtime, frame.transparent))
    {
        bail!("{} view: {note}", entry.id);
    }
    let img = off.start_render(frame, |ui| {
        let scene = figure_scene(state, &runtime, frame.transparent);
        // No fill: the image is cleared to the panels' colour
        // (`Offscreen::start_render`).
        if state.display.caption {
            egui::Panel::bottom("bv figure caption")
                .frame(egui::Frame::NONE.inner_margin(FIGURE_MARGIN))
                .show_separator_line(false)
                .show(ui, |ui| {
                    ui.label(
                        egui::RichText::new(crate::session::naming::figure_caption(state))
                            .color(crate::views::strong_text(ui)),
                    );
                });
        }
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE.inner_margin(FIGURE_MARGIN))
            .show(ui, |ui| {
                let mut ignored = Vec::new();
                view.ui(ui, &scene, &mut ignored);
            });
    })?;
    if let Some(e) = view.figure_error() {
        bail!("{e}");
    }
    check_health(state, &runtime)?;
    Ok(img)
}

/// Draws the whole viewer window showing `state`, as `make` builds it.
pub fn render_window(
    off: &mut Offscreen,
    state: &AppState,
    frame: Frame,
    make: MakeWindow,
) -> Result<image::RgbaImage> {
    render_ui(off, state, frame, make(state))
}

/// [`render_window`] without waiting for the image to be read back (a
/// browser page takes it in a later frame).
pub fn start_window(
    off: &mut Offscreen,
    state: &AppState,
    frame: Frame,
    make: MakeWindow,
) -> Result<PendingFigure> {
    start_ui(off, state, frame, make(state))
}

/// Draws `window`, a whole window's UI showing `state` (a slide of a deck,
/// the viewer), after the checks and slow work [`render_window`] does.
pub fn render_ui(
    off: &mut Offscreen,
    state: &AppState,
    frame: Frame,
    window: Box<dyn WindowUi>,
) -> Result<image::RgbaImage> {
    start_ui(off, state, frame, window)?.wait()
}

/// [`render_ui`] without waiting for the image to be read back.
pub fn start_ui(
    off: &mut Offscreen,
    state: &AppState,
    frame: Frame,
    mut window: Box<dyn WindowUi>,
) -> Result<PendingFigure> {
    // The window's albedo view computes in the background; a figure shows
    // the finished curves, so compute them first (they are cached).
    {
        let mut runtime = runtime::shared();
        runtime.sync(state);
        check_brdfs(state, &runtime)?;
        // The window may show the environment view too small to draw, but
        // a scene naming a map that cannot be read is wrong all the same.
        if let Some(map) = &state.lighting.env.map {
            crate::gpu::EnvironmentMap::load(Path::new(map))
                .with_context(|| "the scene's environment map")?;
        }
        let scene = figure_scene(state, &runtime, false);
        for b in scene
            .brdfs
            .iter()
            .filter(|b| crate::derive::albedo::drawn(&scene, b))
        {
            crate::derive::albedo::curve_now(&scene, b);
        }
        check_health(state, &runtime)?;
    }
    let img = off.start_render(frame, |ui| window.ui(ui))?;
    if let Some(e) = window.error() {
        bail!("{e}");
    }
    Ok(img)
}

/// One view of `state` as SVG (`None` if the view has no vector form).
pub fn view_svg(
    state: &AppState,
    entry: &ViewEntry,
    size: [f32; 2],
    transparent: bool,
) -> Option<String> {
    let mut runtime = runtime::shared();
    runtime.sync(state);
    let scene = figure_scene(state, &runtime, transparent);
    let mut view = (entry.make)();
    // Nothing to draw with the light below and only reflecting models (the
    // PNG of the same view reports why).
    if !view.shows_light_below() && crate::views::light_below_note(&scene).is_some() {
        return None;
    }
    view.svg(&scene, size, is_dark(state))
}
