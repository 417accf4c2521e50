//! The viewer window: an eframe app on wgpu around [`Viewer`].
//!
//! - The state, commands and evaluators are the session's
//!   ([`crate::session`]); [`panel`] and [`measured_ui`]: the left panel;
//!   [`viewer`]: the whole UI; [`shortcuts`]: the keyboard shortcuts and their
//!   help; [`screenshot`]: the export dialog; the views live in
//!   [`crate::views`].
//! - [`run`] opens the window. `--bench-frames N` drives a scripted slider
//!   sweep and prints frame-time percentiles; `--screenshot PATH` saves the
//!   window once it has drawn and exits.

pub mod badges;
pub mod fit_ui;
pub mod measured_ui;
pub mod panel;
pub mod presentation;
pub mod presets_ui;
pub mod screenshot;
pub mod shortcuts;
pub mod viewer;
#[cfg(target_arch = "wasm32")]
pub mod web;

pub use viewer::Viewer;

/// The window's functions the command line calls (`bv` with no sub-command,
/// `bv render --view window`).
pub const SHELL: crate::cli::Shell = crate::cli::Shell {
    run_viewer: run,
    window: viewer::figure_window,
    slide: viewer::slide_window,
};

use crate::cli::viewer_args::ViewerArgs;
#[cfg(not(target_arch = "wasm32"))]
use crate::cli::viewer_args::parse_size;
#[cfg(not(target_arch = "wasm32"))]
use crate::session::AppState;
#[cfg(not(target_arch = "wasm32"))]
use crate::session::scene_file as scene;
use crate::session::{Command, state};

#[cfg(not(target_arch = "wasm32"))]
use crate::gpu::errors::no_gpu_message;
use crate::session::platform::Instant;
use anyhow::{Context as _, bail};
use bv_core::{ParamKind, ParamValue};
use eframe::egui;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// Key of the saved state in eframe's storage.
pub const STORAGE_KEY: &str = "bv-state";

/// The state the window starts with.
#[cfg(not(target_arch = "wasm32"))]
fn initial_state(args: &ViewerArgs, saved: Option<&str>) -> anyhow::Result<AppState> {
    let mut state = if let Some(path) = &args.scene {
        let loaded = scene::load(path).with_context(|| format!("opening {}", path.display()))?;
        for w in &loaded.warnings {
            crate::session::console::eprint(&format!("bv: {}: {w}\n", path.display()));
        }
        loaded.state
    } else if args.fresh {
        AppState::first_run()
    } else {
        saved
            .and_then(AppState::from_json_str)
            .unwrap_or_else(AppState::first_run)
    };
    if !args.models.is_empty() || !args.presets.is_empty() {
        // Check all ids first, so a typo is an error rather than a half list.
        for m in &args.models {
            bv_core::find(m)?;
        }
        let presets = args
            .presets
            .iter()
            .map(|p| bv_core::presets::find(p).with_context(|| format!("--preset {p}")))
            .collect::<anyhow::Result<Vec<_>>>()?;
        let n = args.models.len() + presets.len();
        if n > crate::session::state::MAX_BRDFS {
            anyhow::bail!(
                "{n} BRDFs (--model and --preset); a scene holds at most {}",
                crate::session::state::MAX_BRDFS
            );
        }
        state.brdfs.clear();
        state.solo = None;
        for m in &args.models {
            state.add(bv_core::ModelSpec::new(m)?);
        }
        for p in presets {
            state.add_named(p.spec.clone(), Some(p.name.clone()));
        }
        if let Some(first) = state.brdfs.first() {
            state.selected = Some(first.id);
        }
    }
    if args.light {
        state.theme = state::Theme::Light;
    }
    Ok(state.sanitised())
}

/// The viewer window of a desktop build; a page starts the viewer from
/// [`web`] instead, and has no command line to ask for a window.
#[cfg(target_arch = "wasm32")]
pub fn run(args: &ViewerArgs) -> anyhow::Result<()> {
    let _ = args;
    bail!("in a browser the viewer starts with the page")
}

