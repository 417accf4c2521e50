//! The Snell view: a cut through a flat interface in the plane of incidence,
//! for the lecture's "Snell's law", "Optical manhole" and "Fresnel
//! reflection" slides. The incident, reflected and refracted rays are drawn
//! with widths proportional to their share of the flux (1, R, T), with θi,
//! θt, R (Rs, Rp), T and the radiance scaling `(ηt/ηi)²` written beside
//! them; Brewster's angle is marked; for light from the denser side the
//! incidence angles beyond the critical angle are shaded as the range of
//! total internal reflection, and the cone inside it is named Snell's window.
//!
//! The outer medium (index 1) is always drawn above, the medium of index η
//! below; light comes from either side (a toolbar toggle). η is the selected
//! BRDF's when its Fresnel term is a dielectric
//! ([`bv_core::Brdf::fresnel_term`]), else the view's own slider (kept in the
//! view, not saved). θi is the scene's light and can be dragged in the view.
//! Every number is `bv_core::optics`'s; the figure is a list of primitives
//! ([`SnellFigure`]) that egui and the SVG export draw alike.

use super::svg::{Anchor, Baseline, Svg};
use super::{Scene, View};
use crate::session::command::Command;
use crate::session::state::{Incident, PlotSettings, SnellSettings};
use bv_core::fresnel::Fresnel;
use bv_core::optics::{self, SnellDiagram};
use eframe::egui::{self, Align2, Color32, Pos2, RichText, Sense, Stroke, Ui, Vec2};
use glam::DVec2;

/// The water of the "optical manhole" slide.
pub const WATER: f64 = 4.0 / 3.0;

/// One drawing primitive in diagram units (the hit point at the origin, the
/// interface on the x axis, +y up, rays of length 1).
#[derive(Debug, Clone, PartialEq)]
pub enum Prim {
    /// A filled polygon.
    Fill {
        /// Corners.
        points: Vec<DVec2>,
        /// Fill colour.
        color: Color32,
    },
    /// A polyline.
    Line {
        /// Points.
        points: Vec<DVec2>,
        /// Colour.
        color: Color32,
        /// Width in points.
        width: f32,
        /// Dash length, if dashed.
        dash: Option<f32>,
    },
    /// A label.
    Text {
        /// Anchor point.
        at: DVec2,
        /// The text.
        text: String,
        /// Colour.
        color: Color32,
        /// Font size in points.
        size: f32,
        /// Which corner of the text sits at `at`.
        align: Align2,
        /// Lines (of its own height) it is moved down from `at`: stacks of
        /// text keep their spacing at every figure size.
        line: f32,
        /// Secondary text, left out where the figure is too small to read it.
        detail: bool,
    },
}

/// Where η comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum EtaSource {
    /// The selected BRDF's dielectric Fresnel term (its label).
    Brdf(String),
    /// The view's own slider.
    Own,
}

/// The interface the view draws.
#[derive(Debug, Clone, PartialEq)]
pub struct Interface {
    /// Index of the medium below (the one above is 1).
    pub eta: f64,
    /// Whether the light comes from below (from inside the medium η).
    pub from_below: bool,
    /// Where η comes from.
    pub source: EtaSource,
}

impl Interface {
    /// `(ηi, ηt)`: the index the light comes from and the one it enters.
    pub fn indices(&self) -> (f64, f64) {
        if self.from_below {
            (self.eta, 1.0)
        } else {
            (1.0, self.eta)
        }
    }
}

/// The index of a dielectric Fresnel term: its η, or the mean of the
/// channels' when they differ; `None` for other terms and non-physical η.
pub fn dielectric_eta(f: &Fresnel) -> Option<f64> {
    match f {
        Fresnel::Dielectric { eta } => {
            let e = bv_core::mean_rgb(*eta);
            (e.is_finite() && e > 0.0).then_some(e)
        }
        _ => None,
    }
}

/// The incidence angle (degrees, within the light's slider range) of a
/// pointer at `v` (diagram units, +y up, relative to the hit point) when the
/// light comes from above (`from_below = false`) or below: the angle between
/// the normal on the light's side and the pointer. A pointer on the far side
/// of the interface gives the largest angle.
pub fn theta_of_pointer(v: DVec2, from_below: bool) -> Option<f64> {
    let y = if from_below { -v.y } else { v.y };
    if !(v.x.is_finite() && y.is_finite()) || (v.x == 0.0 && y == 0.0) {
        return None;
    }
    let t = v.x.abs().atan2(y).to_degrees();
    Some(t.clamp(0.0, Incident::MAX_ABOVE_DEG))
}

