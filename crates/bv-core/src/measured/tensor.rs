//! The `tensor_file` container of the RGL material database (Dupuy & Jakob
//! 2018) as Mitsuba's `TensorFile` (`src/core/tensor.cpp`) and the RGL
//! reference loader (`powitacq`) read it: named, typed n-d arrays.
//!
//! # Layout (little-endian)
//! - 12 bytes of magic `tensor_file\0`, 2 bytes of version (major 1, minor
//!   0), a `u32` field count;
//! - per field: `u16` name length and the name's bytes, `u16` rank, `u8`
//!   dtype code ([`Dtype`]), `u64` offset of the data from the start of the
//!   file, then `rank` `u64` sizes (the slowest-varying first);
//! - the data, `∏ shape · size(dtype)` bytes at each field's offset.
//!
//! # Checks
//! Every bounded read is checked before anything is allocated from what the
//! file claims: the header, the field count (each descriptor takes at least
//! 13 bytes, so a count the file cannot hold is refused), each name and
//! shape inside the file, known dtype codes, the product of a shape without
//! overflow, and each field's data inside the file. A field's data is a
//! range of the file's own bytes, so no claimed shape allocates more than
//! the file holds. Errors are [`BvError::File`] naming the file.

use crate::{BvError, Result, fsio};
use std::path::Path;

/// The first 12 bytes of every tensor file.
pub const MAGIC: &[u8; 12] = b"tensor_file\0";
/// Bytes before the first field descriptor: magic, version, field count.
pub const HEADER_BYTES: usize = 12 + 2 + 4;
/// The smallest field descriptor (empty name, rank 0): name length, rank,
/// dtype and offset.
const MIN_DESCRIPTOR: usize = 2 + 2 + 1 + 8;
/// The largest file read (real RGL materials are 0.6–5 MB).
pub const MAX_FILE_BYTES: u64 = 1 << 30;

/// Element types, with the codes of the file format (Mitsuba's
/// `Struct::Type` as the RGL files use it; `powitacq`'s `Tensor::Type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dtype {
    /// Code 1.
    UInt8,
    /// Code 2.
    Int8,
    /// Code 3.
    UInt16,
    /// Code 4.
    Int16,
    /// Code 5.
    UInt32,
    /// Code 6.
    Int32,
    /// Code 7.
    UInt64,
    /// Code 8.
    Int64,
    /// Code 9 (IEEE 754 binary16).
    Float16,
    /// Code 10.
    Float32,
    /// Code 11.
    Float64,
}

impl Dtype {
    /// Every type, in code order.
    pub const ALL: [Dtype; 11] = [
        Dtype::UInt8,
        Dtype::Int8,
        Dtype::UInt16,
        Dtype::Int16,
        Dtype::UInt32,
        Dtype::Int32,
        Dtype::UInt64,
        Dtype::Int64,
        Dtype::Float16,
        Dtype::Float32,
        Dtype::Float64,
    ];

    /// The type of a file's code (0 is "invalid" and, like codes above 11,
    /// has none).
    pub fn from_code(code: u8) -> Option<Self> {
        Self::ALL.get(usize::from(code).checked_sub(1)?).copied()
    }

    /// The file's code of this type.
    pub fn code(self) -> u8 {
        Self::ALL.iter().position(|&d| d == self).unwrap_or(0) as u8 + 1
    }

    /// Bytes per element.
    pub fn size(self) -> usize {
        match self {
            Dtype::UInt8 | Dtype::Int8 => 1,
            Dtype::UInt16 | Dtype::Int16 | Dtype::Float16 => 2,
            Dtype::UInt32 | Dtype::Int32 | Dtype::Float32 => 4,
            Dtype::UInt64 | Dtype::Int64 | Dtype::Float64 => 8,
        }
    }

