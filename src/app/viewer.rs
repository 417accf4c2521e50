//! The whole viewer UI as one value with a `ui()` method, so that the same
//! code runs in eframe's window, in kittest harnesses and in scripted drivers.
//!
//! A frame: rebuild the evaluators whose specs changed, build the [`Scene`],
//! lay out the panels and the views (which push [`Command`]s), handle
//! shortcuts, then apply the commands.

use super::measured_ui;
use super::panel;
use super::presentation::{self, DeckSession, Presenter, StripAction};
use super::screenshot::{self, ExportUi, Request, ScreenGeometry};
use super::shortcuts::{self, Action};
use crate::session::build_scene;
use crate::session::command::Command;
use crate::session::deck::{self, DeckError};
use crate::session::loader::{LoadError, Loader};
use crate::session::runtime::Runtime;
use crate::session::scene_file as scene;
use crate::session::state::{AppState, Theme};
use crate::session::workspace::{Asks, Workspace};
use crate::views::{REGISTRY, Scene, View, ViewEntry};
use crate::widgets::files::Files;
use eframe::egui::{self, Rect, RichText, Ui, UiBuilder, Vec2};
use std::path::Path;

/// Mouse gestures, as shown in the help overlay.
pub const GESTURES: &[(&str, &str)] = &[
    ("drag (lobe)", "orbit the camera"),
    ("scroll (lobe)", "zoom"),
    ("shift + drag (lobe)", "move the light"),
    ("double-click (lobe)", "reset the camera"),
    ("drag (light disc)", "move the light"),
    (
        "drag (lit sphere)",
        "move the light to the point under the pointer",
    ),
    ("drop a .hdr / .exr file", "use it as the environment"),
    ("double-click (slider)", "reset the value to its default"),
    ("drag / scroll (plots)", "pan / zoom; double-click to fit"),
];

/// The viewer.
pub struct Viewer {
    /// The live session: state, evaluators, waiting commands, reads.
    ws: Workspace,
    views: Vec<(&'static ViewEntry, Box<dyn View>)>,
    help: bool,
    applied_look: Option<(Theme, bool)>,
    present: Presenter,
    deck: Option<DeckSession>,
    files: Files<()>,
    /// Treat the frame as if a pointer button were held (scripted drags).
    pub force_interacting: bool,
    /// Draw as a figure (a screenshot of the window): views finish slow work
    /// (renderer builds, environment sampling) before drawing.
    pub figure: bool,
    /// Scene files, figure export and toasts.
    pub export: ExportUi,
    /// The *Fit…* panel.
    pub fit: super::fit_ui::FitPanel,
    /// The window is cleared to the panels' colour (`Visuals::panel_fill`), so
    /// the panels are drawn without a fill of their own. Why: a software
    /// renderer (lavapipe) shades every pixel of every filled shape, and
    /// one window-sized fill under the views cost a quarter of a frame
    /// (80 against 61 ms at 1280×800); a clear is a memset. Off where the
    /// target is cleared to something else (offscreen figures of the window).
    pub panels_on_clear: bool,
}

impl Viewer {
    /// A viewer showing `state`.
    pub fn new(state: AppState) -> Self {
        Self {
            ws: Workspace::new(state),
            views: REGISTRY.iter().map(|e| (e, (e.make)())).collect(),
            help: false,
            applied_look: None,
            present: Presenter::default(),
            deck: None,
            files: Files::default(),
            force_interacting: false,
            figure: false,
            export: ExportUi::default(),
            fit: Default::default(),
            panels_on_clear: false,
        }
    }

    /// The frame of a panel: `frame` itself, or without its fill when the
    /// window is cleared to it ([`Self::panels_on_clear`]).
    fn panel_frame(&self, frame: egui::Frame) -> egui::Frame {
        if self.panels_on_clear {
            frame.fill(egui::Color32::TRANSPARENT)
        } else {
            frame
        }
    }

    /// Replaces the whole state (a scene was opened).
    pub fn replace_state(&mut self, state: AppState) {
        self.ws.replace_state(state);
    }

    /// Opens a scene file; returns its warnings. On error the state is
    /// unchanged.
    pub fn open_scene(&mut self, path: &Path) -> Result<Vec<String>, scene::SceneError> {
        // A BRDF whose table is missing opens with a warning (its panel
        // shows the error) rather than refusing the user's whole scene.
        let loaded = scene::load_with(path, scene::Builds::Warn)?;
        // Keep the theme the user chose for the window.
        let theme = self.ws.state.theme;
        self.replace_state(AppState {
            theme,
            ..loaded.state
        });
        self.export.scene_path = Some(path.to_path_buf());
        Ok(loaded.warnings)
    }

    /// Saves the state as a scene file (atomically).
    pub fn save_scene(&mut self, path: &Path) -> Result<(), scene::SceneError> {
        scene::save(path, &self.ws.state)?;
        self.export.scene_path = Some(path.to_path_buf());
        Ok(())
    }

    /// Whether the window is in presentation mode.
    pub fn presenting(&self) -> bool {
        self.present.on
    }

    /// Enters or leaves presentation mode: the left panel collapses, one
    /// view (the maximised one, or the first) fills the window, text and
    /// lines grow (see `session::presentation`), and the arrow keys step the
    /// deck or the views.
    pub fn set_presenting(&mut self, on: bool) {
        if on == self.present.on {
            return;
        }
        if on {
            self.present.maximised_before = Some(self.ws.state.maximised.clone());
            self.present.controls = false;
            if self.ws.state.maximised.is_none() {
                self.ws.state.maximised = REGISTRY.first().map(|e| e.id.to_string());
            }
        } else if self.deck.is_none()
            && let Some(m) = self.present.maximised_before.take()
        {
            self.ws.state.maximised = m;
        }
        self.present.on = on;
    }

