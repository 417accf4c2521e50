//! The directional albedo view: `ρhd(θi) = ∫ f cos θo dωo` (plus the weights
//! of delta lobes) against θi for every drawn BRDF, with its error band, the
//! energy-conservation line ρ = 1 and the current θi; the legend gives each
//! BRDF's bihemispherical albedo ρhh and the method behind the numbers. They
//! are `bv_core::analysis::albedo`'s, the estimators `bv check` reports:
//! deterministic Gauss–Kronrod quadrature for analytic models (band: its
//! error estimate), Monte Carlo for measured ones (band: ±3 standard errors).
//!
//! A curve costs up to [`N_THETA`] × some 10⁵ evaluations plus ρhh, so it is
//! computed on a background thread and cached process-wide by
//! (model, parameters, φi): a slider drag shows the last finished curve and a
//! progress bar, and starts no work until the pointer is released. Figures
//! (screenshots, `bv render`) compute it before drawing.

use super::BrdfColor as _;
use super::chart::{self, Band, Chart, Marker, Palette, Series};
use super::{Scene, SceneBrdf, View};
use crate::session::command::Command;
use bv_core::analysis::albedo::{AlbedoOptions, Estimate, rho_hd_auto, rho_hh_auto, theta_grid};
use bv_core::analysis::directions::stream_seed;
use bv_core::{Brdf, mean_rgb};
use eframe::egui::{self, Ui};
use egui_plot::{Corner, FilledArea, HLine, Line, LineStyle, Plot, PlotPoints, VLine};
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, LazyLock, Mutex};

/// θi samples: 0°, 2°, …, 88° (90° is left out: no light arrives there).
pub const N_THETA: usize = 45;
/// Evaluations per θi.
pub const SAMPLES: usize = 4096;
/// Evaluations for ρhh.
pub const RHH_SAMPLES: usize = 32768;
/// Seed of the estimates (fixed: the same BRDF always gives the same curve).
pub const SEED: u64 = 0x0062_7661_6c62;
/// Half-width of a Monte Carlo error band in standard errors (±3σ covers the
/// true value with about 99 % probability for these 16-replica estimates); a
/// quadrature's band is its error estimate.
pub const BAND_SIGMAS: f64 = 3.0;

/// The estimators' settings (quadrature for analytic models).
fn options(seed: u64) -> AlbedoOptions {
    AlbedoOptions {
        samples: SAMPLES,
        seed,
        ..AlbedoOptions::default()
    }
}

/// One finished curve.
#[derive(Debug, Clone, PartialEq)]
pub struct AlbedoData {
    /// θi in degrees.
    pub theta_deg: Vec<f64>,
    /// ρhd at each θi.
    pub rho: Vec<Estimate>,
    /// ρhh.
    pub rho_hh: Estimate,
}

/// The computation of an [`AlbedoData`] in steps: a few θi per step (as
/// many as there are worker threads, computed in parallel; one in a browser
/// page, where a step must fit in a slice of a frame), then ρhh.
#[derive(Debug)]
pub struct AlbedoJob {
    phi_i: f64,
    thetas: Vec<f64>,
    rho: Vec<Estimate>,
    per_step: usize,
}

impl AlbedoJob {
    /// A job for the curve at azimuth `phi_i` (radians) computing
    /// `per_step` θi per step (at least one).
    pub fn new(phi_i: f64, per_step: usize) -> Self {
        Self {
            phi_i,
            thetas: theta_grid(N_THETA),
            rho: Vec::with_capacity(N_THETA),
            per_step: per_step.max(1),
        }
    }

    /// Steps finished ([`STEPS`] in all).
    pub fn done(&self) -> usize {
        self.rho.len()
    }

    /// Computes the next θi of `brdf` (or, once all are done, ρhh) and
    /// returns the curve once it is complete. `brdf` must be the same at
    /// every step.
    pub fn step(&mut self, brdf: &dyn Brdf) -> Option<AlbedoData> {
        let k0 = self.rho.len();
        if k0 < self.thetas.len() {
            let k1 = (k0 + self.per_step).min(self.thetas.len());
            let phi_i = self.phi_i;
            let part: Vec<Estimate> = self.thetas[k0..k1]
                .par_iter()
                .enumerate()
                .map(|(j, &t)| {
                    rho_hd_auto(brdf, t, phi_i, &options(stream_seed(SEED, (k0 + j) as u64)))
                })
                .collect();
            self.rho.extend(part);
            return None;
        }
        let rho_hh = rho_hh_auto(brdf, RHH_SAMPLES, &options(SEED));
        Some(AlbedoData {
            theta_deg: self.thetas.iter().map(|t| t.to_degrees()).collect(),
            rho: std::mem::take(&mut self.rho),
            rho_hh,
        })
    }
}

