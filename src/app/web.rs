//! The viewer in a browser page: eframe's web runner on the page's canvas
//! (`bv_canvas`), WebGPU where the browser has it and WebGL2 otherwise
//! (egui-wgpu's choice), and the scene as a link in the URL's fragment
//! ([`crate::session::link`]).
//!
//! The page starts from the scene of its link if it has one, else from the
//! session saved in the browser's storage, else from the first-run scene. A
//! link that cannot be opened says why in a window and shows the default
//! scene. *Copy link* puts the current scene into the address bar and on the
//! clipboard; pasting another link into the same tab (only the fragment
//! changes, so the page does not reload) opens its scene.
//!
//! Files dropped on the page or picked in the browser's file chooser (what
//! the viewer's *Open* dialogs open in a page) arrive as bytes and open as on
//! the desktop: scene files, MERL tables, RGL materials, `.brdf` models,
//! environment maps.
//! What the desktop writes to a file (*Save scene*, figures) becomes a
//! download.
//!
//! If the browser takes the WebGPU device back (its GPU process restarts; or
//! headless Chromium 156 without Vulkan in its GPU process, which then has no
//! shared image to back a WebGPU canvas with and takes the device back at
//! the first present, bv's or any page's: see `web/test.mjs`), the page says
//! why on the console, notes it in the tab's session storage and reloads on
//! WebGL2; `?webgl` in the address asks for WebGL2 from the start.
//!
//! What the page tells a test driver goes to the browser's console as
//! `bv: …` lines (`console.info`), never as errors.

use super::{BvApp, STORAGE_KEY, Viewer};
use crate::session::command::Command;
use crate::session::scene_file::{self, Builds};
use crate::session::{AppState, link, platform};
use eframe::egui;
use std::sync::{Arc, Mutex};
use std::time::Duration;
use wasm_bindgen::JsCast as _;

/// The id of the page's canvas (`web/index.html`).
pub const CANVAS_ID: &str = "bv_canvas";

/// Starts the viewer on the page's canvas (the wasm binary's `main`). A
/// failure to start is logged and shown in the page's loading text.
pub fn start() {
    wasm_bindgen_futures::spawn_local(async {
        if let Err(e) = run().await {
            let text = format!("bv could not start: {e}");
            web_sys::console::error_1(&text.as_str().into());
            if let Some(el) = document().and_then(|d| d.get_element_by_id("bv_loading")) {
                el.set_text_content(Some(&text));
            }
        }
    });
}

fn document() -> Option<web_sys::Document> {
    web_sys::window()?.document()
}

/// Logs a line for whoever reads the console (the headless test).
fn info(text: &str) {
    web_sys::console::info_1(&format!("bv: {text}").into());
}

/// The session-storage key that records a lost WebGPU device (for this tab).
const WEBGPU_LOST: &str = "bv-webgpu-lost";

fn session_storage() -> Option<web_sys::Storage> {
    web_sys::window()?.session_storage().ok()?
}

/// Why this page draws with WebGL2 only, if it was asked to (`?webgl`) or
/// WebGPU was lost in this tab before.
fn webgl_only() -> Option<String> {
    let search = web_sys::window()
        .and_then(|w| w.location().search().ok())
        .unwrap_or_default();
    if search
        .trim_start_matches('?')
        .split('&')
        .any(|kv| kv == "webgl")
    {
        return Some("asked for by the address".into());
    }
    session_storage()?.get_item(WEBGPU_LOST).ok()?
}

fn location_hash() -> String {
    web_sys::window()
        .and_then(|w| w.location().hash().ok())
        .unwrap_or_default()
}

async fn run() -> Result<(), String> {
    let canvas = document()
        .and_then(|d| d.get_element_by_id(CANVAS_ID))
        .ok_or_else(|| format!("the page has no element `{CANVAS_ID}`"))?
        .dyn_into::<web_sys::HtmlCanvasElement>()
        .map_err(|_| format!("`{CANVAS_ID}` is not a canvas"))?;
    // The instruction set of bv-core's batch kernels (the lobe mesh, image
    // slices): `simd128` in a bundle built with WebAssembly SIMD.
    let isa = bv_core::batch::isa();
    info(&format!("batch kernels {isa} ({} lanes)", isa.lanes()));
    let mut options = eframe::WebOptions {
        // As on the desktop: the UI has no gradients that band without it.
        dithering: false,
        ..Default::default()
    };
    if let Some(why) = webgl_only() {
        info(&format!("WebGL2 only ({why})"));
        let mut setup = eframe::egui_wgpu::WgpuSetupCreateNew::without_display_handle();
        setup.instance_descriptor.backends = eframe::wgpu::Backends::GL;
        options.wgpu_options.wgpu_setup = eframe::egui_wgpu::WgpuSetup::CreateNew(setup);
    }
    eframe::WebRunner::new()
        .start(
            canvas,
            options,
            Box::new(|cc| Ok(Box::new(WebApp::new(cc)))),
        )
        .await
        .map_err(|e| format!("{e:?}"))?;
    if let Some(el) = document().and_then(|d| d.get_element_by_id("bv_loading")) {
        el.remove();
    }
    Ok(())
}

