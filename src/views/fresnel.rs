//! The Fresnel view: F against the angle of incidence for every drawn BRDF
//! that has a Fresnel term, overlaid in the BRDFs' colours, with the
//! selected one in detail. The numbers are `bv_core::optics`' and
//! `bv_core::fresnel`'s.
//!
//! For the selected BRDF:
//! - Dielectric (`fresnel = "dielectric"`, and `glass`): Rp = r∥², Rs = r⊥²
//!   and their mean F = (Rp + Rs)/2 for light from outside, F for light from
//!   inside (relative index 1/η, dashed), Brewster's angle θB = atan η (where
//!   r∥ = 0) and the critical angle θc = asin(1/η) beyond which light from
//!   the denser side is totally reflected.
//! - Conductor: F (per linear-RGB channel when coloured) from the complex
//!   index η + ik, and its Rs and Rp (of the green channel when coloured).
//! - Schlick (`fresnel = "schlick"`, and Disney's specular F0): F per channel.
//! - `fresnel = "none"`: F = 1.
//!
//! Exact and Schlick's approximation of the same F0 share the chart: the
//! model's own term is solid, the other one dashed (Schlick's for an exact
//! term, the exact dielectric of that F0 for a Schlick term). Below the
//! chart a colour strip shows F(θ) as a colour (linear RGB through the
//! display's sRGB encoding: copper's red turns white towards grazing), and
//! the readouts give the lecture's inverses F0 ⇔ η (dielectric) and F0 ⇔ k
//! (conductor, given η). Other drawn BRDFs add their F (mean of the channels
//! when coloured). Which term a model has is the model's own declaration
//! ([`bv_core::Brdf::fresnel_term`]); this view names no model.

use super::BrdfColor as _;
use super::chart::{self, Chart, Marker, Palette, Series};
use super::svg::{Anchor, Baseline, Svg};
use super::{Scene, View};
use crate::gpu::display::srgb_encode;
use crate::session::command::Command;
use bv_core::fresnel::{self, Fresnel};
use bv_core::optics;
use bv_core::{Brdf, Rgb};
use eframe::egui::{self, Color32, RichText, Ui};
use egui_plot::{Corner, Line, LineStyle, Plot, PlotPoints, VLine};

/// Samples over 0..90°.
const SAMPLES: usize = 360;

/// Cells of the colour strip over 0..90°.
pub const STRIP_CELLS: usize = 91;

/// What the selected BRDF's Fresnel term is.
#[derive(Debug, Clone, PartialEq)]
pub enum FresnelOf {
    /// A Fresnel term and a one-line description of where it comes from.
    Term(Fresnel, String),
    /// The model has none; the text says so.
    Absent(String),
}

/// The Fresnel term of a built BRDF, as its model declares it.
pub fn fresnel_of(brdf: &dyn Brdf) -> FresnelOf {
    match brdf.fresnel_term() {
        Some(t) => FresnelOf::Term(t.fresnel, t.source),
        None => FresnelOf::Absent(format!("{}: this model has no Fresnel term", brdf.id())),
    }
}

/// Channel colours for per-channel curves.
const CHANNELS: [(&str, [u8; 3]); 3] = [
    ("r", [225, 80, 80]),
    ("g", [80, 185, 90]),
    ("b", [80, 130, 235]),
];

/// Colours of the polarised curves.
const RP: [u8; 3] = [176, 122, 211];
const RS: [u8; 3] = [118, 183, 178];

fn grey(v: Rgb) -> bool {
    v.x == v.y && v.y == v.z
}

fn rgb(c: [u8; 3]) -> Color32 {
    Color32::from_rgb(c[0], c[1], c[2])
}

/// A linear-RGB reflectance as the display shows it (sRGB encoded, clipped).
pub fn display_color(f: Rgb) -> Color32 {
    let e = |x: f64| (srgb_encode(x) * 255.0).round() as u8;
    Color32::from_rgb(e(f.x), e(f.y), e(f.z))
}

