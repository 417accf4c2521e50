//! MERL `.binary` tables : reader, writer, index mapping, lookups and
//! tabulation of analytic models.
//!
//! # File layout
//! Little-endian. A 12-byte header of three `int32` dimensions `nθh, nθd, nφd`
//! (90, 90, 180 in the public set), then `3 · nθh · nθd · nφd` `float64`
//! values, channel-major (all red, then green, then blue), cell
//! `(iθh · nθd + iθd) · nφd + iφd` within a channel. Stored values are scaled:
//! `f = stored · scale` with scales 1/1500, 1.15/1500, 1.66/1500 (red, green,
//! blue). Negative stored values mean "not measured".
//!
//! # In memory
//! [`MerlTable`] keeps one `f32` per sample, in the file's channel-major order
//! (a GPU view can upload [`MerlTable::data`] as it is), with the channel scales
//! **already applied at load**: a table value is `f` in 1/sr. Unmeasured and
//! non-finite samples are stored as 0 and counted in [`MerlWarnings`]. The
//! reader streams the `float64`s through a 64 KiB buffer, so the only full-size
//! allocation is the `f32` table itself (half the file's size).
//!
//! # Index mapping (Matusik's reference `BRDFRead.cpp`)
//! - `iθh = ⌊√(θh / (π/2)) · nθh⌋`: non-linear, so that the specular peak near
//!   `θh = 0` gets many cells; `θh ≤ 0` gives 0.
//! - `iθd = ⌊θd / (π/2) · nθd⌋`.
//! - `iφd = ⌊φd / π · nφd⌋` after folding `φd < 0` by `+π`: swapping `wi` and
//!   `wo` maps `φd` to `φd + π` (the difference vector is mirrored through h),
//!   so by Helmholtz reciprocity one half-turn of `φd` holds the whole BRDF.
//!
//! Every index is clamped to `0..n`, and a φd on the 0 ≡ π seam (within
//! 1e-9) goes to cell 0 ([`phi_d_index`] says why). Angles are those of
//! [`crate::frame::to_half_diff`], which rotates by `−φh` about z and `−θh`
//! about y exactly as the reference code's `std_coords_to_half_diff_coords`
//! (a test below ports the reference code and compares).
//!
//! # Where a sample sits
//! bv reads sample `i` as the value at the **centre** of its cell in index
//! space, `u = i + ½` (so the reference's truncating lookup is a true
//! nearest-sample lookup): θh = ((i + ½)/nθh)² · π/2, θd = (i + ½)/nθd · π/2,
//! φd = (i + ½)/nφd · π. [`tabulate`] samples at these centres and
//! [`Interpolation::Trilinear`] interpolates between them, linearly in the
//! index coordinates (θh in its square-root space), clamping at the θh and
//! θd ends and wrapping around in φd (period π, by the reciprocity fold).

use crate::{Brdf, BvError, Result, Rgb, frame, fsio};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Bytes of the header (three little-endian `int32`).
pub const HEADER_BYTES: u64 = 12;
/// Largest accepted value of any one dimension.
pub const MAX_DIM: usize = 4096;
/// Largest accepted file: the header and [`MAX_CELLS`] cells of 3 `float64`.
pub const MAX_FILE_BYTES: u64 = HEADER_BYTES + 24 * MAX_CELLS;
/// Largest accepted number of cells per channel (`nθh · nθd · nφd`):
/// 2²⁴ = 16,777,216, 11.5 times the public resolution (a 192 MiB `f32` table,
/// a 384 MiB file). Anything larger is refused before allocation.
pub const MAX_CELLS: u64 = 1 << 24;
/// Channel scales of the MERL format: `f = stored · scale` (red, green, blue).
pub const SCALES: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];
/// The dimensions of the public MERL data set.
pub const STANDARD_DIMS: MerlDims = MerlDims {
    theta_h: 90,
    theta_d: 90,
    phi_d: 180,
};

const CHANNEL_NAMES: [&str; 3] = ["red", "green", "blue"];

/// Table dimensions: cells along θh, θd and φd.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct MerlDims {
    /// Cells along θh (non-linear, 0..π/2).
    pub theta_h: usize,
    /// Cells along θd (linear, 0..π/2).
    pub theta_d: usize,
    /// Cells along φd (linear, 0..π).
    pub phi_d: usize,
}

impl std::fmt::Display for MerlDims {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}×{}×{}", self.theta_h, self.theta_d, self.phi_d)
    }
}

impl MerlDims {
    /// Validated dimensions from signed header values: each in `1..=MAX_DIM`,
    /// their product at most [`MAX_CELLS`] (computed in 64 bits, so that
    /// `2048³`, which overflows the reference code's `int`, is refused too).
    pub fn new(theta_h: i64, theta_d: i64, phi_d: i64) -> Result<Self> {
        let names = ["nθh", "nθd", "nφd"];
        let vals = [theta_h, theta_d, phi_d];
        for (name, v) in names.iter().zip(vals) {
            if v <= 0 {
                return Err(BvError::Invalid(format!(
                    "dimension {name} = {v}: dimensions must be positive (the public MERL files have 90, 90, 180)"
                )));
            }
            if v > MAX_DIM as i64 {
                return Err(BvError::Invalid(format!(
                    "dimension {name} = {v} exceeds the cap of {MAX_DIM}"
                )));
            }
        }
        let cells = (theta_h as u64)
            .checked_mul(theta_d as u64)
            .and_then(|x| x.checked_mul(phi_d as u64));
        match cells {
            Some(c) if c <= MAX_CELLS => Ok(Self {
                theta_h: theta_h as usize,
                theta_d: theta_d as usize,
                phi_d: phi_d as usize,
            }),
            _ => Err(BvError::Invalid(format!(
                "dimensions {theta_h}×{theta_d}×{phi_d} give {} cells per channel, over the cap of {MAX_CELLS}",
                (theta_h as u128) * (theta_d as u128) * (phi_d as u128)
            ))),
        }
    }

    /// Parses `"90,90,180"` (the CLI's `--dims`).
    pub fn parse(text: &str) -> Result<Self> {
        let parts: Vec<&str> = text.split(',').map(str::trim).collect();
        if parts.len() != 3 {
            return Err(BvError::Invalid(format!(
                "dimensions `{text}`: expected three integers nθh,nθd,nφd such as 90,90,180"
            )));
        }
        let mut v = [0i64; 3];
        for (slot, p) in v.iter_mut().zip(&parts) {
            *slot = p.parse().map_err(|_| {
                BvError::Invalid(format!("dimensions `{text}`: `{p}` is not an integer"))
            })?;
        }
        Self::new(v[0], v[1], v[2])
    }

    /// Cells per channel.
    pub fn cells(&self) -> usize {
        self.theta_h * self.theta_d * self.phi_d
    }

    /// Size in bytes of a file with these dimensions.
    pub fn file_len(&self) -> u64 {
        HEADER_BYTES + 3 * 8 * self.cells() as u64
    }

    /// Offset of cell `(ih, id, ip)` within one channel.
    #[inline]
    pub fn cell(&self, ih: usize, id: usize, ip: usize) -> usize {
        (ih * self.theta_d + id) * self.phi_d + ip
    }
}

/// How a table is looked up between its samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Interpolation {
    /// The sample whose cell contains the point (MERL reference behaviour).
    Nearest,
    /// Trilinear in (θh index space, θd, φd) between cell centres.
    #[default]
    Trilinear,
}

impl Interpolation {
    /// Names accepted by the `interpolation` parameter, default first.
    pub const NAMES: &'static [&'static str] = &["trilinear", "nearest"];

    /// The interpolation called `name`.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "nearest" => Ok(Self::Nearest),
            "trilinear" => Ok(Self::Trilinear),
            other => Err(BvError::BadValue {
                param: "interpolation".into(),
                reason: format!("`{other}` is not one of trilinear, nearest"),
            }),
        }
    }

    /// Its parameter name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Nearest => "nearest",
            Self::Trilinear => "trilinear",
        }
    }
}

// ---------------------------------------------------------------------------
// Index mapping

/// Continuous θh coordinate `√(θh / (π/2)) · n` in `[0, n]` (0 for θh ≤ 0 or NaN).
#[inline]
pub fn theta_h_coord(theta_h: f64, n: usize) -> f64 {
    if theta_h > 0.0 {
        ((theta_h / FRAC_PI_2).min(1.0)).sqrt() * n as f64
    } else {
        0.0
    }
}

/// Continuous θd coordinate `θd / (π/2) · n` in `[0, n]`.
#[inline]
pub fn theta_d_coord(theta_d: f64, n: usize) -> f64 {
    if theta_d > 0.0 {
        (theta_d / FRAC_PI_2).min(1.0) * n as f64
    } else {
        0.0
    }
}

/// Folds φd by reciprocity as the reference code does: `φd < 0` gets `+π`.
/// For `φd ∈ (−π, π]` (what `atan2` returns) the result is in `[0, π]`.
#[inline]
pub fn fold_phi_d(phi_d: f64) -> f64 {
    if phi_d < 0.0 { phi_d + PI } else { phi_d }
}

