//! Polar plot of the plane of incidence: the radius is `f` (or `f cos θo`, or
//! ln(1 + f) on the log scale, the same radius as the 3D lobe) along the
//! outgoing direction, the light on the left, the mirror direction on the
//! right, the surface horizontal. Every drawn BRDF in its colour, with a legend
//! and the exact values under the pointer.

use super::BrdfColor as _;
use super::curves;
use super::{Scene, View, factor_overlay, sh_overlay};
use crate::derive::interface::InterfaceMarks;
use crate::derive::slices::{self, Sample};
use crate::session::command::Command;
use eframe::egui::{self, Color32, RichText, Ui};
use egui_plot::{Corner, Line, LineStyle, Plot, PlotPoint, PlotPoints, Text};
use std::f64::consts::{FRAC_PI_2, PI};

/// Samples per curve (half circle); 0.25° steps keep a Phong lobe of exponent
/// 10⁴ (≈ 1° wide) smooth.
const SAMPLES: usize = 720;

/// The polar plot view.
#[derive(Default)]
pub struct PolarView {
    /// The values under the pointer in the last frame (for tests and the readout).
    pub readout: Option<Readout>,
    /// Where the plot was drawn in the last frame.
    pub plot_rect: Option<egui::Rect>,
    /// The SH overlay's curve drawn in the last frame (plot coordinates).
    pub sh_curve: Option<Vec<[f64; 2]>>,
    /// The factorisation overlay's curve drawn in the last frame.
    pub factor_curve: Option<Vec<[f64; 2]>>,
    /// The outgoing direction last hovered (signed in-plane angle, radians):
    /// it stays when the pointer leaves the plot, so that the swap button
    /// below can be reached.
    pub pinned: Option<f64>,
    /// Both orders of the selected BRDF at the pinned direction, as shown in
    /// the last frame.
    pub swap: Option<SwapReadout>,
}

/// `f(ωi, ωo)` beside `f(ωo, ωi)` at one outgoing direction: Helmholtz
/// reciprocity read off at a point.
#[derive(Debug, Clone, PartialEq)]
pub struct SwapReadout {
    /// The BRDF's label.
    pub label: String,
    /// The outgoing direction.
    pub wo: glam::DVec3,
    /// `f(ωi, ωo)` (1/sr, r g b).
    pub forward: bv_core::Rgb,
    /// `f(ωo, ωi)`.
    pub swapped: bv_core::Rgb,
    /// `max_c |forward − swapped| / max(forward, swapped)` (0 where both are
    /// 0).
    pub rel_diff: f64,
}

impl SwapReadout {
    /// Both orders of `brdf` for light `wi` and outgoing `wo`.
    pub fn new(label: String, brdf: &dyn bv_core::Brdf, wi: glam::DVec3, wo: glam::DVec3) -> Self {
        let forward = brdf.eval(wi, wo);
        let swapped = brdf.eval(wo, wi);
        let m = forward.max_element().max(swapped.max_element());
        let d = (forward - swapped).abs().max_element();
        Self {
            label,
            wo,
            forward,
            swapped,
            rel_diff: if m > 0.0 { d / m } else { 0.0 },
        }
    }

    /// Whether the light can be put at `wo` (anywhere but the horizon band;
    /// below the surface only where the plot shows directions below, i.e.
    /// for a transmitting model).
    pub fn can_swap(&self) -> bool {
        use crate::session::state::Incident;
        let t = bv_core::frame::to_spherical(self.wo).0.to_degrees();
        t.is_finite() && !Incident::in_horizon_gap(t) && t <= Incident::MAX_THETA_DEG
    }
}

/// The line under the readout: both orders at the pinned direction and the
/// button that moves the light there.
fn swap_ui(ui: &mut Ui, swap: Option<&SwapReadout>, out: &mut Vec<Command>) {
    ui.horizontal(|ui| {
        ui.spacing_mut().item_spacing.x = 10.0;
        // Nothing hovered yet: the line stays empty rather than adding a
        // second hint under the plot's own "hover a plot" line.
        let Some(s) = swap else {
            return;
        };
        let (t, _) = bv_core::frame::to_spherical(s.wo);
        let v = |c: bv_core::Rgb| curves::fmt_value(c.max_element());
        let r = ui
            .add_enabled(s.can_swap(), egui::Button::new("swap ωi and ωo").small())
            .on_hover_text("Move the light to this outgoing direction")
            .on_disabled_hover_text("The light cannot go to the horizon");
        if r.clicked() {
            out.push(Command::SetIncident(
                crate::session::state::Incident::from_direction(s.wo),
            ));
        }
        ui.label(
            RichText::new(format!(
                "θo {:.1}°: f(ωi,ωo) {}  f(ωo,ωi) {}  rel. diff {}",
                t.to_degrees(),
                v(s.forward),
                v(s.swapped),
                curves::fmt_value(s.rel_diff)
            ))
            .monospace(),
        )
        .on_hover_text(format!(
            "{}: Helmholtz reciprocity says f(ωi,ωo) = f(ωo,ωi). Values are the largest \
             channel, 1/sr; rel. diff = |f(ωi,ωo) − f(ωo,ωi)| / max of the two.",
            s.label
        ));
    });
}

/// Exact values at one hovered angle.
#[derive(Debug, Clone, PartialEq)]
pub struct Readout {
    /// What the abscissa is ("θo", "θh", …).
    pub axis: String,
    /// The hovered abscissa, degrees.
    pub x_deg: f64,
    /// Per BRDF: label, colour, exact sample.
    pub values: Vec<(String, Color32, Sample)>,
}

/// Shows a readout line under a plot.
pub fn readout_ui(ui: &mut Ui, readout: Option<&Readout>, cosine: bool) {
    ui.horizontal_wrapped(|ui| {
        ui.spacing_mut().item_spacing.x = 10.0;
        match readout {
            Some(r) => {
                ui.label(RichText::new(format!("{} = {:.1}°", r.axis, r.x_deg)).monospace());
                for (label, color, s) in &r.values {
                    let rgb = s.rgb;
                    ui.label(
                        RichText::new(format!("{label}: {}", curves::fmt_value(s.value)))
                            .color(*color)
                            .strong(),
                    )
                    .on_hover_text(format!(
                        "{} = {} 1/sr\nf (r, g, b) = ({}, {}, {}) 1/sr",
                        super::value_label(cosine),
                        s.value,
                        rgb.x,
                        rgb.y,
                        rgb.z
                    ));
                }
                ui.weak("1/sr");
            }
            None => {
                ui.weak("hover a plot to read exact values");
            }
        }
    });
}

/// The radius of a value on the current scale.
fn radius(v: f64, log: bool) -> f64 {
    if log { v.ln_1p() } else { v }
}

/// The value at a radius (inverse of [`radius`]).
fn value_at(r: f64, log: bool) -> f64 {
    if log { r.exp_m1() } else { r }
}

