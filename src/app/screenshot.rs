//! The viewer's side of figures and scenes: scene files (Ctrl+O, Ctrl+S), the figure
//! export dialog (Ctrl+Shift+S: a view or the whole window as PNG at 1×, 2×
//! or 4× the screen's resolution, optionally transparent; 2D plots as SVG;
//! the lobe as OBJ/PLY), and toasts that say where things went.
//!
//! Figures are drawn offscreen by [`crate::export`] with the window's own GPU
//! device (a renderer of their own, so the window's textures are untouched),
//! laid out at the on-screen size in points and rasterised at the chosen
//! pixels per point: a 4× PNG is drawn at 4×, not upscaled.

use crate::export::{self, Offscreen};
use crate::session::platform::Instant;
use crate::session::scene_file as scene;
use crate::session::state::AppState;
use crate::views::REGISTRY;
use crate::widgets::files::{self, Files, Filter};
use eframe::egui::{self, Align2, RichText};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// How long a toast stays.
pub const TOAST_TIME: Duration = Duration::from_secs(6);

/// What to export.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// The whole window.
    Window,
    /// One view (registry id).
    View(String),
}

/// The file format of a figure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Raster image.
    Png,
    /// Vector drawing (2D plots).
    Svg,
    /// Lobe mesh (OBJ, or PLY by the file's extension).
    Mesh,
}

impl Format {
    fn filter(self) -> Filter {
        match self {
            Format::Png => files::PNG,
            Format::Svg => files::SVG,
            Format::Mesh => files::MESH,
        }
    }
}

/// The export dialog's settings.
#[derive(Debug, Clone, PartialEq)]
pub struct FigureSettings {
    /// What to draw.
    pub target: Target,
    /// File format.
    pub format: Format,
    /// Pixels per screen pixel: 1, 2 or 4.
    pub scale: u32,
    /// Transparent background (PNG and SVG).
    pub transparent: bool,
    /// How a view's figure is laid out.
    pub layout: FigureLayout,
    /// A caption under a view's figure (models, parameters, light).
    pub caption: bool,
}

impl Default for FigureSettings {
    fn default() -> Self {
        Self {
            target: Target::Window,
            format: Format::Png,
            scale: 2,
            transparent: false,
            layout: FigureLayout::Figure,
            caption: false,
        }
    }
}

/// How a view's figure is laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FigureLayout {
    /// At [`FIGURE_SIZE`] points whatever the view's size on screen: a view
    /// in a small grid cell still gets axis numbers and a legend, laid out
    /// as `bv render` lays out its figures.
    Figure,
    /// At the view's size on screen (its grid cell, or the window when
    /// maximised).
    Screen,
}

/// The layout size of a figure of one view, points (×2 at the default 2×
/// resolution: 1600 × 1200 pixels, `bv render`'s default).
pub const FIGURE_SIZE: egui::Vec2 = egui::vec2(800.0, 600.0);

/// What a file dialog was opened for.
#[derive(Debug, Clone)]
enum Task {
    OpenScene,
    SaveScene,
    Figure(FigureSettings),
}

/// A short message shown over the window.
#[derive(Debug, Clone)]
pub struct Toast {
    /// The text.
    pub text: String,
    /// Whether it reports a failure.
    pub error: bool,
    since: Instant,
}

/// Where a view is on screen and the screen's pixels per point (what a
/// figure's size is taken from).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScreenGeometry {
    /// Window size in points.
    pub window: egui::Vec2,
    /// Pixels per point of the screen.
    pub pixels_per_point: f32,
}

/// The scene/figure part of the viewer's UI state.
#[derive(Default)]
pub struct ExportUi {
    files: Files<Task>,
    /// The export dialog is showing.
    pub dialog_open: bool,
    /// The dialog's settings.
    pub settings: FigureSettings,
    /// The scene file last opened or saved (Ctrl+S saves there).
    pub scene_path: Option<PathBuf>,
    /// The last toast.
    pub toast: Option<Toast>,
    gpu: Option<eframe::egui_wgpu::RenderState>,
    svg_views: Option<Vec<&'static str>>,
    /// PNG figures drawn and being read back (a browser page's: it maps
    /// the pixels only between frames), saved when they are there.
    pending: Vec<PendingPng>,
}

