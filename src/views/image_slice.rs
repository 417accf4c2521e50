//! Image slice in half/difference angles (Rusinkiewicz 1998):
//! an image with θh on x (0–90°, optionally on a √θh axis, the spacing of the
//! MERL table's θh cells) and θd on y (0° at the bottom, 90° at the top) at a
//! chosen φd, φh = 0, for every drawn BRDF side by side, measured or analytic.
//! Exposure (EV) and gamma map `f` to the screen; "colour" shows the RGB
//! value, "luminance" its Rec. 709 luminance in grey. Pixels where either
//! direction is below the horizon (θh + θd > 90° at φd = 0) are hatched,
//! so a 0 of the model is never confused with "no such configuration".
//!
//! Residual mode shows instead, for each drawn BRDF but a chosen reference
//! (the data a model was fitted to), the relative error of its luminance
//! `(f − f_ref) / f_ref` over the same θh × θd grid on a diverging colour
//! map (blue: below the reference, red: above, grey: equal) with its legend:
//! where in angle a fit fails (Ngan et al. 2005, Fig. 4).
//!
//! The values of a slice are cached per BRDF, keyed by its revision, φd, the
//! axis and the resolution, so a frame evaluates at most one slice per BRDF
//! and only when one of those changed; a 256 × 256 slice is 65,536
//! evaluations, split across threads. The displayed colours are rebuilt only
//! when the display settings change.

use super::BrdfColor as _;
use super::{Scene, View, curves};
use crate::derive::slice::{
    self, SliceData, SliceKey, luminance, theta_d_at, theta_h_at, u_of_theta_h, value_at,
};
use crate::session::command::Command;
use bv_core::Rgb;
use eframe::egui::{
    self, Align2, Color32, ColorImage, FontId, Pos2, Rect, RichText, Role, Sense, Stroke,
    TextureHandle, TextureOptions, Ui, Vec2, WidgetInfo,
};
use std::collections::HashMap;
use std::sync::Arc;

/// Slice resolution at rest (θh columns, θd rows).
pub const IDLE_RESOLUTION: usize = 256;
/// Slice resolution while something is dragged.
pub const DRAG_RESOLUTION: usize = 128;

/// Smallest image side (points) worth drawing with its axes.
const MIN_TILE: f32 = 56.0;

/// Display settings of the view: the scene's (`plots.slice`), so that a
/// slide keeps its φd and exposure.
pub use crate::session::state::SliceSettings;

/// The colour of one pixel under the display settings.
pub fn display_color(
    v: Option<[f32; 3]>,
    s: &SliceSettings,
    hatch: (Color32, Color32),
    odd: bool,
) -> Color32 {
    let Some(c) = v else {
        return if odd { hatch.0 } else { hatch.1 };
    };
    let k = s.exposure_ev.exp2();
    let g = 1.0 / s.gamma.max(0.05);
    let level = |x: f64| -> u8 {
        let y = (k * x.max(0.0)).powf(g);
        (y.clamp(0.0, 1.0) * 255.0).round() as u8
    };
    if s.chroma {
        Color32::from_rgb(
            level(f64::from(c[0])),
            level(f64::from(c[1])),
            level(f64::from(c[2])),
        )
    } else {
        let y = level(luminance(c));
        Color32::from_rgb(y, y, y)
    }
}

/// The image of a slice.
pub fn to_image(d: &SliceData, s: &SliceSettings, dark: bool) -> ColorImage {
    let hatch = hatch_colors(dark);
    let mut pixels = Vec::with_capacity(d.width * d.height);
    for row in 0..d.height {
        for col in 0..d.width {
            // Diagonal hatching, 6 pixels per stripe at 256 px.
            let odd = ((row + col) * 256 / d.width.max(1) / 6) % 2 == 1;
            pixels.push(display_color(d.values[row * d.width + col], s, hatch, odd));
        }
    }
    ColorImage::new([d.width, d.height], pixels)
}