/// Continuous φd coordinate `fold(φd) / π · n`, reduced modulo `n` into `[0, n)`
/// (the table is periodic in φd with period π).
#[inline]
pub fn phi_d_coord(phi_d: f64, n: usize) -> f64 {
    if !phi_d.is_finite() {
        return 0.0;
    }
    let u = (phi_d / PI).rem_euclid(1.0) * n as f64;
    // rem_euclid can round up to exactly 1.0 for tiny negative inputs.
    if u >= n as f64 { 0.0 } else { u }
}

fn clamp_index(u: f64, n: usize) -> usize {
    if u > 0.0 { (u as usize).min(n - 1) } else { 0 }
}

/// Cell index along θh of the reference code: `⌊√(θh/(π/2)) · n⌋`, clamped.
#[inline]
pub fn theta_h_index(theta_h: f64, n: usize) -> usize {
    clamp_index(theta_h_coord(theta_h, n), n)
}

/// Cell index along θd: `⌊θd/(π/2) · n⌋`, clamped.
#[inline]
pub fn theta_d_index(theta_d: f64, n: usize) -> usize {
    clamp_index(theta_d_coord(theta_d, n), n)
}

/// How close to the φd = 0 ≡ π cell boundary (radians) an angle is taken to
/// lie on it; see [`phi_d_index`].
pub const PHI_D_SEAM: f64 = 1e-9;

/// Cell index along φd: fold `φd < 0` by `+π` as the reference code does,
/// then `⌊φd/π · n⌋`, clamped.
///
/// One deliberate difference: a folded φd within [`PHI_D_SEAM`] of 0 or of π
/// goes to cell 0 (the reference code sends φd = π to the last cell). Pairs
/// in a plane with the normal (the polar plot's plane, `wi` on the normal)
/// have φd = 0 or ±π exactly in theory, and in floating point a rounding-noise
/// sign then picks cell 0 or the last cell, which differ in real data: the
/// lookup would break reciprocity and isotropy on exactly the configurations
/// a lecturer shows. Both cells are equally near (half a cell each way).
#[inline]
pub fn phi_d_index(phi_d: f64, n: usize) -> usize {
    let p = fold_phi_d(phi_d);
    if p > PHI_D_SEAM && p < PI - PHI_D_SEAM {
        clamp_index(p / PI * n as f64, n)
    } else {
        0
    }
}

/// θh at the centre of cell `i`: `((i + ½)/n)² · π/2` (inverse of the mapping).
#[inline]
pub fn theta_h_centre(i: usize, n: usize) -> f64 {
    let t = (i as f64 + 0.5) / n as f64;
    t * t * FRAC_PI_2
}

/// θd at the centre of cell `i`: `(i + ½)/n · π/2`.
#[inline]
pub fn theta_d_centre(i: usize, n: usize) -> f64 {
    (i as f64 + 0.5) / n as f64 * FRAC_PI_2
}

/// φd at the centre of cell `i`: `(i + ½)/n · π`.
#[inline]
pub fn phi_d_centre(i: usize, n: usize) -> f64 {
    (i as f64 + 0.5) / n as f64 * PI
}

/// Linear interpolation weights along a clamped axis: cells `(i0, i1)` and the
/// weight of `i1`, for a continuous coordinate `u` whose samples sit at `i + ½`.
#[inline]
fn clamped_lerp(u: f64, n: usize) -> (usize, usize, f64) {
    let t = (u - 0.5).clamp(0.0, (n - 1) as f64);
    let i0 = (t as usize).min(n - 1);
    let i1 = (i0 + 1).min(n - 1);
    (i0, i1, t - i0 as f64)
}

/// The same along the periodic φd axis.
#[inline]
fn periodic_lerp(u: f64, n: usize) -> (usize, usize, f64) {
    let t = u - 0.5;
    let fl = t.floor();
    let w = t - fl;
    let i0 = (fl as i64).rem_euclid(n as i64) as usize;
    (i0, (i0 + 1) % n, w)
}

// ---------------------------------------------------------------------------
// Table

/// What the reader found wrong with individual samples (the file is still
/// usable; these samples read as 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MerlWarnings {
    /// Negative samples ("not measured") per channel.
    pub unmeasured: [usize; 3],
    /// NaN or infinite samples (or finite ones beyond the `f32` range after
    /// scaling) per channel.
    pub non_finite: [usize; 3],
    /// Channels without a single valid sample (every value unmeasured or
    /// non-finite): their statistics are over nothing and they read as 0.
    pub no_valid: [bool; 3],
}

impl MerlWarnings {
    /// Whether nothing was found.
    pub fn is_empty(&self) -> bool {
        self.unmeasured == [0; 3] && self.non_finite == [0; 3] && self.no_valid == [false; 3]
    }

    /// Human-readable warnings, one per kind that occurred.
    pub fn messages(&self) -> Vec<String> {
        let mut out = Vec::new();
        let per = |c: [usize; 3]| {
            (
                c.iter().sum::<usize>(),
                format!("red {}, green {}, blue {}", c[0], c[1], c[2]),
            )
        };
        if self.unmeasured != [0; 3] {
            let (n, detail) = per(self.unmeasured);
            out.push(format!(
                "{n} negative samples (not measured) read as 0 ({detail})"
            ));
        }
        if self.non_finite != [0; 3] {
            let (n, detail) = per(self.non_finite);
            out.push(format!("{n} NaN or infinite samples set to 0 ({detail})"));
        }
        let empty: Vec<&str> = CHANNEL_NAMES
            .iter()
            .zip(self.no_valid)
            .filter(|(_, e)| *e)
            .map(|(n, _)| *n)
            .collect();
        if !empty.is_empty() {
            out.push(format!(
                "no valid sample at all in channel{} {}: every value is unmeasured or NaN, \
                 so the table reads as 0 there and its statistics cover 0 samples",
                if empty.len() == 1 { "" } else { "s" },
                empty.join(", ")
            ));
        }
        out
    }
}

/// Range of the valid (measured, finite) samples of one channel, in 1/sr.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ChannelRange {
    /// Smallest valid value (0 when there is none).
    pub min: f64,
    /// Largest valid value (0 when there is none).
    pub max: f64,
    /// Mean of the valid values (0 when there is none).
    pub mean: f64,
    /// Number of valid samples.
    pub valid: usize,
}

/// A MERL table in memory: `f32` values of `f` (scales applied), channel-major.
#[derive(Debug, Clone)]
pub struct MerlTable {
    dims: MerlDims,
    data: Vec<f32>,
    warnings: MerlWarnings,
    ranges: [ChannelRange; 3],
    /// [`MerlTable::sampling_proxy`], computed on first use.
    proxy: std::sync::OnceLock<MerlProxy>,
}

impl PartialEq for MerlTable {
    /// The same values (the cached sampling proxy follows from them).
    fn eq(&self, other: &Self) -> bool {
        self.dims == other.dims
            && self.data == other.data
            && self.warnings == other.warnings
            && self.ranges == other.ranges
    }
}

/// The GGX proxy lobe the environment renderer importance-samples for a
/// MERL table (see [`MerlTable::sampling_proxy`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MerlProxy {
    /// GGX roughness whose `D` falls to half its peak at the θh where the
    /// table's glossy profile does.
    pub alpha: f64,
    /// Diffuse weight: π × the floor of the θh profile.
    pub diffuse: f64,
    /// Glossy weight: the profile above its floor, reflected at normal
    /// incidence and integrated, `∫ g(θh) cos 2θh 4 cos θh dωh`.
    pub glossy: f64,
}

fn file_err(path: &str, reason: impl Into<String>) -> BvError {
    BvError::File {
        path: path.to_string(),
        reason: reason.into(),
    }
}

/// Accumulates per-channel statistics while samples stream in.
struct Acc {
    min: f64,
    max: f64,
    sum: f64,
    valid: usize,
}

impl Acc {
    fn new() -> Self {
        Self {
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            sum: 0.0,
            valid: 0,
        }
    }

    fn range(&self) -> ChannelRange {
        if self.valid == 0 {
            ChannelRange::default()
        } else {
            ChannelRange {
                min: self.min,
                max: self.max,
                mean: self.sum / self.valid as f64,
                valid: self.valid,
            }
        }
    }
}

impl crate::model::GpuBlob for MerlTable {
    fn gpu_data(&self) -> &[f32] {
        self.data()
    }
}

impl crate::model::FileData for MerlTable {
    fn summary(&self) -> Vec<String> {
        let d = self.dims();
        let max = self.ranges().map(|r| r.max);
        vec![
            format!(
                "{d} cells (θh × θd × φd), {:.1} MB in memory",
                self.data().len() as f64 * 4.0 / 1e6
            ),
            format!(
                "largest f: r {}, g {}, b {} 1/sr",
                crate::text::fmt_value(max[0]),
                crate::text::fmt_value(max[1]),
                crate::text::fmt_value(max[2])
            ),
        ]
    }

    fn warnings(&self) -> Vec<String> {
        self.warnings().messages()
    }
}