    /// The open deck, if any.
    pub fn deck(&self) -> Option<&DeckSession> {
        self.deck.as_ref()
    }

    /// Opens a deck file at its first slide, in presentation mode; returns
    /// its warnings. On error nothing changes.
    pub fn open_deck(&mut self, path: &Path) -> Result<Vec<String>, DeckError> {
        let loaded = deck::load(path, scene::Builds::Warn)?;
        self.set_deck(loaded.deck, Some(path.to_path_buf()), 0);
        Ok(loaded.warnings)
    }

    /// Shows `deck` at slide `index` in presentation mode; `path` is where
    /// Ctrl+S saves it.
    pub fn set_deck(&mut self, deck: deck::Deck, path: Option<std::path::PathBuf>, index: usize) {
        if deck.slides.is_empty() {
            return;
        }
        self.deck = Some(DeckSession {
            deck,
            path,
            index: 0,
        });
        self.set_presenting(true);
        self.load_slide(index);
    }

    /// Shows slide `index` of the open deck (clamped to the deck), keeping
    /// the edits made to the current one.
    pub fn go_to_slide(&mut self, index: usize) {
        self.store_slide();
        self.load_slide(index);
    }

    /// Writes the viewer's state back into the current slide (the view shown
    /// becomes the slide's view; the slide keeps its own theme).
    fn store_slide(&mut self) {
        let Some(d) = &mut self.deck else { return };
        let Some(slide) = d.deck.slides.get_mut(d.index) else {
            return;
        };
        if let Some(v) = &self.ws.state.maximised {
            slide.view = v.clone();
        }
        let theme = slide.state.theme;
        slide.state = AppState {
            theme,
            maximised: Some(slide.view.clone()),
            ..self.ws.state.clone()
        };
    }

    fn load_slide(&mut self, index: usize) {
        let Some(d) = &mut self.deck else { return };
        let index = index.min(d.deck.slides.len().saturating_sub(1));
        d.index = index;
        let Some(slide) = d.deck.slides.get(index) else {
            return;
        };
        // The window keeps the theme the lecturer chose for the room.
        let theme = if self.applied_look.is_some() {
            self.ws.state.theme
        } else {
            slide.state.theme
        };
        let state = AppState {
            theme,
            maximised: Some(slide.view.clone()),
            ..slide.state.clone()
        };
        self.replace_state(state);
    }

    /// Steps the deck by `delta` slides, or (without a deck) the shown view
    /// through the registry.
    pub fn step(&mut self, delta: i32) {
        if let Some(d) = &self.deck {
            let n = d.deck.slides.len() as i64;
            let to = (d.index as i64 + i64::from(delta)).clamp(0, n - 1);
            self.go_to_slide(to as usize);
            return;
        }
        let n = REGISTRY.len() as i64;
        if n == 0 {
            return;
        }
        let at = self
            .ws
            .state
            .maximised
            .as_deref()
            .and_then(|m| REGISTRY.iter().position(|e| e.id == m))
            .unwrap_or(0) as i64;
        let to = (at + i64::from(delta)).rem_euclid(n) as usize;
        self.ws.state.maximised = Some(REGISTRY[to].id.to_string());
    }

    /// Jumps to the first (`last = false`) or last slide, or view.
    fn jump(&mut self, last: bool) {
        if let Some(d) = &self.deck {
            let to = if last { d.deck.slides.len() } else { 0 };
            self.go_to_slide(to);
        } else {
            let e = if last {
                REGISTRY.last()
            } else {
                REGISTRY.first()
            };
            self.ws.state.maximised = e.map(|e| e.id.to_string());
        }
    }

    /// Saves the open deck to its file, with the current slide's edits (and
    /// the scene files of `file` entries that changed).
    pub fn save_deck(&mut self) -> Result<std::path::PathBuf, DeckError> {
        self.store_slide();
        let Some(d) = &mut self.deck else {
            return Err(DeckError::Syntax("no deck is open".into()));
        };
        let Some(path) = d.path.clone() else {
            return Err(DeckError::Syntax("this deck has no file to save to".into()));
        };
        deck::save(&path, &mut d.deck)?;
        Ok(path)
    }

    /// Sets the window's zoom for presentation mode from its size in pixels
    /// (again when the window is resized), and gives the old zoom back
    /// after. Figures are drawn at the scale their frame gives instead.
    fn sync_zoom(&mut self, ctx: &egui::Context) {
        if self.figure {
            return;
        }
        if self.present.on {
            let px = ctx.content_rect().size() * ctx.pixels_per_point();
            if self
                .present
                .zoom_pixels
                .is_none_or(|p| (p - px).length() > 4.0)
            {
                let native = ctx.native_pixels_per_point().unwrap_or(1.0).max(0.1);
                self.present.zoom_before.get_or_insert(ctx.zoom_factor());
                ctx.set_zoom_factor(crate::session::presentation::scale_for([px.x, px.y]) / native);
                self.present.zoom_pixels = Some(px);
                ctx.request_repaint();
            }
        } else if let Some(z) = self.present.zoom_before.take() {
            ctx.set_zoom_factor(z);
            self.present.zoom_pixels = None;
            ctx.request_repaint();
        }
    }