/// The image of a residual: `(f − f_ref) / f_ref` on the diverging map,
/// ±`range` at its ends; hatched below the horizon.
pub fn residual_image(e: &[Option<f64>], n: usize, range: f64, dark: bool) -> ColorImage {
    let hatch = hatch_colors(dark);
    let range = range.max(1e-6);
    let pixels = e
        .iter()
        .enumerate()
        .map(|(k, v)| match v {
            Some(x) => {
                super::colormap::cool_warm((0.5 + 0.5 * (x / range).clamp(-1.0, 1.0)) as f32)
            }
            None => {
                let (row, col) = (k / n.max(1), k % n.max(1));
                if ((row + col) * 256 / n.max(1) / 6) % 2 == 1 {
                    hatch.0
                } else {
                    hatch.1
                }
            }
        })
        .collect();
    ColorImage::new([n, e.len() / n.max(1)], pixels)
}

/// The two colours of the hatching below the horizon.
fn hatch_colors(dark: bool) -> (Color32, Color32) {
    if dark {
        (Color32::from_rgb(38, 44, 58), Color32::from_rgb(52, 60, 78))
    } else {
        (
            Color32::from_rgb(200, 206, 220),
            Color32::from_rgb(222, 227, 238),
        )
    }
}

struct Cached {
    key: SliceKey,
    data: Arc<SliceData>,
    texture: Option<(SliceSettings, bool, TextureHandle)>,
    /// The residual's image, for the reference's slice key.
    residual: Option<(SliceKey, SliceSettings, bool, TextureHandle)>,
}

/// Exact values at one hovered (θh, θd).
#[derive(Debug, Clone, PartialEq)]
pub struct SliceReadout {
    /// θh, degrees.
    pub theta_h_deg: f64,
    /// θd, degrees.
    pub theta_d_deg: f64,
    /// Per drawn BRDF: label, colour, `f` (None below the horizon).
    pub values: Vec<(String, Color32, Option<Rgb>)>,
}

/// The image slice view.
#[derive(Default)]
pub struct ImageSliceView {
    /// Display settings: the scene's `plots.slice` as last seen, with the
    /// toolbar's edits (sent back to the scene as a command).
    pub settings: SliceSettings,
    /// The scene's `plots.slice` when `settings` was last taken from it:
    /// a change of the scene (a slide, a loaded file, undo) replaces the
    /// view's settings, and only then.
    synced: Option<SliceSettings>,
    cache: HashMap<u64, Cached>,
    rebuilds: u64,
    /// The values under the pointer in the last frame.
    pub readout: Option<SliceReadout>,
    /// Where each BRDF's image was drawn in the last frame.
    pub image_rects: Vec<(u64, Rect)>,
    /// The reference residual mode drew against in the last frame.
    pub reference_id: Option<u64>,
}

impl ImageSliceView {
    /// The cached slice of BRDF `id` (what the view last drew).
    pub fn data(&self, id: u64) -> Option<&Arc<SliceData>> {
        self.cache.get(&id).map(|c| &c.data)
    }

    /// How many slices were evaluated since the view was created.
    pub fn rebuild_count(&self) -> u64 {
        self.rebuilds
    }

    /// The BRDFs this view shows (in residual mode, as residuals).
    fn shown<'s>(&self, scene: &'s Scene<'_>) -> Vec<&'s super::SceneBrdf> {
        let reference = self.reference(scene).map(|r| r.id);
        let shown: Vec<&super::SceneBrdf> = if self.settings.all {
            scene.brdfs.iter().collect()
        } else {
            scene.primary().into_iter().collect()
        };
        if self.settings.residual {
            shown
                .into_iter()
                .filter(|b| Some(b.id) != reference)
                .collect()
        } else {
            shown
        }
    }

    /// The reference of residual mode: the chosen BRDF if it is drawn, the
    /// first drawn one otherwise; `None` outside residual mode.
    pub fn reference<'s>(&self, scene: &'s Scene<'_>) -> Option<&'s super::SceneBrdf> {
        if !self.settings.residual {
            return None;
        }
        self.settings
            .reference
            .and_then(|id| scene.brdfs.iter().find(|b| b.id == id))
            .or_else(|| scene.brdfs.first())
    }

    /// The relative error of BRDF `id`'s cached slice against the
    /// reference's (what residual mode draws), if both are cached.
    pub fn residual(&self, id: u64, reference: u64) -> Option<Vec<Option<f64>>> {
        let (a, r) = (self.cache.get(&id)?, self.cache.get(&reference)?);
        Some(slice::relative_error(&a.data, &r.data))
    }