impl MerlTable {
    /// A table from values of `f` (1/sr, channel-major as the file). Negative
    /// and non-finite values are stored as 0 and counted as they would be on
    /// reading.
    pub fn from_values(dims: MerlDims, mut data: Vec<f32>) -> Result<Self> {
        let dims = MerlDims::new(dims.theta_h as i64, dims.theta_d as i64, dims.phi_d as i64)?;
        if data.len() != 3 * dims.cells() {
            return Err(BvError::Invalid(format!(
                "a {dims} table needs {} values, got {}",
                3 * dims.cells(),
                data.len()
            )));
        }
        let mut warnings = MerlWarnings::default();
        let mut ranges = [ChannelRange::default(); 3];
        for (c, chunk) in data.chunks_mut(dims.cells()).enumerate() {
            let mut acc = Acc::new();
            for v in chunk {
                classify(v, c, &mut warnings, &mut acc);
            }
            ranges[c] = acc.range();
            warnings.no_valid[c] = acc.valid == 0;
        }
        Ok(Self {
            dims,
            data,
            warnings,
            ranges,
            proxy: std::sync::OnceLock::new(),
        })
    }

    /// Reads a `.binary` file. The header and the file's size are checked
    /// against each other before anything large is allocated.
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        Self::read_with_progress(path, &mut |_, _| {})
    }

    /// [`Self::read`], calling `progress(bytes_read, file_len)` as the data
    /// streams in (after the header and after every 64 KiB chunk), so that a
    /// GUI can show how far a 35 MB file has got. The callback sees counts
    /// only: the samples go straight into the table, with no second copy.
    pub fn read_with_progress(
        path: impl AsRef<Path>,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<Self> {
        let path = path.as_ref();
        let name = path.display().to_string();
        if let Some(p) = fsio::provided(path) {
            let len = p.bytes.len() as u64;
            return Self::read_from_with_progress(&p.bytes[..], len, &name, progress);
        }
        // A regular file no larger than the largest table: a FIFO, a device
        // or a directory is refused before it is read (see `crate::fsio`).
        let (file, len) = fsio::open_regular(path, MAX_FILE_BYTES, "a MERL .binary table")?;
        // The size must then match the header exactly (checked next); `take`
        // stops a file that grows meanwhile one byte past it.
        Self::read_from_with_progress(file.take(len + 1), len, &name, progress)
    }

    /// Reads a table from a stream of `len` bytes (`name` is used in errors).
    ///
    /// Refuses, with a message saying what was expected and what was found: a
    /// stream shorter than the header; dimensions that are zero, negative,
    /// above [`MAX_DIM`] or whose product is above [`MAX_CELLS`]; a `len` that
    /// differs from `12 + 24 · cells`; a stream that ends early or goes on
    /// past `len`. The table is allocated only after these checks, so memory
    /// stays within half of `len`.
    pub fn read_from(reader: impl Read, len: u64, name: &str) -> Result<Self> {
        Self::read_from_with_progress(reader, len, name, &mut |_, _| {})
    }

    /// [`Self::read_from`] with a progress callback `progress(bytes_read, len)`
    /// (see [`Self::read_with_progress`]).
    pub fn read_from_with_progress(
        mut reader: impl Read,
        len: u64,
        name: &str,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<Self> {
        if len < HEADER_BYTES {
            return Err(file_err(
                name,
                format!(
                    "{} ({len} bytes): a MERL .binary file starts with a 12-byte header of three int32 dimensions",
                    if len == 0 {
                        "empty file"
                    } else {
                        "too short for the header"
                    }
                ),
            ));
        }
        let mut header = [0u8; 12];
        read_exact(&mut reader, &mut header, name, 0, len)?;
        let d = |i: usize| {
            i32::from_le_bytes([
                header[4 * i],
                header[4 * i + 1],
                header[4 * i + 2],
                header[4 * i + 3],
            ]) as i64
        };
        let dims = MerlDims::new(d(0), d(1), d(2)).map_err(|e| file_err(name, e.to_string()))?;
        let expected = dims.file_len();
        if len != expected {
            let (diff, what) = if len < expected {
                (expected - len, "fewer: truncated")
            } else {
                (len - expected, "extra")
            };
            return Err(file_err(
                name,
                format!(
                    "size mismatch: dimensions {dims} need {expected} bytes (12-byte header + 3·{} float64), the file has {len} ({diff} {what})",
                    dims.cells()
                ),
            ));
        }

        let total = 3 * dims.cells();
        let mut data: Vec<f32> = Vec::new();
        data.try_reserve_exact(total)
            .map_err(|e| file_err(name, format!("cannot allocate {total} samples: {e}")))?;
        let mut warnings = MerlWarnings::default();
        let mut ranges = [ChannelRange::default(); 3];
        const CHUNK: usize = 8192; // samples per read: a 64 KiB buffer
        let mut buf = vec![0u8; CHUNK * 8];
        let mut offset = HEADER_BYTES;
        progress(offset, len);
        for (c, range) in ranges.iter_mut().enumerate() {
            let mut acc = Acc::new();
            let mut left = dims.cells();
            while left > 0 {
                let k = left.min(CHUNK);
                let bytes = &mut buf[..k * 8];
                read_exact(&mut reader, bytes, name, offset, len)?;
                offset += bytes.len() as u64;
                progress(offset, len);
                for b in bytes.chunks_exact(8) {
                    let raw = f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]);
                    let mut v = (raw * SCALES[c]) as f32;
                    // A finite raw value beyond f32 range becomes ±inf here and
                    // is counted as non-finite: it cannot be shown or integrated.
                    if !raw.is_finite() {
                        v = f32::NAN;
                    }
                    classify(&mut v, c, &mut warnings, &mut acc);
                    data.push(v);
                }
                left -= k;
            }
            *range = acc.range();
            warnings.no_valid[c] = acc.valid == 0;
        }
        let mut extra = [0u8; 1];
        match reader.read(&mut extra) {
            Ok(0) => {}
            Ok(_) => {
                return Err(file_err(
                    name,
                    format!("the data goes on past the {len} bytes its header implies"),
                ));
            }
            Err(e) => return Err(file_err(name, e.to_string())),
        }
        Ok(Self {
            dims,
            data,
            warnings,
            ranges,
            proxy: std::sync::OnceLock::new(),
        })
    }

    /// Writes the table as a `.binary` file, atomically: to a temporary file
    /// beside `path`, then renamed over it, so a reader never sees half a file.
    /// What is refused (FIFOs, devices, read-only files, …) and how symlinks
    /// and permissions are treated is [`fsio::write_atomic`]'s.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        fsio::write_atomic(path.as_ref(), |mut w| self.write_to(&mut w))
    }

    /// Writes the `.binary` bytes (header, then `f / scale` as `float64`).
    pub fn write_to(&self, w: &mut impl Write) -> std::io::Result<()> {
        for n in [self.dims.theta_h, self.dims.theta_d, self.dims.phi_d] {
            // Dimensions are at most MAX_DIM, so they fit an int32.
            w.write_all(&(n as i32).to_le_bytes())?;
        }
        for (c, chunk) in self.data.chunks(self.dims.cells()).enumerate() {
            for &v in chunk {
                w.write_all(&(v as f64 / SCALES[c]).to_le_bytes())?;
            }
        }
        Ok(())
    }

    /// Dimensions.
    pub fn dims(&self) -> MerlDims {
        self.dims
    }

    /// All values of `f` (1/sr), channel-major: red cells, green cells, blue
    /// cells; cell `(iθh · nθd + iθd) · nφd + iφd`.
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// What the reader found wrong with individual samples.
    pub fn warnings(&self) -> &MerlWarnings {
        &self.warnings
    }

    /// Range of the valid samples per channel (red, green, blue).
    pub fn ranges(&self) -> &[ChannelRange; 3] {
        &self.ranges
    }

    /// The GGX proxy lobe of the environment renderer's importance sampling
    /// (computed on first use, then kept). The table's θh profile `p(θh)`
    /// (the mean of its positive values over θd < 45°, every φd and the
    /// channels: near the
    /// mirror configuration, where `f ≈ D(θh) F G / (4 cos θi cos θo)`
    /// varies with θh mostly through `D`) less its floor is the glossy part
    /// `g`; the GGX α whose `D(θh)/D(0)` halves where `g` does
    /// (`α² = tan²θ½ / (√2/cos²θ½ − 1)`, from Walter et al. 2007, eq. 33)
    /// shapes the lobe, and π × the floor against the reflected integral of
    /// `g` weighs the cosine part. MERL has no NDF to match the peak height
    /// of, as the RGL proxy does; the half-maximum width needs none. The
    /// shader's pdf is what it draws, so a poor match costs noise, not bias.
    pub fn sampling_proxy(&self) -> MerlProxy {
        *self.proxy.get_or_init(|| self.compute_proxy())
    }

    fn compute_proxy(&self) -> MerlProxy {
        let d = self.dims;
        let n = d.cells();
        let nd = (0..d.theta_d)
            .take_while(|&id| theta_d_centre(id, d.theta_d) < std::f64::consts::FRAC_PI_4)
            .count()
            .max(1);
        let profile: Vec<f64> = (0..d.theta_h)
            .map(|ih| {
                let (mut sum, mut count) = (0.0, 0usize);
                for id in 0..nd {
                    for ip in 0..d.phi_d {
                        let k = d.cell(ih, id, ip);
                        for c in 0..3 {
                            let v = f64::from(self.data[k + c * n]);
                            // Cells below the horizon hold 0 (or a negative
                            // mark): only measured values count.
                            if v.is_finite() && v > 0.0 {
                                sum += v;
                                count += 1;
                            }
                        }
                    }
                }
                if count > 0 { sum / count as f64 } else { 0.0 }
            })
            .collect();
        let floor = profile.iter().copied().fold(f64::INFINITY, f64::min);
        let floor = if floor.is_finite() {
            floor.max(0.0)
        } else {
            0.0
        };
        let g: Vec<f64> = profile.iter().map(|p| (p - floor).max(0.0)).collect();
        let (peak_i, peak) = g
            .iter()
            .copied()
            .enumerate()
            .fold((0, 0.0), |a, (i, v)| if v > a.1 { (i, v) } else { a });
        let mut alpha = 1.0;
        if peak > 0.0 {
            for i in peak_i + 1..d.theta_h {
                if g[i] <= 0.5 * peak {
                    let (t0, t1) = (
                        theta_h_centre(i - 1, d.theta_h),
                        theta_h_centre(i, d.theta_h),
                    );
                    let th = t0 + (t1 - t0) * (g[i - 1] - 0.5 * peak) / (g[i - 1] - g[i]);
                    let den = std::f64::consts::SQRT_2 / th.cos().powi(2) - 1.0;
                    if den > 0.0 {
                        alpha = (th.tan().powi(2) / den).sqrt();
                    }
                    break;
                }
            }
        }
        let mut glossy = 0.0;
        for (i, gi) in g.iter().enumerate() {
            let ta = FRAC_PI_2 * (i as f64 / d.theta_h as f64).powi(2);
            let tb = FRAC_PI_2 * ((i + 1) as f64 / d.theta_h as f64).powi(2);
            let th = theta_h_centre(i, d.theta_h);
            let omega = 2.0 * std::f64::consts::PI * (ta.cos() - tb.cos());
            glossy += gi * (2.0 * th).cos().max(0.0) * 4.0 * th.cos() * omega;
        }
        MerlProxy {
            alpha: alpha.clamp(1e-3, 1.0),
            diffuse: std::f64::consts::PI * floor,
            glossy,
        }
    }

    /// The value of cell `(ih, id, ip)`, per channel.
    #[inline]
    pub fn at(&self, ih: usize, id: usize, ip: usize) -> Rgb {
        let i = self.dims.cell(ih, id, ip);
        let n = self.dims.cells();
        Rgb::new(
            self.data[i] as f64,
            self.data[i + n] as f64,
            self.data[i + 2 * n] as f64,
        )
    }

    /// `f` at half/difference angles (φh is ignored: the table is isotropic).
    pub fn lookup_angles(
        &self,
        theta_h: f64,
        theta_d: f64,
        phi_d: f64,
        mode: Interpolation,
    ) -> Rgb {
        let d = self.dims;
        match mode {
            Interpolation::Nearest => self.at(
                theta_h_index(theta_h, d.theta_h),
                theta_d_index(theta_d, d.theta_d),
                phi_d_index(phi_d, d.phi_d),
            ),
            Interpolation::Trilinear => {
                let (h0, h1, wh) = clamped_lerp(theta_h_coord(theta_h, d.theta_h), d.theta_h);
                let (d0, d1, wd) = clamped_lerp(theta_d_coord(theta_d, d.theta_d), d.theta_d);
                let (p0, p1, wp) = periodic_lerp(phi_d_coord(phi_d, d.phi_d), d.phi_d);
                let n = d.cells();
                let mut out = [0.0f64; 3];
                for (ih, fh) in [(h0, 1.0 - wh), (h1, wh)] {
                    for (id, fd) in [(d0, 1.0 - wd), (d1, wd)] {
                        let base = (ih * d.theta_d + id) * d.phi_d;
                        for (ip, fp) in [(p0, 1.0 - wp), (p1, wp)] {
                            let w = fh * fd * fp;
                            let i = base + ip;
                            out[0] += w * self.data[i] as f64;
                            out[1] += w * self.data[i + n] as f64;
                            out[2] += w * self.data[i + 2 * n] as f64;
                        }
                    }
                }
                Rgb::from_array(out)
            }
        }
    }

    /// `f(wi, wo)`: 0 below the horizon, else the table at the pair's
    /// half/difference angles.
    pub fn lookup(&self, wi: DVec3, wo: DVec3, mode: Interpolation) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        match half_diff_angles(wi, wo) {
            Some((th, td, pd)) => self.lookup_angles(th, td, pd, mode),
            None => Rgb::ZERO,
        }
    }
}