    fn strip_action(&mut self, a: StripAction) {
        match a {
            StripAction::Step(d) => self.step(d),
            StripAction::View(id) => self.ws.state.maximised = Some(id.to_string()),
            StripAction::ToggleControls => self.present.controls = !self.present.controls,
            StripAction::Exit => self.set_presenting(false),
        }
    }

    fn handle(&mut self, r: Request, ctx: &egui::Context) {
        match r {
            Request::OpenScene(path) => match self.open_scene(&path) {
                Ok(w) => {
                    let line = screenshot::warnings_line(&path, &w);
                    if !w.is_empty() {
                        self.ws.status = Some(line.clone());
                    }
                    self.export.toast(line, false);
                }
                Err(e) => {
                    let msg = format!("Could not open {}: {e}", path.display());
                    self.ws.status = Some(msg.clone());
                    self.export.toast(msg, true);
                }
            },
            Request::SaveScene(path) => match self.save_scene(&path) {
                Ok(()) => self
                    .export
                    .toast(format!("Saved the scene to {}", path.display()), false),
                Err(e) => {
                    let msg = format!("Could not save the scene: {e}");
                    self.ws.status = Some(msg.clone());
                    self.export.toast(msg, true);
                }
            },
            Request::Figure(settings, path) => {
                let geometry = ScreenGeometry {
                    window: ctx.content_rect().size(),
                    pixels_per_point: ctx.pixels_per_point(),
                };
                let view_size = match &settings.target {
                    screenshot::Target::View(id) => view_rect(ctx, id).map(|r| r.size()),
                    screenshot::Target::Window => None,
                };
                match self.export.export_figure(
                    &self.ws.state,
                    &settings,
                    &path,
                    geometry,
                    view_size,
                    figure_window,
                ) {
                    Ok(line) => self.export.toast(line, false),
                    Err(e) => self
                        .export
                        .toast(format!("Could not export the figure: {e:#}"), true),
                }
            }
        }
    }

    /// The background reads of measured tables.
    pub fn loader(&self) -> &Loader {
        &self.ws.loader
    }

    /// Files that could not be opened, oldest first (the error dialog shows
    /// the first until it is dismissed).
    pub fn load_errors(&self) -> &[LoadError] {
        &self.ws.load_errors
    }

    /// Whether the file dialog is open.
    pub fn dialog_open(&self) -> bool {
        self.files.is_open()
    }

    /// Applies the reads that have finished (see
    /// [`Workspace::finish_loads`]).
    fn finish_loads(&mut self) {
        let asks = self.ws.finish_loads();
        self.answer(asks);
    }

    /// Waits (up to `timeout`) for the background reads and applies them; for
    /// tests and scripted drivers. Returns whether all finished.
    pub fn wait_for_loads(&mut self, timeout: std::time::Duration) -> bool {
        let ok = self.ws.loader.wait(timeout);
        self.finish_loads();
        ok
    }

    /// The current state (what is saved).
    pub fn state(&self) -> &AppState {
        &self.ws.state
    }

    /// Queues a command, applied at the start of the next frame.
    pub fn push(&mut self, c: Command) {
        self.ws.push(c);
    }

    /// Applies the queued commands now.
    pub fn apply_pending(&mut self) {
        let asks = self.ws.apply_pending();
        self.answer(asks);
    }

    /// The view of concrete type `T`, if registered.
    pub fn view<T: View>(&self) -> Option<&T> {
        self.views
            .iter()
            .find_map(|(_, v)| v.as_any().downcast_ref::<T>())
    }

    /// Whether a rendered view shown in the last frame is still working
    /// (building its renderer, or the environment view sampling towards its
    /// target): screenshots wait for them.
    pub fn views_busy(&self) -> bool {
        self.shown_busy().next().is_some()
    }

    /// The ids of the shown views whose last frame left work to do (in the
    /// layout's order): what [`Self::views_busy`] waits for, named.
    pub fn busy_views(&self) -> Vec<&'static str> {
        self.shown_busy().collect()
    }

    /// The shown views at work, lazily (so that [`Self::views_busy`], asked
    /// every frame of a screenshot's wait, allocates nothing).
    fn shown_busy(&self) -> impl Iterator<Item = &'static str> + '_ {
        // A view is hidden by another one being maximised, or by being
        // outside the overview grid.
        let maximised = self.ws.state.maximised.as_deref();
        self.views
            .iter()
            .filter(move |(e, v)| match maximised {
                Some(m) => m == e.id,
                None => e.in_grid,
            } && v.busy())
            .map(|(e, _)| e.id)
    }

    /// Whether the help overlay is open.
    pub fn help_open(&self) -> bool {
        self.help
    }

    /// The last status message (refused values, unknown models).
    pub fn status(&self) -> Option<&str> {
        self.ws.status.as_deref()
    }

    /// The built evaluators.
    pub fn runtime(&self) -> &Runtime {
        &self.ws.runtime
    }

    /// Applies `cmds` (the session's job, [`Workspace::apply`]) and does what
    /// they ask of the window.
    fn apply(&mut self, cmds: Vec<Command>) {
        let asks = self.ws.apply(cmds);
        self.answer(asks);
    }

    /// Shows what applying commands asked for: the help overlay, the file
    /// dialog.
    fn answer(&mut self, asks: Asks) {
        if asks.toggle_help % 2 == 1 {
            self.help = !self.help;
        }
        if asks.open_dialog && !self.files.is_open() {
            self.files.open(
                (),
                "Open a MERL table (.binary) or a BRDF file (.brdf)",
                measured_ui::OPENABLE_FILES,
            );
        }
    }

