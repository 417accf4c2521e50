//! The lit sphere view: every drawn BRDF on its own
//! orthographic sphere (or only the selected one), with a per-pixel normal and
//! a tangent frame whose tangent follows the parallels (so anisotropy shows),
//! lit by one directional light from the incident direction; exposure, sRGB
//! output, optional tone map and a choice of background. Drawing on a sphere
//! moves the light there.
//!
//! The light is the scene's incident direction expressed in view space. The
//! spheres' tangent frames are turned by π about each normal ([`FRAME_TURN`])
//! so that at the centre of a sphere t points left and b down, as the lobe
//! view's default camera and the polar plot show them: light at φi = 0 comes
//! from the left in every view. The centre pixel shows exactly
//! `f(ωi, n)·cos θi·E` for the (θi, φi) of the sliders, with irradiance E = 1.
//!
//! The image is rendered by [`crate::gpu::LitSphereRenderer`] at the view's
//! pixel size, and only when something it depends on changed (BRDF specs,
//! light, settings, size), so an idle or unrelated frame costs nothing. On a
//! software renderer a drag renders at half the resolution ([`DRAG_SCALE`]).
//! On a device without storage buffers (a browser's WebGL2), which the
//! shader's parameter tables need, the same picture is drawn on the CPU by
//! [`crate::gpu::lit_sphere::reference_image`], the twin the GPU renderer's
//! parity test holds it to, at most [`CPU_PIXELS`] pixels scaled up.

use super::gpu_image::{self, Deferred, Drawable, GpuImage, PackCheck};
use super::{Scene, View};
use crate::gpu::sphere::{light_from_drag, sphere_at};
use crate::gpu::{LitSphereRenderer, LitSphereSettings};
use crate::session::command::Command;
use crate::session::lighting::{BackgroundChoice, EV_RANGE, LitView, Tone};
use crate::session::platform::Instant;
use crate::session::state::Incident;
use bv_core::ModelSpec;
use eframe::egui::{self, Align2, Color32, Rect, Sense, Stroke, Ui, Vec2};
use glam::{DVec2, DVec3};

/// Resolution of the image while a pointer button is held, on a software
/// renderer (relative to the view's pixels).
pub const DRAG_SCALE: f32 = 0.5;

/// What a rendered frame depends on.
#[derive(Debug, Clone, PartialEq)]
struct FrameKey {
    specs: Vec<ModelSpec>,
    settings: LitSphereSettings,
    size: (u32, u32),
    /// Resolution relative to the view's pixels.
    scale: f32,
    /// Which renderer drew it (a rebuilt one draws a reloaded model anew).
    renderer: u64,
}

/// The lit sphere view.
#[derive(Default)]
pub struct LitSphereView {
    renderer: Deferred<LitSphereRenderer>,
    image: GpuImage,
    drawn: Option<FrameKey>,
    renders: u64,
    last_render_ms: f64,
    error: Option<String>,
    messages: Vec<String>,
    pack_check: PackCheck,
    /// Where the view was drawn in the last frame.
    pub view_rect: Option<Rect>,
    /// How many spheres the last frame showed.
    pub tiles: usize,
    /// The picture drawn on the CPU where the device cannot run the shader.
    cpu: CpuSphere,
}

/// Pixels of the CPU-drawn lit sphere at most (a quarter of that while
/// something is dragged; figures are drawn at their full size): one f64
/// evaluation a pixel, so this bounds a redraw's work whatever the view's
/// size, and egui scales the image up.
pub const CPU_PIXELS: f32 = 360_000.0;

/// The lit sphere drawn by [`crate::gpu::lit_sphere::reference_image`] (the
/// CPU twin the GPU renderer's parity test holds it to) into an egui texture,
/// drawn again only when the models, the settings or the size changed.
#[derive(Default)]
struct CpuSphere {
    drawn: Option<(Vec<ModelSpec>, LitSphereSettings, (u32, u32))>,
    texture: Option<egui::TextureHandle>,
}