/// Opens the viewer window and returns when it is closed.
#[cfg(not(target_arch = "wasm32"))]
pub fn run(args: &ViewerArgs) -> anyhow::Result<()> {
    // Validate `--model` before a window opens (and before the size, which
    // the smoke script relies on to probe the catalogue).
    for m in &args.models {
        bv_core::find(m)?;
    }
    for p in &args.presets {
        bv_core::presets::find(p).with_context(|| format!("--preset {p}"))?;
    }
    if let Some(path) = &args.scene {
        // Refuse a bad scene before a window opens.
        scene::load(path).with_context(|| format!("opening {}", path.display()))?;
    }
    if let Some(path) = &args.deck {
        let loaded = crate::session::deck::load(path, scene::Builds::Warn)
            .with_context(|| format!("opening the deck {}", path.display()))?;
        for w in &loaded.warnings {
            crate::session::console::eprint(&format!("bv: {}: {w}\n", path.display()));
        }
    }
    let size = match &args.size {
        Some(s) => parse_size(s)?,
        None => [1280.0, 800.0],
    };
    let scripted = args.bench_frames.is_some() || args.screenshot.is_some();
    // Scripted runs (benchmark, screenshot) start from the saved session unless
    // `--fresh`, but never overwrite it.
    // A lecture's deck is not the user's session either.
    let persist = !(args.fresh || scripted || args.deck.is_some());
    let load_saved = !args.fresh;

    let mut options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("bv — BRDF viewer")
            .with_app_id("bv")
            .with_inner_size(size)
            .with_min_inner_size([720.0, 480.0]),
        persist_window: persist,
        // egui's dithering costs a noise function per pixel; on a software
        // renderer that is a noticeable share of the frame, and the UI has no
        // gradients that band without it.
        dithering: false,
        ..Default::default()
    };
    if let eframe::egui_wgpu::WgpuSetup::CreateNew(setup) = &mut options.wgpu_options.wgpu_setup {
        // egui's device, plus the feature bv's disk pipeline cache needs where
        // the adapter has it.
        let base = setup.device_descriptor.clone();
        setup.device_descriptor = Arc::new(move |adapter| {
            let mut desc = base(adapter);
            desc.required_features |= adapter.features() & crate::gpu::pipeline_cache::FEATURE;
            desc
        });
    }
    if args.bench_frames.is_some() {
        // Measure what drawing costs, not the display's refresh rate.
        options.wgpu_options.surface.present_mode = eframe::wgpu::PresentMode::AutoNoVsync;
    }

    // The lobe's shaders need no device: composed on another core while
    // eframe opens the window and the device.
    crate::gpu::lobe::compose_in_background();
    let outcome: Arc<Mutex<Option<anyhow::Result<()>>>> = Arc::new(Mutex::new(None));
    let args2 = args.clone();
    let outcome2 = outcome.clone();
    let result = eframe::run_native(
        "bv",
        options,
        Box::new(move |cc| {
            if let Some(rs) = &cc.wgpu_render_state {
                let mut renderer = rs.renderer.write();
                crate::views::install_gpu(
                    &mut renderer.callback_resources,
                    &rs.device,
                    &rs.queue,
                    Some(&rs.adapter),
                    rs.target_format,
                );
                drop(renderer);
                crate::views::install_context(&cc.egui_ctx, rs);
            }
            let saved = if load_saved {
                cc.storage.and_then(|s| s.get_string(STORAGE_KEY))
            } else {
                None
            };
            let state = initial_state(&args2, saved.as_deref())
                .map_err(|e| -> Box<dyn std::error::Error + Send + Sync> { e.into() })?;
            let adapter = cc.wgpu_render_state.as_ref().map_or_else(
                || "no wgpu adapter".to_string(),
                |rs| {
                    let i = rs.adapter.get_info();
                    format!("{} ({:?}, {:?})", i.name, i.backend, i.device_type)
                },
            );
            let mut viewer = Viewer::new(state);
            viewer.fit.open = args2.fit;
            for f in &args2.open {
                viewer.push(Command::OpenFile {
                    path: f.display().to_string(),
                    into: None,
                });
            }
            if let Some(rs) = &cc.wgpu_render_state {
                viewer.export.set_gpu(rs.clone());
            }
            viewer.export.scene_path = args2.scene.clone();
            if let Some(path) = &args2.deck {
                viewer.open_deck(path).map_err(
                    |e| -> Box<dyn std::error::Error + Send + Sync> {
                        format!("opening the deck {}: {e}", path.display()).into()
                    },
                )?;
                if args2.light {
                    viewer.push(Command::SetTheme(state::Theme::Light));
                }
            }
            let mut app = BvApp {
                viewer,
                persist,
                bench: args2.bench_frames.map(|n| Bench::new(n, adapter)),
                shot: args2.screenshot.clone().map(Shot::new),
                resize: args2.size.is_some().then(|| egui::Vec2::from(size)),
                outcome: outcome2,
            };
            app.viewer.panels_on_clear = true;
            if app.bench.is_some()
                && let Ok(v) = std::env::var("BV_BENCH_MAXIMISE")
            {
                app.viewer.push(Command::Maximise(Some(v)));
            }
            Ok(Box::new(app))
        }),
    );
    match result {
        Ok(()) => {}
        Err(eframe::Error::Wgpu(e)) => bail!(no_gpu_message(&e.to_string())),
        Err(e) => {
            let text = e.to_string();
            if text.contains("adapter") {
                bail!(no_gpu_message(&text));
            }
            bail!(
                "could not open the viewer window: {text}\n\
                 (no display? set DISPLAY or WAYLAND_DISPLAY, or run under `xvfb-run -a bv …`)"
            );
        }
    }
    let outcome = outcome.lock().map(|mut o| o.take()).unwrap_or(None);
    outcome.unwrap_or(Ok(()))
}

