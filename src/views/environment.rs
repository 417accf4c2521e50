//! The environment view: each drawn BRDF (or the selected
//! one) on a sphere or a torus under an equirectangular HDR environment,
//! rendered by [`crate::gpu::EnvRenderer`] with multiple importance sampling
//! of the BRDF and of the environment, accumulated across frames.
//!
//! - Any change the image depends on (a BRDF's parameters, the object, the
//!   rotation, the map, the view's size) restarts the accumulation; exposure
//!   and tone map only re-display the samples already taken.
//! - The view asks egui for the next frame only while it is visible and below
//!   its target sample count, so a converged image costs no CPU.
//! - Each frame adds a pass whose sample count adapts to the measured cost of
//!   a sample ([`PASS_BUDGET_S`] of device time per frame; one sample right
//!   after a restart and during a drag, so a slider drag stays smooth).
//! - Maps load on a worker thread (a large EXR takes a moment); a bad file is
//!   reported in the view and the previous map stays.

use super::gpu_image::{self, Deferred, Drawable, GpuImage, PackCheck};
use super::lit_sphere::{arrangement_control, exposure_control, tone_control};
use super::{Scene, View};
use crate::gpu::{EnvRenderer, EnvSettings, EnvironmentMap};
use crate::session::command::Command;
use crate::session::lighting::{ELEVATION_RANGE, EnvObject, EnvView, MAX_TARGET_SPP};
use crate::session::platform::Instant;
use crate::widgets::files::{Files, Filter};
use bv_core::ModelSpec;
use eframe::egui::{self, Align2, Color32, Rect, Sense, Ui, Vec2};
use std::path::PathBuf;
use std::sync::mpsc;

/// Largest pass (samples per pixel per frame).
pub const MAX_PASS_SPP: u32 = 64;

/// Device time a pass may take per frame while the image is left alone: the
/// window then still answers at about 10 frames per second on a software
/// renderer (whose own frame takes ~40 ms), and a GPU adds its 64 samples
/// per frame at once.
pub const PASS_BUDGET_S: f64 = 0.06;

/// Resolution of the accumulation relative to the view's pixels (the image is
/// stretched with linear filtering when it is smaller):
///
/// | | at rest | while a pointer button is held |
/// |---|---|---|
/// | GPU | 1 | ½ |
/// | software renderer (lavapipe) | ½ | ¼ |
/// | figure | 1 | 1 |
///
/// A slider drag restarts the image every frame, so a drag shows a quick
/// preview; on a software renderer a quarter of the pixels at rest buys a
/// clean image in a quarter of the time.
pub fn accumulation_scale(figure: bool, interacting: bool, software: bool) -> f32 {
    match (figure, interacting, software) {
        (true, _, _) => 1.0,
        (false, false, false) => 1.0,
        (false, true, false) | (false, false, true) => 0.5,
        (false, true, true) => 0.25,
    }
}

/// Samples in all (pixels × samples per pixel) of a figure on a software
/// renderer when no count was asked for: lavapipe draws about 10⁷ samples a
/// second on two cores, so a figure takes about ten seconds whatever its
/// size (64 samples per pixel at 1600×1200, 256 at 800×600), and `bv render
/// --view all` stays well under a minute. A GPU takes the view's target.
pub const SOFTWARE_FIGURE_SAMPLES: u64 = 1 << 27;

/// Most samples per pixel of a software figure within the budget (a clean
/// image at 800×600 and below).
pub const SOFTWARE_FIGURE_MAX_SPP: u32 = 256;

/// Fewest samples per pixel of a software figure, however large: below
/// this the noise of the sphere's rim and the floor's reflection shows at
/// a glance.
pub const SOFTWARE_FIGURE_MIN_SPP: u32 = 32;

/// Samples per pixel of a figure of `pixels` pixels: `exact` (the count
/// asked for, `bv render --spp`) when given, else the view's `target`, and
/// on a software renderer no more than [`SOFTWARE_FIGURE_SAMPLES`] in all
/// (the power of two below, between [`SOFTWARE_FIGURE_MIN_SPP`] and
/// [`SOFTWARE_FIGURE_MAX_SPP`] per pixel).
pub fn figure_spp(target: u32, exact: Option<u32>, software: bool, pixels: u64) -> u32 {
    if let Some(n) = exact {
        return n.clamp(1, MAX_TARGET_SPP);
    }
    let t = target.clamp(1, MAX_TARGET_SPP);
    if !software {
        return t;
    }
    // A power of two: the quasi-random sequence is best balanced there.
    let budget = (SOFTWARE_FIGURE_SAMPLES / pixels.max(1)).clamp(
        u64::from(SOFTWARE_FIGURE_MIN_SPP),
        u64::from(SOFTWARE_FIGURE_MAX_SPP),
    );
    let budget = 1u32 << (63 - budget.leading_zeros());
    t.min(budget)
}