    /// Draws the viewer into `ui` (the whole window) and applies what the UI
    /// asked for.
    pub fn ui(&mut self, ui: &mut Ui) {
        let ctx = ui.ctx().clone();
        // Keys typed in a frame that began with a widget owning the keyboard
        // are that widget's, even if it lets go during the frame (Enter).
        // A file dialog owns the keyboard too: its name field may not have
        // the focus yet when the user starts typing.
        let keyboard_free =
            shortcuts::keyboard_free(&ctx) && !self.files.is_open() && !self.export.files_open();
        let look = (self.ws.state.theme, self.present.on);
        if self.applied_look != Some(look) {
            let theme = match self.ws.state.theme {
                Theme::Dark => egui::Theme::Dark,
                Theme::Light => egui::Theme::Light,
            };
            // egui's own visuals stay untouched until presentation mode is
            // first used.
            if self.present.on || self.applied_look.is_some_and(|(_, p)| p) {
                ctx.set_visuals_of(
                    theme,
                    presentation::visuals(self.ws.state.theme, self.present.on),
                );
            }
            ctx.set_theme(theme);
            // Every context that shows the viewer (eframe's window, the web
            // page, a test harness, a rendered slide) gets the glyphs of the
            // lecture's notation, and presenting, the projector's typeface.
            if self.applied_look.is_none_or(|(_, p)| p != self.present.on) {
                crate::views::fonts::set_presenting(&ctx, self.present.on);
            }
            self.applied_look = Some(look);
        }
        self.sync_zoom(&ctx);
        self.apply_pending();
        self.finish_loads();
        self.reload_user_files(&ctx);
        if self.ws.loader.busy() {
            // Keep the progress bar moving while nothing else happens.
            ctx.request_repaint_after(std::time::Duration::from_millis(40));
        }
        self.ws.runtime.sync(&self.ws.state);
        let interacting = self.force_interacting || ctx.input(|i| i.pointer.any_down());
        let mut out = Vec::new();
        let mut strip = Vec::new();
        if self.present.on {
            self.presentation_bands(ui, &mut strip);
            if self.present.controls {
                self.left_panel(ui, &mut out);
            }
        } else {
            self.top_bar(ui, &mut out);
            self.left_panel(ui, &mut out);
        }
        {
            let mut scene = build_scene(&self.ws.state, &self.ws.runtime, interacting);
            scene.figure = self.figure;
            let panel = egui::CentralPanel::default()
                .frame(self.panel_frame(egui::Frame::central_panel(ui.style())));
            let views = &mut self.views;
            if self.present.on {
                scene.line_scale = crate::session::presentation::LINE_SCALE;
                scene.presenting = true;
                panel.show(ui, |ui| {
                    central_presenting(ui, views, &scene, &mut out);
                });
            } else {
                panel.show(ui, |ui| {
                    central(ui, views, &scene, &mut out);
                });
            }
        }
        if !strip.is_empty() {
            for a in strip {
                self.strip_action(a);
            }
            ctx.request_repaint();
        }
        self.shortcuts(&ctx, keyboard_free, &mut out);
        dropped_files(&ctx, &self.ws.state, &self.ws.runtime, &mut out);
        self.help_window(&ctx);
        self.fit.window(&ctx, &self.ws.state, &mut out);
        if let Some(((), path)) = self.files.show(&ctx) {
            out.push(Command::OpenFile {
                path: path.display().to_string(),
                into: None,
            });
        }
        if measured_ui::error_window(&ctx, &self.ws.load_errors) {
            self.ws.load_errors.remove(0);
            ctx.request_repaint();
        }
        for r in self.export.ui(&ctx) {
            self.handle(r, &ctx);
        }
        if !out.is_empty() {
            // Repaint only for real changes, so a widget that re-sends the same
            // value cannot keep the app busy.
            let before = self.ws.state.clone();
            let help = self.help;
            self.apply(out);
            if self.ws.state != before || self.help != help {
                ctx.request_repaint();
            }
        }
    }

    /// Applies saved edits of the user BRDF files drawn: the status line
    /// says which file reloaded, the error window shows a file that no
    /// longer compiles (with file, line and column) while its last working
    /// version stays drawn.
    fn reload_user_files(&mut self, ctx: &egui::Context) {
        let c = ctx.clone();
        let (changed, settles) = self.ws.reload_user_files(move || c.request_repaint());
        if changed {
            ctx.request_repaint();
        }
        if let Some(wait) = settles {
            ctx.request_repaint_after(wait);
        }
    }

