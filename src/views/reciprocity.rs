//! The reciprocity map: for the current light direction ωi, the relative
//! reciprocity error `|f(ωi,ωo) − f(ωo,ωi)| / max f` over the outgoing
//! hemisphere, drawn on Lambert's azimuthal equal-area disc (centre: the
//! normal, rim: the horizon, equal areas are equal solid angles) with a
//! logarithmic colour bar from 1e-6 (`bv check`'s reciprocity threshold) to 1,
//! the worst value and where it is. Helmholtz reciprocity is the seed's BRDF
//! property 2: the classical Phong lobe (Phong 1975), which is cut by
//! `cos θi` differently on either side of the swap, lights up; the modified
//! Phong of Lewis (1994) stays dark.
//!
//! The map (`bv_core::analysis::reciprocity_map`) is of the selected BRDF
//! (else the first drawn), computed on a background thread and cached by the
//! BRDF's revision and ωi; figures compute it before drawing.

use super::{Scene, SceneBrdf, View, colormap};
use crate::derive::reciprocity::{self, Key};
use crate::session::command::Command;
use bv_core::analysis::reciprocity_map::{ReciprocityMap, hemisphere_to_disc};
use eframe::egui::{
    self, Align2, Color32, ColorImage, FontId, Pos2, Rect, Sense, Stroke, TextureHandle,
    TextureOptions, Ui, Vec2,
};
use glam::DVec3;
use std::sync::Arc;

/// The colour bar's lowest decade: `bv check`'s verdict threshold (values
/// below it are reciprocal to the check and drawn as the bottom colour).
pub const LOG_MIN: i32 = -6;
/// The colour bar's top decade (a relative difference is at most 1 for
/// non-negative values).
pub const LOG_MAX: i32 = 0;

/// The position of `v` on the colour bar, 0..1.
pub fn bar_position(v: f64) -> f32 {
    if v.is_nan() || v <= 0.0 {
        return 0.0;
    }
    let t = (v.log10() - LOG_MIN as f64) / (LOG_MAX - LOG_MIN) as f64;
    t.clamp(0.0, 1.0) as f32
}

/// The map's image: viridis of [`bar_position`], transparent outside the disc.
pub fn to_image(map: &ReciprocityMap) -> ColorImage {
    let pixels = map
        .values
        .iter()
        .map(|v| match v {
            Some(v) => colormap::viridis(bar_position(*v)),
            None => Color32::TRANSPARENT,
        })
        .collect();
    ColorImage::new([map.width, map.height], pixels)
}

/// The reciprocity-map view.
#[derive(Default)]
pub struct ReciprocityView {
    /// The map drawn in the last frame and whether it was of an older key.
    pub shown: Option<(Arc<ReciprocityMap>, bool)>,
    /// Where the disc was drawn in the last frame.
    pub disc_rect: Option<Rect>,
    texture: Option<(Key, TextureHandle)>,
    waiting: bool,
}

impl ReciprocityView {
    /// The map of `b` for this frame: computed now for a figure, else the
    /// latest finished one (with whether it is stale).
    fn map(
        &mut self,
        ctx: &egui::Context,
        scene: &Scene<'_>,
        b: &SceneBrdf,
    ) -> Option<(Key, Arc<ReciprocityMap>, bool)> {
        let shown = reciprocity::map(&super::waker(ctx), scene, b);
        self.waiting = shown.busy;
        let d = shown.done?;
        Some((d.key, d.value.clone(), shown.stale))
    }

    fn texture(&mut self, ctx: &egui::Context, key: Key, map: &ReciprocityMap) -> TextureHandle {
        if let Some((k, t)) = &self.texture
            && *k == key
        {
            return t.clone();
        }
        let t = ctx.load_texture("bv reciprocity map", to_image(map), TextureOptions::LINEAR);
        self.texture = Some((key, t.clone()));
        t
    }
}

/// The angles of a direction, degrees.
fn angles(w: DVec3) -> (f64, f64) {
    let (t, p) = bv_core::frame::to_spherical(w);
    (t.to_degrees(), p.to_degrees())
}

