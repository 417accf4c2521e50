//! The hemisphere view (LECTURE.md N4): each drawn BRDF's `f(ωi, ·)` (or
//! × cos θo with the display's cosine switch) over the outgoing hemisphere,
//! seen from above on Lambert's azimuthal equal-area disc (centre the
//! normal, rim the horizon, equal areas equal solid angles), one disc per
//! BRDF side by side, each on its own scale (viridis from 0 to its peak),
//! with the contour at half the peak, the mirror direction ωr marked and
//! the light's azimuth on the rim. The shapes the polar plot cannot show
//! read here: Phong's lobe is a circle about ωr, Blinn-Phong's an ellipse
//! narrowed out of the plane of incidence, an anisotropic lobe turns with
//! its tangent. The maps are `derive::hemi`'s.

use super::{BrdfColor, Scene, View, colormap};
use crate::derive::hemi::{self, CONTOUR, Hemi};
use crate::session::command::Command;
use bv_core::analysis::reciprocity_map::hemisphere_to_disc;
use eframe::egui::{
    self, Align2, Color32, ColorImage, FontId, Pos2, Rect, Sense, Stroke, TextureHandle,
    TextureOptions, Ui, Vec2,
};
use glam::DVec2;
use std::collections::HashMap;
use std::sync::Arc;

/// Most discs drawn (the first BRDFs of the list).
pub const MAX_DISCS: usize = 4;

/// The hemisphere view.
#[derive(Default)]
pub struct HemiView {
    textures: HashMap<u64, (hemi::Key, TextureHandle)>,
    busy: bool,
    /// The maps drawn in the last frame, by BRDF label (tests).
    pub shown: Vec<(String, Arc<Hemi>)>,
}

/// A map's image: viridis of value / peak, transparent outside the disc.
pub fn to_image(h: &Hemi) -> ColorImage {
    let peak = h.map.peak;
    let pixels = h
        .map
        .values
        .iter()
        .map(|v| match v {
            Some(v) if peak > 0.0 => colormap::viridis((v / peak) as f32),
            Some(_) => colormap::viridis(0.0),
            None => Color32::TRANSPARENT,
        })
        .collect();
    ColorImage::new([h.map.size, h.map.size], pixels)
}

impl HemiView {
    fn texture(&mut self, ctx: &egui::Context, id: u64, key: hemi::Key, h: &Hemi) -> TextureHandle {
        if let Some((k, t)) = self.textures.get(&id)
            && *k == key
        {
            return t.clone();
        }
        let t = ctx.load_texture(
            format!("bv hemisphere map {id}"),
            to_image(h),
            TextureOptions::LINEAR,
        );
        self.textures.insert(id, (key, t.clone()));
        t
    }
}