    fn top_bar(&mut self, ui: &mut Ui, out: &mut Vec<Command>) {
        let frame = self.panel_frame(egui::Frame::side_top_panel(ui.style()));
        egui::Panel::top("bv top").frame(frame).show(ui, |ui| {
            ui.horizontal(|ui| {
                ui.label(RichText::new("bv").strong().size(16.0));
                ui.weak("BRDF viewer");
                ui.separator();
                if ui
                    .button("Open…")
                    .on_hover_text("Open a scene file (Ctrl+O)")
                    .clicked()
                {
                    self.export.ask_open_scene();
                }
                if ui
                    .button("Save…")
                    .on_hover_text("Save the scene as a TOML file (Ctrl+S)")
                    .clicked()
                {
                    self.export.ask_save_scene();
                }
                if ui
                    .button("Export…")
                    .on_hover_text("A view or the window as PNG, SVG or OBJ (Ctrl+Shift+S)")
                    .clicked()
                {
                    self.export.dialog_open = true;
                }
                if ui
                    .button("Fit…")
                    .on_hover_text("Fit a model to a BRDF of the list (F)")
                    .clicked()
                {
                    self.fit.open = !self.fit.open;
                }
                if ui
                    .button("Present")
                    .on_hover_text("Presentation mode: one view, large text (F5)")
                    .clicked()
                {
                    self.set_presenting(true);
                }
                ui.menu_button("Views", |ui| {
                    for e in REGISTRY.iter() {
                        let on = self.ws.state.maximised.as_deref() == Some(e.id);
                        if ui
                            .selectable_label(on, e.title)
                            .on_hover_text("Show this view alone (again: back to the overview)")
                            .clicked()
                        {
                            out.push(Command::ToggleMaximise(e.id.to_string()));
                            ui.close();
                        }
                    }
                });
                ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                    if ui
                        .button("? help")
                        .on_hover_text("Keyboard shortcuts (F1)")
                        .clicked()
                    {
                        out.push(Command::ToggleHelp);
                    }
                    let (label, next) = match self.ws.state.theme {
                        Theme::Dark => ("light theme", Theme::Light),
                        Theme::Light => ("dark theme", Theme::Dark),
                    };
                    if ui.button(label).on_hover_text("Switch theme (T)").clicked() {
                        out.push(Command::SetTheme(next));
                    }
                });
            });
        });
    }

    /// Presentation mode's title band and strip of views.
    fn presentation_bands(&mut self, ui: &mut Ui, strip: &mut Vec<StripAction>) {
        let shown = self
            .ws
            .state
            .maximised
            .as_deref()
            .and_then(|m| REGISTRY.iter().find(|e| e.id == m))
            .or_else(|| REGISTRY.first());
        let shown_id = shown.map_or("", |e| e.id);
        match &self.deck {
            Some(d) => {
                if let Some(s) = d.deck.slides.get(d.index) {
                    presentation::top_band(
                        ui,
                        &s.title,
                        &s.caption,
                        Some((d.index, d.deck.slides.len())),
                    );
                }
            }
            None => presentation::top_band(ui, shown.map_or("", |e| e.title), "", None),
        }
        strip.extend(presentation::bottom_strip(
            ui,
            shown_id,
            self.deck.is_some(),
            self.present.controls,
        ));
    }

    fn left_panel(&mut self, ui: &mut Ui, out: &mut Vec<Command>) {
        let frame = self.panel_frame(egui::Frame::side_top_panel(ui.style()));
        egui::Panel::left("bv brdfs")
            .frame(frame)
            .resizable(true)
            .default_size(350.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical()
                    .auto_shrink([false, false])
                    .show(ui, |ui| {
                        panel::brdf_list(ui, &self.ws.state, &self.ws.runtime, out);
                        measured_ui::progress_ui(ui, &self.ws.loader);
                        ui.separator();
                        panel::light_ui(ui, &self.ws.state, &self.ws.runtime, out);
                        ui.separator();
                        panel::params_section(ui, &self.ws.state, &self.ws.runtime, out);
                        if let Some(e) = self.ws.state.selected_entry() {
                            measured_ui::measured_section(
                                ui,
                                &self.ws.state,
                                &self.ws.runtime,
                                e,
                                self.ws.last_load.as_deref(),
                            );
                        }
                        if let Some(msg) = &self.ws.status {
                            ui.separator();
                            ui.horizontal_wrapped(|ui| {
                                ui.colored_label(ui.visuals().warn_fg_color, msg);
                            });
                            if ui.small_button("dismiss").clicked() {
                                self.ws.status = None;
                            }
                        }
                    });
            });
    }

    fn hovered_view(&self, ctx: &egui::Context) -> Option<&'static str> {
        let pos = ctx.pointer_hover_pos()?;
        let area = ctx.memory(|m| {
            m.data
                .get_temp::<Vec<(String, Rect)>>(egui::Id::unique("bv view rects"))
        })?;
        area.iter()
            .find(|(_, r)| r.contains(pos))
            .and_then(|(id, _)| REGISTRY.iter().find(|e| e.id == id).map(|e| e.id))
    }

    /// Handles the keyboard shortcuts (see [`shortcuts::SHORTCUTS`]);
    /// `free` says whether the keyboard was free at the start of the frame.
    fn shortcuts(&mut self, ctx: &egui::Context, free: bool, out: &mut Vec<Command>) {
        for action in shortcuts::pressed(ctx, free) {
            match action {
                Action::ToggleHelp => out.push(Command::ToggleHelp),
                Action::ResetCamera => out.push(Command::ResetCamera),
                Action::ToggleLog => out.push(Command::ToggleLog),
                Action::ToggleCosine => out.push(Command::ToggleCosine),
                Action::ToggleWireframe => out.push(Command::ToggleWireframe),
                Action::NextModel => out.push(Command::StepModel(1)),
                Action::PreviousModel => out.push(Command::StepModel(-1)),
                Action::NextBrdf | Action::NextSlide if self.present.on => self.step(1),
                Action::PreviousBrdf | Action::PreviousSlide if self.present.on => self.step(-1),
                Action::FirstSlide | Action::LastSlide if self.present.on => {
                    self.jump(action == Action::LastSlide);
                }
                Action::NextBrdf => out.push(Command::SelectStep(1)),
                Action::PreviousBrdf => out.push(Command::SelectStep(-1)),
                Action::NextSlide
                | Action::PreviousSlide
                | Action::FirstSlide
                | Action::LastSlide => {}
                // egui zooms before the viewer sees the keys.
                Action::Zoom => {}
                Action::TogglePresentation => self.set_presenting(!self.present.on),
                Action::MaximiseHovered => {
                    let id = self
                        .hovered_view(ctx)
                        .or_else(|| REGISTRY.first().map(|e| e.id));
                    if let Some(id) = id {
                        out.push(Command::ToggleMaximise(id.to_string()));
                    }
                }
                Action::MaximiseView(k) => {
                    if let Some(e) = REGISTRY.get(k) {
                        // Presenting, one view is always shown.
                        out.push(if self.present.on {
                            Command::Maximise(Some(e.id.to_string()))
                        } else {
                            Command::ToggleMaximise(e.id.to_string())
                        });
                    }
                }
                Action::Escape => {
                    if self.help {
                        out.push(Command::ToggleHelp);
                    } else if self.present.on {
                        self.set_presenting(false);
                    } else {
                        out.push(Command::Maximise(None));
                    }
                }
                Action::ToggleTheme => out.push(Command::SetTheme(match self.ws.state.theme {
                    Theme::Dark => Theme::Light,
                    Theme::Light => Theme::Dark,
                })),
                Action::OpenScene => self.export.ask_open_scene(),
                Action::SaveScene if self.deck.is_some() => match self.save_deck() {
                    Ok(p) => self
                        .export
                        .toast(format!("Saved the deck to {}", p.display()), false),
                    Err(e) => {
                        let msg = format!("Could not save the deck: {e}");
                        self.ws.status = Some(msg.clone());
                        self.export.toast(msg, true);
                    }
                },
                Action::SaveScene => match self.export.scene_path.clone() {
                    Some(p) => self.handle(Request::SaveScene(p), ctx),
                    None => self.export.ask_save_scene(),
                },
                Action::ExportFigure => self.export.dialog_open = !self.export.dialog_open,
                Action::ToggleFit => self.fit.open = !self.fit.open,
                Action::Quit => ctx.send_viewport_cmd(egui::ViewportCommand::Close),
            }
        }
    }

    fn help_window(&mut self, ctx: &egui::Context) {
        if !self.help {
            return;
        }
        let mut open = true;
        egui::Window::new("Keyboard shortcuts")
            .open(&mut open)
            .collapsible(false)
            .resizable(false)
            .anchor(egui::Align2::CENTER_CENTER, Vec2::ZERO)
            .show(ctx, |ui| {
                egui::Grid::new("bv help keys")
                    .num_columns(2)
                    .spacing([24.0, 4.0])
                    .show(ui, |ui| {
                        for s in shortcuts::SHORTCUTS {
                            ui.label(RichText::new(s.keys_text(ctx)).monospace().strong());
                            ui.label(s.help);
                            ui.end_row();
                        }
                    });
                ui.separator();
                egui::Grid::new("bv help mouse")
                    .num_columns(2)
                    .spacing([24.0, 4.0])
                    .show(ui, |ui| {
                        for (k, what) in GESTURES {
                            ui.label(RichText::new(*k).strong());
                            ui.label(*what);
                            ui.end_row();
                        }
                    });
            });
        if !open {
            self.help = false;
        }
    }
}

