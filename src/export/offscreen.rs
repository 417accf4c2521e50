//! Drawing an egui UI into an image without a window: the same UI code the
//! viewer runs, laid out by a fresh egui context, painted by egui-wgpu into an
//! offscreen `Rgba8Unorm` texture and read back. Views with their own wgpu
//! pipelines (the lobe) render inside it through their paint callbacks, whose
//! resources [`crate::views::GpuResources`] puts into this renderer.
//!
//! Pixels per point are set on the context, so a 2× or 4× image is laid out
//! and rasterised at that resolution (text, lines and the lobe's own target),
//! never upscaled.

use crate::gpu::errors::{self, ErrorLog};
use crate::gpu::readback::PendingImage;
use anyhow::{Context as _, Result, bail};
use eframe::egui::{self, Vec2};
use eframe::egui_wgpu::{self, ScreenDescriptor};
use eframe::wgpu;

/// Colour format of the offscreen image (gamma-encoded, what egui-wgpu blends in).
pub const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// Most egui passes run before painting: a layout settles in two or three, and
/// a view that keeps asking for repaints (progressive rendering) is painted as
/// it stands after this many.
pub const MAX_PASSES: usize = 16;

/// Largest image side accepted whatever the device allows: a 16384-pixel
/// square is already 1 GiB of pixels to lay out, paint and read back.
pub const MAX_SIDE: u32 = 16384;

/// An egui-wgpu renderer of its own on a device (the GUI's, or one opened
/// headless), with every view's GPU resources installed. It is held as an
/// egui-wgpu [`egui_wgpu::RenderState`], like a window's, so that views which
/// find the render state through their egui context (and register textures
/// with its renderer) draw offscreen as they do in the window.
pub struct Offscreen {
    rs: egui_wgpu::RenderState,
    errors: ErrorLog,
}

/// How an image is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Size in points (the layout size).
    pub size: Vec2,
    /// Pixels per point (1, 2, 4 … × the screen's).
    pub pixels_per_point: f32,
    /// Dark or light visuals.
    pub dark: bool,
    /// Leave the background transparent (panels and plot areas unfilled).
    pub transparent: bool,
}

impl Frame {
    /// The image size in pixels.
    pub fn pixels(&self) -> [u32; 2] {
        [
            (self.size.x * self.pixels_per_point).round().max(1.0) as u32,
            (self.size.y * self.pixels_per_point).round().max(1.0) as u32,
        ]
    }
}

impl Offscreen {
    /// Opens a device headless ([`crate::gpu::Headless::open`]: the first
    /// adapter wgpu finds, preferring a real GPU; lavapipe on a server
    /// without one).
    pub fn headless() -> Result<Self> {
        // The lobe's shaders need no device: composed on another core while
        // the device opens.
        crate::gpu::lobe::compose_in_background();
        let h = crate::gpu::Headless::open()?;
        Ok(Self::new(h.instance, h.adapter, h.device, h.queue))
    }

