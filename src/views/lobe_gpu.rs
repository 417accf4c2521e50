//! The lobe view's own wgpu pipeline.
//!
//! A [`LobeFrame`] (CPU side: camera, meshes, line segments) is drawn into an
//! offscreen multisampled colour + depth target, then copied into egui's render
//! pass. Drawing offscreen gives the lobe a depth buffer and MSAA whatever egui's
//! own pass has (eframe's window has neither; kittest's has neither), and the
//! same code renders a frame headless ([`LobeRenderer::render_to_image`]), which
//! is what `bv render` and the snapshot tests use.
//!
//! In a window, [`install`] puts a [`LobeRenderer`] into egui-wgpu's callback
//! resources once; each frame the view adds a [`LobeCallback`], whose `prepare`
//! uploads what changed and records the offscreen pass, and whose `paint` blits
//! the result into the viewport egui sets for it.

use super::camera::CameraMatrices;
use super::colormap;
use bv_core::lobe::LobeMesh;
use eframe::egui;
use eframe::egui_wgpu::{self, CallbackResources, CallbackTrait, ScreenDescriptor};
use eframe::wgpu;
use eframe::wgpu::util::DeviceExt as _;
use std::collections::HashMap;
use std::sync::Arc;

/// Colour format of the offscreen target (gamma-encoded, like egui's).
pub const OFFSCREEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Depth format of the offscreen target.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The lobe surface shader, with the colour map table filled in.
pub fn lobe_shader_source() -> String {
    include_str!("../../shaders/lobe.wgsl").replace("COLORMAP_TABLE", &colormap::wgsl_table())
}

/// The screen-space line shader.
pub const LINES_WGSL: &str = include_str!("../../shaders/lines.wgsl");

/// The shader that copies the offscreen image into egui's pass.
pub const BLIT_WGSL: &str = include_str!("../../shaders/blit.wgsl");

/// How one lobe is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshStyle {
    /// Colour by value through the colour map (else `color`).
    pub by_value: bool,
    /// Solid colour, sRGB 0..1.
    pub color: [f32; 3],
    /// Opacity (1 = opaque and writes depth; less is blended after the opaque
    /// ones).
    pub alpha: f32,
    /// Draw grid lines instead of the filled surface.
    pub wireframe: bool,
    /// Value that maps to the top of the colour map.
    pub value_max: f32,
    /// Colour map on ln(1 + v) (matches the log radius).
    pub log: bool,
    /// World units per radius unit.
    pub scale: f32,
    /// Flat colour without shading (the ground disc).
    pub unlit: bool,
}

/// One mesh to draw.
#[derive(Debug, Clone)]
pub struct MeshDraw {
    /// Identifies the mesh's GPU buffers within a view (e.g. the BRDF id).
    pub key: u64,
    /// Changes whenever the mesh data changes (buffers are re-uploaded then).
    pub revision: u64,
    /// The mesh.
    pub mesh: Arc<LobeMesh>,
    /// How to draw it.
    pub style: MeshStyle,
}

/// A screen-space-width segment in world space.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LineSeg {
    /// Start.
    pub a: [f32; 3],
    /// End.
    pub b: [f32; 3],
    /// sRGB colour and opacity.
    pub color: [f32; 4],
    /// x: width in points (the rest is padding).
    pub width: [f32; 4],
}

impl LineSeg {
    /// A segment from `a` to `b`.
    pub fn new(a: glam::Vec3, b: glam::Vec3, color: [f32; 4], width: f32) -> Self {
        Self {
            a: a.to_array(),
            b: b.to_array(),
            color,
            width: [width, 0.0, 0.0, 0.0],
        }
    }
}

/// Everything one lobe view draws in one frame.
#[derive(Debug, Clone)]
pub struct LobeFrame {
    /// Camera of the frame (its viewport is in points).
    pub camera: CameraMatrices,
    /// Clear colour, sRGB 0..1.
    pub background: [f32; 4],
    /// Meshes, in drawing order within each pass (opaque first, then blended).
    pub meshes: Vec<MeshDraw>,
    /// Line segments (drawn after opaque meshes, before blended ones).
    pub lines: Vec<LineSeg>,
    /// Something is being dragged: on a software renderer the frame is then
    /// drawn without multisampling, which keeps a slider drag smooth.
    pub interacting: bool,
}