/// One row of the colour strip: a name and the colours of F at
/// θ_j = j/(n − 1) · 90°.
#[derive(Debug, Clone, PartialEq)]
pub struct StripRow {
    /// What the row shows ("exact", "Schlick").
    pub label: String,
    /// Linear-RGB F at each cell.
    pub linear: Vec<Rgb>,
}

/// Everything the view draws: the chart, the colour strip and the readouts.
#[derive(Debug, Clone, Default)]
pub struct FresnelFigure {
    /// The curves.
    pub chart: Chart,
    /// The selected BRDF's F(θ) as colours (empty without a term).
    pub strip: Vec<StripRow>,
    /// The selected BRDF's F0 and its inverse.
    pub readouts: Vec<String>,
}

/// The strip of a term: its F(θ) per channel, and for a conductor Schlick's
/// of the same F0 (`optics::conductor_strip`).
fn strip_of(f: &Fresnel) -> Vec<StripRow> {
    let n = STRIP_CELLS;
    if let Fresnel::Conductor { eta, k } = *f
        && let Ok(s) = optics::conductor_strip(eta, k, n)
    {
        return vec![
            StripRow {
                label: "exact".into(),
                linear: s.exact,
            },
            StripRow {
                label: "Schlick".into(),
                linear: s.schlick,
            },
        ];
    }
    let linear = (0..n)
        .map(|j| {
            let th = (j as f64 / (n - 1) as f64 * 90.0).to_radians();
            f.eval(th.cos())
        })
        .collect();
    vec![StripRow {
        label: "F(θ)".into(),
        linear,
    }]
}

/// Three numbers as "a / b / c", or one when they agree.
fn fmt3(v: Rgb, digits: usize) -> String {
    if grey(v) {
        format!("{:.digits$}", v.x)
    } else {
        format!("{:.digits$} / {:.digits$} / {:.digits$}", v.x, v.y, v.z)
    }
}

fn per_channel(v: Rgb, f: impl Fn(f64) -> f64) -> Rgb {
    Rgb::new(f(v.x), f(v.y), f(v.z))
}

/// The lecture's normal-incidence inverses for a term: F0 from η (and k),
/// and η (or k, given η) back from F0.
pub fn readouts(f: &Fresnel) -> Vec<String> {
    match *f {
        Fresnel::None => vec!["F = 1 at every angle".into()],
        Fresnel::Dielectric { eta } => {
            let f0 = per_channel(eta, optics::dielectric_f0);
            let back = per_channel(f0, |x| {
                optics::dielectric_eta_from_f0(x).unwrap_or(f64::NAN)
            });
            vec![
                format!("F0 = ((η − 1)/(η + 1))² = {}", fmt3(f0, 4)),
                format!("η = (1 + √F0)/(1 − √F0) = {}", fmt3(back, 4)),
            ]
        }
        Fresnel::Conductor { eta, k } => {
            let f0 = Rgb::new(
                optics::conductor_f0(eta.x, k.x),
                optics::conductor_f0(eta.y, k.y),
                optics::conductor_f0(eta.z, k.z),
            );
            let kk = |c: usize| optics::conductor_k_from_f0(f0[c], eta[c]).unwrap_or(f64::NAN);
            let back = Rgb::new(kk(0), kk(1), kk(2));
            vec![
                format!("F0 = ((η − 1)² + k²)/((η + 1)² + k²) = {}", fmt3(f0, 4)),
                format!(
                    "k = √(((η + 1)² F0 − (η − 1)²)/(1 − F0)) = {}, given η = {}",
                    fmt3(back, 3),
                    fmt3(eta, 3)
                ),
            ]
        }
        Fresnel::Schlick { f0 } => {
            let eta = per_channel(f0, |x| {
                optics::dielectric_eta_from_f0(x).unwrap_or(f64::INFINITY)
            });
            vec![
                format!("Schlick: F0 + (1 − F0)(1 − cos θ)⁵, F0 = {}", fmt3(f0, 4)),
                format!(
                    "the dielectric of this F0: η = (1 + √F0)/(1 − √F0) = {}",
                    fmt3(eta, 4)
                ),
            ]
        }
    }
}