impl View for PolarView {
    fn toolbar(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        super::display_toggles(ui, scene, out);
        sh_overlay::control(ui, scene, out);
        sh_overlay::error_label(
            ui,
            scene,
            crate::derive::sh::request(&super::waker(ui.ctx()), scene).as_ref(),
        );
        factor_overlay::control(ui, scene, out);
        factor_overlay::error_label(
            ui,
            scene,
            crate::derive::factor::request(&super::waker(ui.ctx()), scene).as_ref(),
        );
        let plots = scene.state.plots;
        if scene.brdfs.len() > 1
            && super::toolbar_toggle(
                ui,
                plots.small_multiples,
                "multiples",
                "Small multiples: each BRDF in its own panel, on its own scale, \
                 instead of all overlaid on the largest one's",
            )
        {
            out.push(Command::SetPlots(crate::session::state::PlotSettings {
                small_multiples: !plots.small_multiples,
                ..plots
            }));
        }
        super::gonio_overlay::control(ui, scene, out);
    }

    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        if scene.state.plots.small_multiples && scene.brdfs.len() > 1 {
            self.small_multiples(ui, scene, out);
        } else {
            self.panel(ui, scene, out, None);
        }
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn svg(&mut self, scene: &Scene<'_>, size: [f32; 2], dark: bool) -> Option<String> {
        Some(polar_svg(scene, size, dark))
    }
}

impl PolarView {
    /// Every drawn BRDF in its own panel on its own scale (LECTURE.md N5),
    /// its name above it in its colour.
    fn small_multiples(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        let transmits = scene.brdfs.iter().any(|b| b.brdf.transmits());
        let area = ui.available_rect_before_wrap();
        let title_h = if scene.presenting { 34.0 } else { 22.0 };
        let [cols, rows] = multiples_grid(
            scene.brdfs.len(),
            [area.width(), area.height()],
            title_h,
            transmits,
        );
        let cell = egui::vec2(area.width() / cols as f32, area.height() / rows as f32);
        let size = if scene.presenting { 18.0 } else { 14.0 };
        for (k, b) in scene.brdfs.iter().enumerate() {
            let min = area.min + egui::vec2((k % cols) as f32 * cell.x, (k / cols) as f32 * cell.y);
            let rect = egui::Rect::from_min_size(min, cell).shrink(4.0);
            let sub = scene.only(b.id);
            ui.scope_builder(egui::UiBuilder::new().max_rect(rect), |ui| {
                ui.set_clip_rect(rect.intersect(ui.clip_rect()));
                ui.label(RichText::new(&b.label).color(b.color()).size(size).strong());
                self.panel(ui, &sub, out, Some(k));
            });
        }
        ui.allocate_rect(area, egui::Sense::hover());
    }

