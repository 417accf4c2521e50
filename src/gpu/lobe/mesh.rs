//! The lobe meshes on the GPU: vertex, index and wireframe index buffers of
//! a [`LobeMesh`], and the uniform of its style.

use super::frame::{MeshDraw, StyleUniform};
use crate::gpu::context::buffer_init;
use bv_core::lobe::LobeMesh;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct Vertex {
    pub(super) pos: [f32; 3],
    pub(super) normal: [f32; 3],
    pub(super) value: f32,
}

pub(super) struct GpuMesh {
    pub(super) revision: u64,
    pub(super) vertices: wgpu::Buffer,
    /// The grid the index buffers were made for, if the mesh is one: a new
    /// revision on the same grid (a slider step at the same resolution)
    /// only rewrites the vertices.
    grid: Option<GridKey>,
    pub(super) indices: wgpu::Buffer,
    pub(super) index_count: u32,
    pub(super) wire_indices: wgpu::Buffer,
    pub(super) wire_count: u32,
    pub(super) style: wgpu::Buffer,
    pub(super) style_bg: wgpu::BindGroup,
    pub(super) used: bool,
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

/// What fixes a grid mesh's connectivity: rings, vertices per ring, whole
/// sphere, and the vertex and index counts they imply. bv-core builds the
/// triangle list of a grid from its resolution alone (and reuses it on the
/// same grounds), so equal keys mean equal index buffers; comparing the
/// lists themselves would read most of a megabyte on every slider step.
#[derive(Clone, Copy, PartialEq, Eq)]
struct GridKey([usize; 5]);

impl GridKey {
    /// The key of `m`; `None` for a mesh that is not a grid (the ground disc)
    /// or is empty.
    fn of(m: &LobeMesh) -> Option<Self> {
        let rows = m.n_theta.checked_add(1)?;
        let grid = m.n_theta > 0
            && m.n_phi > 0
            && m.positions.len() == rows * m.n_phi
            && m.indices.len() == m.n_theta * m.n_phi * 6;
        grid.then_some(Self([
            m.n_theta,
            m.n_phi,
            usize::from(m.full_sphere),
            m.positions.len(),
            m.indices.len(),
        ]))
    }
}

/// The vertices of a mesh as the vertex buffer holds them.
fn vertices_of(m: &LobeMesh) -> Vec<Vertex> {
    m.positions
        .iter()
        .zip(&m.normals)
        .zip(&m.values)
        .map(|((p, n), v)| Vertex {
            pos: *p,
            normal: *n,
            value: (v[0] + v[1] + v[2]) / 3.0,
        })
        .collect()
}

impl GpuMesh {
    /// Takes revision `d.revision` in place when it lies on the grid uploaded
    /// (the vertices are rewritten into the same buffer, the index buffers
    /// kept); `false` when a new upload is needed.
    pub(super) fn refill(&mut self, queue: &wgpu::Queue, d: &MeshDraw) -> bool {
        let m = &d.mesh;
        if self.grid.is_none() || GridKey::of(m) != self.grid {
            return false;
        }
        queue.write_buffer(&self.vertices, 0, bytemuck::cast_slice(&vertices_of(m)));
        self.revision = d.revision;
        true
    }
}

pub(super) fn upload_mesh(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    style_layout: &wgpu::BindGroupLayout,
    d: &MeshDraw,
) -> GpuMesh {
    let m = &d.mesh;
    let vertices = vertices_of(m);
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
    let vb = buffer_init(
        device,
        queue,
        "bv lobe vertices",
        bytemuck::cast_slice(&vertices),
        wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
    );
    let ib = buffer_init(
        device,
        queue,
        "bv lobe indices",
        bytemuck::cast_slice(&indices),
        wgpu::BufferUsages::INDEX,
    );
    let wb = buffer_init(
        device,
        queue,
        "bv lobe wire indices",
        bytemuck::cast_slice(&wire),
        wgpu::BufferUsages::INDEX,
    );
    let style = buffer_init(
        device,
        queue,
        "bv lobe style",
        bytemuck::bytes_of(&StyleUniform::new(&d.style)),
        wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
    );
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
        grid: GridKey::of(m),
        index_count: indices.len() as u32,
        indices: ib,
        wire_count: wire.len() as u32,
        wire_indices: wb,
        style,
        style_bg,
        used: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