/// The page's app: the window's [`BvApp`], the link's message and the
/// *Copy link* button.
struct WebApp {
    inner: BvApp,
    /// The fragment last opened or written (a different one was pasted).
    hash: String,
    /// Why a link's scene was refused, or its warnings, until dismissed.
    message: Option<String>,
    /// When the link was last copied (the button says so for a moment).
    copied: Option<platform::Instant>,
    /// Whether the first frame was reported.
    reported: bool,
    /// Whether the device is the browser's WebGPU (a loss reloads on WebGL2).
    webgpu: bool,
    /// Dropped files being read (the browser reads them asynchronously).
    reads: Vec<std::sync::mpsc::Receiver<DroppedRead>>,
    /// The BRDFs drawn and the load errors in the last frame (reported when
    /// they change).
    reported_brdfs: usize,
    reported_errors: usize,
    /// The status line last told to the console.
    reported_status: Option<String>,
}

/// A dropped file's name and its bytes, or why they could not be read.
type DroppedRead = (String, Result<Vec<u8>, String>);

/// The state of a link's fragment, or the default scene and a message.
fn state_of_link(hash: &str) -> (AppState, Option<String>) {
    match link::decode(hash) {
        Ok(loaded) => {
            info(&format!(
                "opened the scene of the link ({} BRDFs)",
                loaded.state.brdfs.len()
            ));
            let message = (!loaded.warnings.is_empty()).then(|| {
                format!(
                    "The link's scene opened with warnings:\n{}",
                    loaded.warnings.join("\n")
                )
            });
            (loaded.state, message)
        }
        Err(e) => {
            info(&format!("refused the link: {e}"));
            (
                AppState::first_run(),
                Some(format!(
                    "This link's scene could not be opened: {e}.\nShowing the default scene."
                )),
            )
        }
    }
}