/// The eframe app: the viewer plus the scripted drivers.
struct BvApp {
    viewer: Viewer,
    persist: bool,
    bench: Option<Bench>,
    shot: Option<Shot>,
    /// The size `--size` asked for, sent to the window on the first frame:
    /// eframe restores a saved window's size over the one the viewport
    /// builder asks for, whatever `persist_window` says (eframe 0.37,
    /// `load_window_settings`), so `--size` alone lost to the last session.
    resize: Option<egui::Vec2>,
    outcome: Arc<Mutex<Option<anyhow::Result<()>>>>,
}

impl BvApp {
    fn finish(&self, ctx: &egui::Context, r: anyhow::Result<()>) {
        if let Ok(mut o) = self.outcome.lock() {
            *o = Some(r);
        }
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
    }
}

impl eframe::App for BvApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        let t0 = Instant::now();
        if let Some(size) = self.resize.take() {
            ctx.send_viewport_cmd(egui::ViewportCommand::InnerSize(size));
        }
        if let Some(b) = &mut self.bench {
            // The busy views are asked for only while the wait lasts, not on
            // every timed frame of the sweep.
            let settling = b.settled_after.is_none() && b.settling(&self.viewer.busy_views());
            // At rest while the views settle, as a window is before a user
            // takes a slider; dragging from the sweep's first frame. (Forced
            // from the start, the environment view took one sample a frame
            // and never finished on a CPU rasteriser: the wait ran out.)
            self.viewer.force_interacting = !settling;
            if settling {
                // Let progressive views finish (as they have when a user
                // starts dragging) before the sweep is timed.
                self.viewer.ui(ui);
                ctx.request_repaint();
                return;
            }
            b.drive(&mut self.viewer);
        }
        self.viewer.ui(ui);
        let ui_time = t0.elapsed();
        if let Some(b) = &mut self.bench {
            b.record(t0, ui_time);
            ctx.request_repaint();
            if b.done() && !b.reported {
                b.reported = true;
                let printed = crate::session::console::print(&format!("{}\n", b.report()));
                self.finish(&ctx, printed);
            }
        }
        if let Some(s) = &mut self.shot {
            ctx.request_repaint();
            // Rendered views still at work (shaders compiling, environment
            // sampling) are waited for, for at most MAX_BUSY.
            let busy = self.viewer.views_busy();
            match s.tick(&ctx, busy) {
                ShotState::Waiting => {}
                ShotState::Done(r) => {
                    self.shot = None;
                    self.finish(&ctx, r);
                }
            }
        }
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        if self.persist {
            storage.set_string(STORAGE_KEY, self.viewer.state().to_json_string());
        }
    }

    fn persist_egui_memory(&self) -> bool {
        self.persist
    }

    /// The panels' colour: the panels are drawn without a fill of their own
    /// on it (see `Viewer::panels_on_clear`).
    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        visuals.panel_fill.to_normalized_gamma_f32()
    }

    fn auto_save_interval(&self) -> Duration {
        Duration::from_secs(10)
    }
}