/// The curves of one BRDF's term: all of them for the selected BRDF
/// (`detail`), its F alone for the others.
fn add_curves(
    c: &mut Chart,
    f: &Fresnel,
    color: Color32,
    prefix: &str,
    detail: bool,
    strong: Color32,
) {
    let xs: Vec<f64> = (0..=SAMPLES)
        .map(|k| 90.0 * k as f64 / SAMPLES as f64)
        .collect();
    let curve = |g: &dyn Fn(f64) -> f64| -> Vec<[f64; 2]> {
        xs.iter().map(|&x| [x, g(x.to_radians())]).collect()
    };
    let mut push = |label: String, color: Color32, points, width, dash| {
        c.series.push(Series {
            label: format!("{prefix}{label}"),
            color,
            points,
            width,
            dash,
        });
    };
    if !detail {
        let label = match f {
            Fresnel::None => "F = 1".to_string(),
            _ => format!("F ({})", f.kind_name()),
        };
        push(
            label,
            color,
            curve(&|th| bv_core::mean_rgb(f.eval(th.cos()))),
            1.8,
            None,
        );
        return;
    }
    match *f {
        Fresnel::None => {
            push(
                "F = 1 (no Fresnel effect)".into(),
                color,
                curve(&|_| 1.0),
                2.5,
                None,
            );
        }
        Fresnel::Dielectric { eta } => {
            let e = if grey(eta) {
                eta.x
            } else {
                bv_core::mean_rgb(eta)
            };
            let w = |th: f64| optics::dielectric(th, 1.0, e).ok();
            if grey(eta) {
                push(
                    "Rp = rp² (p-polarised)".into(),
                    rgb(RP),
                    curve(&|th| w(th).map_or(f64::NAN, |w| w.rp)),
                    1.6,
                    None,
                );
                push(
                    "Rs = rs² (s-polarised)".into(),
                    rgb(RS),
                    curve(&|th| w(th).map_or(f64::NAN, |w| w.rs)),
                    1.6,
                    None,
                );
                push(
                    format!("F = (Rp + Rs)/2, η = {}", fmt_eta(e)),
                    color,
                    curve(&|th| fresnel::dielectric(th.cos(), e)),
                    2.5,
                    None,
                );
            } else {
                for (k, (name, ch)) in CHANNELS.iter().enumerate() {
                    let ek = eta[k];
                    push(
                        format!("F {name}, η = {}", fmt_eta(ek)),
                        rgb(*ch),
                        curve(&|th| fresnel::dielectric(th.cos(), ek)),
                        2.0,
                        None,
                    );
                }
            }
            push(
                format!("F from inside (η = {})", fmt_eta(1.0 / e)),
                strong.gamma_multiply(0.7),
                curve(&|th| fresnel::dielectric(-th.cos(), e)),
                1.6,
                Some(6.0),
            );
            let f0 = optics::dielectric_f0(e);
            push(
                format!("Schlick, same F0 = {f0:.3}"),
                color,
                curve(&|th| optics::schlick(f0, th)),
                1.6,
                Some(3.0),
            );
            if (e - 1.0).abs() > 1e-9 {
                let brewster = optics::brewster_angle(1.0, e).to_degrees();
                c.vlines.push(Marker {
                    at: brewster,
                    color: strong.gamma_multiply(0.8),
                    dashed: true,
                    label: format!("θB = {brewster:.1}°"),
                });
                // The denser side sees total internal reflection beyond θc.
                let crit = optics::critical_angle(e.max(1.0), e.min(1.0))
                    .unwrap_or(0.0)
                    .to_degrees();
                c.vlines.push(Marker {
                    at: crit,
                    color: strong.gamma_multiply(0.6),
                    dashed: true,
                    label: format!("θc = {crit:.1}°"),
                });
            }
        }
        Fresnel::Conductor { eta, k } => {
            // Rs and Rp of one channel: the green one when they differ.
            let (e, kk, ch) = if grey(eta) && grey(k) {
                (eta.x, k.x, "")
            } else {
                (eta.y, k.y, " (g)")
            };
            let w = |th: f64| optics::conductor(th, e, kk).ok();
            push(
                format!("Rp{ch} (p-polarised)"),
                rgb(RP),
                curve(&|th| w(th).map_or(f64::NAN, |w| w.rp)),
                1.4,
                None,
            );
            push(
                format!("Rs{ch} (s-polarised)"),
                rgb(RS),
                curve(&|th| w(th).map_or(f64::NAN, |w| w.rs)),
                1.4,
                None,
            );
            if ch.is_empty() {
                push(
                    format!("F, η = {} + {}i", fmt_eta(e), fmt_eta(kk)),
                    color,
                    curve(&|th| fresnel::conductor(th.cos(), e, kk)),
                    2.5,
                    None,
                );
                let f0 = optics::conductor_f0(e, kk);
                push(
                    format!("Schlick, same F0 = {f0:.3}"),
                    color,
                    curve(&|th| optics::schlick(f0, th)),
                    1.6,
                    Some(3.0),
                );
            } else {
                for (c_idx, (name, chc)) in CHANNELS.iter().enumerate() {
                    let (e, kk) = (eta[c_idx], k[c_idx]);
                    push(
                        format!("F {name}, η = {} + {}i", fmt_eta(e), fmt_eta(kk)),
                        rgb(*chc),
                        curve(&|th| fresnel::conductor(th.cos(), e, kk)),
                        2.0,
                        None,
                    );
                }
                for (c_idx, (name, chc)) in CHANNELS.iter().enumerate() {
                    let f0 = optics::conductor_f0(eta[c_idx], k[c_idx]);
                    push(
                        format!("Schlick {name}, same F0 = {f0:.3}"),
                        rgb(*chc),
                        curve(&|th| optics::schlick(f0, th)),
                        1.3,
                        Some(3.0),
                    );
                }
            }
        }
        Fresnel::Schlick { f0 } => {
            if grey(f0) {
                push(
                    format!("Schlick, F0 = {:.3}", f0.x),
                    color,
                    curve(&|th| optics::schlick(f0.x, th)),
                    2.5,
                    None,
                );
            } else {
                for (ch, (name, chc)) in CHANNELS.iter().enumerate() {
                    let f = f0[ch];
                    push(
                        format!("Schlick {name}, F0 = {f:.3}"),
                        rgb(*chc),
                        curve(&|th| optics::schlick(f, th)),
                        2.0,
                        None,
                    );
                }
            }
            let m = bv_core::mean_rgb(f0);
            if let Ok(e) = optics::dielectric_eta_from_f0(m) {
                push(
                    format!("exact dielectric, η = {}", fmt_eta(e)),
                    strong.gamma_multiply(0.7),
                    curve(&|th| fresnel::dielectric(th.cos(), e)),
                    1.6,
                    Some(6.0),
                );
            }
        }
    }
}