    /// One polar plot of `scene`'s BRDFs; `cell`: the panel's index among
    /// small multiples (no legend, no readout: the panel's title names it).
    fn panel(
        &mut self,
        ui: &mut Ui,
        scene: &Scene<'_>,
        out: &mut Vec<Command>,
        cell: Option<usize>,
    ) {
        let dark = ui.visuals().dark_mode;
        let d = scene.state.display;
        let (theta_i, phi_i) = (
            scene.incident.theta_deg.to_radians(),
            scene.incident.phi_deg.to_radians(),
        );
        let transmits = scene.brdfs.iter().any(|b| b.brdf.transmits());
        let (curves, outer) = polar_curves(scene);
        // The SH reconstruction of the selected lobe, dashed.
        let sh = crate::derive::sh::request(&super::waker(ui.ctx()), scene).and_then(|done| {
            let r = done.value.as_ref().ok()?;
            let b = scene.brdfs.iter().find(|b| b.id == r.brdf_id)?;
            let pts: Vec<[f64; 2]> = r
                .plane
                .iter()
                .map(|s| {
                    let rad = radius(s.value, d.log);
                    [rad * s.x.sin(), rad * s.x.cos()]
                })
                .collect();
            Some((
                // The error in the legend too: presenting, the toolbar's
                // error line is hidden.
                format!(
                    "{} SH L = {}: L2 error {}",
                    b.label,
                    r.lobe.order,
                    sh_overlay::percent(r.lobe.rel_l2_error)
                ),
                b.color(),
                pts,
            ))
        });
        self.sh_curve = sh.as_ref().map(|s| s.2.clone());
        // The factorisation's reconstruction, dashed in amber (as its
        // wireframe in the 3D lobe).
        let factor =
            crate::derive::factor::request(&super::waker(ui.ctx()), scene).and_then(|done| {
                let r = done.value.as_ref().ok()?;
                let b = scene.brdfs.iter().find(|b| b.id == r.brdf_id)?;
                let pts: Vec<[f64; 2]> = r
                    .plane
                    .iter()
                    .map(|s| {
                        let rad = radius(s.value, d.log);
                        [rad * s.x.sin(), rad * s.x.cos()]
                    })
                    .collect();
                Some((format!("{} factor K = {}", b.label, r.terms), pts))
            });
        self.factor_curve = factor.as_ref().map(|f| f.1.clone());
        let gonio = gonio_dots(scene, &super::waker(ui.ctx()));
        let factor_color = if dark {
            egui::Color32::from_rgb(255, 184, 51)
        } else {
            egui::Color32::from_rgb(191, 97, 0)
        };

        let grid = super::grid_color(dark);
        let text_col = super::strong_text(ui);
        let light = super::light_color(dark);
        let mirror = super::mirror_color(dark);
        // Room for the readout line, and for the swap line once a direction
        // has been hovered (before that it would be an empty band).
        // Presenting, no hover readout (nor its hint) below the plot.
        let readout_h =
            if cell.is_some() || scene.figure || (scene.presenting && self.pinned.is_none()) {
                0.0
            } else if self.pinned.is_some() {
                46.0
            } else {
                22.0
            };
        let size = ui.available_size() - egui::vec2(0.0, readout_h);
        let value_name = super::value_label(d.cosine);
        let log = d.log;

        // Presenting, the legend is a column beside the plot: in the corner
        // it covered the ωr label and a δ spike's weight once the circle
        // filled the slide's height.
        let legend: Vec<super::chart::Series> = if scene.presenting && cell.is_none() {
            let entry =
                |label: &str, color: Color32, width: f32, dash: Option<f32>| super::chart::Series {
                    label: label.to_string(),
                    color,
                    points: Vec::new(),
                    width,
                    dash,
                };
            let mut l: Vec<_> = curves
                .iter()
                .filter(|c| !c.3.is_empty())
                .map(|c| entry(&c.0, c.1, if c.2 { 2.5 } else { 1.8 }, None))
                .collect();
            if let Some((label, color, _)) = &sh {
                l.push(entry(label, *color, 2.0, Some(8.0)));
            }
            if let Some((label, _)) = &factor {
                l.push(entry(label, factor_color, 2.0, Some(12.0)));
            }
            if let Some(g) = &gonio {
                if let Some(c) = &g.reference {
                    l.push(entry(&c.label, c.color, 2.0, Some(10.0)));
                }
                for set in &g.sets {
                    let width = if set.filled { 4.0 } else { 1.5 };
                    l.push(entry(&set.label, text_col, width, None));
                }
                // Presenting, the counter is a line of the legend column:
                // under the plot it ran wider than the circle.
                l.push(entry(&g.counter, Color32::TRANSPARENT, 0.0, None));
            }
            for s in delta_spikes(scene, outer) {
                l.push(entry(&s.legend(), s.color, 1.8, None));
            }
            l
        } else {
            Vec::new()
        };
        let legend_w = super::side_legend_room(ui, &legend, size.x);
        let plot = Plot::new(super::view_id(crate::session::views::POLAR.id).with(cell));
        // A small panel keeps room for the ring values under the surface.
        let plot = if cell.is_some() {
            plot.include_y(-0.14 * outer)
        } else {
            plot
        };
        let plot = if scene.presenting || cell.is_some() {
            plot
        } else {
            super::with_legend(plot, size, scene.brdfs.len(), Corner::RightTop)
        };
        let plot = super::calm_hover(plot, scene)
            .width((size.x - legend_w).max(50.0))
            .height(size.y.max(50.0))
            .data_aspect(1.0)
            .show_axes(false)
            .show_grid(false)
            .allow_scroll(false)
            .label_formatter(move |hover| match hover {
                egui_plot::HoverPosition::NearDataPoint {
                    plot_name,
                    position,
                    ..
                } if !plot_name.is_empty() => {
                    let angle = position.x.atan2(position.y).to_degrees();
                    let v = value_at(position.x.hypot(position.y), log);
                    Some(format!(
                        "{plot_name}\nθo = {:.1}°\n{value_name} = {} 1/sr",
                        angle,
                        curves::fmt_value(v)
                    ))
                }
                _ => None,
            });

        let span: i32 = if transmits { 180 } else { 90 };
        let marks = interface_marks(scene, outer, dark);
        let draw = |pui: &mut egui_plot::PlotUi<'_>| {
            // Rings with the value they stand for, and spokes every 15°.
            // On the log scale the rings stand at round values of f.
            for (j, (r, _)) in rings(outer, log).into_iter().enumerate() {
                let n = 4 * span as usize;
                let pts: Vec<[f64; 2]> = (0..=n)
                    .map(|j| {
                        let a =
                            (-(span as f64) + 2.0 * span as f64 * j as f64 / n as f64).to_radians();
                        [r * a.sin(), r * a.cos()]
                    })
                    .collect();
                pui.line(
                    Line::new("", PlotPoints::from(pts))
                        .color(grid)
                        .width(scene.stroke(1.0))
                        .allow_hover(false),
                );
                // Ring values read along the surface line, like a radial axis;
                // a small panel labels every other ring, which keeps its
                // scale and leaves the labels room.
                if cell.is_some() && j % 2 == 0 {
                    continue;
                }
                let label = curves::fmt_tick(value_at(r, log));
                pui.text(
                    Text::new(
                        "",
                        PlotPoint::new(r, -outer * 0.015),
                        RichText::new(label).size(11.0),
                    )
                    .color(text_col.gamma_multiply(0.8))
                    .anchor(egui::Align2::CENTER_TOP)
                    .allow_hover(false),
                );
            }
            for deg in (-span..=span).step_by(15) {
                let a = (deg as f64).to_radians();
                let pts = vec![[0.0, 0.0], [outer * a.sin(), outer * a.cos()]];
                pui.line(
                    Line::new("", PlotPoints::from(pts))
                        .color(grid)
                        .width(scene.stroke(1.0))
                        .allow_hover(false),
                );
                if deg % 30 == 0 && tick_label_clear(deg, theta_i, &marks) {
                    // ±90° sit just above the surface line, clear of the ring values.
                    let lift = if deg.abs() == 90 { outer * 0.05 } else { 0.0 };
                    let p = PlotPoint::new(outer * 1.09 * a.sin(), outer * 1.09 * a.cos() + lift);
                    pui.text(
                        Text::new("", p, RichText::new(format!("{}°", deg.abs())).size(11.0))
                            .color(text_col.gamma_multiply(0.8))
                            .allow_hover(false),
                    );
                }
            }
            // The surface.
            pui.line(
                Line::new(
                    "",
                    PlotPoints::from(vec![[-outer * 1.15, 0.0], [outer * 1.15, 0.0]]),
                )
                .color(text_col.gamma_multiply(0.7))
                .width(scene.stroke(1.5))
                .allow_hover(false),
            );
            // Snell's window, the critical angle and the refracted ray.
            for m in &marks {
                match m {
                    Mark::Fill { points, color } => pui.polygon(
                        egui_plot::Polygon::new("", PlotPoints::from(points.clone()))
                            .fill_color(*color)
                            .stroke(egui::Stroke::NONE)
                            .allow_hover(false),
                    ),
                    Mark::Line {
                        points,
                        color,
                        width,
                        dash,
                    } => {
                        let mut l = Line::new("", PlotPoints::from(points.clone()))
                            .color(*color)
                            .width(scene.stroke(*width))
                            .allow_hover(false);
                        if let Some(d) = dash {
                            l = l.style(LineStyle::Dashed { length: *d });
                        }
                        pui.line(l);
                    }
                    Mark::Text { at, text, color } => pui.text(
                        Text::new(
                            "",
                            PlotPoint::new(at[0], at[1]),
                            RichText::new(text.clone()).size(13.0),
                        )
                        .color(*color)
                        .allow_hover(false),
                    ),
                }
            }
            // Light (left) and mirror direction (right).
            let li = slices::incident_signed_angle(theta_i);
            let lp = [outer * 1.2 * li.sin(), outer * 1.2 * li.cos()];
            pui.line(
                Line::new("", PlotPoints::from(vec![lp, [0.0, 0.0]]))
                    .color(light)
                    .width(scene.stroke(2.5))
                    .allow_hover(false),
            );
            pui.text(
                Text::new(
                    "",
                    PlotPoint::new(lp[0] * 1.06, lp[1] * 1.06 + outer * 0.04),
                    RichText::new("ωi").size(14.0),
                )
                .color(light)
                .allow_hover(false),
            );
            let mp = [outer * 1.12 * theta_i.sin(), outer * 1.12 * theta_i.cos()];
            pui.line(
                Line::new("", PlotPoints::from(vec![[0.0, 0.0], mp]))
                    .color(mirror)
                    .style(LineStyle::Dashed { length: 6.0 })
                    .width(scene.stroke(1.5))
                    .allow_hover(false),
            );
            pui.text(
                Text::new(
                    "",
                    PlotPoint::new(mp[0] * 1.08, mp[1] * 1.08),
                    RichText::new("ωr").size(14.0),
                )
                .color(mirror)
                .allow_hover(false),
            );
            // The curves, selected one on top.
            let mut order: Vec<&(String, Color32, bool, Vec<[f64; 2]>)> = curves.iter().collect();
            order.sort_by_key(|c| c.2);
            for (label, color, selected, pts) in order {
                pui.line(
                    Line::new(label.clone(), PlotPoints::from(pts.clone()))
                        .color(*color)
                        .width(scene.stroke(if *selected { 2.5 } else { 1.8 })),
                );
            }
            if let Some((label, color, pts)) = &sh {
                pui.line(
                    Line::new(label.clone(), PlotPoints::from(pts.clone()))
                        .color(*color)
                        .style(LineStyle::Dashed { length: 8.0 })
                        .width(scene.stroke(2.0)),
                );
            }
            if let Some((label, pts)) = &factor {
                pui.line(
                    Line::new(label.clone(), PlotPoints::from(pts.clone()))
                        .color(factor_color)
                        .style(LineStyle::Dashed { length: 12.0 })
                        .width(scene.stroke(2.0)),
                );
            }
            // The gonioreflectometer's readings: 2σ bars, then the dots.
            if let Some(g) = &gonio {
                if let Some(c) = &g.reference {
                    pui.line(
                        Line::new(c.label.clone(), PlotPoints::from(c.points.clone()))
                            .color(c.color)
                            .style(LineStyle::Dashed { length: 10.0 })
                            .width(scene.stroke(2.0)),
                    );
                }
                for set in &g.sets {
                    for bar in &set.bars {
                        pui.line(
                            Line::new("", PlotPoints::from(bar.to_vec()))
                                .color(text_col)
                                .width(scene.stroke(1.5))
                                .allow_hover(false),
                        );
                    }
                    pui.points(
                        egui_plot::Points::new(
                            set.label.clone(),
                            PlotPoints::from(set.dots.clone()),
                        )
                        .color(text_col)
                        .filled(set.filled)
                        .radius(scene.stroke(3.5)),
                    );
                }
                if !scene.presenting || cell.is_some() {
                    pui.text(
                        Text::new(
                            "",
                            PlotPoint::new(0.0, counter_y(transmits, outer)),
                            RichText::new(g.counter.clone()).size(13.0),
                        )
                        .color(text_col)
                        .anchor(egui::Align2::CENTER_BOTTOM)
                        .allow_hover(false),
                    );
                }
            }
            // Delta lobes in the plane, as labelled spikes.
            for s in delta_spikes(scene, outer) {
                pui.arrows(
                    egui_plot::Arrows::new(
                        s.legend(),
                        PlotPoints::from(vec![[0.0, 0.0]]),
                        PlotPoints::from(vec![s.tip]),
                    )
                    .color(s.color),
                );
                pui.text(
                    Text::new(
                        "",
                        PlotPoint::from(s.label_at(outer)),
                        RichText::new(s.text()).size(11.0),
                    )
                    .color(s.color)
                    .allow_hover(false),
                );
            }
            pui.pointer_coordinate()
        };
        let response = super::show_with_side_legend(ui, plot, draw, &legend, scene, legend_w);