impl AlbedoData {
    /// Computes the curve of `brdf` for light at azimuth `phi_i` (radians),
    /// counting finished steps in `progress` ([`STEPS`] in all); `None` when
    /// `cancel` was raised.
    pub fn compute(
        brdf: &dyn Brdf,
        phi_i: f64,
        progress: &AtomicUsize,
        cancel: &AtomicBool,
    ) -> Option<Self> {
        // Every θi in one parallel step: the one-shot computation.
        let mut job = AlbedoJob::new(phi_i, N_THETA);
        loop {
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            let d = job.step(brdf);
            progress.store(job.done() + usize::from(d.is_some()), Ordering::Relaxed);
            if d.is_some() {
                return d;
            }
        }
    }

    /// The plotted value (channel mean) and its band half-width at sample `k`.
    pub fn mean_and_band(&self, k: usize) -> (f64, f64) {
        let e = &self.rho[k];
        (mean_rgb(e.value), mean_rgb(e.allowance(BAND_SIGMAS)))
    }

    /// Whether some channel exceeds 1 by more than its error band somewhere.
    pub fn exceeds_one(&self) -> bool {
        self.rho.iter().any(|e| {
            let band = e.allowance(BAND_SIGMAS);
            (0..3).any(|c| e.value[c] - band[c] > 1.0 + 1e-9)
        })
    }

    /// How the numbers were computed, for the legend: `quadrature` or
    /// `monte carlo`.
    pub fn method(&self) -> &'static str {
        self.rho.first().map_or("quadrature", |e| e.method.name())
    }
}

/// Steps of a computation (one per θi, one for ρhh).
pub const STEPS: usize = N_THETA + 1;

/// Cache key: the spec as JSON and φi.
type Key = (String, u64);

struct Job {
    progress: Arc<AtomicUsize>,
    cancel: Arc<AtomicBool>,
}

#[derive(Default)]
struct Cache {
    done: HashMap<Key, Arc<AlbedoData>>,
    running: HashMap<Key, Job>,
}

/// Finished curves and running jobs of the whole process (shared by the
/// window's view and the views of offscreen figures).
static CACHE: LazyLock<Mutex<Cache>> = LazyLock::new(Mutex::default);

/// Most finished curves kept.
const CACHE_LIMIT: usize = 64;

fn key_of(scene: &Scene<'_>, b: &SceneBrdf) -> Option<Key> {
    let e = scene.state.entry(b.id)?;
    Some((
        e.spec.to_json().to_string(),
        scene.incident.phi_deg.to_bits(),
    ))
}

fn cached(key: &Key) -> Option<Arc<AlbedoData>> {
    CACHE.lock().ok()?.done.get(key).cloned()
}

fn store(key: Key, data: Arc<AlbedoData>) {
    if let Ok(mut c) = CACHE.lock() {
        if c.done.len() >= CACHE_LIMIT {
            c.done.clear();
        }
        c.done.insert(key.clone(), data);
        c.running.remove(&key);
    }
}

/// Starts computing `key` in the background unless it is running; returns its
/// progress counter.
fn start(key: &Key, brdf: Arc<dyn Brdf>, phi_i: f64, ctx: &egui::Context) -> Arc<AtomicUsize> {
    let Ok(mut c) = CACHE.lock() else {
        return Arc::new(AtomicUsize::new(0));
    };
    if let Some(j) = c.running.get(key) {
        return j.progress.clone();
    }
    let progress = Arc::new(AtomicUsize::new(0));
    let cancel = Arc::new(AtomicBool::new(false));
    c.running.insert(
        key.clone(),
        Job {
            progress: progress.clone(),
            cancel: cancel.clone(),
        },
    );
    let (p, k, ctx) = (progress.clone(), key.clone(), ctx.clone());
    let mut job = AlbedoJob::new(phi_i, rayon::current_num_threads());
    let spawned = crate::session::platform::spawn_steps("bv albedo", move || {
        if cancel.load(Ordering::Relaxed) {
            if let Ok(mut c) = CACHE.lock() {
                c.running.remove(&k);
            }
            ctx.request_repaint();
            return true;
        }
        let d = job.step(brdf.as_ref());
        p.store(job.done() + usize::from(d.is_some()), Ordering::Relaxed);
        match d {
            Some(d) => {
                store(k.clone(), Arc::new(d));
                ctx.request_repaint();
                true
            }
            None => false,
        }
    });
    if spawned.is_err() {
        c.running.remove(key);
    }
    progress
}