impl CpuSphere {
    fn draw(
        &mut self,
        ctx: &egui::Context,
        scene: &Scene<'_>,
        drawables: &[Drawable],
        rect: Rect,
        dark: bool,
    ) -> Result<Option<egui::TextureId>, String> {
        if drawables.is_empty() {
            return Ok(None);
        }
        let ppp = ctx.pixels_per_point();
        let budget = if scene.interacting && !scene.figure {
            CPU_PIXELS / 4.0
        } else {
            CPU_PIXELS
        };
        let full = rect.width() * rect.height() * ppp * ppp;
        let scale = if scene.figure {
            1.0
        } else {
            (budget / full.max(1.0)).sqrt().min(1.0)
        };
        let size = gpu_image::pixel_size(rect, ppp * scale);
        let settings = LitSphereView::settings(scene, dark, ppp * scale);
        let specs: Vec<ModelSpec> = drawables.iter().map(|d| d.spec.clone()).collect();
        let key = (specs, settings, size);
        if self.drawn.as_ref() != Some(&key) || self.texture.is_none() {
            let img = crate::gpu::lit_sphere::reference_image(&key.0, &settings, size.0, size.1)
                .map_err(|e| format!("cannot draw the lit sphere on the CPU: {e}"))?;
            let image = egui::ColorImage::from_rgba_unmultiplied(
                [img.width() as usize, img.height() as usize],
                img.as_raw(),
            );
            let options = egui::TextureOptions::LINEAR;
            match &mut self.texture {
                Some(t) => t.set(image, options),
                None => {
                    self.texture = Some(ctx.load_texture("bv lit sphere (CPU)", image, options))
                }
            }
            self.drawn = Some(key);
        }
        Ok(self.texture.as_ref().map(egui::TextureHandle::id))
    }
}

impl LitSphereView {
    /// A view that creates its renderer on first use.
    pub fn new() -> Self {
        Self::default()
    }

    /// How many frames were rendered since the view was created (a frame is
    /// rendered only when something changed).
    pub fn render_count(&self) -> u64 {
        self.renders
    }

    /// CPU time of the last render call (recording and submitting), ms.
    pub fn last_render_ms(&self) -> f64 {
        self.last_render_ms
    }

    /// The messages the last frame showed (BRDFs the GPU cannot draw, errors).
    pub fn messages(&self) -> &[String] {
        &self.messages
    }

    /// Whether the renderer is still being built (shown last frame).
    pub fn busy(&self) -> bool {
        self.renderer.building() && self.view_rect.is_some()
    }

    /// Whether the renderer is ready (it is built on a worker thread).
    pub fn ready(&self) -> bool {
        self.renderer.ready().is_some()
    }

    /// The last error (renderer creation or rendering), if any.
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    /// The renderer's settings for the current scene.
    pub fn settings(scene: &Scene<'_>, dark: bool, pixels_per_point: f32) -> LitSphereSettings {
        let lit = scene.state.lighting.lit;
        LitSphereSettings {
            light: to_view(scene.wi()),
            irradiance: 1.0,
            exposure_ev: lit.exposure_ev,
            tone_map: gpu_image::tone_map(lit.tone_map),
            background: gpu_image::background(
                lit.background,
                gpu_image::theme_background(dark),
                pixels_per_point,
            ),
            turn: scene.state.display.turn_deg.to_radians() + FRAME_TURN,
        }
    }

    /// The GPU renderer's image of this frame (drawn again only when
    /// something it depends on changed).
    fn gpu_texture(
        &mut self,
        ui: &Ui,
        scene: &Scene<'_>,
        drawables: &[Drawable],
        rect: Rect,
        dark: bool,
    ) -> Option<egui::TextureId> {
        let ppp = ui.ctx().pixels_per_point();
        // While something is dragged on a software renderer, a quarter of the
        // pixels keeps the drag smooth; the full image follows on release. A
        // click that changes nothing keeps the image as it is.
        let rs = gpu_image::render_state(ui.ctx());
        let software = rs.as_ref().is_some_and(gpu_image::is_software);
        let scale = if software && scene.interacting && !scene.figure {
            let current = self.drawn.as_ref().map_or(1.0, |k| k.scale);
            let unchanged = self.drawn.as_ref().is_some_and(|k| {
                k.specs.len() == drawables.len()
                    && k.specs.iter().zip(drawables).all(|(a, b)| *a == b.spec)
                    && k.settings == Self::settings(scene, dark, ppp * current)
                    && k.size == gpu_image::pixel_size(rect, ppp * current)
            });
            if unchanged { current } else { DRAG_SCALE }
        } else {
            1.0
        };
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
        let size = gpu_image::pixel_size(rect, ppp * scale);
        let settings = Self::settings(scene, dark, ppp * scale);
        if drawables.is_empty() {
            return None;
        }
        self.render(ui, drawables, settings, size, scale, scene.figure)
    }

