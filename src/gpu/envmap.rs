//! Equirectangular HDR environments as CPU data: [`EnvironmentMap`] (loading
//! and decoding Radiance `.hdr` or OpenEXR files, writing `.hdr`, the
//! procedural studio and the bundled copy of it) and the CDFs by which the
//! environment pass importance-samples it (`shaders/common/envmap.wgsl`).
//! Nothing here touches the GPU; [`super::env`] uploads a map and renders
//! under it.

use anyhow::{Context, Result, bail};
use std::f64::consts::PI;
use std::path::Path;

/// An equirectangular environment: `width × height` linear-RGB texels, row 0 at
/// the zenith (+y), column 0 at azimuth −π (φ measured from −z towards +x).
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentMap {
    /// Texels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Row-major radiance.
    pub texels: Vec<[f32; 3]>,
}

/// Largest accepted side of a loaded map (a hostile header must not allocate
/// gigabytes).
pub const MAX_ENV_SIDE: u32 = 16384;

impl EnvironmentMap {
    /// A constant environment (the white furnace when `c` is 1).
    pub fn constant(c: [f32; 3]) -> Self {
        Self {
            width: 8,
            height: 4,
            texels: vec![c; 32],
        }
    }

    /// Loads a Radiance `.hdr` or OpenEXR file (equirectangular): a regular
    /// file of at most [`bv_core::fsio::MAX_ENV_MAP_BYTES`] (a FIFO or a
    /// device is refused, not waited on).
    pub fn load(path: &Path) -> Result<Self> {
        let bytes = bv_core::fsio::read_capped(
            path,
            bv_core::fsio::MAX_ENV_MAP_BYTES,
            "an environment map",
        )?;
        Self::decode(&bytes, &path.display().to_string())
    }

    /// Writes the map as a Radiance `.hdr` file.
    pub fn save_hdr(&self, path: &Path) -> Result<()> {
        let file =
            std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
        let pixels: Vec<image::Rgb<f32>> = self.texels.iter().map(|&c| image::Rgb(c)).collect();
        image::codecs::hdr::HdrEncoder::new(std::io::BufWriter::new(file))
            .encode(&pixels, self.width as usize, self.height as usize)
            .with_context(|| format!("writing {}", path.display()))?;
        Ok(())
    }

    /// The procedural studio shipped as `assets/studio.hdr`: a dim grey
    /// cyclorama (lighter towards the horizon, darker floor) lit by three soft
    /// boxes: a large warm key upper left in front, a cooler fill on the right
    /// and a narrow strip light behind, above. Soft boxes are rectangles in
    /// (φ, θ) with smoothstep edges.
    pub fn studio(width: u32, height: u32) -> Self {
        // (centre φ, centre θ, half width, half height, radiance) in radians.
        let boxes: [(f64, f64, f64, f64, [f64; 3]); 3] = [
            (-0.6, 0.75, 0.35, 0.28, [14.0, 12.5, 10.5]),
            (1.3, 1.2, 0.25, 0.35, [3.0, 3.4, 4.0]),
            (3.0, 0.45, 0.6, 0.08, [9.0, 9.0, 9.0]),
        ];
        let smooth = |e0: f64, e1: f64, x: f64| {
            let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
            t * t * (3.0 - 2.0 * t)
        };
        let mut texels = Vec::with_capacity((width * height) as usize);
        for j in 0..height {
            let theta = (f64::from(j) + 0.5) / f64::from(height) * PI;
            for i in 0..width {
                let phi = (f64::from(i) + 0.5) / f64::from(width) * 2.0 * PI - PI;
                let up = theta.cos();
                let mut c = if up >= 0.0 {
                    [0.18 + 0.1 * (1.0 - up); 3]
                } else {
                    [0.06, 0.055, 0.05]
                };
                for (p0, t0, hw, hh, l) in boxes {
                    let dphi = (phi - p0 + PI).rem_euclid(2.0 * PI) - PI;
                    let wx = 1.0 - smooth(hw * 0.8, hw, dphi.abs());
                    let wy = 1.0 - smooth(hh * 0.8, hh, (theta - t0).abs());
                    for k in 0..3 {
                        c[k] += wx * wy * l[k];
                    }
                }
                texels.push(c.map(|x| x as f32));
            }
        }
        Self {
            width,
            height,
            texels,
        }
    }

    /// Marginal and conditional CDFs of the texel probabilities
    /// ∝ luminance × solid angle (what `shaders/common/envmap.wgsl` samples),
    /// and whether the map has any energy.
    pub fn cdfs(&self) -> (Vec<f32>, Vec<f32>, bool) {
        let (w, h) = (self.width as usize, self.height as usize);
        let mut conditional = vec![0f32; h * (w + 1)];
        let mut rows = vec![0f64; h];
        for j in 0..h {
            let t0 = j as f64 * PI / h as f64;
            let t1 = (j + 1) as f64 * PI / h as f64;
            let omega = 2.0 * PI / w as f64 * (t0.cos() - t1.cos());
            let mut acc = vec![0f64; w + 1];
            for i in 0..w {
                let c = self.texels[j * w + i];
                let lum =
                    0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2]);
                acc[i + 1] = acc[i] + lum.max(0.0) * omega;
            }
            rows[j] = acc[w];
            for i in 0..=w {
                conditional[j * (w + 1) + i] = if acc[w] > 0.0 {
                    (acc[i] / acc[w]) as f32
                } else {
                    i as f32 / w as f32
                };
            }
        }
        let total: f64 = rows.iter().sum();
        let mut marginal = vec![0f32; h + 1];
        let mut acc = 0.0;
        for j in 0..h {
            acc += rows[j];
            marginal[j + 1] = if total > 0.0 {
                (acc / total) as f32
            } else {
                (j + 1) as f32 / h as f32
            };
        }
        marginal[h] = 1.0;
        for j in 0..h {
            conditional[j * (w + 1) + w] = 1.0;
        }
        (marginal, conditional, total > 0.0 && total.is_finite())
    }
}

/// The bundled studio environment (`assets/studio.hdr`, made by
/// `examples/make_studio.rs`), compiled in so that the environment view works
/// on a fresh machine whatever the working directory.
pub const STUDIO_HDR: &[u8] = include_bytes!("../../assets/studio.hdr");

impl EnvironmentMap {
    /// Decodes a Radiance `.hdr` or OpenEXR file held in memory; `name` is
    /// used in error messages.
    pub fn decode(bytes: &[u8], name: &str) -> Result<Self> {
        let reader = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .with_context(|| format!("reading {name}"))?;
        let (w, h) = reader
            .into_dimensions()
            .with_context(|| format!("reading the size of {name}"))?;
        if w == 0 || h == 0 || w > MAX_ENV_SIDE || h > MAX_ENV_SIDE {
            bail!("{name}: {w}×{h} is not a usable environment (1..={MAX_ENV_SIDE} per side)");
        }
        let img = image::load_from_memory(bytes)
            .with_context(|| format!("decoding {name}"))?
            .into_rgb32f();
        let texels = img
            .pixels()
            .map(|p| {
                let c = p.0.map(|x| if x.is_finite() { x.max(0.0) } else { 0.0 });
                [c[0], c[1], c[2]]
            })
            .collect();
        Ok(Self {
            width: img.width(),
            height: img.height(),
            texels,
        })
    }

    /// The bundled studio ([`STUDIO_HDR`]).
    pub fn builtin_studio() -> Result<Self> {
        Self::decode(STUDIO_HDR, "the built-in studio.hdr")
    }
}
