//! Cartesian plot of `f` versus an angle: θo in the plane of incidence
//! (negative on the light's side), or θh at a fixed θd, or θd at a fixed θh
//! (Rusinkiewicz angles with φh = 0 and φd = 90°). Every drawn BRDF in its
//! colour, a legend, a log toggle and the exact values under the pointer.

use super::BrdfColor as _;
use super::chart::{self, Chart, Marker, Palette, Series};
use super::curves;
use super::polar::{Readout, readout_ui};
use super::{Scene, View};
use crate::derive::slices::{self, HalfDiffAxis};
use crate::session::command::Command;
use crate::session::state::CartesianAxis;
use eframe::egui::{self, Color32, RichText, Ui};
use egui_plot::{Corner, Line, LineStyle, Plot, PlotPoint, PlotPoints, Text, VLine};

/// Samples per curve over 180° (0.25° steps).
const SAMPLES: usize = 720;

/// The Cartesian plot view.
#[derive(Default)]
pub struct CartesianView {
    /// The values under the pointer in the last frame.
    pub readout: Option<Readout>,
    /// Where the plot was drawn in the last frame.
    pub plot_rect: Option<egui::Rect>,
    /// The y range the plot showed in the last frame (decades on the log
    /// scale).
    pub y_bounds: Option<(f64, f64)>,
}

fn axis_name(a: CartesianAxis) -> &'static str {
    match a {
        CartesianAxis::ThetaO => "θo",
        CartesianAxis::ThetaH => "θh",
        CartesianAxis::ThetaD => "θd",
    }
}