    /// Light drag: the light goes where the pointer is on the sphere.
    fn light_drag(
        &self,
        response: &egui::Response,
        rect: Rect,
        tiles: usize,
        out: &mut Vec<Command>,
    ) {
        if (response.dragged() || response.clicked())
            && tiles > 0
            && let Some(p) = response.interact_pointer_pos()
        {
            let local = p - rect.min;
            let dir = light_from_drag(
                DVec2::new(local.x.into(), local.y.into()),
                DVec2::new(rect.width().into(), rect.height().into()),
                tiles,
            );
            out.push(Command::SetIncident(Incident::from_direction(to_view(dir))));
        }
    }

    /// Renders the frame if anything changed; returns the egui texture.
    fn render(
        &mut self,
        ui: &Ui,
        drawables: &[Drawable],
        settings: LitSphereSettings,
        size: (u32, u32),
        scale: f32,
        figure: bool,
    ) -> Option<egui::TextureId> {
        let rs = gpu_image::render_state(ui.ctx())?;
        let gpu = gpu_image::gpu_of(&rs);
        let build = move || {
            gpu_image::library()
                .and_then(|mut lib| LitSphereRenderer::new(gpu, &mut lib))
                .map_err(|e| format!("cannot build the lit sphere renderer: {e:#}"))
        };
        let built = if figure {
            self.renderer.now(build).map(|_| Some(()))
        } else {
            self.renderer.poll(ui.ctx(), build).map(|r| r.map(|_| ()))
        };
        match built {
            Ok(Some(())) => {}
            Ok(None) => return None,
            Err(e) => {
                self.error = Some(e);
                return None;
            }
        }
        // Read after polling: pipelines that arrived in this poll are drawn
        // in this frame, not the next.
        let generation = self.renderer.generation();
        let renderer = self.renderer.ready_mut()?;
        let key = FrameKey {
            specs: drawables.iter().map(|d| d.spec.clone()).collect(),
            settings,
            size,
            scale,
            renderer: generation,
        };
        if self.drawn.as_ref() == Some(&key) {
            return self.image.current();
        }
        let t0 = Instant::now();
        match renderer.render(&key.specs, &settings, size.0, size.1) {
            Ok(texture) => {
                let texture = texture.clone();
                self.last_render_ms = t0.elapsed().as_secs_f64() * 1e3;
                self.renders += 1;
                self.drawn = Some(key);
                self.error = None;
                Some(self.image.id(&rs, &texture))
            }
            Err(e) => {
                self.error = Some(format!("{e:#}"));
                self.drawn = None;
                None
            }
        }
    }
}

impl View for LitSphereView {
    fn toolbar(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        let lit = scene.state.lighting.lit;
        let mut next = lit;
        exposure_control(ui, "lit", &mut next.exposure_ev);
        tone_control(ui, "lit", &mut next.tone_map);
        egui::ComboBox::from_id_salt("bv lit background")
            .selected_text(lit.background.label())
            .width(70.0)
            .show_ui(ui, |ui| {
                for b in BackgroundChoice::ALL {
                    ui.selectable_value(&mut next.background, b, b.label());
                }
            })
            .response
            .on_hover_text("Background behind the spheres")
            .widget_info(|| {
                egui::WidgetInfo::labeled(egui::Role::ComboBox, true, "lit sphere background")
            });
        arrangement_control(ui, "lit", scene, &mut next.side_by_side, out);
        if next != lit {
            out.push(Command::SetLitView(next));
        }
    }

    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        let rect = ui.available_rect_before_wrap();
        if rect.width() < 8.0 || rect.height() < 8.0 {
            return;
        }
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        self.view_rect = Some(rect);
        let dark = ui.visuals().dark_mode;
        let painter = ui.painter_at(rect);
        let [r, g, b] = gpu_image::theme_background(dark).map(|c| (c * 255.0).round() as u8);
        let backdrop = gpu_image::Backdrop::reserve(
            &painter,
            rect,
            (!scene.transparent).then_some(Color32::from_rgb(r, g, b)),
        );
        let weak = ui.visuals().weak_text_color();
        let text = super::strong_text(ui);