/// The scripted slider sweep of `--bench-frames`.
struct Bench {
    frames: usize,
    warmup: usize,
    k: usize,
    last: Option<Instant>,
    intervals: Vec<f64>,
    ui_times: Vec<f64>,
    what: String,
    adapter: String,
    reported: bool,
    /// When the first frame asked whether the views are still busy.
    settle_start: Option<Instant>,
    /// Frames in a row whose views were all idle.
    idle_frames: usize,
    /// How long the views took to settle, once they have.
    settled_after: Option<Duration>,
    /// The views still at work when [`Self::MAX_SETTLE`] ran out (the
    /// sweep's frames then include their work: the report names them).
    unsettled: Vec<&'static str>,
}

impl Bench {
    #[cfg(not(target_arch = "wasm32"))]
    fn new(frames: usize, adapter: String) -> Self {
        Self {
            adapter,
            reported: false,
            frames: frames.max(1),
            warmup: 10,
            k: 0,
            last: None,
            intervals: Vec::new(),
            ui_times: Vec::new(),
            what: String::new(),
            settle_start: None,
            idle_frames: 0,
            settled_after: None,
            unsettled: Vec::new(),
        }
    }

    /// Longest wait for busy views before the sweep starts regardless.
    const MAX_SETTLE: Duration = Duration::from_secs(60);
    /// Frames in a row with every view idle that make the window settled (a
    /// view starts its work, a renderer build or an accumulation, only once
    /// it has drawn).
    const IDLE_FRAMES: usize = 5;