impl View for CartesianView {
    fn toolbar(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        super::display_toggles(ui, scene, out);
        let p = scene.state.plots;
        let mut axis = p.axis;
        egui::ComboBox::new(
            super::view_id(crate::session::views::CARTESIAN.id).with("axis"),
            "x axis",
        )
        .selected_text(axis_name(axis))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut axis, CartesianAxis::ThetaO, "θo (plane of incidence)");
            ui.selectable_value(&mut axis, CartesianAxis::ThetaH, "θh (fixed θd)");
            ui.selectable_value(&mut axis, CartesianAxis::ThetaD, "θd (fixed θh)");
        });
        if axis != p.axis {
            out.push(Command::SetCartesianAxis(axis));
        }
        let mut p2 = p;
        match axis {
            CartesianAxis::ThetaO => {}
            CartesianAxis::ThetaH => {
                ui.add(
                    egui::Slider::new(&mut p2.fixed_theta_d_deg, 0.0..=89.5)
                        .text("θd")
                        .suffix("°")
                        .update_while_editing(false),
                );
            }
            CartesianAxis::ThetaD => {
                ui.add(
                    egui::Slider::new(&mut p2.fixed_theta_h_deg, 0.0..=89.5)
                        .text("θh")
                        .suffix("°")
                        .update_while_editing(false),
                );
            }
        }
        if p2 != p {
            // Keep the axis chosen in this same frame.
            p2.axis = axis;
            out.push(Command::SetPlots(p2));
        }
    }

    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, _out: &mut Vec<Command>) {
        let dark = ui.visuals().dark_mode;
        let d = scene.state.display;
        let p = scene.state.plots;
        let (theta_i, phi_i) = (
            scene.incident.theta_deg.to_radians(),
            scene.incident.phi_deg.to_radians(),
        );
        let Data {
            curves: data,
            bottom,
            top,
            x_label,
            y_label,
        } = Data::compute(scene);
        let log = d.log;
        let y_of = move |v: f64| if log { curves::log_ordinate(v) } else { v };
        let value_name = super::value_label(d.cosine);
        let axis = p.axis;
        let x_name = axis_name(axis);

        // Presenting, no hover readout (nor its hint) below the plot.
        let readout_h = if scene.figure || scene.presenting {
            0.0
        } else {
            22.0
        };
        let size = ui.available_size() - egui::vec2(0.0, readout_h);
        // Presenting, the legend is a column beside the plot (a curve
        // rising to the right, GGX's tail, ran under it in the corner).
        let legend: Vec<super::chart::Series> = if scene.presenting {
            data.iter()
                .map(|(b, _)| super::chart::Series {
                    label: b.label.clone(),
                    color: b.color(),
                    points: Vec::new(),
                    width: if b.selected { 2.5 } else { 1.8 },
                    dash: None,
                })
                .collect()
        } else {
            Vec::new()
        };
        let legend_w = super::side_legend_room(ui, &legend, size.x);
        let plot = Plot::new(super::view_id(crate::session::views::CARTESIAN.id))
            .width((size.x - legend_w).max(50.0))
            .height(size.y.max(50.0));
        let plot = if scene.presenting {
            super::calm_hover(plot, scene)
        } else {
            super::with_legend(plot, size, scene.brdfs.len(), Corner::RightTop)
        };
        let mut plot = plot
            .x_axis_label(x_label)
            .y_axis_label(y_label)
            .y_axis_min_width(44.0)
            // Angles read in steps a lecturer uses: 15°, 45°, 90°.
            .x_grid_spacer(egui_plot::uniform_grid_spacer(|input| {
                let span = input.bounds.1 - input.bounds.0;
                if span > 200.0 {
                    [10.0, 30.0, 90.0]
                } else if span > 50.0 {
                    [5.0, 15.0, 45.0]
                } else {
                    [1.0, 5.0, 15.0]
                }
            }))
            .allow_scroll(false)
            .label_formatter(move |hover| match hover {
                egui_plot::HoverPosition::NearDataPoint {
                    plot_name,
                    position,
                    ..
                } if !plot_name.is_empty() => {
                    let v = if log {
                        10f64.powf(position.y)
                    } else {
                        position.y
                    };
                    Some(format!(
                        "{plot_name}\n{x_name} = {:.1}°\n{value_name} = {} 1/sr",
                        position.x,
                        curves::fmt_value(v)
                    ))
                }
                _ => None,
            });
        if log {
            // The axis spans the decades the data reach (see
            // `curves::LogRange`): curves below it leave through the bottom
            // edge, clipped, rather than resting on a floor.
            plot = plot
                .default_y_bounds(bottom, top)
                .y_axis_formatter(|mark, _| {
                    curves::decade_mark_label(mark.value, mark.step_size)
                        .map(super::decade_label)
                        .unwrap_or_default()
                })
                .y_grid_spacer(|input| curves::log_grid_marks(input.bounds, input.base_step_size));
        } else {
            plot = curves::with_linear_y(plot.include_y(bottom).include_y(top));
        }
        let light = super::light_color(dark);
        let mirror = super::mirror_color(dark);
        let wi = scene.wi();
        let draw = |pui: &mut egui_plot::PlotUi<'_>| {
            if axis == CartesianAxis::ThetaO {
                let li = slices::incident_signed_angle(theta_i).to_degrees();
                pui.vline(
                    VLine::new("", li)
                        .color(light)
                        .width(scene.stroke(2.0))
                        .allow_hover(false),
                );
                pui.vline(
                    VLine::new("", theta_i.to_degrees())
                        .color(mirror)
                        .style(LineStyle::Dashed { length: 6.0 })
                        .width(scene.stroke(1.5))
                        .allow_hover(false),
                );
                pui.text(
                    Text::new(
                        "",
                        PlotPoint::new(li, bottom),
                        RichText::new(" ωi ").size(14.0),
                    )
                    .color(light)
                    .anchor(egui::Align2::RIGHT_BOTTOM)
                    .allow_hover(false),
                );
                pui.text(
                    Text::new(
                        "",
                        PlotPoint::new(theta_i.to_degrees(), bottom),
                        RichText::new(" ωr ").size(14.0),
                    )
                    .color(mirror)
                    .anchor(egui::Align2::LEFT_BOTTOM)
                    .allow_hover(false),
                );
                // Delta lobes: where they point, with their weight.
                for (b, _) in &data {
                    for dl in b.brdf.deltas(wi) {
                        let along = -(dl.direction.x * phi_i.cos() + dl.direction.y * phi_i.sin());
                        let a = along.atan2(dl.direction.z).to_degrees();
                        let w = bv_core::mean_rgb(dl.weight);
                        pui.vline(
                            VLine::new(format!("{} δ", b.label), a)
                                .color(b.color())
                                .style(LineStyle::Dotted { spacing: 4.0 })
                                .width(scene.stroke(2.0)),
                        );
                        pui.text(
                            Text::new(
                                "",
                                PlotPoint::new(a, bottom + (top - bottom) * 0.85),
                                RichText::new(format!("δ {w:.3}")).size(11.0),
                            )
                            .color(b.color())
                            .anchor(egui::Align2::LEFT_TOP)
                            .allow_hover(false),
                        );
                    }
                }
            }
            let mut order: Vec<&(&super::SceneBrdf, Vec<slices::Sample>)> = data.iter().collect();
            order.sort_by_key(|(b, _)| b.selected);
            for (b, samples) in order {
                let pts: Vec<[f64; 2]> = samples
                    .iter()
                    .map(|s| [s.x.to_degrees(), y_of(s.value)])
                    .collect();
                pui.line(
                    Line::new(b.label.clone(), PlotPoints::from(pts))
                        .color(b.color())
                        .width(scene.stroke(if b.selected { 2.5 } else { 1.8 })),
                );
            }
            pui.pointer_coordinate()
        };
        let response = super::show_with_side_legend(ui, plot, draw, &legend, scene, legend_w);

        self.readout = None;
        self.plot_rect = Some(response.response.rect);
        let b = response.transform.bounds();
        self.y_bounds = Some((b.min()[1], b.max()[1]));
        // No readout where a presenter's pointer happens to rest.
        if response.response.hovered()
            && !scene.presenting
            && let Some(pc) = response.inner
        {
            let x = pc.x.to_radians();
            let values: Vec<(String, Color32, slices::Sample)> = scene
                .brdfs
                .iter()
                .map(|b| {
                    let s = match axis {
                        CartesianAxis::ThetaO => {
                            slices::plane_value(b.brdf.as_ref(), theta_i, phi_i, x, d.cosine)
                        }
                        CartesianAxis::ThetaH => slices::half_diff_value(
                            b.brdf.as_ref(),
                            HalfDiffAxis::ThetaH,
                            p.fixed_theta_d_deg.to_radians(),
                            x,
                            d.cosine,
                        ),
                        CartesianAxis::ThetaD => slices::half_diff_value(
                            b.brdf.as_ref(),
                            HalfDiffAxis::ThetaD,
                            p.fixed_theta_h_deg.to_radians(),
                            x,
                            d.cosine,
                        ),
                    };
                    (b.label.clone(), b.color(), s)
                })
                .collect();
            let limit = match axis {
                CartesianAxis::ThetaO if scene.brdfs.iter().any(|b| b.brdf.transmits()) => 180.0,
                CartesianAxis::ThetaO => 90.0,
                _ => 90.0,
            };
            let in_range = match axis {
                CartesianAxis::ThetaO => pc.x.abs() <= limit,
                _ => (0.0..=limit).contains(&pc.x),
            };
            if in_range {
                self.readout = Some(Readout {
                    axis: x_name.into(),
                    x_deg: pc.x,
                    values,
                });
            }
        }
        if !scene.figure && !scene.presenting {
            readout_ui(ui, self.readout.as_ref(), d.cosine);
        }
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn svg(&mut self, scene: &Scene<'_>, size: [f32; 2], dark: bool) -> Option<String> {
        Some(chart(scene, dark).to_svg(size, Palette::new(dark, scene.transparent)))
    }
}