        let lit: LitView = scene.state.lighting.lit;
        let (drawables, mut errors) =
            gpu_image::drawables(scene, lit.side_by_side, &mut self.pack_check);
        self.tiles = drawables.len();
        // WebGL2 has no storage buffers: the same picture from bv-core's f64
        // models on the CPU.
        let on_cpu = gpu_image::lacks_storage_buffers(ui.ctx());
        if !on_cpu && let Some(why) = gpu_image::unavailable(ui.ctx(), "The lit sphere") {
            gpu_image::unavailable_notice(&painter, rect, backdrop, &why, weak);
            return;
        }
        let id = if on_cpu {
            self.cpu
                .draw(ui.ctx(), scene, &drawables, rect, dark)
                .unwrap_or_else(|e| {
                    errors.push(e);
                    None
                })
        } else {
            self.gpu_texture(ui, scene, &drawables, rect, dark)
        };
        if id.is_none() || on_cpu {
            backdrop.fill(&painter);
        }
        if let Some(id) = id {
            painter.image(
                id,
                rect,
                Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
                Color32::WHITE,
            );
            if on_cpu {
                painter.text(
                    rect.right_bottom() + Vec2::new(-6.0, -6.0),
                    Align2::RIGHT_BOTTOM,
                    "drawn on the CPU (WebGL2, not WebGPU)",
                    egui::FontId::proportional(11.0),
                    weak,
                );
            }
        }
        if let Some(e) = &self.error {
            errors.push(e.clone());
        }
        self.messages = errors.clone();

        self.light_drag(&response, rect, drawables.len(), out);