/// Everything the view draws, as a chart (the GUI plot and the SVG share it).
pub fn chart_of(scene: &Scene<'_>, dark: bool) -> Chart {
    figure_of(scene, dark).chart
}

/// The chart, the strip and the readouts of `scene`.
pub fn figure_of(scene: &Scene<'_>, dark: bool) -> FresnelFigure {
    let mut c = Chart {
        x_label: "θ (°), angle of incidence".into(),
        y_label: "F (reflectance)".into(),
        x_range: (0.0, 90.0),
        y_range: (0.0, 1.05),
        x_ticks: chart::angle_ticks(0.0, 90.0),
        y_ticks: chart::labelled(chart::nice_ticks(0.0, 1.0, 8)),
        ..Default::default()
    };
    let mut fig = FresnelFigure::default();
    let Some(primary) = scene.primary() else {
        c.note = "no BRDF is shown".into();
        fig.chart = c;
        return fig;
    };
    // A light below the surface (issue 33) meets the interface at 180° − θi
    // from the downward normal: read it on the curve from inside.
    let (at, label) = if scene.incident.below() {
        (180.0 - scene.incident.theta_deg, "θi (inside)")
    } else {
        (scene.incident.theta_deg, "θi")
    };
    c.vlines.push(Marker {
        at,
        color: super::light_color(dark),
        dashed: false,
        label: label.into(),
    });
    let strong = super::strong_text_color(dark);
    let with_term = scene
        .brdfs
        .iter()
        .filter(|b| b.brdf.fresnel_term().is_some())
        .count();
    let mut notes = Vec::new();
    // The others first, so that the selected BRDF's curves lie on top.
    let order = scene
        .brdfs
        .iter()
        .filter(|b| b.id != primary.id)
        .chain(std::iter::once(primary));
    for b in order {
        let detail = b.id == primary.id;
        match fresnel_of(b.brdf.as_ref()) {
            FresnelOf::Absent(_) => {
                notes.push(format!("{}: no Fresnel term", b.label));
            }
            FresnelOf::Term(f, desc) => {
                if detail {
                    notes.push(format!("{}: {desc}", b.label));
                    fig.strip = strip_of(&f);
                    fig.readouts = readouts(&f);
                }
                let prefix = if with_term > 1 {
                    format!("{}: ", b.label)
                } else {
                    String::new()
                };
                add_curves(&mut c, &f, b.color(), &prefix, detail, strong);
            }
        }
    }
    // The selected BRDF's line first.
    notes.rotate_right(1);
    c.note = notes.join("\n");
    fig.chart = c;
    fig
}