        // Exact values along the hovered direction.
        self.readout = None;
        self.plot_rect = Some(response.response.rect);
        // No readout where a presenter's pointer happens to rest.
        if response.response.hovered()
            && !scene.presenting
            && cell.is_none()
            && let Some(p) = response.inner
        {
            let a = p.x.atan2(p.y);
            let limit = if transmits {
                std::f64::consts::PI
            } else {
                FRAC_PI_2
            };
            if a.abs() <= limit {
                self.pinned = Some(a);
                self.readout = Some(Readout {
                    axis: "θo".into(),
                    x_deg: a.to_degrees(),
                    values: scene
                        .brdfs
                        .iter()
                        .map(|b| {
                            (
                                b.label.clone(),
                                b.color(),
                                slices::plane_value(b.brdf.as_ref(), theta_i, phi_i, a, d.cosine),
                            )
                        })
                        .collect(),
                });
            }
        }
        if !scene.figure && cell.is_none() {
            if !scene.presenting {
                readout_ui(ui, self.readout.as_ref(), d.cosine);
            }
            self.swap = self.pinned.and_then(|a| {
                let b = scene.primary()?;
                let wo = slices::plane_direction(a, phi_i);
                Some(SwapReadout::new(
                    b.label.clone(),
                    b.brdf.as_ref(),
                    scene.wi(),
                    wo,
                ))
            });
            if self.swap.is_some() {
                swap_ui(ui, self.swap.as_ref(), out);
            }
        }
    }
}

/// Columns and rows of small multiples in an area of `size` (points) with a
/// title of `title_h` above each panel: the layout whose plots are largest
/// (a polar plot is 2.6 outer radii wide and 1.45 high, 2.6 high when it
/// shows transmission); on a tie, the fewest empty panels.
fn multiples_grid(n: usize, size: [f32; 2], title_h: f32, transmits: bool) -> [usize; 2] {
    let n = n.max(1);
    let aspect = if transmits { 1.0 } else { 1.45 / 2.6 };
    let scale = |cols: usize| {
        let rows = n.div_ceil(cols);
        let (w, h) = (size[0] / cols as f32, size[1] / rows as f32 - title_h);
        w.min(h / aspect)
    };
    let best = crate::gpu::sphere::best_columns(n, 1e-4, |c| f64::from(scale(c)));
    [best, n.div_ceil(best)]
}

/// The panels the polar view draws and the value of each one's outer ring
/// (1/sr, of the quantity drawn): one panel of every BRDF on one scale, or,
/// as small multiples, one panel per BRDF (its id) on its own.
pub fn panel_scales(scene: &Scene<'_>) -> Vec<(Vec<u64>, f64)> {
    let log = scene.state.display.log;
    if scene.state.plots.small_multiples && scene.brdfs.len() > 1 {
        scene
            .brdfs
            .iter()
            .map(|b| (vec![b.id], value_at(polar_curves(&scene.only(b.id)).1, log)))
            .collect()
    } else {
        vec![(
            scene.brdfs.iter().map(|b| b.id).collect(),
            value_at(polar_curves(scene).1, log),
        )]
    }
}

/// One curve of the polar plot: label, colour, selected, points (x, y) in
/// plot coordinates (radius along the outgoing direction).
type PolarCurve = (String, Color32, bool, Vec<[f64; 2]>);

