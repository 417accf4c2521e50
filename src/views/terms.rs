//! The microfacet term view: the factors of `f = F D G2 / (4 cosθi cosθo)`
//! (Walter et al. 2007, eq. 20) plotted apart for every drawn BRDF that
//! declares them ([`bv_core::Brdf::microfacet_terms`], its Fresnel term from
//! [`bv_core::Brdf::fresnel_term`]), overlaid in the BRDFs' colours:
//!
//! - D(θh): the distribution of microfacet normals along the azimuth of the
//!   light (linear or log scale), 1/sr;
//! - G1(ωo) (dashed) and G2(ωi, ωo) (solid) for ωo in the plane of incidence
//!   of the current light, against the signed θo of the other plots;
//! - F(θd): the Fresnel factor against the angle between ωi and h (mean of
//!   the RGB channels when they differ).
//!
//! With *v-groove* on, a strip under the charts draws Torrance & Sparrow's
//! V-grooves in the plane of incidence (`bv_core::microfacet::
//! v_groove_section`) at three outgoing directions, the mirror direction,
//! the normal and back towards the light: the grooves whose facets reflect
//! ωi into ωo, the part of the facet the light reaches (from the rim down:
//! the partner facet shadows the rest) and the part the viewer sees, and
//! their overlap, the v-groove G (LECTURE.md N9, scene "G: shadowing and
//! masking").
//!
//! Loading several Cook-Torrance BRDFs compares Beckmann, Blinn and GGX, or
//! v-groove, separable and height-correlated Smith, side by side. Models
//! without terms are listed as such. The numbers are the models' own
//! closures; this view names no model.

use super::BrdfColor as _;
use super::chart::{self, Chart, Marker, Palette, Series};
use super::curves;
use super::svg::Svg;
use super::vgroove;
use super::{Scene, View};
use crate::derive::slices;
use crate::session::command::Command;
use crate::session::state::PlotSettings;
use bv_core::frame;
use eframe::egui::{self, RichText, Ui};
use egui_plot::{Corner, Line, LineStyle, Plot, PlotPoints, VLine};
use std::f64::consts::FRAC_PI_2;

/// Samples over 0..90° (D, F); twice as many over −90..90° (G).
const SAMPLES: usize = 360;

pub use super::vgroove::{VGroovePanel, vgroove_sections};
/// Which terms are drawn: the scene's (`plots.terms`), so that a slide can
/// show D alone or G2 alone.
pub use crate::session::state::TermToggles;

/// The charts of one frame.
#[derive(Debug, Clone, Default)]
pub struct TermCharts {
    /// One line per drawn BRDF: its D, G and F, or "no microfacet terms".
    pub lines: Vec<String>,
    /// D(θh), when shown.
    pub d: Option<Chart>,
    /// G1 and G2 against θo, when either is shown.
    pub g: Option<Chart>,
    /// F(θd), when shown.
    pub f: Option<Chart>,
}

impl TermCharts {
    /// The charts that are shown, top to bottom.
    pub fn shown(&self) -> Vec<&Chart> {
        [&self.d, &self.g, &self.f]
            .into_iter()
            .filter_map(Option::as_ref)
            .collect()
    }
}

/// Angles 0..90° in degrees, `n + 1` of them.
fn degrees(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..=n)
        .map(|k| lo + (hi - lo) * k as f64 / n as f64)
        .collect()
}