/// Cancels the running jobs of `keys`.
fn cancel(keys: &[Key]) {
    if let Ok(c) = CACHE.lock() {
        for k in keys {
            if let Some(j) = c.running.get(k) {
                j.cancel.store(true, Ordering::Relaxed);
            }
        }
    }
}

/// The curve of `b`, computed now (blocking) if it is not cached.
pub fn curve_now(scene: &Scene<'_>, b: &SceneBrdf) -> Option<Arc<AlbedoData>> {
    let key = key_of(scene, b)?;
    if let Some(d) = cached(&key) {
        return Some(d);
    }
    let d = Arc::new(AlbedoData::compute(
        b.brdf.as_ref(),
        scene.incident.phi_deg.to_radians(),
        &AtomicUsize::new(0),
        &AtomicBool::new(false),
    )?);
    store(key, d.clone());
    Some(d)
}

/// The albedo view.
#[derive(Default)]
pub struct AlbedoView {
    /// Last finished curve per BRDF id (shown, marked stale, while its new
    /// curve is computed).
    latest: HashMap<u64, (Key, Arc<AlbedoData>)>,
    /// The key each BRDF is being computed for.
    wanted: HashMap<u64, Key>,
    /// Progress of the running computations, (done, total) steps, in the last
    /// frame (for tests and the progress bar).
    pub progress: Option<(usize, usize)>,
}

/// One BRDF's curve in a frame.
struct Shown {
    brdf: SceneBrdf,
    data: Arc<AlbedoData>,
    stale: bool,
}

impl AlbedoView {
    /// Brings the curves up to date and returns what to draw.
    fn update(&mut self, scene: &Scene<'_>, ctx: Option<&egui::Context>) -> Vec<Shown> {
        let mut shown = Vec::new();
        let mut done = 0;
        let mut total = 0;
        for b in &scene.brdfs {
            let Some(key) = key_of(scene, b) else {
                continue;
            };
            if let Some(d) = cached(&key) {
                self.latest.insert(b.id, (key.clone(), d));
            } else if scene.figure || ctx.is_none() {
                if let Some(d) = curve_now(scene, b) {
                    self.latest.insert(b.id, (key.clone(), d));
                }
            } else if let Some(ctx) = ctx {
                if !scene.interacting {
                    // A new key for this BRDF: the old job is of no more use.
                    if let Some(old) = self.wanted.get(&b.id)
                        && *old != key
                    {
                        cancel(std::slice::from_ref(old));
                    }
                    self.wanted.insert(b.id, key.clone());
                    let p = start(
                        &key,
                        b.brdf.clone(),
                        scene.incident.phi_deg.to_radians(),
                        ctx,
                    );
                    done += p.load(Ordering::Relaxed).min(STEPS);
                    total += STEPS;
                } else {
                    total += STEPS;
                }
            }
            if let Some((k, d)) = self.latest.get(&b.id) {
                shown.push(Shown {
                    brdf: b.clone(),
                    data: d.clone(),
                    stale: *k != key,
                });
            }
        }
        self.latest
            .retain(|id, _| scene.brdfs.iter().any(|b| b.id == *id));
        self.progress = (total > 0).then_some((done, total));
        if total > 0
            && let Some(ctx) = ctx
        {
            ctx.request_repaint_after(std::time::Duration::from_millis(100));
        }
        shown
    }
}

fn legend_label(s: &Shown) -> String {
    let hh = &s.data.rho_hh;
    let err = mean_rgb(hh.allowance(BAND_SIGMAS));
    // Four decimals, or the error's own first digit when it is coarser.
    let err_text = if err < 5e-5 {
        format!("{:.0e}", err.max(1e-12))
    } else {
        format!("{err:.4}")
    };
    // The method, briefly: the band is the quadrature's error estimate, or
    // ±3 standard errors of Monte Carlo.
    let method = match s.data.method() {
        "quadrature" => "quad.".to_string(),
        _ => format!("MC ±{BAND_SIGMAS}σ"),
    };
    let mut l = format!(
        "{}: ρhh = {:.4} ± {err_text} {method}",
        s.brdf.label,
        mean_rgb(hh.value),
    );
    if s.data.exceeds_one() {
        l.push_str(" (ρhd > 1!)");
    }
    if s.stale {
        l.push_str(" (updating)");
    }
    l
}

