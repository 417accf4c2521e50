//! Reading GPU results back to the CPU: the one place that copies into a
//! `MAP_READ` staging buffer and maps it. [`read_rgba8`] brings back an
//! `Rgba8Unorm` texture (every rendered image: lit sphere, environment, lobe,
//! egui figures) and waits, [`start_rgba8`] does so without waiting (a
//! browser page's figures), [`read_buffer`] the bytes of a storage buffer (GPU
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

/// The row layout of an `Rgba8Unorm` texture's readback: rows padded to
/// wgpu's copy alignment, in bands of rows that each fit the device's largest
/// buffer (a 16384-pixel square is 1 GiB, four times what lavapipe allows in
/// one buffer).
struct Bands {
    width: u32,
    height: u32,
    /// Bytes of one image row.
    row: usize,
    /// Bytes of one row in the buffer.
    padded: usize,
    /// Rows per band.
    band: u32,
}

impl Bands {
    fn of(device: &wgpu::Device, texture: &wgpu::Texture) -> Result<Self> {
        let (w, h) = (texture.width(), texture.height());
        let row = 4 * w as usize;
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as usize;
        let padded = row.div_ceil(align) * align;
        let max = device.limits().max_buffer_size;
        if padded as u64 > max {
            bail!(
                "reading back an image {w} pixels wide needs rows of {padded} bytes; this \
                 device's buffers hold at most {max} bytes"
            );
        }
        let band = (max / padded as u64).clamp(1, u64::from(h.max(1))) as u32;
        Ok(Self {
            width: w,
            height: h,
            row,
            padded,
            band,
        })
    }

    /// `(first row, rows)` of every band.
    fn ranges(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        (0..self.height)
            .step_by(self.band as usize)
            .map(|y| (y, self.band.min(self.height - y)))
    }

    /// Submits the copy of `rows` rows from row `y` into a new staging buffer.
    fn copy(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        texture: &wgpu::Texture,
        (y, rows): (u32, u32),
    ) -> (wgpu::Buffer, u64) {
        let size = self.padded as u64 * u64::from(rows);
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
                    bytes_per_row: Some(self.padded as u32),
                    rows_per_image: Some(rows),
                },
            },
            wgpu::Extent3d {
                width: self.width,
                height: rows,
                depth_or_array_layers: 1,
            },
        );
        queue.submit([enc.finish()]);
        (buffer, size)
    }

    /// Appends the unpadded rows of a band's bytes to `pixels`.
    fn unpad(&self, bytes: &[u8], pixels: &mut Vec<u8>) {
        for r in bytes.chunks_exact(self.padded) {
            pixels.extend_from_slice(&r[..self.row]);
        }
    }

    fn image(&self, pixels: Vec<u8>) -> Result<image::RgbaImage> {
        image::RgbaImage::from_raw(self.width, self.height, pixels)
            .context("readback has the wrong size")
    }
}

/// Reads an `Rgba8Unorm` texture (with `COPY_SRC`) back as an image, band by
/// band (one staging buffer at a time), waiting for the work already
/// submitted that renders into the texture.
pub fn read_rgba8(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
) -> Result<image::RgbaImage> {
    let bands = Bands::of(device, texture)?;
    errors::scoped(device, "reading the image back", || {
        let mut pixels = Vec::with_capacity(bands.row * bands.height as usize);
        for range in bands.ranges() {
            let (buffer, size) = bands.copy(device, queue, texture, range);
            let bytes = map_read(device, &buffer, size)?;
            bands.unpad(&bytes, &mut pixels);
            buffer.destroy();
        }
        bands.image(pixels)
    })
}

/// An image being read back without waiting: its copies are submitted and
/// its staging buffers' mappings asked for; [`PendingImage::poll`] takes the
/// image once the GPU is done. Why: a browser maps buffers only when the
/// page returns to its event loop, so a page that waited for a mapping would
/// wait for ever; it polls once a frame instead.
pub struct PendingImage {
    bands: Bands,
    /// Each band's staging buffer, its size, and the news of its mapping
    /// (`None` once it came).
    staged: Vec<(wgpu::Buffer, u64, Option<Receiver>)>,
}

type Receiver = std::sync::mpsc::Receiver<Result<(), wgpu::BufferAsyncError>>;

impl std::fmt::Debug for PendingImage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PendingImage")
            .field("width", &self.bands.width)
            .field("height", &self.bands.height)
            .finish_non_exhaustive()
    }
}

/// Starts reading an `Rgba8Unorm` texture (with `COPY_SRC`) back, after the
/// work already submitted that renders into it; every band's staging buffer
/// is made at once.
pub fn start_rgba8(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
) -> Result<PendingImage> {
    let bands = Bands::of(device, texture)?;
    errors::scoped(device, "reading the image back", || {
        let staged = bands
            .ranges()
            .map(|range| {
                let (buffer, size) = bands.copy(device, queue, texture, range);
                let (tx, rx) = std::sync::mpsc::channel();
                buffer
                    .slice(..size)
                    .map_async(wgpu::MapMode::Read, move |r| {
                        // The receiver goes only with the PendingImage.
                        let _ = tx.send(r);
                    });
                (buffer, size, Some(rx))
            })
            .collect();
        Ok(PendingImage { bands, staged })
    })
}

impl PendingImage {
    /// The image if the GPU is done (`None` while it is not), without
    /// blocking.
    pub fn poll(&mut self, device: &wgpu::Device) -> Option<Result<image::RgbaImage>> {
        // Native backends call the mapping callbacks from a poll; a browser
        // calls them from its event loop (the poll does nothing there).
        let _ = device.poll(wgpu::PollType::Poll);
        let mut waiting = false;
        for (_, _, news) in &mut self.staged {
            let Some(rx) = news else { continue };
            match rx.try_recv() {
                Ok(Ok(())) => *news = None,
                Ok(Err(e)) => return Some(Err(anyhow!("mapping a readback buffer: {e}"))),
                Err(std::sync::mpsc::TryRecvError::Empty) => waiting = true,
                Err(std::sync::mpsc::TryRecvError::Disconnected) => {
                    return Some(Err(anyhow!("the GPU dropped a buffer mapping")));
                }
            }
        }
        if waiting {
            return None;
        }
        let mut pixels = Vec::with_capacity(self.bands.row * self.bands.height as usize);
        for (buffer, size, _) in &self.staged {
            let slice = buffer.slice(..*size);
            match slice.get_mapped_range() {
                Ok(bytes) => self.bands.unpad(&bytes, &mut pixels),
                Err(e) => return Some(Err(anyhow!("reading a mapped buffer: {e:?}"))),
            }
            buffer.unmap();
        }
        Some(self.bands.image(pixels))
    }
}

impl Drop for PendingImage {
    fn drop(&mut self) {
        for (buffer, _, _) in &self.staged {
            buffer.destroy();
        }
    }
}