    /// The type's name in messages (`float32`).
    pub fn name(self) -> &'static str {
        match self {
            Dtype::UInt8 => "uint8",
            Dtype::Int8 => "int8",
            Dtype::UInt16 => "uint16",
            Dtype::Int16 => "int16",
            Dtype::UInt32 => "uint32",
            Dtype::Int32 => "int32",
            Dtype::UInt64 => "uint64",
            Dtype::Int64 => "int64",
            Dtype::Float16 => "float16",
            Dtype::Float32 => "float32",
            Dtype::Float64 => "float64",
        }
    }

    /// Whether the type is a floating-point one.
    pub fn is_float(self) -> bool {
        matches!(self, Dtype::Float16 | Dtype::Float32 | Dtype::Float64)
    }

    /// Element `b` (exactly [`Dtype::size`] bytes) as an `f64`.
    fn decode(self, b: &[u8]) -> f64 {
        let a = |n: usize| -> [u8; 8] {
            let mut x = [0u8; 8];
            x[..n].copy_from_slice(&b[..n]);
            x
        };
        match self {
            Dtype::UInt8 => f64::from(b[0]),
            Dtype::Int8 => f64::from(b[0] as i8),
            Dtype::UInt16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
            Dtype::Int16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
            Dtype::UInt32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Dtype::Int32 => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Dtype::UInt64 => u64::from_le_bytes(a(8)) as f64,
            Dtype::Int64 => i64::from_le_bytes(a(8)) as f64,
            Dtype::Float16 => half_to_f64(u16::from_le_bytes([b[0], b[1]])),
            Dtype::Float32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Dtype::Float64 => f64::from_le_bytes(a(8)),
        }
    }
}

/// IEEE 754 binary16 to `f64` (subnormals, infinities and NaN included).
pub fn half_to_f64(h: u16) -> f64 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = i32::from((h >> 10) & 0x1f);
    let frac = f64::from(h & 0x3ff);
    match exp {
        0 => sign * frac * 2f64.powi(-24),
        31 if frac == 0.0 => sign * f64::INFINITY,
        31 => f64::NAN,
        e => sign * (1.0 + frac / 1024.0) * 2f64.powi(e - 15),
    }
}

/// One field's descriptor.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Field {
    /// Its name.
    pub name: String,
    /// Element type.
    pub dtype: Dtype,
    /// Sizes, slowest-varying first.
    pub shape: Vec<u64>,
    /// Offset of the data from the start of the file.
    pub offset: u64,
}

impl Field {
    /// Number of elements (checked when the file was parsed).
    pub fn len(&self) -> usize {
        self.shape.iter().product::<u64>() as usize
    }

    /// Whether the field holds no element.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The shape as messages write it (`[1, 8, 128, 128]`).
    pub fn shape_text(&self) -> String {
        let parts: Vec<String> = self.shape.iter().map(u64::to_string).collect();
        format!("[{}]", parts.join(", "))
    }
}

/// A parsed tensor file: its bytes and the fields found in them.
#[derive(Debug, Clone)]
pub struct TensorFile {
    name: String,
    bytes: Vec<u8>,
    fields: Vec<Field>,
}

fn file_err(name: &str, reason: impl Into<String>) -> BvError {
    BvError::File {
        path: name.to_string(),
        reason: reason.into(),
    }
}

/// A cursor over the header that refuses to read past the end.
struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
    name: &'a str,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(file_err(
                self.name,
                format!(
                    "truncated: {what} needs {n} bytes at byte {}, the file has {}",
                    self.at,
                    self.bytes.len()
                ),
            ));
        };
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn u16(&mut self, what: &str) -> Result<u16> {
        let b = self.take(2, what)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }

    fn u64(&mut self, what: &str) -> Result<u64> {
        let b = self.take(8, what)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(u64::from_le_bytes(a))
    }
}

impl TensorFile {
    /// Reads and parses the file at `path` (at most [`MAX_FILE_BYTES`]; a
    /// file handed in with [`fsio::provide`] is read from memory).
    pub fn read(path: &Path) -> Result<Self> {
        let bytes = fsio::read_capped(path, MAX_FILE_BYTES, "an RGL .bsdf tensor file")?;
        Self::parse(bytes, &path.display().to_string())
    }