/// Field of view of the background behind the objects (vertical, degrees).
const BACKGROUND_FOV_DEG: f64 = 60.0;

/// What the displayed image depends on beyond the accumulation key.
#[derive(Debug, Clone, PartialEq)]
struct Shown {
    specs: Vec<ModelSpec>,
    settings: EnvSettings,
    size: (u32, u32),
    samples: u64,
}

/// Environment maps the view opens.
pub const ENVIRONMENT_FILES: Filter = Filter {
    name: "environment map (.hdr, .exr)",
    extensions: &["hdr", "exr"],
};

/// How a frame is drawn.
#[derive(Debug, Clone, Copy)]
struct Mode {
    /// A pointer button is held: one sample per frame.
    interacting: bool,
    /// A figure: everything now.
    figure: bool,
    /// On a software renderer.
    software: bool,
    /// The surface turned about its normal, degrees.
    turn_deg: f64,
}

/// A map being loaded on a worker thread.
struct Loading {
    path: String,
    rx: mpsc::Receiver<anyhow::Result<EnvironmentMap>>,
}

/// The environment view.
pub struct EnvironmentView {
    renderer: Deferred<EnvRenderer>,
    image: GpuImage,
    /// The map the renderer holds (`None`: the built-in studio).
    map_in_use: Option<String>,
    /// The map last asked for (loaded, loading or failed).
    map_requested: Option<Option<String>>,
    loading: Option<Loading>,
    map_error: Option<String>,
    render_error: Option<String>,
    /// An error the device reported outside any error scope since the view
    /// last restarted (recorded by the device's handler instead of a panic).
    gpu_error: Option<String>,
    /// The device's uncaptured-error count already looked at.
    gpu_errors_seen: Option<u64>,
    shown: Option<Shown>,
    pass_spp: u32,
    /// Measured device seconds per sample per pixel (running average).
    spp_cost: Option<f64>,
    max_pass: u32,
    scale_in_use: Option<f32>,
    busy: bool,
    restarts: u64,
    restarted_at: Option<Instant>,
    /// Seconds from the last restart to the target sample count.
    converged_after: Option<f64>,
    path_edit: Option<String>,
    files: Files<()>,
    messages: Vec<String>,
    pack_check: PackCheck,
    /// Where the view was drawn in the last frame.
    pub view_rect: Option<Rect>,
}

impl Default for EnvironmentView {
    fn default() -> Self {
        Self::new()
    }
}

impl EnvironmentView {
    /// A view that creates its renderer on first use.
    pub fn new() -> Self {
        Self {
            renderer: Deferred::default(),
            image: GpuImage::default(),
            map_in_use: None,
            map_requested: None,
            loading: None,
            map_error: None,
            render_error: None,
            gpu_error: None,
            gpu_errors_seen: None,
            shown: None,
            pass_spp: 1,
            spp_cost: None,
            max_pass: MAX_PASS_SPP,
            scale_in_use: None,
            busy: false,
            restarts: 0,
            restarted_at: None,
            converged_after: None,
            path_edit: None,
            files: Files::default(),
            messages: Vec::new(),
            pack_check: PackCheck::default(),
            view_rect: None,
        }
    }

    /// Samples per pixel accumulated in the image shown (0 before the first).
    pub fn samples_per_pixel(&self) -> u64 {
        self.renderer
            .ready()
            .map_or(0, EnvRenderer::samples_per_pixel)
    }

    /// Caps the samples per pixel a frame adds (1 makes the image independent
    /// of the machine's speed, for tests; at most [`MAX_PASS_SPP`]).
    pub fn set_max_pass(&mut self, spp: u32) {
        self.max_pass = spp.clamp(1, MAX_PASS_SPP);
    }

    /// How many times the accumulation restarted.
    pub fn restart_count(&self) -> u64 {
        self.restarts
    }

    /// Seconds the last accumulation took to reach its target, if it did.
    pub fn converged_after(&self) -> Option<f64> {
        self.converged_after
    }

