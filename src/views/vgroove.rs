//! The microfacet term view's *v-groove* strip: Torrance & Sparrow's
//! grooves in the plane of incidence at three outgoing directions (the
//! mirror direction, the normal, back towards the light), each with the part
//! of the facet the light reaches, the part the viewer sees, a few rays and
//! the limiting ray past the partner facet's rim (LECTURE.md N9; the
//! sections are `bv_core::microfacet::v_groove_section`).
//!
//! One drawing serves the window and the SVG figure: the panels are painted
//! on a [`GrooveCanvas`], implemented by the egui painter
//! ([`PainterCanvas`]) and by [`Svg`].

use super::Scene;
use super::svg::{Anchor, Baseline, Svg};
use crate::derive::slices;
use bv_core::microfacet::{VGrooveSection, v_groove_section};
use eframe::egui::{self, Align, Align2, Color32, Pos2, Rect, Vec2};

/// One panel of the v-groove strip: the outgoing direction's signed θo
/// (the charts' convention: + on the mirror side), its name, and the
/// section there.
#[derive(Debug, Clone, PartialEq)]
pub struct VGroovePanel {
    /// The light's θi, degrees.
    pub theta_i_deg: f64,
    /// Signed θo, degrees.
    pub theta_o_deg: f64,
    /// "ωr", "n" or "towards the light".
    pub name: &'static str,
    /// The grooves, or `None` where there is none (light at the horizon).
    pub section: Option<VGrooveSection>,
}

/// The strip's panels for the scene's light: θo = +θi (the mirror
/// direction), 0 and −θi (back towards the light); one panel at normal
/// incidence.
pub fn vgroove_sections(scene: &Scene<'_>) -> Vec<VGroovePanel> {
    let theta_i = scene.incident.theta_deg;
    let phi_i = scene.incident.phi_deg.to_radians();
    let wi = scene.wi();
    // The plane's horizontal direction towards the light.
    let u = glam::DVec3::new(phi_i.cos(), phi_i.sin(), 0.0);
    let mut out: Vec<VGroovePanel> = Vec::new();
    for (t, name) in [(theta_i, "ωr"), (0.0, "n"), (-theta_i, "towards the light")] {
        if out.iter().any(|p| (p.theta_o_deg - t).abs() < 1e-9) {
            continue;
        }
        let wo = slices::plane_direction(t.to_radians(), phi_i);
        out.push(VGroovePanel {
            theta_i_deg: theta_i,
            theta_o_deg: t,
            name,
            section: v_groove_section(wi, wo, u),
        });
    }
    out
}

/// Where the panels are painted, in screen points (y down).
pub trait GrooveCanvas {
    /// Text anchored at `at` by `align`; returns the rectangle it takes
    /// (the panels are laid out around their titles).
    fn text(&mut self, at: Pos2, align: Align2, text: &str, size: f32, color: Color32) -> Rect;
    /// A filled convex polygon.
    fn fill(&mut self, points: &[Pos2], color: Color32);
    /// A polyline, dashed as (dash, gap) if given.
    fn line(&mut self, points: &[Pos2], width: f32, color: Color32, dash: Option<(f32, f32)>);
    /// Clips what follows to `rect`, or ends the clip (`None`).
    fn clip(&mut self, rect: Option<Rect>);
    /// An arrow from `origin` along `vec`, its head a quarter of its length
    /// (egui's `Painter::arrow`).
    fn arrow(&mut self, origin: Pos2, vec: Vec2, width: f32, color: Color32) {
        let tip = origin + vec;
        let head = vec.length() / 4.0;
        let dir = vec.normalized();
        let rot = egui::emath::Rot2::from_angle(std::f32::consts::TAU / 10.0);
        self.line(&[origin, tip], width, color, None);
        self.line(&[tip, tip - head * (rot * dir)], width, color, None);
        self.line(
            &[tip, tip - head * (rot.inverse() * dir)],
            width,
            color,
            None,
        );
    }
}

/// The window's painter as a [`GrooveCanvas`].
pub struct PainterCanvas {
    painter: egui::Painter,
    clipped: Option<egui::Painter>,
}

impl PainterCanvas {
    /// Paints with `painter` (and its clip rectangle).
    pub fn new(painter: egui::Painter) -> Self {
        Self {
            painter,
            clipped: None,
        }
    }