    /// Parses the bytes of a tensor file (`name` is used in errors).
    pub fn parse(bytes: Vec<u8>, name: &str) -> Result<Self> {
        let len = bytes.len();
        if len < HEADER_BYTES {
            return Err(file_err(
                name,
                format!(
                    "{} ({len} bytes): a tensor file starts with an 18-byte header (`tensor_file\\0`, version, field count)",
                    if len == 0 { "empty file" } else { "too short" }
                ),
            ));
        }
        if &bytes[..12] != MAGIC {
            return Err(file_err(
                name,
                format!(
                    "not a tensor file: it starts with {:?}, not `tensor_file\\0`",
                    String::from_utf8_lossy(&bytes[..12])
                ),
            ));
        }
        let (major, minor) = (bytes[12], bytes[13]);
        if (major, minor) != (1, 0) {
            return Err(file_err(
                name,
                format!("tensor file version {major}.{minor}; only version 1.0 is known"),
            ));
        }
        let count = u32::from_le_bytes([bytes[14], bytes[15], bytes[16], bytes[17]]) as usize;
        let room = (len - HEADER_BYTES) / MIN_DESCRIPTOR;
        if count > room {
            return Err(file_err(
                name,
                format!(
                    "the header claims {count} fields, but the {len}-byte file has room for at most {room} field descriptors"
                ),
            ));
        }
        let mut cur = Cursor {
            bytes: &bytes,
            at: HEADER_BYTES,
            name,
        };
        let mut fields: Vec<Field> = Vec::with_capacity(count);
        for k in 0..count {
            let what = format!("field {}", k + 1);
            let n = usize::from(cur.u16(&format!("the name length of {what}"))?);
            let raw = cur.take(n, &format!("the name of {what}"))?;
            let fname = String::from_utf8_lossy(raw).into_owned();
            let what = format!("field `{fname}`");
            let rank = usize::from(cur.u16(&format!("the rank of {what}"))?);
            let code = cur.take(1, &format!("the dtype of {what}"))?[0];
            let dtype = Dtype::from_code(code).ok_or_else(|| {
                file_err(
                    name,
                    format!("{what} has unknown dtype code {code} (known: 1 uint8 … 10 float32, 11 float64)"),
                )
            })?;
            let offset = cur.u64(&format!("the data offset of {what}"))?;
            // The shape's bytes are checked to be in the file before the
            // vector is sized by the claimed rank.
            let shape_bytes = cur.take(8 * rank, &format!("the shape of {what}"))?;
            let shape: Vec<u64> = shape_bytes
                .chunks_exact(8)
                .map(|c| {
                    let mut a = [0u8; 8];
                    a.copy_from_slice(c);
                    u64::from_le_bytes(a)
                })
                .collect();
            let data_len = shape
                .iter()
                .try_fold(dtype.size() as u64, |acc, &s| acc.checked_mul(s));
            let end = data_len.and_then(|d| offset.checked_add(d));
            match (data_len, end) {
                (Some(d), Some(e)) if e <= len as u64 => {
                    let _ = d;
                }
                (Some(d), _) => {
                    return Err(file_err(
                        name,
                        format!(
                            "{what} ({} {}, {d} bytes at offset {offset}) ends past the end of the {len}-byte file",
                            dtype.name(),
                            shape_text(&shape)
                        ),
                    ));
                }
                (None, _) => {
                    return Err(file_err(
                        name,
                        format!(
                            "{what} claims shape {} of {}: more bytes than any file holds",
                            shape_text(&shape),
                            dtype.name()
                        ),
                    ));
                }
            }
            if fields.iter().any(|f| f.name == fname) {
                return Err(file_err(name, format!("{what} appears twice")));
            }
            fields.push(Field {
                name: fname,
                dtype,
                shape,
                offset,
            });
        }
        Ok(Self {
            name: name.to_string(),
            bytes,
            fields,
        })
    }

    /// The file's name, as given.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The fields, in file order.
    pub fn fields(&self) -> &[Field] {
        &self.fields
    }

    /// The field named `name`, if there is one.
    pub fn field(&self, name: &str) -> Option<&Field> {
        self.fields.iter().find(|f| f.name == name)
    }

    /// The field named `name`, or an error saying the file lacks it.
    pub fn require(&self, name: &str) -> Result<&Field> {
        self.field(name).ok_or_else(|| {
            let have: Vec<&str> = self.fields.iter().map(|f| f.name.as_str()).collect();
            file_err(
                &self.name,
                format!("no field `{name}` (the file has: {})", have.join(", ")),
            )
        })
    }

    /// The raw bytes of a field (inside the file: checked on parsing).
    pub fn raw(&self, f: &Field) -> &[u8] {
        let start = f.offset as usize;
        &self.bytes[start..start + f.len() * f.dtype.size()]
    }

    /// A field's elements as `f64`, whatever its dtype (integers exactly up
    /// to 2⁵³; binary16 widened).
    pub fn values(&self, f: &Field) -> Vec<f64> {
        let size = f.dtype.size();
        self.raw(f)
            .chunks_exact(size)
            .map(|b| f.dtype.decode(b))
            .collect()
    }

