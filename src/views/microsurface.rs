//! The microsurface view (issue 29): a patch of a simulated rough surface
//! (`bv_core::microsurface`, a Beckmann or GGX heightfield) drawn in 3D and
//! shaded by the scene's light, a few rays from the light traced on it
//! (incoming yellow, bounces orange, leaving blue), and beside it what the
//! virtual gonioreflectometer measured: masking G1 at θi against Smith's
//! closed form, and ρhd split into single and multiple bounces against the
//! single-scattering Cook–Torrance model with the same D — the energy such a
//! model loses is the multiple-bounce share.
//!
//! The distribution and α are the view's own (its toolbar), not a model's
//! parameters: the surface is a specimen, not the drawn BRDF. The drawing
//! sorts triangles back to front; the rays are drawn over the surface
//! (a ray behind a ridge is still shown).

use super::{Scene, View};
use crate::derive::microsurface::{self, Simulation};
use crate::session::command::Command;
use bv_core::microsurface::SlopeDistribution;
use eframe::egui::{self, Align2, Color32, FontId, Pos2, Rect, Sense, Stroke, Ui, epaint::Mesh};
use glam::DVec3;
use std::any::Any;

/// Cells of the drawn patch per side (around the tile's centre).
const PATCH: usize = 28;

/// The microsurface view.
pub struct MicrosurfaceView {
    /// Slope distribution of the specimen.
    pub distribution: SlopeDistribution,
    /// Its roughness α.
    pub alpha: f64,
    busy: bool,
}

impl Default for MicrosurfaceView {
    fn default() -> Self {
        Self {
            distribution: SlopeDistribution::Beckmann,
            alpha: 0.5,
            busy: false,
        }
    }
}

/// An orthographic camera looking down at the patch from θ = 55°.
struct Camera {
    right: DVec3,
    up: DVec3,
    toward: DVec3,
}

impl Camera {
    fn new() -> Self {
        let (t, p) = (55f64.to_radians(), (-115f64).to_radians());
        let toward = DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
        let right = DVec3::Z.cross(toward).normalize();
        let up = toward.cross(right);
        Self { right, up, toward }
    }

    fn project(&self, p: DVec3) -> (f64, f64, f64) {
        (p.dot(self.right), p.dot(self.up), p.dot(self.toward))
    }
}

impl View for MicrosurfaceView {
    fn toolbar(&mut self, ui: &mut Ui, _scene: &Scene<'_>, _out: &mut Vec<Command>) {
        egui::ComboBox::from_id_salt("microsurface distribution")
            .selected_text(match self.distribution {
                SlopeDistribution::Beckmann => "Beckmann",
                SlopeDistribution::Ggx => "GGX",
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(
                    &mut self.distribution,
                    SlopeDistribution::Beckmann,
                    "Beckmann",
                );
                ui.selectable_value(&mut self.distribution, SlopeDistribution::Ggx, "GGX");
            });
        ui.add(egui::Slider::new(&mut self.alpha, 0.05..=1.5).text("α"));
    }

    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, _out: &mut Vec<Command>) {
        let rect = ui.available_rect_before_wrap();
        ui.allocate_rect(rect, Sense::hover());
        let painter = ui.painter_at(rect);
        let shown = microsurface::request(
            &super::waker(ui.ctx()),
            scene,
            self.distribution,
            self.alpha,
        );
        self.busy = shown.busy;
        let text = ui.visuals().text_color();
        let font = FontId::proportional(14.0);
        let Some(done) = &shown.done else {
            painter.text(
                rect.center(),
                Align2::CENTER_CENTER,
                "simulating the surface…",
                font,
                text,
            );
            return;
        };
        let sim = &done.value;
        let mut lines = summary(sim);
        if let Some((a, b)) = shown.progress.filter(|_| shown.busy) {
            lines.push(format!("simulating: {a}/{b} batches"));
        }
        let text_w = 330.0;
        // Lines 20 points apart, closer (down to 16, for 14-point text) in
        // a short pane such as presentation mode's; blank separators go
        // before any number does.
        let spacing = |n: usize| ((rect.height() - 24.0) / n.max(1) as f32).min(20.0);
        let fits = |lines: &[String]| spacing(lines.len()) >= 16.0;
        if !fits(&lines) {
            lines.retain(|l| !l.is_empty());
        }
        let line_h = spacing(lines.len());
        // Beside the drawing when there is room for the text; else the
        // drawing with one line under it (small figures, the overview).
        if rect.width() < text_w + 280.0 || !fits(&lines) {
            let small = FontId::proportional(11.0);
            let draw_rect =
                Rect::from_min_max(rect.min, Pos2::new(rect.max.x, rect.max.y - 16.0)).shrink(6.0);
            draw_surface(&painter, draw_rect, sim, scene.wi(), shown.stale);
            let g = &sim.gonio;
            painter.text(
                Pos2::new(rect.min.x + 4.0, rect.max.y - 2.0),
                Align2::LEFT_BOTTOM,
                format!(
                    "ρ single {:.3} · multiple {:.3}",
                    g.rho_single, g.rho_multiple
                ),
                small,
                text,
            );
            return;
        }
        let draw_rect =
            Rect::from_min_max(rect.min, Pos2::new(rect.max.x - text_w, rect.max.y)).shrink(12.0);
        draw_surface(&painter, draw_rect, sim, scene.wi(), shown.stale);
        let mut y = rect.min.y + 14.0;
        for l in lines {
            painter.text(
                Pos2::new(rect.max.x - text_w, y),
                Align2::LEFT_TOP,
                l,
                font.clone(),
                text,
            );
            y += line_h;
        }
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn busy(&self) -> bool {
        self.busy
    }
}