impl LobeFrame {
    /// A fingerprint of everything that affects the image (meshes by key and
    /// revision), so an unchanged frame is not drawn again.
    fn fingerprint(&self, size: [u32; 2], ppp: f32) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        let floats = |h: &mut std::collections::hash_map::DefaultHasher, xs: &[f32]| {
            for x in xs {
                x.to_bits().hash(h);
            }
        };
        floats(&mut h, &self.camera.view_proj.to_cols_array());
        floats(&mut h, &self.camera.eye.to_array());
        floats(&mut h, &self.background);
        floats(&mut h, &[ppp]);
        size.hash(&mut h);
        for m in &self.meshes {
            (m.key, m.revision).hash(&mut h);
            let s = StyleUniform::new(&m.style);
            bytemuck::bytes_of(&s).hash(&mut h);
        }
        bytemuck::cast_slice::<LineSeg, u8>(&self.lines).hash(&mut h);
        h.finish()
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Globals {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    viewport: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct StyleUniform {
    color: [f32; 4],
    params: [f32; 4],
    extra: [f32; 4],
}

impl StyleUniform {
    fn new(s: &MeshStyle) -> Self {
        Self {
            color: [s.color[0], s.color[1], s.color[2], s.alpha],
            params: [
                f32::from(u8::from(s.by_value)),
                s.value_max,
                f32::from(u8::from(s.log)),
                s.scale,
            ],
            extra: [f32::from(u8::from(s.unlit)), 0.0, 0.0, 0.0],
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Vertex {
    pos: [f32; 3],
    normal: [f32; 3],
    value: f32,
}

struct GpuMesh {
    revision: u64,
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    wire_indices: wgpu::Buffer,
    wire_count: u32,
    style: wgpu::Buffer,
    style_bg: wgpu::BindGroup,
    used: bool,
}

struct Target {
    size: [u32; 2],
    samples: u32,
    /// Fingerprint of the frame the target holds.
    drawn: Option<u64>,
    msaa_color: Option<wgpu::TextureView>,
    depth: wgpu::TextureView,
    resolve: wgpu::Texture,
    resolve_view: wgpu::TextureView,
    blit_bg: wgpu::BindGroup,
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
    /// Pipelines at the full sample count, then (software renderers only) at one
    /// sample for frames drawn while something is dragged.
    sets: Vec<Pipelines>,
    globals_layout: wgpu::BindGroupLayout,
    style_layout: wgpu::BindGroupLayout,
    blit_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    blit: wgpu::RenderPipeline,
    views: HashMap<u64, ViewResources>,
}

/// The drawing pipelines for one sample count.
struct Pipelines {
    samples: u32,
    opaque: wgpu::RenderPipeline,
    blended: wgpu::RenderPipeline,
    wire: wgpu::RenderPipeline,
    lines: wgpu::RenderPipeline,
}

/// The sample count used offscreen: 4 where the adapter supports it for both
/// formats, else 1. `BV_MSAA=1` turns multisampling off (software renderers
/// pay for every sample).
fn pick_samples(adapter: Option<&wgpu::Adapter>) -> u32 {
    let Some(adapter) = adapter else { return 1 };
    if std::env::var("BV_MSAA").is_ok_and(|v| v.trim() == "1") {
        return 1;
    }
    let ok = |f: wgpu::TextureFormat| {
        adapter
            .get_texture_format_features(f)
            .flags
            .sample_count_supported(4)
    };
    if ok(OFFSCREEN_FORMAT) && ok(DEPTH_FORMAT) {
        4
    } else {
        1
    }
}

impl LobeRenderer {
    /// Creates the pipelines; `target_format` is the format of the pass the
    /// result is copied into (the window's surface, or Rgba8Unorm headless).
    pub fn new(
        device: &wgpu::Device,
        adapter: Option<&wgpu::Adapter>,
        target_format: wgpu::TextureFormat,
    ) -> Self {
        let samples = pick_samples(adapter);
        // A CPU rasteriser pays for every sample: while something is dragged it
        // draws with one, and multisamples the frame once the drag ends.
        let software = adapter.is_some_and(|a| a.get_info().device_type == wgpu::DeviceType::Cpu);
        let uniform_entry = |visibility| wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let globals_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bv lobe globals"),
            entries: &[uniform_entry(
                wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
            )],
        });
        let style_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bv lobe style"),
            entries: &[uniform_entry(
                wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
            )],
        });
        let blit_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bv lobe blit"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        multisampled: false,
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("bv lobe blit sampler"),
            // The target matches the viewport pixel for pixel: linear sampling at
            // pixel centres copies it exactly.
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });

