//! What the rendered views (lit sphere, environment) share: the wgpu device
//! they get from egui's render state, the registration of their offscreen
//! texture with egui, and the split of the drawn BRDFs into those the GPU can
//! draw and the messages for the others.
//!
//! The render state reaches the views through the egui context
//! ([`install`]), so that neither the [`super::Scene`] nor the viewer has to
//! carry it: eframe's window installs it at start-up, a test harness after
//! building. Without it (kittest without a renderer) the views say so and draw
//! nothing.

use super::{Scene, SceneBrdf};
use crate::gpu::env::Object;
use crate::gpu::shaders::ShaderLibrary;
use crate::gpu::specialised::Followed;
use crate::gpu::{Background, Gpu, ToneMap};
use crate::session::lighting::{BackgroundChoice, EnvObject, Tone};
use bv_core::ModelSpec;
use eframe::egui::{self, TextureId};
use eframe::egui_wgpu::RenderState;
use eframe::wgpu;

fn key() -> egui::Id {
    egui::Id::unique("bv wgpu render state")
}

fn lost_key() -> egui::Id {
    egui::Id::unique("bv wgpu device lost")
}

/// Why the device was lost, once it was (shared with its lost callback).
type Lost = std::sync::Arc<std::sync::Mutex<Option<String>>>;

/// Makes egui's render state (device, queue, renderer) available to the
/// rendered views of `ctx`, and notes when its device is lost (a browser
/// may take it back, e.g. when its GPU process restarts; every later buffer
/// the views create would then fail).
pub fn install(ctx: &egui::Context, render_state: &RenderState) {
    let lost: Lost = Default::default();
    let sink = lost.clone();
    let ctx2 = ctx.clone();
    render_state
        .device
        .set_device_lost_callback(move |reason, message| {
            // Dropping the device at exit reports a loss too: not news.
            if reason != wgpu::DeviceLostReason::Destroyed || crate::session::platform::WEB {
                if let Ok(mut l) = sink.lock() {
                    *l = Some(format!("{reason:?}: {message}"));
                }
                ctx2.request_repaint();
            }
        });
    ctx.data_mut(|d| {
        d.insert_temp(key(), render_state.clone());
        d.insert_temp(lost_key(), lost);
    });
}

/// Why a rendered view (`what`, e.g. "The lit sphere") cannot draw here, if
/// it cannot: no wgpu renderer, a device that was lost, or a device without
/// storage buffers (a browser's WebGL2, which the parameter tables and the
/// environment's sampling need).
pub fn unavailable(ctx: &egui::Context, what: &str) -> Option<String> {
    let Some(rs) = render_state(ctx) else {
        return Some(format!("{what} needs the wgpu renderer"));
    };
    if let Some(why) = device_lost(ctx) {
        return Some(format!(
            "{what} cannot draw: the GPU device was lost ({why}); reload the page"
        ));
    }
    if rs.device.limits().max_storage_buffers_per_shader_stage == 0 {
        return Some(format!(
            "{what} needs WebGPU\n(storage buffers); this\nbrowser gave WebGL2 only"
        ));
    }
    None
}

/// Whether the device draws but has no storage buffers (a browser's WebGL2):
/// the views whose shaders read the parameter tables from them draw on the
/// CPU or say that they need WebGPU.
pub fn lacks_storage_buffers(ctx: &egui::Context) -> bool {
    device_lost(ctx).is_none()
        && render_state(ctx)
            .is_some_and(|rs| rs.device.limits().max_storage_buffers_per_shader_stage == 0)
}

/// Why the device of `ctx`'s render state was lost, if it was.
pub fn device_lost(ctx: &egui::Context) -> Option<String> {
    let lost: Option<Lost> = ctx.data(|d| d.get_temp(lost_key()));
    lost.and_then(|l| l.lock().ok().and_then(|g| g.clone()))
}

/// The render state [`install`]ed into `ctx`, if any.
pub fn render_state(ctx: &egui::Context) -> Option<RenderState> {
    ctx.data(|d| d.get_temp::<RenderState>(key()))
}

