//! The directional albedo view: `ρhd(θi)` for every drawn BRDF, with its
//! error band, the energy-conservation line ρ = 1 and the current θi; the
//! legend gives each BRDF's bihemispherical albedo ρhh and the method behind
//! the numbers. The curves are [`crate::derive::albedo`]'s: a slider drag
//! shows the last finished curve (dashed) and a progress bar, and starts no
//! work until the pointer is released; figures compute them before drawing.

use super::BrdfColor as _;
use super::chart::{self, Band, Chart, Marker, Palette, Series};
use super::{Scene, SceneBrdf, View};
use crate::derive::albedo::{self, AlbedoData, BAND_SIGMAS};
use crate::session::command::Command;
use bv_core::mean_rgb;
use eframe::egui::{self, Ui};
use egui_plot::{Corner, FilledArea, HLine, Line, LineStyle, Plot, PlotPoints, VLine};
use std::sync::Arc;

/// The albedo view.
#[derive(Default)]
pub struct AlbedoView {
    /// Progress of the running computations, (done, total) steps, in the last
    /// frame (for tests and the progress bar).
    pub progress: Option<(usize, usize)>,
}

/// One BRDF's curve in a frame.
struct Shown {
    brdf: SceneBrdf,
    data: Arc<AlbedoData>,
    stale: bool,
}

impl AlbedoView {
    /// The curves to draw: computed now for a figure (or an SVG, `ctx`
    /// `None`), else the latest finished ones while jobs compute the current
    /// ones.
    fn update(&mut self, scene: &Scene<'_>, ctx: Option<&egui::Context>) -> Vec<Shown> {
        let mut shown = Vec::new();
        let mut done = 0;
        let mut total = 0;
        for b in &scene.brdfs {
            let (data, stale) = match ctx.filter(|_| !scene.figure) {
                None => (albedo::curve_now(scene, b), false),
                Some(ctx) => {
                    let s = albedo::curve(&super::waker(ctx), scene, b);
                    if s.busy || s.stale || s.done.is_none() {
                        total += albedo::STEPS;
                        done += s.progress.map_or(0, |p| p.0.min(albedo::STEPS));
                    }
                    match s.value() {
                        Some(v) => v,
                        None => continue,
                    }
                }
            };
            shown.push(Shown {
                brdf: b.clone(),
                data,
                stale,
            });
        }
        self.progress = (total > 0).then_some((done, total));
        shown
    }
}

fn legend_label(s: &Shown) -> String {
    let hh = &s.data.rho_hh;
    let err = mean_rgb(hh.allowance(BAND_SIGMAS));
    // Four decimals, or the error's own first digit when it is coarser.
    let err_text = if err < 5e-5 {
        format!("{:.0e}", err.max(1e-12))
    } else {
        format!("{err:.4}")
    };
    // The method, briefly: the band is the quadrature's error estimate, or
    // ±3 standard errors of Monte Carlo.
    let method = match s.data.method() {
        "quadrature" => "quad.".to_string(),
        _ => format!("MC ±{BAND_SIGMAS}σ"),
    };
    let mut l = format!(
        "{}: ρhh = {:.4} ± {err_text} {method}",
        s.brdf.label,
        mean_rgb(hh.value),
    );
    if s.data.exceeds_one() {
        l.push_str(" (ρhd > 1!)");
    }
    if s.stale {
        l.push_str(" (updating)");
    }
    l
}

fn y_top(shown: &[Shown]) -> f64 {
    let m = shown
        .iter()
        .flat_map(|s| (0..s.data.rho.len()).map(|k| s.data.mean_and_band(k)))
        .map(|(v, b)| v + b)
        .fold(0.0, f64::max);
    (m * 1.08).max(1.1)
}

/// The plot corner whose legend box covers the fewest curve points, given
/// the plot's size in points (the box's extent is estimated from the labels:
/// about 6.5 points per character plus the swatch, 18 points per line), in
/// the order of preference bottom right, top right, bottom left, top left.
fn legend_corner(shown: &[Shown], top: f64, size: egui::Vec2) -> Corner {
    let chars = shown
        .iter()
        .map(|s| legend_label(s).chars().count())
        .max()
        .unwrap_or(0);
    let w = ((chars as f32 * 6.5 + 30.0) / size.x.max(1.0)).min(1.0) as f64 * 90.0;
    let h = ((shown.len() as f32 * 18.0 + 12.0) / size.y.max(1.0)).min(1.0) as f64 * top;
    let boxes = [
        (Corner::RightBottom, 90.0 - w, 90.0, 0.0, h),
        (Corner::RightTop, 90.0 - w, 90.0, top - h, top),
        (Corner::LeftBottom, 0.0, w, 0.0, h),
        (Corner::LeftTop, 0.0, w, top - h, top),
    ];
    let covered = |(x0, x1, y0, y1): (f64, f64, f64, f64)| {
        shown
            .iter()
            .flat_map(|s| {
                (0..s.data.rho.len()).map(move |k| (s.data.theta_deg[k], s.data.mean_and_band(k).0))
            })
            .filter(|&(x, y)| (x0..=x1).contains(&x) && (y0..=y1).contains(&y))
            .count()
    };
    boxes
        .iter()
        .min_by_key(|b| covered((b.1, b.2, b.3, b.4)))
        .map_or(Corner::RightBottom, |b| b.0)
}