        let lobe_src = lobe_shader_source();
        let lobe_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("bv lobe.wgsl"),
            source: wgpu::ShaderSource::Wgsl(lobe_src.into()),
        });
        let lines_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("bv lines.wgsl"),
            source: wgpu::ShaderSource::Wgsl(LINES_WGSL.into()),
        });
        let blit_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("bv blit.wgsl"),
            source: wgpu::ShaderSource::Wgsl(BLIT_WGSL.into()),
        });

        let mesh_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("bv lobe mesh layout"),
            bind_group_layouts: &[Some(&globals_layout), Some(&style_layout)],
            immediate_size: 0,
        });
        let lines_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("bv lobe lines layout"),
            bind_group_layouts: &[Some(&globals_layout)],
            immediate_size: 0,
        });
        let blit_pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("bv lobe blit layout"),
            bind_group_layouts: &[Some(&blit_layout)],
            immediate_size: 0,
        });

        let alpha_blend = wgpu::BlendState::ALPHA_BLENDING;
        let vertex_layout = wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32],
        };
        let depth = |write: bool| {
            Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(write),
                depth_compare: Some(wgpu::CompareFunction::LessEqual),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            })
        };
        let mesh_pipeline =
            |label: &str, topology, write: bool, blend: Option<wgpu::BlendState>, multisample| {
                device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some(label),
                    layout: Some(&mesh_layout),
                    vertex: wgpu::VertexState {
                        module: &lobe_module,
                        entry_point: Some("vs_main"),
                        compilation_options: Default::default(),
                        buffers: &[Some(vertex_layout.clone())],
                    },
                    primitive: wgpu::PrimitiveState {
                        topology,
                        cull_mode: None,
                        ..Default::default()
                    },
                    depth_stencil: depth(write),
                    multisample,
                    fragment: Some(wgpu::FragmentState {
                        module: &lobe_module,
                        entry_point: Some("fs_main"),
                        compilation_options: Default::default(),
                        targets: &[Some(wgpu::ColorTargetState {
                            format: OFFSCREEN_FORMAT,
                            blend,
                            write_mask: wgpu::ColorWrites::ALL,
                        })],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            };

        let seg_layout = wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<LineSeg>() as u64,
            step_mode: wgpu::VertexStepMode::Instance,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x4, 3 => Float32x4],
        };
        let lines_pipeline = |multisample| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("bv lobe lines"),
                layout: Some(&lines_layout),
                vertex: wgpu::VertexState {
                    module: &lines_module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(seg_layout.clone())],
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: depth(false),
                multisample,
                fragment: Some(wgpu::FragmentState {
                    module: &lines_module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: OFFSCREEN_FORMAT,
                        blend: Some(alpha_blend),
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let make_set = |samples: u32| {
            let ms = wgpu::MultisampleState {
                count: samples,
                mask: !0,
                alpha_to_coverage_enabled: false,
            };
            Pipelines {
                samples,
                opaque: mesh_pipeline(
                    "bv lobe opaque",
                    wgpu::PrimitiveTopology::TriangleList,
                    true,
                    None,
                    ms,
                ),
                blended: mesh_pipeline(
                    "bv lobe blended",
                    wgpu::PrimitiveTopology::TriangleList,
                    false,
                    Some(alpha_blend),
                    ms,
                ),
                wire: mesh_pipeline(
                    "bv lobe wire",
                    wgpu::PrimitiveTopology::LineList,
                    true,
                    Some(alpha_blend),
                    ms,
                ),
                lines: lines_pipeline(ms),
            }
        };
        let mut sets = vec![make_set(samples)];
        if software && samples > 1 {
            sets.push(make_set(1));
        }
        let blit = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("bv lobe blit"),
            layout: Some(&blit_pl),
            vertex: wgpu::VertexState {
                module: &blit_module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &blit_module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: target_format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });

        Self {
            sets,
            globals_layout,
            style_layout,
            blit_layout,
            sampler,
            blit,
            views: HashMap::new(),
        }
    }

    /// The offscreen sample count of frames drawn at rest.
    pub fn samples(&self) -> u32 {
        self.sets[0].samples
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
        let set = match self.sets.get(1) {
            Some(fast) if frame.interacting => fast,
            _ => &self.sets[0],
        };
        let samples = set.samples;
        let fingerprint = frame.fingerprint(size, ppp) ^ u64::from(samples);
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
                vr.meshes
                    .insert(d.key, upload_mesh(device, style_layout, d));
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

    /// Blits view `view`'s offscreen image into the current pass (whose viewport
    /// egui has set to the callback's rectangle).
    pub fn paint(&self, view: u64, pass: &mut wgpu::RenderPass<'static>) {
        let Some(target) = self.views.get(&view).and_then(|v| v.target.as_ref()) else {
            return;
        };
        pass.set_pipeline(&self.blit);
        pass.set_bind_group(0, &target.blit_bg, &[]);
        pass.draw(0..3, 0..1);
    }

    /// Renders `frame` headless at `width × height` pixels and reads it back
    /// (for `bv render` and tests). `ppp` scales line widths.
    pub fn render_to_image(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        frame: &LobeFrame,
        width: u32,
        height: u32,
        ppp: f32,
    ) -> Result<image::RgbaImage, String> {
        // A view key of its own, so a window's targets are left alone.
        const HEADLESS: u64 = u64::MAX;
        crate::gpu::errors::scoped(device, "drawing the lobe", || {
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("bv lobe headless"),
            });
            self.prepare(
                device,
                queue,
                &mut encoder,
                HEADLESS,
                frame,
                PixelSize {
                    size: [width, height],
                    ppp,
                },
            );
            queue.submit(std::iter::once(encoder.finish()));
            let target = self
                .views
                .get(&HEADLESS)
                .and_then(|v| v.target.as_ref())
                .ok_or_else(|| anyhow::anyhow!("no target"))?;
            crate::gpu::context::read_rgba8(device, queue, &target.resolve)
        })
        .map_err(|e| format!("{e:#}"))
    }
}