/// Whether the adapter is a CPU (lavapipe, llvmpipe, WARP): the views then
/// trade resolution for speed where a GPU would not need to.
pub fn is_software(rs: &RenderState) -> bool {
    rs.adapter.get_info().device_type == wgpu::DeviceType::Cpu
}

/// The renderers' device, built from egui's.
pub fn gpu_of(rs: &RenderState) -> Gpu {
    Gpu::from_parts(rs.device.clone(), rs.queue.clone(), rs.adapter.get_info())
}

/// The composed shader library (built once per view; composition takes a
/// moment and the views create their pipelines once).
pub fn library() -> anyhow::Result<ShaderLibrary> {
    ShaderLibrary::new()
}

/// A renderer built on a worker thread: composing the shaders and, above
/// all, the driver's compilation of the pipelines (seconds for the
/// environment shader on lavapipe with a cold shader cache) must not freeze
/// the window.
///
/// A renderer's shaders are composed from the catalogue as it was when it
/// was built; when the catalogue changes (a user file opened or reloaded:
/// [`bv_core::registry::revision`]) it adopts the new one in place
/// ([`FollowsCatalogue`]: a saved file costs the compilation of its own
/// model's pipeline, a tenth of a second, not the whole renderer's), the
/// last working version drawn until the new pipelines arrive.
pub struct Deferred<T> {
    slot: Slot<T>,
    /// The catalogue revision the current slot was (or is being) built for.
    revision: u64,
    /// Counts the renderers that became ready.
    generation: u64,
}

impl<T> Default for Deferred<T> {
    fn default() -> Self {
        Self {
            slot: Slot::Empty,
            revision: 0,
            generation: 0,
        }
    }
}

/// A renderer that can adopt a changed catalogue without being built again.
pub trait FollowsCatalogue {
    /// Adopts the current catalogue: what changed.
    fn follow_catalogue(&mut self) -> Followed;

    /// Takes the pipelines compiled since for the new catalogue:
    /// `(arrived, waiting)`, whether what it draws changed, and whether more
    /// are still compiling.
    fn poll_pipelines(&mut self) -> (bool, bool);
}

impl FollowsCatalogue for crate::gpu::LitSphereRenderer {
    fn follow_catalogue(&mut self) -> Followed {
        self.follow_catalogue()
    }

    fn poll_pipelines(&mut self) -> (bool, bool) {
        self.poll_pipelines()
    }
}

impl FollowsCatalogue for crate::gpu::EnvRenderer {
    fn follow_catalogue(&mut self) -> Followed {
        self.follow_catalogue()
    }

    fn poll_pipelines(&mut self) -> (bool, bool) {
        self.poll_pipelines()
    }
}

#[derive(Default)]
enum Slot<T> {
    /// Not asked for yet.
    #[default]
    Empty,
    /// Being built.
    Building(std::sync::mpsc::Receiver<Result<T, String>>),
    /// Built.
    Ready(T),
    /// Building failed (the message says why).
    Failed(String),
}