/// The curves of one frame and the axes they need (shared by the plot and
/// its SVG).
struct Data<'s> {
    curves: Vec<(&'s super::SceneBrdf, Vec<slices::Sample>)>,
    /// The y range: in decades on the log scale.
    bottom: f64,
    top: f64,
    x_label: String,
    y_label: String,
}

impl<'s> Data<'s> {
    fn compute(scene: &'s Scene<'_>) -> Self {
        let d = scene.state.display;
        let p = scene.state.plots;
        let (theta_i, phi_i) = (
            scene.incident.theta_deg.to_radians(),
            scene.incident.phi_deg.to_radians(),
        );
        let eval = |b: &super::SceneBrdf| -> Vec<slices::Sample> {
            match p.axis {
                CartesianAxis::ThetaO => {
                    let n = if b.brdf.transmits() {
                        2 * SAMPLES
                    } else {
                        SAMPLES
                    };
                    slices::plane_of_incidence(b.brdf.as_ref(), theta_i, phi_i, n, d.cosine)
                }
                CartesianAxis::ThetaH => slices::half_diff_slice(
                    b.brdf.as_ref(),
                    HalfDiffAxis::ThetaH,
                    p.fixed_theta_d_deg.to_radians(),
                    SAMPLES / 2,
                    d.cosine,
                ),
                CartesianAxis::ThetaD => slices::half_diff_slice(
                    b.brdf.as_ref(),
                    HalfDiffAxis::ThetaD,
                    p.fixed_theta_h_deg.to_radians(),
                    SAMPLES / 2,
                    d.cosine,
                ),
            }
        };
        let curves: Vec<(&super::SceneBrdf, Vec<slices::Sample>)> =
            scene.brdfs.iter().map(|b| (b, eval(b))).collect();
        let values = || curves.iter().flat_map(|(_, s)| s.iter()).map(|s| s.value);
        let vmax = values().fold(0.0, f64::max);
        let value_name = super::value_label(d.cosine);
        let x_label = match p.axis {
            CartesianAxis::ThetaO => "θo (°), negative on the light's side".to_string(),
            CartesianAxis::ThetaH => format!("θh (°), θd = {:.1}°, φd = 90°", p.fixed_theta_d_deg),
            CartesianAxis::ThetaD => format!("θd (°), θh = {:.1}°, φd = 90°", p.fixed_theta_h_deg),
        };
        let y_label = if d.log {
            format!("{value_name} (1/sr, log scale)")
        } else {
            format!("{value_name} (1/sr)")
        };
        // Headroom above the largest value for the legend and markers.
        let (bottom, top) = if d.log {
            let r = curves::LogRange::of(values());
            (r.bottom, r.top)
        } else {
            (0.0, vmax.max(1e-6) * 1.3)
        };
        Self {
            curves,
            bottom,
            top,
            x_label,
            y_label,
        }
    }
}