    /// A field's elements as `f64` after checking its rank, that every
    /// element is finite and (with `min`) at least `min`: what a table of
    /// the material must satisfy.
    pub fn finite_values(&self, f: &Field, rank: usize, min: Option<f64>) -> Result<Vec<f64>> {
        if f.shape.len() != rank {
            return Err(file_err(
                &self.name,
                format!(
                    "field `{}` has shape {}, expected rank {rank}",
                    f.name,
                    f.shape_text()
                ),
            ));
        }
        let v = self.values(f);
        if let Some((i, x)) = v
            .iter()
            .enumerate()
            .find(|(_, x)| !x.is_finite() || min.is_some_and(|m| **x < m))
        {
            return Err(file_err(
                &self.name,
                format!(
                    "field `{}` holds {x} at element {i}{}",
                    f.name,
                    match min {
                        Some(m) if x.is_finite() => format!(" (values must be ≥ {m})"),
                        _ => " (values must be finite)".to_string(),
                    }
                ),
            ));
        }
        Ok(v)
    }
}

fn shape_text(shape: &[u64]) -> String {
    let parts: Vec<String> = shape.iter().map(u64::to_string).collect();
    format!("[{}]", parts.join(", "))
}

/// Builds a tensor file: fields are added in order and written after the
/// descriptors, each at an offset that is a multiple of 8.
#[derive(Debug, Default, Clone)]
pub struct TensorWriter {
    fields: Vec<(String, Dtype, Vec<u64>, Vec<u8>)>,
}

impl TensorWriter {
    /// An empty file.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a field of raw little-endian bytes (the caller's `bytes` must be
    /// `∏ shape · size(dtype)` long).
    pub fn raw(&mut self, name: &str, dtype: Dtype, shape: &[u64], bytes: Vec<u8>) -> &mut Self {
        self.fields
            .push((name.to_string(), dtype, shape.to_vec(), bytes));
        self
    }

    /// Adds a `float32` field.
    pub fn f32(&mut self, name: &str, shape: &[u64], values: &[f32]) -> &mut Self {
        let bytes = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.raw(name, Dtype::Float32, shape, bytes)
    }

    /// Adds a `uint8` field.
    pub fn u8(&mut self, name: &str, shape: &[u64], values: &[u8]) -> &mut Self {
        self.raw(name, Dtype::UInt8, shape, values.to_vec())
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut head = Vec::new();
        head.extend_from_slice(MAGIC);
        head.extend_from_slice(&[1, 0]);
        head.extend_from_slice(&(self.fields.len() as u32).to_le_bytes());
        let desc_len: usize = self
            .fields
            .iter()
            .map(|(n, _, s, _)| MIN_DESCRIPTOR + n.len() + 8 * s.len())
            .sum();
        let mut offset = (HEADER_BYTES + desc_len).next_multiple_of(8);
        let mut offsets = Vec::with_capacity(self.fields.len());
        for (_, _, _, b) in &self.fields {
            offsets.push(offset);
            offset = (offset + b.len()).next_multiple_of(8);
        }
        for ((n, d, s, _), off) in self.fields.iter().zip(&offsets) {
            head.extend_from_slice(&(n.len() as u16).to_le_bytes());
            head.extend_from_slice(n.as_bytes());
            head.extend_from_slice(&(s.len() as u16).to_le_bytes());
            head.push(d.code());
            head.extend_from_slice(&(*off as u64).to_le_bytes());
            for x in s {
                head.extend_from_slice(&x.to_le_bytes());
            }
        }
        for ((_, _, _, b), off) in self.fields.iter().zip(&offsets) {
            head.resize(*off, 0);
            head.extend_from_slice(b);
        }
        head
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_round_trip_and_halves_decode() {
        for d in Dtype::ALL {
            assert_eq!(Dtype::from_code(d.code()), Some(d));
        }
        assert_eq!(Dtype::from_code(0), None);
        assert_eq!(Dtype::from_code(12), None);
        assert_eq!(Dtype::Float32.code(), 10);
        assert_eq!(Dtype::UInt8.code(), 1);
        assert_eq!(half_to_f64(0x3c00), 1.0);
        assert_eq!(half_to_f64(0xc000), -2.0);
        assert_eq!(half_to_f64(0x0001), 2f64.powi(-24));
        assert!(half_to_f64(0x7e00).is_nan());
    }
}