    /// Takes the scene's slice settings when they changed since last seen.
    fn sync(&mut self, scene: &Scene<'_>) {
        let saved = scene.state.plots.slice;
        if self.synced != Some(saved) {
            self.settings = saved;
            self.synced = Some(saved);
        }
    }

    /// Brings the cached slices up to date (at most one evaluation per BRDF)
    /// and drops those of BRDFs no longer shown.
    pub fn update(&mut self, scene: &Scene<'_>) {
        self.sync(scene);
        let resolution = if scene.interacting {
            DRAG_RESOLUTION
        } else {
            IDLE_RESOLUTION
        };
        let mut shown = self.shown(scene);
        if let Some(r) = self.reference(scene) {
            shown.push(r);
        }
        for b in &shown {
            let key = SliceKey {
                revision: b.revision,
                phi_d_deg: self.settings.phi_d_deg,
                sqrt: self.settings.sqrt_theta_h,
                resolution,
            };
            if self.cache.get(&b.id).is_some_and(|c| c.key == key) {
                continue;
            }
            let data = slice::slice_now(b.id, key, &b.brdf);
            self.rebuilds += 1;
            self.cache.insert(
                b.id,
                Cached {
                    key,
                    data,
                    texture: None,
                    residual: None,
                },
            );
        }
        let ids: Vec<u64> = shown.iter().map(|b| b.id).collect();
        self.cache.retain(|id, _| ids.contains(id));
    }

    fn texture(&mut self, ctx: &egui::Context, id: u64, dark: bool) -> Option<TextureHandle> {
        let s = self.settings;
        if s.residual {
            return self.residual_texture(ctx, id, dark);
        }
        let c = self.cache.get_mut(&id)?;
        if let Some((ts, td, t)) = &c.texture
            && *ts == s
            && *td == dark
        {
            return Some(t.clone());
        }
        let img = to_image(&c.data, &s, dark);
        let t = ctx.load_texture(format!("bv slice {id}"), img, TextureOptions::NEAREST);
        c.texture = Some((s, dark, t.clone()));
        Some(t)
    }

    /// The residual image of BRDF `id` against the reference.
    fn residual_texture(
        &mut self,
        ctx: &egui::Context,
        id: u64,
        dark: bool,
    ) -> Option<TextureHandle> {
        let s = self.settings;
        let reference = self.reference_id?;
        let rkey = self.cache.get(&reference)?.key;
        if let Some((k, ts, td, t)) = &self.cache.get(&id)?.residual
            && *k == rkey
            && *ts == s
            && *td == dark
        {
            return Some(t.clone());
        }
        let e = self.residual(id, reference)?;
        let c = self.cache.get_mut(&id)?;
        let img = residual_image(&e, c.data.width, s.residual_range, dark);
        let t = ctx.load_texture(format!("bv residual {id}"), img, TextureOptions::NEAREST);
        c.residual = Some((rkey, s, dark, t.clone()));
        Some(t)
    }

    /// Sets the exposure so that the 99th percentile of the shown slices'
    /// luminance maps to white.
    fn fit_exposure(&self) -> Option<f64> {
        let q = self
            .cache
            .values()
            .map(|c| c.data.luminance_quantile(0.99))
            .fold(0.0, f64::max);
        (q > 0.0 && q.is_finite()).then(|| (-q.log2()).clamp(-20.0, 20.0))
    }
}