/// `(θh, θd, φd)` of a direction pair: the angles of
/// [`frame::to_half_diff`] (same rotations, −φh about z then −θh about y), but
/// with the rotations built from h's components instead of from its angles,
/// which saves four of the seven transcendental calls of a lookup. θ angles
/// come from `atan2(sin, cos)`, accurate near 0 where `acos` is not. `None`
/// when `wi = −wo`.
#[inline]
pub fn half_diff_angles(wi: DVec3, wo: DVec3) -> Option<(f64, f64, f64)> {
    let h = frame::half_vector(wi, wo)?;
    let s = (h.x * h.x + h.y * h.y).sqrt();
    let (cp, sp) = if s > 0.0 {
        (h.x / s, h.y / s)
    } else {
        (1.0, 0.0)
    };
    // Rotate wi by −φh about z ...
    let x1 = cp * wi.x + sp * wi.y;
    let y1 = cp * wi.y - sp * wi.x;
    // ... then by −θh about y (cos θh = h.z, sin θh = s).
    let x2 = h.z * x1 - s * wi.z;
    let z2 = s * x1 + h.z * wi.z;
    let theta_h = s.atan2(h.z);
    let theta_d = (x2 * x2 + y1 * y1).sqrt().atan2(z2);
    Some((theta_h, theta_d, y1.atan2(x2)))
}

/// Zeroes a non-finite or negative value, counting it, and accumulates the rest.
#[inline]
fn classify(v: &mut f32, c: usize, warnings: &mut MerlWarnings, acc: &mut Acc) {
    if !v.is_finite() {
        warnings.non_finite[c] += 1;
        *v = 0.0;
    } else if *v < 0.0 {
        warnings.unmeasured[c] += 1;
        *v = 0.0;
    } else {
        let x = *v as f64;
        acc.min = acc.min.min(x);
        acc.max = acc.max.max(x);
        acc.sum += x;
        acc.valid += 1;
    }
}

fn read_exact(r: &mut impl Read, buf: &mut [u8], name: &str, offset: u64, len: u64) -> Result<()> {
    r.read_exact(buf).map_err(|e| {
        if e.kind() == std::io::ErrorKind::UnexpectedEof {
            file_err(
                name,
                format!(
                    "truncated: the data ends before byte {offset} + {} of the {len} expected",
                    buf.len()
                ),
            )
        } else {
            file_err(name, e.to_string())
        }
    })
}

/// Samples `brdf` at the centre of every cell (φh = 0) into a table that
/// [`MerlTable::lookup`] returns `f` from. Runs in parallel over θh.
///
/// The MERL layout is isotropic: for an anisotropic model this stores its
/// φh = 0 slice. Negative or non-finite model values are stored as 0 and
/// counted in the table's warnings.
pub fn tabulate(brdf: &dyn Brdf, dims: MerlDims) -> Result<MerlTable> {
    let dims = MerlDims::new(dims.theta_h as i64, dims.theta_d as i64, dims.phi_d as i64)?;
    let n = dims.cells();
    let slab = dims.theta_d * dims.phi_d;
    let mut data = vec![0f32; 3 * n];
    let (r, rest) = data.split_at_mut(n);
    let (g, b) = rest.split_at_mut(n);
    r.par_chunks_mut(slab)
        .zip(g.par_chunks_mut(slab))
        .zip(b.par_chunks_mut(slab))
        .enumerate()
        .for_each(|(ih, ((r, g), b))| {
            let theta_h = theta_h_centre(ih, dims.theta_h);
            for id in 0..dims.theta_d {
                let theta_d = theta_d_centre(id, dims.theta_d);
                for ip in 0..dims.phi_d {
                    let (wi, wo) = frame::from_half_diff(frame::HalfDiff {
                        theta_h,
                        phi_h: 0.0,
                        theta_d,
                        phi_d: phi_d_centre(ip, dims.phi_d),
                    });
                    let f = if wi.z > 0.0 && wo.z > 0.0 {
                        brdf.eval(wi, wo)
                    } else {
                        Rgb::ZERO
                    };
                    let k = id * dims.phi_d + ip;
                    // Non-finite values become NaN here and are counted below.
                    r[k] = f.x as f32;
                    g[k] = f.y as f32;
                    b[k] = f.z as f32;
                }
            }
        });
    MerlTable::from_values(dims, data)
}

// ---------------------------------------------------------------------------
// Process-wide cache

/// How many tables the cache keeps (a full-size table is 17.5 MB).
const CACHE_ENTRIES: usize = 4;

struct CacheEntry {
    path: PathBuf,
    modified: Option<std::time::SystemTime>,
    len: u64,
    last_use: u64,
    table: Arc<MerlTable>,
}

static CACHE: Mutex<(u64, Vec<CacheEntry>)> = Mutex::new((0, Vec::new()));

