//! Reading GPU results back to the CPU: the one place that copies into a
//! `MAP_READ` staging buffer, maps it and waits. [`read_rgba8`] brings back an
//! `Rgba8Unorm` texture (every rendered image: lit sphere, environment, lobe,
//! egui figures), [`read_buffer`] the bytes of a storage buffer (GPU
//! evaluation, the environment's accumulated radiance).

use super::errors;
use anyhow::{Context, Result, anyhow, bail};

/// A fresh `MAP_READ | COPY_DST` staging buffer of `size` bytes.
fn staging(device: &wgpu::Device, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("bv readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Waits for `device` and copies a `MAP_READ` buffer's first `len` bytes back.
fn map_read(device: &wgpu::Device, buffer: &wgpu::Buffer, len: u64) -> Result<Vec<u8>> {
    let slice = buffer.slice(..len);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        // The receiver lives until recv() below returns.
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| anyhow!("waiting for the GPU: {e}"))?;
    rx.recv()
        .context("the GPU dropped a buffer mapping")?
        .map_err(|e| anyhow!("mapping a readback buffer: {e}"))?;
    let bytes = slice
        .get_mapped_range()
        .map_err(|e| anyhow!("reading a mapped buffer: {e:?}"))?
        .to_vec();
    buffer.unmap();
    Ok(bytes)
}

/// Copies the first `len` bytes of `buffer` (with `COPY_SRC`) into a staging
/// buffer and reads them back, after the work already submitted that writes
/// it. The caller runs it inside its error scope ([`errors::scoped`]).
pub fn read_buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    len: u64,
) -> Result<Vec<u8>> {
    let rb = staging(device, len);
    let mut enc = device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(buffer, 0, &rb, 0, len);
    queue.submit([enc.finish()]);
    let bytes = map_read(device, &rb, len);
    rb.destroy();
    bytes
}

/// Reads an `Rgba8Unorm` texture (with `COPY_SRC`) back as an image, in
/// bands of rows that each fit the device's largest buffer (a 16384-pixel
/// square is 1 GiB, four times what lavapipe allows in one buffer); rows are
/// padded to wgpu's copy alignment in the buffer and unpadded here. Work
/// already submitted that renders into the texture is waited for.
pub fn read_rgba8(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
) -> Result<image::RgbaImage> {
    let (w, h) = (texture.width(), texture.height());
    let row = 4 * w as usize;
    let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as usize;
    let padded = row.div_ceil(align) * align;
    let max = device.limits().max_buffer_size;
    let band = (max / padded as u64).clamp(1, u64::from(h.max(1))) as u32;
    if padded as u64 > max {
        bail!(
            "reading back an image {w} pixels wide needs rows of {padded} bytes; this device's \
             buffers hold at most {max} bytes"
        );
    }
    errors::scoped(device, "reading the image back", || {
        let mut pixels = Vec::with_capacity(row * h as usize);
        let mut y = 0;
        while y < h {
            let rows = band.min(h - y);
            let size = padded as u64 * u64::from(rows);
            let buffer = staging(device, size);
            let mut enc = device.create_command_encoder(&Default::default());
            enc.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x: 0, y, z: 0 },
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: &buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(padded as u32),
                        rows_per_image: Some(rows),
                    },
                },
                wgpu::Extent3d {
                    width: w,
                    height: rows,
                    depth_or_array_layers: 1,
                },
            );
            queue.submit([enc.finish()]);
            let bytes = map_read(device, &buffer, size)?;
            for r in bytes.chunks_exact(padded) {
                pixels.extend_from_slice(&r[..row]);
            }
            buffer.destroy();
            y += rows;
        }
        image::RgbaImage::from_raw(w, h, pixels).context("readback has the wrong size")
    })
}