fn fmt_eta(x: f64) -> String {
    super::curves::fmt_tick(super::curves::round_significant(x, 4))
}

/// Height of one row of the colour strip, points.
const STRIP_ROW: f32 = 14.0;

/// The Fresnel view.
#[derive(Default)]
pub struct FresnelView {
    /// The chart of the last frame (for tests).
    pub last: Option<Chart>,
    /// The strip and readouts of the last frame (for tests).
    pub last_figure: Option<FresnelFigure>,
}

/// Paints the strip's rows between `x0` and `x1` (the plot's 0° and 90°)
/// from `top`, the rows' names in `label_pt` points.
fn paint_strip(ui: &Ui, rows: &[StripRow], x0: f32, x1: f32, top: f32, label_pt: f32) {
    let painter = ui.painter();
    let text = ui.visuals().weak_text_color();
    for (r, row) in rows.iter().enumerate() {
        let y = top + r as f32 * (STRIP_ROW + 2.0);
        let n = row.linear.len().max(2);
        let cell = (x1 - x0) / (n - 1) as f32;
        for (j, f) in row.linear.iter().enumerate() {
            let cx = x0 + j as f32 * cell;
            let rect = egui::Rect::from_min_max(
                egui::pos2((cx - cell * 0.5).max(x0), y),
                egui::pos2((cx + cell * 0.5).min(x1), y + STRIP_ROW),
            );
            painter.rect_filled(rect, 0.0, display_color(*f));
        }
        painter.text(
            egui::pos2(x0 - 4.0, y + STRIP_ROW * 0.5),
            egui::Align2::RIGHT_CENTER,
            &row.label,
            egui::FontId::proportional(label_pt),
            text,
        );
    }
}