    /// The current error (map loading or rendering), if any.
    pub fn error(&self) -> Option<String> {
        let all: Vec<&str> = [&self.map_error, &self.render_error, &self.gpu_error]
            .into_iter()
            .flatten()
            .map(String::as_str)
            .collect();
        (!all.is_empty()).then(|| all.join("\n"))
    }

    /// Takes note of errors the device reported outside error scopes (by
    /// any code drawing on it) since the last look.
    fn check_device_errors(&mut self) {
        let Some(r) = self.renderer.ready() else {
            return;
        };
        let log = &r.gpu().errors;
        let seen = *self.gpu_errors_seen.get_or_insert(log.count());
        if let Some(e) = log.since(seen) {
            self.gpu_error = Some(format!("GPU error: {e}"));
            self.gpu_errors_seen = Some(log.count());
        }
    }

    /// The messages the last frame showed (BRDFs the GPU cannot draw, errors).
    pub fn messages(&self) -> &[String] {
        &self.messages
    }

    /// Whether the last frame left work to do (the renderer or a map still
    /// loading, or samples still to take).
    pub fn busy(&self) -> bool {
        self.busy
    }

    /// Whether the renderer is ready (it is built on a worker thread).
    pub fn ready(&self) -> bool {
        self.renderer.ready().is_some()
    }

    /// Whether a map is being loaded.
    pub fn loading(&self) -> bool {
        self.loading.is_some()
    }

    /// The map the renderer holds (`None`: the built-in studio).
    pub fn map_in_use(&self) -> Option<&str> {
        self.map_in_use.as_deref()
    }

    fn settings(env: &EnvView, turn_deg: f64) -> EnvSettings {
        EnvSettings {
            // The lit sphere's frames: t to the left at a sphere's centre.
            turn: turn_deg.to_radians() + super::lit_sphere::FRAME_TURN,
            rotation: env.rotation_deg.to_radians(),
            exposure_ev: env.exposure_ev,
            tone_map: gpu_image::tone_map(env.tone_map),
            background_fov_deg: BACKGROUND_FOV_DEG,
            elevation: env.elevation_deg.to_radians(),
        }
    }

    /// Starts loading `map` if it is not what was asked for last, and takes a
    /// finished load.
    fn sync_map(&mut self, ctx: &egui::Context, map: &Option<String>) {
        if self.map_requested.as_ref() != Some(map) {
            self.map_requested = Some(map.clone());
            self.map_error = None;
            match map {
                None => {
                    self.loading = None;
                    if self.map_in_use.is_some() {
                        match EnvironmentMap::builtin_studio() {
                            Ok(m) => self.install_map(None, &m),
                            Err(e) => self.map_error = Some(format!("{e:#}")),
                        }
                    }
                }
                Some(path) => {
                    let (tx, rx) = mpsc::channel();
                    let p = PathBuf::from(path);
                    let ctx2 = ctx.clone();
                    let spawned = crate::session::platform::spawn("bv env load", move || {
                        // The receiver may be gone (another map asked for).
                        let _ = tx.send(EnvironmentMap::load(&p));
                        ctx2.request_repaint();
                    });
                    match spawned {
                        Ok(_) => {
                            self.loading = Some(Loading {
                                path: path.clone(),
                                rx,
                            })
                        }
                        Err(e) => self.map_error = Some(format!("cannot start a loader: {e}")),
                    }
                }
            }
        }
        if let Some(l) = &self.loading {
            match l.rx.try_recv() {
                Ok(Ok(m)) => {
                    let path = l.path.clone();
                    self.loading = None;
                    self.install_map(Some(path), &m);
                }
                Ok(Err(e)) => {
                    self.map_error = Some(format!(
                        "{e:#} (still showing {})",
                        self.map_in_use.as_deref().unwrap_or("the studio")
                    ));
                    self.loading = None;
                }
                Err(mpsc::TryRecvError::Empty) => {}
                Err(mpsc::TryRecvError::Disconnected) => {
                    self.map_error = Some("the map loader stopped".into());
                    self.loading = None;
                }
            }
        }
    }