    fn current(&self) -> &egui::Painter {
        self.clipped.as_ref().unwrap_or(&self.painter)
    }
}

impl GrooveCanvas for PainterCanvas {
    fn text(&mut self, at: Pos2, align: Align2, text: &str, size: f32, color: Color32) -> Rect {
        self.current()
            .text(at, align, text, egui::FontId::proportional(size), color)
    }

    fn fill(&mut self, points: &[Pos2], color: Color32) {
        self.current().add(egui::Shape::convex_polygon(
            points.to_vec(),
            color,
            egui::Stroke::NONE,
        ));
    }

    fn line(&mut self, points: &[Pos2], width: f32, color: Color32, dash: Option<(f32, f32)>) {
        let stroke = egui::Stroke::new(width, color);
        match dash {
            Some((d, g)) => {
                self.current()
                    .add(egui::Shape::dashed_line(points, stroke, d, g));
            }
            None => {
                self.current()
                    .add(egui::Shape::line(points.to_vec(), stroke));
            }
        }
    }

    fn clip(&mut self, rect: Option<Rect>) {
        self.clipped = rect.map(|r| self.painter.with_clip_rect(r));
    }
}

impl GrooveCanvas for Svg {
    fn text(&mut self, at: Pos2, align: Align2, text: &str, size: f32, color: Color32) -> Rect {
        let anchor = match align.x() {
            Align::Min => Anchor::Start,
            Align::Center => Anchor::Middle,
            Align::Max => Anchor::End,
        };
        let baseline = match align.y() {
            Align::Min => Baseline::Top,
            Align::Center => Baseline::Middle,
            Align::Max => Baseline::Bottom,
        };
        Svg::text(
            self,
            [at.x, at.y],
            text,
            size,
            color,
            anchor,
            baseline,
            None,
        );
        // No font metrics here: 0.58 em per character, 1.25 em a line.
        let extent = egui::vec2(text.chars().count() as f32 * size * 0.58, size * 1.25);
        align.anchor_size(at, extent)
    }

    fn fill(&mut self, points: &[Pos2], color: Color32) {
        let pts: Vec<[f32; 2]> = points.iter().map(|p| [p.x, p.y]).collect();
        self.polygon(&pts, color);
    }

    fn line(&mut self, points: &[Pos2], width: f32, color: Color32, dash: Option<(f32, f32)>) {
        let pts: Vec<[f32; 2]> = points.iter().map(|p| [p.x, p.y]).collect();
        self.polyline(&pts, color, width, dash.map(|d| d.0));
    }

    fn clip(&mut self, rect: Option<Rect>) {
        match rect {
            Some(r) => self.begin_clip([r.min.x, r.min.y], [r.width(), r.height()]),
            None => self.end_group(),
        }
    }
}

/// The light's and the viewer's colours in the v-groove panels.
const LIGHT: Color32 = Color32::from_rgb(250, 200, 60);
const VIEW: Color32 = Color32::from_rgb(90, 170, 255);
/// The panels' font size, points.
const FONT: f32 = 13.0;

/// Draws the v-groove panels side by side in `rect`.
pub fn paint_vgrooves(
    canvas: &mut dyn GrooveCanvas,
    rect: Rect,
    panels: &[VGroovePanel],
    dark: bool,
) {
    let text = super::strong_text_color(dark);
    let n = panels.len().max(1) as f32;
    let w = rect.width() / n;
    for (k, p) in panels.iter().enumerate() {
        let r = Rect::from_min_size(
            egui::pos2(rect.left() + k as f32 * w, rect.top()),
            egui::vec2(w, rect.height()),
        )
        .shrink(6.0);
        paint_vgroove(canvas, r, p, dark, text);
    }
}

