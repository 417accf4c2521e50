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
    /// Row-major radiance, in units of [`EnvironmentMap::unit`].
    pub texels: Vec<[f32; 3]>,
    /// The radiance of a texel value of 1: a power of two, 1 unless the
    /// file's values are so large that rendering with them would overflow
    /// f32 (see [`MAX_TEXEL`]); the renderer folds it into the exposure.
    pub unit: f32,
}

/// Largest accepted side of a loaded map (a hostile header must not allocate
/// gigabytes).
pub const MAX_ENV_SIDE: u32 = 16384;

/// Most texels of a loaded map (4096 × 2048, the usual "4k" panorama): more
/// detail than the environment view draws, and about the 128 MiB that
/// every wgpu device binds once uploaded (16 bytes a texel with its
/// sampling tables: `EnvRenderer::upload`). Checked from the
/// file's header, before anything is decoded (an 8192 × 4096 map took
/// 1.2 GB to decode, only to be refused by the upload).
pub const MAX_ENV_TEXELS: u64 = 1 << 23;

/// Largest texel value kept as it is (2⁴⁰, about 10¹²: a thousand times an
/// unclipped sun). Rendering multiplies radiance by BRDF values, divides by
/// sampling densities and sums thousands of samples in f32; a map whose
/// values reach f32's maximum overflowed to infinity and NaN and came out
/// black. Such a map is stored divided by a power of two (exact) and
/// [`EnvironmentMap::unit`] says by how much.
pub const MAX_TEXEL: f32 = (1u64 << 40) as f32;

impl EnvironmentMap {
    /// A constant environment (the white furnace when `c` is 1).
    pub fn constant(c: [f32; 3]) -> Self {
        Self {
            width: 8,
            height: 4,
            texels: vec![c; 32],
            unit: 1.0,
        }
    }

    /// Loads a Radiance `.hdr` or OpenEXR file (equirectangular): a regular
    /// file of at most [`bv_core::fsio::MAX_ENV_MAP_BYTES`] (a FIFO or a
    /// device is refused, not waited on).
    pub fn load(path: &Path) -> Result<Self> {
        let name = path.display().to_string();
        // The size from the header first: a map bv refuses is not read,
        // let alone decoded. (A file handed in as bytes is checked by
        // `decode`.)
        if bv_core::fsio::provided(path).is_none() {
            let (file, _) = bv_core::fsio::open_regular(
                path,
                bv_core::fsio::MAX_ENV_MAP_BYTES,
                "an environment map",
            )?;
            let reader = image::ImageReader::new(std::io::BufReader::new(file))
                .with_guessed_format()
                .with_context(|| format!("reading {name}"))?;
            check_size(reader, &name)?;
        }
        let bytes = bv_core::fsio::read_capped(
            path,
            bv_core::fsio::MAX_ENV_MAP_BYTES,
            "an environment map",
        )?;
        Self::decode(&bytes, &name)
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
            unit: 1.0,
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
        check_size(reader, name)?;
        let img = image::load_from_memory(bytes)
            .map_err(flat)
            .with_context(|| format!("decoding {name}"))?
            .into_rgb32f();
        let texels = img
            .pixels()
            .map(|p| {
                let c = p.0.map(|x| if x.is_finite() { x.max(0.0) } else { 0.0 });
                [c[0], c[1], c[2]]
            })
            .collect();
        let mut map = Self {
            width: img.width(),
            height: img.height(),
            texels,
            unit: 1.0,
        };
        map.rescale();
        Ok(map)
    }

    /// Divides the texels by the power of two that brings the largest to at
    /// most [`MAX_TEXEL`], and records it in [`EnvironmentMap::unit`].
    fn rescale(&mut self) {
        let max = self
            .texels
            .iter()
            .flatten()
            .fold(0f32, |m, &x| if x > m { x } else { m });
        if max <= MAX_TEXEL {
            return;
        }
        // max ≤ f32::MAX < 2¹²⁸, so k ≤ 88 and 2^±k are exact f32 values.
        let k = (f64::from(max) / f64::from(MAX_TEXEL)).log2().ceil() as i32;
        let down = 2f32.powi(-k);
        for t in &mut self.texels {
            *t = t.map(|x| x * down);
        }
        self.unit = 2f32.powi(k);
    }

