//! The lobe view's egui side: the paint callback that hands each frame to
//! the renderer ([`crate::gpu::lobe`]) and blits its image into the viewport
//! egui sets, and the installation of that renderer.
//!
//! In a window, [`install`] puts a [`LobeRenderer`] into egui-wgpu's callback
//! resources once; each frame the view adds a [`LobeCallback`], whose `prepare`
//! uploads what changed and records the offscreen pass, and whose `paint` blits
//! the result into the viewport egui sets for it.

use crate::gpu::lobe::{LobeFrame, LobeRenderer, PixelSize};
use eframe::egui;
use eframe::egui_wgpu::{self, CallbackResources, CallbackTrait, ScreenDescriptor};
use eframe::wgpu;
use std::sync::Arc;

/// A [`LobeRenderer`] for `target_format`, primed
/// ([`LobeRenderer::prime`]: a CPU rasteriser compiles its shaders while the
/// caller goes on); `None` where its shaders do not compose.
pub fn renderer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    adapter: Option<&wgpu::Adapter>,
    target_format: wgpu::TextureFormat,
) -> Option<LobeRenderer> {
    match LobeRenderer::new(device, adapter, target_format) {
        Ok(mut r) => {
            r.prime(device, queue);
            Some(r)
        }
        // The shaders are compiled into bv and composed by its tests, so this
        // is a broken build; the lobe view then stays empty (its callback
        // finds no renderer), which is said on stderr rather than a panic
        // (`eprintln!` would panic on a closed stderr).
        Err(e) => {
            use std::io::Write as _;
            let _ = writeln!(std::io::stderr(), "bv: the lobe view cannot draw: {e:#}");
            None
        }
    }
}

/// Installs the lobe pipeline into egui-wgpu's render state (eframe's window or
/// a kittest harness's).
pub fn install(render_state: &egui_wgpu::RenderState) {
    let lobe = renderer(
        &render_state.device,
        &render_state.queue,
        Some(&render_state.adapter),
        render_state.target_format,
    );
    if let Some(lobe) = lobe {
        render_state
            .renderer
            .write()
            .callback_resources
            .insert(lobe);
    }
}

/// The paint callback of one lobe view for one frame.
pub struct LobeCallback {
    /// The view's key (separate GPU targets per view).
    pub view: u64,
    /// The callback's rectangle in points (the same as the shape's).
    pub rect: egui::Rect,
    /// What to draw.
    pub frame: Arc<LobeFrame>,
}

impl LobeCallback {
    /// The shape to add to a painter.
    pub fn shape(self) -> egui::Shape {
        let rect = self.rect;
        egui::Shape::Callback(egui_wgpu::Callback::new_paint_callback(rect, self))
    }
}

/// The pixel size of the viewport egui-wgpu sets for a callback rectangle.
pub fn rect_pixels(rect: egui::Rect, ppp: f32, screen_px: [u32; 2]) -> [u32; 2] {
    let v = egui::epaint::ViewportInPixels::from_points(&rect, ppp, screen_px);
    [v.width_px.max(1) as u32, v.height_px.max(1) as u32]
}

impl CallbackTrait for LobeCallback {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        screen: &ScreenDescriptor,
        encoder: &mut wgpu::CommandEncoder,
        resources: &mut CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        if let Some(r) = resources.get_mut::<LobeRenderer>() {
            let ppp = screen.pixels_per_point;
            r.prepare(
                device,
                queue,
                encoder,
                self.view,
                &self.frame,
                PixelSize {
                    size: rect_pixels(self.rect, ppp, screen.size_in_pixels),
                    ppp,
                },
            );
        }
        Vec::new()
    }

    fn paint(
        &self,
        info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &CallbackResources,
    ) {
        if let Some(r) = resources.get::<LobeRenderer>() {
            let pixels = |v: egui::epaint::ViewportInPixels| {
                [v.left_px, v.top_px, v.width_px, v.height_px].map(|x| x.max(0) as u32)
            };
            let (viewport, clip) = (info.viewport_in_pixels(), info.clip_rect_in_pixels());
            r.paint(self.view, pass, pixels(viewport), pixels(clip));
        }
    }
}
