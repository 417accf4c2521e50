//! Importance sampling made visible: for the current light direction ωi, the
//! directions ωo that the selected BRDF's own sampler draws
//! (`Brdf::sample`), beside a histogram of many draws over equal-solid-angle
//! bins of the outgoing hemisphere and what the sampler's density
//! (`Brdf::pdf`) integrates to over each bin, with Pearson's χ² verdict (the
//! test PBRT-v4 and Mitsuba run on every sampler). A sampler whose density
//! does not describe what it draws gets a tiny p-value. For a model that
//! transmits the bins cover the whole sphere, one χ² over both, and a second
//! row of discs shows the hemisphere below the surface (issue 33).
//!
//! All three panels use Lambert's azimuthal equal-area disc (centre: the
//! normal, rim: the horizon), on which the bins of
//! `bv_core::analysis::sample_histogram` are annulus sectors of equal area.
//! The histogram is computed in the background (in steps of a few thousand
//! evaluations, so that a browser page keeps drawing) and cached by the
//! BRDF's revision and ωi; figures compute it before drawing.

use super::{Scene, SceneBrdf, View, colormap};
use crate::derive::sampling::{self, N_PHI, N_THETA, Outcome, SIGNIFICANCE, verdict};
use crate::session::command::Command;
use bv_core::analysis::reciprocity_map::hemisphere_to_disc;
use eframe::egui::{
    self, Align2, Color32, FontId, Mesh, Pos2, Rect, Sense, Shape, Stroke, Ui, Vec2,
};
use glam::DVec3;
use std::f64::consts::PI;

/// The sampling view.
#[derive(Default)]
pub struct SamplingView {
    /// The histogram drawn in the last frame and whether it was of an older key.
    pub shown: Option<(Outcome, bool)>,
    /// Where the three discs were drawn in the last frame (points, draws, pdf).
    pub disc_rects: Vec<Rect>,
    waiting: bool,
}

impl SamplingView {
    fn histogram(
        &mut self,
        ctx: &egui::Context,
        scene: &Scene<'_>,
        b: &SceneBrdf,
    ) -> Option<(Outcome, bool)> {
        let shown = sampling::histogram(&super::waker(ctx), scene, b);
        self.waiting = shown.busy;
        shown.value()
    }
}

/// Screen position of a disc point (x right, y up on the disc).
fn on_disc(c: Pos2, r: f32, x: f64, y: f64) -> Pos2 {
    c + Vec2::new(x as f32 * r, -y as f32 * r)
}

/// Fills bin `(t, p)` of the equal-area disc: the annulus sector
/// `ρ ∈ [√(t/nθ), √((t+1)/nθ)]`, `φ ∈ [2π p/nφ, 2π (p+1)/nφ)`.
fn sector(mesh: &mut Mesh, c: Pos2, r: f32, t: usize, p: usize, color: Color32) {
    let r0 = (t as f64 / N_THETA as f64).sqrt();
    let r1 = ((t + 1) as f64 / N_THETA as f64).sqrt();
    let steps = 4;
    let phi0 = 2.0 * PI * p as f64 / N_PHI as f64;
    let dphi = 2.0 * PI / N_PHI as f64 / steps as f64;
    for k in 0..steps {
        let a = phi0 + k as f64 * dphi;
        let b = a + dphi;
        let base = mesh.vertices.len() as u32;
        for (rr, phi) in [(r0, a), (r1, a), (r1, b), (r0, b)] {
            mesh.colored_vertex(on_disc(c, r, rr * phi.cos(), rr * phi.sin()), color);
        }
        mesh.add_triangle(base, base + 1, base + 2);
        mesh.add_triangle(base, base + 2, base + 3);
    }
}

/// Which hemisphere a disc shows. The lower one is seen through the
/// surface (x and y as on the upper disc, the rim its horizon, the centre
/// −z), as the light disc shows a light below.
#[derive(Clone, Copy, PartialEq)]
enum Side {
    Above,
    Below,
}

impl Side {
    /// The histogram row drawn as ring `t` of this side's disc (ring 0 at
    /// the centre): below the surface the rows run from the horizon down to
    /// −z (`derive::sampling::options_for`).
    fn row(self, t: usize) -> usize {
        match self {
            Side::Above => t,
            Side::Below => 2 * N_THETA - 1 - t,
        }
    }