/// The scene light's angle from the normal on its own side (radians): the
/// diagram draws the light on the side its toggle chooses, so a light below
/// the surface (θi > 90°, issue 33) is read as `180° − θi` from the downward
/// normal.
fn side_angle(theta_deg: f64) -> f64 {
    let t = if theta_deg > 90.0 {
        180.0 - theta_deg
    } else {
        theta_deg
    };
    t.to_radians()
}

/// Colours of the figure.
struct Colors {
    text: Color32,
    weak: Color32,
    light: Color32,
    refl: Color32,
    refr: Color32,
    lower: Color32,
    tir: Color32,
    window: Color32,
}

impl Colors {
    fn new(dark: bool) -> Self {
        let text = super::strong_text_color(dark);
        Self {
            text,
            weak: text.gamma_multiply(0.65),
            light: super::light_color(dark),
            refl: if dark {
                Color32::from_rgb(240, 130, 90)
            } else {
                Color32::from_rgb(200, 70, 30)
            },
            refr: if dark {
                Color32::from_rgb(110, 190, 255)
            } else {
                Color32::from_rgb(20, 100, 200)
            },
            lower: Color32::from_rgba_unmultiplied(70, 140, 220, if dark { 45 } else { 40 }),
            tir: Color32::from_rgba_unmultiplied(220, 60, 60, if dark { 70 } else { 55 }),
            window: Color32::from_rgba_unmultiplied(255, 220, 90, if dark { 45 } else { 60 }),
        }
    }
}

/// The figure: its primitives and the numbers they show.
#[derive(Debug, Clone)]
pub struct SnellFigure {
    /// What is drawn, in order.
    pub prims: Vec<Prim>,
    /// The optics of the interface.
    pub diagram: SnellDiagram,
    /// The interface.
    pub interface: Interface,
}

impl SnellFigure {
    /// Every label of the figure (for tests and readers).
    pub fn texts(&self) -> Vec<&str> {
        self.prims
            .iter()
            .filter_map(|p| match p {
                Prim::Text { text, .. } => Some(text.as_str()),
                _ => None,
            })
            .collect()
    }
}

/// Points of an arc of radius `r` about the origin between polar angles `a0`
/// and `a1` measured from +y towards +x (diagram orientation `s` = +1 above,
/// −1 below).
fn arc(r: f64, a0: f64, a1: f64, s: f64) -> Vec<DVec2> {
    let n = 24;
    (0..=n)
        .map(|k| {
            let a = a0 + (a1 - a0) * k as f64 / n as f64;
            DVec2::new(r * a.sin(), s * r * a.cos())
        })
        .collect()
}

/// A ray from `a` to `b` with an arrowhead at `0.7` of a unit from the hit
/// point (clear of the angle labels), pointing to `b`.
fn ray(out: &mut Vec<Prim>, a: DVec2, b: DVec2, color: Color32, width: f32) {
    out.push(Prim::Line {
        points: vec![a, b],
        color,
        width,
        dash: None,
    });
    let d = (b - a).normalize_or_zero();
    let n = DVec2::new(-d.y, d.x);
    // One end is the hit point (the origin): put the tip 0.7 from it.
    let tip = if a.length_squared() < b.length_squared() {
        d * 0.7
    } else {
        a.normalize_or_zero() * 0.7 + d * 0.06
    };
    let size = 0.035 + 0.004 * f64::from(width);
    out.push(Prim::Fill {
        points: vec![
            tip + d * size,
            tip - d * size + n * size * 0.8,
            tip - d * size - n * size * 0.8,
        ],
        color,
    });
}

fn fmt_eta(x: f64) -> String {
    super::curves::fmt_tick(super::curves::round_significant(x, 4))
}