impl<T: FollowsCatalogue + Send + 'static> Deferred<T> {
    /// Follows a catalogue that changed since the ready renderer was built,
    /// in place: `true` when what it draws changed, or will when its
    /// compiling pipelines arrive.
    fn follow_catalogue(&mut self) -> bool {
        let now = bv_core::registry::revision();
        let Slot::Ready(t) = &mut self.slot else {
            return false;
        };
        if self.revision == now {
            return false;
        }
        self.revision = now;
        let followed = t.follow_catalogue();
        // Stale pipelines draw what was drawn: nothing to draw again before
        // their replacements arrive.
        if followed.redraw {
            self.generation += 1;
        }
        followed.changed()
    }

    /// Takes the ready renderer's newly compiled pipelines (what it draws
    /// must be drawn again when some arrived); `true` while more compile.
    fn poll_pipelines(&mut self) -> bool {
        let Slot::Ready(t) = &mut self.slot else {
            return false;
        };
        let (arrived, waiting) = t.poll_pipelines();
        if arrived {
            self.generation += 1;
        }
        waiting
    }

    /// Starts `build` on a worker thread the first time, takes its result
    /// when it is there: `Ok(Some(_))` when ready (following a changed
    /// catalogue in place), `Ok(None)` while building (the worker asks `ctx`
    /// for a frame when it is done).
    pub fn poll(
        &mut self,
        ctx: &egui::Context,
        build: impl FnOnce() -> Result<T, String> + Send + 'static,
    ) -> Result<Option<&mut T>, String> {
        // Frames keep coming while new pipelines compile, to show them as
        // soon as they are there.
        let followed = self.follow_catalogue();
        if self.poll_pipelines() || followed {
            ctx.request_repaint_after(std::time::Duration::from_millis(15));
        }
        if matches!(self.slot, Slot::Empty) {
            self.revision = bv_core::registry::revision();
            let (tx, rx) = std::sync::mpsc::channel();
            let ctx2 = ctx.clone();
            let spawned = crate::session::platform::spawn("bv renderer build", move || {
                // The receiver is gone only if the view was dropped.
                let _ = tx.send(build());
                ctx2.request_repaint();
            });
            self.slot = match spawned {
                Ok(_) => Slot::Building(rx),
                Err(e) => Slot::Failed(format!("cannot start a worker thread: {e}")),
            };
        }
        if let Slot::Building(rx) = &self.slot {
            match rx.try_recv() {
                Ok(Ok(t)) => {
                    self.slot = Slot::Ready(t);
                    self.generation += 1;
                }
                Ok(Err(e)) => self.slot = Slot::Failed(e),
                Err(std::sync::mpsc::TryRecvError::Empty) => {}
                Err(std::sync::mpsc::TryRecvError::Disconnected) => {
                    self.slot = Slot::Failed("the renderer build stopped".into())
                }
            }
        }
        match &mut self.slot {
            Slot::Ready(t) => Ok(Some(t)),
            Slot::Failed(e) => Err(e.clone()),
            Slot::Empty | Slot::Building(_) => Ok(None),
        }
    }

    /// The value now: built on this thread if not asked for yet (or after a
    /// failure), waited for if a worker is building it, its pipelines for a
    /// changed catalogue waited for. For figures, which are drawn in one go.
    pub fn now(&mut self, build: impl FnOnce() -> Result<T, String>) -> Result<&mut T, String> {
        self.follow_catalogue();
        // A figure shows the new pipelines, not the stale ones.
        while self.poll_pipelines() {
            std::thread::sleep(std::time::Duration::from_millis(2));
        }
        if let Slot::Building(rx) = &self.slot {
            self.generation += 1;
            self.slot = match rx.recv() {
                Ok(Ok(t)) => Slot::Ready(t),
                Ok(Err(e)) => Slot::Failed(e),
                Err(_) => Slot::Empty,
            };
        }
        if !matches!(self.slot, Slot::Ready(_)) {
            self.revision = bv_core::registry::revision();
            self.generation += 1;
            self.slot = match build() {
                Ok(t) => Slot::Ready(t),
                Err(e) => Slot::Failed(e),
            };
        }
        match &mut self.slot {
            Slot::Ready(t) => Ok(t),
            Slot::Failed(e) => Err(e.clone()),
            Slot::Empty | Slot::Building(_) => Err("no renderer".into()),
        }
    }

    /// The built value, if ready.
    pub fn ready(&self) -> Option<&T> {
        match &self.slot {
            Slot::Ready(t) => Some(t),
            _ => None,
        }
    }

    /// The built value, if ready.
    pub fn ready_mut(&mut self) -> Option<&mut T> {
        match &mut self.slot {
            Slot::Ready(t) => Some(t),
            _ => None,
        }
    }

    /// Changes whenever what the renderer draws changed: a first build, a
    /// changed catalogue drawn from new code at once, or pipelines compiled
    /// for it arriving. What was drawn before must be drawn again.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Whether it is being built.
    pub fn building(&self) -> bool {
        matches!(self.slot, Slot::Building(_))
    }
}

