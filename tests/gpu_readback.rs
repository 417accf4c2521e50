//! Reading images back: the blocking readback and the one a browser page
//! polls once a frame give the pixels that were written, for widths with and
//! without row padding (wgpu copies rows in multiples of 256 bytes).

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::gpu::gpu_for_test;
use bv::gpu::readback::{read_rgba8, start_rgba8};
use std::time::{Duration, Instant};

/// A texture of `w × h` pixels holding a pattern no two pixels share.
fn patterned(gpu: &bv::gpu::Gpu, w: u32, h: u32) -> (wgpu::Texture, Vec<u8>) {
    let pixels: Vec<u8> = (0..w * h)
        .flat_map(|i| {
            let (x, y) = (i % w, i / w);
            [
                (x % 251) as u8,
                (y % 241) as u8,
                ((x * 7 + y * 13) % 256) as u8,
                255,
            ]
        })
        .collect();
    let size = wgpu::Extent3d {
        width: w,
        height: h,
        depth_or_array_layers: 1,
    };
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("patterned"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    gpu.queue.write_texture(
        texture.as_image_copy(),
        &pixels,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(4 * w),
            rows_per_image: Some(h),
        },
        size,
    );
    (texture, pixels)
}

#[test]
fn both_readbacks_give_the_pixels_written() {
    let Some(gpu) = gpu_for_test() else { return };
    for (w, h) in [(1, 1), (64, 3), (300, 7), (1000, 33)] {
        let (texture, want) = patterned(&gpu, w, h);
        let blocking = read_rgba8(&gpu.device, &gpu.queue, &texture).unwrap();
        assert_eq!(blocking.dimensions(), (w, h));
        assert!(
            blocking.as_raw() == &want,
            "{w}×{h}: the blocking readback differs"
        );

        let mut pending = start_rgba8(&gpu.device, &gpu.queue, &texture).unwrap();
        let t0 = Instant::now();
        let polled = loop {
            if let Some(img) = pending.poll(&gpu.device) {
                break img.unwrap();
            }
            assert!(
                t0.elapsed() < Duration::from_secs(30),
                "{w}×{h}: never read back"
            );
            std::thread::sleep(Duration::from_millis(1));
        };
        assert_eq!(polled.dimensions(), (w, h));
        assert!(
            polled.as_raw() == &want,
            "{w}×{h}: the polled readback differs"
        );
    }
}