/// The legend of residual mode: the diverging colour bar from −range to
/// +range with its ticks, and what it shows.
fn residual_legend(painter: &egui::Painter, at: Pos2, width: f32, range: f64, text: Color32) {
    let bar_w = (width * 0.5).clamp(120.0, 320.0);
    let x0 = at.x + (width - bar_w) * 0.5;
    let bar = Rect::from_min_size(Pos2::new(x0, at.y + 6.0), Vec2::new(bar_w, 10.0));
    const STEPS: usize = 64;
    for k in 0..STEPS {
        let t0 = k as f32 / STEPS as f32;
        let t1 = (k + 1) as f32 / STEPS as f32;
        let seg = Rect::from_min_max(
            Pos2::new(bar.min.x + t0 * bar_w, bar.min.y),
            Pos2::new(bar.min.x + t1 * bar_w, bar.max.y),
        );
        painter.rect_filled(seg, 0.0, super::colormap::cool_warm((t0 + t1) * 0.5));
    }
    let small = FontId::proportional(11.0);
    let pct = range * 100.0;
    for (t, label) in [
        (0.0, format!("−{pct:.0} %")),
        (0.5, "0".to_string()),
        (1.0, format!("+{pct:.0} %")),
    ] {
        let x = bar.min.x + t * bar_w;
        painter.line_segment(
            [Pos2::new(x, bar.max.y), Pos2::new(x, bar.max.y + 3.0)],
            Stroke::new(1.0, text),
        );
        painter.text(
            Pos2::new(x, bar.max.y + 3.0),
            Align2::CENTER_TOP,
            label,
            small.clone(),
            text,
        );
    }
    painter.text(
        Pos2::new(bar.min.x - 8.0, bar.center().y),
        Align2::RIGHT_CENTER,
        "(f − f_ref) / f_ref",
        small.clone(),
        text,
    );
}

/// Where the tiles go: the largest square images that fit `n` in `area`,
/// each with room for its title and axes.
fn tiles(area: Rect, n: usize) -> Vec<Rect> {
    const LEFT: f32 = 40.0;
    const BOTTOM: f32 = 34.0;
    const TOP: f32 = 18.0;
    const RIGHT: f32 = 10.0;
    if n == 0 {
        return Vec::new();
    }
    let mut best = (0.0f32, 1usize);
    for cols in 1..=n {
        let rows = n.div_ceil(cols);
        let w = area.width() / cols as f32 - LEFT - RIGHT;
        let h = area.height() / rows as f32 - TOP - BOTTOM;
        let side = w.min(h);
        if side > best.0 {
            best = (side, cols);
        }
    }
    let (side, cols) = (best.0.max(8.0), best.1);
    let cell = Vec2::new(side + LEFT + RIGHT, side + TOP + BOTTOM);
    (0..n)
        .map(|k| {
            let (r, c) = (k / cols, k % cols);
            let min = area.min + Vec2::new(c as f32 * cell.x + LEFT, r as f32 * cell.y + TOP);
            Rect::from_min_size(min, Vec2::splat(side))
        })
        .collect()
}