    /// An offscreen renderer on an existing device: it shares the device and
    /// queue but has its own egui textures and view resources, so a window's
    /// are left alone.
    pub fn new(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> Self {
        // A GPU error must become a message, never wgpu's default panic.
        let errors = errors::watch(&device);
        // The views' pipelines first: a CPU rasteriser compiles their shaders
        // on its queue thread while egui's renderer is made here.
        let views = crate::views::GpuResources::new(&device, &queue, Some(&adapter), FORMAT);
        let mut renderer =
            egui_wgpu::Renderer::new(&device, FORMAT, egui_wgpu::RendererOptions::PREDICTABLE);
        views.install(&mut renderer.callback_resources);
        Self {
            rs: egui_wgpu::RenderState {
                // egui-wgpu lists the adapters only where it can enumerate
                // them (not in a browser).
                #[cfg(not(target_arch = "wasm32"))]
                available_adapters: vec![adapter.clone()],
                adapter,
                instance,
                device,
                queue,
                target_format: FORMAT,
                renderer: std::sync::Arc::new(eframe::egui::mutex::RwLock::new(renderer)),
            },
            errors,
        }
    }

    /// On the device of an egui-wgpu render state (eframe's window).
    pub fn from_render_state(rs: &egui_wgpu::RenderState) -> Self {
        Self::new(
            rs.instance.clone(),
            rs.adapter.clone(),
            rs.device.clone(),
            rs.queue.clone(),
        )
    }

    /// The render state figures are drawn with.
    pub fn render_state(&self) -> &egui_wgpu::RenderState {
        &self.rs
    }

    /// The largest image side this device can draw (its texture limit, at
    /// most [`MAX_SIDE`]).
    pub fn max_side(&self) -> u32 {
        self.rs
            .device
            .limits()
            .max_texture_dimension_2d
            .min(MAX_SIDE)
    }

    /// One line naming the adapter.
    pub fn describe(&self) -> String {
        let i = self.rs.adapter.get_info();
        format!("{} ({:?}, {:?})", i.name, i.backend, i.device_type)
    }

    /// Runs `ui` in a fresh egui context of `frame.size` points until it
    /// settles (at most [`MAX_PASSES`] passes), paints the last pass and reads
    /// it back. With `transparent`, the image is un-premultiplied so that PNG
    /// viewers show the right colours over any background.
    pub fn render(
        &mut self,
        frame: Frame,
        ui: impl FnMut(&mut egui::Ui),
    ) -> Result<image::RgbaImage> {
        self.start_render(frame, ui)?.wait()
    }

    /// [`Self::render`] without waiting for the image: the drawing is
    /// submitted and its readback started; the figure is taken with
    /// [`PendingFigure::poll`] in a later frame (what a browser page must do:
    /// it maps buffers only between frames).
    pub fn start_render(
        &mut self,
        frame: Frame,
        mut ui: impl FnMut(&mut egui::Ui),
    ) -> Result<PendingFigure> {
        let [w, h] = frame.pixels();
        let max = self.max_side();
        if w > max || h > max {
            bail!("an image of {w}×{h} pixels: this device draws at most {max} pixels on a side");
        }
        let before = self.errors.count();
        let device = self.rs.device.clone();
        let image = errors::scoped(&device, "drawing the figure", || {
            self.render_unscoped(frame, [w, h], &mut ui)
        });
        // Errors of work on other threads (a renderer built in the
        // background) reach the uncaptured-error handler instead.
        if let Some(e) = self.errors.since(before) {
            bail!("drawing the figure: GPU error: {e}");
        }
        image
    }

    fn render_unscoped(
        &mut self,
        frame: Frame,
        [w, h]: [u32; 2],
        ui: &mut impl FnMut(&mut egui::Ui),
    ) -> Result<PendingFigure> {
        let ctx = egui::Context::default();
        ctx.set_theme(if frame.dark {
            egui::Theme::Dark
        } else {
            egui::Theme::Light
        });
        ctx.all_styles_mut(|style| {
            style.animation_time = 0.0;
            style.visuals.text_cursor.blink = false;
            if frame.transparent {
                let v = &mut style.visuals;
                v.panel_fill = egui::Color32::TRANSPARENT;
                v.window_fill = egui::Color32::TRANSPARENT;
                v.extreme_bg_color = egui::Color32::TRANSPARENT;
                v.faint_bg_color = egui::Color32::TRANSPARENT;
            }
        });
        let mut input = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, frame.size)),
            max_texture_side: Some(self.rs.device.limits().max_texture_dimension_2d as usize),
            ..Default::default()
        };
        // The scale is the viewport's native pixels per point, zoom staying 1.
        // (Setting a zoom as well multiplies the two, and egui then replaces
        // the first pass's screen by its default 10 000-point one, scaled:
        // the environment view sized its buffers from that, 20 000 pixels a
        // side at 2×.)
        input
            .viewports
            .entry(egui::ViewportId::ROOT)
            .or_default()
            .native_pixels_per_point = Some(frame.pixels_per_point);
        crate::views::install_context(&ctx, &self.rs);

        let mut output = None;
        for pass in 0..MAX_PASSES {
            let mut out = ctx.run_ui(input.clone(), |u| ui(u));
            {
                let mut r = self.rs.renderer.write();
                for (id, deltas) in &out.textures_delta.set {
                    for delta in deltas {
                        r.update_texture(&self.rs.device, &self.rs.queue, *id, delta);
                    }
                }
            }
            let settled = out
                .viewport_output
                .get(&egui::ViewportId::ROOT)
                .is_none_or(|v| v.repaint_delay > std::time::Duration::ZERO);
            if settled || pass + 1 == MAX_PASSES {
                output = Some(out);
                break;
            }
            for id in &out.textures_delta.free {
                self.rs.renderer.write().free_texture(id);
            }
            out.textures_delta.clear();
        }
        let mut output = output.context("egui produced no frame")?;
        let image = self.paint(&ctx, &output, frame, [w, h]);
        for id in &output.textures_delta.free {
            self.rs.renderer.write().free_texture(id);
        }
        output.textures_delta.clear();
        let (texture, image) = image?;
        Ok(PendingFigure {
            device: self.rs.device.clone(),
            texture,
            image,
            transparent: frame.transparent,
        })
    }

    fn paint(
        &mut self,
        ctx: &egui::Context,
        output: &egui::FullOutput,
        frame: Frame,
        [w, h]: [u32; 2],
    ) -> Result<(wgpu::Texture, PendingImage)> {
        let ppp = frame.pixels_per_point;
        let screen = ScreenDescriptor {
            size_in_pixels: [w, h],
            pixels_per_point: ppp,
        };
        let jobs = ctx.tessellate(output.shapes.clone(), ppp);
        // Cleared to the panels' colour (transparent for a transparent
        // figure), so a figure's background needs no fill: on a software
        // renderer a window-sized fill costs tens of milliseconds, a clear
        // next to nothing. The value is gamma-encoded, as egui-wgpu writes.
        let [r, g, b, a] = ctx
            .global_style()
            .visuals
            .panel_fill
            .to_normalized_gamma_f32();
        let clear = wgpu::Color {
            r: f64::from(r),
            g: f64::from(g),
            b: f64::from(b),
            a: f64::from(a),
        };
        let (device, queue) = (&self.rs.device, &self.rs.queue);
        let mut renderer = self.rs.renderer.write();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("bv offscreen"),
        });
        let user = renderer.update_buffers(device, queue, &mut encoder, &jobs, &screen);
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("bv offscreen target"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        {
            let mut pass = encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("bv offscreen egui"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &view,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(clear),
                            store: wgpu::StoreOp::Store,
                        },
                        depth_slice: None,
                    })],
                    ..Default::default()
                })
                .forget_lifetime();
            renderer.render(&mut pass, &jobs, &screen);
        }
        drop(renderer);
        queue.submit(user.into_iter().chain(std::iter::once(encoder.finish())));
        let image = crate::gpu::readback::start_rgba8(device, queue, &texture);
        match image {
            Ok(image) => Ok((texture, image)),
            Err(e) => {
                texture.destroy();
                Err(e)
            }
        }
    }
}

