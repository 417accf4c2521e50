//! The Fresnel view: F against the angle of incidence for the selected BRDF's
//! Fresnel settings, computed with the
//! core's own `bv_core::fresnel` functions.
//!
//! - Dielectric (`fresnel = "dielectric"`, and `glass`): r∥², r⊥² and their
//!   mean F = (r∥² + r⊥²)/2 for light from outside, and F for light from
//!   inside (relative index 1/η, dashed), with Brewster's angle
//!   θB = atan η (where r∥ = 0) and the critical angle θc = asin(1/η) beyond
//!   which light from the denser side is totally reflected.
//! - Conductor: F per linear-RGB channel from the complex index η + ik.
//! - Schlick (`fresnel = "schlick"`, and Disney's specular F0): F per
//!   channel, with the exact dielectric of the same F0 (η = (1 + √F0)/(1 − √F0))
//!   dashed for comparison.
//! - `fresnel = "none"`: F = 1. Models without a Fresnel term say so.
//!
//! Which term a model has is the model's own declaration
//! ([`bv_core::Brdf::fresnel_term`]); this view names no model.

use super::BrdfColor as _;
use super::chart::{self, Chart, Marker, Palette, Series};
use super::{Scene, View};
use crate::session::command::Command;
use bv_core::fresnel::{self, Fresnel};
use bv_core::{Brdf, Rgb};
use eframe::egui::{self, Color32, RichText, Ui};
use egui_plot::{Corner, Legend, Line, LineStyle, Plot, PlotPoints, VLine};

/// Samples over 0..90°.
const SAMPLES: usize = 360;

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

fn grey(v: Rgb) -> bool {
    v.x == v.y && v.y == v.z
}