/// An offscreen texture shown by egui: registered once, re-pointed when the
/// renderer replaces the texture (on a resize), freed with the view.
#[derive(Default)]
pub struct GpuImage {
    registered: Option<(TextureId, wgpu::Texture)>,
    render_state: Option<RenderState>,
    filter: Option<wgpu::FilterMode>,
}

impl GpuImage {
    /// Sets how egui samples the texture (nearest for an image at screen
    /// resolution, linear for one rendered smaller and stretched).
    pub fn set_filter(&mut self, rs: &RenderState, filter: wgpu::FilterMode) {
        if self.filter.unwrap_or(wgpu::FilterMode::Nearest) != filter {
            self.filter = Some(filter);
            if let Some((id, t)) = &self.registered {
                let view = t.create_view(&wgpu::TextureViewDescriptor::default());
                rs.renderer
                    .write()
                    .update_egui_texture_from_wgpu_texture(&rs.device, &view, filter, *id);
            }
        }
    }

    /// The egui id of `texture` (an `Rgba8Unorm` texture holding sRGB-encoded
    /// values: what egui-wgpu expects of a native texture).
    pub fn id(&mut self, rs: &RenderState, texture: &wgpu::Texture) -> TextureId {
        let view = || texture.create_view(&wgpu::TextureViewDescriptor::default());
        let filter = self.filter.unwrap_or(wgpu::FilterMode::Nearest);
        match &self.registered {
            Some((id, t)) if t == texture => *id,
            Some((id, _)) => {
                let id = *id;
                rs.renderer.write().update_egui_texture_from_wgpu_texture(
                    &rs.device,
                    &view(),
                    filter,
                    id,
                );
                self.registered = Some((id, texture.clone()));
                id
            }
            None => {
                let id = rs
                    .renderer
                    .write()
                    .register_native_texture(&rs.device, &view(), filter);
                self.registered = Some((id, texture.clone()));
                self.render_state = Some(rs.clone());
                id
            }
        }
    }

    /// The id of the texture registered last, if any.
    pub fn current(&self) -> Option<TextureId> {
        self.registered.as_ref().map(|(id, _)| *id)
    }
}

impl Drop for GpuImage {
    fn drop(&mut self) {
        if let (Some((id, _)), Some(rs)) = (&self.registered, &self.render_state) {
            rs.renderer.write().free_texture(id);
        }
    }
}

/// One BRDF the GPU can draw.
#[derive(Debug, Clone)]
pub struct Drawable {
    /// The scene's BRDF (label, colour, id).
    pub brdf: SceneBrdf,
    /// Its spec (what the renderers pack).
    pub spec: ModelSpec,
}

/// Whether each BRDF (by id and revision) packs for the GPU, remembered so
/// that a frame does not pack every model again (a measured model builds its
/// table lookup to pack).
#[derive(Default)]
pub struct PackCheck {
    known: std::collections::HashMap<u64, (u64, Result<(), String>)>,
}

impl PackCheck {
    fn check(&mut self, b: &SceneBrdf, spec: &ModelSpec) -> Result<(), String> {
        if let Some((rev, r)) = self.known.get(&b.id)
            && *rev == b.revision
        {
            return r.clone();
        }
        let mut scratch = Vec::new();
        let mut tables = crate::gpu::pack::Tables::default();
        let r = crate::gpu::pack::pack(spec, &mut scratch, &mut tables)
            .map(|_| ())
            .map_err(|e| format!("{}: {e:#}", b.label));
        self.known.insert(b.id, (b.revision, r.clone()));
        r
    }
}

/// The BRDFs a rendered view shows: every drawn one side by side, or only the
/// primary (selected) one; those the GPU cannot draw become messages.
pub fn drawables(
    scene: &Scene<'_>,
    side_by_side: bool,
    check: &mut PackCheck,
) -> (Vec<Drawable>, Vec<String>) {
    let primary = scene.primary().map(|b| b.id);
    let mut out = Vec::new();
    let mut errors = Vec::new();
    for b in &scene.brdfs {
        if !side_by_side && Some(b.id) != primary {
            continue;
        }
        let Some(entry) = scene.state.entry(b.id) else {
            continue;
        };
        match check.check(b, &entry.spec) {
            Ok(()) => out.push(Drawable {
                brdf: b.clone(),
                spec: entry.spec.clone(),
            }),
            Err(e) => errors.push(e),
        }
    }
    check
        .known
        .retain(|id, _| scene.brdfs.iter().any(|b| b.id == *id));
    (out, errors)
}