/// The plot as a [`Chart`] (for SVG export).
pub fn chart(scene: &Scene<'_>, dark: bool) -> Chart {
    let data = Data::compute(scene);
    let d = scene.state.display;
    let p = scene.state.plots;
    let theta_i = scene.incident.theta_deg.to_radians();
    let phi_i = scene.incident.phi_deg.to_radians();
    let y_of = |v: f64| if d.log { curves::log_ordinate(v) } else { v };
    let transmits = scene.brdfs.iter().any(|b| b.brdf.transmits());
    let x_range = match p.axis {
        CartesianAxis::ThetaO if transmits => (-180.0, 180.0),
        CartesianAxis::ThetaO => (-90.0, 90.0),
        _ => (0.0, 90.0),
    };
    let y_ticks = if d.log {
        let range = curves::LogRange {
            bottom: data.bottom,
            top: data.top,
        };
        // Every decade up to a dozen, then every few.
        let n = range.decades().count().max(1);
        let every = n.div_ceil(13);
        range
            .decades()
            .filter(|k| k.rem_euclid(every as i32) == 0)
            .map(|k| (f64::from(k), super::decade_label(k)))
            .collect()
    } else {
        chart::labelled(chart::nice_ticks(data.bottom, data.top, 8))
    };
    let mut c = Chart {
        x_label: data.x_label.clone(),
        y_label: data.y_label.clone(),
        x_range,
        y_range: (data.bottom, data.top),
        x_ticks: chart::angle_ticks(x_range.0, x_range.1),
        y_ticks,
        ..Default::default()
    };
    if p.axis == CartesianAxis::ThetaO {
        c.vlines.push(Marker {
            at: slices::incident_signed_angle(theta_i).to_degrees(),
            color: super::light_color(dark),
            dashed: false,
            label: "ωi".into(),
        });
        c.vlines.push(Marker {
            at: theta_i.to_degrees(),
            color: super::mirror_color(dark),
            dashed: true,
            label: "ωr".into(),
        });
        for (b, _) in &data.curves {
            for dl in b.brdf.deltas(scene.wi()) {
                let along = -(dl.direction.x * phi_i.cos() + dl.direction.y * phi_i.sin());
                let a = along.atan2(dl.direction.z).to_degrees();
                c.vlines.push(Marker {
                    at: a,
                    color: b.color(),
                    dashed: true,
                    label: format!("δ {:.3}", bv_core::mean_rgb(dl.weight)),
                });
            }
        }
    }
    let mut order: Vec<&(&super::SceneBrdf, Vec<slices::Sample>)> = data.curves.iter().collect();
    order.sort_by_key(|(b, _)| b.selected);
    for (b, samples) in order {
        c.series.push(Series {
            label: b.label.clone(),
            color: b.color(),
            points: samples
                .iter()
                .map(|s| [s.x.to_degrees(), y_of(s.value)])
                .collect(),
            width: if b.selected { 2.5 } else { 1.8 },
            dash: None,
        });
    }
    c
}