impl crate::export::WindowUi for Viewer {
    fn ui(&mut self, ui: &mut Ui) {
        Viewer::ui(self, ui);
    }

    fn error(&self) -> Option<String> {
        self.views.iter().find_map(|(_, v)| v.figure_error())
    }
}

/// The window drawn as a figure (what `bv render --view window` and the
/// export dialog's "whole window" draw).
pub fn figure_window(state: &AppState) -> Box<dyn crate::export::WindowUi> {
    let mut viewer = Viewer::new(state.clone());
    viewer.figure = true;
    Box::new(viewer)
}

/// Slide `index` of `deck` drawn as a figure, as presentation mode shows it
/// (what `bv render --deck` draws).
pub fn slide_window(deck: &deck::Deck, index: usize) -> Box<dyn crate::export::WindowUi> {
    let state = deck
        .slides
        .get(index)
        .map(|s| s.state.clone())
        .unwrap_or_default();
    let mut viewer = Viewer::new(state);
    viewer.figure = true;
    viewer.set_deck(deck.clone(), None, index);
    Box::new(viewer)
}

/// Where view `id` was drawn in the last frame.
pub fn view_rect(ctx: &egui::Context, id: &str) -> Option<Rect> {
    ctx.memory(|m| {
        m.data
            .get_temp::<Vec<(String, Rect)>>(egui::Id::unique("bv view rects"))
    })?
    .into_iter()
    .find(|(v, _)| v == id)
    .map(|(_, r)| r)
}