    /// The resolution of this frame: the preview resolution only when the
    /// image has to restart while a pointer button is held (a slider drag),
    /// so that a click elsewhere does not throw the samples away; back to the
    /// resting resolution when the button is released.
    fn choose_scale(
        &self,
        rect: Rect,
        pixels_per_point: f32,
        scene: &Scene<'_>,
        drawables: &[Drawable],
        software: bool,
    ) -> f32 {
        let rest = accumulation_scale(scene.figure, false, software);
        if scene.figure || !scene.interacting {
            return rest;
        }
        let current = self.scale_in_use.unwrap_or(rest);
        let env = &scene.state.lighting.env;
        let changed = match self.renderer.ready() {
            Some(r) => {
                let specs: Vec<ModelSpec> = drawables.iter().map(|d| d.spec.clone()).collect();
                let (w, h) = gpu_image::pixel_size(rect, pixels_per_point * current);
                r.object() != gpu_image::env_object(env.object)
                    || r.would_restart(
                        &specs,
                        &Self::settings(env, scene.state.display.turn_deg),
                        w,
                        h,
                    )
            }
            None => false,
        };
        if changed {
            accumulation_scale(false, true, software)
        } else {
            current
        }
    }

    /// Loads `map` on this thread if it is not the one in use (figures).
    fn load_map_now(&mut self, map: &Option<String>) {
        if self.map_requested.as_ref() == Some(map) && self.loading.is_none() {
            return;
        }
        self.loading = None;
        self.map_requested = Some(map.clone());
        let loaded = match map {
            None => EnvironmentMap::builtin_studio(),
            Some(p) => EnvironmentMap::load(std::path::Path::new(p)),
        };
        match loaded {
            Ok(m) => self.install_map(map.clone(), &m),
            // A figure with another map than asked for is wrong: the error
            // alone (`bv render` fails with it).
            Err(e) => self.map_error = Some(format!("{e:#}")),
        }
    }

    fn install_map(&mut self, path: Option<String>, map: &EnvironmentMap) {
        if let Some(r) = self.renderer.ready_mut() {
            match r.set_environment(map) {
                Ok(()) => {
                    self.map_in_use = path;
                    self.map_error = None;
                }
                Err(e) => self.map_error = Some(format!("{e:#}")),
            }
        }
    }