/// The largest size within `max` pixels per side with the aspect of `size`
/// (the lobe's offscreen target is stretched over the callback rectangle,
/// so a window or figure wider than the device's textures still draws).
pub fn fit_texture(size: [u32; 2], max: u32) -> [u32; 2] {
    let [w, h] = [size[0].max(1), size[1].max(1)];
    let max = max.max(1);
    if w <= max && h <= max {
        return [w, h];
    }
    let s = f64::from(max) / f64::from(w.max(h));
    [
        ((f64::from(w) * s).floor() as u32).clamp(1, max),
        ((f64::from(h) * s).floor() as u32).clamp(1, max),
    ]
}

fn create_target(
    device: &wgpu::Device,
    blit_layout: &wgpu::BindGroupLayout,
    sampler: &wgpu::Sampler,
    size: [u32; 2],
    samples: u32,
) -> Target {
    let extent = wgpu::Extent3d {
        width: size[0],
        height: size[1],
        depth_or_array_layers: 1,
    };
    let tex = |label: &str, format, sample_count, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: extent,
            mip_level_count: 1,
            sample_count,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let resolve = tex(
        "bv lobe colour",
        OFFSCREEN_FORMAT,
        1,
        wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
    );
    let resolve_view = resolve.create_view(&Default::default());
    let msaa_color = (samples > 1).then(|| {
        tex(
            "bv lobe colour msaa",
            OFFSCREEN_FORMAT,
            samples,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default())
    });
    let depth = tex(
        "bv lobe depth",
        DEPTH_FORMAT,
        samples,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    )
    .create_view(&Default::default());
    let blit_bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("bv lobe blit"),
        layout: blit_layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&resolve_view),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::Sampler(sampler),
            },
        ],
    });
    Target {
        size,
        samples,
        drawn: None,
        msaa_color,
        depth,
        resolve,
        resolve_view,
        blit_bg,
    }
}

