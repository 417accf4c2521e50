//! MERL `.binary` tables (SPEC §4): reader, writer, index mapping, lookups and
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
//! Every index is clamped to `0..n`. Angles are those of
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

use crate::{Brdf, BvError, Result, Rgb, frame};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use std::io::{BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Bytes of the header (three little-endian `int32`).
pub const HEADER_BYTES: u64 = 12;
/// Largest accepted value of any one dimension.
pub const MAX_DIM: usize = 4096;
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
    if u > 0.0 {
        (u as usize).min(n - 1)
    } else {
        0
    }
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

/// Cell index along φd of the reference code: fold `φd < 0` by `+π`, then
/// `⌊φd/π · n⌋`, clamped (so `φd = π` exactly lands in the last cell, as there).
#[inline]
pub fn phi_d_index(phi_d: f64, n: usize) -> usize {
    let p = fold_phi_d(phi_d);
    if p > 0.0 {
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
}

impl MerlWarnings {
    /// Whether nothing was found.
    pub fn is_empty(&self) -> bool {
        self.unmeasured == [0; 3] && self.non_finite == [0; 3]
    }

    /// Human-readable warnings, one per kind that occurred.
    pub fn messages(&self) -> Vec<String> {
        let mut out = Vec::new();
        let per = |c: [usize; 3]| {
            format!(
                "{} (red {}, green {}, blue {})",
                c.iter().sum::<usize>(),
                c[0],
                c[1],
                c[2]
            )
        };
        if self.unmeasured != [0; 3] {
            out.push(format!(
                "{} negative samples (not measured) read as 0",
                per(self.unmeasured)
            ));
        }
        if self.non_finite != [0; 3] {
            out.push(format!(
                "{} NaN or infinite samples set to 0",
                per(self.non_finite)
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
#[derive(Debug, Clone, PartialEq)]
pub struct MerlTable {
    dims: MerlDims,
    data: Vec<f32>,
    warnings: MerlWarnings,
    ranges: [ChannelRange; 3],
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
        }
        Ok(Self {
            dims,
            data,
            warnings,
            ranges,
        })
    }

    /// Reads a `.binary` file. The header and the file's size are checked
    /// against each other before anything large is allocated.
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let file = std::fs::File::open(path).map_err(|e| file_err(&name, e.to_string()))?;
        let meta = file
            .metadata()
            .map_err(|e| file_err(&name, e.to_string()))?;
        if !meta.is_file() {
            return Err(file_err(&name, "not a regular file"));
        }
        Self::read_from(file, meta.len(), &name)
    }

    /// Reads a table from a stream of `len` bytes (`name` is used in errors).
    ///
    /// Refuses, with a message saying what was expected and what was found: a
    /// stream shorter than the header; dimensions that are zero, negative,
    /// above [`MAX_DIM`] or whose product is above [`MAX_CELLS`]; a `len` that
    /// differs from `12 + 24 · cells`; a stream that ends early or goes on
    /// past `len`. The table is allocated only after these checks, so memory
    /// stays within half of `len`.
    pub fn read_from(mut reader: impl Read, len: u64, name: &str) -> Result<Self> {
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
        for (c, range) in ranges.iter_mut().enumerate() {
            let mut acc = Acc::new();
            let mut left = dims.cells();
            while left > 0 {
                let k = left.min(CHUNK);
                let bytes = &mut buf[..k * 8];
                read_exact(&mut reader, bytes, name, offset, len)?;
                offset += bytes.len() as u64;
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
        })
    }

    /// Writes the table as a `.binary` file, atomically: to a temporary file
    /// beside `path`, then renamed over it, so a reader never sees half a file.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let file_name = path
            .file_name()
            .ok_or_else(|| file_err(&name, "not a file path"))?;
        let mut tmp_name = std::ffi::OsString::from(".");
        tmp_name.push(file_name);
        tmp_name.push(format!(".tmp-{}", std::process::id()));
        let tmp: PathBuf = path.with_file_name(tmp_name);
        let result = (|| -> std::io::Result<()> {
            let file = std::fs::File::create(&tmp)?;
            let mut w = BufWriter::with_capacity(1 << 16, file);
            self.write_to(&mut w)?;
            let file = w.into_inner().map_err(|e| e.into_error())?;
            file.sync_all()?;
            std::fs::rename(&tmp, path)
        })();
        result.map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            file_err(&name, e.to_string())
        })
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
    pub fn lookup_angles(&self, theta_h: f64, theta_d: f64, phi_d: f64, mode: Interpolation) -> Rgb {
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
        match frame::to_half_diff(wi, wo) {
            Some(hd) => self.lookup_angles(hd.theta_h, hd.theta_d, hd.phi_d, mode),
            None => Rgb::ZERO,
        }
    }
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
                format!("truncated: the data ends before byte {offset} + {} of the {len} expected", buf.len()),
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
    let path = path.as_ref();
    let name = path.display().to_string();
    let canon = std::fs::canonicalize(path).map_err(|e| file_err(&name, e.to_string()))?;
    let meta = std::fs::metadata(&canon).map_err(|e| file_err(&name, e.to_string()))?;
    let (modified, len) = (meta.modified().ok(), meta.len());
    // A poisoned lock only means another thread panicked mid-update; the
    // entries are still whole tables, so keep using them.
    let mut guard = CACHE.lock().unwrap_or_else(|e| e.into_inner());
    let (clock, entries) = &mut *guard;
    *clock += 1;
    let now = *clock;
    if let Some(e) = entries
        .iter_mut()
        .find(|e| e.path == canon && e.modified == modified && e.len == len && modified.is_some())
    {
        e.last_use = now;
        return Ok(e.table.clone());
    }
    let table = Arc::new(MerlTable::read(path)?);
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