fn y_top(shown: &[Shown]) -> f64 {
    let m = shown
        .iter()
        .flat_map(|s| (0..s.data.rho.len()).map(|k| s.data.mean_and_band(k)))
        .map(|(v, b)| v + b)
        .fold(0.0, f64::max);
    (m * 1.08).max(1.1)
}

/// The plot corner whose legend box covers the fewest curve points, given
/// the plot's size in points (the box's extent is estimated from the labels:
/// about 6.5 points per character plus the swatch, 18 points per line), in
/// the order of preference bottom right, top right, bottom left, top left.
fn legend_corner(shown: &[Shown], top: f64, size: egui::Vec2) -> Corner {
    let chars = shown
        .iter()
        .map(|s| legend_label(s).chars().count())
        .max()
        .unwrap_or(0);
    let w = ((chars as f32 * 6.5 + 30.0) / size.x.max(1.0)).min(1.0) as f64 * 90.0;
    let h = ((shown.len() as f32 * 18.0 + 12.0) / size.y.max(1.0)).min(1.0) as f64 * top;
    let boxes = [
        (Corner::RightBottom, 90.0 - w, 90.0, 0.0, h),
        (Corner::RightTop, 90.0 - w, 90.0, top - h, top),
        (Corner::LeftBottom, 0.0, w, 0.0, h),
        (Corner::LeftTop, 0.0, w, top - h, top),
    ];
    let covered = |(x0, x1, y0, y1): (f64, f64, f64, f64)| {
        shown
            .iter()
            .flat_map(|s| {
                (0..s.data.rho.len()).map(move |k| (s.data.theta_deg[k], s.data.mean_and_band(k).0))
            })
            .filter(|&(x, y)| (x0..=x1).contains(&x) && (y0..=y1).contains(&y))
            .count()
    };
    boxes
        .iter()
        .min_by_key(|b| covered((b.1, b.2, b.3, b.4)))
        .map_or(Corner::RightBottom, |b| b.0)
}

const Y_LABEL: &str = "ρhd (mean of r, g, b)";
const X_LABEL: &str = "θi (°)";

