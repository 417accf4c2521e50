//! The lecture's "Representations" slide made visible: the selected BRDF
//! tabulated over (θh, θd, φd) and factored into a sum of K products
//! `g_k(θh) · h_k(θd, φd)` by a truncated SVD per colour channel (Kautz &
//! McCool 1999, "Interactive rendering with arbitrary BRDFs using separable
//! approximations"; see [`bv_core::represent::factor`]).
//!
//! One chart holds the relative L2 error of the rank-K rebuild against K and,
//! beside it, the error of the spherical-harmonics representation against
//! the order L, measured over the same table cells
//! ([`bv_core::represent::sh_table`]); below it the first few factors: the
//! g_k as curves over θh, the h_k as small images over (θd, φd). The work is
//! done in the background (in steps, so that a browser page draws between
//! them) and cached by the BRDF's build revision;
//! figures compute it before drawing. Anisotropic models are refused with the
//! reason: the table has no φh axis.

use super::{Scene, SceneBrdf, View};
use crate::derive::factor::{self, Factored, ViewOutcome as Outcome};
use crate::session::command::Command;
use crate::session::state::Display;
use bv_core::measured::merl::theta_h_centre;
use bv_core::represent::sh;
use bv_core::represent::sh_table::{self};
use eframe::egui::{
    self, Align2, Color32, FontId, Mesh, Pos2, Rect, Sense, Shape, Stroke, Ui, UiBuilder, Vec2,
};
use egui_plot::{Corner, GridMark, Legend, Line, LineStyle, MarkerShape, Plot, PlotPoints, Points};

/// Factors drawn below the chart.
pub const SHOWN: usize = 3;

/// The colour channel whose factors are drawn (green: closest to luminance).
pub const CHANNEL: usize = 1;

/// Smallest error drawn on the log axis (a rebuild this good is exact for
/// the eye; 0 would be −∞).
const FLOOR: f64 = 1e-6;

/// The factorisation view.
#[derive(Default)]
pub struct FactorView {
    /// The data drawn in the last frame and whether it was of an older build.
    pub shown: Option<(Outcome, bool)>,
    /// The chart's series drawn in the last frame: name and points
    /// (K or L, log10 of the error).
    pub chart: Vec<(String, Vec<[f64; 2]>)>,
    waiting: bool,
}

impl FactorView {
    fn data(
        &mut self,
        ctx: &egui::Context,
        scene: &Scene<'_>,
        b: &SceneBrdf,
    ) -> Option<(Outcome, bool)> {
        let shown = factor::view_data(&super::waker(ctx), scene, b);
        self.waiting = shown.busy;
        shown.value()
    }
}

/// Colours of the SVD and SH series and of the factor curves.
fn palette(dark: bool) -> [Color32; 4] {
    if dark {
        [
            Color32::from_rgb(255, 184, 51),
            Color32::from_rgb(110, 190, 255),
            Color32::from_rgb(140, 220, 140),
            Color32::from_rgb(230, 130, 230),
        ]
    } else {
        [
            Color32::from_rgb(191, 97, 0),
            Color32::from_rgb(20, 100, 200),
            Color32::from_rgb(30, 140, 40),
            Color32::from_rgb(160, 40, 160),
        ]
    }
}

/// A diverging colour for `t` in [−1, 1]: blue below 0, red above, the
/// background's contrast colour at 0 (after Moreland's cool–warm map).
fn diverging(t: f32, dark: bool) -> Color32 {
    let t = t.clamp(-1.0, 1.0);
    let mid: [f32; 3] = if dark {
        [40.0, 40.0, 44.0]
    } else {
        [240.0, 240.0, 240.0]
    };
    let end: [f32; 3] = if t < 0.0 {
        [59.0, 110.0, 235.0]
    } else {
        [225.0, 50.0, 40.0]
    };
    let a = t.abs();
    let ch = |i: usize| (mid[i] + (end[i] - mid[i]) * a).round() as u8;
    Color32::from_rgb(ch(0), ch(1), ch(2))
}

/// The sign that makes the largest entry of `h_k` positive (an SVD's
/// factors are defined up to a joint sign; this keeps the drawing stable).
fn sign_of(f: &Factored, k: usize) -> f64 {
    let v = &f.fac.channels[CHANNEL].v[k];
    let big = v
        .iter()
        .copied()
        .fold(0.0f64, |m, x| if x.abs() > m.abs() { x } else { m });
    if big < 0.0 { -1.0 } else { 1.0 }
}

fn log_points(values: impl Iterator<Item = (f64, f64)>) -> Vec<[f64; 2]> {
    values.map(|(x, e)| [x, e.max(FLOOR).log10()]).collect()
}