/// The charts for `scene` with `show`.
pub fn term_charts(scene: &Scene<'_>, show: TermToggles, dark: bool) -> TermCharts {
    let mut out = TermCharts::default();
    let phi_i = scene.incident.phi_deg.to_radians();
    let theta_i = scene.incident.theta_deg;
    let wi = scene.wi();
    let mut d_series = Vec::new();
    let mut g_series = Vec::new();
    let mut f_series = Vec::new();
    let xs = degrees(0.0, 90.0, SAMPLES);
    let xs_signed = degrees(-90.0, 90.0, 2 * SAMPLES);
    for b in &scene.brdfs {
        let Some(t) = b.brdf.microfacet_terms() else {
            out.lines.push(format!("{}: no microfacet terms", b.label));
            continue;
        };
        let fres = b.brdf.fresnel_term();
        let f_name = fres
            .as_ref()
            .map_or("none", |f| f.fresnel.kind_name())
            .to_string();
        out.lines.push(format!(
            "{}: D = {}, G = {}, F = {f_name}",
            b.label, t.distribution, t.geometry
        ));
        let color = b.color();
        let width = if b.selected { 2.5 } else { 1.8 };
        if show.d {
            // h along the light's azimuth: the section an anisotropic D
            // shows in the plane of incidence.
            let points = xs
                .iter()
                .map(|&x| {
                    let h = frame::from_spherical(x.to_radians().min(FRAC_PI_2), phi_i);
                    [x, (t.d)(h)]
                })
                .collect();
            d_series.push(Series {
                label: format!("{}: D {}", b.label, t.distribution),
                color,
                points,
                width,
                dash: None,
            });
        }
        if show.g2 {
            let points = xs_signed
                .iter()
                .map(|&x| {
                    let wo = slices::plane_direction(x.to_radians(), phi_i);
                    let g = frame::half_vector(wi, wo).map_or(f64::NAN, |h| (t.g2)(wi, wo, h));
                    [x, g]
                })
                .collect();
            g_series.push(Series {
                label: format!("{}: G2 {}", b.label, t.geometry),
                color,
                points,
                width,
                dash: None,
            });
        }
        if show.g1 {
            let points = xs_signed
                .iter()
                .map(|&x| [x, (t.g1)(slices::plane_direction(x.to_radians(), phi_i))])
                .collect();
            g_series.push(Series {
                label: format!("{}: G1(ωo)", b.label),
                color,
                points,
                width: width - 0.6,
                dash: Some(5.0),
            });
        }
        if show.f
            && let Some(fr) = &fres
        {
            let points = xs
                .iter()
                .map(|&x| [x, bv_core::mean_rgb(fr.fresnel.eval(x.to_radians().cos()))])
                .collect();
            f_series.push(Series {
                label: format!("{}: F {f_name}", b.label),
                color,
                points,
                width,
                dash: None,
            });
            // A transmitting interface: what it passes, 1 − F, and its
            // reflectance for light arriving from inside, which reaches 1
            // (total internal reflection) at the critical angle (issue 33).
            if b.brdf.transmits()
                && matches!(fr.fresnel, bv_core::fresnel::Fresnel::Dielectric { .. })
            {
                let f_of = |c: f64| bv_core::mean_rgb(fr.fresnel.eval(c));
                f_series.push(Series {
                    label: format!("{}: 1 − F, transmitted", b.label),
                    color,
                    points: xs
                        .iter()
                        .map(|&x| [x, 1.0 - f_of(x.to_radians().cos())])
                        .collect(),
                    width: width - 0.6,
                    dash: Some(3.0),
                });
                f_series.push(Series {
                    label: format!("{}: F from inside", b.label),
                    color,
                    points: xs
                        .iter()
                        .map(|&x| [x, f_of(-x.to_radians().cos())])
                        .collect(),
                    width: width - 0.6,
                    dash: Some(9.0),
                });
            }
        }
    }
    if scene.brdfs.is_empty() {
        out.lines.push("no BRDF is shown".into());
    }
    if show.d {
        out.d = Some(d_chart(d_series, show.log_d));
    }
    if show.g1 || show.g2 {
        let mut c = Chart {
            x_label: "θo (°) in the plane of incidence, negative on the light's side".into(),
            y_label: match (show.g1, show.g2) {
                (true, true) => "G1, G2",
                (true, false) => "G1",
                _ => "G2",
            }
            .into(),
            x_range: (-90.0, 90.0),
            // Headroom above 1 for the legend.
            y_range: (0.0, 1.45),
            x_ticks: chart::angle_ticks(-90.0, 90.0),
            y_ticks: chart::labelled(chart::nice_ticks(0.0, 1.0, 5)),
            series: g_series,
            ..Default::default()
        };
        c.vlines.push(Marker {
            at: slices::incident_signed_angle(theta_i.to_radians()).to_degrees(),
            color: super::light_color(dark),
            dashed: false,
            label: "ωi".into(),
        });
        c.vlines.push(Marker {
            at: theta_i,
            color: super::mirror_color(dark),
            dashed: true,
            label: "ωr".into(),
        });
        out.g = Some(c);
    }
    if show.f {
        out.f = Some(Chart {
            x_label: "θd (°), angle between ωi and h".into(),
            y_label: "F".into(),
            x_range: (0.0, 90.0),
            y_range: (0.0, 1.45),
            x_ticks: chart::angle_ticks(0.0, 90.0),
            y_ticks: chart::labelled(chart::nice_ticks(0.0, 1.0, 5)),
            series: f_series,
            ..Default::default()
        });
    }
    // The list of models goes with the first chart (the SVG's note).
    let note = out.lines.join("\n");
    if let Some(first) = [&mut out.d, &mut out.g, &mut out.f]
        .into_iter()
        .flatten()
        .next()
    {
        first.note = note;
    }
    out
}

