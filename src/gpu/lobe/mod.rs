//! The lobe view's renderer (the GPU side of the 3D lobe): a [`LobeFrame`]
//! (camera matrices, meshes, line segments) is drawn into an offscreen
//! colour + depth target, which is then either copied into a render pass
//! someone else began ([`LobeRenderer::paint`]: egui's, through the paint
//! callback in `views::lobe_gpu`; what the window, `bv render` and the
//! snapshot tests show) or read back as drawn
//! ([`LobeRenderer::render_to_image`]). Drawing offscreen gives the lobe a
//! depth buffer and anti-aliased edges whatever egui's own pass has
//! (eframe's window has neither; kittest's has neither): four samples where
//! the GPU makes them cheap, else one sample and FXAA in the copy.
//!
//! Per view (a key chosen by the caller) it keeps the uniform, line and mesh
//! buffers and the target, re-uploading only what changed and redrawing only
//! when the frame's fingerprint changes. It depends on bv-core's meshes and
//! wgpu only: what the view computes (camera, colours) arrives as plain data.

mod content;
mod frame;
mod mesh;
mod pipelines;
mod prime;
mod sources;
mod target;

pub use content::{Content, content};
pub use frame::{LineSeg, LobeCamera, LobeFrame, MeshDraw, MeshStyle};
pub use mesh::wire_indices;
pub use sources::compose_in_background;
pub use target::fit_texture;

use super::{errors, fullscreen, readback};
use frame::StyleUniform;
use mesh::{GpuMesh, upload_mesh};
use pipelines::Pipelines;
use std::collections::HashMap;
use target::{Target, create_target};

/// Colour format of the offscreen target (gamma-encoded, like egui's).
pub const OFFSCREEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Depth format of the offscreen target.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Globals {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    viewport: [f32; 4],
}

struct ViewResources {
    globals: wgpu::Buffer,
    globals_bg: wgpu::BindGroup,
    lines: Option<(wgpu::Buffer, u64)>,
    line_count: u32,
    target: Option<Target>,
    meshes: HashMap<u64, GpuMesh>,
}

/// The size of a lobe view's image in pixels, and pixels per point (which
/// scales line widths).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelSize {
    /// Width and height in pixels.
    pub size: [u32; 2],
    /// Pixels per point.
    pub ppp: f32,
}

/// Pipelines and per-view GPU resources of every lobe view.
pub struct LobeRenderer {
    /// The drawing pipelines, at the offscreen sample count.
    pipelines: Pipelines,
    globals_layout: wgpu::BindGroupLayout,
    style_layout: wgpu::BindGroupLayout,
    blit_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    blit: wgpu::RenderPipeline,
    /// The copy through FXAA, where the target has one sample.
    blit_smooth: Option<wgpu::RenderPipeline>,
    /// Copy every pixel through FXAA, not only those about what is drawn
    /// ([`Self::set_smooth_everywhere`]).
    smooth_everywhere: bool,
    /// The format of the passes the copies draw into.
    target_format: wgpu::TextureFormat,
    views: HashMap<u64, ViewResources>,
}

impl LobeRenderer {
    /// The offscreen sample count of frames drawn at rest.
    pub fn samples(&self) -> u32 {
        self.pipelines.samples
    }

    /// With `true`, a smoothed copy runs FXAA over the whole image instead of
    /// only over the rectangle about what the frame draws ([`content`]).
    /// The pixels are the same and it costs more: a reference for tests and
    /// measurements.
    pub fn set_smooth_everywhere(&mut self, on: bool) {
        self.smooth_everywhere = on;
    }

