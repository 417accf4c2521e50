//! The directional albedo view: `ρhd(θi)` for every drawn BRDF, with its
//! error band, the energy-conservation line ρ = 1 and the current θi; the
//! legend gives each BRDF's bihemispherical albedo ρhh and the method behind
//! the numbers. The curves are [`crate::derive::albedo`]'s: a slider drag
//! shows the last finished curve (dashed) and a progress bar, and starts no
//! work until the pointer is released; figures compute them before drawing.
//!
//! A transmitting model (issue 33) is plotted over θi 0°..180° (light from
//! below beyond 90°, the surface marked): ρR dashed, ρT dotted and their sum
//! solid in its colour. For a non-absorbing dielectric the sum would be 1
//! with every bounce counted; what it lacks is the energy a single-scattering
//! microfacet BSDF loses (the white furnace test).
//!
//! The *furnace* switch (`plots.albedo.furnace`, in the toolbar and in
//! scene files) plots, for every microfacet model shown, the albedo `E(θi)`
//! of its lobe with F = 1, kd = 0, ks = 1 (solid) and the energy single
//! scattering loses, `1 − E` (dashed; Kulla & Conty 2017); with
//! `multiscatter = kulla-conty` the first is flat at 1 and the second at 0.
//! Models that are not microfacet models are left out.

use super::BrdfColor as _;
use super::chart::{self, Band, Chart, Marker, Palette, Series};
use super::{Scene, SceneBrdf, View};
use crate::derive::albedo::{self, AlbedoData, BAND_SIGMAS, Which};
use crate::session::command::Command;
use crate::session::state::{AlbedoSettings, PlotSettings};
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
    /// The furnace curve (the lobe with F = 1, kd = 0, ks = 1).
    furnace: bool,
    /// The swapped integral ρdh (LECTURE.md N12), dashed.
    swapped: bool,
}