    /// Adds a pass if the image is not converged, re-displays it if only the
    /// display settings changed; returns the texture and whether more passes
    /// are wanted.
    fn step(
        &mut self,
        ui: &Ui,
        drawables: &[Drawable],
        env: &EnvView,
        size: (u32, u32),
        mode: Mode,
    ) -> (Option<egui::TextureId>, bool) {
        let Mode {
            interacting,
            figure,
            software,
            turn_deg,
        } = mode;
        let Some(rs) = gpu_image::render_state(ui.ctx()) else {
            return (None, false);
        };
        let gpu = gpu_image::gpu_of(&rs);
        let build = move || {
            EnvironmentMap::builtin_studio()
                .and_then(|map| {
                    let mut lib = gpu_image::library()?;
                    EnvRenderer::new(gpu, &mut lib, &map)
                })
                .map_err(|e| format!("cannot build the environment renderer: {e:#}"))
        };
        let built = if figure {
            self.renderer.now(build).map(|_| Some(()))
        } else {
            self.renderer.poll(ui.ctx(), build).map(|r| r.map(|_| ()))
        };
        match built {
            Ok(Some(_)) => {}
            Ok(None) => return (None, false),
            Err(e) => {
                self.render_error = Some(e);
                return (None, false);
            }
        }
        if figure {
            self.load_map_now(&env.map);
        } else {
            self.sync_map(ui.ctx(), &env.map);
        }
        self.check_device_errors();
        let Some(renderer) = self.renderer.ready_mut() else {
            return (None, false);
        };
        renderer.set_object(gpu_image::env_object(env.object));
        if figure {
            // A figure is drawn in one go: accumulate to the target now.
            let pixels = u64::from(size.0) * u64::from(size.1);
            let target = figure_spp(env.target_spp, env.figure_spp, software, pixels);
            let specs: Vec<ModelSpec> = drawables.iter().map(|d| d.spec.clone()).collect();
            let settings = Self::settings(env, turn_deg);
            let mut texture = None;
            loop {
                let done = if renderer.would_restart(&specs, &settings, size.0, size.1) {
                    0
                } else {
                    renderer.samples_per_pixel()
                };
                if done >= u64::from(target) {
                    break;
                }
                let pass = (u64::from(target) - done).min(u64::from(MAX_PASS_SPP)) as u32;
                match renderer.render(&specs, &settings, size.0, size.1, pass) {
                    Ok(t) => texture = Some(t.clone()),
                    Err(e) => {
                        self.render_error = Some(format!("{e:#}"));
                        return (None, false);
                    }
                }
                if let Err(e) = renderer.gpu().wait() {
                    self.render_error = Some(format!("{e:#}"));
                    return (None, false);
                }
            }
            let texture = match texture {
                Some(t) => t,
                None => match renderer.display(&settings, size.0, size.1) {
                    Ok(t) => t.clone(),
                    Err(e) => {
                        self.render_error = Some(format!("{e:#}"));
                        return (None, false);
                    }
                },
            };
            self.render_error = None;
            return (Some(self.image.id(&rs, &texture)), false);
        }
        let specs: Vec<ModelSpec> = drawables.iter().map(|d| d.spec.clone()).collect();
        let settings = Self::settings(env, turn_deg);
        let restart = renderer.would_restart(&specs, &settings, size.0, size.1);
        let target = u64::from(env.target_spp.clamp(1, MAX_TARGET_SPP));
        let done = renderer.samples_per_pixel();
        let texture = if restart || done < target {
            if restart {
                self.gpu_error = None;
                self.restarts += 1;
                self.restarted_at = Some(Instant::now());
                self.converged_after = None;
            }
            // One sample right after a restart and while something is being
            // dragged (the picture follows the pointer); otherwise as many as
            // fit the per-frame budget at the measured cost.
            self.pass_spp = match self.spp_cost {
                Some(c) if !restart && !interacting && c > 0.0 => {
                    ((PASS_BUDGET_S / c).floor() as u32).clamp(1, self.max_pass)
                }
                _ => 1,
            };
            let left = if restart { target } else { target - done };
            let pass = u64::from(self.pass_spp).min(left).max(1) as u32;
            let t0 = Instant::now();
            match renderer.render(&specs, &settings, size.0, size.1, pass) {
                Ok(t) => {
                    let t = t.clone();
                    // Wait for the pass to measure its cost (the frame would
                    // wait for it anyway before it can be shown).
                    if renderer.gpu().wait().is_ok() {
                        let c = t0.elapsed().as_secs_f64() / f64::from(pass);
                        self.spp_cost = Some(match self.spp_cost {
                            Some(old) => 0.6 * old + 0.4 * c,
                            None => c,
                        });
                    }
                    Some(t)
                }
                Err(e) => {
                    self.render_error = Some(format!("{e:#}"));
                    return (None, false);
                }
            }
        } else {
            let shown = Shown {
                specs: specs.clone(),
                settings,
                size,
                samples: done,
            };
            if self.shown.as_ref() == Some(&shown) {
                return (self.image.current(), false);
            }
            match renderer.display(&settings, size.0, size.1) {
                Ok(t) => Some(t.clone()),
                Err(e) => {
                    self.render_error = Some(format!("{e:#}"));
                    return (None, false);
                }
            }
        };
        self.render_error = None;
        let samples = renderer.samples_per_pixel();
        if samples >= target && self.converged_after.is_none() {
            self.converged_after = self.restarted_at.map(|t| t.elapsed().as_secs_f64());
        }
        self.shown = Some(Shown {
            specs,
            settings,
            size,
            samples,
        });
        let id = texture.map(|t| self.image.id(&rs, &t));
        (id, samples < target)
    }
}

/// Whether `path` names a map the view can load (by its extension).
pub fn is_environment_file(path: &std::path::Path) -> bool {
    ENVIRONMENT_FILES.accepts(path)
}

