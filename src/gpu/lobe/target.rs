//! The lobe's offscreen targets: a colour and depth pair (multisampled,
//! then resolved into a single-sample colour texture, where multisampling is
//! cheap), which is read back headless
//! or copied into egui's pass; sized to fit the device.

use super::{DEPTH_FORMAT, OFFSCREEN_FORMAT};

pub(super) struct Target {
    pub(super) size: [u32; 2],
    pub(super) samples: u32,
    /// Fingerprint of the frame the target holds.
    pub(super) drawn: Option<u64>,
    /// Whether it is copied into egui's pass through FXAA (one sample, at
    /// rest).
    pub(super) smooth: bool,
    /// Where the smoothed copy needs FXAA, and the fingerprint of the image
    /// it was found for.
    pub(super) content: Option<(u64, super::Content)>,
    pub(super) msaa_color: Option<wgpu::TextureView>,
    pub(super) depth: wgpu::TextureView,
    pub(super) resolve: wgpu::Texture,
    pub(super) resolve_view: wgpu::TextureView,
    pub(super) blit_bg: wgpu::BindGroup,
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

pub(super) fn create_target(
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
        smooth: false,
        content: None,
        msaa_color,
        depth,
        resolve,
        resolve_view,
        blit_bg,
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
}