impl AlbedoView {
    /// The curves to draw: computed now for a figure (or an SVG, `ctx`
    /// `None`), else the latest finished ones while jobs compute the current
    /// ones.
    fn update(&mut self, scene: &Scene<'_>, ctx: Option<&egui::Context>) -> Vec<Shown> {
        let mut shown = Vec::new();
        let mut done = 0;
        let mut total = 0;
        let furnace = scene.state.plots.albedo.furnace;
        let wanted = scene
            .brdfs
            .iter()
            .filter(|b| albedo::drawn(scene, b))
            .flat_map(|b| {
                let dh = albedo::drawn_swapped(scene, b).then_some((b, Which::Dh));
                std::iter::once((b, Which::Hd)).chain(dh)
            });
        for (b, which) in wanted {
            let (data, stale) = match ctx.filter(|_| !scene.figure) {
                None => (albedo::curve_now_of(scene, b, which), false),
                Some(ctx) => {
                    let s = albedo::curve_of(&super::waker(ctx), scene, b, which);
                    if s.busy || s.stale || s.done.is_none() {
                        let (d, t) = s.progress.unwrap_or((0, albedo::STEPS));
                        total += t;
                        done += d.min(t);
                    }
                    match s.value() {
                        Some(v) => v,
                        None => continue,
                    }
                }
            };
            let mut brdf = b.clone();
            if which == Which::Dh {
                // Paler dashes, so that over a curve it equals (a
                // reciprocal BRDF) the dashes show on the solid line.
                brdf.rgb = brdf.rgb.map(|c| c / 2 + 128);
            }
            shown.push(Shown {
                brdf,
                data,
                stale,
                furnace,
                swapped: which == Which::Dh,
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
        "{}{}: ρhh = {:.4} ± {err_text} {method}",
        s.brdf.label,
        if s.furnace { " E (F = 1)" } else { "" },
        mean_rgb(hh.value),
    );
    match s.data.excess_over_one() {
        // Within a thousandth: say by how much (an approximation's error,
        // not a model creating energy).
        Some(e) if e < 1e-3 => l.push_str(&format!(" (ρhd ≤ 1 + {e:.0e})")),
        Some(_) => l.push_str(" (ρhd > 1!)"),
        None => {}
    }
    if s.stale {
        l.push_str(" (updating)");
    }
    l
}

/// The top of the y axis, leaving `legend_h` points of a plot `plot_h`
/// points tall above ρ = 1 for the legend box under the furnace switch
/// (where the curves to read run along 1 and a legend in a top corner would
/// cover them).
fn y_top_with_legend(shown: &[Shown], legend: bool, plot_h: f32) -> f64 {
    let top = y_top(shown);
    if !legend || !shown.iter().any(|s| s.furnace) {
        return top;
    }
    let lines: usize = shown.iter().map(|s| series_of(s).len()).sum();
    let frac = ((lines as f32 * 18.0 + 24.0) / plot_h.max(1.0)).min(0.6) as f64;
    top.max(1.03 / (1.0 - frac))
}

fn y_top(shown: &[Shown]) -> f64 {
    let m = shown
        .iter()
        .flat_map(|s| (0..s.data.rho.len()).map(|k| s.data.mean_and_band(k)))
        .map(|(v, b)| v + b)
        .fold(0.0, f64::max);
    // Room above ρ = 1 for the legend of a transmitting model's three
    // lines (its sum runs close under 1 at every θi).
    let floor = if shown.iter().any(|s| s.data.has_parts()) {
        1.4
    } else {
        1.1
    };
    (m * 1.08).max(floor)
}

/// The largest θi of the plot: 180° when a curve covers light from below
/// (a transmitting model), else 90°.
fn x_max(shown: &[Shown]) -> f64 {
    if shown.iter().any(|s| s.data.has_parts()) {
        180.0
    } else {
        90.0
    }
}

/// How one series of a curve is drawn.
#[derive(Clone, Copy, PartialEq)]
enum Part {
    /// ρhd (= ρR + ρT for a transmitting model): solid, with its band.
    Total,
    /// ρR: dashed.
    Reflected,
    /// ρT: dotted.
    Transmitted,
    /// The energy lost, 1 − E, under the furnace switch: short dashes.
    Lost,
    /// The swapped integral ρdh: long dashes.
    Swapped,
}

impl Part {
    fn dash(self) -> Option<f32> {
        match self {
            Part::Total => None,
            Part::Reflected => Some(10.0),
            Part::Transmitted => Some(3.0),
            Part::Lost => Some(5.0),
            Part::Swapped => Some(14.0),
        }
    }
}

/// One series of a curve: its part, its legend label, and its points in
/// pieces split at the surface.
type PartSeries = (Part, String, Vec<Vec<[f64; 2]>>);

/// The series of one curve: (part, label, points split at the surface so
/// that no line crosses the horizon, where no light arrives).
fn series_of(s: &Shown) -> Vec<PartSeries> {
    let split = |pts: Vec<[f64; 2]>| -> Vec<Vec<[f64; 2]>> {
        let (above, below): (Vec<[f64; 2]>, Vec<[f64; 2]>) =
            pts.into_iter().partition(|p| p[0] < 90.0);
        [above, below]
            .into_iter()
            .filter(|v| !v.is_empty())
            .collect()
    };
    let total: Vec<[f64; 2]> = (0..s.data.rho.len())
        .map(|k| [s.data.theta_deg[k], s.data.mean_and_band(k).0])
        .collect();
    if s.swapped {
        let label = format!("{} ρdh = ∫ f cos θi dωi (at θo)", s.brdf.label);
        return vec![(Part::Swapped, label, split(total))];
    }
    let lost: Vec<[f64; 2]> = total.iter().map(|p| [p[0], 1.0 - p[1]]).collect();
    let mut out = vec![(Part::Total, legend_label(s), split(total))];
    if s.furnace {
        out.push((
            Part::Lost,
            format!("{} 1 − E (lost)", s.brdf.label),
            split(lost),
        ));
    }
    if s.data.has_parts() {
        out.push((
            Part::Reflected,
            format!("{} ρR (reflected)", s.brdf.label),
            split(s.data.series(&s.data.reflected)),
        ));
        out.push((
            Part::Transmitted,
            format!("{} ρT (transmitted)", s.brdf.label),
            split(s.data.series(&s.data.transmitted)),
        ));
    }
    out
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
    let xm = x_max(shown);
    let lines: usize = shown.iter().map(|s| series_of(s).len()).sum();
    let w = ((chars as f32 * 6.5 + 30.0) / size.x.max(1.0)).min(1.0) as f64 * xm;
    let h = ((lines as f32 * 18.0 + 12.0) / size.y.max(1.0)).min(1.0) as f64 * top;
    let boxes = [
        (Corner::RightBottom, xm - w, xm, 0.0, h),
        (Corner::RightTop, xm - w, xm, top - h, top),
        (Corner::LeftBottom, 0.0, w, 0.0, h),
        (Corner::LeftTop, 0.0, w, top - h, top),
    ];
    // Every drawn point, ρR and ρT included.
    let points: Vec<[f64; 2]> = shown
        .iter()
        .flat_map(series_of)
        .flat_map(|(_, _, pieces)| pieces.into_iter().flatten())
        .collect();
    let covered = |(x0, x1, y0, y1): (f64, f64, f64, f64)| {
        points
            .iter()
            .filter(|p| (x0..=x1).contains(&p[0]) && (y0..=y1).contains(&p[1]))
            .count()
    };
    boxes
        .iter()
        .min_by_key(|b| covered((b.1, b.2, b.3, b.4)))
        .map_or(Corner::RightBottom, |b| b.0)
}

const Y_LABEL: &str = "ρhd (mean of r, g, b)";
const Y_LABEL_FURNACE: &str = "E (F = 1, kd = 0) and 1 − E";

fn y_label(scene: &Scene<'_>) -> &'static str {
    if scene.state.plots.albedo.furnace {
        Y_LABEL_FURNACE
    } else {
        Y_LABEL
    }
}
const X_LABEL: &str = "θi (°)";

impl View for AlbedoView {
    fn toolbar(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        let before = scene.state.plots.albedo;
        if super::toolbar_toggle(
            ui,
            before.swapped,
            "ρdh",
            "Beside each ρhd, dashed: ρdh(θo) = ∫ f(ωi, ωo) cos θi dωi, the light a viewer \
             at θo gets from a uniform sky. Equal to ρhd for a reciprocal BRDF \
             (Helmholtz), apart for one that is not",
        ) {
            out.push(Command::SetPlots(PlotSettings {
                albedo: AlbedoSettings {
                    swapped: !before.swapped,
                    ..before
                },
                ..scene.state.plots
            }));
        }
        if super::toolbar_toggle(
            ui,
            before.furnace,
            "furnace",
            "White furnace: each microfacet model's lobe with F = 1, kd = 0, ks = 1, \
             and the energy single scattering loses, 1 − E (others left out)",
        ) {
            out.push(Command::SetPlots(PlotSettings {
                albedo: AlbedoSettings {
                    furnace: !before.furnace,
                    ..before
                },
                ..scene.state.plots
            }));
        }
    }

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
        let size = ui.available_size();
        let top = y_top_with_legend(&shown, !scene.presenting, size.y);
        let light = super::light_color(dark);
        // Presenting, the legend is a column beside the plot: its long
        // lines (ρhh of each) covered a curve in every corner of a plot
        // that short.
        let legend: Vec<Series> = if scene.presenting {
            shown
                .iter()
                .flat_map(|s| {
                    let width = if s.brdf.selected { 2.5 } else { 1.8 };
                    series_of(s)
                        .into_iter()
                        .map(move |(part, label, _)| Series {
                            label,
                            color: s.brdf.color(),
                            points: Vec::new(),
                            width,
                            dash: part.dash(),
                        })
                })
                .collect()
        } else {
            Vec::new()
        };
        let legend_w = if legend.is_empty() {
            0.0
        } else {
            super::side_legend_width(ui, &legend).min(0.4 * size.x)
        };
        let plot_w = if legend.is_empty() {
            size.x
        } else {
            size.x - legend_w - ui.spacing().item_spacing.x
        };
        let plot = Plot::new(super::view_id(crate::session::views::ALBEDO.id));
        let plot = if scene.presenting {
            super::calm_hover(plot, scene)
        } else {
            super::with_legend(
                plot,
                size,
                shown.iter().map(|s| series_of(s).len()).sum(),
                legend_corner(&shown, top, size),
            )
        };
        let plot = super::curves::with_linear_y(plot)
            .width(plot_w.max(50.0))
            .height(size.y.max(50.0))
            .x_axis_label(X_LABEL)
            .y_axis_label(y_label(scene))
            .y_axis_min_width(36.0)
            .include_x(0.0)
            .include_x(x_max(&shown))
            .include_y(0.0)
            .include_y(top)
            .allow_scroll(false)
            .x_grid_spacer(egui_plot::uniform_grid_spacer(|_| [5.0, 15.0, 45.0]));
        let theta_i = scene.incident.theta_deg;
        let surface = x_max(&shown) > 90.0;
        let surface_col = super::strong_text(ui).gamma_multiply(0.6);
        let draw = |pui: &mut egui_plot::PlotUi<'_>| {
            if surface {
                // The surface: light from above on the left, from below on
                // the right.
                pui.vline(
                    VLine::new("", 90.0)
                        .color(surface_col)
                        .width(scene.stroke(1.0))
                        .allow_hover(false),
                );
            }
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
                // The band on either side of the surface separately.
                let cut = s.data.theta_deg.partition_point(|t| *t < 90.0);
                for r in [0..cut, cut..n] {
                    if r.is_empty() {
                        continue;
                    }
                    pui.add(
                        FilledArea::new("", &s.data.theta_deg[r.clone()], &lo[r.clone()], &hi[r])
                            .fill_color(s.brdf.color().gamma_multiply(0.3)),
                    );
                }
                for (part, label, pieces) in series_of(s) {
                    for pts in pieces {
                        let mut line = Line::new(label.clone(), PlotPoints::from(pts))
                            .color(s.brdf.color())
                            .width(scene.stroke(if s.brdf.selected { 2.5 } else { 1.8 }));
                        // Stale: every part dashed alike (the parts are few
                        // and short-lived while a drag ends).
                        if let Some(d) = part.dash().or(s.stale.then_some(8.0)) {
                            line = line.style(LineStyle::Dashed { length: d });
                        }
                        pui.line(line);
                    }
                }
            }
        };
        if legend.is_empty() {
            plot.show(ui, draw);
        } else {
            ui.horizontal_top(|ui| {
                plot.show(ui, draw);
                ui.vertical(|ui| {
                    ui.add_space(4.0);
                    super::side_legend(ui, &legend, scene, legend_w);
                });
            });
        }
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn svg(&mut self, scene: &Scene<'_>, size: [f32; 2], dark: bool) -> Option<String> {
        let shown = self.update(scene, None);
        let top = y_top_with_legend(&shown, true, size[1]);
        let xm = x_max(&shown);
        let mut c = Chart {
            x_label: X_LABEL.into(),
            y_label: y_label(scene).into(),
            x_range: (0.0, xm),
            y_range: (0.0, top),
            x_ticks: chart::angle_ticks(0.0, xm),
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
        if xm > 90.0 {
            c.vlines.push(Marker {
                at: 90.0,
                color: super::mirror_color(dark),
                dashed: false,
                label: "surface".into(),
            });
        }
        for s in &shown {
            let n = s.data.rho.len();
            let mb: Vec<(f64, f64)> = (0..n).map(|k| s.data.mean_and_band(k)).collect();
            let cut = s.data.theta_deg.partition_point(|t| *t < 90.0);
            for r in [0..cut, cut..n] {
                if r.is_empty() {
                    continue;
                }
                c.bands.push(Band {
                    color: s.brdf.color().gamma_multiply(0.3),
                    xs: s.data.theta_deg[r.clone()].to_vec(),
                    lo: mb[r.clone()].iter().map(|(v, b)| v - b).collect(),
                    hi: mb[r].iter().map(|(v, b)| v + b).collect(),
                });
            }
            for (part, label, pieces) in series_of(s) {
                for (j, pts) in pieces.into_iter().enumerate() {
                    c.series.push(Series {
                        // One legend entry per part.
                        label: if j == 0 { label.clone() } else { String::new() },
                        color: s.brdf.color(),
                        points: pts,
                        width: if s.brdf.selected { 2.5 } else { 1.8 },
                        dash: part.dash(),
                    });
                }
            }
        }
        Some(c.to_svg(size, Palette::new(dark, scene.transparent)))
    }
}