/// The numbers beside the drawing.
fn summary(sim: &Simulation) -> Vec<String> {
    let o = sim.surface.options();
    let g = &sim.gonio;
    vec![
        format!(
            "{} surface, α = {:.2}, {}²",
            match o.distribution {
                SlopeDistribution::Beckmann => "Beckmann",
                SlopeDistribution::Ggx => "GGX",
            },
            o.alpha_x,
            o.size
        ),
        format!("light θi = {:.1}°", g.opts.theta_i.to_degrees()),
        String::new(),
        "masking G1(θi)".into(),
        format!("  measured {:.4} ± {:.4}", sim.g1.measured, sim.g1.sigma),
        format!("  Smith     {:.4}", sim.g1.smith),
        String::new(),
        format!("ρhd(θi), F = 1, {} rays", g.rays),
        format!(
            "  single    {:.4} ± {:.4}",
            g.rho_single, g.rho_single_sigma_surface
        ),
        format!(
            "  multiple  {:.4} ± {:.4}",
            g.rho_multiple, g.rho_multiple_sigma_surface
        ),
        format!("  total     {:.4}", g.rho()),
        format!("  Cook–Torrance (single) {:.4}", sim.analytic_rho),
        String::new(),
        format!(
            "Cook–Torrance loses {:.1} %;",
            100.0 * (1.0 - sim.analytic_rho)
        ),
        format!(
            "the surface returns {:.1} % in ≥ 2 bounces",
            100.0 * g.rho_multiple
        ),
    ]
}

/// The patch, shaded by the light, and the ray paths.
fn draw_surface(painter: &egui::Painter, rect: Rect, sim: &Simulation, wi: DVec3, stale: bool) {
    let s = &sim.surface;
    let n = s.size();
    let (dx, dy) = s.cell();
    let c0 = n / 2 - PATCH / 2;
    let centre = DVec3::new((n / 2) as f64 * dx, (n / 2) as f64 * dy, 0.0);
    let cam = Camera::new();
    let point =
        |i: usize, j: usize| DVec3::new(i as f64 * dx, j as f64 * dy, s.height(i, j)) - centre;
    // Fit the patch and the rays (in from the light, out after the last
    // bounce, each `reach` long) into the rectangle.
    let reach = 0.35 * PATCH as f64 * dx.max(dy);
    let mut points: Vec<DVec3> = Vec::new();
    for j in [c0, c0 + PATCH] {
        for i in c0..=c0 + PATCH {
            points.push(point(i, j));
            points.push(point(j, i));
        }
    }
    for (path, dir) in &sim.paths {
        if let (Some(first), Some(last)) = (path.get(1), path.last()) {
            points.push(*first - centre + wi * reach);
            points.push(*last - centre + *dir * reach);
        }
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in &points {
        let (x, y, _) = cam.project(*p);
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    let scale = (rect.width() as f64 / (x1 - x0)).min(rect.height() as f64 / (y1 - y0));
    let to_screen = |p: DVec3| {
        let (x, y, _) = cam.project(p);
        Pos2::new(
            rect.center().x + ((x - 0.5 * (x0 + x1)) * scale) as f32,
            rect.center().y - ((y - 0.5 * (y0 + y1)) * scale) as f32,
        )
    };
    // Triangles back to front.
    let mut tris: Vec<(f64, [DVec3; 3], DVec3)> = Vec::with_capacity(2 * PATCH * PATCH);
    for j in c0..c0 + PATCH {
        for i in c0..c0 + PATCH {
            let (p00, p10, p01, p11) = (
                point(i, j),
                point(i + 1, j),
                point(i, j + 1),
                point(i + 1, j + 1),
            );
            let corners = if bv_core::microsurface::Surface::main_diagonal(i, j) {
                [[p00, p10, p11], [p00, p11, p01]]
            } else {
                [[p00, p10, p01], [p10, p11, p01]]
            };
            for (t, c) in corners.into_iter().enumerate() {
                let m = s.facet(i, j, t).normal();
                let depth = (c[0] + c[1] + c[2]).dot(cam.toward) / 3.0;
                tris.push((depth, c, m));
            }
        }
    }
    tris.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut mesh = Mesh::default();
    let alpha = if stale { 150 } else { 255 };
    for (_, c, m) in &tris {
        let lit = 0.18 + 0.82 * m.dot(wi).max(0.0);
        let shade = (lit.clamp(0.0, 1.0) * 225.0) as u8;
        let colour = Color32::from_rgba_unmultiplied(
            shade,
            shade,
            (shade as f32 * 1.05).min(255.0) as u8,
            alpha,
        );
        let base = mesh.vertices.len() as u32;
        for p in c {
            mesh.colored_vertex(to_screen(*p), colour);
        }
        mesh.add_triangle(base, base + 1, base + 2);
    }
    painter.add(egui::Shape::mesh(mesh));
    // Rays: in from the light, the bounces, out.
    let incoming = Stroke::new(1.5, Color32::from_rgb(240, 200, 40));
    let bounce = Stroke::new(1.5, Color32::from_rgb(240, 120, 30));
    let out = Stroke::new(1.5, Color32::from_rgb(90, 170, 255));
    for (path, dir) in &sim.paths {
        let hits: Vec<DVec3> = path.iter().skip(1).map(|p| *p - centre).collect();
        let (Some(first), Some(last)) = (hits.first(), hits.last()) else {
            continue;
        };
        painter.line_segment(
            [to_screen(*first + wi * reach), to_screen(*first)],
            incoming,
        );
        for w in hits.windows(2) {
            painter.line_segment([to_screen(w[0]), to_screen(w[1])], bounce);
        }
        painter.line_segment([to_screen(*last), to_screen(*last + *dir * reach)], out);
    }
}