impl View for ReciprocityView {
    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, _out: &mut Vec<Command>) {
        let dark = ui.visuals().dark_mode;
        let text = super::strong_text(ui);
        let area = ui.available_rect_before_wrap();
        let (_, response) = ui.allocate_exact_size(area.size(), Sense::hover());
        let painter = ui.painter_at(area);
        let fill = super::figure_fill(ui, scene);
        if fill != Color32::TRANSPARENT {
            painter.rect_filled(area, 0.0, fill);
        }
        self.shown = None;
        self.disc_rect = None;
        let Some(b) = scene.primary().cloned() else {
            painter.text(
                area.center(),
                Align2::CENTER_CENTER,
                "no BRDF drawn",
                FontId::proportional(14.0),
                ui.visuals().weak_text_color(),
            );
            return;
        };
        let Some((key, map, stale)) = self.map(ui.ctx(), scene, &b) else {
            painter.text(
                area.center(),
                Align2::CENTER_CENTER,
                "computing the reciprocity map…",
                FontId::proportional(14.0),
                ui.visuals().weak_text_color(),
            );
            return;
        };
        self.shown = Some((map.clone(), stale));
        let font = FontId::proportional(12.0);
        let small = FontId::proportional(11.0);
        // Layout: title on top, the disc, the colour bar on its right, the
        // worst value below.
        let top = 30.0;
        let bar_w = 64.0;
        // A wide, low cell (the window's grid) puts the text beside the disc
        // rather than under it.
        let wide = area.width() > 2.2 * area.height();
        let bottom = if wide {
            0.0
        } else if scene.figure {
            22.0
        } else {
            40.0
        };
        let side = if wide {
            area.height() - top - 12.0
        } else {
            (area.width() - bar_w - 24.0).min(area.height() - top - bottom - 16.0)
        }
        .max(20.0);
        let left = if wide {
            area.left() + 16.0
        } else {
            area.left() + ((area.width() - bar_w - side) * 0.5).max(8.0)
        };
        let disc = Rect::from_min_size(Pos2::new(left, area.top() + top + 4.0), Vec2::splat(side));
        self.disc_rect = Some(disc);
        let (ti, pi) = (scene.incident.theta_deg, scene.incident.phi_deg);
        painter.text(
            Pos2::new(area.left() + 6.0, area.top() + 4.0),
            Align2::LEFT_TOP,
            format!(
                "{}: |f(ωi,ωo) − f(ωo,ωi)| / max f over ωo, θi {ti:.1}°, φi {pi:.1}°{}",
                b.label,
                if stale { " (updating)" } else { "" }
            ),
            font.clone(),
            text,
        );
        let tex = self.texture(ui.ctx(), key, &map);
        painter.image(
            tex.id(),
            disc,
            Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
            Color32::WHITE,
        );
        let c = disc.center();
        let r = side * 0.5;
        let grid = super::grid_color(dark);
        painter.circle_stroke(c, r, Stroke::new(1.5, text.gamma_multiply(0.7)));
        // θo = 30° and 60° on the equal-area disc: radius √(1 − cos θ).
        for deg in [30.0f64, 60.0] {
            let rr = (1.0 - deg.to_radians().cos()).sqrt() as f32 * r;
            painter.circle_stroke(c, rr, Stroke::new(1.0, grid));
        }
        painter.line_segment(
            [c - Vec2::new(r, 0.0), c + Vec2::new(r, 0.0)],
            Stroke::new(1.0, grid),
        );
        painter.line_segment(
            [c - Vec2::new(0.0, r), c + Vec2::new(0.0, r)],
            Stroke::new(1.0, grid),
        );
        painter.text(
            c + Vec2::new(r + 8.0, 0.0),
            Align2::CENTER_CENTER,
            "t",
            small.clone(),
            text,
        );
        painter.text(
            c - Vec2::new(0.0, r + 8.0),
            Align2::CENTER_CENTER,
            "b",
            small.clone(),
            text,
        );
        let to_screen = |w: DVec3| {
            let p = hemisphere_to_disc(w);
            c + Vec2::new(p.x as f32 * r, -p.y as f32 * r)
        };
        let wi = scene.wi();
        let light = super::light_color(dark);
        let mirror = DVec3::new(-wi.x, -wi.y, wi.z);
        painter.circle_stroke(
            to_screen(mirror),
            5.0,
            Stroke::new(1.5, super::mirror_color(dark)),
        );
        painter.circle_filled(to_screen(wi), 5.0, light);
        painter.circle_stroke(to_screen(wi), 5.0, Stroke::new(1.0, Color32::BLACK));
        // A cross only where something is above the bar's floor: the
        // "worst" of a reciprocal model is rounding noise at an arbitrary place.
        let floor = 10f64.powi(LOG_MIN);
        if let Some(w) = map.worst.filter(|w| w.value > floor) {
            let p = to_screen(w.wo);
            let s = Stroke::new(2.0, Color32::from_rgb(255, 60, 60));
            painter.line_segment([p - Vec2::splat(6.0), p + Vec2::splat(6.0)], s);
            painter.line_segment([p + Vec2::new(-6.0, 6.0), p + Vec2::new(6.0, -6.0)], s);
        }
        // The colour bar, log scale.
        let bar = Rect::from_min_max(
            Pos2::new(disc.right() + 24.0, disc.top()),
            Pos2::new(disc.right() + 38.0, disc.bottom()),
        );
        let steps = 64;
        for k in 0..steps {
            let t0 = k as f32 / steps as f32;
            let t1 = (k + 1) as f32 / steps as f32;
            let seg = Rect::from_min_max(
                Pos2::new(bar.left(), bar.bottom() - t1 * bar.height()),
                Pos2::new(bar.right(), bar.bottom() - t0 * bar.height()),
            );
            painter.rect_filled(seg, 0.0, colormap::viridis((t0 + t1) * 0.5));
        }
        painter.rect_stroke(
            bar,
            0.0,
            Stroke::new(1.0, text.gamma_multiply(0.6)),
            egui::StrokeKind::Outside,
        );
        for k in LOG_MIN..=LOG_MAX {
            let t = (k - LOG_MIN) as f32 / (LOG_MAX - LOG_MIN) as f32;
            let y = bar.bottom() - t * bar.height();
            painter.line_segment(
                [Pos2::new(bar.right(), y), Pos2::new(bar.right() + 4.0, y)],
                Stroke::new(1.0, text),
            );
            let label = if k == LOG_MIN {
                format!("≤{}", super::decade_label(k))
            } else {
                super::decade_label(k)
            };
            painter.text(
                Pos2::new(bar.right() + 6.0, y),
                Align2::LEFT_CENTER,
                label,
                small.clone(),
                text,
            );
        }
        // The worst value and where it is.
        let worst = match map.worst {
            Some(w) if w.value <= floor => format!(
                "worst {}: reciprocal to within {} everywhere; max f {} 1/sr",
                bv_core::text::fmt_value(w.value),
                super::decade_label(LOG_MIN),
                bv_core::text::fmt_value(map.max_f),
            ),
            Some(w) => {
                let (t, p) = angles(w.wo);
                format!(
                    "worst {} at θo {t:.1}°, φo {p:.1}° (×); max f {} 1/sr{}",
                    bv_core::text::fmt_value(w.value),
                    bv_core::text::fmt_value(map.max_f),
                    if map.non_finite > 0 {
                        format!("; {} non-finite", map.non_finite)
                    } else {
                        String::new()
                    }
                )
            }
            None => "no direction to compare".into(),
        };
        let text_at = if wide {
            Pos2::new(disc.right() + bar_w + 36.0, disc.top() + 8.0)
        } else {
            Pos2::new(area.left() + 6.0, disc.bottom() + 6.0)
        };
        // Beside the disc the text gets its own lines and wraps at the
        // view's edge (on one line it ran past it at 1920×1080).
        let worst = if wide {
            worst.replace("; ", "\n")
        } else {
            worst
        };
        let galley = painter.layout(
            worst,
            font.clone(),
            text,
            (area.right() - text_at.x - 6.0).max(80.0),
        );
        painter.galley(text_at, galley, text);
        if !scene.figure {
            let hover = response
                .hover_pos()
                .map(|p| ((p.x - c.x) / r, (c.y - p.y) / r))
                .filter(|(x, y)| x * x + y * y <= 1.0);
            let line = match hover {
                Some((x, y)) => {
                    let i = (((x + 1.0) * 0.5 * map.width as f32) as usize).min(map.width - 1);
                    let j = (((1.0 - y) * 0.5 * map.height as f32) as usize).min(map.height - 1);
                    match (map.direction(i, j), map.at(i, j)) {
                        (Some(w), Some(v)) => {
                            let (t, p) = angles(w);
                            format!(
                                "θo {t:.1}°, φo {p:.1}°: {}",
                                bv_core::text::fmt_value(v)
                            )
                        }
                        _ => String::new(),
                    }
                }
                None => "hover the disc to read a value; centre: normal, rim: horizon, equal areas: equal solid angles".into(),
            };
            painter.text(
                text_at + Vec2::new(0.0, 16.0),
                Align2::LEFT_TOP,
                line,
                small,
                ui.visuals().weak_text_color(),
            );
        }
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn busy(&self) -> bool {
        self.waiting
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bar_positions_by_decade() {
        assert_eq!(bar_position(0.0), 0.0);
        assert_eq!(bar_position(f64::NAN), 0.0);
        assert_eq!(bar_position(1e-9), 0.0);
        assert!((bar_position(1e-3) - 0.5).abs() < 1e-6);
        assert_eq!(bar_position(1.0), 1.0);
        assert_eq!(bar_position(3.0), 1.0);
    }
}