impl WebApp {
    fn new(cc: &eframe::CreationContext<'_>) -> Self {
        let mut backend = "no wgpu adapter".to_string();
        let mut webgpu = false;
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
            let i = rs.adapter.get_info();
            backend = format!("{:?} ({})", i.backend, i.name);
            webgpu = i.backend == eframe::wgpu::Backend::BrowserWebGpu;
        }
        info(&format!("renderer {backend}"));
        let hash = location_hash();
        let (state, message) = if link::has_scene(&hash) {
            state_of_link(&hash)
        } else {
            let saved = cc.storage.and_then(|s| s.get_string(STORAGE_KEY));
            let state = saved
                .as_deref()
                .and_then(AppState::from_json_str)
                .unwrap_or_else(AppState::first_run);
            (state.sanitised(), None)
        };
        let ctx = cc.egui_ctx.clone();
        platform::set_picked_waker(move || ctx.request_repaint());
        let mut viewer = Viewer::new(state);
        if let Some(rs) = &cc.wgpu_render_state {
            viewer.export.set_gpu(rs.clone());
        }
        Self {
            inner: BvApp {
                viewer,
                persist: true,
                bench: None,
                shot: None,
                outcome: Arc::new(Mutex::new(None)),
                // The page's canvas takes the size the page gives it.
                resize: None,
            },
            hash,
            message,
            copied: None,
            reported: false,
            webgpu,
            reads: Vec::new(),
            reported_brdfs: 0,
            reported_errors: 0,
            reported_status: None,
        }
    }

    /// Opens the scene of a link pasted into this tab's address bar.
    fn follow_hash(&mut self) {
        let hash = location_hash();
        if hash == self.hash {
            return;
        }
        self.hash = hash.clone();
        if link::has_scene(&hash) {
            let (state, message) = state_of_link(&hash);
            self.inner.viewer.replace_state(state);
            self.message = message;
        }
    }

    /// Puts the scene's link into the address bar and on the clipboard.
    fn copy_link(&mut self, ctx: &egui::Context) {
        let Some(window) = web_sys::window() else {
            return;
        };
        let Ok(href) = window.location().href() else {
            return;
        };
        match link::url_with(&href, self.inner.viewer.state()) {
            Ok(url) => {
                // `replaceState`, not a new history entry per click; the
                // fragment alone changes, so nothing reloads.
                if let Ok(h) = window.history() {
                    let _ = h.replace_state_with_url(&wasm_bindgen::JsValue::NULL, "", Some(&url));
                }
                self.hash = location_hash();
                ctx.copy_text(url.clone());
                self.copied = Some(platform::Instant::now());
                info(&format!("link {url}"));
            }
            Err(e) => self.message = Some(format!("The scene could not be put in a link: {e}")),
        }
    }

    /// Takes the files dropped on the page before the viewer sees them (it
    /// would look for them on a disk the page does not have) and starts
    /// reading them; opens the files that have been read, and those picked
    /// in the browser's file chooser.
    fn dropped(&mut self, ctx: &egui::Context) {
        let files = ctx.input_mut(|i| std::mem::take(&mut i.raw.dropped_files));
        for f in files {
            let (tx, rx) = std::sync::mpsc::channel();
            let ctx2 = ctx.clone();
            wasm_bindgen_futures::spawn_local(async move {
                let name = f.path().display().to_string();
                let bytes = f.bytes_async().await;
                let _ = tx.send((name, bytes));
                ctx2.request_repaint();
            });
            self.reads.push(rx);
        }
        let mut read = platform::take_picked();
        self.reads.retain(|rx| match rx.try_recv() {
            Ok(r) => {
                read.push(r);
                false
            }
            Err(std::sync::mpsc::TryRecvError::Empty) => true,
            Err(std::sync::mpsc::TryRecvError::Disconnected) => false,
        });
        let several = read.len() > 1;
        for (name, bytes) in read {
            match bytes {
                Ok(bytes) => self.open_bytes(&name, bytes, several),
                Err(e) => self.message = Some(format!("{name} could not be read: {e}")),
            }
        }
    }

    /// Opens a file the page was handed as bytes, as the desktop opens the
    /// file of that name: a scene file replaces the scene; an environment
    /// map becomes the environment view's; a MERL table, an RGL material or a
    /// `.brdf` model becomes a BRDF (or the selected BRDF's file, as a drop on
    /// the desktop does). The bytes are handed to bv's readers under the file's name
    /// ([`bv_core::fsio::provide`]), so the one loading path reads them.
    fn open_bytes(&mut self, name: &str, bytes: Vec<u8>, several: bool) {
        let ext = name
            .rsplit_once('.')
            .map_or(String::new(), |(_, e)| e.to_ascii_lowercase());
        if ext == scene_file::EXTENSION {
            let opened = scene_file::utf8_text(bytes).and_then(|t| {
                scene_file::from_toml_in(&t, None, Builds::Warn).map_err(|e| e.to_string())
            });
            match opened {
                Ok(loaded) => {
                    info(&format!("opened the scene file {name}"));
                    self.inner.viewer.replace_state(loaded.state);
                    self.message = (!loaded.warnings.is_empty())
                        .then(|| format!("{name}:\n{}", loaded.warnings.join("\n")));
                }
                Err(e) => self.message = Some(format!("{name}: {e}")),
            }
            return;
        }
        let path = std::path::Path::new(name);
        let viewer = &mut self.inner.viewer;
        if crate::views::environment::ENVIRONMENT_FILES.accepts(path) {
            bv_core::fsio::provide(name, bytes);
            let mut env = viewer.state().lighting.env.clone();
            env.map = Some(name.to_string());
            viewer.push(Command::SetEnvView(env));
            info(&format!("opened the environment map {name}"));
            return;
        }
        let brdf_file = crate::session::user_models::is_file(name);
        if brdf_file
            || crate::session::loader::file_model_for(path)
                .is_some_and(|(_, _, f)| f.extensions().contains(&ext.as_str()))
        {
            bv_core::fsio::provide(name, bytes);
            let c = super::viewer::file_command(viewer.state(), viewer.runtime(), name, several);
            viewer.push(c);
            info(&format!("opening the file {name}"));
            return;
        }
        self.message = Some(format!(
            "{name}: not a file bv opens (scene files .{}, MERL tables, RGL materials, .brdf models, \
             environment maps)",
            scene_file::EXTENSION
        ));
    }

    /// Tells the console when the number of BRDFs or of files that could not
    /// be opened changes, and the status line (what a test driver waits for
    /// after a drop).
    fn report(&mut self) {
        let n = self.inner.viewer.state().brdfs.len();
        if n != self.reported_brdfs {
            self.reported_brdfs = n;
            info(&format!("{n} BRDFs"));
        }
        let errors = self.inner.viewer.load_errors();
        if errors.len() > self.reported_errors {
            for e in &errors[self.reported_errors..] {
                info(&format!("could not open {}: {}", e.path, e.message));
            }
        }
        self.reported_errors = errors.len();
        // A refused file (a `.brdf` that does not compile, or one past a
        // limit) is said on the status line.
        let status = self.inner.viewer.status().map(str::to_string);
        if status != self.reported_status {
            if let Some(s) = &status {
                info(&format!("status: {s}"));
            }
            self.reported_status = status;
        }
    }

    fn save_scene(&mut self) {
        let saved = scene_file::to_toml(self.inner.viewer.state())
            .map_err(|e| e.to_string())
            .and_then(|t| platform::download("bv-scene.toml", t.as_bytes()));
        if let Err(e) = saved {
            self.message = Some(format!("The scene could not be saved: {e}"));
        }
    }

    fn overlay(&mut self, ctx: &egui::Context) {
        let recent = self
            .copied
            .is_some_and(|t| t.elapsed() < Duration::from_secs(2));
        egui::Area::new(egui::Id::unique("bv web link"))
            .anchor(egui::Align2::RIGHT_BOTTOM, egui::vec2(-8.0, -8.0))
            .order(egui::Order::Foreground)
            .show(ctx, |ui| {
                ui.horizontal(|ui| {
                    if ui
                        .add(egui::Button::new("Save scene").wrap_mode(egui::TextWrapMode::Extend))
                        .on_hover_text(
                            "Download this scene as a scene file (drop one on the page to open it)",
                        )
                        .clicked()
                    {
                        self.save_scene();
                    }
                    let label = if recent { "Link copied" } else { "Copy link" };
                    if ui
                        .add(egui::Button::new(label).wrap_mode(egui::TextWrapMode::Extend))
                        .on_hover_text("Put this scene into the address bar and on the clipboard")
                        .clicked()
                    {
                        self.copy_link(ctx);
                    }
                });
            });
        if recent {
            ctx.request_repaint_after(Duration::from_millis(250));
        }
        let mut open = self.message.is_some();
        if let Some(text) = &self.message {
            let mut dismissed = false;
            egui::Window::new("Scene link")
                .collapsible(false)
                .resizable(false)
                .anchor(egui::Align2::CENTER_TOP, egui::vec2(0.0, 48.0))
                .open(&mut open)
                .show(ctx, |ui| {
                    ui.label(text);
                    dismissed = ui.button("OK").clicked();
                });
            if dismissed {
                open = false;
            }
        }
        if !open {
            self.message = None;
        }
    }
}

impl eframe::App for WebApp {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        if self.webgpu
            && let Some(why) = crate::views::gpu_image::device_lost(&ctx)
        {
            // Nothing drawn on a lost device reaches the page: start again on
            // WebGL2 (the fragment, hence the scene, survives the reload).
            self.webgpu = false;
            info(&format!("WebGPU was lost ({why}); reloading on WebGL2"));
            if let Some(s) = session_storage() {
                let _ = s.set_item(WEBGPU_LOST, &format!("WebGPU was lost: {why}"));
            }
            if let Some(w) = web_sys::window() {
                let _ = w.location().reload();
            }
        }
        self.follow_hash();
        self.dropped(&ctx);
        let t0 = platform::Instant::now();
        self.inner.ui(ui, frame);
        self.report();
        self.overlay(&ctx);
        platform::set_frame_cost(t0.elapsed());
        if !self.reported {
            self.reported = true;
            info("first frame");
        }
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::App::save(&mut self.inner, storage);
    }

    fn persist_egui_memory(&self) -> bool {
        self.inner.persist_egui_memory()
    }

    fn auto_save_interval(&self) -> Duration {
        self.inner.auto_save_interval()
    }
}