/// The curves and the outer ring's radius.
fn polar_curves(scene: &Scene<'_>) -> (Vec<PolarCurve>, f64) {
    let d = scene.state.display;
    let (theta_i, phi_i) = (
        scene.incident.theta_deg.to_radians(),
        scene.incident.phi_deg.to_radians(),
    );
    let curves: Vec<PolarCurve> = scene
        .brdfs
        .iter()
        .map(|b| {
            let n = if b.brdf.transmits() {
                2 * SAMPLES
            } else {
                SAMPLES
            };
            let pts = slices::plane_of_incidence(b.brdf.as_ref(), theta_i, phi_i, n, d.cosine)
                .iter()
                .map(|s| {
                    let r = radius(s.value, d.log);
                    [r * s.x.sin(), r * s.x.cos()]
                })
                .collect();
            (b.label.clone(), b.color(), b.selected, pts)
        })
        .collect();
    let rmax = curves
        .iter()
        .flat_map(|c| c.3.iter())
        .map(|p| p[0].hypot(p[1]))
        .fold(0.0, f64::max);
    let outer = curves::nice_ceil(if rmax > 0.0 { rmax } else { radius(1.0, d.log) });
    (curves, outer)
}

/// One mark of the interface overlay in plot coordinates, drawn alike by
/// egui and the SVG export.
#[derive(Debug, Clone, PartialEq)]
pub enum Mark {
    /// A filled polygon (Snell's window).
    Fill {
        /// Corners.
        points: Vec<[f64; 2]>,
        /// Fill colour.
        color: Color32,
    },
    /// A line.
    Line {
        /// Points.
        points: Vec<[f64; 2]>,
        /// Colour.
        color: Color32,
        /// Width in points.
        width: f32,
        /// Dash length, if dashed.
        dash: Option<f32>,
    },
    /// A label centred on a point.
    Text {
        /// Anchor point.
        at: [f64; 2],
        /// The text.
        text: String,
        /// Colour.
        color: Color32,
    },
}

/// The point at radius `r` along the signed in-plane angle `a`.
/// One set of gonio readings in plot coordinates: a dot per detector stop
/// at the reading's radius, a radial bar over ±2σ.
struct DotSet {
    label: String,
    filled: bool,
    dots: Vec<[f64; 2]>,
    bars: Vec<[[f64; 2]; 2]>,
}

/// A curve the readings are set against (a surface's single-scattering
/// model, dashed).
struct RefCurve {
    label: String,
    color: Color32,
    points: Vec<[f64; 2]>,
}

/// The gonio overlay: the reading sets, the curve they are set against
/// when it is not the drawn BRDF's own, and the counter (two lines).
struct GonioDots {
    sets: Vec<DotSet>,
    reference: Option<RefCurve>,
    counter: String,
}

/// The readings as dots and bars on the plot's radius scale.
fn dot_set(
    label: String,
    filled: bool,
    readings: &[bv_core::analysis::gonio::Reading],
    d: crate::session::state::Display,
) -> DotSet {
    let at = |v: f64, theta_s: f64| polar_point(radius(v, d.log), theta_s);
    let stops = super::gonio_overlay::stops(readings, d.cosine);
    DotSet {
        label,
        filled,
        dots: stops.iter().map(|s| at(s.value, s.theta_s)).collect(),
        bars: stops
            .iter()
            .map(|s| [at(s.lo, s.theta_s), at(s.hi, s.theta_s)])
            .collect(),
    }
}

/// The gonioreflectometer's readings of the primary BRDF (or of a surface
/// with its slopes) as the polar plot draws them; `None` with the overlay
/// off or nothing measured yet.
fn gonio_dots(scene: &Scene<'_>, waker: &crate::derive::jobs::Waker) -> Option<GonioDots> {
    use crate::derive::gonio::Specimen;
    let shown = crate::derive::gonio::request(waker, scene)?;
    let done = shown.done?;
    let m = &done.value;
    let b = scene.primary()?;
    let d = scene.state.display;
    let step = m.setup.step_deg;
    let count = |n: u64| {
        let n = n as f64;
        if n >= 1e6 {
            format!("{:.1} M", n / 1e6)
        } else {
            format!("{:.0} k", n / 1e3)
        }
    };
    let grid = format!(
        "an isotropic sample at 1°: 90 θi × 90 θo × 180 Δφ = {} cells",
        grouped(bv_core::analysis::gonio::isotropic_grid_cells(1.0))
    );
    match (m.specimen, &m.single) {
        (Specimen::Surface(dist, ax, ay), Some(single)) => {
            let alpha = if ax == ay {
                format!("α {ax:.2}")
            } else {
                format!("αx {ax:.2}, αy {ay:.2}")
            };
            let reference =
                super::gonio_overlay::f1_section(scene, &m.setup, 2 * SAMPLES).map(|c| RefCurve {
                    label: format!("{}, F = 1: one bounce", b.label),
                    color: b.color(),
                    points: c
                        .into_iter()
                        .map(|(t, v)| polar_point(radius(v, d.log), t))
                        .collect(),
                });
            Some(GonioDots {
                sets: vec![
                    dot_set(
                        format!("surface, all bounces ({} rays)", count(m.photons)),
                        true,
                        &m.readings,
                        d,
                    ),
                    dot_set("surface, one bounce".into(), false, single, d),
                ],
                reference,
                counter: format!(
                    "{} stops of {step}° over a simulated {} {alpha} surface \
                     ({}², F = 1)\n{grid}",
                    m.readings.len(),
                    dist.label(),
                    crate::derive::gonio::SURFACE_SIZE
                ),
            })
        }
        _ => Some(GonioDots {
            sets: vec![dot_set(
                format!("{} measured ({} photons)", b.label, count(m.photons)),
                true,
                &m.readings,
                d,
            )],
            reference: None,
            counter: format!(
                "{} detector stops, {step}° apart, in one plane\n{grid}",
                m.readings.len()
            ),
        }),
    }
}

/// Where the gonio counter's two lines end (their bottom, so that the
/// plot's bounds take them in): under the surface line, or
/// under the whole circle (and Snell's window label) for a transmitting
/// model.
fn counter_y(transmits: bool, outer: f64) -> f64 {
    if transmits {
        -outer * 1.52
    } else {
        -outer * 0.24
    }
}