/// The D chart: values as they are, or their log10 with decade ticks.
fn d_chart(mut series: Vec<Series>, log: bool) -> Chart {
    let values = || series.iter().flat_map(|s| s.points.iter().map(|p| p[1]));
    let (y_range, y_ticks, y_label) = if log {
        let r = curves::LogRange::of(values());
        let n = r.decades().count().max(1);
        let every = n.div_ceil(8);
        let ticks = r
            .decades()
            .filter(|k| k.rem_euclid(every as i32) == 0)
            .map(|k| (f64::from(k), super::decade_label(k)))
            .collect();
        ((r.bottom, r.top), ticks, "D (1/sr, log scale)".to_string())
    } else {
        let top = values().filter(|v| v.is_finite()).fold(0.0, f64::max);
        let top = top.max(1e-6) * 1.15;
        (
            (0.0, top),
            chart::labelled(chart::nice_ticks(0.0, top, 6)),
            "D (1/sr)".to_string(),
        )
    };
    if log {
        // Below the axis' 12 decades a curve leaves through the bottom edge
        // (an underflowed D would otherwise be a point at −1000 decades).
        // The first point below the floor is kept on it, the rest break the
        // line (NaN).
        let floor = y_range.0 - 1.0;
        for s in &mut series {
            let mut below = false;
            for p in &mut s.points {
                let y = curves::log_ordinate(p[1]);
                p[1] = if y >= floor {
                    below = false;
                    y
                } else if below {
                    f64::NAN
                } else {
                    below = true;
                    floor
                };
            }
        }
    }
    Chart {
        x_label: "θh (°), h along the light's azimuth".into(),
        y_label,
        x_range: (0.0, 90.0),
        y_range,
        x_ticks: chart::angle_ticks(0.0, 90.0),
        y_ticks,
        series,
        ..Default::default()
    }
}

/// The microfacet term view.
#[derive(Default)]
pub struct TermsView {
    /// The charts of the last frame (for tests).
    pub last: Option<TermCharts>,
}

/// Where a chart's legend covers the least of its curves: D falls from its
/// peak at 0° (and G from 1 towards grazing), F rises towards 90°.
fn legend_corner(c: &Chart) -> Corner {
    if c.x_label.starts_with("θd") {
        Corner::LeftTop
    } else {
        Corner::RightTop
    }
}