/// Where the label of an angle `a` from the upward normal goes, on the side
/// `side` (−1 left, +1 right): inside a wide wedge, centred between the ray
/// and the normal at the height of the bisector 0.45 out, else beside the
/// ray's end of the arc. A label is about 0.55 units wide at full size, so a
/// wedge below 55° has no room for it inside: centred on the bisector there
/// (as before), the ray ran through the label's first letters.
fn angle_label_place(a: f64, side: f64) -> (DVec2, Align2) {
    if a > 55f64.to_radians() {
        let y = 0.45 * (0.5 * a).cos();
        (
            DVec2::new(side * 0.5 * y * a.tan().min(4.0), y),
            Align2::CENTER_CENTER,
        )
    } else {
        let align = if side < 0.0 {
            Align2::RIGHT_CENTER
        } else {
            Align2::LEFT_CENTER
        };
        (
            DVec2::new(side * (0.3 * a.sin() + 0.1), 0.3 * a.cos()),
            align,
        )
    }
}

/// A label at `at` (line 0, not a detail).
fn label(at: DVec2, text: String, color: Color32, size: f32, align: Align2) -> Prim {
    Prim::Text {
        at,
        text,
        color,
        size,
        align,
        line: 0.0,
        detail: false,
    }
}

/// Diagram extent drawn (x half-width, y half-height).
const EXTENT: [f64; 2] = [2.0, 1.15];