impl View for FresnelView {
    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, _out: &mut Vec<Command>) {
        let dark = ui.visuals().dark_mode;
        let fig = figure_of(scene, dark);
        let c = &fig.chart;
        if !c.note.is_empty() {
            ui.label(RichText::new(c.note.replace('\n', "; ")).weak());
        }
        let strip_h = if fig.strip.is_empty() {
            0.0
        } else {
            fig.strip.len() as f32 * (STRIP_ROW + 2.0) + 4.0
        };
        let size = ui.available_size();
        // Small views (thumbnails) keep their height for the curves; a
        // presented slide keeps the formulas (its plot is short at the
        // presentation scale, but the formulas are what the slide is about).
        let readouts: &[String] = if size.y >= 260.0 || scene.presenting {
            &fig.readouts
        } else {
            &[]
        };
        let readout_h = readouts.len() as f32
            * (ui.text_style_height(&egui::TextStyle::Body) + ui.spacing().item_spacing.y);
        let plot_h = (size.y - strip_h - readout_h).max(50.0);
        // Presenting, the legend is a column beside the plot: over a plot
        // that short it covered the curves (and was left out for lack of
        // room).
        let legend_w = if scene.presenting {
            super::side_legend_width(ui, &c.series).min(0.45 * size.x)
        } else {
            0.0
        };
        // (The column sits one item spacing right of the plot.)
        let gap = if scene.presenting {
            ui.spacing().item_spacing.x
        } else {
            0.0
        };
        let plot_w = (size.x - legend_w - gap).max(50.0);
        let plot = Plot::new(super::view_id(crate::session::views::FRESNEL.id))
            .width(plot_w)
            .height(plot_h);
        let plot = if scene.presenting {
            super::calm_hover(plot, scene)
        } else {
            super::with_legend(
                plot,
                egui::vec2(size.x, plot_h),
                c.series.len(),
                Corner::LeftTop,
            )
        };
        let plot = super::curves::with_linear_y(plot)
            .x_axis_label(c.x_label.clone())
            .y_axis_label(c.y_label.clone())
            .y_axis_min_width(36.0)
            .include_x(0.0)
            .include_x(90.0)
            .include_y(0.0)
            .include_y(1.05)
            .allow_scroll(false)
            .x_grid_spacer(egui_plot::uniform_grid_spacer(|_| [5.0, 15.0, 45.0]));
        let plot = if scene.presenting {
            super::presented_axes(plot, c)
        } else {
            plot
        };
        let draw = |pui: &mut egui_plot::PlotUi<'_>| {
            for (k, m) in c.vlines.iter().enumerate() {
                let mut v = VLine::new("", m.at)
                    .color(m.color)
                    .width(scene.stroke(1.3))
                    .allow_hover(false);
                if m.dashed {
                    v = v.style(LineStyle::Dashed { length: 6.0 });
                }
                pui.vline(v);
                pui.text(
                    egui_plot::Text::new(
                        "",
                        egui_plot::PlotPoint::new(m.at, 0.02 + 0.07 * k as f64),
                        RichText::new(format!(" {}", m.label)).size(11.0),
                    )
                    .color(m.color)
                    .anchor(egui::Align2::LEFT_BOTTOM)
                    .allow_hover(false),
                );
            }
            for s in &c.series {
                let mut l = Line::new(s.label.clone(), PlotPoints::from(s.points.clone()))
                    .color(s.color)
                    .width(scene.stroke(s.width));
                if let Some(d) = s.dash {
                    l = l.style(LineStyle::Dashed { length: d });
                }
                pui.line(l);
            }
        };
        let response = if scene.presenting {
            ui.horizontal_top(|ui| {
                let r = plot.show(ui, draw);
                ui.vertical(|ui| {
                    ui.add_space(4.0);
                    super::side_legend(ui, &c.series, scene, legend_w);
                });
                r
            })
            .inner
        } else {
            plot.show(ui, draw)
        };
        if !fig.strip.is_empty() {
            // Aligned with the plot's own 0° and 90°.
            let t = &response.transform;
            let x0 = t
                .position_from_point(&egui_plot::PlotPoint::new(0.0, 0.0))
                .x;
            let x1 = t
                .position_from_point(&egui_plot::PlotPoint::new(90.0, 0.0))
                .x;
            let (rect, _) =
                ui.allocate_exact_size(egui::vec2(size.x.max(50.0), strip_h), egui::Sense::hover());
            // Presenting: no smaller than the other text of the slide
            // (11 points, 20-pixel capitals at 1080p).
            let label_pt = if scene.presenting { 11.0 } else { 10.0 };
            paint_strip(ui, &fig.strip, x0, x1, rect.top() + 2.0, label_pt);
        }
        for line in readouts {
            ui.label(RichText::new(line).size(11.0));
        }
        self.last = Some(fig.chart.clone());
        self.last_figure = Some(fig);
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn svg(&mut self, scene: &Scene<'_>, size: [f32; 2], dark: bool) -> Option<String> {
        let fig = figure_of(scene, dark);
        let pal = Palette::new(dark, scene.transparent);
        let [w, h] = [size[0].max(120.0), size[1].max(90.0)];
        let mut svg = Svg::new(w, h);
        if let Some(bg) = pal.background {
            svg.rect([0.0, 0.0], [w, h], Some(bg), None);
        }
        let strip_h = fig.strip.len() as f32 * (STRIP_ROW + 2.0) + 4.0;
        let readout_h = fig.readouts.len() as f32 * 15.0 + 4.0;
        let chart_h = (h - strip_h - readout_h).max(60.0);
        fig.chart.draw(&mut svg, [w, chart_h], pal);
        let (pmin, psize) = fig.chart.plot_area([w, chart_h]);
        let (x0, x1) = (pmin[0], pmin[0] + psize[0]);
        for (r, row) in fig.strip.iter().enumerate() {
            let y = chart_h + 2.0 + r as f32 * (STRIP_ROW + 2.0);
            let n = row.linear.len().max(2);
            let cell = (x1 - x0) / (n - 1) as f32;
            for (j, f) in row.linear.iter().enumerate() {
                let cx = x0 + j as f32 * cell;
                let a = (cx - cell * 0.5).max(x0);
                let b = (cx + cell * 0.5).min(x1);
                svg.rect([a, y], [b - a, STRIP_ROW], Some(display_color(*f)), None);
            }
            svg.text(
                [x0 - 4.0, y + STRIP_ROW * 0.5],
                &row.label,
                10.0,
                pal.weak,
                Anchor::End,
                Baseline::Middle,
                None,
            );
        }
        for (k, line) in fig.readouts.iter().enumerate() {
            svg.text(
                [x0, chart_h + strip_h + 2.0 + 15.0 * k as f32],
                line,
                11.0,
                pal.text,
                Anchor::Start,
                Baseline::Top,
                None,
            );
        }
        Some(svg.finish())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bv_core::ModelSpec;

    fn of(spec: &ModelSpec) -> FresnelOf {
        fresnel_of(spec.build().unwrap().as_ref())
    }

    #[test]
    fn models_with_and_without_fresnel() {
        let ct = ModelSpec::new("cook-torrance").unwrap();
        assert!(matches!(of(&ct), FresnelOf::Term(..)));
        let glass = ModelSpec::from_json("glass", &serde_json::json!({"eta": 1.5})).unwrap();
        assert_eq!(
            of(&glass),
            FresnelOf::Term(
                Fresnel::Dielectric {
                    eta: Rgb::splat(1.5)
                },
                "exact dielectric (glass)".into()
            )
        );
        let l = ModelSpec::new("lambert").unwrap();
        match of(&l) {
            FresnelOf::Absent(m) => assert!(m.contains("no Fresnel term"), "{m}"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn disney_f0_follows_the_reference_shader() {
        // specular 0.5, no tint, no metal: F0 = 0.08 · 0.5 = 0.04.
        let d = ModelSpec::from_json(
            "disney",
            &serde_json::json!({"specular": 0.5, "specular_tint": 0.0, "metallic": 0.0}),
        )
        .unwrap();
        match of(&d) {
            FresnelOf::Term(Fresnel::Schlick { f0 }, _) => {
                assert!((f0 - Rgb::splat(0.04)).abs().max_element() < 1e-15, "{f0}");
            }
            other => panic!("{other:?}"),
        }
        // Full metal: F0 is the base colour.
        let m = ModelSpec::from_json(
            "disney",
            &serde_json::json!({"base_color": [0.9, 0.6, 0.2], "metallic": 1.0}),
        )
        .unwrap();
        match of(&m) {
            FresnelOf::Term(Fresnel::Schlick { f0 }, _) => {
                assert!((f0 - Rgb::new(0.9, 0.6, 0.2)).abs().max_element() < 1e-12);
            }
            other => panic!("{other:?}"),
        }
    }
}