impl ImageSliceView {
    /// The toolbar's widgets, editing `self.settings`.
    fn toolbar_widgets(&mut self, ui: &mut Ui, scene: &Scene<'_>) {
        let s = &mut self.settings;
        ui.spacing_mut().slider_width = 90.0;
        let row = crate::widgets::params_ui::slider_row(
            ui,
            super::view_id("image_slice").with("phi_d"),
            &mut s.phi_d_deg,
            0.0..=180.0,
            0.0..=180.0,
            false,
            "°",
            "φd",
        );
        row.track
            .on_hover_text("Difference azimuth φd of the slice (φh = 0)");
        if row.reset {
            s.phi_d_deg = SliceSettings::default().phi_d_deg;
        }
        if super::toolbar_toggle(
            ui,
            s.sqrt_theta_h,
            "√θh",
            "θh on a square-root axis, as the MERL table's cells: the specular peak gets room",
        ) {
            s.sqrt_theta_h = !s.sqrt_theta_h;
        }
        let r = ui
            .add(
                egui::DragValue::new(&mut s.exposure_ev)
                    .range(-20.0..=20.0)
                    .speed(0.05)
                    .fixed_decimals(1)
                    .prefix("EV ")
                    .update_while_editing(false),
            )
            .on_hover_text("Exposure: f × 2^EV before the gamma");
        r.widget_info(|| WidgetInfo::labeled(Role::SpinButton, true, "Exposure EV"));
        let r = ui
            .add(
                egui::DragValue::new(&mut s.gamma)
                    .range(1.0..=4.0)
                    .speed(0.01)
                    .fixed_decimals(2)
                    .prefix("γ ")
                    .update_while_editing(false),
            )
            .on_hover_text("Display gamma: level = (2^EV f)^(1/γ)");
        r.widget_info(|| WidgetInfo::labeled(Role::SpinButton, true, "Gamma"));
        let fit = self.fit_exposure();
        let s = &mut self.settings;
        if ui
            .add_enabled(fit.is_some(), egui::Button::new("fit"))
            .on_hover_text("Exposure that maps the 99th percentile of the shown slices to white")
            .clicked()
            && let Some(ev) = fit
        {
            s.exposure_ev = ev;
        }
        let label = if s.chroma { "colour" } else { "luminance" };
        if ui
            .selectable_label(s.chroma, label)
            .on_hover_text("Colour (RGB) or luminance (grey)")
            .clicked()
        {
            s.chroma = !s.chroma;
        }
        let label = if s.all { "all drawn" } else { "selected" };
        if ui
            .selectable_label(s.all, label)
            .on_hover_text("Every drawn BRDF side by side, or only the selected one")
            .clicked()
        {
            s.all = !s.all;
        }
        if super::toolbar_toggle(
            ui,
            s.residual,
            "residual",
            "Relative error (f − f_ref)/f_ref of each BRDF against a reference (the data a \
             model was fitted to)",
        ) {
            s.residual = !s.residual;
        }
        if s.residual {
            let current = self
                .reference(scene)
                .map_or_else(|| "(none)".to_string(), |b| b.label.clone());
            let mut chosen = None;
            egui::ComboBox::from_id_salt(super::view_id("image_slice").with("reference"))
                .selected_text(format!("vs {current}"))
                .show_ui(ui, |ui| {
                    for b in &scene.brdfs {
                        if ui.selectable_label(b.label == current, &b.label).clicked() {
                            chosen = Some(b.id);
                        }
                    }
                })
                .response
                .on_hover_text("The reference f_ref of the residuals")
                .widget_info(|| WidgetInfo::labeled(Role::ComboBox, true, "Residual reference"));
            let s = &mut self.settings;
            if chosen.is_some() {
                s.reference = chosen;
            }
            let mut pct = s.residual_range * 100.0;
            let r = ui
                .add(
                    egui::DragValue::new(&mut pct)
                        .range(1.0..=1000.0)
                        .speed(1.0)
                        .fixed_decimals(0)
                        .prefix("± ")
                        .suffix(" %")
                        .update_while_editing(false),
                )
                .on_hover_text("The relative error at the ends of the colour map");
            r.widget_info(|| WidgetInfo::labeled(Role::SpinButton, true, "Residual range"));
            s.residual_range = pct / 100.0;
        }
    }
}