    /// Whether the sweep should still wait: views at work (the environment
    /// accumulating its samples, a renderer compiling) finish first, for at
    /// most [`Self::MAX_SETTLE`]. Without this the first frames time the
    /// environment view converging, which is no part of a slider drag.
    fn settling(&mut self, busy: &[&'static str]) -> bool {
        if self.settled_after.is_some() {
            return false;
        }
        let start = *self.settle_start.get_or_insert_with(Instant::now);
        self.idle_frames = if busy.is_empty() {
            self.idle_frames + 1
        } else {
            0
        };
        if self.idle_frames < Self::IDLE_FRAMES && start.elapsed() < Self::MAX_SETTLE {
            return true;
        }
        self.settled_after = Some(start.elapsed());
        if self.idle_frames < Self::IDLE_FRAMES {
            self.unsettled = busy.to_vec();
        }
        false
    }

    /// Moves a float parameter of the selected BRDF one step along a
    /// triangle wave across its slider span (log-spaced for log parameters), as
    /// a user's slider drag would; with no float parameter, sweeps θi.
    fn drive(&mut self, viewer: &mut Viewer) {
        let phase = (self.k % 120) as f64 / 60.0;
        let u = if phase <= 1.0 { phase } else { 2.0 - phase };
        let state = viewer.state();
        let target = state.selected_entry().and_then(|e| {
            let info = e.spec.model();
            // A log-scaled float first (roughness, exponent: what a lecturer
            // drags), else the first float.
            let floats = || {
                info.params.iter().filter_map(|d| match d.kind {
                    ParamKind::Float(s) => Some((e.id, d.id, s)),
                    _ => None,
                })
            };
            floats().find(|(_, _, s)| s.log).or_else(|| floats().next())
        });
        let cmd = match target {
            Some((id, param, s)) => {
                let lo = s.slider_min.max(s.min);
                let hi = s.slider_max.min(s.max);
                let x = if s.log {
                    let lo = if lo > 0.0 { lo } else { hi * 1e-3 };
                    lo * (hi / lo).powf(u)
                } else {
                    lo + (hi - lo) * u
                };
                self.what = format!(
                    "{}.{param}",
                    state.entry(id).map(|e| e.spec.id()).unwrap_or("?")
                );
                Command::SetParam {
                    brdf: id,
                    param: param.to_string(),
                    value: ParamValue::Float(x),
                }
            }
            None => {
                self.what = "θi".to_string();
                Command::SetIncident(state::Incident {
                    theta_deg: 85.0 * u,
                    ..state.incident
                })
            }
        };
        viewer.push(cmd);
        self.k += 1;
    }

    fn record(&mut self, start: Instant, ui_time: Duration) {
        if self.k > self.warmup {
            if let Some(last) = self.last {
                self.intervals.push((start - last).as_secs_f64() * 1e3);
            }
            self.ui_times.push(ui_time.as_secs_f64() * 1e3);
        }
        self.last = Some(start);
    }

    fn done(&self) -> bool {
        self.intervals.len() >= self.frames
    }

    fn report(&self) -> String {
        let still = if self.unsettled.is_empty() {
            String::new()
        } else {
            format!("; still at work: {}", self.unsettled.join(", "))
        };
        format!(
            "bench: {} frames sweeping {} on {} (after {:.1} s of views settling{still}): frame time p50 {:.2} ms, \
             p95 {:.2} ms ({:.1} fps median); app ui (incl. mesh rebuild) p50 {:.2} ms, p95 {:.2} ms",
            self.intervals.len(),
            self.what,
            self.adapter,
            self.settled_after.unwrap_or_default().as_secs_f64(),
            percentile(&self.intervals, 0.5),
            percentile(&self.intervals, 0.95),
            1e3 / percentile(&self.intervals, 0.5).max(1e-9),
            percentile(&self.ui_times, 0.5),
            percentile(&self.ui_times, 0.95),
        )
    }
}

/// The `q`-quantile (nearest rank) of `xs`; 0 for an empty list.
pub fn percentile(xs: &[f64], q: f64) -> f64 {
    if xs.is_empty() {
        return 0.0;
    }
    let mut v: Vec<f64> = xs.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let rank = (q.clamp(0.0, 1.0) * v.len() as f64).ceil() as usize;
    v[rank.clamp(1, v.len()) - 1]
}

enum ShotState {
    Waiting,
    Done(anyhow::Result<()>),
}

/// The `--screenshot` driver: waits until the meshes are final, asks eframe
/// for a screenshot and saves it.
struct Shot {
    path: PathBuf,
    frames: usize,
    started: Instant,
    requested: bool,
    image: Arc<Mutex<Option<Arc<egui::ColorImage>>>>,
}

impl Shot {
    /// Frames drawn before the screenshot (layout settles, meshes at full
    /// resolution).
    const SETTLE_FRAMES: usize = 6;
    /// Longest wait for views that are still working (the environment view
    /// converging on a software renderer).
    const MAX_BUSY: Duration = Duration::from_secs(40);

    #[cfg(not(target_arch = "wasm32"))]
    fn new(path: PathBuf) -> Self {
        Self {
            path,
            frames: 0,
            started: Instant::now(),
            requested: false,
            image: Arc::new(Mutex::new(None)),
        }
    }