/// The figure for incidence `theta_i` (radians) at `interface`; `None` for an
/// index the optics refuse (non-positive, not finite).
pub fn snell_figure(theta_i: f64, interface: &Interface, dark: bool) -> Option<SnellFigure> {
    let (eta_i, eta_t) = interface.indices();
    let d = optics::snell_diagram(theta_i, eta_i, eta_t).ok()?;
    let c = Colors::new(dark);
    // s flips the diagram's y so that the medium η is always drawn below; it
    // is also the side the light comes from (+1 above, −1 below).
    let s = if interface.from_below { -1.0 } else { 1.0 };
    let flip = |v: DVec2| DVec2::new(v.x, s * v.y);
    // Anchors of text that sits on the light's side (`near`) or across the
    // interface (`far`), vertically.
    let near = |top: Align2, bottom: Align2| if s > 0.0 { top } else { bottom };
    let mut p = Vec::new();
    let ([x0, y0], [x1, y1]) = ([-EXTENT[0], -EXTENT[1]], EXTENT);
    // The medium η, tinted, and the interface, out to the edges of any
    // figure (the painter clips them).
    let far = 50.0;
    p.push(Prim::Fill {
        points: vec![
            DVec2::new(-far, 0.0),
            DVec2::new(far, 0.0),
            DVec2::new(far, -far),
            DVec2::new(-far, -far),
        ],
        color: c.lower,
    });
    // Total internal reflection: the incidence angles beyond θc, shaded on
    // the light's side (both halves: the light may come from either).
    if let Some((lo, hi)) = d.tir_range {
        for side in [-1.0, 1.0] {
            let mut pts = vec![DVec2::ZERO];
            pts.extend(
                arc(1.08, lo, hi, s)
                    .into_iter()
                    .map(|v| DVec2::new(side * v.x, v.y)),
            );
            p.push(Prim::Fill {
                points: pts,
                color: c.tir,
            });
        }
        let mid = 0.5 * (lo + hi);
        let at = DVec2::new(-1.1 * mid.sin(), s * 1.1 * mid.cos());
        let align = near(Align2::RIGHT_BOTTOM, Align2::RIGHT_TOP);
        // Two lines, the first nearer the interface's far side.
        let (first, second) = if s > 0.0 { (-1.0, 0.0) } else { (0.0, 1.0) };
        for (line, text) in [
            (first, "total internal reflection".to_string()),
            (second, format!("θi > θc = {:.1}°", lo.to_degrees())),
        ] {
            p.push(Prim::Text {
                at,
                text,
                color: c.text,
                size: 12.0,
                align,
                line,
                detail: false,
            });
        }
        // Snell's window: everything from the other side arrives within θc.
        let mut cone = vec![DVec2::ZERO];
        cone.extend(arc(0.75, -lo, lo, s));
        p.push(Prim::Fill {
            points: cone,
            color: c.window,
        });
        // The label below the rays' ends (radius 1) and Brewster's mark,
        // not across them.
        p.push(label(
            DVec2::new(0.0, s * 1.04),
            format!(
                "Snell's window 2 × {:.1}° = {:.1}°",
                lo.to_degrees(),
                2.0 * lo.to_degrees()
            ),
            c.weak,
            11.0,
            near(Align2::CENTER_BOTTOM, Align2::CENTER_TOP),
        ));
    }
    p.push(Prim::Line {
        points: vec![DVec2::new(-far, 0.0), DVec2::new(far, 0.0)],
        color: c.text,
        width: 1.5,
        dash: None,
    });
    // The normal; on the light's side it stops short of Snell's window's
    // label when there is one.
    let (n_lo, n_hi) = match (d.tir_range.is_some(), s > 0.0) {
        (true, true) => (y0, 1.02),
        (true, false) => (-1.02, y1),
        (false, _) => (y0, y1),
    };
    p.push(Prim::Line {
        points: vec![DVec2::new(0.0, n_lo), DVec2::new(0.0, n_hi)],
        color: c.weak,
        width: 1.0,
        dash: Some(5.0),
    });
    // Brewster's angle on the light's side.
    let b = d.brewster;
    let bdir = flip(DVec2::new(-b.sin(), b.cos()));
    p.push(Prim::Line {
        points: vec![DVec2::ZERO, bdir * 1.02],
        color: c.weak,
        width: 1.0,
        dash: Some(3.0),
    });
    p.push(label(
        bdir * 1.04,
        format!("θB = {:.1}°", b.to_degrees()),
        c.weak,
        11.0,
        near(Align2::RIGHT_BOTTOM, Align2::RIGHT_TOP),
    ));
    // Media names.
    p.push(label(
        DVec2::new(x1 - 0.03, 0.03),
        "n = 1".into(),
        c.weak,
        12.0,
        Align2::RIGHT_BOTTOM,
    ));
    p.push(label(
        DVec2::new(x1 - 0.03, -0.03),
        format!("η = {}", fmt_eta(interface.eta)),
        c.weak,
        12.0,
        Align2::RIGHT_TOP,
    ));
    // Rays: widths in proportion to their flux (the incident one is 1).
    let w0 = 7.0f32;
    let w = d.weights;
    let min_w = 0.6f32;
    ray(&mut p, flip(d.incident), DVec2::ZERO, c.light, w0);
    ray(
        &mut p,
        DVec2::ZERO,
        flip(d.reflected),
        c.refl,
        (w0 * w.r as f32).max(min_w),
    );
    // θi on its arc's bisector, R at the reflected ray's end.
    let ti = d.theta_i;
    p.push(Prim::Line {
        points: arc(0.3, -ti, 0.0, s),
        color: c.light,
        width: 1.2,
        dash: None,
    });
    // Angle labels: inside a wide wedge on its bisector, else just outside
    // it, where the arc meets the ray.
    let (at, align) = angle_label_place(ti, -1.0);
    p.push(label(
        flip(at),
        format!("θi = {:.1}°", ti.to_degrees()),
        c.light,
        13.0,
        align,
    ));
    p.push(label(
        flip(d.reflected * 1.03),
        format!("R = {:.3}", w.r),
        c.refl,
        13.0,
        near(Align2::LEFT_BOTTOM, Align2::LEFT_TOP),
    ));
    let scale = optics::radiance_scale(eta_i, eta_t);
    let mut details = vec![
        format!(
            "light from {}",
            if interface.from_below {
                "below"
            } else {
                "above"
            }
        ),
        format!(
            "ηi = {}, ηt = {} ({})",
            fmt_eta(eta_i),
            fmt_eta(eta_t),
            match &interface.source {
                EtaSource::Brdf(label) => label.as_str(),
                EtaSource::Own => "this view's η",
            }
        ),
        format!("radiance scale (ηt/ηi)² = {scale:.3}"),
        optics::critical_angle(eta_i, eta_t).map_or_else(
            || "no critical angle".to_string(),
            |c| format!("critical angle θc = {:.1}°", c.to_degrees()),
        ),
        format!("R = {:.3}: Rs {:.3}, Rp {:.3}", w.r, w.rs, w.rp),
    ];
    match (d.refracted, d.theta_t) {
        (Some(t), Some(tt)) => {
            ray(
                &mut p,
                DVec2::ZERO,
                flip(t),
                c.refr,
                (w0 * w.t as f32).max(min_w),
            );
            p.push(Prim::Line {
                points: arc(0.3, std::f64::consts::PI - tt, std::f64::consts::PI, s),
                color: c.refr,
                width: 1.2,
                dash: None,
            });
            let (at, align) = angle_label_place(tt, 1.0);
            p.push(label(
                flip(DVec2::new(at.x, -at.y)),
                format!("θt = {:.1}°", tt.to_degrees()),
                c.refr,
                13.0,
                align,
            ));
            p.push(label(
                flip(t * 1.03),
                format!("T = {:.3}", w.t),
                c.refr,
                13.0,
                near(Align2::LEFT_TOP, Align2::LEFT_BOTTOM),
            ));
            details.push(format!(
                "T = {:.3}; radiance × T (ηt/ηi)² = {:.3}",
                w.t, d.refracted_radiance
            ));
        }
        _ => {
            p.push(label(
                flip(DVec2::new(0.08, -0.4)),
                "no refracted ray: R = 1".into(),
                c.refr,
                13.0,
                near(Align2::LEFT_TOP, Align2::LEFT_BOTTOM),
            ));
            details.push("T = 0: totally reflected".into());
        }
    }
    // The interface's numbers in the corner on the light's side, left (the
    // incident ray never reaches x < −1).
    let n = details.len();
    for (k, text) in details.into_iter().enumerate() {
        let (at, align, line) = if s > 0.0 {
            (DVec2::new(x0 + 0.03, y1 - 0.02), Align2::LEFT_TOP, k as f32)
        } else {
            (
                DVec2::new(x0 + 0.03, y0 + 0.02),
                Align2::LEFT_BOTTOM,
                k as f32 - (n - 1) as f32,
            )
        };
        p.push(Prim::Text {
            at,
            text,
            color: c.text,
            size: 12.0,
            align,
            line,
            detail: true,
        });
    }
    Some(SnellFigure {
        prims: p,
        diagram: d,
        interface: interface.clone(),
    })
}