/// Reads `path` through a small process-wide cache keyed by the canonical path,
/// modification time and size, so that rebuilding a `merl` model (every slider
/// move in the GUI, every `bv eval` line) does not reread the file. A changed
/// file is read again. At most 4 tables are kept (least recently used goes).
pub fn read_cached(path: impl AsRef<Path>) -> Result<Arc<MerlTable>> {
    read_cached_with_progress(path, &mut |_, _| {})
}

/// Identity of a file for the cache: canonical path, modification time, size.
fn cache_key(path: &Path) -> Result<(PathBuf, Option<std::time::SystemTime>, u64)> {
    if let Some(p) = fsio::provided(path) {
        return Ok((path.to_path_buf(), Some(p.stamp()), p.bytes.len() as u64));
    }
    let name = path.display().to_string();
    let canon = std::fs::canonicalize(path).map_err(|e| file_err(&name, e.to_string()))?;
    let meta = std::fs::metadata(&canon).map_err(|e| file_err(&name, e.to_string()))?;
    Ok((canon, meta.modified().ok(), meta.len()))
}

fn cache_lock() -> std::sync::MutexGuard<'static, (u64, Vec<CacheEntry>)> {
    // A poisoned lock only means another thread panicked mid-update; the
    // entries are still whole tables, so keep using them.
    CACHE.lock().unwrap_or_else(|e| e.into_inner())
}

/// The cached table of `key`, marked as just used.
fn cache_get(key: &(PathBuf, Option<std::time::SystemTime>, u64)) -> Option<Arc<MerlTable>> {
    let mut guard = cache_lock();
    let (clock, entries) = &mut *guard;
    *clock += 1;
    let now = *clock;
    let e = entries
        .iter_mut()
        .find(|e| e.path == key.0 && e.modified == key.1 && e.len == key.2 && key.1.is_some())?;
    e.last_use = now;
    Some(e.table.clone())
}

/// Whether [`read_cached`] of `path` would return at once (the file is in the
/// cache and unchanged), so that a GUI can decide whether to read it on a
/// background thread.
pub fn is_cached(path: impl AsRef<Path>) -> bool {
    cache_key(path.as_ref()).is_ok_and(|k| cache_get(&k).is_some())
}