impl View for EnvironmentView {
    fn toolbar(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        let env = &scene.state.lighting.env;
        let mut next = env.clone();
        exposure_control(
            ui,
            crate::session::views::ENVIRONMENT.id,
            &mut next.exposure_ev,
        );
        tone_control(
            ui,
            crate::session::views::ENVIRONMENT.id,
            &mut next.tone_map,
        );
        egui::ComboBox::from_id_salt("bv env object")
            .selected_text(env.object.label())
            .width(60.0)
            .show_ui(ui, |ui| {
                for o in EnvObject::ALL {
                    ui.selectable_value(&mut next.object, o, o.label());
                }
            })
            .response
            .on_hover_text("Object under the environment")
            .widget_info(|| {
                egui::WidgetInfo::labeled(egui::Role::ComboBox, true, "environment object")
            });
        if env.object == EnvObject::Plane {
            let label = ui.label("eye");
            ui.add(
                egui::DragValue::new(&mut next.elevation_deg)
                    .speed(0.5)
                    .range(ELEVATION_RANGE.0..=ELEVATION_RANGE.1)
                    .suffix("°")
                    .fixed_decimals(0)
                    .update_while_editing(false),
            )
            .labelled_by(label.id)
            .on_hover_text(
                "The eye's elevation above the plane: 90° looks straight down \
                 (normal incidence), a few degrees is grazing",
            )
            .widget_info(|| {
                egui::WidgetInfo::labeled(egui::Role::SpinButton, true, "eye elevation")
            });
        }
        let label = ui.label("rot");
        let r = ui
            .add(
                egui::DragValue::new(&mut next.rotation_deg)
                    .speed(1.0)
                    .range(-180.0..=180.0)
                    .suffix("°")
                    .fixed_decimals(0)
                    .update_while_editing(false),
            )
            .labelled_by(label.id)
            .on_hover_text("Rotation of the environment about the vertical (double-click: 0)");
        r.widget_info(|| {
            egui::WidgetInfo::labeled(egui::Role::SpinButton, true, "environment rotation")
        });
        if r.double_clicked() {
            next.rotation_deg = 0.0;
        }
        arrangement_control(
            ui,
            crate::session::views::ENVIRONMENT.id,
            scene,
            &mut next.side_by_side,
            out,
        );
        // The map: a path field (Enter loads), the studio button.
        let edit = self
            .path_edit
            .get_or_insert_with(|| env.map.clone().unwrap_or_default());
        let r = ui.add(
            egui::TextEdit::singleline(edit)
                .hint_text("studio (built in) — .hdr/.exr path, or drop a file")
                .desired_width(150.0),
        );
        r.widget_info(|| {
            egui::WidgetInfo::labeled(egui::Role::TextInput, true, "environment file")
        });
        let r = r.on_hover_text("Environment map (.hdr or .exr, equirectangular); Enter loads it");
        if r.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) {
            let t = edit.trim().to_string();
            next.map = if t.is_empty() { None } else { Some(t) };
        }
        if !r.has_focus() && next.map.clone().unwrap_or_default() != *edit {
            // Follow changes made elsewhere (a drop, the studio button).
            *edit = next.map.clone().unwrap_or_default();
        }
        if ui
            .small_button("open…")
            .on_hover_text("Choose a .hdr or .exr environment map")
            .clicked()
        {
            self.files
                .open((), "Open an environment map", ENVIRONMENT_FILES);
        }
        if let Some(((), path)) = self.files.show(ui.ctx()) {
            next.map = Some(path.display().to_string());
            self.path_edit = None;
        }
        if ui
            .small_button("studio")
            .on_hover_text("Back to the built-in studio environment")
            .clicked()
        {
            next.map = None;
            self.path_edit = Some(String::new());
        }
        if next != *env {
            out.push(Command::SetEnvView(next));
        }
    }

    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        let rect = ui.available_rect_before_wrap();
        if rect.width() < 8.0 || rect.height() < 8.0 {
            return;
        }
        let response = ui.allocate_rect(rect, Sense::hover());
        self.view_rect = Some(rect);
        let painter = ui.painter_at(rect);
        let backdrop = gpu_image::Backdrop::reserve(
            &painter,
            rect,
            (!scene.transparent).then_some(Color32::BLACK),
        );
        let weak = ui.visuals().weak_text_color();
        let env = &scene.state.lighting.env;

        // Dropped .hdr/.exr files (anywhere in the window: this is the only
        // view that takes them).
        let dropped: Vec<PathBuf> = ui.ctx().input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .filter(|p| is_environment_file(p))
                .collect()
        });
        if let Some(p) = dropped.last() {
            let mut next = env.clone();
            next.map = Some(p.display().to_string());
            self.path_edit = None;
            out.push(Command::SetEnvView(next));
        }
        let hovering_file = ui.ctx().input(|i| {
            i.raw
                .hovered_files
                .iter()
                .any(|f| f.path.as_deref().is_some_and(is_environment_file))
        });

        if let Some(why) = gpu_image::unavailable(ui.ctx(), "The environment view") {
            gpu_image::unavailable_notice(&painter, rect, backdrop, &why, weak);
            return;
        }
        let (drawables, mut errors) =
            gpu_image::drawables(scene, env.side_by_side, &mut self.pack_check);
        let rs = gpu_image::render_state(ui.ctx());
        let software = rs.as_ref().is_some_and(gpu_image::is_software);
        let scale = self.choose_scale(
            rect,
            ui.ctx().pixels_per_point(),
            scene,
            &drawables,
            software,
        );
        self.scale_in_use = Some(scale);
        if let Some(rs) = &rs {
            self.image.set_filter(
                rs,
                if scale < 1.0 {
                    eframe::wgpu::FilterMode::Linear
                } else {
                    eframe::wgpu::FilterMode::Nearest
                },
            );
        }
        let size = gpu_image::pixel_size(rect, ui.ctx().pixels_per_point() * scale);
        let mut more = false;
        let mut covered = false;
        if !drawables.is_empty() {
            let mode = Mode {
                interacting: scene.interacting,
                figure: scene.figure,
                software,
                turn_deg: scene.state.display.turn_deg,
            };
            let (id, m) = self.step(ui, &drawables, env, size, mode);
            more = m;
            if let Some(id) = id {
                covered = true;
                painter.image(
                    id,
                    rect,
                    Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
                    Color32::WHITE,
                );
            }
        } else {
            // Still take a finished map load.
            if self.renderer.ready().is_some() {
                self.sync_map(ui.ctx(), &env.map);
            }
        }
        if !covered {
            backdrop.fill(&painter);
        }
        if more || self.loading.is_some() {
            ui.ctx().request_repaint();
        }
        self.busy = more || self.loading.is_some() || self.renderer.building();
        let (restarted, converged, pass, cost) = (
            self.restarted_at,
            self.converged_after,
            self.pass_spp,
            self.spp_cost,
        );
        if !scene.figure {
            response.on_hover_ui(|ui| {
                ui.label(format!(
                    "{} samples per pixel (one BRDF and one environment sample each, combined \
                 with the power heuristic); stops at {}.",
                    self.samples_per_pixel(),
                    env.target_spp
                ));
                match (converged, restarted) {
                    (Some(t), _) => ui.label(format!("Reached it {t:.1} s after the last change.")),
                    (None, Some(t)) => ui.label(format!(
                        "{:.1} s since the last change; {pass} samples per frame ({:.2} ms each).",
                        t.elapsed().as_secs_f64(),
                        cost.unwrap_or(0.0) * 1e3
                    )),
                    (None, None) => ui.label(""),
                };
                if software {
                    ui.label(
                        "Software renderer: accumulated at half the view's resolution \
                     (a quarter during a drag).",
                    );
                }
            });
        }
        if self.renderer.building() {
            gpu_image::centre_note(&painter, rect, "compiling the shaders…", weak);
        }
        if let Some(e) = self.error() {
            errors.push(e);
        }
        self.messages = errors.clone();

        // Overlays: sample count, map, labels, errors.
        let text = Color32::from_gray(235);
        let spp = self.samples_per_pixel();
        let mut status = format!("{spp} spp");
        if spp >= u64::from(env.target_spp) && !drawables.is_empty() {
            status.push_str(" · done");
        } else if self.pass_spp > 1 {
            status.push_str(&format!(" (+{} per frame)", self.pass_spp));
        }
        if !scene.figure {
            gpu_image::plate_text(
                &painter,
                rect.left_top() + Vec2::new(6.0, 6.0),
                Align2::LEFT_TOP,
                &status,
                text,
            );
            let map_name = match (&self.loading, &self.map_in_use) {
                (Some(l), _) => format!("loading {} …", l.path),
                (None, Some(p)) => std::path::Path::new(p)
                    .file_name()
                    .map(|f| f.to_string_lossy().to_string())
                    .unwrap_or_else(|| p.clone()),
                (None, None) => "studio (built in)".to_string(),
            };
            gpu_image::plate_text(
                &painter,
                rect.right_top() + Vec2::new(-6.0, 6.0),
                Align2::RIGHT_TOP,
                &{
                    let mut t = if env.object == EnvObject::Plane {
                        format!(
                            "{map_name} · rot {:.0}° · eye {:.0}° above the plane",
                            env.rotation_deg, env.elevation_deg
                        )
                    } else {
                        format!("{map_name} · rot {:.0}°", env.rotation_deg)
                    };
                    // A transmitting model's light is followed through
                    // the object: say how far.
                    if env.object != EnvObject::Plane
                        && drawables.iter().any(|d| d.brdf.brdf.transmits())
                    {
                        t.push_str(&format!(
                            "\nlight followed through the object, ≤ {} interfaces",
                            crate::gpu::env::MAX_BOUNCES
                        ));
                    }
                    t
                },
                text,
            );
        }
        let circle = gpu_image::sphere_circle(rect, drawables.len());
        for (k, d) in drawables.iter().enumerate() {
            let (c, r) = circle(k);
            let [cr, cg, cb] = d.brdf.rgb;
            // The plane's square, framed in the BRDF's colour: at a grazing
            // eye its sky merges with the background.
            if env.object == EnvObject::Plane {
                painter.rect_stroke(
                    egui::Rect::from_center_size(c, egui::vec2(2.0 * r, 2.0 * r)),
                    0.0,
                    egui::Stroke::new(2.0, Color32::from_rgb(cr, cg, cb)),
                    egui::StrokeKind::Outside,
                );
            }
            gpu_image::plate_text_within(
                &painter,
                egui::pos2(c.x, (c.y + r + 3.0).min(rect.max.y - 18.0)),
                Align2::CENTER_TOP,
                &d.brdf.label,
                Color32::from_rgb(cr, cg, cb),
                Some(gpu_image::sphere_tile_width(rect, drawables.len())),
            );
        }
        gpu_image::errors_and_empty(
            ui,
            &painter,
            rect,
            rect.min.y + 30.0,
            &errors,
            drawables.is_empty(),
        );
        if hovering_file {
            painter.rect_filled(rect, 0.0, Color32::from_black_alpha(120));
            painter.text(
                rect.center(),
                Align2::CENTER_CENTER,
                "drop to use as the environment",
                egui::FontId::proportional(16.0),
                text,
            );
        }
    }

    fn busy(&self) -> bool {
        Self::busy(self)
    }

    fn figure_error(&self) -> Option<String> {
        let messages = self.messages();
        if messages.is_empty() {
            self.error()
        } else {
            Some(messages.join("; "))
        }
    }

    /// Independent of the scene's light (issue 33: it draws with the light
    /// below the surface too).
    fn shows_light_below(&self) -> bool {
        true
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn software_figures_keep_to_their_sample_budget() {
        // The sizes of `bv render` (default, 1080p, the deck's 4K), small
        // ones and degenerate ones.
        for (w, h) in [
            (1600u64, 1200u64),
            (1920, 1080),
            (3840, 2160),
            (800, 600),
            (640, 480),
            (1, 1),
            (0, 0),
            (16384, 16384),
        ] {
            let pixels = w * h;
            let spp = figure_spp(1024, None, true, pixels);
            assert!(spp.is_power_of_two(), "{w}×{h}: {spp}");
            assert!((SOFTWARE_FIGURE_MIN_SPP..=SOFTWARE_FIGURE_MAX_SPP).contains(&spp));
            if spp > SOFTWARE_FIGURE_MIN_SPP {
                // Within the budget, and not half of what it allows.
                assert!(
                    pixels * u64::from(spp) <= SOFTWARE_FIGURE_SAMPLES,
                    "{w}×{h}"
                );
            }
            if spp < SOFTWARE_FIGURE_MAX_SPP {
                assert!(
                    pixels * u64::from(2 * spp) > SOFTWARE_FIGURE_SAMPLES,
                    "{w}×{h}"
                );
            }
            // A smaller target is kept; a GPU takes the target.
            assert_eq!(figure_spp(8, None, true, pixels), 8);
            assert_eq!(figure_spp(1024, None, false, pixels), 1024);
        }
        assert_eq!(figure_spp(1024, None, true, 1600 * 1200), 64);
        assert_eq!(figure_spp(1024, None, true, 800 * 600), 256);
        assert_eq!(figure_spp(1024, None, true, 3840 * 2160), 32);
    }

    #[test]
    fn a_count_asked_for_is_honoured_exactly() {
        for software in [false, true] {
            for n in [1, 3, 100, 1000, 4096, MAX_TARGET_SPP] {
                assert_eq!(figure_spp(1024, Some(n), software, 3840 * 2160), n);
            }
            assert_eq!(figure_spp(1024, Some(0), software, 100), 1);
            assert_eq!(
                figure_spp(1024, Some(u32::MAX), software, 100),
                MAX_TARGET_SPP
            );
            assert_eq!(figure_spp(0, None, software, 100), 1);
        }
    }
}