    fn tick(&mut self, ctx: &egui::Context, busy: bool) -> ShotState {
        self.frames += 1;
        let settled = !busy || self.started.elapsed() > Self::MAX_BUSY;
        if !self.requested && self.frames >= Self::SETTLE_FRAMES && settled {
            let slot = self.image.clone();
            let ctx2 = ctx.clone();
            ctx.request_screenshot(move |img| {
                if let Ok(mut s) = slot.lock() {
                    *s = Some(img);
                }
                ctx2.request_repaint();
            });
            self.requested = true;
        }
        let img = self.image.lock().ok().and_then(|mut s| s.take());
        if let Some(img) = img {
            return ShotState::Done(save_color_image(&img, &self.path));
        }
        if self.started.elapsed() > Duration::from_secs(60) {
            return ShotState::Done(Err(anyhow::anyhow!("no screenshot arrived within 60 s")));
        }
        ShotState::Waiting
    }
}

/// Saves an egui image as PNG.
pub fn save_color_image(img: &egui::ColorImage, path: &std::path::Path) -> anyhow::Result<()> {
    let [w, h] = img.size;
    let bytes: Vec<u8> = img.pixels.iter().flat_map(|c| c.to_array()).collect();
    let rgba = image::RgbaImage::from_raw(w as u32, h as u32, bytes)
        .context("screenshot has the wrong size")?;
    // Through the safe writer: atomic, and never over a FIFO, a device, a
    // read-only file or through a dangling link.
    crate::export::save_png(&rgba, path)?;
    crate::session::console::eprint(&format!(
        "bv: saved screenshot {} ({w}x{h})\n",
        path.display()
    ));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles() {
        let xs: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(percentile(&xs, 0.5), 50.0);
        assert_eq!(percentile(&xs, 0.95), 95.0);
        assert_eq!(percentile(&[], 0.5), 0.0);
    }

    #[test]
    fn models_flag_replaces_the_list() {
        let args = ViewerArgs {
            models: vec!["lambert".into(), "lambert".into()],
            ..Default::default()
        };
        let s = initial_state(&args, None).unwrap();
        assert_eq!(s.brdfs.len(), 2);
        assert_eq!(s.selected, Some(s.brdfs[0].id));
        let bad = ViewerArgs {
            models: vec!["nope".into()],
            ..Default::default()
        };
        assert!(initial_state(&bad, None).is_err());
    }

    #[test]
    fn the_bench_report_names_views_still_at_work_when_the_wait_runs_out() {
        // Idle views settle after IDLE_FRAMES frames; the report names none.
        let mut b = Bench::new(10, "test".into());
        let mut frames = 0;
        while b.settling(&[]) {
            frames += 1;
            assert!(frames < 100, "idle views never settled");
        }
        assert_eq!(frames, Bench::IDLE_FRAMES - 1);
        assert!(!b.report().contains("still at work"), "{}", b.report());

        // A view busy until the wait runs out is named, once the wait is over.
        let mut b = Bench::new(10, "test".into());
        assert!(b.settling(&["environment"]));
        let Some(long_ago) = Instant::now().checked_sub(Bench::MAX_SETTLE) else {
            return; // a clock this close to its epoch cannot go back 60 s
        };
        b.settle_start = Some(long_ago);
        assert!(!b.settling(&["environment", "lit-sphere"]));
        assert!(
            b.report()
                .contains("still at work: environment, lit-sphere"),
            "{}",
            b.report()
        );
        // A view that went idle just before the wait ran out is not named.
        let mut b = Bench::new(10, "test".into());
        assert!(b.settling(&[]));
        b.settle_start = Some(long_ago);
        assert!(!b.settling(&[]));
        assert!(!b.report().contains("still at work"), "{}", b.report());
    }

    #[test]
    fn no_gpu_message_says_what_to_install() {
        let m = no_gpu_message("x");
        assert!(m.contains("mesa-vulkan-drivers"));
    }
}