impl View for AlbedoView {
    fn ui(&mut self, ui: &mut Ui, scene: &Scene<'_>, _out: &mut Vec<Command>) {
        let dark = ui.visuals().dark_mode;
        let shown = self.update(scene, (!scene.figure).then(|| ui.ctx()));
        if let Some((done, total)) = self.progress
            && !scene.figure
        {
            ui.add(
                egui::ProgressBar::new(done as f32 / total.max(1) as f32)
                    .desired_height(12.0)
                    .text(format!("computing ρhd: {done}/{total} steps")),
            );
        }
        let top = y_top(&shown);
        let size = ui.available_size();
        let light = super::light_color(dark);
        let plot = super::with_legend(
            super::curves::with_linear_y(Plot::new(super::view_id("albedo"))),
            size,
            shown.len(),
            legend_corner(&shown, top, size),
        )
        .width(size.x.max(50.0))
        .height(size.y.max(50.0))
        .x_axis_label(X_LABEL)
        .y_axis_label(Y_LABEL)
        .y_axis_min_width(36.0)
        .include_x(0.0)
        .include_x(90.0)
        .include_y(0.0)
        .include_y(top)
        .allow_scroll(false)
        .x_grid_spacer(egui_plot::uniform_grid_spacer(|_| [5.0, 15.0, 45.0]));
        let theta_i = scene.incident.theta_deg;
        plot.show(ui, |pui| {
            pui.hline(
                HLine::new("", 1.0)
                    .color(super::mirror_color(dark))
                    .style(LineStyle::Dashed { length: 6.0 })
                    .width(scene.stroke(1.2))
                    .allow_hover(false),
            );
            pui.vline(
                VLine::new("", theta_i)
                    .color(light)
                    .width(scene.stroke(1.5))
                    .allow_hover(false),
            );
            for s in &shown {
                let n = s.data.rho.len();
                let (mut lo, mut hi) = (Vec::with_capacity(n), Vec::with_capacity(n));
                for k in 0..n {
                    let (v, b) = s.data.mean_and_band(k);
                    lo.push(v - b);
                    hi.push(v + b);
                }
                pui.add(
                    FilledArea::new("", &s.data.theta_deg, &lo, &hi)
                        .fill_color(s.brdf.color().gamma_multiply(0.3)),
                );
                let pts: Vec<[f64; 2]> = (0..n)
                    .map(|k| [s.data.theta_deg[k], s.data.mean_and_band(k).0])
                    .collect();
                let mut line = Line::new(legend_label(s), PlotPoints::from(pts))
                    .color(s.brdf.color())
                    .width(scene.stroke(if s.brdf.selected { 2.5 } else { 1.8 }));
                if s.stale {
                    line = line.style(LineStyle::Dashed { length: 8.0 });
                }
                pui.line(line);
            }
        });
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn svg(&mut self, scene: &Scene<'_>, size: [f32; 2], dark: bool) -> Option<String> {
        let shown = self.update(scene, None);
        let top = y_top(&shown);
        let mut c = Chart {
            x_label: X_LABEL.into(),
            y_label: Y_LABEL.into(),
            x_range: (0.0, 90.0),
            y_range: (0.0, top),
            x_ticks: chart::angle_ticks(0.0, 90.0),
            y_ticks: chart::labelled(chart::nice_ticks(0.0, top, 8)),
            ..Default::default()
        };
        c.hlines.push(Marker {
            at: 1.0,
            color: super::mirror_color(dark),
            dashed: true,
            label: "ρ = 1".into(),
        });
        c.vlines.push(Marker {
            at: scene.incident.theta_deg,
            color: super::light_color(dark),
            dashed: false,
            label: "θi".into(),
        });
        for s in &shown {
            let n = s.data.rho.len();
            let mb: Vec<(f64, f64)> = (0..n).map(|k| s.data.mean_and_band(k)).collect();
            c.bands.push(Band {
                color: s.brdf.color().gamma_multiply(0.3),
                xs: s.data.theta_deg.clone(),
                lo: mb.iter().map(|(v, b)| v - b).collect(),
                hi: mb.iter().map(|(v, b)| v + b).collect(),
            });
            c.series.push(Series {
                label: legend_label(s),
                color: s.brdf.color(),
                points: (0..n).map(|k| [s.data.theta_deg[k], mb[k].0]).collect(),
                width: if s.brdf.selected { 2.5 } else { 1.8 },
                dash: None,
            });
        }
        Some(c.to_svg(size, Palette::new(dark, scene.transparent)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lambert_albedo_is_flat_at_its_albedo() {
        // ρhd of a Lambertian surface is its albedo at every θi (∫ a/π cos dω = a).
        let b = bv_core::ModelSpec::from_json("lambert", &serde_json::json!({"albedo": 0.6}))
            .unwrap()
            .build()
            .unwrap();
        let d = AlbedoData::compute(
            b.as_ref(),
            0.0,
            &AtomicUsize::new(0),
            &AtomicBool::new(false),
        )
        .unwrap();
        assert_eq!(d.rho.len(), N_THETA);
        for k in 0..N_THETA {
            let (v, band) = d.mean_and_band(k);
            assert!(
                (v - 0.6).abs() <= band.max(1e-9) + 1e-3,
                "{k}: {v} ± {band}"
            );
        }
        assert!((mean_rgb(d.rho_hh.value) - 0.6).abs() < 0.01);
        assert!(!d.exceeds_one());
    }

    /// A job of one θi per step (as in a browser page) gives the curve that
    /// bv-core's estimators give called one θi at a time here, and so the
    /// one-shot computation's.
    #[test]
    fn the_curve_in_steps_is_the_one_shot_curve() {
        let b = bv_core::ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"alpha": 0.3, "kd": 0.2}),
        )
        .unwrap()
        .build()
        .unwrap();
        let phi = 0.4;
        let mut job = AlbedoJob::new(phi, 1);
        let mut steps = 0;
        let stepped = loop {
            steps += 1;
            if let Some(d) = job.step(b.as_ref()) {
                break d;
            }
        };
        assert_eq!(steps, STEPS);
        let thetas = theta_grid(N_THETA);
        let by_hand: Vec<Estimate> = thetas
            .iter()
            .enumerate()
            .map(|(k, &t)| rho_hd_auto(b.as_ref(), t, phi, &options(stream_seed(SEED, k as u64))))
            .collect();
        assert_eq!(stepped.rho, by_hand);
        assert_eq!(
            stepped.rho_hh,
            rho_hh_auto(b.as_ref(), RHH_SAMPLES, &options(SEED))
        );
        let once = AlbedoData::compute(
            b.as_ref(),
            phi,
            &AtomicUsize::new(0),
            &AtomicBool::new(false),
        )
        .unwrap();
        assert_eq!(stepped, once);
    }

    #[test]
    fn cancelled_jobs_give_nothing() {
        let b = bv_core::ModelSpec::new("lambert").unwrap().build().unwrap();
        assert!(
            AlbedoData::compute(
                b.as_ref(),
                0.0,
                &AtomicUsize::new(0),
                &AtomicBool::new(true)
            )
            .is_none()
        );
    }
}