/// A figure drawn and being read back ([`Offscreen::start_render`]).
#[derive(Debug)]
pub struct PendingFigure {
    device: wgpu::Device,
    texture: wgpu::Texture,
    image: PendingImage,
    transparent: bool,
}

impl PendingFigure {
    /// The figure if the GPU is done (`None` while it is not), without
    /// blocking.
    pub fn poll(&mut self) -> Option<Result<image::RgbaImage>> {
        let image = self.image.poll(&self.device)?;
        Some(image.map(|mut image| {
            if self.transparent {
                unpremultiply(&mut image);
            }
            image
        }))
    }

    /// Blocks until the figure is there (native backends only).
    pub fn wait(mut self) -> Result<image::RgbaImage> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| anyhow::anyhow!("waiting for the GPU: {e}"))?;
        self.poll().unwrap_or_else(|| {
            Err(anyhow::anyhow!(
                "the figure was not read back after waiting"
            ))
        })
    }
}

impl Drop for PendingFigure {
    fn drop(&mut self) {
        self.texture.destroy();
    }
}

/// egui blends with premultiplied alpha; PNG stores straight alpha.
pub fn unpremultiply(img: &mut image::RgbaImage) {
    for p in img.pixels_mut() {
        let a = p.0[3];
        if a == 0 {
            p.0 = [0, 0, 0, 0];
        } else if a < 255 {
            for c in &mut p.0[..3] {
                *c = ((u32::from(*c) * 255 + u32::from(a) / 2) / u32::from(a)).min(255) as u8;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unpremultiply_restores_straight_alpha() {
        let mut img = image::RgbaImage::from_raw(
            3,
            1,
            vec![
                64, 32, 0, 128, //
                10, 10, 10, 0, //
                200, 100, 50, 255,
            ],
        )
        .unwrap();
        unpremultiply(&mut img);
        assert_eq!(img.get_pixel(0, 0).0, [128, 64, 0, 128]);
        assert_eq!(img.get_pixel(1, 0).0, [0, 0, 0, 0]);
        assert_eq!(img.get_pixel(2, 0).0, [200, 100, 50, 255]);
    }

    #[test]
    fn pixel_size_follows_the_scale() {
        let f = Frame {
            size: Vec2::new(400.0, 300.0),
            pixels_per_point: 2.0,
            dark: true,
            transparent: false,
        };
        assert_eq!(f.pixels(), [800, 600]);
    }
}