/// A PNG figure being read back, and where it goes.
struct PendingPng {
    figure: export::PendingFigure,
    path: PathBuf,
    what: &'static str,
}

/// Which views have a vector (SVG) form.
fn svg_views() -> Vec<&'static str> {
    export::files::svg_views().iter().map(|e| e.id).collect()
}

impl ExportUi {
    /// Gives figures a GPU device (the window's render state; figures get
    /// a renderer of their own on its device).
    pub fn set_gpu(&mut self, render_state: eframe::egui_wgpu::RenderState) {
        self.gpu = Some(render_state);
    }

    /// Shows a toast.
    pub fn toast(&mut self, text: impl Into<String>, error: bool) {
        let text = text.into();
        if error {
            eprintln!("bv: {text}");
        }
        self.toast = Some(Toast {
            text,
            error,
            since: Instant::now(),
        });
    }

    /// Whether a file dialog (or its "Replace?" question) is showing.
    pub fn files_open(&self) -> bool {
        self.files.is_open()
    }

    /// Opens the scene dialog.
    pub fn ask_open_scene(&mut self) {
        self.files
            .open(Task::OpenScene, "Open a bv scene", files::SCENE);
    }

    /// Opens the save-as dialog.
    pub fn ask_save_scene(&mut self) {
        let name = self
            .scene_path
            .as_ref()
            .and_then(|p| p.file_name())
            .map_or_else(
                || "scene.toml".to_string(),
                |n| n.to_string_lossy().into_owned(),
            );
        self.files
            .save(Task::SaveScene, "Save the scene", files::SCENE, &name);
    }

    fn svg_ok(&mut self, id: &str) -> bool {
        self.svg_views.get_or_insert_with(svg_views).contains(&id)
    }

    /// Draws the dialogs and the toast; returns what the user asked for.
    pub fn ui(&mut self, ctx: &egui::Context) -> Vec<Request> {
        let mut out = Vec::new();
        if self.dialog_open {
            self.dialog(ctx);
        }
        if let Some((task, path)) = self.files.show(ctx) {
            out.push(match task {
                Task::OpenScene => Request::OpenScene(path),
                Task::SaveScene => Request::SaveScene(path),
                Task::Figure(s) => Request::Figure(s, path),
            });
        }
        self.save_pending(ctx);
        self.toast_ui(ctx);
        out
    }

    /// Saves the PNG figures whose pixels came back; asks for frames while
    /// some have not.
    fn save_pending(&mut self, ctx: &egui::Context) {
        let mut done = Vec::new();
        self.pending.retain_mut(|p| match p.figure.poll() {
            Some(image) => {
                done.push((image, std::mem::take(&mut p.path), p.what));
                false
            }
            None => true,
        });
        for (image, path, what) in done {
            match image.and_then(|img| export::save_png(&img, &path).map(|()| img)) {
                Ok(img) => self.toast(saved_line(what, &img, &path), false),
                Err(e) => self.toast(format!("Could not export the figure: {e:#}"), true),
            }
        }
        if !self.pending.is_empty() {
            ctx.request_repaint_after(Duration::from_millis(16));
        }
    }