/// An integer with its digits in groups of three (`1 458 000`).
fn grouped(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

fn polar_point(r: f64, a: f64) -> [f64; 2] {
    [r * a.sin(), r * a.cos()]
}

/// Shortest δ spike, as a fraction of the outer ring. A spike's length is
/// its flux weight, and a small one (glass's F = 0.04 at normal incidence)
/// would be a dot hidden under the origin's labels; its label gives the true
/// weight (LECTURE.md, N3).
pub const MIN_SPIKE: f64 = 0.25;

/// A delta lobe in the plane of incidence, as the polar plot draws it.
#[derive(Debug, Clone, PartialEq)]
pub struct Spike {
    /// The BRDF's label.
    pub label: String,
    /// Its colour.
    pub color: Color32,
    /// The tip, in plot units (the origin is the hit point, +y the normal).
    pub tip: [f64; 2],
    /// The lobe's flux weight (mean of r, g, b): what its label reads.
    pub weight: f64,
    /// For a transmitted lobe, the factor on radiance along it,
    /// `(ηo/ηi)² (1 − F)` (mean of r, g, b): radiance is compressed
    /// entering a denser medium, so it differs from the flux weight.
    pub radiance: Option<f64>,
}

impl Spike {
    /// Where its label goes (plot units), `outer` the outer ring's radius:
    /// past the tip of a short spike; beside a long one, two thirds of the
    /// way out and to its horizon side, since past its tip it would sit on
    /// the ωr or ωt label at the end of the same direction.
    pub fn label_at(&self, outer: f64) -> [f64; 2] {
        let [x, y] = self.tip;
        let len = x.hypot(y);
        if len < 0.6 * outer || len == 0.0 {
            return [x * 1.08, y * 1.08];
        }
        // The unit normal to the spike pointing away from the surface
        // normal (+y), towards the horizon.
        let (ux, uy) = (x / len, y / len);
        let (mut px, mut py) = (uy, -ux);
        if px * x < 0.0 {
            (px, py) = (-px, -py);
        }
        let off = 0.1 * outer;
        [0.62 * x + off * px, 0.62 * y + off * py]
    }

    /// The legend entry: `glass δ reflected` or `glass δ transmitted`.
    pub fn legend(&self) -> String {
        let kind = if self.radiance.is_some() {
            "transmitted"
        } else {
            "reflected"
        };
        format!("{} δ {kind}", self.label)
    }

    /// The label: `δ 0.050`, or for a transmitted lobe
    /// `δ 0.950, radiance × 2.138` (LECTURE.md N3).
    pub fn text(&self) -> String {
        match self.radiance {
            Some(r) => format!("δ {:.3}, radiance × {r:.3}", self.weight),
            None => format!("δ {:.3}", self.weight),
        }
    }
}

/// The δ lobes of the scene's BRDFs that lie in the plane of incidence: each
/// reaches its weight of `outer`, and at least [`MIN_SPIKE`] of it.
pub fn delta_spikes(scene: &Scene<'_>, outer: f64) -> Vec<Spike> {
    let phi_i = scene.incident.phi_deg.to_radians();
    let plane_n = glam::DVec3::new(-phi_i.sin(), phi_i.cos(), 0.0);
    let mut out = Vec::new();
    for b in &scene.brdfs {
        for dl in b.brdf.deltas(scene.wi()) {
            let dir = dl.direction;
            if dir.dot(plane_n).abs() > 1e-6 {
                continue;
            }
            // Signed in-plane angle: positive towards the mirror side.
            let along = -(dir.x * phi_i.cos() + dir.y * phi_i.sin());
            let a = along.atan2(dir.z);
            let weight = bv_core::mean_rgb(dl.weight);
            let len = outer * weight.max(MIN_SPIKE);
            out.push(Spike {
                label: b.label.clone(),
                color: b.color(),
                tip: [len * a.sin(), len * a.cos()],
                weight,
                radiance: (dl.kind == bv_core::DeltaKind::Transmission)
                    .then(|| bv_core::mean_rgb(dl.radiance_scale)),
            });
        }
    }
    out
}

/// The interface overlay of a transmitting model (issue 33): Snell's window
/// shaded and bounded by the critical angle on the denser side, the
/// refracted direction ωt with θt, or "TIR" when the light is beyond the
/// critical angle inside the denser medium. Empty for reflection-only
/// scenes, which keep the plot they always had. The numbers are
/// [`InterfaceMarks`]'s (`bv_core::optics`).
pub fn interface_marks(scene: &Scene<'_>, outer: f64, dark: bool) -> Vec<Mark> {
    let Some((label, eta)) = super::interface_model(scene) else {
        return Vec::new();
    };
    let theta_i = scene.incident.theta_deg.to_radians();
    let Some(m) = InterfaceMarks::new(theta_i, eta) else {
        return Vec::new();
    };
    let refr = if dark {
        Color32::from_rgb(110, 190, 255)
    } else {
        Color32::from_rgb(20, 100, 200)
    };
    let window = Color32::from_rgba_unmultiplied(255, 220, 90, if dark { 40 } else { 55 });
    let window_line = if dark {
        Color32::from_rgb(230, 200, 80)
    } else {
        Color32::from_rgb(170, 130, 0)
    };
    let tir = if dark {
        Color32::from_rgb(255, 120, 120)
    } else {
        Color32::from_rgb(190, 30, 30)
    };
    let mut out = Vec::new();
    if let (Some(c), Some([a0, a1])) = (m.critical, m.window_edges()) {
        // The window as a wedge around the dense side's normal.
        let n = 48;
        let mut pts = vec![[0.0, 0.0]];
        pts.extend((0..=n).map(|k| {
            let a = m.window_axis - c + 2.0 * c * k as f64 / n as f64;
            polar_point(outer, a)
        }));
        out.push(Mark::Fill {
            points: pts,
            color: window,
        });
        for a in [a0, a1] {
            out.push(Mark::Line {
                points: vec![[0.0, 0.0], polar_point(outer * 1.05, a)],
                color: window_line,
                width: 1.5,
                dash: Some(4.0),
            });
        }
        // Named outside the rings (where no curve runs) past the window's
        // axis, where neither the light nor the mirror direction is (they
        // sit at ∓θi, near the edges when θi is near 180° − θc); beside an
        // edge when the light itself is near the axis.
        let light_near_axis = (PI - theta_i).abs() < 0.35 || theta_i < 0.35;
        let place = if !light_near_axis {
            m.window_axis
        } else if m.light_below == m.dense_below {
            a1
        } else {
            a0
        };
        // One label: two stacked ones overlapped each other and the ring's
        // angle label at presentation mode's text size.
        out.push(Mark::Text {
            at: polar_point(outer * 1.27, place),
            text: format!("Snell's window, θc {:.1}°", c.to_degrees()),
            color: window_line,
        });
    }
    match (m.refracted, m.theta_t) {
        (Some(a), Some(t)) => {
            let tip = polar_point(outer * 1.12, a);
            out.push(Mark::Line {
                points: vec![[0.0, 0.0], tip],
                color: refr,
                width: 2.0,
                dash: Some(9.0),
            });
            out.push(Mark::Text {
                at: [tip[0] * 1.1, tip[1] * 1.1],
                text: format!("ωt θt {:.1}°", t.to_degrees()),
                color: refr,
            });
        }
        _ if m.tir => {
            // Of the mean surface: a rough one still refracts through the
            // microfacets tilted towards the light.
            out.push(Mark::Text {
                at: [-outer * 1.25, -outer * 0.16],
                text: "no refracted ray: TIR beyond θc".into(),
                color: tir,
            });
        }
        _ => {}
    }
    // Which BRDF the interface is, when there is more than one to tell
    // apart (a panel of small multiples names its BRDF in its title).
    let text = if scene.brdfs.len() > 1 {
        format!("η {eta:.3} ({label})")
    } else {
        format!("η {eta:.3}")
    };
    out.push(Mark::Text {
        at: [-outer * 1.25, -outer * 0.06],
        text,
        color: window_line,
    });
    out
}

/// The ring radii (plot units) and the values they stand for.
fn rings(outer: f64, log: bool) -> Vec<(f64, f64)> {
    (1..=4)
        .map(|k| {
            let r = if log {
                radius(
                    curves::round_significant(value_at(outer * k as f64 / 4.0, log), 2),
                    log,
                )
            } else {
                outer * k as f64 / 4.0
            };
            (r, value_at(r, log))
        })
        .collect()
}

/// The polar plot as SVG: the same rings, spokes, markers and curves.
pub fn polar_svg(scene: &Scene<'_>, size: [f32; 2], dark: bool) -> String {
    use super::svg::{Anchor, Baseline, Svg};
    let [w, h] = [size[0].max(120.0), size[1].max(90.0)];
    let mut svg = Svg::new(w, h);
    if !(scene.state.plots.small_multiples && scene.brdfs.len() > 1) {
        polar_svg_panel(&mut svg, scene, [w, h], dark, false);
        return svg.finish();
    }
    // Small multiples: a panel per BRDF, its name above it.
    let pal = super::chart::Palette::new(dark, scene.transparent);
    if let Some(bg) = pal.background {
        svg.rect([0.0, 0.0], [w, h], Some(bg), None);
    }
    let transmits = scene.brdfs.iter().any(|b| b.brdf.transmits());
    let title_h = 20.0;
    let [cols, rows] = multiples_grid(scene.brdfs.len(), [w, h], title_h, transmits);
    let cell = [w / cols as f32, h / rows as f32];
    for (k, b) in scene.brdfs.iter().enumerate() {
        let at = [(k % cols) as f32 * cell[0], (k / cols) as f32 * cell[1]];
        svg.begin_translate(at);
        svg.text(
            [8.0, 4.0],
            &b.label,
            14.0,
            b.color(),
            Anchor::Start,
            Baseline::Top,
            None,
        );
        svg.begin_translate([0.0, title_h]);
        polar_svg_panel(
            &mut svg,
            &scene.only(b.id),
            [cell[0], cell[1] - title_h],
            dark,
            true,
        );
        svg.end_group();
        svg.end_group();
    }
    svg.finish()
}

/// One polar plot of `scene`'s BRDFs drawn into `svg` over `[0, size]`;
/// `titled`: a panel of small multiples, whose title names its BRDF (its
/// curve then has no legend entry).
fn polar_svg_panel(
    svg: &mut super::svg::Svg,
    scene: &Scene<'_>,
    size: [f32; 2],
    dark: bool,
    titled: bool,
) {
    use super::chart::{Palette, Series, legend};
    use super::svg::{Anchor, Baseline};
    let d = scene.state.display;
    let pal = Palette::new(dark, scene.transparent);
    let (curves, outer) = polar_curves(scene);
    let transmits = scene.brdfs.iter().any(|b| b.brdf.transmits());
    let theta_i = scene.incident.theta_deg.to_radians();
    let [w, h] = [size[0].max(120.0), size[1].max(90.0)];
    if let Some(bg) = pal.background {
        svg.rect([0.0, 0.0], [w, h], Some(bg), None);
    }
    // Data extents (plot units) and a uniform scale that fits them.
    let (x0, x1) = (-1.3 * outer, 1.3 * outer);
    let gonio = gonio_dots(scene, &crate::derive::jobs::Waker::none());
    // Room under the plot for the gonio counter's two lines.
    let counter_room = match (&gonio, transmits) {
        (None, _) => 0.0,
        (Some(_), false) => 0.12 * outer,
        (Some(_), true) => 0.25 * outer,
    };
    let (y0, y1) = if transmits {
        (-1.3 * outer - counter_room, 1.3 * outer)
    } else {
        (-0.15 * outer - counter_room, 1.3 * outer)
    };
    let k = ((w - 20.0) as f64 / (x1 - x0)).min((h - 20.0) as f64 / (y1 - y0));
    let cx = w as f64 * 0.5 - (x0 + x1) * 0.5 * k;
    let cy = h as f64 * 0.5 + (y0 + y1) * 0.5 * k;
    let at = |p: [f64; 2]| [(cx + p[0] * k) as f32, (cy - p[1] * k) as f32];
    let text_col = pal.text.gamma_multiply(0.8);
    let span: i32 = if transmits { 180 } else { 90 };
    for (r, v) in rings(outer, d.log) {
        let n = 4 * span as usize;
        let pts: Vec<[f32; 2]> = (0..=n)
            .map(|j| {
                let a = (-(span as f64) + 2.0 * span as f64 * j as f64 / n as f64).to_radians();
                at([r * a.sin(), r * a.cos()])
            })
            .collect();
        svg.polyline(&pts, pal.grid, 1.0, None);
        svg.text(
            at([r, -outer * 0.015]),
            &curves::fmt_tick(v),
            10.5,
            text_col,
            Anchor::Middle,
            Baseline::Top,
            None,
        );
    }
    let marks = interface_marks(scene, outer, dark);
    for deg in (-span..=span).step_by(15) {
        let a = f64::from(deg).to_radians();
        svg.line(
            at([0.0, 0.0]),
            at([outer * a.sin(), outer * a.cos()]),
            pal.grid,
            1.0,
            None,
        );
        if deg % 30 == 0 && tick_label_clear(deg, theta_i, &marks) {
            let lift = if deg.abs() == 90 { outer * 0.05 } else { 0.0 };
            svg.text(
                at([outer * 1.09 * a.sin(), outer * 1.09 * a.cos() + lift]),
                &format!("{}°", deg.abs()),
                10.5,
                text_col,
                Anchor::Middle,
                Baseline::Middle,
                None,
            );
        }
    }
    svg.line(
        at([-outer * 1.15, 0.0]),
        at([outer * 1.15, 0.0]),
        pal.text.gamma_multiply(0.7),
        1.5,
        None,
    );
    for m in marks {
        match m {
            Mark::Fill { points, color } => {
                let p: Vec<[f32; 2]> = points.iter().map(|p| at(*p)).collect();
                svg.polygon(&p, color);
            }
            Mark::Line {
                points,
                color,
                width,
                dash,
            } => {
                let p: Vec<[f32; 2]> = points.iter().map(|p| at(*p)).collect();
                svg.polyline(&p, color, width, dash);
            }
            Mark::Text { at: p, text, color } => svg.text(
                at(p),
                &text,
                12.0,
                color,
                Anchor::Middle,
                Baseline::Middle,
                None,
            ),
        }
    }
    let light = super::light_color(dark);
    let mirror = super::mirror_color(dark);
    let li = slices::incident_signed_angle(theta_i);
    let lp = [outer * 1.2 * li.sin(), outer * 1.2 * li.cos()];
    svg.line(at(lp), at([0.0, 0.0]), light, 2.5, None);
    svg.text(
        at([lp[0] * 1.06, lp[1] * 1.06 + outer * 0.04]),
        "ωi",
        14.0,
        light,
        Anchor::Middle,
        Baseline::Middle,
        None,
    );
    let mp = [outer * 1.12 * theta_i.sin(), outer * 1.12 * theta_i.cos()];
    svg.line(at([0.0, 0.0]), at(mp), mirror, 1.5, Some(6.0));
    svg.text(
        at([mp[0] * 1.08, mp[1] * 1.08]),
        "ωr",
        14.0,
        mirror,
        Anchor::Middle,
        Baseline::Middle,
        None,
    );
    let mut order: Vec<&PolarCurve> = curves.iter().collect();
    order.sort_by_key(|c| c.2);
    let mut series = Vec::new();
    for (label, color, selected, pts) in order {
        let width = if *selected { 2.5 } else { 1.8 };
        let p: Vec<[f32; 2]> = pts.iter().map(|p| at(*p)).collect();
        svg.polyline(&p, *color, width, None);
        series.push(Series {
            label: label.clone(),
            color: *color,
            points: Vec::new(),
            width,
            dash: None,
        });
    }
    if let Some(g) = &gonio {
        if let Some(c) = &g.reference {
            let p: Vec<[f32; 2]> = c.points.iter().map(|p| at(*p)).collect();
            svg.polyline(&p, c.color, 2.0, Some(10.0));
            series.push(Series {
                label: c.label.clone(),
                color: c.color,
                points: Vec::new(),
                width: 2.0,
                dash: Some(10.0),
            });
        }
        for set in &g.sets {
            for bar in &set.bars {
                svg.line(at(bar[0]), at(bar[1]), pal.text, 1.5, None);
            }
            for p in &set.dots {
                let c = at(*p);
                let r = 3.5;
                let ring: Vec<[f32; 2]> = (0..=12)
                    .map(|j| {
                        let a = j as f32 * std::f32::consts::TAU / 12.0;
                        [c[0] + r * a.cos(), c[1] + r * a.sin()]
                    })
                    .collect();
                if set.filled {
                    svg.polygon(&ring, pal.text);
                } else {
                    svg.polyline(&ring, pal.text, 1.5, None);
                }
            }
            series.push(Series {
                label: set.label.clone(),
                color: pal.text,
                points: Vec::new(),
                width: if set.filled { 4.0 } else { 1.5 },
                dash: None,
            });
        }
        let [x, y] = at([0.0, counter_y(transmits, outer)]);
        let lines: Vec<&str> = g.counter.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            svg.text(
                [x, y - 14.0 * (lines.len() - 1 - i) as f32],
                line,
                11.0,
                pal.text,
                Anchor::Middle,
                Baseline::Bottom,
                None,
            );
        }
    }
    for s in delta_spikes(scene, outer) {
        svg.line(at([0.0, 0.0]), at(s.tip), s.color, 2.0, None);
        svg.text(
            at(s.label_at(outer)),
            &s.text(),
            10.5,
            s.color,
            Anchor::Middle,
            Baseline::Middle,
            None,
        );
    }
    svg.text(
        [10.0, h - 8.0],
        &format!(
            "radius: {} (1/sr){}",
            super::value_label(d.cosine),
            if d.log { ", ln(1 + value)" } else { "" }
        ),
        11.0,
        pal.weak,
        Anchor::Start,
        Baseline::Bottom,
        None,
    );
    if titled {
        series.retain(|e| !scene.brdfs.iter().any(|b| b.label == e.label));
    }
    legend(svg, &series, [w - 4.0, 4.0], pal);
}