const Y_LABEL: &str = "ρhd (mean of r, g, b)";
const X_LABEL: &str = "θi (°)";

impl View for AlbedoView {
    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, _out: &mut Vec<Command>) {
        let dark = ui.visuals().dark_mode;
        let shown = self.update(scene, (!scene.figure).then(|| ui.ctx()));
        if let Some((done, total)) = self.progress
            && !scene.figure
        {
            ui.add(
                egui::ProgressBar::new(done as f32 / total.max(1) as f32)
                    .desired_height(12.0)
                    .text(format!("computing ρhd: {done}/{total} steps")),
            );
        }
        let top = y_top(&shown);
        let size = ui.available_size();
        let light = super::light_color(dark);
        let plot = super::with_legend(
            super::curves::with_linear_y(Plot::new(super::view_id(
                crate::session::views::ALBEDO.id,
            ))),
            size,
            shown.len(),
            legend_corner(&shown, top, size),
        )
        .width(size.x.max(50.0))
        .height(size.y.max(50.0))
        .x_axis_label(X_LABEL)
        .y_axis_label(Y_LABEL)
        .y_axis_min_width(36.0)
        .include_x(0.0)
        .include_x(90.0)
        .include_y(0.0)
        .include_y(top)
        .allow_scroll(false)
        .x_grid_spacer(egui_plot::uniform_grid_spacer(|_| [5.0, 15.0, 45.0]));
        let theta_i = scene.incident.theta_deg;
        plot.show(ui, |pui| {
            pui.hline(
                HLine::new("", 1.0)
                    .color(super::mirror_color(dark))
                    .style(LineStyle::Dashed { length: 6.0 })
                    .width(scene.stroke(1.2))
                    .allow_hover(false),
            );
            pui.vline(
                VLine::new("", theta_i)
                    .color(light)
                    .width(scene.stroke(1.5))
                    .allow_hover(false),
            );
            for s in &shown {
                let n = s.data.rho.len();
                let (mut lo, mut hi) = (Vec::with_capacity(n), Vec::with_capacity(n));
                for k in 0..n {
                    let (v, b) = s.data.mean_and_band(k);
                    lo.push(v - b);
                    hi.push(v + b);
                }
                pui.add(
                    FilledArea::new("", &s.data.theta_deg, &lo, &hi)
                        .fill_color(s.brdf.color().gamma_multiply(0.3)),
                );
                let pts: Vec<[f64; 2]> = (0..n)
                    .map(|k| [s.data.theta_deg[k], s.data.mean_and_band(k).0])
                    .collect();
                let mut line = Line::new(legend_label(s), PlotPoints::from(pts))
                    .color(s.brdf.color())
                    .width(scene.stroke(if s.brdf.selected { 2.5 } else { 1.8 }));
                if s.stale {
                    line = line.style(LineStyle::Dashed { length: 8.0 });
                }
                pui.line(line);
            }
        });
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn svg(&mut self, scene: &Scene<'_>, size: [f32; 2], dark: bool) -> Option<String> {
        let shown = self.update(scene, None);
        let top = y_top(&shown);
        let mut c = Chart {
            x_label: X_LABEL.into(),
            y_label: Y_LABEL.into(),
            x_range: (0.0, 90.0),
            y_range: (0.0, top),
            x_ticks: chart::angle_ticks(0.0, 90.0),
            y_ticks: chart::labelled(chart::nice_ticks(0.0, top, 8)),
            ..Default::default()
        };
        c.hlines.push(Marker {
            at: 1.0,
            color: super::mirror_color(dark),
            dashed: true,
            label: "ρ = 1".into(),
        });
        c.vlines.push(Marker {
            at: scene.incident.theta_deg,
            color: super::light_color(dark),
            dashed: false,
            label: "θi".into(),
        });
        for s in &shown {
            let n = s.data.rho.len();
            let mb: Vec<(f64, f64)> = (0..n).map(|k| s.data.mean_and_band(k)).collect();
            c.bands.push(Band {
                color: s.brdf.color().gamma_multiply(0.3),
                xs: s.data.theta_deg.clone(),
                lo: mb.iter().map(|(v, b)| v - b).collect(),
                hi: mb.iter().map(|(v, b)| v + b).collect(),
            });
            c.series.push(Series {
                label: legend_label(s),
                color: s.brdf.color(),
                points: (0..n).map(|k| [s.data.theta_deg[k], mb[k].0]).collect(),
                width: if s.brdf.selected { 2.5 } else { 1.8 },
                dash: None,
            });
        }
        Some(c.to_svg(size, Palette::new(dark, scene.transparent)))
    }
}