    fn dialog(&mut self, ctx: &egui::Context) {
        let mut open = true;
        let mut s = self.settings.clone();
        let mut save = false;
        egui::Window::new("Export figure")
            .open(&mut open)
            .collapsible(false)
            .resizable(false)
            .anchor(Align2::CENTER_CENTER, egui::Vec2::ZERO)
            .show(ctx, |ui| {
                egui::Grid::new("bv export grid")
                    .num_columns(2)
                    .spacing([16.0, 6.0])
                    .show(ui, |ui| {
                        let label = ui.label("Figure of");
                        let current = match &s.target {
                            Target::Window => "Whole window".to_string(),
                            Target::View(id) => crate::views::entry(id)
                                .map_or_else(|| id.clone(), |e| e.title.to_string()),
                        };
                        egui::ComboBox::new("bv export target", "")
                            .selected_text(current)
                            .show_ui(ui, |ui| {
                                ui.selectable_value(&mut s.target, Target::Window, "Whole window");
                                for e in REGISTRY.iter() {
                                    ui.selectable_value(
                                        &mut s.target,
                                        Target::View(e.id.to_string()),
                                        e.title,
                                    );
                                }
                            })
                            .response
                            .labelled_by(label.id);
                        ui.end_row();

                        ui.label("Format");
                        ui.horizontal(|ui| {
                            ui.selectable_value(&mut s.format, Format::Png, "PNG");
                            let svg = matches!(&s.target, Target::View(id) if self.svg_ok(id));
                            ui.add_enabled_ui(svg, |ui| {
                                ui.selectable_value(&mut s.format, Format::Svg, "SVG")
                                    .on_disabled_hover_text("Only the 2D plots have a vector form");
                            });
                            let mesh = matches!(&s.target, Target::View(id) if id == crate::session::views::LOBE.id);
                            ui.add_enabled_ui(mesh, |ui| {
                                ui.selectable_value(&mut s.format, Format::Mesh, "OBJ / PLY")
                                    .on_disabled_hover_text("The lobe view's mesh, for Blender");
                            });
                        });
                        ui.end_row();

                        if s.format == Format::Png {
                            ui.label("Resolution");
                            ui.horizontal(|ui| {
                                for k in [1, 2, 4] {
                                    ui.selectable_value(&mut s.scale, k, format!("{k}×"));
                                }
                            });
                            ui.end_row();
                        }
                        if matches!(s.target, Target::View(_)) && s.format != Format::Mesh {
                            ui.label("Layout");
                            ui.horizontal(|ui| {
                                ui.selectable_value(
                                    &mut s.layout,
                                    FigureLayout::Figure,
                                    format!("figure {}×{}", FIGURE_SIZE.x, FIGURE_SIZE.y),
                                )
                                .on_hover_text("Laid out for the figure's own size (points)");
                                ui.selectable_value(
                                    &mut s.layout,
                                    FigureLayout::Screen,
                                    "as on screen",
                                )
                                .on_hover_text("The view's size in the window");
                            });
                            ui.end_row();
                        }
                        if matches!(s.target, Target::View(_)) && s.format == Format::Png {
                            ui.label("Caption");
                            ui.checkbox(&mut s.caption, "models, parameters and θi under it");
                            ui.end_row();
                        }
                        if s.format != Format::Mesh {
                            ui.label("Background");
                            ui.checkbox(&mut s.transparent, "transparent");
                            ui.end_row();
                        }
                    });
                ui.add_space(6.0);
                ui.horizontal(|ui| {
                    if ui.button("Save…").clicked() {
                        save = true;
                    }
                    ui.weak("Enter saves · Ctrl+Shift+S closes");
                });
            });
        // Enter saves, as the button does (unless a list of the dialog is
        // open: Enter then picks its item).
        if !egui::Popup::is_any_open(ctx)
            && ctx.input_mut(|i| i.consume_key(egui::Modifiers::NONE, egui::Key::Enter))
        {
            save = true;
        }
        // Keep the format consistent with the target.
        let svg = matches!(&s.target, Target::View(id) if self.svg_ok(id));
        let mesh = matches!(&s.target, Target::View(id) if id == crate::session::views::LOBE.id);
        if (s.format == Format::Svg && !svg) || (s.format == Format::Mesh && !mesh) {
            s.format = Format::Png;
        }
        self.settings = s.clone();
        if save {
            self.dialog_open = false;
            let stem = match &s.target {
                Target::Window => "bv-window".to_string(),
                Target::View(id) => format!("bv-{id}"),
            };
            let ext = s.format.filter().extensions[0];
            self.files.save(
                Task::Figure(s),
                "Save the figure",
                self.settings.format.filter(),
                &format!("{stem}.{ext}"),
            );
        }
        if !open {
            self.dialog_open = false;
        }
    }

    fn toast_ui(&mut self, ctx: &egui::Context) {
        let Some(t) = &self.toast else { return };
        let age = t.since.elapsed();
        if age > TOAST_TIME {
            self.toast = None;
            return;
        }
        ctx.request_repaint_after(TOAST_TIME.saturating_sub(age));
        let color = if t.error {
            ctx.global_style().visuals.error_fg_color
        } else {
            ctx.global_style().visuals.strong_text_color()
        };
        let text = t.text.clone();
        egui::Area::new(egui::Id::unique("bv toast"))
            .anchor(Align2::CENTER_BOTTOM, egui::vec2(0.0, -24.0))
            .order(egui::Order::Foreground)
            .interactable(false)
            .show(ctx, |ui| {
                egui::Frame::popup(ui.style()).show(ui, |ui| {
                    ui.set_max_width(720.0);
                    ui.label(RichText::new(text).color(color));
                });
            });
    }