/// The size in physical pixels of a rectangle in points (at least 1×1).
pub fn pixel_size(rect: egui::Rect, pixels_per_point: f32) -> (u32, u32) {
    let w = (rect.width() * pixels_per_point).round().max(1.0) as u32;
    let h = (rect.height() * pixels_per_point).round().max(1.0) as u32;
    (w, h)
}

/// Centre and radius (points) of sphere `tile` of `tiles` in `rect` (the
/// geometry of `gpu::sphere`, its [`Grid`](crate::gpu::sphere::Grid), for
/// overlays and hit tests).
pub fn sphere_circle(rect: egui::Rect, tiles: usize) -> impl Fn(usize) -> (egui::Pos2, f32) {
    let size = glam::DVec2::new(rect.width().into(), rect.height().into());
    let grid = crate::gpu::sphere::Grid::new(tiles, size);
    move |tile| {
        let (c, r) = grid.circle(tile, size);
        (
            egui::pos2(rect.min.x + c.x as f32, rect.min.y + c.y as f32),
            r as f32,
        )
    }
}

/// The width (points) of one sphere's tile in `rect`: the room its label
/// may take.
pub fn sphere_tile_width(rect: egui::Rect, tiles: usize) -> f32 {
    let size = glam::DVec2::new(rect.width().into(), rect.height().into());
    let grid = crate::gpu::sphere::Grid::new(tiles, size);
    grid.tile_size(size).x as f32
}

/// What a view of the drawn BRDFs says when none is drawn.
pub const NOTHING_DRAWN: &str = "No BRDF shown: add one on the left";

/// A note in the middle of a view (its empty state, a renderer being built,
/// a device it cannot draw with), in the weak text colour.
pub fn centre_note(painter: &egui::Painter, rect: egui::Rect, text: &str, color: egui::Color32) {
    painter.text(
        rect.center(),
        egui::Align2::CENTER_CENTER,
        text,
        egui::FontId::proportional(14.0),
        color,
    );
}

/// The chrome the GPU image views share below their picture: the errors as
/// warning plates stacked from `top` down the left edge, and, when nothing
/// is drawn and nothing went wrong, [`NOTHING_DRAWN`] in the middle.
pub fn errors_and_empty(
    ui: &egui::Ui,
    painter: &egui::Painter,
    rect: egui::Rect,
    top: f32,
    errors: &[String],
    nothing_drawn: bool,
) {
    let mut y = top;
    for e in errors {
        let r = plate_text(
            painter,
            egui::pos2(rect.min.x + 6.0, y),
            egui::Align2::LEFT_TOP,
            e,
            ui.visuals().warn_fg_color,
        );
        y = r.max.y + 4.0;
    }
    if nothing_drawn && errors.is_empty() {
        centre_note(painter, rect, NOTHING_DRAWN, ui.visuals().weak_text_color());
    }
}

/// A GPU view that cannot draw on this device (see [`unavailable`]): its
/// backdrop filled and the reason in the middle.
pub fn unavailable_notice(
    painter: &egui::Painter,
    rect: egui::Rect,
    backdrop: Backdrop,
    why: &str,
    color: egui::Color32,
) {
    backdrop.fill(painter);
    centre_note(painter, rect, why, color);
}

/// Draws text on a translucent plate (messages over rendered images).
pub fn plate_text(
    painter: &egui::Painter,
    pos: egui::Pos2,
    align: egui::Align2,
    text: &str,
    color: egui::Color32,
) -> egui::Rect {
    plate_text_within(painter, pos, align, text, color, None)
}

