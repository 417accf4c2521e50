//! The microsurface view (issue 29): a patch of a simulated rough surface
//! (`bv_core::microsurface`, a Beckmann or GGX heightfield) drawn in 3D and
//! shaded by the scene's light, a few rays from the light traced on it
//! (incoming yellow, bounces orange, leaving blue), and beside it what the
//! virtual gonioreflectometer measured: masking G1 at θi against Smith's
//! closed form, and ρhd split into single and multiple bounces against the
//! single-scattering Cook–Torrance model with the same D — the energy such a
//! model loses is the multiple-bounce share.
//!
//! The specimen is the selected BRDF's distribution and roughness when it
//! names them (`bv_core::Ndf::slopes`: Beckmann or GGX, one scale), else the
//! view's own distribution and α; both are saved with the scene
//! (`plots.microsurface`), so a deck's slide shows the surface it means. The
//! drawing
//! sorts triangles back to front; the rays are drawn over the surface
//! (a ray behind a ridge is still shown).
//!
//! With *NDF* on, a chart under it compares the facet normals' histogram
//! (the measured D averaged over each θm bin, dashed) with the model's
//! D(θm) (LECTURE.md N9: a rough surface and its NDF).

use super::{Scene, View};
use crate::derive::microsurface::{self, Simulation, Specimen};
use crate::session::command::Command;
use crate::session::state::{MicrosurfaceSettings, PlotSettings};
use bv_core::microsurface::SlopeDistribution;
use bv_core::microsurface::measure::NdfHistogram;
use eframe::egui::{self, Align2, Color32, FontId, Pos2, Rect, Sense, Stroke, Ui, epaint::Mesh};
use glam::DVec3;
use std::any::Any;

/// Cells of the drawn patch per side (around the tile's centre).
const PATCH: usize = 28;