/// Whether the angle label of spoke `deg` (signed, from the normal) is
/// drawn: not where the light's line or the mirror direction's runs
/// through it (within 8°), where the ωi and ωr labels say the angle, nor
/// under one of the interface's labels outside the rings (`marks`: ωt's,
/// Snell's window's; within 16°).
fn tick_label_clear(deg: i32, theta_i: f64, marks: &[Mark]) -> bool {
    let d = f64::from(deg);
    let light = slices::incident_signed_angle(theta_i).to_degrees();
    // (The medium's name beside the surface line leaves ±90° alone: those
    // labels are lifted above the line.)
    let taken = marks
        .iter()
        .filter_map(|m| match m {
            Mark::Text { at, .. } if at[0].hypot(at[1]) > 0.0 => {
                Some(at[0].atan2(at[1]).to_degrees())
            }
            _ => None,
        })
        .filter(|a| (a.abs() - 90.0).abs() > 12.0);
    // The interface's labels are wider than ωi and ωr: 16° either side.
    [light, theta_i.to_degrees()]
        .into_iter()
        .all(|a| (d - a).abs() >= 8.0)
        && taken.into_iter().all(|a| (d - a).abs() >= 16.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spoke_labels_give_way_to_the_light_and_the_mirror() {
        let t = 60f64.to_radians();
        // The light on the left (−60°), the mirror direction at +60°.
        assert!(!tick_label_clear(-60, t, &[]) && !tick_label_clear(60, t, &[]));
        assert!(tick_label_clear(-30, t, &[]) && tick_label_clear(30, t, &[]));
        assert!(tick_label_clear(0, t, &[]));
        // Light from below (θi 120°): it comes from −120°, the mirror is at +120°.
        let b = 120f64.to_radians();
        assert!(!tick_label_clear(-120, b, &[]) && !tick_label_clear(120, b, &[]));
        assert!(tick_label_clear(-90, b, &[]) && tick_label_clear(150, b, &[]));
        // A label outside the rings at 153° (ωt's) takes the 150° spoke's.
        let a = 153f64.to_radians();
        let wt = Mark::Text {
            at: [1.2 * a.sin(), 1.2 * a.cos()],
            text: "ωt".into(),
            color: Color32::WHITE,
        };
        assert!(!tick_label_clear(150, t, std::slice::from_ref(&wt)));
        assert!(tick_label_clear(-150, t, &[wt]));
    }

    #[test]
    fn small_multiples_fill_the_area() {
        // Four reflection plots on a slide: 2 × 2; on a wide strip: a row.
        assert_eq!(multiples_grid(4, [1800.0, 800.0], 30.0, false), [2, 2]);
        assert_eq!(multiples_grid(4, [3000.0, 300.0], 20.0, false), [4, 1]);
        // Transmission doubles a plot's height: three side by side.
        assert_eq!(multiples_grid(3, [1800.0, 600.0], 30.0, true), [3, 1]);
        // Five: 3 + 2 rather than 4 + 1 or 5.
        assert_eq!(multiples_grid(5, [1800.0, 900.0], 30.0, false), [3, 2]);
        assert_eq!(multiples_grid(1, [100.0, 100.0], 10.0, false), [1, 1]);
    }

    #[test]
    fn radius_and_value_are_inverse() {
        for v in [0.0, 0.3, 5.0, 1234.0] {
            for log in [false, true] {
                assert!((value_at(radius(v, log), log) - v).abs() < 1e-9 * (1.0 + v));
            }
        }
    }
}
