//! The lobe renderer's pipelines: opaque, blended and wireframe surfaces and
//! screen-space lines at the offscreen sample count, and the copies of the
//! result into egui's pass (as it stands, or through FXAA where the target
//! has one sample).

use super::frame::LineSeg;
use super::mesh::Vertex;
use super::{DEPTH_FORMAT, LobeRenderer, OFFSCREEN_FORMAT};
use crate::gpu::fullscreen;
use crate::gpu::pipeline_cache::DiskPipelineCache;
use anyhow::Result;
use std::collections::HashMap;

/// The drawing pipelines for one sample count.
pub(super) struct Pipelines {
    pub(super) samples: u32,
    pub(super) opaque: wgpu::RenderPipeline,
    pub(super) blended: wgpu::RenderPipeline,
    pub(super) wire: wgpu::RenderPipeline,
    pub(super) lines: wgpu::RenderPipeline,
}

/// What the drawing pipelines are made from.
struct PipelineParts {
    /// The pipeline cache kept on disk, where the backend has one.
    cache: Option<DiskPipelineCache>,
    lobe_module: wgpu::ShaderModule,
    lines_module: wgpu::ShaderModule,
    mesh_layout: wgpu::PipelineLayout,
    lines_layout: wgpu::PipelineLayout,
}

/// The sample count used offscreen: 4 where the adapter supports it for both
/// formats and multisampling is cheap, else 1, whose edges the copy into
/// egui's pass smooths with FXAA (`blit.wgsl`'s `fs_smooth`). A CPU
/// rasteriser (lavapipe) pays for every sample: four made a 1600 × 1200
/// figure's lobe pass two to three times as long as one (0.24–0.48 s against
/// 0.13–0.15 s on a 2-core Xeon), for edges the FXAA copy smooths as well.
/// `BV_MSAA=1` or `BV_MSAA=4` overrides the choice (4 only where
/// supported).
fn pick_samples(adapter: Option<&wgpu::Adapter>) -> u32 {
    let Some(adapter) = adapter else { return 1 };
    let asked = std::env::var("BV_MSAA").ok();
    match asked.as_deref().map(str::trim) {
        Some("1") => return 1,
        Some("4") => {}
        _ if adapter.get_info().device_type == wgpu::DeviceType::Cpu => return 1,
        _ => {}
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
    /// Creates the pipelines, its shaders composed by the [`ShaderLibrary`];
    /// `target_format` is the format of the pass the result is copied into
    /// (the window's surface, or Rgba8Unorm headless).
    pub fn new(
        device: &wgpu::Device,
        adapter: Option<&wgpu::Adapter>,
        target_format: wgpu::TextureFormat,
    ) -> Result<Self> {
        let samples = pick_samples(adapter);
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

        let sources = super::sources::sources()?;
        let module = |name: &str, wgsl: &str| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(name),
                source: wgpu::ShaderSource::Wgsl(wgsl.into()),
            })
        };
        let lobe_module = module("lobe", &sources.lobe);
        let lines_module = module("lines", &sources.lines);
        let blit_module = module("blit", &sources.blit);

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

        let parts = PipelineParts {
            cache: adapter.and_then(|a| DiskPipelineCache::open(device, &a.get_info())),
            lobe_module,
            lines_module,
            mesh_layout,
            lines_layout,
        };
        let pipelines = parts.make_set(device, samples);
        let blit = fullscreen::pipeline(
            device,
            "bv lobe blit",
            Some(&blit_pl),
            &blit_module,
            target_format,
        );
        // Compiled only where it is used: a driver compiles a pipeline's
        // shaders when it is made, and a multisampled target never needs it.
        let blit_smooth = (samples == 1).then(|| {
            fullscreen::pipeline_with(
                device,
                "bv lobe blit (FXAA)",
                Some(&blit_pl),
                &blit_module,
                "fs_smooth",
                target_format,
            )
        });

        Ok(Self {
            pipelines,
            globals_layout,
            style_layout,
            blit_layout,
            sampler,
            blit,
            blit_smooth,
            smooth_everywhere: false,
            target_format,
            views: HashMap::new(),
        })
    }
}

impl PipelineParts {
    /// The drawing pipelines at `samples` samples (the disk cache updated
    /// with them).
    fn make_set(&self, device: &wgpu::Device, samples: u32) -> Pipelines {
        let pc = self.cache.as_ref().map(DiskPipelineCache::cache);
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
                    layout: Some(&self.mesh_layout),
                    vertex: wgpu::VertexState {
                        module: &self.lobe_module,
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
                        module: &self.lobe_module,
                        entry_point: Some("fs_main"),
                        compilation_options: Default::default(),
                        targets: &[Some(wgpu::ColorTargetState {
                            format: OFFSCREEN_FORMAT,
                            blend,
                            write_mask: wgpu::ColorWrites::ALL,
                        })],
                    }),
                    multiview_mask: None,
                    cache: pc,
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
                layout: Some(&self.lines_layout),
                vertex: wgpu::VertexState {
                    module: &self.lines_module,
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
                    module: &self.lines_module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: OFFSCREEN_FORMAT,
                        blend: Some(alpha_blend),
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: pc,
            })
        };
        let ms = wgpu::MultisampleState {
            count: samples,
            mask: !0,
            alpha_to_coverage_enabled: false,
        };
        let set = Pipelines {
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
        };
        if let Some(cache) = &self.cache {
            // A cache that cannot be written costs the next run a compile,
            // nothing else: not worth an error.
            let _ = cache.save();
        }
        set
    }
}