/// The microsurface view.
#[derive(Default)]
pub struct MicrosurfaceView {
    busy: bool,
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
    fn toolbar(&mut self, ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
        let plots = scene.state.plots;
        let before = plots.microsurface;
        let mut set = before;
        let named = microsurface::specimen_with(
            scene,
            &MicrosurfaceSettings {
                from_model: true,
                ..before
            },
        );
        if super::toolbar_toggle(
            ui,
            set.from_model,
            "from model",
            "Generate the surface with the selected BRDF's distribution and roughness \
             (Beckmann or GGX); off, or for a model without them, with the settings here",
        ) {
            set.from_model = !set.from_model;
        }
        if set.from_model && named.from.is_some() {
            ui.label(named.describe());
        } else {
            egui::ComboBox::from_id_salt("microsurface distribution")
                .selected_text(set.distribution.label())
                .show_ui(ui, |ui| {
                    for d in [SlopeDistribution::Beckmann, SlopeDistribution::Ggx] {
                        ui.selectable_value(&mut set.distribution, d, d.label());
                    }
                });
            let range = microsurface::ALPHA_RANGE;
            ui.add(egui::Slider::new(&mut set.alpha, range).text("α"));
        }
        if super::toolbar_toggle(
            ui,
            set.ndf,
            "NDF",
            "Under the surface, the histogram of its facet normals (measured D \
             averaged over each θm bin) against the model's D(θm)",
        ) {
            set.ndf = !set.ndf;
        }
        if set != before {
            out.push(Command::SetPlots(PlotSettings {
                microsurface: set,
                ..plots
            }));
        }
    }

    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, _out: &mut Vec<Command>) {
        let full = ui.available_rect_before_wrap();
        ui.allocate_rect(full, Sense::hover());
        // With the NDF chart, the surface takes the left half and the chart
        // the right.
        let show_ndf = scene.state.plots.microsurface.ndf;
        let rect = if show_ndf {
            Rect::from_min_max(full.min, Pos2::new(full.center().x, full.max.y))
        } else {
            full
        };
        let painter = ui.painter_at(rect);
        let specimen = microsurface::specimen(scene);
        let shown = microsurface::request(&super::waker(ui.ctx()), scene, &specimen);
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
        if show_ndf
            && let Some(done) = microsurface::ndf(&super::waker(ui.ctx()), scene, &specimen).done
        {
            let chart_rect = Rect::from_min_max(Pos2::new(rect.max.x + 8.0, full.min.y), full.max);
            let dark = ui.visuals().dark_mode;
            let chart = ndf_chart(&done.value, &specimen, dark);
            let id = super::view_id(crate::session::views::MICROSURFACE.id).with("ndf");
            ui.scope_builder(egui::UiBuilder::new().max_rect(chart_rect), |ui| {
                // Presenting, the legend is a column beside the chart.
                let legend_w = if scene.presenting {
                    super::side_legend_width(ui, &chart.series).min(0.4 * chart_rect.width())
                } else {
                    0.0
                };
                super::terms::plot_chart(ui, id, &chart, chart_rect.size(), false, scene, legend_w);
            });
        }
        let mut lines = summary(sim, &specimen);
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
fn summary(sim: &Simulation, specimen: &Specimen) -> Vec<String> {
    let o = sim.surface.options();
    let g = &sim.gonio;
    // The BRDF it comes from on a line of its own, its name cut to fit the
    // 330-point text column (a deck's legend names run long).
    let from = match &specimen.from {
        Some(l) if l.chars().count() > 24 => {
            format!("slopes of {}…", l.chars().take(23).collect::<String>())
        }
        Some(l) => format!("slopes of {l}"),
        None => "the view's own slopes".into(),
    };
    vec![
        format!("{} surface, {}²", specimen.describe(), o.size),
        from,
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

/// The facet normals against the model: the measured D averaged over each
/// θm bin (`derive::microsurface::ndf`, joined at the bins' centres) and
/// the specimen's D(θm) averaged over azimuth, in 1/sr.
pub fn ndf_chart(h: &NdfHistogram, specimen: &Specimen, dark: bool) -> super::chart::Chart {
    use super::chart::{self, Chart, Series};
    let dt = h.theta_max / h.n_theta as f64;
    // Each bin's mean D at its centre.
    let stairs: Vec<[f64; 2]> = (0..h.n_theta)
        .map(|t| {
            let (d, _) = h.d_values(t * h.n_phi);
            [((t as f64 + 0.5) * dt).to_degrees(), d]
        })
        .collect();
    let mf = bv_core::microfacet::Microfacet::new(
        specimen.distribution.distribution(),
        specimen.alpha_x,
        specimen.alpha_y,
    );
    let model: Vec<[f64; 2]> = (0..=200)
        .map(|k| {
            let th = h.theta_max * k as f64 / 200.0;
            let d = (0..32)
                .map(|j| {
                    let ph = std::f64::consts::TAU * (j as f64 + 0.5) / 32.0;
                    mf.d(bv_core::microsurface::measure::direction(th, ph))
                })
                .sum::<f64>()
                / 32.0;
            [th.to_degrees(), d]
        })
        .collect();
    let top = stairs
        .iter()
        .chain(&model)
        .map(|p| p[1])
        .fold(0.0, f64::max)
        * 1.08;
    let x_max = h.theta_max.to_degrees();
    let measured = super::strong_text_color(dark);
    let blue = Color32::from_rgb(78, 151, 234);
    Chart {
        title: String::new(),
        x_label: "θm (facet normal from the surface normal)".into(),
        y_label: "D (1/sr)".into(),
        x_range: (0.0, x_max),
        y_range: (0.0, top),
        x_ticks: chart::angle_ticks(0.0, x_max),
        y_ticks: chart::labelled(chart::nice_ticks(0.0, top, 5)),
        bands: Vec::new(),
        series: vec![
            Series {
                label: format!("{} D(θm)", specimen.distribution.label()),
                color: blue,
                points: model,
                width: 2.5,
                dash: None,
            },
            Series {
                label: format!(
                    "facet normals of a {}² surface like it (bins of {:.1}°)",
                    microsurface::NDF_SIZE,
                    dt.to_degrees()
                ),
                color: measured,
                points: stairs,
                width: 2.0,
                dash: Some(6.0),
            },
        ],
        vlines: Vec::new(),
        hlines: Vec::new(),
        note: String::new(),
    }
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
    for edge in [c0, c0 + PATCH] {
        for k in c0..=c0 + PATCH {
            points.push(point(k, edge));
            points.push(point(edge, k));
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