/// Grid lines of a lobe mesh (rings and meridians, thinned to about 24 × 48
/// so a wireframe stays readable at any resolution).
pub fn wire_indices(mesh: &LobeMesh) -> Vec<u32> {
    let (nt, np) = (mesh.n_theta, mesh.n_phi);
    if nt == 0 || np == 0 || mesh.positions.len() < (nt + 1) * np {
        return Vec::new();
    }
    let ring_step = nt.div_ceil(24).max(1);
    let meridian_step = np.div_ceil(48).max(1);
    let idx = |i: usize, j: usize| (i * np + j % np) as u32;
    let mut out = Vec::new();
    for i in (ring_step..=nt).step_by(ring_step) {
        for j in 0..np {
            out.extend_from_slice(&[idx(i, j), idx(i, j + 1)]);
        }
    }
    for j in (0..np).step_by(meridian_step) {
        for i in 0..nt {
            out.extend_from_slice(&[idx(i, j), idx(i + 1, j)]);
        }
    }
    out
}

fn upload_mesh(
    device: &wgpu::Device,
    style_layout: &wgpu::BindGroupLayout,
    d: &MeshDraw,
) -> GpuMesh {
    let m = &d.mesh;
    let vertices: Vec<Vertex> = m
        .positions
        .iter()
        .zip(&m.normals)
        .zip(&m.values)
        .map(|((p, n), v)| Vertex {
            pos: *p,
            normal: *n,
            value: (v[0] + v[1] + v[2]) / 3.0,
        })
        .collect();
    // Empty buffers are not allowed; a degenerate triangle keeps things simple.
    let vertices = if vertices.is_empty() {
        vec![Vertex {
            pos: [0.0; 3],
            normal: [0.0, 0.0, 1.0],
            value: 0.0,
        }]
    } else {
        vertices
    };
    let indices = if m.indices.is_empty() {
        vec![0u32; 3]
    } else {
        m.indices.clone()
    };
    let wire = wire_indices(m);
    let wire = if wire.is_empty() { vec![0u32; 2] } else { wire };
    let vb = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("bv lobe vertices"),
        contents: bytemuck::cast_slice(&vertices),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let ib = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("bv lobe indices"),
        contents: bytemuck::cast_slice(&indices),
        usage: wgpu::BufferUsages::INDEX,
    });
    let wb = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("bv lobe wire indices"),
        contents: bytemuck::cast_slice(&wire),
        usage: wgpu::BufferUsages::INDEX,
    });
    let style = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("bv lobe style"),
        contents: bytemuck::bytes_of(&StyleUniform::new(&d.style)),
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
    });
    let style_bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("bv lobe style"),
        layout: style_layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: style.as_entire_binding(),
        }],
    });
    GpuMesh {
        revision: d.revision,
        vertices: vb,
        index_count: indices.len() as u32,
        indices: ib,
        wire_count: wire.len() as u32,
        wire_indices: wb,
        style,
        style_bg,
        used: true,
    }
}

/// Puts a [`LobeRenderer`] for `target_format` into a renderer's callback
/// resources (once per window or test harness).
pub fn install_into(
    resources: &mut CallbackResources,
    device: &wgpu::Device,
    adapter: Option<&wgpu::Adapter>,
    target_format: wgpu::TextureFormat,
) {
    resources.insert(LobeRenderer::new(device, adapter, target_format));
}

/// Installs the lobe pipeline into egui-wgpu's render state (eframe's window or
/// a kittest harness's).
pub fn install(render_state: &egui_wgpu::RenderState) {
    let mut renderer = render_state.renderer.write();
    install_into(
        &mut renderer.callback_resources,
        &render_state.device,
        Some(&render_state.adapter),
        render_state.target_format,
    );
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
        _info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &CallbackResources,
    ) {
        if let Some(r) = resources.get::<LobeRenderer>() {
            r.paint(self.view, pass);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_fit_the_device_keeping_the_aspect() {
        assert_eq!(fit_texture([800, 600], 8192), [800, 600]);
        assert_eq!(fit_texture([0, 0], 8192), [1, 1]);
        assert_eq!(fit_texture([20000, 10000], 8192), [8192, 4096]);
        assert_eq!(fit_texture([100, 40000], 8192), [20, 8192]);
    }

    #[test]
    fn wireframe_indices_stay_in_range() {
        let b = bv_core::ModelSpec::new("lambert").unwrap().build().unwrap();
        let m = bv_core::lobe::build(b.as_ref(), glam::DVec3::Z, &Default::default());
        let w = wire_indices(&m);
        assert!(!w.is_empty());
        assert_eq!(w.len() % 2, 0);
        assert!(w.iter().all(|&i| (i as usize) < m.positions.len()));
    }
}