    /// The bundled studio ([`STUDIO_HDR`]).
    pub fn builtin_studio() -> Result<Self> {
        Self::decode(STUDIO_HDR, "the built-in studio.hdr")
    }
}

/// Refuses a map whose header gives a size bv does not draw (see
/// [`MAX_ENV_SIDE`], [`MAX_ENV_TEXELS`]), before any texel is decoded.
fn check_size<R: std::io::BufRead + std::io::Seek>(
    reader: image::ImageReader<R>,
    name: &str,
) -> Result<()> {
    let (w, h) = reader
        .into_dimensions()
        .map_err(flat)
        .with_context(|| format!("reading the size of {name}"))?;
    if w == 0 || h == 0 || w > MAX_ENV_SIDE || h > MAX_ENV_SIDE {
        bail!("{name}: {w}×{h} is not a usable environment (1..={MAX_ENV_SIDE} per side)");
    }
    let texels = u64::from(w) * u64::from(h);
    if texels > MAX_ENV_TEXELS {
        bail!(
            "{name}: an environment map of {w}×{h} ({texels} texels) is over the limit of \
             {MAX_ENV_TEXELS} texels (4096×2048); downscale it (the environment view draws \
             less detail than that)"
        );
    }
    Ok(())
}

/// An image error as one message: its `Display` already includes its
/// cause, which `{:#}` would print a second time from `source()`.
fn flat(e: image::ImageError) -> anyhow::Error {
    anyhow::anyhow!("{e}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An OpenEXR file of `w × h` texels of `value` (RGB f32, in memory).
    fn exr(w: u32, h: u32, value: f32) -> Vec<u8> {
        let img = image::Rgb32FImage::from_pixel(w, h, image::Rgb([value; 3]));
        let mut bytes = std::io::Cursor::new(Vec::new());
        image::DynamicImage::ImageRgb32F(img)
            .write_to(&mut bytes, image::ImageFormat::OpenExr)
            .unwrap();
        bytes.into_inner()
    }

    #[test]
    fn a_map_too_large_is_refused_from_its_header() {
        let m = EnvironmentMap::decode(&exr(8, 4, 1.0), "small.exr").unwrap();
        assert_eq!((m.width, m.height, m.unit), (8, 4, 1.0));
        // A header claiming 33 M texels, with no texels after it: the size
        // alone refuses it, so nothing is decoded.
        let hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4096 +X 8192\n";
        let e = format!("{:#}", EnvironmentMap::decode(hdr, "big.hdr").unwrap_err());
        assert!(
            e.contains("8192×4096") && e.contains(&MAX_ENV_TEXELS.to_string()),
            "{e}"
        );
    }

    #[test]
    fn decoding_errors_say_their_cause_once() {
        let mut bytes = exr(8, 4, 1.0);
        let n = bytes.len();
        bytes.truncate(n - 16);
        let e = format!(
            "{:#}",
            EnvironmentMap::decode(&bytes, "cut.exr").unwrap_err()
        );
        assert!(e.starts_with("decoding cut.exr: "), "{e}");
        let cause = e.trim_start_matches("decoding cut.exr: ");
        // No sentence of the cause appears twice.
        for part in cause.split(": ").filter(|p| p.len() > 8) {
            assert_eq!(e.matches(part).count(), 1, "{e}");
        }
    }

    #[test]
    fn a_map_near_the_largest_float_is_scaled_exactly() {
        let bytes = exr(8, 4, f32::MAX);
        let m = EnvironmentMap::decode(&bytes, "bright.exr").unwrap();
        let t = m.texels[0][0];
        assert!(t <= MAX_TEXEL && t > MAX_TEXEL / 2.0, "{t}");
        assert_eq!(m.unit.log2().fract(), 0.0);
        assert_eq!(f64::from(t) * f64::from(m.unit), f64::from(f32::MAX));
        // An ordinary map is left alone.
        let m = EnvironmentMap::decode(&exr(8, 4, 3.5), "sky.exr").unwrap();
        assert_eq!((m.texels[5], m.unit), ([3.5; 3], 1.0));
    }
}