        if self.renderer.building() {
            painter.text(
                rect.center(),
                Align2::CENTER_CENTER,
                "compiling the shaders…",
                egui::FontId::proportional(14.0),
                weak,
            );
        }
        self.overlays(ui, rect, scene, &drawables, &errors, dark, text, weak);
        if let Some(p) = response.hover_pos().filter(|_| !scene.figure) {
            self.hover_value(ui, rect, p, scene, &drawables, text);
        }
    }

    fn busy(&self) -> bool {
        Self::busy(self)
    }

    fn figure_error(&self) -> Option<String> {
        let messages = self.messages();
        if messages.is_empty() {
            self.error().map(str::to_string)
        } else {
            Some(messages.join("; "))
        }
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

impl LitSphereView {
    #[allow(clippy::too_many_arguments)]
    fn overlays(
        &self,
        ui: &Ui,
        rect: Rect,
        scene: &Scene<'_>,
        drawables: &[Drawable],
        errors: &[String],
        dark: bool,
        text: Color32,
        weak: Color32,
    ) {
        let painter = ui.painter_at(rect);
        let circle = gpu_image::sphere_circle(rect, drawables.len());
        let wi = to_view(scene.wi());
        let light = super::light_color(dark);
        for (k, d) in drawables.iter().enumerate() {
            let (c, r) = circle(k);
            // The point the light shines straight onto (its normal is ωi).
            let at = c + Vec2::new(wi.x as f32, -wi.y as f32) * r;
            painter.circle_stroke(at, 5.0, Stroke::new(2.0, light));
            // An outline of the opposite shade, so that the ring reads on a
            // lit and on a black sphere alike.
            let outline = if dark {
                Color32::from_black_alpha(160)
            } else {
                Color32::from_white_alpha(200)
            };
            painter.circle_stroke(at, 6.5, Stroke::new(1.5, outline));
            painter.circle_stroke(at, 3.5, Stroke::new(1.0, outline));
            let [cr, cg, cb] = d.brdf.rgb;
            gpu_image::plate_text_within(
                &painter,
                egui::pos2(c.x, (c.y + r + 3.0).min(rect.max.y - 18.0)),
                Align2::CENTER_TOP,
                &d.brdf.label,
                Color32::from_rgb(cr, cg, cb),
                Some(gpu_image::sphere_tile_width(rect, drawables.len())),
            );
            // A mirror or smooth glass under a point light is black but for
            // one point: say why rather than show a black disc.
            if delta_only(d.brdf.brdf.as_ref()) {
                // The whole sentence where the sphere has room for it.
                let note = if r >= 110.0 {
                    "only δ lobes: a point light\nlights one direction, no pixel;\nsee the environment view"
                } else {
                    "only δ lobes"
                };
                gpu_image::plate_text(
                    &painter,
                    c + Vec2::new(0.0, 0.45 * r),
                    Align2::CENTER_CENTER,
                    note,
                    // On the plate's dark backing in either theme.
                    Color32::from_gray(235),
                );
            }
        }
        let lit = scene.state.lighting.lit;
        let status = format!(
            "θi {:.0}° φi {:.0}° · E = 1 · EV {:+.1} · {}",
            scene.incident.theta_deg,
            scene.incident.phi_deg,
            lit.exposure_ev,
            lit.tone_map.label()
        );
        if !scene.figure {
            painter.text(
                rect.left_top() + Vec2::new(6.0, 4.0),
                Align2::LEFT_TOP,
                status,
                egui::FontId::proportional(12.0),
                text,
            );
        }
        // The hint only where it clears the spheres' labels.
        let last = circle(drawables.len().saturating_sub(1));
        let below = rect.max.y - (last.0.y + last.1);
        if below > 44.0 && !scene.figure {
            painter.text(
                rect.left_bottom() + Vec2::new(6.0, -5.0),
                Align2::LEFT_BOTTOM,
                "drag on a sphere: move the light · ring: where the light is",
                egui::FontId::proportional(12.0),
                weak,
            );
        }
        gpu_image::errors_and_empty(
            ui,
            &painter,
            rect,
            rect.min.y + 24.0,
            errors,
            drawables.is_empty(),
        );
    }

    /// The radiance under the pointer, from bv-core in f64 (what the pixel
    /// shows before exposure and tone mapping).
    fn hover_value(
        &self,
        ui: &Ui,
        rect: Rect,
        p: egui::Pos2,
        scene: &Scene<'_>,
        drawables: &[Drawable],
        text: Color32,
    ) {
        let local = p - rect.min;
        let Some(s) = sphere_at(
            DVec2::new(local.x.into(), local.y.into()),
            DVec2::new(rect.width().into(), rect.height().into()),
            drawables.len(),
        ) else {
            return;
        };
        let Some(d) = drawables.get(s.tile) else {
            return;
        };
        // The shader's frame is turned by FRAME_TURN; the scene's BRDF
        // already carries the user's turn.
        let wi = to_view(s.to_local(to_view(scene.wi())));
        let wo = to_view(s.to_local(DVec3::Z));
        let l = if wi.z > 0.0 {
            d.brdf.brdf.eval(wi, wo) * wi.z
        } else {
            DVec3::ZERO
        };
        let painter = ui.painter_at(rect);
        gpu_image::plate_text(
            &painter,
            rect.right_bottom() + Vec2::new(-6.0, -6.0),
            Align2::RIGHT_BOTTOM,
            &format!(
                "L = f·cos θi·E = ({:.4}, {:.4}, {:.4})\nθi {:.1}°, θo {:.1}° in the local frame",
                l.x,
                l.y,
                l.z,
                wi.z.clamp(-1.0, 1.0).acos().to_degrees(),
                wo.z.clamp(-1.0, 1.0).acos().to_degrees()
            ),
            text,
        );
    }
}

/// The exposure control of a rendered view's toolbar ("EV", ±0.1 per step,
/// double-click resets to 0).
pub fn exposure_control(ui: &mut Ui, salt: &str, ev: &mut f64) {
    let label = ui.label("EV");
    let r = ui
        .add(
            egui::DragValue::new(ev)
                .speed(0.05)
                .range(EV_RANGE.0..=EV_RANGE.1)
                .fixed_decimals(1)
                .update_while_editing(false),
        )
        .labelled_by(label.id)
        .on_hover_text("Exposure in stops: radiance × 2^EV (double-click: 0)");
    r.widget_info(|| {
        egui::WidgetInfo::labeled(egui::Role::SpinButton, true, format!("{salt} exposure"))
    });
    if r.double_clicked() {
        *ev = 0.0;
    }
}

/// The tone map choice of a rendered view's toolbar.
pub fn tone_control(ui: &mut Ui, salt: &str, tone: &mut Tone) {
    let current = *tone;
    egui::ComboBox::from_id_salt(("bv tone", salt))
        .selected_text(match current {
            Tone::None => "clip",
            Tone::Reinhard => "Reinhard",
            Tone::Aces => "ACES",
        })
        .width(70.0)
        .show_ui(ui, |ui| {
            for t in Tone::ALL {
                ui.selectable_value(tone, t, t.label());
            }
        })
        .response
        .on_hover_text("Tone map after exposure (then sRGB encoding)")
        .widget_info(|| {
            egui::WidgetInfo::labeled(egui::Role::ComboBox, true, format!("{salt} tone map"))
        });
}

/// "all side by side" or one BRDF (the selected one; picking another selects it).
pub fn arrangement_control(
    ui: &mut Ui,
    salt: &str,
    scene: &Scene<'_>,
    side_by_side: &mut bool,
    out: &mut Vec<Command>,
) {
    let primary = scene.primary().map(|b| (b.id, b.label.clone()));
    let text = match (&primary, *side_by_side) {
        (_, true) | (None, _) => "all side by side".to_string(),
        (Some((_, l)), false) => l.clone(),
    };
    egui::ComboBox::from_id_salt(("bv arrangement", salt))
        .selected_text(text)
        .width(110.0)
        .show_ui(ui, |ui| {
            if ui
                .selectable_label(*side_by_side, "all side by side")
                .clicked()
            {
                *side_by_side = true;
            }
            for b in &scene.brdfs {
                let on = !*side_by_side && primary.as_ref().is_some_and(|(id, _)| *id == b.id);
                if ui.selectable_label(on, &b.label).clicked() {
                    *side_by_side = false;
                    out.push(Command::Select(b.id));
                }
            }
        })
        .response
        .on_hover_text("Every drawn BRDF side by side, or one at a time (the selected one)")
        .widget_info(|| {
            egui::WidgetInfo::labeled(egui::Role::ComboBox, true, format!("{salt} BRDFs shown"))
        });
}

/// The turn of the spheres' tangent frames about their normals (radians) on
/// top of the user's: t points left at a sphere's centre (see the module
/// doc).
pub const FRAME_TURN: f64 = std::f64::consts::PI;

/// A direction in the sphere centre's shading frame (turned by
/// [`FRAME_TURN`]) in view space, and back: the turn by π negates x and y,
/// and is its own inverse.
pub fn to_view(w: DVec3) -> DVec3 {
    DVec3::new(-w.x, -w.y, w.z)
}

/// Whether `b` scatters only through delta lobes (a smooth mirror or glass):
/// it has delta lobes and its finite part is 0 at a spread of direction
/// pairs, so that a point light lights none of the sphere's pixels.
pub fn delta_only(b: &dyn bv_core::Brdf) -> bool {
    let n = glam::DVec3::Z;
    if b.deltas(n).is_empty() {
        return false;
    }
    let dirs = [
        n,
        glam::DVec3::new(0.6, 0.0, 0.8),
        glam::DVec3::new(-0.3, 0.5, 0.81),
        glam::DVec3::new(0.0, -0.95, 0.312),
    ];
    dirs.iter().all(|&wi| {
        dirs.iter()
            .all(|&wo| b.eval(wi.normalize(), wo.normalize()).max_element() == 0.0)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_pure_delta_models_are_delta_only() {
        let b = |id: &str, p: serde_json::Value| {
            bv_core::ModelSpec::from_json(id, &p)
                .unwrap()
                .build()
                .unwrap()
        };
        assert!(delta_only(b("mirror", serde_json::json!({})).as_ref()));
        assert!(delta_only(b("glass", serde_json::json!({})).as_ref()));
        assert!(!delta_only(b("lambert", serde_json::json!({})).as_ref()));
        let half = serde_json::json!({"components": [
            {"weight": 0.5, "model": "mirror"},
            {"weight": 0.5, "model": "lambert"}]});
        assert!(!delta_only(b("mix", half).as_ref()));
    }
}