/// [`plate_text`] on one line of at most `max_width` points (cut with "…"),
/// when given; the plate is kept inside the painter's clip rectangle, so a
/// label wider than its place is shortened rather than cut off at the edge.
pub fn plate_text_within(
    painter: &egui::Painter,
    pos: egui::Pos2,
    align: egui::Align2,
    text: &str,
    color: egui::Color32,
    max_width: Option<f32>,
) -> egui::Rect {
    let font = egui::FontId::proportional(12.5);
    let galley = match max_width {
        Some(w) => {
            let mut job = egui::text::LayoutJob::simple_singleline(text.to_string(), font, color);
            job.wrap = egui::text::TextWrapping::truncate_at_width((w - 8.0).max(8.0));
            painter.layout_job(job)
        }
        None => painter.layout(text.to_string(), font, color, 420.0),
    };
    let mut r = align.anchor_size(pos, galley.size());
    let clip = painter.clip_rect().shrink(3.0);
    if r.width() <= clip.width() {
        let dx = (clip.min.x - r.min.x).max(0.0) + (clip.max.x - r.max.x).min(0.0);
        r = r.translate(egui::vec2(dx, 0.0));
    }
    let plate = r.expand(3.0);
    painter.rect_filled(
        plate,
        3.0,
        egui::Color32::from_rgba_unmultiplied(0, 0, 0, 150),
    );
    painter.galley(r.min, galley, color);
    plate
}

/// A view's background under its GPU picture, painted only where no opaque
/// picture covers the rectangle (no renderer yet, the view unavailable, the
/// CPU fallback): on a software renderer a hidden fill costs as much as a
/// visible one. Its place is kept at the bottom of the view's shapes.
pub struct Backdrop {
    slot: egui::layers::ShapeIdx,
    rect: egui::Rect,
    /// `None` for a transparent figure.
    color: Option<egui::Color32>,
}

impl Backdrop {
    /// Keeps the bottom place of `painter`'s shapes for a fill of `rect`.
    pub fn reserve(
        painter: &egui::Painter,
        rect: egui::Rect,
        color: Option<egui::Color32>,
    ) -> Self {
        Self {
            slot: painter.add(egui::Shape::Noop),
            rect,
            color,
        }
    }

    /// Paints the background (nothing for a transparent figure).
    pub fn fill(&self, painter: &egui::Painter) {
        if let Some(c) = self.color {
            painter.set(self.slot, egui::Shape::rect_filled(self.rect, 0.0, c));
        }
    }
}

/// The background of the GPU views (the 3D lobe, the lit sphere, the
/// environment) in a theme, sRGB 0..1 with alpha.
pub fn view_background(dark: bool) -> [f32; 4] {
    if dark {
        [0.106, 0.11, 0.122, 1.0]
    } else {
        [0.985, 0.985, 0.985, 1.0]
    }
}

/// [`view_background`] without alpha.
pub fn theme_background(dark: bool) -> [f32; 3] {
    let b = view_background(dark);
    [b[0], b[1], b[2]]
}

/// The renderers' tone map for a saved choice.
pub fn tone_map(t: Tone) -> ToneMap {
    match t {
        Tone::None => ToneMap::None,
        Tone::Reinhard => ToneMap::Reinhard,
        Tone::Aces => ToneMap::Aces,
    }
}

/// The renderer's background for a saved choice; `theme` is the theme's view
/// colour (sRGB 0..1) and `pixels_per_point` scales the checker squares to 12
/// points.
pub fn background(b: BackgroundChoice, theme: [f32; 3], pixels_per_point: f32) -> Background {
    match b {
        BackgroundChoice::Theme => Background::Flat(theme),
        BackgroundChoice::Black => Background::Flat([0.0; 3]),
        // sRGB encoding of 18 % reflectance.
        BackgroundChoice::Grey => Background::Flat([0.4613; 3]),
        BackgroundChoice::White => Background::Flat([1.0; 3]),
        BackgroundChoice::Checker => Background::Checker {
            a: [0.32; 3],
            b: [0.55; 3],
            size: 12.0 * pixels_per_point,
        },
    }
}

/// The environment renderer's object for a saved choice.
pub fn env_object(o: EnvObject) -> Object {
    match o {
        EnvObject::Sphere => Object::Sphere,
        EnvObject::Torus => Object::Torus,
        EnvObject::Plane => Object::Plane,
    }
}
