//! Batch evaluation of a model on the GPU (the parity test's compute pass, also
//! usable by any tool that wants GPU values of f).

use super::pack::{TableBuffer, Tables, pack};
use super::{Gpu, shaders::ShaderLibrary};
use anyhow::Result;
use bv_core::ModelSpec;
use wgpu::util::DeviceExt;

/// Evaluates packed models on batches of direction pairs with the `parity`
/// compute shader.
#[derive(Debug)]
pub struct GpuEvaluator {
    gpu: Gpu,
    pipeline: wgpu::ComputePipeline,
}

/// Threads per workgroup of `parity.wgsl`.
const WORKGROUP: u32 = 64;

impl GpuEvaluator {
    /// Builds the pipeline on `gpu`.
    pub fn new(gpu: Gpu, library: &mut ShaderLibrary) -> Result<Self> {
        let module = library.shader_module(&gpu.device, "parity")?;
        let pipeline = gpu
            .device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("parity"),
                layout: None,
                module: &module,
                entry_point: Some("main"),
                compilation_options: Default::default(),
                cache: None,
            });
        Ok(Self { gpu, pipeline })
    }

    /// The device it runs on.
    pub fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    /// `f(wi, wo)` of `spec` for every pair, computed by the WGSL port in f32.
    pub fn eval(&self, spec: &ModelSpec, pairs: &[([f32; 3], [f32; 3])]) -> Result<Vec<[f32; 3]>> {
        let mut params = Vec::new();
        let mut tables = Tables::default();
        let r = pack(spec, &mut params, &mut tables)?;
        if params.is_empty() {
            params.push(0.0);
        }
        let n = pairs.len();
        if n == 0 {
            return Ok(Vec::new());
        }
        let mut dirs = Vec::with_capacity(8 * n);
        for (wi, wo) in pairs {
            dirs.extend_from_slice(&[wi[0], wi[1], wi[2], 0.0, wo[0], wo[1], wo[2], 0.0]);
        }
        let count = u32::try_from(n)?;
        let d = &self.gpu.device;
        let usage_in = wgpu::BufferUsages::STORAGE;
        let pbuf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("params"),
            contents: bytemuck::cast_slice(&params),
            usage: usage_in,
        });
        let dbuf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("dirs"),
            contents: bytemuck::cast_slice(&dirs),
            usage: usage_in,
        });
        let job = [r.model, r.offset, count, 0];
        let jbuf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("job"),
            contents: bytemuck::cast_slice(&job),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let size = 16 * n as u64;
        let obuf = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("values"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        // A fresh buffer per call: the evaluator is a batch tool, not a view.
        let mut tbuf = TableBuffer::default();
        let tbuf = tbuf.get(&self.gpu, &tables)?;
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("parity"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[
                entry(0, &pbuf),
                entry(1, &dbuf),
                entry(2, &obuf),
                entry(3, &jbuf),
                entry(8, tbuf),
            ],
        });
        let mut enc = d.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(count.div_ceil(WORKGROUP), 1, 1);
        }
        self.gpu.queue.submit([enc.finish()]);
        let bytes = self.gpu.read_buffer(&obuf, size)?;
        let v: &[f32] = bytemuck::cast_slice(&bytes);
        Ok(v.chunks_exact(4).map(|c| [c[0], c[1], c[2]]).collect())
    }
}

fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}