/// Draws chart `c` with egui_plot into `size` points (`log_y`: the values
/// are log10, labelled as decades); presenting, its legend is a column
/// `legend_w` wide beside it (over a plot that short it covered the
/// curves). The term charts and the microsurface view's NDF use it.
pub fn plot_chart(
    ui: &mut Ui,
    id: egui::Id,
    c: &Chart,
    size: egui::Vec2,
    log_y: bool,
    scene: &Scene<'_>,
    legend_w: f32,
) {
    let height = size.y;
    let gap = if legend_w > 0.0 {
        ui.spacing().item_spacing.x
    } else {
        0.0
    };
    let width = (size.x - legend_w - gap).max(50.0);
    let plot = Plot::new(id).width(width).height(height.max(40.0));
    let plot = if scene.presenting {
        super::calm_hover(plot, scene)
    } else {
        super::with_legend(
            plot,
            egui::vec2(width, height),
            c.series.len(),
            legend_corner(c),
        )
    };
    let mut plot = plot
        .x_axis_label(c.x_label.clone())
        .y_axis_label(c.y_label.clone())
        .y_axis_min_width(40.0)
        .include_x(c.x_range.0)
        .include_x(c.x_range.1)
        .include_y(c.y_range.0)
        .include_y(c.y_range.1)
        .allow_scroll(false)
        .x_grid_spacer(egui_plot::uniform_grid_spacer(|input| {
            if input.bounds.1 - input.bounds.0 > 100.0 {
                [5.0, 15.0, 45.0]
            } else {
                [5.0, 15.0, 15.0]
            }
        }));
    if log_y {
        plot = plot
            .y_axis_formatter(|mark, _| {
                curves::decade_mark_label(mark.value, mark.step_size)
                    .map(super::decade_label)
                    .unwrap_or_default()
            })
            .y_grid_spacer(|input| curves::log_grid_marks(input.bounds, input.base_step_size));
    } else {
        plot = curves::with_linear_y(plot);
    }
    if scene.presenting {
        plot = super::presented_axes(plot, c);
    }
    let draw = |pui: &mut egui_plot::PlotUi<'_>| {
        for m in &c.vlines {
            let mut v = VLine::new("", m.at)
                .color(m.color)
                .width(1.3)
                .allow_hover(false);
            if m.dashed {
                v = v.style(LineStyle::Dashed { length: 6.0 });
            }
            pui.vline(v);
        }
        for s in &c.series {
            // Non-finite points break a curve into pieces (one legend entry:
            // egui_plot merges equal names).
            for piece in s.points.split(|p| !(p[0].is_finite() && p[1].is_finite())) {
                if piece.is_empty() {
                    continue;
                }
                let mut l = Line::new(s.label.clone(), PlotPoints::from(piece.to_vec()))
                    .color(s.color)
                    .width(s.width);
                if let Some(d) = s.dash {
                    l = l.style(LineStyle::Dashed { length: d });
                }
                pui.line(l);
            }
        }
    };
    if scene.presenting {
        ui.horizontal_top(|ui| {
            plot.show(ui, draw);
            ui.vertical(|ui| {
                ui.add_space(4.0);
                super::side_legend(ui, &c.series, scene, legend_w);
            });
        });
    } else {
        plot.show(ui, draw);
    }
}

/// The height of the v-groove strip under `charts` charts in a view
/// `height` high: all of it without a chart, otherwise a share (more beside
/// one chart: the grooves towards a low light are deep).
fn strip_height(on: bool, charts: usize, height: f32) -> f32 {
    if !on {
        0.0
    } else if charts == 0 {
        height
    } else {
        let share = if charts == 1 { 0.42 } else { 0.32 };
        (share * height).max(80.0).min(height)
    }
}