/// The map from diagram units to a rectangle of points: centre, points per
/// unit, the text's scale and whether details are legible.
fn fit(rect: egui::Rect) -> (Pos2, f32, f32, bool) {
    let s = (rect.width() / (2.0 * EXTENT[0] as f32)).min(rect.height() / (2.0 * EXTENT[1] as f32));
    let s = s.max(1e-3);
    // Text grows with the figure up to a point (a 1600-pixel figure at 2×
    // reads like the 800-point view), and shrinks with it in thumbnails.
    let text_scale = (s / 200.0).clamp(0.3, 1.2);
    (rect.center(), s, text_scale, s >= 110.0)
}

fn to_screen(v: DVec2, centre: Pos2, s: f32) -> Pos2 {
    Pos2::new(centre.x + v.x as f32 * s, centre.y - v.y as f32 * s)
}

/// The figure's details (the interface's numbers) as a column of text in
/// `rect`, at their own size: presenting, the diagram is too short for
/// them at a legible size (they covered the rays and each other).
fn paint_details(painter: &egui::Painter, rect: egui::Rect, fig: &SnellFigure) {
    let mut y = rect.top();
    for prim in &fig.prims {
        if let Prim::Text {
            text,
            color,
            size,
            detail: true,
            ..
        } = prim
        {
            let galley = painter.layout(
                text.clone(),
                egui::FontId::proportional(*size),
                *color,
                rect.width().max(1.0),
            );
            let h = galley.size().y;
            painter.galley(Pos2::new(rect.left(), y), galley, *color);
            y += h + 2.0;
        }
    }
}

/// `fig` with its translucent labels (the weak ones) in `strong`: opaque
/// text for a projector.
fn presented(mut fig: SnellFigure, strong: Color32) -> SnellFigure {
    for p in &mut fig.prims {
        if let Prim::Text { color, .. } = p
            && color.a() < 255
        {
            *color = strong;
        }
    }
    fig
}

