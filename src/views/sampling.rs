//! Importance sampling made visible: for the current light direction ωi, the
//! directions ωo that the selected BRDF's own sampler draws
//! (`Brdf::sample`), beside a histogram of many draws over equal-solid-angle
//! bins of the outgoing hemisphere and what the sampler's density
//! (`Brdf::pdf`) integrates to over each bin, with Pearson's χ² verdict (the
//! test PBRT-v4 and Mitsuba run on every sampler). A sampler whose density
//! does not describe what it draws gets a tiny p-value.
//!
//! All three panels use Lambert's azimuthal equal-area disc (centre: the
//! normal, rim: the horizon), on which the bins of
//! `bv_core::analysis::sample_histogram` are annulus sectors of equal area.
//! The histogram is computed in the background (in steps of a few thousand
//! evaluations, so that a browser page keeps drawing) and cached by the
//! BRDF's revision and ωi; figures compute it before drawing.

use super::background::{self, Slots};
use super::{Scene, SceneBrdf, View, colormap};
use crate::session::command::Command;
use bv_core::analysis::reciprocity_map::hemisphere_to_disc;
use bv_core::analysis::sample_histogram::{HistogramJob, HistogramOptions, SampleHistogram};
use eframe::egui::{
    self, Align2, Color32, FontId, Mesh, Pos2, Rect, Sense, Shape, Stroke, Ui, Vec2,
};
use glam::DVec3;
use std::f64::consts::PI;
use std::sync::Arc;
use std::time::Duration;

/// Bins in `cos θ`: 10 rings of equal solid angle.
pub const N_THETA: usize = 10;
/// Bins in φ.
pub const N_PHI: usize = 24;
/// Draws for the histogram: enough that every bin a sampler visits has tens
/// of draws, and quick (tens of milliseconds for an analytic model).
pub const SAMPLES: usize = 100_000;
/// Directions shown as points.
pub const POINTS: usize = 1_500;
/// The p-value below which the sampler is called inconsistent with its
/// density (a 1 % test, as in PBRT-v4's and Mitsuba's χ² sampling tests).
pub const SIGNIFICANCE: f64 = 0.01;

/// What a histogram was computed for: BRDF revision, ωi (θ, φ bits).
pub type Key = (u64, u64, u64);

/// The histogram options this view uses.
pub fn options() -> HistogramOptions {
    HistogramOptions {
        n_theta: N_THETA,
        n_phi: N_PHI,
        samples: SAMPLES,
        seed: 1,
        max_points: POINTS,
        ..HistogramOptions::default()
    }
}

type Outcome = Arc<Result<SampleHistogram, String>>;

/// Draws or density evaluations per step of the background job: a few
/// milliseconds of an analytic model in a browser page, where a step must
/// fit in a slice of a frame.
const WORK_PER_STEP: usize = 8192;

/// One step of the histogram's computation (`job` holds it between steps).
fn step(job: &mut Option<HistogramJob>, brdf: &dyn bv_core::Brdf, wi: DVec3) -> Option<Outcome> {
    let j = match job {
        Some(j) => j,
        None => match HistogramJob::new(wi, &options()) {
            Ok(j) => job.insert(j),
            Err(e) => return Some(Arc::new(Err(e.to_string()))),
        },
    };
    j.step(brdf, WORK_PER_STEP).map(|h| Arc::new(Ok(h)))
}

/// The verdict line of a histogram.
pub fn verdict(h: &SampleHistogram) -> String {
    let c = &h.chi2;
    let sign = if c.p_value >= SIGNIFICANCE {
        "passed: the draws follow the pdf"
    } else {
        "FAILED: the draws do not follow the pdf"
    };
    let mut s = format!(
        "χ² = {} with {} degrees of freedom, p = {}: {sign} (1 % test)",
        bv_core::text::fmt_value(c.statistic),
        c.dof,
        bv_core::text::fmt_value(c.p_value),
    );
    if c.impossible > 0 {
        s.push_str(&format!("; {} draws where the pdf is 0", c.impossible));
    }
    s
}

/// The histograms of the process, shared through egui's memory (slot: BRDF id).
fn slots(ctx: &egui::Context) -> Arc<Slots<Key, Outcome>> {
    background::shared(ctx, "sample histogram")
}

