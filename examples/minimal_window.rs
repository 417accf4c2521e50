//! The frame-time baseline for `bv --bench-frames N`: the smallest eframe
//! window with the same renderer (wgpu), size, present mode and dithering as
//! bv's, drawing one side panel with a slider that moves every frame and an
//! empty central panel. Whatever a frame of this costs (surface acquire,
//! egui's tessellation and paint, present) bv cannot go below; bv's own cost
//! is its frame time divided by this one, measured side by side in one run
//! (`benches/frames.sh`).
//!
//! `cargo run --release --example minimal_window -- [FRAMES] [WIDTHxHEIGHT]`
//! prints one line in the format of bv's `--bench-frames` report and exits.

// Benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use eframe::egui;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let frames: usize = args.next().map_or(Ok(120), |s| s.parse())?;
    let size = args.next().unwrap_or_else(|| "1280x800".to_string());
    let (w, h) = size
        .split_once('x')
        .ok_or_else(|| anyhow::anyhow!("size must be WIDTHxHEIGHT, got `{size}`"))?;
    let size = [w.parse::<f32>()?, h.parse::<f32>()?];
    let mut options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("bv frame-time baseline")
            .with_inner_size(size),
        persist_window: false,
        dithering: false,
        ..Default::default()
    };
    options.wgpu_options.surface.present_mode = eframe::wgpu::PresentMode::AutoNoVsync;
    eframe::run_native(
        "bv-baseline",
        options,
        Box::new(move |cc| {
            let adapter = cc
                .wgpu_render_state
                .as_ref()
                .map(|rs| rs.adapter.get_info().name)
                .unwrap_or_else(|| "?".to_string());
            Ok(Box::new(Baseline {
                frames: frames.max(1),
                warmup: 10,
                k: 0,
                value: 0.0,
                last: None,
                intervals: Vec::new(),
                adapter,
                reported: false,
            }))
        }),
    )
    .map_err(|e| anyhow::anyhow!("{e}"))
}

struct Baseline {
    frames: usize,
    warmup: usize,
    k: usize,
    value: f64,
    last: Option<Instant>,
    intervals: Vec<f64>,
    adapter: String,
    reported: bool,
}

impl eframe::App for Baseline {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let start = Instant::now();
        if self.k > self.warmup
            && let Some(last) = self.last
        {
            self.intervals.push((start - last).as_secs_f64() * 1e3);
        }
        self.last = Some(start);
        // The same triangle wave as bv's sweep.
        let phase = (self.k % 120) as f64 / 60.0;
        self.value = if phase <= 1.0 { phase } else { 2.0 - phase };
        self.k += 1;
        egui::Panel::left("params")
            .default_size(350.0)
            .show(ui, |ui| {
                ui.add(egui::Slider::new(&mut self.value, 0.0..=1.0).text("value"));
            });
        egui::CentralPanel::default().show(ui, |_ui| {});
        if self.intervals.len() >= self.frames && !self.reported {
            self.reported = true;
            println!(
                "baseline: {} frames on {}: frame time p50 {:.2} ms, p95 {:.2} ms",
                self.intervals.len(),
                self.adapter,
                bv::app::percentile(&self.intervals, 0.5),
                bv::app::percentile(&self.intervals, 0.95),
            );
            ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
        }
        ui.ctx().request_repaint();
    }
}
