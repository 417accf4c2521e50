//! What the lobe renderer draws in one frame, as plain data: meshes with
//! their styles, screen-width line segments and the camera's matrices (the
//! view computes them; the renderer only uploads them).

use bv_core::lobe::LobeMesh;
use std::sync::Arc;

/// The camera of a frame as the shaders take it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobeCamera {
    /// World to clip (wgpu convention: depth 0..1).
    pub view_proj: glam::Mat4,
    /// Eye position in world space (for shading).
    pub eye: glam::Vec3,
}

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
    /// Camera of the frame.
    pub camera: LobeCamera,
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
    pub(super) fn fingerprint(&self, size: [u32; 2], ppp: f32) -> u64 {
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
pub(super) struct StyleUniform {
    pub(super) color: [f32; 4],
    pub(super) params: [f32; 4],
    pub(super) extra: [f32; 4],
}

impl StyleUniform {
    pub(super) fn new(s: &MeshStyle) -> Self {
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