/// Position of θh (degrees) on the g_k plot's axis: `√(θh / 90°) · 90`, the
/// table's own spacing (MERL's θh index is `√(θh / 90°)` times the cells),
/// so that the cells near the specular peak are not crowded into a corner.
fn sqrt_axis(theta_h_deg: f64) -> f64 {
    (theta_h_deg.max(0.0) / 90.0).sqrt() * 90.0
}

/// Decades of `|h_k|` the images shade (microfacet models grow like
/// 1/cos θi towards grazing, so a linear shade would show one bright row).
pub const DECADES: i32 = 4;

/// The image shade of `x` in [−1, 1]: its sign, and `log10 |x| / max`
/// mapped from −[`DECADES`] (0) to 0 (1).
fn log_colour(x: f64, max: f64) -> f32 {
    if !(max > 0.0 && x.is_finite()) || x == 0.0 {
        return 0.0;
    }
    let d = f64::from(DECADES);
    let t = ((x.abs() / max).log10() + d) / d;
    (t.clamp(0.0, 1.0) * x.signum()) as f32
}

/// One chart series: name, points, colour, dashed, marker.
type Series = (String, Vec<[f64; 2]>, Color32, bool, MarkerShape);

impl View for FactorView {
    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, _out: &mut Vec<Command>) {
        let dark = ui.visuals().dark_mode;
        let text = super::strong_text(ui);
        let weak = ui.visuals().weak_text_color();
        let area = ui.available_rect_before_wrap();
        let fill = super::figure_fill(ui, scene);
        if fill != Color32::TRANSPARENT {
            ui.painter().rect_filled(area, 0.0, fill);
        }
        self.shown = None;
        self.chart.clear();
        let font = FontId::proportional(13.0);
        let small = FontId::proportional(12.0);
        // A centred message, wrapped to the view's width.
        let message = |ui: &mut Ui, s: String, color: Color32| {
            let _ = ui.allocate_exact_size(area.size(), Sense::hover());
            let painter = ui.painter_at(area);
            let g = painter.layout(
                s,
                FontId::proportional(13.0),
                color,
                (area.width() - 12.0).max(40.0),
            );
            let pos = area.center() - g.size() * 0.5;
            painter.galley(pos, g, color);
        };
        let Some(b) = scene.primary().cloned() else {
            message(ui, "no BRDF drawn".into(), weak);
            return;
        };
        let Some((outcome, stale)) = self.data(ui.ctx(), scene, &b) else {
            message(ui, format!("factoring {}…", b.label), weak);
            return;
        };
        self.shown = Some((outcome.clone(), stale));
        let data = match outcome.as_ref() {
            Ok(d) => d,
            Err(e) => {
                message(ui, format!("{}: cannot factor: {e}", b.label), text);
                return;
            }
        };
        let fac = &data.factored.fac;
        if fac
            .channels
            .iter()
            .all(|c| c.sigma.first().is_none_or(|&s| s == 0.0))
        {
            message(
                ui,
                format!(
                    "{}: the table is 0 everywhere (a delta lobe has no finite value to tabulate)",
                    b.label
                ),
                text,
            );
            return;
        }
        let _ = ui.allocate_exact_size(area.size(), Sense::hover());
        let painter = ui.painter_at(area);
        let dims = fac.dims;
        let [c_svd, c_sh, c_2, c_3] = palette(dark);
        // Wrapped lines: at presentation scale the view is under 700 points wide.
        let wrap = (area.width() - 12.0).max(50.0);
        let mut y = area.top() + 4.0;
        let mut line = |s: String, font: FontId, color: Color32| {
            let g = painter.layout(s, font, color, wrap);
            let h = g.size().y;
            painter.galley(Pos2::new(area.left() + 6.0, y), g, color);
            y += h + 2.0;
        };
        line(
            format!(
                "{}: its {dims} table over (θh, θd, φd) factored per channel, \
                 f cos θi cos θo ≈ Σ_k g_k(θh) h_k(θd, φd){}",
                b.label,
                if stale { " (updating)" } else { "" }
            ),
            font.clone(),
            text,
        );
        let cols = dims.theta_d * dims.phi_d;
        line(
            format!(
                "Factored and compared as f cos θi cos θo (the reflected light: f grows like 1/cos θi \
                 at grazing). Beside it, SH of order L per θi ({n} incident directions). \
                 Error: |rebuilt − exact| / |exact| over the cells. Numbers kept per channel: \
                 K·({} + {cols}) for K terms, {n}·(L + 1)² for SH.",
                dims.theta_h,
                n = sh_table::VIEW_INCIDENT,
            ),
            small.clone(),
            weak,
        );
        let top = y + 2.0;
        let chart_h = ((area.bottom() - top) * 0.55).max(60.0);
        let chart = Rect::from_min_size(
            Pos2::new(area.left(), top),
            Vec2::new(area.width(), chart_h),
        );
        let by_k = |e: &[f64]| log_points(e.iter().enumerate().map(|(k, &e)| ((k + 1) as f64, e)));
        let by_l = |e: &[f64]| log_points(e.iter().enumerate().map(|(l, &e)| (l as f64, e)));
        let cosine = "f cos θi cos θo";
        let series: [Series; 2] = [
            (
                format!("SVD, K terms: {cosine}"),
                by_k(&data.svd_error.cosine),
                c_svd,
                false,
                MarkerShape::Circle,
            ),
            (
                format!("SH, order L: {cosine}"),
                by_l(&data.sh_error.cosine),
                c_sh,
                false,
                MarkerShape::Square,
            ),
        ];
        self.chart = series.iter().map(|s| (s.0.clone(), s.1.clone())).collect();
        let lowest = series
            .iter()
            .flat_map(|s| s.1.iter().map(|p| p[1]))
            .fold(0.0f64, f64::min)
            .floor()
            .min(-1.0);
        let stroke = scene.stroke(2.2);
        ui.scope_builder(UiBuilder::new().max_rect(chart), |ui| {
            Plot::new(super::view_id("factor errors"))
                .width(chart.width())
                .height(chart.height())
                .legend(Legend::default().position(Corner::LeftBottom))
                .x_axis_label("K (SVD terms)  ·  L (SH order)")
                .y_axis_label("relative L2 error")
                .y_axis_min_width(48.0)
                .include_x(0.0)
                .include_x(sh::MAX_ORDER as f64)
                .include_y(0.0)
                .include_y(lowest)
                .allow_scroll(false)
                .allow_drag(false)
                .allow_zoom(false)
                .x_grid_spacer(egui_plot::uniform_grid_spacer(|_| [1.0, 2.0, 4.0]))
                .y_axis_formatter(|mark, _| {
                    super::curves::decade_mark_label(mark.value, mark.step_size)
                        .map(super::decade_label)
                        .unwrap_or_default()
                })
                .y_grid_spacer(|input| {
                    super::curves::log_grid_marks(input.bounds, input.base_step_size)
                })
                .show(ui, |pui| {
                    for (name, pts, color, dashed, shape) in &series {
                        let line =
                            Line::new(name.clone(), PlotPoints::from(pts.clone())).color(*color);
                        pui.line(if *dashed {
                            line.style(LineStyle::Dashed { length: 10.0 })
                                .width(stroke * 0.7)
                        } else {
                            line.width(stroke)
                        });
                        pui.points(
                            Points::new(name.clone(), PlotPoints::from(pts.clone()))
                                .color(*color)
                                .shape(*shape)
                                .filled(!*dashed)
                                .radius(stroke * 1.8),
                        );
                    }
                });
        });
        // The factors: g_k curves (left), h_k images (right).
        let below = Rect::from_min_max(
            Pos2::new(area.left(), chart.bottom() + 8.0),
            area.right_bottom(),
        );
        if below.height() < 60.0 {
            return;
        }
        let shown = SHOWN.min(fac.terms());
        let f = &data.factored;
        let colors = [c_svd, c_2, c_3];
        let sigma1 = fac.channels[CHANNEL].sigma[0].max(f64::MIN_POSITIVE);
        let curves_rect =
            Rect::from_min_size(below.min, Vec2::new(below.width() * 0.42, below.height()));
        ui.scope_builder(UiBuilder::new().max_rect(curves_rect), |ui| {
            Plot::new(super::view_id("factor g"))
                .width(curves_rect.width())
                .height(curves_rect.height())
                .legend(Legend::default().position(Corner::RightTop))
                .x_axis_label("θh (°), square-root axis like the table's cells")
                .y_axis_label("g_k / σ_k (green)")
                .include_x(0.0)
                .include_x(90.0)
                .allow_scroll(false)
                .allow_drag(false)
                .allow_zoom(false)
                .x_grid_spacer(|_| {
                    [0.0, 1.0, 5.0, 10.0, 20.0, 45.0, 90.0]
                        .into_iter()
                        .map(|t| GridMark {
                            value: sqrt_axis(t),
                            step_size: 30.0,
                        })
                        .collect()
                })
                .x_axis_formatter(|mark, _| {
                    let t = (mark.value / 90.0).powi(2) * 90.0;
                    format!("{t:.0}")
                })
                .show(ui, |pui| {
                    for (k, &color) in colors.iter().enumerate().take(shown) {
                        let s = sign_of(f, k);
                        let pts: Vec<[f64; 2]> = (0..dims.theta_h)
                            .map(|ih| {
                                [
                                    sqrt_axis(theta_h_centre(ih, dims.theta_h).to_degrees()),
                                    s * fac.channels[CHANNEL].u[k][ih],
                                ]
                            })
                            .collect();
                        let ratio = fac.channels[CHANNEL].sigma[k] / sigma1;
                        pui.line(
                            Line::new(
                                format!(
                                    "g_{} (σ_{}/σ_1 = {})",
                                    k + 1,
                                    k + 1,
                                    bv_core::text::fmt_value(ratio)
                                ),
                                PlotPoints::from(pts),
                            )
                            .color(color)
                            .width(stroke),
                        );
                    }
                });
        });
        // h_k images: θd down (0° at the top), φd across (0°–180°).
        let img_area = Rect::from_min_max(
            Pos2::new(curves_rect.right() + 16.0, below.top()),
            below.right_bottom(),
        );
        let gap = 12.0;
        let label_h = 20.0;
        let w = ((img_area.width() - gap * (shown as f32 - 1.0)) / shown as f32).max(10.0);
        let h = (w * 0.5)
            .min(img_area.height() - 2.0 * label_h - 44.0)
            .max(10.0);
        let w = w.min(2.0 * h);
        for (k, &color) in colors.iter().enumerate().take(shown) {
            let r = Rect::from_min_size(
                Pos2::new(
                    img_area.left() + k as f32 * (w + gap),
                    img_area.top() + label_h,
                ),
                Vec2::new(w, h),
            );
            let s = sign_of(f, k);
            let v = &fac.channels[CHANNEL].v[k];
            let scale = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let mut mesh = Mesh::default();
            let (cw, ch) = (w / dims.phi_d as f32, h / dims.theta_d as f32);
            for id in 0..dims.theta_d {
                for ip in 0..dims.phi_d {
                    let t = log_colour(s * v[id * dims.phi_d + ip], scale);
                    let cell = Rect::from_min_size(
                        Pos2::new(r.left() + ip as f32 * cw, r.top() + id as f32 * ch),
                        Vec2::new(cw + 0.5, ch + 0.5),
                    );
                    mesh.add_colored_rect(cell, diverging(t, dark));
                }
            }
            painter.add(Shape::mesh(mesh));
            painter.rect_stroke(r, 0.0, Stroke::new(1.0, weak), egui::StrokeKind::Outside);
            painter.text(
                Pos2::new(r.left(), r.top() - 3.0),
                Align2::LEFT_BOTTOM,
                if w >= 110.0 {
                    format!("h_{}(θd, φd)", k + 1)
                } else {
                    format!("h_{}", k + 1)
                },
                font.clone(),
                color,
            );
        }
        let y = img_area.top() + label_h + h + 4.0;
        painter.text(
            Pos2::new(img_area.left(), y),
            Align2::LEFT_TOP,
            "across: φd 0–180°; down: θd 0–90° (green channel)",
            small.clone(),
            weak,
        );
        painter.text(
            Pos2::new(img_area.left(), y + 18.0),
            Align2::LEFT_TOP,
            format!("red > 0 > blue; shade: log10 |h_k| over the top {DECADES} decades"),
            small,
            weak,
        );
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn busy(&self) -> bool {
        self.waiting
    }
}

/// The most terms the view draws errors for (the overlay's limit).
pub const TERMS: u8 = Display::MAX_FACTOR_TERMS;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_shades_by_hand() {
        assert_eq!(log_colour(2.0, 2.0), 1.0);
        // 1/100 of the largest: two of four decades down.
        assert!((log_colour(-0.02, 2.0) + 0.5).abs() < 1e-6);
        assert_eq!(log_colour(1e-9, 2.0), 0.0);
        assert_eq!(log_colour(0.0, 0.0), 0.0);
        assert!((sqrt_axis(22.5) - 45.0).abs() < 1e-12);
    }

    #[test]
    fn diverging_map_ends_and_middle() {
        assert_eq!(diverging(0.0, false), Color32::from_rgb(240, 240, 240));
        assert_eq!(diverging(1.0, false), Color32::from_rgb(225, 50, 40));
        assert_eq!(diverging(-2.0, true), Color32::from_rgb(59, 110, 235));
    }
}