/// The sampling view.
#[derive(Default)]
pub struct SamplingView {
    /// The histogram drawn in the last frame and whether it was of an older key.
    pub shown: Option<(Outcome, bool)>,
    /// Where the three discs were drawn in the last frame (points, draws, pdf).
    pub disc_rects: Vec<Rect>,
    waiting: bool,
}

fn key_of(scene: &Scene<'_>, b: &SceneBrdf) -> Key {
    (
        b.revision,
        scene.incident.theta_deg.to_bits(),
        scene.incident.phi_deg.to_bits(),
    )
}

impl SamplingView {
    fn histogram(
        &mut self,
        ctx: &egui::Context,
        scene: &Scene<'_>,
        b: &SceneBrdf,
    ) -> Option<(Outcome, bool)> {
        let wi = scene.wi();
        let brdf = b.brdf.clone();
        let (shown, busy) = slots(ctx).for_frame(
            ctx,
            b.id,
            key_of(scene, b),
            scene.figure,
            Duration::from_millis(50),
            {
                let mut job = None;
                move || step(&mut job, brdf.as_ref(), wi)
            },
        );
        self.waiting = busy;
        shown
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

/// A histogram disc: each bin coloured by `value / scale` (viridis).
fn histogram_disc(painter: &egui::Painter, c: Pos2, r: f32, values: &[f64], scale: f64) {
    let mut mesh = Mesh::default();
    for t in 0..N_THETA {
        for p in 0..N_PHI {
            let v = values.get(t * N_PHI + p).copied().unwrap_or(0.0);
            let x = if scale > 0.0 { (v / scale) as f32 } else { 0.0 };
            sector(&mut mesh, c, r, t, p, colormap::viridis(x.clamp(0.0, 1.0)));
        }
    }
    painter.add(Shape::mesh(mesh));
}

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
        // Three discs in a row, titles above, the verdict below.
        let top = 48.0;
        let bottom = 52.0;
        let gap = 16.0;
        let side = ((area.width() - 4.0 * gap) / 3.0)
            .min(area.height() - top - bottom)
            .max(20.0);
        // Centre the discs and the verdict in a tall area.
        let top = top + ((area.height() - top - bottom - side) * 0.4).max(0.0);
        let row_w = 3.0 * side + 2.0 * gap;
        let left = area.left() + ((area.width() - row_w) * 0.5).max(gap);
        let discs: Vec<Rect> = (0..3)
            .map(|k| {
                Rect::from_min_size(
                    Pos2::new(left + k as f32 * (side + gap), area.top() + top),
                    Vec2::splat(side),
                )
            })
            .collect();
        self.disc_rects = discs.clone();
        let r = side * 0.5;
        let grid = super::grid_color(dark);
        let titles = [
            format!("{} of the draws", h.points.len()),
            "draws per bin".to_string(),
            "draws × ∫ pdf dω per bin".to_string(),
        ];
        // One colour scale for both histograms: the largest of either.
        let observed: Vec<f64> = h.observed.iter().map(|&o| o as f64).collect();
        let scale = observed
            .iter()
            .chain(&h.expected)
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        for (k, disc) in discs.iter().enumerate() {
            let c = disc.center();
            painter.text(
                Pos2::new(c.x, disc.top() - 4.0),
                Align2::CENTER_BOTTOM,
                &titles[k],
                small.clone(),
                text,
            );
            match k {
                0 => {
                    painter.circle_filled(c, r, super::grid_color(!dark).gamma_multiply(0.15));
                }
                1 => histogram_disc(&painter, c, r, &observed, scale),
                _ => histogram_disc(&painter, c, r, &h.expected, scale),
            }
            painter.circle_stroke(c, r, Stroke::new(1.5, text.gamma_multiply(0.7)));
            for deg in [30.0f64, 60.0] {
                let rr = (1.0 - deg.to_radians().cos()).sqrt() as f32 * r;
                painter.circle_stroke(c, rr, Stroke::new(1.0, grid));
            }
            let wi = scene.wi();
            let to_screen = |w: DVec3| {
                let p = hemisphere_to_disc(w);
                on_disc(c, r, p.x, p.y)
            };
            if k == 0 {
                let color = Color32::from_rgb(b.rgb[0], b.rgb[1], b.rgb[2]);
                for w in &h.points {
                    painter.circle_filled(to_screen(*w), 1.6, color);
                }
            }
            let mirror = DVec3::new(-wi.x, -wi.y, wi.z);
            painter.circle_stroke(
                to_screen(mirror),
                5.0,
                Stroke::new(1.5, super::mirror_color(dark)),
            );
            if wi.z > 0.0 {
                painter.circle_filled(to_screen(wi), 5.0, super::light_color(dark));
                painter.circle_stroke(to_screen(wi), 5.0, Stroke::new(1.0, Color32::BLACK));
            }
        }
        let y = discs[0].bottom() + 8.0;
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
        painter.text(
            Pos2::new(area.left() + 6.0, y + 18.0),
            Align2::LEFT_TOP,
            format!(
                "∫ pdf dω over the hemisphere {}; {} draws gave no direction above the horizon ({} expected); colour: count / {}; dot: ωi, ring: its mirror direction",
                bv_core::text::fmt_value(h.pdf_mass),
                h.failed,
                bv_core::text::fmt_value(h.expected_failed),
                bv_core::text::fmt_value(scale),
            ),
            small,
            weak,
        );
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn busy(&self) -> bool {
        self.waiting
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The view's histogram, computed in its background job's steps.
    fn compute(brdf: &dyn bv_core::Brdf, wi: DVec3) -> Outcome {
        let mut job = None;
        background::run_to_end(|| step(&mut job, brdf, wi))
    }

    /// The steps of the background job add up to the one-shot histogram of
    /// bv-core (same draws, same bins, same χ²), though the job takes
    /// `SAMPLES / WORK_PER_STEP` and more steps.
    #[test]
    fn the_stepped_histogram_is_the_one_shot_one() {
        let ct = bv_core::ModelSpec::new("cook-torrance")
            .unwrap()
            .build()
            .unwrap();
        let wi = DVec3::new(0.5, -0.2, 0.8).normalize();
        let mut job = None;
        let mut steps = 0;
        let stepped = background::run_to_end(|| {
            steps += 1;
            step(&mut job, ct.as_ref(), wi)
        });
        assert!(steps > SAMPLES / WORK_PER_STEP, "{steps} steps");
        let once =
            bv_core::analysis::sample_histogram::sample_histogram(ct.as_ref(), wi, &options())
                .unwrap();
        assert_eq!(stepped.as_ref().as_ref().unwrap(), &once);
    }

    /// Lambert's cosine sampler matches its density; a sampler that draws
    /// uniformly while claiming the cosine density is rejected.
    #[test]
    fn the_verdict_tells_a_good_sampler_from_a_bad_one() {
        let lambert = bv_core::ModelSpec::new("lambert").unwrap().build().unwrap();
        let wi = DVec3::new(0.3, 0.1, 0.95).normalize();
        let good = compute(lambert.as_ref(), wi);
        let good = good.as_ref().as_ref().unwrap();
        assert!(good.chi2.p_value >= SIGNIFICANCE, "{}", verdict(good));
        assert!(verdict(good).contains("passed"));

        #[derive(Debug)]
        struct Liar;
        impl bv_core::Brdf for Liar {
            fn id(&self) -> &'static str {
                "uniform sampler claiming the cosine density"
            }
            fn eval(&self, _wi: DVec3, _wo: DVec3) -> bv_core::Rgb {
                bv_core::Rgb::splat(std::f64::consts::FRAC_1_PI)
            }
            fn claims(&self) -> bv_core::Claims {
                bv_core::Claims {
                    reciprocal: true,
                    energy_conserving: true,
                    isotropic: true,
                }
            }
            fn sample(&self, _wi: DVec3, u: glam::DVec2) -> Option<DVec3> {
                // Uniform over the hemisphere: z uniform in (0, 1].
                let z = 1.0 - u.x;
                let s = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * PI * u.y;
                Some(DVec3::new(s * phi.cos(), s * phi.sin(), z))
            }
        }
        let bad = compute(&Liar, wi);
        let bad = bad.as_ref().as_ref().unwrap();
        assert!(bad.chi2.p_value < 1e-6, "{}", verdict(bad));
        assert!(verdict(bad).contains("FAILED"));
    }
}
