//! Priming the lobe's pipelines: one frame that draws nothing visible with
//! every pipeline a lobe figure uses, submitted as soon as the pipelines
//! exist and never waited for.
//!
//! A CPU rasteriser (Mesa's lavapipe) compiles a pipeline's shaders for the
//! state they run in, or loads them from its disk cache, when the first draw
//! that uses them executes, on its queue thread. Measured on a 2-core Xeon
//! (lavapipe, LLVM 15), a figure's first frame took 40–47 ms longer to
//! execute than the same frame drawn again by the same process, and that
//! work began only when the figure was submitted, after egui's renderer was
//! made and the layout passes had run, while the submitting thread waited.
//! Primed, the lobe's share of it runs on the queue thread while the caller
//! goes on with those: `bv render --view lobe3d` at 1600 × 1200 went from a
//! median of 0.25 s to 0.23 s (12 interleaved runs each). A GPU driver
//! compiles when the pipeline is made, so there the frame costs a few empty
//! draws.

use super::{LobeCamera, LobeFrame, LobeRenderer, MeshDraw, MeshStyle, PixelSize};
use bv_core::lobe::LobeMesh;
use std::sync::Arc;

/// Side in pixels of the priming frame's targets: not a power of two, as a
/// figure's sides seldom are (a CPU rasteriser may specialise its texture
/// reads on that).
const PRIME_SIDE: u32 = 3;

impl LobeRenderer {
    /// Records and submits a frame with one empty mesh in each way a mesh is
    /// drawn (opaque, wireframe, translucent), one line segment, and its copy
    /// into a small texture of the renderer's target format through the
    /// copies a figure at rest uses, without waiting for it. Its resources are released once
    /// submitted; the pipelines and the driver's compiled shaders stay.
    pub fn prime(&mut self, device: &wgpu::Device, queue: &wgpu::Queue) {
        let mesh = |alpha: f32, wireframe: bool, key: u64| MeshDraw {
            key,
            revision: 0,
            // An empty mesh is uploaded as one degenerate triangle: every
            // draw runs, none covers a pixel.
            mesh: Arc::new(LobeMesh::default()),
            style: MeshStyle {
                by_value: true,
                color: [1.0; 3],
                alpha,
                wireframe,
                value_max: 1.0,
                log: false,
                scale: 1.0,
                unlit: false,
            },
        };
        let frame = LobeFrame {
            camera: LobeCamera {
                view_proj: glam::Mat4::IDENTITY,
                eye: glam::Vec3::Z,
            },
            background: [0.0; 4],
            meshes: vec![mesh(1.0, false, 0), mesh(1.0, true, 1), mesh(0.5, false, 2)],
            // A segment of no length: drawn, and covering nothing.
            lines: vec![super::LineSeg::new(
                glam::Vec3::ZERO,
                glam::Vec3::ZERO,
                [1.0; 4],
                1.0,
            )],
            interacting: false,
        };
        let label = "bv lobe priming";
        let pixels = PixelSize {
            size: [PRIME_SIDE; 2],
            ppp: 1.0,
        };
        let mut encoder = self.record_frame(device, queue, label, Self::PRIMING, &frame, pixels);
        // The line's pixels get FXAA, the rest the plain copy: both copies'
        // pipelines run.
        let usage = wgpu::TextureUsages::empty();
        let copy = self.record_copy(device, &mut encoder, label, Self::PRIMING, usage);
        queue.submit(std::iter::once(encoder.finish()));
        // wgpu keeps what the submitted work uses alive until it is done.
        drop(copy);
        self.views.remove(&Self::PRIMING);
    }
}