/// Everything the view draws, as a chart (the GUI plot and the SVG share it).
pub fn chart_of(scene: &Scene<'_>, dark: bool) -> Chart {
    let mut c = Chart {
        x_label: "θ (°), angle of incidence".into(),
        y_label: "F (reflectance)".into(),
        x_range: (0.0, 90.0),
        y_range: (0.0, 1.05),
        x_ticks: chart::angle_ticks(0.0, 90.0),
        y_ticks: chart::labelled(chart::nice_ticks(0.0, 1.0, 8)),
        ..Default::default()
    };
    let Some(b) = scene.primary() else {
        c.note = "no BRDF is shown".into();
        return c;
    };
    let xs: Vec<f64> = (0..=SAMPLES)
        .map(|k| 90.0 * k as f64 / SAMPLES as f64)
        .collect();
    let curve = |f: &dyn Fn(f64) -> f64| -> Vec<[f64; 2]> {
        xs.iter().map(|&x| [x, f(x.to_radians().cos())]).collect()
    };
    let series = |label: String, color: Color32, points, width, dash| Series {
        label,
        color,
        points,
        width,
        dash,
    };
    c.vlines.push(Marker {
        at: scene.incident.theta_deg,
        color: super::light_color(dark),
        dashed: false,
        label: "θi".into(),
    });
    let fres = match fresnel_of(b.brdf.as_ref()) {
        FresnelOf::Absent(msg) => {
            c.note = msg;
            return c;
        }
        FresnelOf::Term(f, desc) => {
            c.note = format!("{}: {desc}", b.label);
            f
        }
    };
    let strong = super::strong_text_color(dark);
    match fres {
        Fresnel::None => {
            c.series.push(series(
                "F = 1 (no Fresnel effect)".into(),
                b.color(),
                curve(&|_| 1.0),
                2.5,
                None,
            ));
        }
        Fresnel::Dielectric { eta } => {
            let e = if grey(eta) {
                eta.x
            } else {
                bv_core::mean_rgb(eta)
            };
            if grey(eta) {
                let par = [176, 122, 211];
                let perp = [118, 183, 178];
                c.series.push(series(
                    "Rp = rp² (p-polarised)".into(),
                    Color32::from_rgb(par[0], par[1], par[2]),
                    curve(&|cos| fresnel::dielectric_polarized(cos, e).0.powi(2)),
                    1.6,
                    None,
                ));
                c.series.push(series(
                    "Rs = rs² (s-polarised)".into(),
                    Color32::from_rgb(perp[0], perp[1], perp[2]),
                    curve(&|cos| fresnel::dielectric_polarized(cos, e).1.powi(2)),
                    1.6,
                    None,
                ));
                c.series.push(series(
                    format!("F = (Rp + Rs)/2, η = {}", fmt_eta(e)),
                    b.color(),
                    curve(&|cos| fresnel::dielectric(cos, e)),
                    2.5,
                    None,
                ));
            } else {
                for (k, (name, rgb)) in CHANNELS.iter().enumerate() {
                    let ek = eta[k];
                    c.series.push(series(
                        format!("F {name}, η = {}", fmt_eta(ek)),
                        Color32::from_rgb(rgb[0], rgb[1], rgb[2]),
                        curve(&|cos| fresnel::dielectric(cos, ek)),
                        2.0,
                        None,
                    ));
                }
            }
            c.series.push(series(
                format!("F from inside (η = {})", fmt_eta(1.0 / e)),
                strong.gamma_multiply(0.7),
                curve(&|cos| fresnel::dielectric(-cos, e)),
                1.6,
                Some(6.0),
            ));
            if (e - 1.0).abs() > 1e-9 {
                let brewster = e.atan().to_degrees();
                c.vlines.push(Marker {
                    at: brewster,
                    color: strong.gamma_multiply(0.8),
                    dashed: true,
                    label: format!("θB = {brewster:.1}°"),
                });
                // The denser side sees total internal reflection beyond θc.
                let sin_c = if e > 1.0 { 1.0 / e } else { e };
                let crit = sin_c.asin().to_degrees();
                c.vlines.push(Marker {
                    at: crit,
                    color: strong.gamma_multiply(0.6),
                    dashed: true,
                    label: format!("θc = {crit:.1}°"),
                });
            }
        }
        Fresnel::Conductor { eta, k } => {
            if grey(eta) && grey(k) {
                c.series.push(series(
                    format!("F, η = {} + {}i", fmt_eta(eta.x), fmt_eta(k.x)),
                    b.color(),
                    curve(&|cos| fresnel::conductor(cos, eta.x, k.x)),
                    2.5,
                    None,
                ));
            } else {
                for (ch, (name, rgb)) in CHANNELS.iter().enumerate() {
                    let (e, kk) = (eta[ch], k[ch]);
                    c.series.push(series(
                        format!("F {name}, η = {} + {}i", fmt_eta(e), fmt_eta(kk)),
                        Color32::from_rgb(rgb[0], rgb[1], rgb[2]),
                        curve(&|cos| fresnel::conductor(cos, e, kk)),
                        2.0,
                        None,
                    ));
                }
            }
        }
        Fresnel::Schlick { f0 } => {
            if grey(f0) {
                c.series.push(series(
                    format!("Schlick, F0 = {:.3}", f0.x),
                    b.color(),
                    curve(&|cos| fresnel::schlick(f0.x, cos)),
                    2.5,
                    None,
                ));
            } else {
                for (ch, (name, rgb)) in CHANNELS.iter().enumerate() {
                    let f = f0[ch];
                    c.series.push(series(
                        format!("Schlick {name}, F0 = {f:.3}"),
                        Color32::from_rgb(rgb[0], rgb[1], rgb[2]),
                        curve(&|cos| fresnel::schlick(f, cos)),
                        2.0,
                        None,
                    ));
                }
            }
            let m = bv_core::mean_rgb(f0);
            if m < 1.0 {
                let e = fresnel::eta_from_f0(m);
                c.series.push(series(
                    format!("exact dielectric, η = {}", fmt_eta(e)),
                    strong.gamma_multiply(0.7),
                    curve(&|cos| fresnel::dielectric(cos, e)),
                    1.6,
                    Some(6.0),
                ));
            }
        }
    }
    c
}

fn fmt_eta(x: f64) -> String {
    super::curves::fmt_tick(super::curves::round_significant(x, 4))
}

/// The Fresnel view.
#[derive(Default)]
pub struct FresnelView {
    /// The chart of the last frame (for tests).
    pub last: Option<Chart>,
}

impl View for FresnelView {
    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, _out: &mut Vec<Command>) {
        let dark = ui.visuals().dark_mode;
        let c = chart_of(scene, dark);
        if !c.note.is_empty() {
            ui.label(RichText::new(&c.note).weak());
        }
        let size = ui.available_size();
        let plot = Plot::new(super::view_id("fresnel"))
            .width(size.x.max(50.0))
            .height(size.y.max(50.0))
            .legend(Legend::default().position(Corner::LeftTop))
            .x_axis_label(c.x_label.clone())
            .y_axis_label(c.y_label.clone())
            .y_axis_min_width(36.0)
            .include_x(0.0)
            .include_x(90.0)
            .include_y(0.0)
            .include_y(1.05)
            .allow_scroll(false)
            .x_grid_spacer(egui_plot::uniform_grid_spacer(|_| [5.0, 15.0, 45.0]));
        plot.show(ui, |pui| {
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
        });
        self.last = Some(c);
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn svg(&mut self, scene: &Scene<'_>, size: [f32; 2], dark: bool) -> Option<String> {
        Some(chart_of(scene, dark).to_svg(size, Palette::new(dark, scene.transparent)))
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