/// [`read_cached`] with a progress callback for a read that misses the cache
/// (see [`MerlTable::read_with_progress`]). The cache lock is not held while
/// the file is read, so a long read on one thread never blocks another
/// thread's lookups of other tables.
pub fn read_cached_with_progress(
    path: impl AsRef<Path>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Arc<MerlTable>> {
    let path = path.as_ref();
    let key = cache_key(path)?;
    if let Some(t) = cache_get(&key) {
        progress(key.2, key.2);
        return Ok(t);
    }
    let table = Arc::new(MerlTable::read_with_progress(path, progress)?);
    let mut guard = cache_lock();
    let (clock, entries) = &mut *guard;
    *clock += 1;
    let now = *clock;
    let (canon, modified, len) = key;
    entries.retain(|e| e.path != canon);
    if entries.len() >= CACHE_ENTRIES
        && let Some(oldest) = entries
            .iter()
            .enumerate()
            .min_by_key(|(_, e)| e.last_use)
            .map(|(i, _)| i)
    {
        entries.swap_remove(oldest);
    }
    entries.push(CacheEntry {
        path: canon,
        modified,
        len,
        last_use: now,
        table: table.clone(),
    });
    Ok(table)
}

/// Channel names in file order, for reports.
pub fn channel_names() -> [&'static str; 3] {
    CHANNEL_NAMES
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::lambert::Lambert;
    use crate::{Claims, ModelSpec, sampling};
    use proptest::prelude::*;
    use rand::Rng;

    const DEG: f64 = PI / 180.0;

    fn temp_dir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("bv-merl-{}-{tag}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// A smooth, reciprocal, isotropic test BRDF written directly in
    /// half/difference angles: `k_c (0.5 + 0.3 θh + 0.2 θd + 0.1 cos 2φd)`.
    /// `cos 2φd` is invariant under φd → φd + π, so it is reciprocal.
    #[derive(Debug)]
    struct Smooth;
    const K: [f64; 3] = [1.0, 0.7, 0.4];

    impl Smooth {
        fn at(theta_h: f64, theta_d: f64, phi_d: f64) -> Rgb {
            let v = 0.5 + 0.3 * theta_h + 0.2 * theta_d + 0.1 * (2.0 * phi_d).cos();
            Rgb::from_array(K) * v
        }
    }

    impl Brdf for Smooth {
        fn id(&self) -> &'static str {
            "smooth-test"
        }
        fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
            if wi.z <= 0.0 || wo.z <= 0.0 {
                return Rgb::ZERO;
            }
            let hd = frame::to_half_diff(wi, wo).unwrap();
            Self::at(hd.theta_h, hd.theta_d, hd.phi_d)
        }
        fn claims(&self) -> Claims {
            Claims {
                reciprocal: true,
                energy_conserving: false,
                isotropic: true,
            }
        }
    }

    fn dims(h: usize, d: usize, p: usize) -> MerlDims {
        MerlDims::new(h as i64, d as i64, p as i64).unwrap()
    }

    // --- index mapping -------------------------------------------------------

    #[test]
    fn theta_h_index_by_hand() {
        // iθh = ⌊√(θh/90°) · 90⌋ (reference: ⌊√(θh/90° · 90 · 90)⌋).
        let n = 90;
        assert_eq!(theta_h_index(0.0, n), 0);
        assert_eq!(theta_h_index(-0.1, n), 0);
        assert_eq!(theta_h_index(f64::NAN, n), 0);
        // √(0.01/90)·90 = √0.9 = 0.949 → 0; √(0.012/90)·90 = √1.08 = 1.039 → 1:
        // a hundredth of a degree already moves a cell (the sqrt mapping).
        assert_eq!(theta_h_index(0.01 * DEG, n), 0);
        assert_eq!(theta_h_index(0.012 * DEG, n), 1);
        // √(1/90)·90 = √90 = 9.487 → 9; √(5/90)·90 = √450 = 21.21 → 21.
        assert_eq!(theta_h_index(1.0 * DEG, n), 9);
        assert_eq!(theta_h_index(5.0 * DEG, n), 21);
        // √(45/90)·90 = 63.64 → 63; √(89.9/90)·90 = 89.95 → 89.
        assert_eq!(theta_h_index(45.0 * DEG, n), 63);
        assert_eq!(theta_h_index(89.9 * DEG, n), 89);
        // π/2 and beyond clamp to the last cell.
        assert_eq!(theta_h_index(FRAC_PI_2, n), 89);
        assert_eq!(theta_h_index(2.0, n), 89);
        // A linear mapping would put 45° in cell 45: the classic wrong-scale bug.
        assert_ne!(theta_h_index(45.0 * DEG, n), 45);
    }

    #[test]
    fn theta_d_index_by_hand() {
        let n = 90;
        assert_eq!(theta_d_index(0.0, n), 0);
        assert_eq!(theta_d_index(0.99 * DEG, n), 0);
        assert_eq!(theta_d_index(1.01 * DEG, n), 1);
        assert_eq!(theta_d_index(45.5 * DEG, n), 45);
        assert_eq!(theta_d_index(89.5 * DEG, n), 89);
        assert_eq!(theta_d_index(FRAC_PI_2, n), 89);
        assert_eq!(theta_d_index(-1.0, n), 0);
    }

    #[test]
    fn phi_d_index_folds_across_pi() {
        let n = 180;
        assert_eq!(phi_d_index(0.0, n), 0);
        assert_eq!(phi_d_index(10.5 * DEG, n), 10);
        assert_eq!(phi_d_index(179.9 * DEG, n), 179);
        // φd = π would land past the end (the reference clamps it to 179); on
        // the seam, within 1e-9 of 0 or π either way, bv picks cell 0.
        assert_eq!(phi_d_index(PI, n), 0);
        assert_eq!(phi_d_index(PI - 1e-12, n), 0);
        assert_eq!(phi_d_index(-1e-12, n), 0);
        assert_eq!(phi_d_index(-PI, n), 0);
        assert_eq!(phi_d_index(PI - 1e-6, n), 179);
        // Negative φd gets +π: −10.5° ≡ 169.5°, −0.1° ≡ 179.9°, −179.5° ≡ 0.5°.
        assert_eq!(phi_d_index(-10.5 * DEG, n), 169);
        assert_eq!(phi_d_index(-0.1 * DEG, n), 179);
        assert_eq!(phi_d_index(-179.5 * DEG, n), 0);
        // Same cell for φd and φd − π (reciprocity).
        for k in 0..360 {
            let p = (k as f64 + 0.25) * 0.5 * DEG; // 0.125° .. 179.875°
            assert_eq!(phi_d_index(p, n), phi_d_index(p - PI, n), "{p}");
        }
        // Continuous coordinate: periodic with period π.
        assert!((phi_d_coord(-10.5 * DEG, n) - 169.5).abs() < 1e-9);
        assert!((phi_d_coord(190.5 * DEG, n) - 10.5).abs() < 1e-9);
        assert!(phi_d_coord(-1e-300, n) < n as f64);
    }

    #[test]
    fn cell_centres_invert_the_mapping() {
        for n in [1usize, 7, 90, 180] {
            for i in 0..n {
                assert_eq!(theta_h_index(theta_h_centre(i, n), n), i);
                assert_eq!(theta_d_index(theta_d_centre(i, n), n), i);
                assert_eq!(phi_d_index(phi_d_centre(i, n), n), i);
                assert!((theta_h_coord(theta_h_centre(i, n), n) - (i as f64 + 0.5)).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn known_configurations_land_in_known_cells() {
        let d = STANDARD_DIMS;
        let cells = |wi: DVec3, wo: DVec3| {
            let hd = frame::to_half_diff(wi, wo).unwrap();
            (
                theta_h_index(hd.theta_h, d.theta_h),
                theta_d_index(hd.theta_d, d.theta_d),
                phi_d_index(hd.phi_d, d.phi_d),
            )
        };
        // Normal incidence and exit: h = n, d = n.
        assert_eq!(cells(DVec3::Z, DVec3::Z), (0, 0, 0));
        // Mirror pair at 31.4°: θh = 0, θd = 31.4° → cell 31 (whole degrees
        // are cell boundaries of θd).
        let wi = frame::from_spherical(31.4 * DEG, 0.3);
        assert_eq!(cells(wi, frame::reflect(wi)).0, 0);
        assert_eq!(cells(wi, frame::reflect(wi)).1, 31);
        // Retro-reflection at 50°: h = wi, θh = 50° → ⌊√(50/90)·90⌋ = 67, θd = 0.
        let wi = frame::from_spherical(50.0 * DEG, 1.0);
        assert_eq!((cells(wi, wi).0, cells(wi, wi).1), (67, 0));
    }

    // A line-by-line port of the reference code's std_coords_to_half_diff_coords
    // and index functions (MERL BRDFRead.cpp, 90/90/360 constants).
    fn ref_rotate(v: [f64; 3], axis: [f64; 3], angle: f64) -> [f64; 3] {
        let (s, c) = angle.sin_cos();
        let mut out = [v[0] * c, v[1] * c, v[2] * c];
        let temp = (axis[0] * v[0] + axis[1] * v[1] + axis[2] * v[2]) * (1.0 - c);
        for k in 0..3 {
            out[k] += axis[k] * temp;
        }
        let cross = [
            axis[1] * v[2] - axis[2] * v[1],
            axis[2] * v[0] - axis[0] * v[2],
            axis[0] * v[1] - axis[1] * v[0],
        ];
        for k in 0..3 {
            out[k] += cross[k] * s;
        }
        out
    }

    fn ref_half_diff(ti: f64, fi: f64, to: f64, fo: f64) -> (f64, f64, f64) {
        let inv = [ti.sin() * fi.cos(), ti.sin() * fi.sin(), ti.cos()];
        let outv = [to.sin() * fo.cos(), to.sin() * fo.sin(), to.cos()];
        let mut half = [
            (inv[0] + outv[0]) / 2.0,
            (inv[1] + outv[1]) / 2.0,
            (inv[2] + outv[2]) / 2.0,
        ];
        let l = (half[0] * half[0] + half[1] * half[1] + half[2] * half[2]).sqrt();
        half = [half[0] / l, half[1] / l, half[2] / l];
        let theta_half = half[2].acos();
        let fi_half = half[1].atan2(half[0]);
        let temp = ref_rotate(inv, [0.0, 0.0, 1.0], -fi_half);
        let diff = ref_rotate(temp, [0.0, 1.0, 0.0], -theta_half);
        (theta_half, diff[2].acos(), diff[1].atan2(diff[0]))
    }

    fn ref_indices(th: f64, td: f64, pd: f64) -> (usize, usize, usize) {
        let ih = if th <= 0.0 {
            0
        } else {
            let deg = th / (PI / 2.0) * 90.0;
            ((deg * 90.0).sqrt() as i64).clamp(0, 89) as usize
        };
        let id = ((td / (PI * 0.5) * 90.0) as i64).clamp(0, 89) as usize;
        let p = if pd < 0.0 { pd + PI } else { pd };
        let ip = ((p / PI * 360.0 / 2.0) as i64).clamp(0, 179) as usize;
        (ih, id, ip)
    }

    #[test]
    fn half_diff_and_indices_match_the_reference_code() {
        let mut rng = sampling::rng(11);
        let d = STANDARD_DIMS;
        let mut same = 0;
        let n = 20_000;
        for _ in 0..n {
            let wi = sampling::cosine_hemisphere(sampling::uniform2(&mut rng));
            let wo = sampling::cosine_hemisphere(sampling::uniform2(&mut rng));
            let (ti, fi) = frame::to_spherical(wi);
            let (to, fo) = frame::to_spherical(wo);
            let (th, td, pd) = ref_half_diff(ti, fi, to, fo);
            let hd = frame::to_half_diff(wi, wo).unwrap();
            assert!((hd.theta_h - th).abs() < 1e-9, "{wi} {wo}");
            assert!((hd.theta_d - td).abs() < 1e-9, "{wi} {wo}");
            assert!(frame::wrap_phi(hd.phi_d - pd).abs() < 1e-7, "{wi} {wo}");
            // Indices as the lookup computes them (the fast path).
            let (fh, fd, fp) = half_diff_angles(wi, wo).unwrap();
            let ours = (
                theta_h_index(fh, d.theta_h),
                theta_d_index(fd, d.theta_d),
                phi_d_index(fp, d.phi_d),
            );
            let on_seam = fold_phi_d(pd) < 1e-9 || fold_phi_d(pd) > PI - 1e-9;
            if ours == ref_indices(th, td, pd) || on_seam {
                same += 1;
            }
        }
        // Angles agree to ~1e-15; only a pair within that of a cell boundary
        // could land differently.
        assert!(same >= n - 2, "{same} of {n}");
    }

    #[test]
    fn fast_half_diff_matches_frame() {
        let mut rng = sampling::rng(12);
        for k in 0..20_000 {
            let mut wi = sampling::cosine_hemisphere(sampling::uniform2(&mut rng));
            let wo = sampling::cosine_hemisphere(sampling::uniform2(&mut rng));
            if k % 10 == 0 {
                wi = frame::reflect(wo); // θh = 0 exactly or nearly
            }
            let hd = frame::to_half_diff(wi, wo).unwrap();
            let (th, td, pd) = half_diff_angles(wi, wo).unwrap();
            // acos in frame::to_half_diff loses ~1e-8 near 0; elsewhere they agree to 1e-12.
            assert!((hd.theta_h - th).abs() < 1e-7, "{wi} {wo}");
            assert!((hd.theta_d - td).abs() < 1e-7, "{wi} {wo}");
            if hd.theta_d > 1e-6 {
                assert!(frame::wrap_phi(hd.phi_d - pd).abs() < 1e-7, "{wi} {wo}");
            }
        }
        assert_eq!(half_diff_angles(DVec3::Z, DVec3::Z), Some((0.0, 0.0, 0.0)));
        assert!(half_diff_angles(DVec3::Z, -DVec3::Z).is_none());
    }

    // --- round trip ------------------------------------------------------------

    #[test]
    fn round_trip_is_exact_at_centres_and_bounded_between() {
        let dm = dims(16, 12, 24);
        let t1 = tabulate(&Smooth, dm).unwrap();
        assert!(t1.warnings().is_empty());
        let mut bytes = Vec::new();
        t1.write_to(&mut bytes).unwrap();
        assert_eq!(bytes.len() as u64, dm.file_len());
        let t2 = MerlTable::read_from(&bytes[..], bytes.len() as u64, "mem").unwrap();
        // f32 → f64 / scale → × scale → f32 is the identity.
        assert_eq!(t1.data(), t2.data());

        let mut rng = sampling::rng(3);
        // At cell centres, through the full (wi, wo) path with a random φh, both
        // lookups return f up to f32 rounding.
        for ih in 0..dm.theta_h {
            for id in 0..dm.theta_d {
                for ip in 0..dm.phi_d {
                    let (th, td, pd) = (
                        theta_h_centre(ih, dm.theta_h),
                        theta_d_centre(id, dm.theta_d),
                        phi_d_centre(ip, dm.phi_d),
                    );
                    let (wi, wo) = frame::from_half_diff(frame::HalfDiff {
                        theta_h: th,
                        phi_h: rng.random_range(0.0..2.0 * PI),
                        theta_d: td,
                        phi_d: pd,
                    });
                    if wi.z <= 1e-9 || wo.z <= 1e-9 {
                        continue;
                    }
                    let f = Smooth::at(th, td, pd);
                    for mode in [Interpolation::Nearest, Interpolation::Trilinear] {
                        let g = t2.lookup(wi, wo, mode);
                        assert!(
                            (g - f).abs().max_element() <= 2e-7 * f.max_element(),
                            "{mode:?} {ih} {id} {ip}: {g} vs {f}"
                        );
                        // Reciprocity through the fold.
                        let r = t2.lookup(wo, wi, mode);
                        assert!((g - r).abs().max_element() <= 2e-7 * f.max_element());
                    }
                }
            }
        }

        // Between centres: the function is a sum of one-dimensional terms, so
        // the trilinear error is the sum of the 1D linear-interpolation errors,
        // each at most (spacing²/8)·max|∂²f| in index units (spacing 1):
        //   θh term 0.3 θh, θh = (π/2)(u/n)²  → ∂²/∂u² = 0.3 π / nθh²
        //   θd term 0.2 θd, linear in u        → 0
        //   φd term 0.1 cos 2φd, φd = π w/nφd   → |∂²/∂w²| ≤ 0.4 π² / nφd²
        // times k_c, plus f32 rounding (≤ 1e-7 · f). Points are kept where all
        // eight neighbouring centres are above the horizon (the table is 0
        // there, the function is not) and away from the clamped θ ends.
        let bound = |k: f64| {
            k * (0.3 * PI / (dm.theta_h * dm.theta_h) as f64
                + 0.4 * PI * PI / (dm.phi_d * dm.phi_d) as f64)
                / 8.0
                + 2e-7
        };
        let mut checked = 0;
        let mut worst = 0.0f64;
        for _ in 0..20_000 {
            let uh = rng.random_range(0.5..dm.theta_h as f64 - 0.5);
            let ud = rng.random_range(0.5..dm.theta_d as f64 - 0.5);
            let th = (uh / dm.theta_h as f64).powi(2) * FRAC_PI_2;
            let td = ud / dm.theta_d as f64 * FRAC_PI_2;
            let th_hi = theta_h_centre((uh - 0.5).ceil() as usize, dm.theta_h);
            let td_hi = theta_d_centre((ud - 0.5).ceil() as usize, dm.theta_d);
            if th_hi + td_hi >= FRAC_PI_2 - 1e-6 {
                continue;
            }
            let pd = rng.random_range(-PI..PI);
            let (wi, wo) = frame::from_half_diff(frame::HalfDiff {
                theta_h: th,
                phi_h: rng.random_range(0.0..2.0 * PI),
                theta_d: td,
                phi_d: pd,
            });
            let f = Smooth::at(th, td, pd);
            let g = t2.lookup(wi, wo, Interpolation::Trilinear);
            for c in 0..3 {
                let err = (g[c] - f[c]).abs();
                assert!(err <= bound(K[c]), "channel {c}: {err} > {}", bound(K[c]));
                worst = worst.max(err / bound(K[c]));
            }
            checked += 1;
        }
        assert!(checked > 5_000, "{checked}");
        // The bound is not vacuous: the error reaches a good part of it.
        assert!(worst > 0.2, "{worst}");
    }

    #[test]
    fn full_size_file_round_trip() {
        let dir = temp_dir("full");
        let path = dir.join("lambert.binary");
        let albedo = Rgb::new(0.2, 0.5, 0.8);
        let t = tabulate(&Lambert::new(albedo), STANDARD_DIMS).unwrap();
        t.write(&path).unwrap();
        assert_eq!(std::fs::metadata(&path).unwrap().len(), 34_992_012);
        let back = MerlTable::read(&path).unwrap();
        assert_eq!(back.dims(), STANDARD_DIMS);
        assert_eq!(back.data(), t.data());
        // No temporary file is left beside it.
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        let f = back.lookup(
            frame::from_spherical(0.4, 0.0),
            frame::from_spherical(0.9, 2.0),
            Interpolation::Trilinear,
        );
        let want = albedo / PI;
        assert!((f - want).abs().max_element() < 1e-7 * want.max_element());
        // Max over cells is ρ/π (cells below the horizon hold 0).
        for c in 0..3 {
            assert!((back.ranges()[c].max - want[c]).abs() < 1e-7);
            assert_eq!(back.ranges()[c].min, 0.0);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn tabulated_cook_torrance_tracks_the_analytic_lobe() {
        // A glossy GGX lobe (α = 0.3) tabulated at half the public resolution
        // per axis: the table's lobe at θi = 30° against the analytic one, as
        // the GUI's "tabulated vs analytic" error shows it. Trilinear must beat
        // nearest (it removes the O(cell) staircase, leaving O(cell²)), and
        // both stay within a few percent for a lobe many cells wide
        // (measured: 0.13 % and 0.76 %).
        let spec = ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"kd": 0.2, "ks": 0.8, "distribution": "ggx", "alpha": 0.3}),
        )
        .unwrap();
        let analytic = spec.build().unwrap();
        let table = Arc::new(tabulate(analytic.as_ref(), dims(45, 45, 90)).unwrap());
        let wi = frame::from_spherical(30.0 * DEG, 0.0);
        let err = |mode| {
            let m = crate::models::merl::Merl::from_table(table.clone(), mode);
            crate::represent::sh::relative_l2(&m, analytic.as_ref(), wi, true, 96).unwrap()
        };
        let (near, tri) = (err(Interpolation::Nearest), err(Interpolation::Trilinear));
        assert!(tri < near, "trilinear {tri} vs nearest {near}");
        assert!(
            tri < 0.005 && near < 0.03,
            "trilinear {tri}, nearest {near}"
        );
    }

    #[test]
    fn sampling_proxy_follows_the_tabulated_lobe() {
        // GGX lobes tabulated at the public resolution: the proxy's α (by
        // the θh profile's half maximum, against the closed-form D of the
        // model's α) and its weights; a Lambertian table is all floor.
        for alpha in [0.08, 0.3] {
            let spec = ModelSpec::from_json(
                "cook-torrance",
                &serde_json::json!({"kd": 0.0, "ks": 1.0, "distribution": "ggx", "alpha": alpha,
                    "fresnel": "schlick", "f0": 0.9}),
            )
            .unwrap();
            let b = spec.build().unwrap();
            let p = tabulate(b.as_ref(), dims(90, 90, 180))
                .unwrap()
                .sampling_proxy();
            println!("GGX α {alpha}: {p:?}");
            assert!((p.alpha / alpha - 1.0).abs() < 0.2, "α {alpha}: {p:?}");
            assert!(p.diffuse < 0.2 * (p.diffuse + p.glossy), "{p:?}");
        }
        let spec = ModelSpec::from_json("lambert", &serde_json::json!({"albedo": 0.7})).unwrap();
        let b = spec.build().unwrap();
        let p = tabulate(b.as_ref(), dims(45, 45, 90))
            .unwrap()
            .sampling_proxy();
        println!("lambert 0.7: {p:?}");
        assert!((p.diffuse - 0.7).abs() < 1e-3 && p.glossy < 1e-3, "{p:?}");
    }

    // --- bad files -----------------------------------------------------------

    fn header(d: [i32; 3]) -> Vec<u8> {
        d.iter().flat_map(|x| x.to_le_bytes()).collect()
    }

    fn file_with(d: [i32; 3], values: &[f64]) -> Vec<u8> {
        let mut b = header(d);
        for v in values {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b
    }

    #[test]
    fn bad_file_corpus_is_refused_with_clear_messages() {
        let dir = temp_dir("bad");
        let good = file_with([2, 2, 2], &[100.0; 24]);
        let mut extra = good.clone();
        extra.extend_from_slice(&[0u8; 5]);
        let overflow = header([2048, 2048, 2048]);
        let mut huge = header([4000, 4000, 1]);
        huge.extend_from_slice(&[0u8; 64]);
        let corpus: Vec<(&str, Vec<u8>, &[&str])> = vec![
            ("empty", vec![], &["empty file", "12-byte header"]),
            ("short", vec![1, 2, 3], &["too short", "3 bytes"]),
            (
                "header-only",
                header([90, 90, 180]),
                &["90×90×180", "34992012", "has 12"],
            ),
            (
                "truncated",
                good[..good.len() - 8].to_vec(),
                &["truncated", "8 fewer"],
            ),
            ("extra", extra, &["5 extra"]),
            (
                "zero",
                file_with([0, 90, 180], &[]),
                &["nθh = 0", "positive"],
            ),
            (
                "negative",
                file_with([90, -90, 180], &[]),
                &["nθd = -90", "positive"],
            ),
            (
                "too-big-dim",
                header([90, 90, 100_000]),
                &["nφd = 100000", "cap of 4096"],
            ),
            (
                "overflow",
                overflow,
                &["2048×2048×2048", "8589934592", "cap"],
            ),
            (
                "huge-tiny",
                huge,
                &["4000×4000×1", "need 384000012 bytes", "has 76"],
            ),
        ];
        for (name, bytes, expect) in corpus {
            let path = dir.join(format!("{name}.binary"));
            std::fs::write(&path, &bytes).unwrap();
            let err = MerlTable::read(&path).unwrap_err().to_string();
            assert!(err.contains(&format!("{name}.binary")), "{name}: {err}");
            for e in expect {
                assert!(err.contains(e), "{name}: `{err}` lacks `{e}`");
            }
            // The model reports the same error instead of building.
            let mut spec = ModelSpec::new("merl").unwrap();
            spec.set_str("path", path.to_str().unwrap()).unwrap();
            assert!(spec.build().is_err());
        }
        // A directory and a missing file.
        assert!(MerlTable::read(&dir).is_err());
        assert!(MerlTable::read(dir.join("missing.binary")).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn stream_shorter_or_longer_than_declared_is_refused() {
        let good = file_with([2, 2, 2], &[100.0; 24]);
        let n = good.len() as u64;
        let err = MerlTable::read_from(&good[..100], n, "s").unwrap_err();
        assert!(err.to_string().contains("truncated"), "{err}");
        let mut longer = good.clone();
        longer.push(0);
        let err = MerlTable::read_from(&longer[..], n, "s").unwrap_err();
        assert!(err.to_string().contains("goes on past"), "{err}");
        assert!(MerlTable::read_from(&good[..], n, "s").is_ok());
    }

    #[test]
    fn unmeasured_and_non_finite_samples_are_zeroed_and_counted() {
        let mut v = vec![1500.0; 24];
        v[0] = -1.0; // red unmeasured
        v[3] = f64::NAN; // red NaN
        v[9] = f64::INFINITY; // green inf
        v[17] = -1.0; // blue unmeasured
        v[18] = 1e300; // blue: finite, but beyond f32 after scaling
        v[19] = f64::NEG_INFINITY; // blue −inf: non-finite, not "unmeasured"
        let bytes = file_with([2, 2, 2], &v);
        let t = MerlTable::read_from(&bytes[..], bytes.len() as u64, "w").unwrap();
        assert_eq!(t.warnings().unmeasured, [1, 0, 1]);
        assert_eq!(t.warnings().non_finite, [1, 1, 2]);
        assert_eq!(t.data()[0], 0.0);
        assert_eq!(t.data()[3], 0.0);
        assert_eq!(t.data()[18], 0.0);
        assert!(t.data().iter().all(|x| x.is_finite() && *x >= 0.0));
        // 1500 stored is f = scale · 1500 = 1, 1.15, 1.66.
        assert!((t.data()[1] - 1.0).abs() < 1e-7);
        assert!((t.data()[8 + 2] - 1.15).abs() < 1e-6);
        assert!((t.data()[16] - 1.66).abs() < 1e-6);
        assert_eq!(t.ranges()[0].valid, 6);
        assert!((t.ranges()[2].max - 1.66).abs() < 1e-6);
        let m = t.warnings().messages().join("; ");
        assert!(m.contains("2 negative samples"), "{m}");
        assert!(m.contains("4 NaN or infinite"), "{m}");
    }

    #[test]
    fn dims_parse() {
        assert_eq!(MerlDims::parse("90,90,180").unwrap(), STANDARD_DIMS);
        assert_eq!(MerlDims::parse(" 4, 5 ,6").unwrap(), dims(4, 5, 6));
        assert!(MerlDims::parse("90,90").is_err());
        assert!(MerlDims::parse("90,x,180").is_err());
        assert!(MerlDims::parse("90,0,180").is_err());
        assert!(MerlDims::parse("4096,4096,4096").is_err());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(400))]

        /// Arbitrary bytes never panic, and whatever is accepted is consistent.
        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
            if let Ok(t) = MerlTable::read_from(&bytes[..], bytes.len() as u64, "p") {
                prop_assert_eq!(t.dims().file_len(), bytes.len() as u64);
                prop_assert!(t.data().iter().all(|x| x.is_finite() && *x >= 0.0));
            }
        }

        /// Small valid headers with random lengths and payloads.
        #[test]
        fn random_headers_and_lengths(
            d in proptest::array::uniform3(-3i32..5),
            extra in -30i64..30,
            fill in any::<u64>(),
        ) {
            let cells = d.iter().map(|&x| x.max(0) as i64).product::<i64>();
            let len = (12 + 24 * cells + extra).max(0) as usize;
            let mut bytes = header(d);
            while bytes.len() < len {
                bytes.extend_from_slice(&fill.to_le_bytes());
            }
            bytes.truncate(len);
            let r = MerlTable::read_from(&bytes[..], bytes.len() as u64, "p");
            let valid = d.iter().all(|&x| x > 0) && extra == 0;
            prop_assert_eq!(r.is_ok(), valid, "{:?}", r.err());
        }
    }

    // --- model and cache -------------------------------------------------------

    #[test]
    fn merl_model_builds_from_a_file_and_is_cached() {
        let dir = temp_dir("model");
        let path = dir.join("smooth.binary");
        tabulate(&Smooth, dims(8, 8, 16))
            .unwrap()
            .write(&path)
            .unwrap();

        let mut spec = ModelSpec::new("merl").unwrap();
        let err = spec.build().unwrap_err().to_string();
        assert!(
            err.contains("path") && err.contains("no file given"),
            "{err}"
        );
        spec.set_str("path", path.to_str().unwrap()).unwrap();
        let b = spec.build().unwrap();
        // Built twice, and with the other lookup: one cached table.
        let t1 = read_cached(&path).unwrap();
        let same = |b: &dyn Brdf| {
            b.file_data()
                .is_some_and(|d| std::ptr::addr_eq(Arc::as_ptr(&d), Arc::as_ptr(&t1)))
        };
        assert!(same(b.as_ref()));
        let b2 = spec.build().unwrap();
        assert!(same(b2.as_ref()));
        assert!(spec.set_str("interpolation", "cubic").is_err());
        spec.set_str("interpolation", "nearest").unwrap();
        let b3 = spec.build().unwrap();
        assert!(same(b3.as_ref()));
        let wi3 = frame::from_spherical(0.3, 0.2);
        let wo3 = frame::from_spherical(0.5, 2.2);
        assert_eq!(
            b3.eval(wi3, wo3),
            t1.lookup(wi3, wo3, Interpolation::Nearest)
        );

        let wi = frame::from_spherical(0.3, 0.2);
        let wo = frame::from_spherical(0.5, 2.2);
        assert_eq!(b.eval(wi, wo), t1.lookup(wi, wo, Interpolation::Trilinear));
        assert_eq!(b.eval(wi, -wo), Rgb::ZERO);
        let c = b.claims();
        assert!(c.reciprocal && c.isotropic && !c.energy_conserving);

        // A rewritten file (different size) is read again.
        tabulate(&Smooth, dims(4, 4, 8))
            .unwrap()
            .write(&path)
            .unwrap();
        let b4 = spec.build().unwrap();
        assert!(!same(b4.as_ref()));
        assert_eq!(read_cached(&path).unwrap().dims(), dims(4, 4, 8));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn progress_reaches_the_file_length_and_the_cache_reports_hits() {
        let dir = temp_dir("progress");
        let path = dir.join("smooth.binary");
        let dm = dims(20, 20, 40); // 192,012 bytes: several 64 KiB chunks
        tabulate(&Smooth, dm).unwrap().write(&path).unwrap();
        let mut seen: Vec<(u64, u64)> = Vec::new();
        let t = MerlTable::read_with_progress(&path, &mut |a, b| seen.push((a, b))).unwrap();
        let len = dm.file_len();
        assert!(seen.len() >= 4, "{seen:?}");
        assert!(seen.iter().all(|&(_, total)| total == len));
        assert!(seen.windows(2).all(|w| w[0].0 < w[1].0), "{seen:?}");
        assert_eq!(seen.first().unwrap().0, HEADER_BYTES);
        assert_eq!(seen.last().unwrap().0, len);
        assert_eq!(t, MerlTable::read(&path).unwrap());

        assert!(!is_cached(&path));
        assert!(!is_cached(dir.join("missing.binary")));
        let mut calls = 0;
        let a = read_cached_with_progress(&path, &mut |_, _| calls += 1).unwrap();
        assert!(calls >= 4);
        assert!(is_cached(&path));
        // A hit reports completion once and returns the same table.
        let mut hit = Vec::new();
        let b = read_cached_with_progress(&path, &mut |x, y| hit.push((x, y))).unwrap();
        assert!(Arc::ptr_eq(&a, &b));
        assert_eq!(hit, vec![(len, len)]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn trilinear_wraps_in_phi_d_and_clamps_in_theta() {
        // One θh, one θd, four φd cells with values 0, 1, 2, 3 (red).
        let dm = dims(1, 1, 4);
        let mut v = vec![0f32; 12];
        v[..4].copy_from_slice(&[0.0, 1.0, 2.0, 3.0]);
        let t = MerlTable::from_values(dm, v).unwrap();
        let at = |pd: f64| t.lookup_angles(0.1, 0.1, pd, Interpolation::Trilinear).x;
        // Centres at φd = (i + ½)π/4.
        assert!((at(0.5 * PI / 4.0) - 0.0).abs() < 1e-12);
        assert!((at(1.0 * PI / 4.0) - 0.5).abs() < 1e-12);
        // Between the last centre (3.5π/4) and the first (0.5π/4 + π): wraps.
        assert!((at(PI) - 1.5).abs() < 1e-12);
        assert!((at(0.0) - 1.5).abs() < 1e-12);
        assert!((at(-0.25 * PI / 4.0) - 2.25).abs() < 1e-12);
        // Nearest on the φd = 0 ≡ π seam: cell 0, whichever side.
        assert_eq!(t.lookup_angles(0.1, 0.1, PI, Interpolation::Nearest).x, 0.0);
        assert_eq!(
            t.lookup_angles(0.1, 0.1, -1e-13, Interpolation::Nearest).x,
            0.0
        );
        // θ axes of one cell: constant.
        assert_eq!(
            t.lookup_angles(1.5, 1.5, 1.0 * PI / 4.0, Interpolation::Trilinear)
                .x,
            at(1.0 * PI / 4.0)
        );
    }
}