impl View for HemiView {
    fn toolbar(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        super::display_toggles(ui, scene, out);
    }

    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, _out: &mut Vec<Command>) {
        let dark = ui.visuals().dark_mode;
        let text = super::strong_text(ui);
        let area = ui.available_rect_before_wrap();
        ui.allocate_rect(area, Sense::hover());
        let painter = ui.painter_at(area);
        let fill = super::figure_fill(ui, scene);
        if fill != Color32::TRANSPARENT {
            painter.rect_filled(area, 0.0, fill);
        }
        self.shown.clear();
        self.busy = false;
        let brdfs: Vec<_> = scene.brdfs.iter().take(MAX_DISCS).collect();
        if brdfs.is_empty() {
            painter.text(
                area.center(),
                Align2::CENTER_CENTER,
                "no BRDF drawn",
                FontId::proportional(14.0),
                ui.visuals().weak_text_color(),
            );
            return;
        }
        let big = scene.presenting || area.height() > 500.0;
        // A small cell (the overview, a thumbnail) keeps the discs and
        // their names: no peak line, no explanatory footer.
        let tiny = !scene.presenting && (area.height() < 320.0 || area.width() < 360.0);
        let (title_size, small_size) = if big { (17.0, 14.0) } else { (13.0, 11.0) };
        let footer = if tiny {
            4.0
        } else if big {
            2.6 * small_size + 8.0
        } else {
            2.6 * small_size + 4.0
        };
        let n = brdfs.len() as f32;
        // Room between discs for the ωi label on the rim.
        let gap = 3.0 * small_size + 16.0;
        let cell_w = (area.width() - gap * (n + 1.0)) / n;
        let title_h = if tiny {
            1.3 * title_size
        } else {
            2.4 * title_size
        };
        let side = cell_w
            .min(area.height() - title_h - footer - 16.0)
            .max(20.0);
        let total_w = n * side + (n - 1.0) * gap;
        let left0 = area.left() + (area.width() - total_w) * 0.5;
        let top = area.top() + 8.0;
        let grid = super::grid_color(dark);
        let light = super::light_color(dark);
        let mirror = super::mirror_color(dark);
        let contour_col = if dark { Color32::WHITE } else { Color32::BLACK };
        let wi = scene.wi();
        let wr = glam::DVec3::new(-wi.x, -wi.y, wi.z);
        for (k, b) in brdfs.iter().enumerate() {
            let x0 = left0 + k as f32 * (side + gap);
            let shown = hemi::request(&super::waker(ui.ctx()), scene, b);
            self.busy |= shown.busy;
            let Some(done) = shown.done.clone() else {
                painter.text(
                    Pos2::new(x0 + side * 0.5, top + title_h + side * 0.5),
                    Align2::CENTER_CENTER,
                    "computing…",
                    FontId::proportional(small_size),
                    ui.visuals().weak_text_color(),
                );
                continue;
            };
            let h = done.value.clone();
            self.shown.push((b.label.clone(), h.clone()));
            painter.text(
                Pos2::new(x0 + side * 0.5, top),
                Align2::CENTER_TOP,
                &b.label,
                FontId::proportional(title_size),
                b.color(),
            );
            if !tiny {
                painter.text(
                    Pos2::new(x0 + side * 0.5, top + 1.2 * title_size),
                    Align2::CENTER_TOP,
                    format!(
                        "peak {} 1/sr{}",
                        super::curves::fmt_value(h.map.peak),
                        if shown.stale { " (updating)" } else { "" }
                    ),
                    FontId::proportional(small_size),
                    text,
                );
            }
            let disc = Rect::from_min_size(Pos2::new(x0, top + title_h), Vec2::splat(side));
            let c = disc.center();
            let r = side * 0.5;
            let to_screen = |p: DVec2| c + Vec2::new(p.x as f32 * r, -p.y as f32 * r);
            let tex = self.texture(ui.ctx(), b.id, done.key, &h);
            painter.image(
                tex.id(),
                disc,
                Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
                Color32::WHITE,
            );
            painter.circle_stroke(c, r, Stroke::new(1.5, text.gamma_multiply(0.7)));
            // θo = 30° and 60°: radius √(1 − cos θ) on the equal-area disc.
            for deg in [30.0f64, 60.0] {
                let rr = (1.0 - deg.to_radians().cos()).sqrt() as f32 * r;
                painter.circle_stroke(c, rr, Stroke::new(1.0, grid));
            }
            // The half-maximum contour.
            let stroke = Stroke::new(scene.stroke(1.6), contour_col);
            for s in &h.contour {
                painter.line_segment([to_screen(s[0]), to_screen(s[1])], stroke);
            }
            // ωr: a ring with a cross; the light's azimuth: a dot on the rim.
            let pr = to_screen(hemisphere_to_disc(wr));
            let m = scene.stroke(6.0);
            painter.circle_stroke(pr, m, Stroke::new(scene.stroke(1.8), mirror));
            painter.line_segment(
                [pr - Vec2::new(m, 0.0), pr + Vec2::new(m, 0.0)],
                Stroke::new(scene.stroke(1.2), mirror),
            );
            painter.line_segment(
                [pr - Vec2::new(0.0, m), pr + Vec2::new(0.0, m)],
                Stroke::new(scene.stroke(1.2), mirror),
            );
            painter.text(
                pr + Vec2::new(m + 3.0, -m - 2.0),
                Align2::LEFT_BOTTOM,
                "ωr",
                FontId::proportional(small_size),
                mirror,
            );
            let az = DVec2::new(wi.x, wi.y);
            if az.length() > 1e-9 {
                let rim = to_screen(az.normalize());
                painter.circle_filled(rim, scene.stroke(5.0), light);
                let out = (rim - c).normalized() * (small_size + 4.0);
                painter.text(
                    rim + out,
                    Align2::CENTER_CENTER,
                    "ωi",
                    FontId::proportional(small_size),
                    light,
                );
            }
        }
        if tiny {
            return;
        }
        let ti = scene.incident.theta_deg;
        let value = if scene.state.display.cosine {
            "f · cos θo"
        } else {
            "f"
        };
        // Two lines, wrapped at the view's width.
        let note = format!(
            "{value} over the outgoing hemisphere from above, θi {ti:.0}° (equal-area disc: \
             equal areas are equal solid angles; rings at 30° and 60°). Each disc on its \
             own scale, 0 to its peak; line: {:.0} % of the peak",
            100.0 * CONTOUR
        );
        let galley = painter.layout(
            note,
            FontId::proportional(small_size),
            text,
            area.width() - 16.0,
        );
        let at = Pos2::new(
            area.center().x - galley.size().x * 0.5,
            area.bottom() - 4.0 - galley.size().y,
        );
        painter.galley(at, galley, text);
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn busy(&self) -> bool {
        self.busy
    }
}