    /// Whether `w` is on this side.
    fn holds(self, w: DVec3) -> bool {
        match self {
            Side::Above => w.z > 0.0,
            Side::Below => w.z < 0.0,
        }
    }

    /// `w` as the upper-hemisphere direction the disc maps.
    fn folded(self, w: DVec3) -> DVec3 {
        match self {
            Side::Above => w,
            Side::Below => DVec3::new(w.x, w.y, -w.z),
        }
    }
}

/// A histogram disc: each bin coloured by `value / scale` (viridis).
fn histogram_disc(
    painter: &egui::Painter,
    c: Pos2,
    r: f32,
    values: &[f64],
    scale: f64,
    side: Side,
) {
    let mut mesh = Mesh::default();
    for t in 0..N_THETA {
        for p in 0..N_PHI {
            let v = values.get(side.row(t) * N_PHI + p).copied().unwrap_or(0.0);
            let x = if scale > 0.0 { (v / scale) as f32 } else { 0.0 };
            sector(&mut mesh, c, r, t, p, colormap::viridis(x.clamp(0.0, 1.0)));
        }
    }
    painter.add(Shape::mesh(mesh));
}

/// Where the footer starts below the verdict's top, points.
const FOOTER_AT: f32 = 18.0;

impl View for SamplingView {
    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, _out: &mut Vec<Command>) {
        let dark = ui.visuals().dark_mode;
        let text = super::strong_text(ui);
        let weak = ui.visuals().weak_text_color();
        let area = ui.available_rect_before_wrap();
        let _ = ui.allocate_exact_size(area.size(), Sense::hover());
        let painter = ui.painter_at(area);
        let fill = super::figure_fill(ui, scene);
        if fill != Color32::TRANSPARENT {
            painter.rect_filled(area, 0.0, fill);
        }
        self.shown = None;
        self.disc_rects.clear();
        let font = FontId::proportional(12.0);
        let small = FontId::proportional(11.0);
        let Some(b) = scene.primary().cloned() else {
            painter.text(
                area.center(),
                Align2::CENTER_CENTER,
                "no BRDF drawn",
                font,
                weak,
            );
            return;
        };
        let Some((outcome, stale)) = self.histogram(ui.ctx(), scene, &b) else {
            painter.text(
                area.center(),
                Align2::CENTER_CENTER,
                "drawing samples…",
                font,
                weak,
            );
            return;
        };
        self.shown = Some((outcome.clone(), stale));
        let h = match outcome.as_ref() {
            Ok(h) => h,
            Err(e) => {
                painter.text(
                    area.center(),
                    Align2::CENTER_CENTER,
                    format!("cannot sample: {e}"),
                    font,
                    Color32::from_rgb(220, 60, 60),
                );
                return;
            }
        };
        let (ti, pi) = (scene.incident.theta_deg, scene.incident.phi_deg);
        painter.text(
            Pos2::new(area.left() + 6.0, area.top() + 4.0),
            Align2::LEFT_TOP,
            format!(
                "{}: ωo drawn by its sampler for θi {ti:.1}°, φi {pi:.1}° ({} draws){}",
                b.label,
                h.samples,
                if stale { " (updating)" } else { "" }
            ),
            font.clone(),
            text,
        );
        // Three discs in a row (two rows for a transmitting model: above and
        // below the surface), titles above, the verdict below.
        let sides: &[Side] = if h.whole_sphere {
            &[Side::Above, Side::Below]
        } else {
            &[Side::Above]
        };
        let rows = sides.len() as f32;
        // One colour scale for both histograms: the largest of either.
        let observed: Vec<f64> = h.observed.iter().map(|&o| o as f64).collect();
        let scale = observed
            .iter()
            .chain(&h.expected)
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        // The footer wraps at the view's width, and the discs leave it room:
        // as one line it ran off the right edge (a presented slide cut it
        // after "ring:").
        let footer = painter.layout(
            format!(
                "∫ pdf dω over the {} {}; {} draws gave no direction{} ({} expected); colour: count / {}; dot: ωi, ring: its mirror direction",
                if h.whole_sphere { "sphere" } else { "hemisphere" },
                bv_core::text::fmt_value(h.pdf_mass),
                h.failed,
                if h.whole_sphere { "" } else { " above the horizon" },
                bv_core::text::fmt_value(h.expected_failed),
                bv_core::text::fmt_value(scale),
            ),
            small.clone(),
            weak,
            (area.width() - 12.0).max(40.0),
        );
        let top = 48.0;
        let bottom = (FOOTER_AT + footer.size().y + 12.0).max(52.0);
        let gap = 16.0;
        // Room for a row's caption between the rows.
        let row_gap = if h.whole_sphere { 34.0 } else { 0.0 };
        let side = ((area.width() - 4.0 * gap) / 3.0)
            .min((area.height() - top - bottom - row_gap * (rows - 1.0)) / rows)
            .max(20.0);
        // Centre the discs and the verdict in a tall area.
        let top = top
            + ((area.height() - top - bottom - rows * side - (rows - 1.0) * row_gap) * 0.4)
                .max(0.0);
        let row_w = 3.0 * side + 2.0 * gap;
        let left = area.left() + ((area.width() - row_w) * 0.5).max(gap);
        let discs: Vec<(Rect, Side)> = sides
            .iter()
            .enumerate()
            .flat_map(|(row, &s)| {
                (0..3).map(move |k| {
                    (
                        Rect::from_min_size(
                            Pos2::new(
                                left + k as f32 * (side + gap),
                                area.top() + top + row as f32 * (side + row_gap),
                            ),
                            Vec2::splat(side),
                        ),
                        s,
                    )
                })
            })
            .collect();
        self.disc_rects = discs.iter().map(|d| d.0).collect();
        let r = side * 0.5;
        let grid = super::grid_color(dark);
        let titles = [
            format!("{} of the draws", h.points.len()),
            "draws per bin".to_string(),
            "draws × ∫ pdf dω per bin".to_string(),
        ];
        let wi = scene.wi();
        for (n, (disc, s)) in discs.iter().enumerate() {
            let (k, s) = (n % 3, *s);
            let c = disc.center();
            let title = match (h.whole_sphere, s, k) {
                (true, Side::Above, 0) => "draws above the surface".to_string(),
                (true, Side::Below, 0) => "draws below (seen through it)".to_string(),
                _ => titles[k].clone(),
            };
            painter.text(
                Pos2::new(c.x, disc.top() - 4.0),
                Align2::CENTER_BOTTOM,
                title,
                small.clone(),
                text,
            );
            match k {
                0 => {
                    painter.circle_filled(c, r, super::grid_color(!dark).gamma_multiply(0.15));
                }
                1 => histogram_disc(&painter, c, r, &observed, scale, s),
                _ => histogram_disc(&painter, c, r, &h.expected, scale, s),
            }
            painter.circle_stroke(c, r, Stroke::new(1.5, text.gamma_multiply(0.7)));
            for deg in [30.0f64, 60.0] {
                let rr = (1.0 - deg.to_radians().cos()).sqrt() as f32 * r;
                painter.circle_stroke(c, rr, Stroke::new(1.0, grid));
            }
            let to_screen = |w: DVec3| {
                let p = hemisphere_to_disc(s.folded(w));
                on_disc(c, r, p.x, p.y)
            };
            if k == 0 {
                let color = Color32::from_rgb(b.rgb[0], b.rgb[1], b.rgb[2]);
                for w in h.points.iter().filter(|w| s.holds(**w)) {
                    painter.circle_filled(to_screen(*w), 1.6, color);
                }
            }
            // The light and its mirror direction on the disc of their side.
            if s.holds(wi) {
                let mirror = DVec3::new(-wi.x, -wi.y, wi.z);
                painter.circle_stroke(
                    to_screen(mirror),
                    5.0,
                    Stroke::new(1.5, super::mirror_color(dark)),
                );
                painter.circle_filled(to_screen(wi), 5.0, super::light_color(dark));
                painter.circle_stroke(to_screen(wi), 5.0, Stroke::new(1.0, Color32::BLACK));
            }
        }
        let y = discs.last().map_or(area.top(), |d| d.0.bottom()) + 8.0;
        let verdict_color = if h.chi2.p_value >= SIGNIFICANCE {
            text
        } else {
            Color32::from_rgb(230, 70, 70)
        };
        painter.text(
            Pos2::new(area.left() + 6.0, y),
            Align2::LEFT_TOP,
            verdict(h),
            font,
            verdict_color,
        );
        painter.galley(Pos2::new(area.left() + 6.0, y + FOOTER_AT), footer, weak);
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn busy(&self) -> bool {
        self.waiting
    }
}