/// One v-groove panel in `r`. Screen x runs as the charts' θo: the light on
/// the left (at −θi), the mirror direction on the right; a direction at
/// signed angle θ is `(sin θ, cos θ)`, and the facets' normal, the half
/// vector, is at `−tilt`.
fn paint_vgroove(
    canvas: &mut dyn GrooveCanvas,
    r: Rect,
    p: &VGroovePanel,
    dark: bool,
    text: Color32,
) {
    let sign = if p.theta_o_deg > 0.0 { "+" } else { "" };
    let title = format!("θo = {sign}{:.0}° ({})", p.theta_o_deg, p.name);
    let head = canvas.text(r.center_top(), Align2::CENTER_TOP, &title, FONT, text);
    let Some(s) = p.section else {
        canvas.text(r.center(), Align2::CENTER_CENTER, "no groove", FONT, text);
        return;
    };
    let foot = format!("lit {:.2} · seen {:.2} · G = {:.2}", s.lit, s.seen, s.g);
    let foot = canvas.text(r.center_bottom(), Align2::CENTER_BOTTOM, &foot, FONT, text);
    let fig = Rect::from_x_y_ranges(r.x_range(), head.bottom() + 4.0..=foot.top() - 4.0);
    if fig.height() < 20.0 || fig.width() < 40.0 {
        return;
    }
    // Two grooves of half-width 1 and depth t = tan|tilt|, with room above
    // for the rays. A deep groove (a low light) is cut below what matters,
    // 2.5 times the deeper of the lit and seen parts, at least one unit: its
    // rims, where the light and the view reach, stay large enough to read.
    let t = s.tilt.abs().min(89f64.to_radians()).tan() as f32;
    let reach = s.lit.max(s.seen) as f32 * t;
    let depth = t.min((2.5 * reach).max(1.0));
    let scale = (fig.width() / 4.8).min(fig.height() / (depth + 1.3));
    let origin = egui::pos2(fig.center().x, fig.top() + 1.2 * scale);
    let at = |(x, z): (f32, f32)| egui::pos2(origin.x + x * scale, origin.y - z * scale);
    let cut = depth < t;
    let cut_y = at((0.0, -depth - 0.12)).y;
    if cut {
        // The groove goes on below the cut, to depth t (outside the clip).
        canvas.text(
            egui::pos2(at((-2.0, 0.0)).x - 6.0, cut_y - 1.0),
            Align2::RIGHT_CENTER,
            &format!("{:.1}× deeper", t / depth),
            11.0,
            text,
        );
    }
    canvas.clip(Some(Rect::from_x_y_ranges(
        fig.x_range(),
        fig.top()..=cut_y,
    )));
    let profile = [(-2.0, 0.0), (-1.0, -t), (0.0, 0.0), (1.0, -t), (2.0, 0.0)];
    let material = if dark {
        Color32::from_gray(70)
    } else {
        Color32::from_gray(190)
    };
    // The material under the profile, one quad per facet (the clip cuts a
    // deep groove's material and facets).
    let bottom = -t - 0.15;
    for w2 in profile.windows(2) {
        let (a, b) = (w2[0], w2[1]);
        canvas.fill(
            &[at(a), at(b), at((b.0, bottom)), at((a.0, bottom))],
            material,
        );
    }
    let outline: Vec<Pos2> = profile.iter().map(|&q| at(q)).collect();
    canvas.line(&outline, 1.5, text.gamma_multiply(0.6), None);
    if cut {
        let y = cut_y - 1.0;
        canvas.line(
            &[
                egui::pos2(at((-2.0, 0.0)).x, y),
                egui::pos2(at((2.0, 0.0)).x, y),
            ],
            1.5,
            text,
            Some((6.0, 5.0)),
        );
    }
    // The reflecting facets (rim, foot): with the light on the left, a
    // tilt towards it (> 0) is the facets that rise to the right.
    let facets: [((f32, f32), (f32, f32)); 2] = if s.tilt >= 0.0 {
        [((0.0, 0.0), (-1.0, -t)), ((2.0, 0.0), (1.0, -t))]
    } else {
        [((-2.0, 0.0), (-1.0, -t)), ((0.0, 0.0), (1.0, -t))]
    };
    let lerp =
        |a: (f32, f32), b: (f32, f32), f: f32| (a.0 + (b.0 - a.0) * f, a.1 + (b.1 - a.1) * f);
    for (rim, base) in facets {
        let lit_end = lerp(rim, base, s.lit as f32);
        let seen_end = lerp(rim, base, s.seen as f32);
        canvas.line(
            &[at(lit_end), at(base)],
            4.0,
            text.gamma_multiply(0.35),
            None,
        );
        canvas.line(&[at(rim), at(lit_end)], 4.0, LIGHT, None);
        // The seen part: a blue band just above the facet.
        let d = at(base) - at(rim);
        let mut n = egui::vec2(-d.y, d.x).normalized();
        if n.y > 0.0 {
            n = -n;
        }
        let off = n * 5.0;
        canvas.line(&[at(rim) + off, at(seen_end) + off], 2.5, VIEW, None);
    }
    // On the first groove: rays from the light onto the lit part and from
    // the seen part to the viewer, and the limiting ray (dashed), which
    // grazes the partner facet's rim.
    let dir = |deg: f64| {
        let a = deg.to_radians() as f32;
        egui::vec2(a.sin(), -a.cos())
    };
    let (rim, base) = facets[0];
    for (frac, ray, colour, incoming) in [
        (s.lit as f32, dir(-p.theta_i_deg), LIGHT, true),
        (s.seen as f32, dir(p.theta_o_deg), VIEW, false),
    ] {
        let len = 1.1 * scale;
        for q in [0.3, 0.8] {
            let on = at(lerp(rim, base, q * frac));
            let away = on + ray * len;
            if incoming {
                canvas.arrow(away, on - away, 1.3, colour);
            } else {
                canvas.arrow(on, away - on, 1.3, colour);
            }
        }
        if frac < 0.999 {
            let edge = lerp(rim, base, frac);
            // Up to the rims' height and a little beyond.
            let reach = (-edge.1 / (-ray.y).max(0.05) + 0.5) * scale;
            let e = at(edge);
            canvas.line(&[e, e + ray * reach], 1.2, colour, Some((5.0, 4.0)));
        }
    }
    canvas.clip(None);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What a canvas was asked to draw, for the tests.
    #[derive(Default)]
    struct Record {
        texts: Vec<String>,
        lines: Vec<(Color32, usize)>,
        clips: Vec<bool>,
    }

    impl GrooveCanvas for Record {
        fn text(&mut self, at: Pos2, _: Align2, text: &str, _: f32, _: Color32) -> Rect {
            self.texts.push(text.to_string());
            Rect::from_min_size(at, egui::vec2(10.0, 10.0))
        }
        fn fill(&mut self, _: &[Pos2], _: Color32) {}
        fn line(&mut self, points: &[Pos2], _: f32, color: Color32, _: Option<(f32, f32)>) {
            self.lines.push((color, points.len()));
        }
        fn clip(&mut self, rect: Option<Rect>) {
            self.clips.push(rect.is_some());
        }
    }

    fn panel(theta_i: f64, theta_o: f64) -> VGroovePanel {
        let (ti, to) = (theta_i.to_radians(), theta_o.to_radians());
        let wi = glam::DVec3::new(ti.sin(), 0.0, ti.cos());
        let wo = glam::DVec3::new(-to.sin(), 0.0, to.cos());
        VGroovePanel {
            theta_i_deg: theta_i,
            theta_o_deg: theta_o,
            name: "test",
            section: v_groove_section(wi, wo, glam::DVec3::X),
        }
    }

    #[test]
    fn a_panel_draws_its_numbers_rays_and_balanced_clips() {
        let mut rec = Record::default();
        let p = panel(80.0, 0.0);
        let s = p.section.expect("a groove");
        let rect = Rect::from_min_size(Pos2::ZERO, egui::vec2(900.0, 300.0));
        paint_vgrooves(&mut rec, rect, std::slice::from_ref(&p), true);
        let foot = format!("lit {:.2} · seen {:.2} · G = {:.2}", s.lit, s.seen, s.g);
        assert!(rec.texts.contains(&foot), "{:?}", rec.texts);
        assert!(rec.texts.iter().any(|t| t.starts_with("θo = 0°")));
        // Both facets lit and seen, four arrows of three strokes each.
        assert_eq!(
            rec.lines.iter().filter(|l| l.0 == LIGHT).count(),
            2 + 2 * 3 + 1
        );
        assert!(rec.lines.iter().filter(|l| l.0 == VIEW).count() >= 2 + 2 * 3);
        assert_eq!(rec.clips, vec![true, false]);
    }

    #[test]
    fn a_light_at_the_horizon_draws_no_groove() {
        let mut rec = Record::default();
        let p = VGroovePanel {
            section: None,
            ..panel(45.0, 0.0)
        };
        let rect = Rect::from_min_size(Pos2::ZERO, egui::vec2(300.0, 200.0));
        paint_vgrooves(&mut rec, rect, &[p], false);
        assert!(rec.texts.iter().any(|t| t == "no groove"));
        assert!(rec.lines.is_empty() && rec.clips.is_empty());
    }
}