    /// Uploads what changed in `frame` and records its offscreen pass for view
    /// `view` at the given pixel size.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        view: u64,
        frame: &LobeFrame,
        pixels: PixelSize,
    ) {
        let PixelSize { size: asked, ppp } = pixels;
        let size = fit_texture(asked, device.limits().max_texture_dimension_2d);
        // Line widths follow a target made smaller than asked.
        let ppp = ppp * size[0] as f32 / asked[0].max(1) as f32;
        let set = &self.pipelines;
        let samples = set.samples;
        let fingerprint = frame.fingerprint(size, ppp);
        let (style_layout, blit_layout, sampler) =
            (&self.style_layout, &self.blit_layout, &self.sampler);
        let (opaque, blended, wire, lines_pl) = (&set.opaque, &set.blended, &set.wire, &set.lines);
        let vr = {
            let layout = &self.globals_layout;
            self.views.entry(view).or_insert_with(|| {
                let globals = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("bv lobe globals"),
                    size: std::mem::size_of::<Globals>() as u64,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                let globals_bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("bv lobe globals"),
                    layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: globals.as_entire_binding(),
                    }],
                });
                ViewResources {
                    globals,
                    globals_bg,
                    lines: None,
                    line_count: 0,
                    target: None,
                    meshes: HashMap::new(),
                }
            })
        };

        // Target textures follow the viewport's pixel size.
        if vr
            .target
            .as_ref()
            .is_none_or(|t| t.size != size || t.samples != samples)
        {
            vr.target = Some(create_target(device, blit_layout, sampler, size, samples));
        }

        let cam = &frame.camera;
        let globals = Globals {
            view_proj: cam.view_proj.to_cols_array_2d(),
            eye: cam.eye.extend(1.0).to_array(),
            viewport: [size[0] as f32, size[1] as f32, 0.0, 0.0],
        };
        queue.write_buffer(&vr.globals, 0, bytemuck::bytes_of(&globals));

        // Lines: widths in pixels.
        let segs: Vec<LineSeg> = frame
            .lines
            .iter()
            .map(|s| LineSeg {
                width: [s.width[0] * ppp, 0.0, 0.0, 0.0],
                ..*s
            })
            .collect();
        vr.line_count = segs.len() as u32;
        if !segs.is_empty() {
            let bytes = bytemuck::cast_slice(&segs);
            let need = bytes.len() as u64;
            if vr.lines.as_ref().is_none_or(|(_, cap)| *cap < need) {
                let cap = need.next_power_of_two().max(4096);
                let buf = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("bv lobe lines"),
                    size: cap,
                    usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                vr.lines = Some((buf, cap));
            }
            if let Some((buf, _)) = &vr.lines {
                queue.write_buffer(buf, 0, bytes);
            }
        }

        // Meshes: upload new revisions, refresh styles, drop the ones not drawn.
        for m in vr.meshes.values_mut() {
            m.used = false;
        }
        for d in &frame.meshes {
            let stale = vr
                .meshes
                .get(&d.key)
                .is_none_or(|g| g.revision != d.revision);
            if stale {
                let refilled = vr
                    .meshes
                    .get_mut(&d.key)
                    .is_some_and(|g| g.refill(queue, d));
                if !refilled {
                    vr.meshes
                        .insert(d.key, upload_mesh(device, queue, style_layout, d));
                }
            }
            if let Some(g) = vr.meshes.get_mut(&d.key) {
                g.used = true;
                queue.write_buffer(
                    &g.style,
                    0,
                    bytemuck::bytes_of(&StyleUniform::new(&d.style)),
                );
            }
        }
        vr.meshes.retain(|_, m| m.used);

        let Some(target) = &mut vr.target else { return };
        // A drag's frames are copied as drawn: they follow each other too
        // fast for their edges to be seen, and the frame at rest is smoothed.
        target.smooth = self.blit_smooth.is_some() && !frame.interacting;
        // Where the smoothed copy needs FXAA: found once per image (a drag's
        // last frame, drawn unsmoothed, may be the one copied at rest).
        if target.smooth && target.content.is_none_or(|(f, _)| f != fingerprint) {
            target.content = Some((fingerprint, content::content(frame, size, ppp)));
        }
        if target.drawn == Some(fingerprint) {
            // Same image as last time: egui repainted for something else.
            return;
        }
        target.drawn = Some(fingerprint);
        let target = &*target;
        let bg = frame.background;
        let (color_view, resolve) = match &target.msaa_color {
            Some(ms) => (ms, Some(&target.resolve_view)),
            None => (&target.resolve_view, None),
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("bv lobe offscreen"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: color_view,
                depth_slice: None,
                resolve_target: resolve,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: bg[0] as f64,
                        g: bg[1] as f64,
                        b: bg[2] as f64,
                        a: bg[3] as f64,
                    }),
                    store: if resolve.is_some() {
                        wgpu::StoreOp::Discard
                    } else {
                        wgpu::StoreOp::Store
                    },
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &target.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        pass.set_bind_group(0, &vr.globals_bg, &[]);

        let draw_mesh = |pass: &mut wgpu::RenderPass<'_>, d: &MeshDraw, wire_pass: bool| {
            let Some(g) = vr.meshes.get(&d.key) else {
                return;
            };
            pass.set_bind_group(1, &g.style_bg, &[]);
            pass.set_vertex_buffer(0, g.vertices.slice(..));
            if wire_pass {
                pass.set_index_buffer(g.wire_indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..g.wire_count, 0, 0..1);
            } else {
                pass.set_index_buffer(g.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..g.index_count, 0, 0..1);
            }
        };

        // 1. Opaque surfaces write depth.
        pass.set_pipeline(opaque);
        for d in frame
            .meshes
            .iter()
            .filter(|d| d.style.alpha >= 1.0 && !d.style.wireframe)
        {
            draw_mesh(&mut pass, d, false);
        }
        // 2. Wireframes.
        pass.set_pipeline(wire);
        for d in frame.meshes.iter().filter(|d| d.style.wireframe) {
            draw_mesh(&mut pass, d, true);
        }
        // 3. Lines, tested against the surfaces.
        if vr.line_count > 0
            && let Some((buf, _)) = &vr.lines
        {
            pass.set_pipeline(lines_pl);
            pass.set_vertex_buffer(0, buf.slice(..));
            pass.draw(0..6, 0..vr.line_count);
        }
        // 4. Translucent surfaces (overlaid BRDFs, ground disc), no depth write.
        pass.set_pipeline(blended);
        pass.set_bind_group(0, &vr.globals_bg, &[]);
        for d in frame
            .meshes
            .iter()
            .filter(|d| d.style.alpha < 1.0 && !d.style.wireframe)
        {
            draw_mesh(&mut pass, d, false);
        }
    }

    /// Blits view `view`'s offscreen image into the current pass, whose
    /// viewport egui has set to the callback's rectangle, `viewport`, and
    /// whose scissor to `clip` (both `[x, y, width, height]` in the pass's
    /// pixels).
    pub fn paint(
        &self,
        view: u64,
        pass: &mut wgpu::RenderPass<'static>,
        viewport: [u32; 4],
        clip: [u32; 4],
    ) {
        for copy in self.copy_draws(view, viewport, clip).iter().flatten() {
            fullscreen::draw(pass, copy);
        }
    }

    /// The draws, in order, that copy view `view`'s image over `viewport`
    /// within `clip` (see [`Self::paint`]): as it stands, or, where the
    /// target is smoothed, as it stands and then through FXAA about what the
    /// frame draws ([`content`]). None before the view has a target. An
    /// array, not a list: this runs for every frame egui paints.
    fn copy_draws(
        &self,
        view: u64,
        viewport: [u32; 4],
        clip: [u32; 4],
    ) -> [Option<fullscreen::Draw<'_>>; 2] {
        let Some(target) = self.views.get(&view).and_then(|v| v.target.as_ref()) else {
            return [None, None];
        };
        let draw = |pipeline, scissor| fullscreen::Draw {
            pipeline,
            bind_group: &target.blit_bg,
            scissor,
        };
        let plain = draw(&self.blit, None);
        let Some(smooth) = self.blit_smooth.as_ref().filter(|_| target.smooth) else {
            return [Some(plain), None];
        };
        let content = match target.content {
            Some((_, c)) if !self.smooth_everywhere => c,
            _ => Content::Everywhere,
        };
        match content {
            Content::Everywhere => [Some(draw(smooth, None)), None],
            Content::Empty => [Some(plain), None],
            Content::Within(rect) => {
                let inside = content::scissor(rect, target.size, viewport, clip);
                [Some(plain), inside.map(|r| draw(smooth, Some(r)))]
            }
        }
    }

    /// The view keys of the renderer's own frames, so that a window's
    /// targets are left alone: [`Self::render_to_image`]'s,
    /// [`Self::render_copied`]'s and [`Self::prime`]'s. View keys are egui
    /// id values, so a window's could equal one only by a very unlikely
    /// chance; the copied and priming frames' targets are removed before
    /// their functions return, the priming one before any view draws.
    const HEADLESS: u64 = u64::MAX;
    const COPIED: u64 = u64::MAX - 1;
    const PRIMING: u64 = u64::MAX - 2;

    /// A command encoder with `frame`'s pass for view `view` at `pixels`
    /// recorded ([`Self::prepare`]): how the renderer's own frames begin.
    fn record_frame(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        label: &str,
        view: u64,
        frame: &LobeFrame,
        pixels: PixelSize,
    ) -> wgpu::CommandEncoder {
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        self.prepare(device, queue, &mut encoder, view, frame, pixels);
        encoder
    }

    /// Records the copy of view `view`'s image as [`Self::paint`] draws it
    /// into a new one-sample texture of its size, in the format the copies
    /// draw into, usable as `usage` too; `None` before the view has a target.
    fn record_copy(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
        view: u64,
        usage: wgpu::TextureUsages,
    ) -> Option<wgpu::Texture> {
        let size = self.views.get(&view)?.target.as_ref()?.size;
        let copy = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: size[0],
                height: size[1],
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.target_format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | usage,
            view_formats: &[],
        });
        let all = [0, 0, size[0], size[1]];
        let draws: Vec<_> = self
            .copy_draws(view, all, all)
            .into_iter()
            .flatten()
            .collect();
        fullscreen::pass(
            encoder,
            label,
            &copy.create_view(&Default::default()),
            &draws,
        );
        Some(copy)
    }

    /// Renders `frame` headless at `width × height` pixels and reads the
    /// target back as drawn (for tests: one sample on a CPU rasteriser, whose
    /// edges only the copy into egui's pass smooths). `ppp` scales line
    /// widths.
    pub fn render_to_image(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        frame: &LobeFrame,
        width: u32,
        height: u32,
        ppp: f32,
    ) -> Result<image::RgbaImage, String> {
        errors::scoped(device, "drawing the lobe", || {
            let label = "bv lobe headless";
            let encoder = self.record_frame(
                device,
                queue,
                label,
                Self::HEADLESS,
                frame,
                PixelSize {
                    size: [width, height],
                    ppp,
                },
            );
            queue.submit(std::iter::once(encoder.finish()));
            let target = self
                .views
                .get(&Self::HEADLESS)
                .and_then(|v| v.target.as_ref())
                .ok_or_else(|| anyhow::anyhow!("no target"))?;
            readback::read_rgba8(device, queue, &target.resolve)
        })
        .map_err(|e| format!("{e:#}"))
    }

    /// Renders `frame` headless as [`Self::render_to_image`] does and reads
    /// back what a figure shows of it: the image copied by [`Self::paint`]'s
    /// draws (through FXAA about the frame's content at rest, where the
    /// target has one sample) into a texture of the format the renderer was
    /// made for, pixel for pixel.
    pub fn render_copied(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        frame: &LobeFrame,
        width: u32,
        height: u32,
        ppp: f32,
    ) -> Result<image::RgbaImage, String> {
        let result = errors::scoped(device, "drawing and copying the lobe", || {
            let label = "bv lobe copied";
            let mut encoder = self.record_frame(
                device,
                queue,
                label,
                Self::COPIED,
                frame,
                PixelSize {
                    size: [width, height],
                    ppp,
                },
            );
            let usage = wgpu::TextureUsages::COPY_SRC;
            let copy = self
                .record_copy(device, &mut encoder, label, Self::COPIED, usage)
                .ok_or_else(|| anyhow::anyhow!("no target"))?;
            queue.submit(std::iter::once(encoder.finish()));
            let image = readback::read_rgba8(device, queue, &copy);
            copy.destroy();
            image
        });
        self.views.remove(&Self::COPIED);
        result.map_err(|e| format!("{e:#}"))
    }
}