    /// The offscreen renderer on the window's device, or a headless one.
    fn offscreen(&self) -> anyhow::Result<Offscreen> {
        match &self.gpu {
            Some(rs) => Ok(Offscreen::from_render_state(rs)),
            None => Offscreen::headless(),
        }
    }

    /// Exports a figure of `state` to `path`; returns a line saying what was
    /// written. `geometry` gives the on-screen size; `view_rect` the view's
    /// size in points when one view is exported.
    pub fn export_figure(
        &mut self,
        state: &AppState,
        settings: &FigureSettings,
        path: &Path,
        geometry: ScreenGeometry,
        view_size: Option<egui::Vec2>,
        window: export::MakeWindow,
    ) -> anyhow::Result<String> {
        let entry = match &settings.target {
            Target::Window => None,
            Target::View(id) => Some(
                crate::views::entry(id)
                    .ok_or_else(|| anyhow::anyhow!("no view `{id}` in this build"))?,
            ),
        };
        let size = match (entry, settings.layout) {
            (Some(_), FigureLayout::Figure) => FIGURE_SIZE,
            (Some(_), FigureLayout::Screen) => view_size.unwrap_or(geometry.window * 0.5),
            (None, _) => geometry.window,
        };
        match settings.format {
            Format::Png => {
                let frame = export::Frame {
                    size,
                    pixels_per_point: geometry.pixels_per_point * settings.scale as f32,
                    dark: export::is_dark(state),
                    transparent: settings.transparent,
                };
                let mut off = self.offscreen()?;
                let figure = match entry {
                    Some(e) if settings.caption => {
                        let mut captioned = state.clone();
                        captioned.display.caption = true;
                        export::start_view(&mut off, &captioned, e, frame)?
                    }
                    Some(e) => export::start_view(&mut off, state, e, frame)?,
                    None => export::start_window(&mut off, state, frame, window)?,
                };
                let what = entry.map_or("the window", |e| e.title);
                if crate::session::platform::WEB {
                    self.pending.push(PendingPng {
                        figure,
                        path: path.to_path_buf(),
                        what,
                    });
                    return Ok(format!("Drawing {what}…"));
                }
                let img = figure.wait()?;
                export::save_png(&img, path)?;
                Ok(saved_line(what, &img, path))
            }
            Format::Svg => {
                let e = entry.ok_or_else(|| anyhow::anyhow!("SVG needs a 2D plot view"))?;
                export::files::write_view_svg(
                    state,
                    e,
                    [size.x, size.y],
                    settings.transparent,
                    path,
                )?;
                Ok(format!("Saved {} as SVG to {}", e.title, path.display()))
            }
            Format::Mesh => {
                let ply = export::files::Kind::of(path) == Some(export::files::Kind::Ply);
                let n = export::files::write_mesh(state, ply, path)?;
                Ok(format!(
                    "Saved the lobe mesh{} to {}",
                    if n == 1 { "" } else { "es" },
                    path.display()
                ))
            }
        }
    }
}

/// The toast line of a saved PNG figure.
fn saved_line(what: &str, img: &image::RgbaImage, path: &Path) -> String {
    format!(
        "Saved {what} ({}×{} px) to {}",
        img.width(),
        img.height(),
        path.display()
    )
}

/// What the dialogs asked the viewer to do.
#[derive(Debug, Clone)]
pub enum Request {
    /// Load this scene.
    OpenScene(PathBuf),
    /// Save the scene here.
    SaveScene(PathBuf),
    /// Export a figure here.
    Figure(FigureSettings, PathBuf),
}

/// A scene file's warnings as one status line.
pub fn warnings_line(path: &Path, w: &[String]) -> String {
    match w.len() {
        0 => format!("Opened {}", path.display()),
        _ => format!(
            "Opened {} with {} warning{}: {}",
            path.display(),
            w.len(),
            if w.len() == 1 { "" } else { "s" },
            w.join("; ")
        ),
    }
}

/// Saves the scene (used by the viewer; kept here with the other file code).
pub fn save_scene(path: &Path, state: &AppState) -> anyhow::Result<String> {
    scene::save(path, state)?;
    Ok(format!("Saved the scene to {}", path.display()))
}