/// Lays out the views in the central area.
fn central(
    ui: &mut Ui,
    views: &mut [(&'static ViewEntry, Box<dyn View>)],
    scene: &Scene<'_>,
    out: &mut Vec<Command>,
) {
    let area = ui.available_rect_before_wrap();
    let maximised = scene
        .state
        .maximised
        .as_deref()
        .and_then(|id| views.iter().position(|(e, _)| e.id == id));
    // The grid holds the overview views; a view outside it is shown when it
    // is the maximised one.
    let shown: Vec<usize> = (0..views.len())
        .filter(|&i| views[i].0.in_grid || maximised == Some(i))
        .collect();
    let max_in_shown = maximised.and_then(|m| shown.iter().position(|&i| i == m));
    for (k, rect) in layout(area, shown.len(), max_in_shown) {
        let i = shown[k];
        let (entry, view) = &mut views[i];
        let is_max = maximised == Some(i);
        ui.scope_builder(UiBuilder::new().max_rect(rect).id_salt(entry.id), |ui| {
            ui.set_clip_rect(rect.intersect(ui.clip_rect()));
            view_frame(ui, entry, view.as_mut(), is_max, scene, out);
        });
    }
}

/// Presentation mode's central area: the shown view (the maximised one, or
/// the first) alone, without its header.
fn central_presenting(
    ui: &mut Ui,
    views: &mut [(&'static ViewEntry, Box<dyn View>)],
    scene: &Scene<'_>,
    out: &mut Vec<Command>,
) {
    let i = scene
        .state
        .maximised
        .as_deref()
        .and_then(|id| views.iter().position(|(e, _)| e.id == id))
        .unwrap_or(0);
    let Some((entry, view)) = views.get_mut(i) else {
        return;
    };
    let rect = ui.available_rect_before_wrap();
    ui.ctx().data_mut(|d| {
        d.insert_temp(
            egui::Id::unique("bv view rects"),
            vec![(entry.id.to_string(), rect)],
        );
    });
    ui.scope_builder(UiBuilder::new().max_rect(rect).id_salt(entry.id), |ui| {
        // Room on the left for a plot's rotated y label (the panel's margin).
        let clip = rect.with_min_x(rect.min.x - crate::views::y_label_overhang(ui));
        ui.set_clip_rect(clip.intersect(ui.clip_rect()));
        crate::views::show(view.as_mut(), ui, scene, out);
    });
}

/// Files dropped on the window are opened as measured tables (see
/// [`file_command`]).
fn dropped_files(ctx: &egui::Context, state: &AppState, runtime: &Runtime, out: &mut Vec<Command>) {
    let paths: Vec<String> = ctx.input(|i| {
        i.raw
            .dropped_files
            .iter()
            .map(|f| f.path().display().to_string())
            .filter(|p| !p.is_empty())
            .collect()
    });
    let several = paths.len() > 1;
    for path in paths {
        out.push(file_command(state, runtime, &path, several));
    }
}

/// The command that opens `path` (a dropped file): it becomes the file of
/// the selected BRDF when that one takes a file but has none that loads (a
/// fresh `merl`, or one whose file went away), and a new BRDF otherwise, so
/// that dropping tables one after the other puts them side by side.
/// `several` files dropped at once always become new BRDFs.
pub fn file_command(state: &AppState, runtime: &Runtime, path: &str, several: bool) -> Command {
    let into = state
        .selected_entry()
        .filter(|_| !several)
        .filter(|e| crate::session::command::path_param(&e.spec).is_some())
        .filter(|e| runtime.get(e.id).is_none_or(|b| b.brdf.is_none()))
        .map(|e| e.id);
    Command::OpenFile {
        path: path.to_string(),
        into,
    }
}

/// Where each view goes: the maximised one fills the area. Up to three views:
/// the first takes the left part and the others stack on the right. From four
/// on: the first two share the top row (the lobe and the lit sphere side by
/// side), the others fill rows of up to three below (four views make a 2×2
/// grid).
pub fn layout(area: Rect, n: usize, maximised: Option<usize>) -> Vec<(usize, Rect)> {
    const GAP: f32 = 6.0;
    if let Some(i) = maximised.filter(|&i| i < n) {
        return vec![(i, area)];
    }
    match n {
        0 => Vec::new(),
        1 => vec![(0, area)],
        2 | 3 => {
            let left_w = (area.width() * 0.56).round();
            let left = Rect::from_min_size(area.min, Vec2::new(left_w - GAP * 0.5, area.height()));
            let right_x = area.min.x + left_w + GAP * 0.5;
            let rest = n - 1;
            let h = (area.height() - GAP * (rest as f32 - 1.0)) / rest as f32;
            let mut out = vec![(0, left)];
            for k in 0..rest {
                let y = area.min.y + k as f32 * (h + GAP);
                out.push((
                    k + 1,
                    Rect::from_min_max(egui::pos2(right_x, y), egui::pos2(area.max.x, y + h)),
                ));
            }
            out
        }
        _ => {
            // Rows: the top one (2 views, weight TOP) and ⌈(n − 2)/3⌉ below
            // (weight 1 each), the views of a row sharing its width equally
            // except the top row's 55/45 split.
            const TOP: f32 = 1.3;
            let rest = n - 2;
            let rows_below = rest.div_ceil(3);
            let weights = TOP + rows_below as f32;
            let free = area.height() - GAP * rows_below as f32;
            let top_h = free * TOP / weights;
            let row_h = free / weights;
            let mut out = Vec::with_capacity(n);
            let split = (area.width() * 0.55).round();
            out.push((
                0,
                Rect::from_min_size(area.min, Vec2::new(split - GAP * 0.5, top_h)),
            ));
            out.push((
                1,
                Rect::from_min_max(
                    egui::pos2(area.min.x + split + GAP * 0.5, area.min.y),
                    egui::pos2(area.max.x, area.min.y + top_h),
                ),
            ));
            let mut i = 2;
            for row in 0..rows_below {
                let in_row = (n - i).min(3);
                let y = area.min.y + top_h + GAP + row as f32 * (row_h + GAP);
                let w = (area.width() - GAP * (in_row as f32 - 1.0)) / in_row as f32;
                for c in 0..in_row {
                    let x = area.min.x + c as f32 * (w + GAP);
                    out.push((
                        i,
                        Rect::from_min_size(egui::pos2(x, y), Vec2::new(w, row_h)),
                    ));
                    i += 1;
                }
            }
            out
        }
    }
}

/// A view's frame: a header with its title, toolbar and maximise button, and
/// the view below.
fn view_frame(
    ui: &mut Ui,
    entry: &ViewEntry,
    view: &mut dyn View,
    is_max: bool,
    scene: &Scene<'_>,
    out: &mut Vec<Command>,
) {
    let rect = ui.max_rect();
    // Remember where views are, for the M shortcut.
    ui.ctx().data_mut(|d| {
        let list =
            d.get_temp_mut_or_default::<Vec<(String, Rect)>>(egui::Id::unique("bv view rects"));
        list.retain(|(id, _)| id != entry.id);
        list.push((entry.id.to_string(), rect));
    });
    egui::Frame::group(ui.style())
        .inner_margin(4.0)
        .show(ui, |ui| {
            ui.set_min_size(rect.size() - Vec2::splat(10.0));
            ui.horizontal_wrapped(|ui| {
                let title = ui.label(RichText::new(entry.title).strong());
                if title.double_clicked() {
                    out.push(Command::ToggleMaximise(entry.id.to_string()));
                }
                let (text, hint) = if is_max {
                    ("restore", "Show all views again (Esc)")
                } else {
                    ("maximise", "Fill the window with this view (M)")
                };
                let r = ui.small_button(text).on_hover_text(hint);
                let label = if is_max {
                    format!("Restore {}", entry.title)
                } else {
                    format!("Maximise {}", entry.title)
                };
                r.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Button, true, &label));
                if r.clicked() {
                    out.push(Command::ToggleMaximise(entry.id.to_string()));
                }
                ui.separator();
                view.toolbar(ui, scene, out);
            });
            ui.separator();
            crate::views::show(view, ui, scene, out);
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::session::loader::LoadTarget;

    #[test]
    fn a_dropped_file_opens_as_a_new_brdf_or_fills_an_empty_one() {
        let mut s = AppState::first_run();
        let mut rt = Runtime::default();
        rt.sync(&s);
        // The selected BRDF takes no file: a new one.
        assert_eq!(
            file_command(&s, &rt, "/data/gold.binary", false),
            Command::OpenFile {
                path: "/data/gold.binary".into(),
                into: None
            }
        );
        // A fresh merl (no file yet, so it does not build) is filled in.
        let id = s.add(bv_core::ModelSpec::new("merl").unwrap());
        rt.sync(&s);
        assert!(rt.get(id).unwrap().brdf.is_none());
        assert_eq!(
            file_command(&s, &rt, "/data/red.binary", false),
            Command::OpenFile {
                path: "/data/red.binary".into(),
                into: Some(id)
            }
        );
        // Several files at once: each its own BRDF.
        assert!(matches!(
            file_command(&s, &rt, "/data/a.binary", true),
            Command::OpenFile { into: None, .. }
        ));
        // The command names the path parameter of the target.
        let r = Command::OpenFile {
            path: "/x.binary".into(),
            into: Some(id),
        }
        .apply(&mut s);
        assert_eq!(
            r.open,
            Some((
                "/x.binary".to_string(),
                LoadTarget::Into {
                    brdf: id,
                    param: "path".into()
                }
            ))
        );
    }

    #[test]
    fn layout_fills_the_area() {
        let area = Rect::from_min_size(egui::pos2(10.0, 20.0), Vec2::new(1000.0, 600.0));
        let l = layout(area, 3, None);
        assert_eq!(l.len(), 3);
        for (_, r) in &l {
            assert!(area.contains_rect(*r), "{r:?}");
        }
        assert!(l[0].1.width() > l[1].1.width());
        assert!((l[1].1.height() + l[2].1.height() + 6.0 - 600.0).abs() < 1e-3);
        assert_eq!(layout(area, 3, Some(2)), vec![(2, area)]);
        assert_eq!(layout(area, 3, Some(7)).len(), 3);
    }

    #[test]
    fn grid_layouts_tile_the_area_without_overlap() {
        let area = Rect::from_min_size(egui::pos2(10.0, 20.0), Vec2::new(900.0, 700.0));
        for n in 4..=9 {
            let l = layout(area, n, None);
            assert_eq!(l.len(), n);
            let covered: f32 = l.iter().map(|(_, r)| r.area()).sum();
            assert!(
                covered > 0.9 * area.area() && covered <= area.area() + 1e-2,
                "{n}"
            );
            for (i, (k, a)) in l.iter().enumerate() {
                assert_eq!(*k, i);
                assert!(area.expand(1e-3).contains_rect(*a), "{n}: {a:?}");
                assert!(a.width() > 100.0 && a.height() > 100.0, "{n}: {a:?}");
                for (_, b) in &l[i + 1..] {
                    assert!(a.intersect(*b).area() <= 1e-3, "{n}: {a:?} {b:?}");
                }
            }
            // The first two views share the top row.
            assert_eq!(l[0].1.min.y, l[1].1.min.y);
            assert!(l[1].1.min.x > l[0].1.max.x);
        }
        // Four views: a 2×2 grid.
        let l = layout(area, 4, None);
        assert!((l[2].1.min.x - l[0].1.min.x).abs() < 1e-3);
        assert!(l[2].1.min.y > l[0].1.max.y);
    }
}
