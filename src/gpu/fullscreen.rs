//! Full-screen passes: a shader whose `vs_main` makes one triangle over the
//! viewport from the vertex index (no vertex buffers) and whose `fs_main`
//! shades every pixel. The lit sphere, the environment's display of its
//! accumulation and the lobe's copy into egui's pass are all drawn this way;
//! each draw may be clipped to a rectangle (a sphere's tile, a band of rows).

/// The render pipeline of a full-screen shader writing one colour target of
/// `format` (no blending, no depth, one sample). `layout` `None` takes the
/// shader's own bindings.
pub fn pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: Option<&wgpu::PipelineLayout>,
    module: &wgpu::ShaderModule,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    pipeline_with(device, label, layout, module, "fs_main", format)
}

/// [`pipeline`] with the fragment entry point `fragment` instead of
/// `fs_main` (a shader with two ways of shading the same triangle).
pub fn pipeline_with(
    device: &wgpu::Device,
    label: &str,
    layout: Option<&wgpu::PipelineLayout>,
    module: &wgpu::ShaderModule,
    fragment: &str,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout,
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fragment),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// One full-screen triangle: its pipeline, its group-0 bindings and the
/// pixels it may touch (`[x, y, width, height]`; `None`: all of them).
#[derive(Debug, Clone, Copy)]
pub struct Draw<'a> {
    /// The pipeline (from [`pipeline`]).
    pub pipeline: &'a wgpu::RenderPipeline,
    /// Bind group 0.
    pub bind_group: &'a wgpu::BindGroup,
    /// Scissor rectangle in pixels.
    pub scissor: Option<[u32; 4]>,
}

/// Records `draw` into a pass already begun (egui's, or [`pass`]'s).
pub fn draw(pass: &mut wgpu::RenderPass<'_>, draw: &Draw<'_>) {
    pass.set_pipeline(draw.pipeline);
    pass.set_bind_group(0, draw.bind_group, &[]);
    if let Some([x, y, w, h]) = draw.scissor {
        pass.set_scissor_rect(x, y, w, h);
    }
    pass.draw(0..3, 0..1);
}

/// Records a pass that clears `view` to black and then makes `draws`, in
/// order.
pub fn pass(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    view: &wgpu::TextureView,
    draws: &[Draw<'_>],
) {
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    for d in draws {
        draw(&mut pass, d);
    }
}