/// Paints the figure into `rect`, its text scaled by at least `min_text`;
/// without its details (the interface's numbers) when `details_apart`
/// (drawn beside it by [`paint_details`]).
fn paint(
    painter: &egui::Painter,
    rect: egui::Rect,
    fig: &SnellFigure,
    min_text: f32,
    details_apart: bool,
) {
    let (centre, s, text_scale, details) = fit(rect);
    let text_scale = text_scale.max(min_text);
    let details = details && !details_apart;
    for prim in &fig.prims {
        match prim {
            Prim::Fill { points, color } => {
                let pts: Vec<Pos2> = points.iter().map(|v| to_screen(*v, centre, s)).collect();
                painter.add(egui::Shape::convex_polygon(pts, *color, Stroke::NONE));
            }
            Prim::Line {
                points,
                color,
                width,
                dash,
            } => {
                let pts: Vec<Pos2> = points.iter().map(|v| to_screen(*v, centre, s)).collect();
                let stroke = Stroke::new(*width * text_scale.max(0.8), *color);
                match dash {
                    Some(d) => {
                        painter.extend(egui::Shape::dashed_line(&pts, stroke, *d, *d * 0.8));
                    }
                    None => {
                        painter.add(egui::Shape::line(pts, stroke));
                    }
                }
            }
            Prim::Text {
                at,
                text,
                color,
                size,
                align,
                line,
                detail,
            } => {
                if *detail && !details {
                    continue;
                }
                let dy = line * size * text_scale * 1.3;
                painter.text(
                    to_screen(*at, centre, s) + Vec2::new(0.0, dy),
                    *align,
                    text,
                    egui::FontId::proportional(*size * text_scale),
                    *color,
                );
            }
        }
    }
}

/// The figure as SVG.
fn to_svg(fig: &SnellFigure, size: [f32; 2], background: Option<Color32>) -> String {
    let [w, h] = [size[0].max(120.0), size[1].max(90.0)];
    let mut svg = Svg::new(w, h);
    svg.comment("Snell's law at a flat interface");
    if let Some(bg) = background {
        svg.rect([0.0, 0.0], [w, h], Some(bg), None);
    }
    let rect = egui::Rect::from_min_size(Pos2::ZERO, Vec2::new(w, h));
    let (centre, s, text_scale, details) = fit(rect);
    let pt = |v: &DVec2| {
        let p = to_screen(*v, centre, s);
        [p.x, p.y]
    };
    for prim in &fig.prims {
        match prim {
            Prim::Fill { points, color } => {
                let pts: Vec<[f32; 2]> = points.iter().map(pt).collect();
                svg.polygon(&pts, *color);
            }
            Prim::Line {
                points,
                color,
                width,
                dash,
            } => {
                let pts: Vec<[f32; 2]> = points.iter().map(pt).collect();
                svg.polyline(&pts, *color, *width * text_scale.max(0.8), *dash);
            }
            Prim::Text {
                at,
                text,
                color,
                size,
                align,
                line,
                detail,
            } => {
                if *detail && !details {
                    continue;
                }
                let [x, y] = pt(at);
                let at = [x, y + line * size * text_scale * 1.3];
                let anchor = match align.x() {
                    egui::Align::Min => Anchor::Start,
                    egui::Align::Center => Anchor::Middle,
                    egui::Align::Max => Anchor::End,
                };
                let baseline = match align.y() {
                    egui::Align::Min => Baseline::Top,
                    egui::Align::Center => Baseline::Middle,
                    egui::Align::Max => Baseline::Bottom,
                };
                svg.text(at, text, *size * text_scale, *color, anchor, baseline, None);
            }
        }
    }
    svg.finish()
}

/// The Snell view (its settings are the scene's `plots.snell`).
#[derive(Default)]
pub struct SnellView {
    /// The figure of the last frame (for tests).
    pub last: Option<SnellFigure>,
    /// Where it was drawn, and the hit point's position and points per
    /// diagram unit there (for tests that drag the light).
    pub last_rect: Option<(egui::Rect, Pos2, f32)>,
}

impl SnellView {
    /// The interface for `scene`: the selected BRDF's dielectric η unless the
    /// view's own is asked for.
    pub fn interface(&self, scene: &Scene<'_>) -> Interface {
        let own = scene.state.plots.snell;
        let brdf = scene.primary().and_then(|b| {
            let f = b.brdf.fresnel_term()?;
            Some((b.label.clone(), dielectric_eta(&f.fresnel)?))
        });
        match brdf {
            Some((label, eta)) if !own.use_own => Interface {
                eta,
                from_below: own.from_below,
                source: EtaSource::Brdf(label),
            },
            _ => Interface {
                eta: own.eta,
                from_below: own.from_below,
                source: EtaSource::Own,
            },
        }
    }

    /// The lecture's "optical manhole": water (n = 4/3) seen from below.
    pub fn optical_manhole() -> SnellSettings {
        SnellSettings {
            eta: WATER,
            use_own: true,
            from_below: true,
        }
    }
}