impl View for ImageSliceView {
    fn toolbar(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        self.sync(scene);
        let before = self.settings;
        self.toolbar_widgets(ui, scene);
        if self.settings != before {
            out.push(Command::SetPlots(crate::session::state::PlotSettings {
                slice: self.settings,
                ..scene.state.plots
            }));
        }
    }

    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, _out: &mut Vec<Command>) {
        self.sync(scene);
        let readout_h = if scene.figure { 0.0 } else { 22.0 };
        let reference = self.reference(scene).cloned();
        self.reference_id = reference.as_ref().map(|r| r.id);
        // Residual mode: a band for the colour map's legend under the tiles.
        let legend_h = if reference.is_some() { 34.0 } else { 0.0 };
        let area = ui.available_rect_before_wrap();
        let area = Rect::from_min_max(area.min, area.max - Vec2::new(0.0, readout_h + legend_h));
        if area.width() < 40.0 || area.height() < 40.0 {
            return;
        }
        let response = ui.allocate_rect(area, Sense::hover());
        // The legend's band is the view's too: the readout goes below it.
        if legend_h > 0.0 {
            ui.allocate_rect(
                Rect::from_min_size(
                    Pos2::new(area.min.x, area.max.y),
                    Vec2::new(area.width(), legend_h),
                ),
                Sense::hover(),
            );
        }
        let dark = ui.visuals().dark_mode;
        let shown: Vec<super::SceneBrdf> = self.shown(scene).into_iter().cloned().collect();
        let rects = tiles(area, shown.len());
        if rects.first().is_some_and(|r| r.width() < MIN_TILE) {
            ui.painter_at(area).text(
                area.center(),
                Align2::CENTER_CENTER,
                "too small for the slices: maximise this view",
                FontId::proportional(12.5),
                ui.visuals().weak_text_color(),
            );
            self.image_rects.clear();
            self.readout = None;
            return;
        }
        self.update(scene);
        let painter = ui.painter_at(area);
        let text = super::strong_text(ui);
        let weak = ui.visuals().weak_text_color();
        let small = FontId::proportional(11.0);
        let grid = super::grid_color(dark);
        self.image_rects.clear();
        let s = self.settings;
        for (b, rect) in shown.iter().zip(&rects) {
            let Some(tex) = self.texture(ui.ctx(), b.id, dark) else {
                continue;
            };
            self.image_rects.push((b.id, *rect));
            painter.image(
                tex.id(),
                *rect,
                Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
                Color32::WHITE,
            );
            painter.rect_stroke(
                *rect,
                0.0,
                Stroke::new(1.0, grid),
                egui::StrokeKind::Outside,
            );
            let title = match &reference {
                Some(r) => format!("{} vs {}", b.label, r.label),
                None => b.label.clone(),
            };
            painter.text(
                rect.left_top() - Vec2::new(0.0, 3.0),
                Align2::LEFT_BOTTOM,
                title,
                FontId::proportional(12.5),
                b.color(),
            );
            // Axes: θh along the bottom, θd up the left side, ticks every
            // 15°, labels as dense as the tile allows.
            let label_step = if rect.width() >= 320.0 {
                15
            } else if rect.width() >= 150.0 {
                30
            } else {
                90
            };
            for deg in (0..=90).step_by(15) {
                let t = f64::from(deg).to_radians();
                let x = rect.min.x + u_of_theta_h(t, s.sqrt_theta_h) as f32 * rect.width();
                let y = rect.max.y - (f64::from(deg) / 90.0) as f32 * rect.height();
                let major = deg % 30 == 0;
                let labelled = deg % label_step == 0;
                let len = if major { 5.0 } else { 3.0 };
                painter.line_segment(
                    [Pos2::new(x, rect.max.y), Pos2::new(x, rect.max.y + len)],
                    Stroke::new(1.0, text),
                );
                painter.line_segment(
                    [Pos2::new(rect.min.x - len, y), Pos2::new(rect.min.x, y)],
                    Stroke::new(1.0, text),
                );
                if labelled {
                    painter.text(
                        Pos2::new(x, rect.max.y + 6.0),
                        Align2::CENTER_TOP,
                        format!("{deg}°"),
                        small.clone(),
                        text,
                    );
                }
                if labelled {
                    painter.text(
                        Pos2::new(rect.min.x - 7.0, y),
                        Align2::RIGHT_CENTER,
                        format!("{deg}°"),
                        small.clone(),
                        text,
                    );
                }
            }
            painter.text(
                Pos2::new(rect.center().x, rect.max.y + 19.0),
                Align2::CENTER_TOP,
                if s.sqrt_theta_h {
                    "θh (√ axis)"
                } else {
                    "θh"
                },
                small.clone(),
                weak,
            );
            // The θd title sits above its axis, clear of the tick labels.
            painter.text(
                Pos2::new(rect.min.x - 7.0, rect.min.y - 8.0),
                Align2::RIGHT_BOTTOM,
                "θd",
                small.clone(),
                weak,
            );
        }
        if reference.is_some() && !shown.is_empty() {
            residual_legend(
                &ui.painter_at(Rect::from_min_size(
                    Pos2::new(area.min.x, area.max.y),
                    Vec2::new(area.width(), legend_h),
                )),
                Pos2::new(area.min.x, area.max.y),
                area.width(),
                s.residual_range,
                text,
            );
        }
        if shown.is_empty() {
            painter.text(
                area.center(),
                Align2::CENTER_CENTER,
                if reference.is_some() {
                    "Residuals need a second drawn BRDF besides the reference"
                } else {
                    "No BRDF shown: add one on the left"
                },
                FontId::proportional(15.0),
                weak,
            );
        }

        // Exact values under the pointer.
        self.readout = None;
        if scene.figure {
            return;
        }
        if let Some(p) = response.hover_pos()
            && let Some((_, r)) = self.image_rects.iter().find(|(_, r)| r.contains(p))
        {
            let u = f64::from((p.x - r.min.x) / r.width());
            let v = f64::from((p.y - r.min.y) / r.height());
            let (th, td) = (theta_h_at(u, s.sqrt_theta_h), theta_d_at(v));
            let pd = s.phi_d_deg.to_radians();
            self.readout = Some(SliceReadout {
                theta_h_deg: th.to_degrees(),
                theta_d_deg: td.to_degrees(),
                values: shown
                    .iter()
                    .chain(reference.as_ref())
                    .map(|b| {
                        (
                            b.label.clone(),
                            b.color(),
                            value_at(b.brdf.as_ref(), th, td, pd),
                        )
                    })
                    .collect(),
            });
        }
        let secs = self
            .cache
            .values()
            .map(|c| c.data.seconds)
            .fold(0.0, f64::max);
        ui.horizontal_wrapped(|ui| {
            ui.spacing_mut().item_spacing.x = 10.0;
            match &self.readout {
                Some(r) => {
                    ui.label(
                        RichText::new(format!(
                            "θh = {:.1}°, θd = {:.1}°, φd = {:.0}°",
                            r.theta_h_deg, r.theta_d_deg, s.phi_d_deg
                        ))
                        .monospace(),
                    );
                    for (label, color, f) in &r.values {
                        let t = match f {
                            Some(f) => format!(
                                "{label}: ({}, {}, {})",
                                curves::fmt_value(f.x),
                                curves::fmt_value(f.y),
                                curves::fmt_value(f.z)
                            ),
                            None => format!("{label}: below the horizon"),
                        };
                        ui.label(RichText::new(t).color(*color).strong());
                    }
                    ui.weak("f in 1/sr");
                }
                None => {
                    ui.weak("hover to read f · hatched: below the horizon · φh = 0")
                        .on_hover_text(format!(
                            "{} × {} evaluations per slice; the last took {:.0} ms",
                            self.cache.values().next().map_or(0, |c| c.data.width),
                            self.cache.values().next().map_or(0, |c| c.data.height),
                            secs * 1e3
                        ));
                }
            }
        });
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
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn axes_are_inverse_and_sqrt_spreads_the_peak() {
        for sqrt in [false, true] {
            for u in [0.0, 0.1, 0.5, 1.0] {
                assert!((u_of_theta_h(theta_h_at(u, sqrt), sqrt) - u).abs() < 1e-12);
            }
        }
        // 10% of the √ axis reaches only 1% of 90°.
        assert!((theta_h_at(0.1, true) - 0.01 * FRAC_PI_2).abs() < 1e-12);
        assert_eq!(theta_d_at(0.0), FRAC_PI_2);
        assert_eq!(theta_d_at(1.0), 0.0);
    }

    #[test]
    fn exposure_gamma_and_luminance() {
        let s = SliceSettings {
            exposure_ev: 1.0,
            gamma: 1.0,
            ..Default::default()
        };
        let h = (Color32::RED, Color32::BLUE);
        // 2^1 · 0.25 = 0.5 → 128.
        assert_eq!(
            display_color(Some([0.25, 0.0, 1.0]), &s, h, false),
            Color32::from_rgb(128, 0, 255)
        );
        let g = SliceSettings { gamma: 2.0, ..s };
        assert_eq!(
            display_color(Some([0.125, 0.125, 0.125]), &g, h, false),
            Color32::from_rgb(128, 128, 128)
        );
        let l = SliceSettings { chroma: false, ..s };
        let c = display_color(Some([0.5, 0.0, 0.0]), &l, h, false);
        assert_eq!(c.r(), c.g());
        assert_eq!(c.r(), (0.2126f64 * 255.0).round() as u8);
        assert_eq!(display_color(None, &s, h, true), Color32::RED);
    }

    #[test]
    fn tiles_fit_and_do_not_overlap() {
        let area = Rect::from_min_size(Pos2::new(0.0, 0.0), Vec2::new(600.0, 300.0));
        for n in 1..6 {
            let t = tiles(area, n);
            assert_eq!(t.len(), n);
            for (i, a) in t.iter().enumerate() {
                assert!(area.contains_rect(*a), "{n} {a:?}");
                assert!((a.width() - a.height()).abs() < 1e-3);
                for b in &t[i + 1..] {
                    assert!(!a.intersects(*b));
                }
            }
        }
    }
}