impl View for TermsView {
    fn toolbar(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        let before = scene.state.plots.terms;
        let mut s = before;
        for (on, label, hint) in [
            (&mut s.d, "D", "The distribution of normals D(θh)"),
            (&mut s.log_d, "log D", "D on a logarithmic scale"),
            (&mut s.g1, "G1", "Smith's masking G1(ωo) (dashed)"),
            (&mut s.g2, "G2", "The model's masking-shadowing G2(ωi, ωo)"),
            (&mut s.f, "F", "The Fresnel factor F(θd)"),
            (
                &mut s.vgroove,
                "v-groove",
                "Torrance & Sparrow's V-grooves at three outgoing directions: the facets' lit \
                 and seen parts, whose overlap is the v-groove G",
            ),
        ] {
            if super::toolbar_toggle(ui, *on, label, hint) {
                *on = !*on;
            }
        }
        if s != before {
            out.push(Command::SetPlots(PlotSettings {
                terms: s,
                ..scene.state.plots
            }));
        }
    }

    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, _out: &mut Vec<Command>) {
        let dark = ui.visuals().dark_mode;
        let charts = term_charts(scene, scene.state.plots.terms, dark);
        for line in &charts.lines {
            ui.label(RichText::new(line).weak().size(11.0));
        }
        let shown = charts.shown();
        // The v-groove strip takes the bottom of the view (half of it beside
        // one chart: the grooves towards a low light are deep).
        let strip_h = strip_height(
            scene.state.plots.terms.vgroove,
            shown.len(),
            ui.available_height(),
        );
        if shown.is_empty() && strip_h == 0.0 {
            ui.label(RichText::new("no term is switched on").weak());
        } else if !shown.is_empty() {
            // One width for all three, taken before any is drawn (a
            // legend may widen the ui), and one legend width, so that their
            // axes align.
            let width = ui.available_width();
            let legend_w = if scene.presenting {
                shown
                    .iter()
                    .map(|c| super::side_legend_width(ui, &c.series))
                    .fold(0.0, f32::max)
                    .min(0.4 * width)
            } else {
                0.0
            };
            let spacing = ui.spacing().item_spacing.y;
            let strip_gap = if strip_h > 0.0 {
                strip_h + spacing
            } else {
                0.0
            };
            let height = (ui.available_height() - strip_gap - spacing * (shown.len() as f32 - 1.0))
                / shown.len() as f32;
            for (k, c) in shown.iter().enumerate() {
                let log_y = scene.state.plots.terms.log_d
                    && charts.d.as_ref().is_some_and(|d| std::ptr::eq(d, *c));
                // The scale is part of the id: each keeps its own zoom.
                let id = super::view_id(crate::session::views::TERMS.id).with((k, log_y));
                plot_chart(ui, id, c, egui::vec2(width, height), log_y, scene, legend_w);
            }
        }
        if strip_h > 0.0 {
            let (r, _) = ui.allocate_exact_size(
                egui::vec2(ui.available_width(), strip_h.min(ui.available_height())),
                egui::Sense::hover(),
            );
            vgroove::paint_vgrooves(
                &mut vgroove::PainterCanvas::new(ui.painter_at(r)),
                r,
                &vgroove_sections(scene),
                dark,
            );
        }
        self.last = Some(charts);
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn svg(&mut self, scene: &Scene<'_>, size: [f32; 2], dark: bool) -> Option<String> {
        let charts = term_charts(scene, scene.state.plots.terms, dark);
        let pal = Palette::new(dark, scene.transparent);
        let [w, h] = [size[0].max(120.0), size[1].max(90.0)];
        let mut svg = Svg::new(w, h);
        if let Some(bg) = pal.background {
            svg.rect([0.0, 0.0], [w, h], Some(bg), None);
        }
        let shown = charts.shown();
        // The v-groove strip at the bottom, as in the window.
        let strip_h = strip_height(scene.state.plots.terms.vgroove, shown.len(), h);
        let panel_h = (h - strip_h) / shown.len().max(1) as f32;
        for (k, c) in shown.iter().enumerate() {
            svg.begin_translate([0.0, k as f32 * panel_h]);
            c.draw(&mut svg, [w, panel_h], pal);
            svg.end_group();
        }
        if strip_h > 0.0 {
            let r = egui::Rect::from_min_size(egui::pos2(0.0, h - strip_h), egui::vec2(w, strip_h));
            vgroove::paint_vgrooves(&mut svg, r, &vgroove_sections(scene), dark);
        }
        Some(svg.finish())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::session::state::AppState;
    use bv_core::ModelSpec;
    use std::sync::Arc;

    fn scene_of(state: &AppState, specs: &[ModelSpec]) -> Vec<super::super::SceneBrdf> {
        let _ = state;
        specs
            .iter()
            .enumerate()
            .map(|(k, s)| super::super::SceneBrdf {
                id: k as u64,
                label: format!("b{k}"),
                rgb: [200, 100, 50],
                brdf: Arc::from(s.build().unwrap()),
                revision: 0,
                selected: k == 0,
            })
            .collect()
    }

    /// A figure of `specs` with the light at θi = 30°.
    fn figure_at_30<'a>(state: &'a AppState, specs: &[ModelSpec]) -> Scene<'a> {
        Scene {
            state,
            brdfs: scene_of(state, specs),
            incident: crate::session::state::Incident {
                theta_deg: 30.0,
                phi_deg: 0.0,
            },
            interacting: false,
            figure: true,
            transparent: false,
            line_scale: 1.0,
            presenting: false,
        }
    }

    #[test]
    fn a_transmitting_interface_shows_what_it_passes_and_its_tir() {
        let state = AppState::default();
        let rd = ModelSpec::from_json(
            "rough-dielectric",
            &serde_json::json!({"alpha": 0.3, "eta": 1.5}),
        )
        .unwrap();
        let scene = figure_at_30(&state, &[rd]);
        let c = term_charts(&scene, TermToggles::default(), true);
        let f = c.f.unwrap();
        assert_eq!(f.series.len(), 3);
        let at = |s: &Series, x: f64| {
            s.points
                .iter()
                .min_by(|a, b| (a[0] - x).abs().total_cmp(&(b[0] - x).abs()))
                .unwrap()[1]
        };
        // F + (1 − F) = 1; from inside, F(0) is the same 4 % and TIR sets
        // in past θc = asin(1/1.5) = 41.8°.
        for x in [0.0, 20.0, 60.0] {
            assert!((at(&f.series[0], x) + at(&f.series[1], x) - 1.0).abs() < 1e-12);
        }
        assert!((at(&f.series[2], 0.0) - 0.04).abs() < 1e-12);
        let theta_c = (1.0f64 / 1.5).asin().to_degrees();
        assert!(at(&f.series[2], theta_c + 1.0) == 1.0);
        assert!(at(&f.series[2], theta_c - 2.0) < 1.0);
    }

    #[test]
    fn curves_are_the_models_terms_and_lambert_is_listed() {
        let state = AppState::default();
        let ct = ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"alpha": 0.3, "distribution": "ggx",
                "geometry": "smith-correlated", "fresnel": "dielectric", "eta": 1.5}),
        )
        .unwrap();
        let lambert = ModelSpec::new("lambert").unwrap();
        let scene = figure_at_30(&state, &[ct, lambert]);
        let c = term_charts(&scene, TermToggles::default(), true);
        assert_eq!(c.lines.len(), 2);
        assert!(c.lines[0].contains("D = GGX") && c.lines[0].contains("F = dielectric"));
        assert_eq!(c.lines[1], "b1: no microfacet terms");
        // GGX at the normal: D = 1/(π α²) (Walter et al. 2007, eq. 33).
        let d = &c.d.as_ref().unwrap().series[0];
        assert!((d.points[0][1] - 1.0 / (std::f64::consts::PI * 0.09)).abs() < 1e-9);
        // G1 of GGX in closed form (Heitz 2014, eq. 86) at θo = 60°:
        // 2/(1 + √(1 + α² tan²θ)).
        let g = c.g.as_ref().unwrap();
        let g1 = g.series.iter().find(|s| s.label.contains("G1")).unwrap();
        let at = |s: &Series, x: f64| s.points.iter().find(|p| (p[0] - x).abs() < 1e-9).unwrap()[1];
        let want = 2.0 / (1.0 + (1.0 + 0.09 * 3.0f64).sqrt());
        assert!((at(g1, 60.0) - want).abs() < 1e-12);
        assert!((at(g1, -60.0) - want).abs() < 1e-12);
        // Height-correlated G2 at the mirror direction (θo = θi = 30°):
        // 1/(1 + 2Λ(30°)), Λ = (√(1 + α² tan²θ) − 1)/2.
        let g2 = g.series.iter().find(|s| s.label.contains("G2")).unwrap();
        let lam = ((1.0 + 0.09 / 3.0f64).sqrt() - 1.0) / 2.0;
        assert!((at(g2, 30.0) - 1.0 / (1.0 + 2.0 * lam)).abs() < 1e-12);
        // F at θd = 0 is F0 = 0.04 for η = 1.5.
        let f = &c.f.as_ref().unwrap().series[0];
        assert!((f.points[0][1] - 0.04).abs() < 1e-12);
        // Log D: the same curve as log10.
        let log = term_charts(
            &scene,
            TermToggles {
                log_d: true,
                ..TermToggles::default()
            },
            true,
        );
        let dl = &log.d.unwrap().series[0];
        assert!((dl.points[0][1] - d.points[0][1].log10()).abs() < 1e-12);
        // Beckmann underflows to 0 before the horizon: on the log axis it
        // leaves through the bottom edge instead of dragging the axis down.
        let beckmann = ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"alpha": 0.1, "distribution": "beckmann"}),
        )
        .unwrap();
        let scene_b = Scene {
            brdfs: scene_of(&state, &[beckmann]),
            ..scene
        };
        let c = term_charts(
            &scene_b,
            TermToggles {
                log_d: true,
                ..TermToggles::default()
            },
            true,
        )
        .d
        .unwrap();
        let pts = &c.series[0].points;
        let floor = c.y_range.0 - 1.0;
        let first_gone = pts
            .iter()
            .position(|p| p[1].is_nan() || p[1] <= floor)
            .unwrap();
        assert_eq!(pts[first_gone][1], floor);
        assert!(pts[first_gone + 1..].iter().all(|p| p[1].is_nan()));
        assert!(
            c.y_range.1 - c.y_range.0 <= curves::LOG_DECADES + 2.0,
            "{:?}",
            c.y_range
        );
        // Switched off terms have no chart; the list moves to the next one.
        let only_f = term_charts(
            &scene,
            TermToggles {
                d: false,
                g1: false,
                g2: false,
                ..TermToggles::default()
            },
            true,
        );
        assert!(only_f.d.is_none() && only_f.g.is_none());
        assert!(only_f.f.unwrap().note.contains("no microfacet terms"));
    }
}