impl View for SnellView {
    fn toolbar(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        let before = scene.state.plots.snell;
        let mut own = before;
        if super::toolbar_toggle(
            ui,
            own.from_below,
            "light from below",
            "Light arrives from inside the medium η (the dense side for η > 1)",
        ) {
            own.from_below = !own.from_below;
        }
        let has_dielectric = scene
            .primary()
            .and_then(|b| b.brdf.fresnel_term())
            .is_some_and(|f| dielectric_eta(&f.fresnel).is_some());
        if has_dielectric
            && super::toolbar_toggle(
                ui,
                !own.use_own,
                "η of BRDF",
                "Use the selected BRDF's dielectric index (off: the slider's)",
            )
        {
            own.use_own = !own.use_own;
        }
        if !has_dielectric || own.use_own {
            let (lo, hi) = SnellSettings::ETA_RANGE;
            ui.add(
                // No max_decimals: it would round the preset's 4/3 to 1.333.
                egui::Slider::new(&mut own.eta, lo..=hi).text("η"),
            );
        }
        if ui
            .button("optical manhole")
            .on_hover_text("Water, n = 4/3, light from below: Snell's window of 2 × 48.6°")
            .clicked()
        {
            own = Self::optical_manhole();
        }
        if own != before {
            out.push(Command::SetPlots(PlotSettings {
                snell: own,
                ..scene.state.plots
            }));
        }
    }

    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        let dark = ui.visuals().dark_mode;
        let interface = self.interface(scene);
        let Some(fig) = snell_figure(side_angle(scene.incident.theta_deg), &interface, dark) else {
            ui.label(
                RichText::new(format!("η = {} is not a refractive index", interface.eta)).weak(),
            );
            self.last = None;
            return;
        };
        let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 0.0, super::figure_fill(ui, scene));
        // Presenting, the annotations keep their full size (11–12 points,
        // 30 pixels at 1080p, where the figure's fit had shrunk them to
        // 14 pixels) and are drawn opaque: a translucent grey over the
        // tinted media fell short of AA contrast.
        let fig = if scene.presenting {
            presented(fig, super::strong_text_color(dark))
        } else {
            fig
        };
        let rect = if scene.presenting {
            // The diagram as large as the height allows, its numbers in the
            // column to its right; a little of the width left over goes to
            // its left, where its full-size labels reach past its edge.
            let s = rect.height() / (2.0 * EXTENT[1] as f32);
            let w = (2.0 * EXTENT[0] as f32 * s).min(0.66 * rect.width());
            let left = rect.left() + ((rect.width() - w) / 5.0).clamp(0.0, 60.0);
            let diagram = egui::Rect::from_x_y_ranges(left..=left + w, rect.y_range());
            let column = rect
                .with_min_x(diagram.right() + 12.0)
                .shrink2(Vec2::new(0.0, 12.0));
            paint(&painter, diagram, &fig, 1.0, true);
            // The column is a panel of its own: the interface line and the
            // medium's tint, which run to the view's edge, stop at it
            // rather than strike through its text.
            painter.rect_filled(
                column.expand2(Vec2::new(6.0, 12.0)),
                0.0,
                super::figure_fill(ui, scene),
            );
            paint_details(&painter, column, &fig);
            diagram
        } else {
            paint(&painter, rect, &fig, 0.0, false);
            rect
        };
        let (centre, scale, _, _) = fit(rect);
        self.last_rect = Some((rect, centre, scale));
        if !scene.figure {
            let response = response.on_hover_text("Drag to move the light");
            if (response.dragged() || response.clicked())
                && let Some(pos) = response.interact_pointer_pos()
            {
                let (centre, s, _, _) = fit(rect);
                let v = DVec2::new(
                    f64::from((pos.x - centre.x) / s),
                    f64::from((centre.y - pos.y) / s),
                );
                if let Some(t) = theta_of_pointer(v, interface.from_below) {
                    out.push(Command::SetIncident(Incident {
                        theta_deg: t,
                        phi_deg: scene.incident.phi_deg,
                    }));
                }
            }
        }
        self.last = Some(fig);
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn shows_light_below(&self) -> bool {
        true
    }

    fn svg(&mut self, scene: &Scene<'_>, size: [f32; 2], dark: bool) -> Option<String> {
        let interface = self.interface(scene);
        let fig = snell_figure(side_angle(scene.incident.theta_deg), &interface, dark)?;
        let bg = super::chart::Palette::new(dark, scene.transparent).background;
        Some(to_svg(&fig, size, bg))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn own(eta: f64, from_below: bool) -> Interface {
        Interface {
            eta,
            from_below,
            source: EtaSource::Own,
        }
    }

    #[test]
    fn pointer_angles() {
        // Up and to the left at 45° from the normal, light from above.
        let t = theta_of_pointer(DVec2::new(-1.0, 1.0), false).unwrap();
        assert!((t - 45.0).abs() < 1e-12);
        // Either side of the normal means the same incidence angle.
        assert!((theta_of_pointer(DVec2::new(1.0, 1.0), false).unwrap() - 45.0).abs() < 1e-12);
        // 30° from the downward normal with light from below.
        let v = DVec2::new(-(30f64.to_radians().sin()), -(30f64.to_radians().cos()));
        assert!((theta_of_pointer(v, true).unwrap() - 30.0).abs() < 1e-12);
        // The far side clamps to the slider's largest angle.
        assert_eq!(
            theta_of_pointer(DVec2::new(0.1, -1.0), false),
            Some(Incident::MAX_ABOVE_DEG)
        );
        assert_eq!(theta_of_pointer(DVec2::ZERO, false), None);
    }

    #[test]
    fn dielectric_index_of_a_term() {
        use bv_core::Rgb;
        assert_eq!(
            dielectric_eta(&Fresnel::Dielectric {
                eta: Rgb::splat(1.5)
            }),
            Some(1.5)
        );
        let e = dielectric_eta(&Fresnel::Dielectric {
            eta: Rgb::new(1.4, 1.5, 1.6),
        })
        .unwrap();
        assert!((e - 1.5).abs() < 1e-15);
        assert_eq!(
            dielectric_eta(&Fresnel::Schlick {
                f0: Rgb::splat(0.04)
            }),
            None
        );
        assert_eq!(dielectric_eta(&Fresnel::None), None);
    }

    #[test]
    fn tir_is_named_only_from_the_dense_side_past_the_critical_angle() {
        let has = |f: &SnellFigure, s: &str| f.texts().iter().any(|t| t.contains(s));
        // Water from below at 60° (> 48.6°): no refracted ray, the range and
        // the window are named.
        let f = snell_figure(60f64.to_radians(), &own(WATER, true), true).unwrap();
        assert!(f.diagram.tir);
        assert!(has(&f, "total internal reflection"));
        assert!(has(&f, "θi > θc = 48.6°"));
        assert!(has(&f, "Snell's window 2 × 48.6° = 97.2°"));
        assert!(has(&f, "no refracted ray"));
        assert!(has(&f, "R = 1.000"));
        assert!(has(&f, "T = 0: totally reflected"));
        // From below but inside the window: a refracted ray, θt by Snell.
        let f = snell_figure(30f64.to_radians(), &own(WATER, true), true).unwrap();
        let tt = (WATER * 0.5f64).asin().to_degrees();
        assert!(has(&f, &format!("θt = {tt:.1}°")), "{:?}", f.texts());
        assert!(!has(&f, "no refracted ray"));
        // From above there is no critical angle and no TIR range.
        let f = snell_figure(60f64.to_radians(), &own(1.5, false), false).unwrap();
        assert!(!has(&f, "total internal reflection"));
        assert!(has(&f, "θB = 56.3°"));
        // Radiance into glass: (1.5/1)² = 2.25.
        assert!(has(&f, "(ηt/ηi)² = 2.250"));
        assert!(snell_figure(0.3, &own(-1.0, false), true).is_none());
    }

    #[test]
    fn the_manhole_preset_is_water_from_below() {
        let v = SnellView::optical_manhole();
        assert_eq!((v.eta, v.use_own, v.from_below), (WATER, true, true));
    }

    #[test]
    fn svg_carries_the_labels() {
        let f = snell_figure(0.5, &own(1.5, false), false).unwrap();
        let s = to_svg(&f, [800.0, 600.0], Some(Color32::WHITE));
        assert!(s.contains("θi = 28.6°"), "{s}");
        assert!(s.contains("<polyline") && s.contains("<polygon"));
    }
}
