//! How shader types lie in the interpreter's memory: every value is a run of
//! `f64` cells (a scalar is one cell, a vector one per component, a matrix
//! column-major, arrays and structures their elements one after another), and
//! a pointer is one cell holding an absolute cell address.

use naga::{ArraySize, Handle, Scalar, ScalarKind, Type, TypeInner, UniqueArena};

use crate::{InterpError, Kind, Matrix, Value, Vector};

/// The kind of a naga scalar, when the interpreter evaluates it (floats of any
/// width, 32-bit integers, booleans).
pub(crate) fn kind_of(s: Scalar) -> Option<Kind> {
    match (s.kind, s.width) {
        (ScalarKind::Float | ScalarKind::AbstractFloat, _) => Some(Kind::F),
        (ScalarKind::Sint, 4) | (ScalarKind::AbstractInt, _) => Some(Kind::I32),
        (ScalarKind::Uint, 4) => Some(Kind::U32),
        (ScalarKind::Bool, _) => Some(Kind::Bool),
        _ => None,
    }
}

/// Cell counts of every type of a module, and the cell offsets of structure
/// members, computed once (naga orders types so that a type only refers to
/// earlier ones).
pub(crate) struct Types {
    cells: Vec<u64>,
    members: Vec<Vec<u64>>,
    /// Types whose size is not known without a pipeline (runtime-sized or
    /// override-sized arrays, or structures holding one).
    unsized_: Vec<bool>,
}

impl Types {
    /// Sizes every type of `arena`. Sizes saturate instead of overflowing: a
    /// huge type is refused later when memory is checked.
    pub(crate) fn new(arena: &UniqueArena<Type>) -> Types {
        let mut t = Types {
            cells: Vec::with_capacity(arena.len()),
            members: Vec::with_capacity(arena.len()),
            unsized_: Vec::with_capacity(arena.len()),
        };
        for (_, ty) in arena.iter() {
            let mut offsets = Vec::new();
            let mut unsized_ = false;
            let cells = match ty.inner {
                TypeInner::Struct { ref members, .. } => {
                    let mut at = 0u64;
                    for m in members {
                        offsets.push(at);
                        at = at.saturating_add(t.get(m.ty));
                        unsized_ |= t.is_unsized(m.ty);
                    }
                    at
                }
                TypeInner::Array { base, size, .. } => {
                    unsized_ = !matches!(size, ArraySize::Constant(_)) || t.is_unsized(base);
                    t.cells_of(&ty.inner)
                }
                ref inner => t.cells_of(inner),
            };
            t.cells.push(cells);
            t.members.push(offsets);
            t.unsized_.push(unsized_);
        }
        t
    }

    fn get(&self, h: Handle<Type>) -> u64 {
        self.cells.get(h.index()).copied().unwrap_or(0)
    }

    /// Cells of the type `h`.
    pub(crate) fn cells(&self, h: Handle<Type>) -> u64 {
        self.get(h)
    }

    /// Whether `h` has no size of its own (runtime- or override-sized arrays).
    pub(crate) fn is_unsized(&self, h: Handle<Type>) -> bool {
        self.unsized_.get(h.index()).copied().unwrap_or(true)
    }

    /// Cells of a type given by value (as type resolutions give them).
    pub(crate) fn cells_of(&self, inner: &TypeInner) -> u64 {
        match *inner {
            TypeInner::Scalar(_) | TypeInner::Atomic(_) => 1,
            TypeInner::Vector { size, .. } => size as u64,
            TypeInner::Matrix { columns, rows, .. } => columns as u64 * rows as u64,
            TypeInner::Pointer { .. } | TypeInner::ValuePointer { .. } => 1,
            TypeInner::Array {
                base,
                size: ArraySize::Constant(n),
                ..
            } => u64::from(n.get()).saturating_mul(self.get(base)),
            TypeInner::Struct { .. } => {
                // Structures are always in the arena; this is only reached for
                // a resolution by value, which naga never makes for them.
                0
            }
            _ => 0,
        }
    }

    /// The cell offset of member `index` of the structure `h`.
    pub(crate) fn member_offset(&self, h: Handle<Type>, index: usize) -> Option<u64> {
        self.members.get(h.index())?.get(index).copied()
    }
}

/// A WGSL-like name of a type, for messages.
pub(crate) fn type_name(arena: &UniqueArena<Type>, inner: &TypeInner) -> String {
    let scalar = |s: Scalar| match kind_of(s) {
        Some(k) => k.name().to_string(),
        None => format!("{:?}{}", s.kind, s.width * 8),
    };
    match *inner {
        TypeInner::Scalar(s) => scalar(s),
        TypeInner::Vector { size, scalar: s } => format!("vec{}<{}>", size as u8, scalar(s)),
        TypeInner::Matrix {
            columns,
            rows,
            scalar: s,
        } => format!("mat{}x{}<{}>", columns as u8, rows as u8, scalar(s)),
        TypeInner::Array { base, size, .. } => {
            let b = type_name(arena, &arena[base].inner);
            match size {
                ArraySize::Constant(n) => format!("array<{b}, {n}>"),
                _ => format!("array<{b}>"),
            }
        }
        TypeInner::Struct { .. } => "a structure".to_string(),
        TypeInner::Pointer { .. } | TypeInner::ValuePointer { .. } => "a pointer".to_string(),
        TypeInner::Image { .. } => "a texture".to_string(),
        TypeInner::Sampler { .. } => "a sampler".to_string(),
        _ => "an opaque type".to_string(),
    }
}

/// Writes `v` into `out` (the cells of type `ty`), checking its shape.
pub(crate) fn encode(
    arena: &UniqueArena<Type>,
    types: &Types,
    ty: Handle<Type>,
    v: &Value,
    out: &mut [f64],
    what: &dyn Fn() -> String,
) -> Result<(), InterpError> {
    let inner = &arena[ty].inner;
    let mismatch = || InterpError::Type {
        what: what(),
        expected: type_name(arena, inner),
        found: v.to_string(),
    };
    let cells = types.cells(ty) as usize;
    if out.len() < cells {
        return Err(InterpError::Internal("value does not fit its cells".into()));
    }
    match (inner, v) {
        (&TypeInner::Scalar(s), v) => {
            out[0] = match (kind_of(s), v) {
                (Some(Kind::F), &Value::F(x)) => x,
                (Some(Kind::I32), &Value::I32(x)) => f64::from(x),
                (Some(Kind::U32), &Value::U32(x)) => f64::from(x),
                (Some(Kind::Bool), &Value::Bool(x)) => f64::from(u8::from(x)),
                _ => return Err(mismatch()),
            };
        }
        (&TypeInner::Vector { size, scalar }, Value::Vec(vec)) => {
            if kind_of(scalar) != Some(vec.kind()) || vec.size() != size as usize {
                return Err(mismatch());
            }
            out[..vec.size()].copy_from_slice(vec.as_slice());
        }
        (&TypeInner::Matrix { columns, rows, .. }, Value::Mat(m)) => {
            if m.columns() != columns as usize || m.rows() != rows as usize {
                return Err(mismatch());
            }
            out[..m.as_slice().len()].copy_from_slice(m.as_slice());
        }
        (
            &TypeInner::Array {
                base,
                size: ArraySize::Constant(n),
                ..
            },
            Value::Array(items),
        ) => {
            if items.len() != n.get() as usize {
                return Err(mismatch());
            }
            let stride = types.cells(base) as usize;
            for (i, item) in items.iter().enumerate() {
                let at = i * stride;
                encode(arena, types, base, item, &mut out[at..at + stride], what)?;
            }
        }
        (TypeInner::Struct { members, .. }, Value::Struct(items)) => {
            if items.len() != members.len() {
                return Err(mismatch());
            }
            for (i, (m, item)) in members.iter().zip(items).enumerate() {
                let at = types.member_offset(ty, i).unwrap_or(0) as usize;
                let n = types.cells(m.ty) as usize;
                encode(arena, types, m.ty, item, &mut out[at..at + n], what)?;
            }
        }
        _ => return Err(mismatch()),
    }
    Ok(())
}

/// Reads a value of type `inner` from its cells.
pub(crate) fn decode(
    arena: &UniqueArena<Type>,
    types: &Types,
    ty: Option<Handle<Type>>,
    inner: &TypeInner,
    cells: &[f64],
) -> Value {
    let at = |i: usize| cells.get(i).copied().unwrap_or(0.0);
    match *inner {
        TypeInner::Scalar(s) => scalar_value(kind_of(s).unwrap_or(Kind::F), at(0)),
        TypeInner::Vector { size, scalar } => {
            let n = size as usize;
            let c = &cells[..n.min(cells.len())];
            let kind = kind_of(scalar).unwrap_or(Kind::F);
            Vector::new(kind, c)
                .or_else(|| Vector::float(c))
                .map_or(Value::Void, Value::Vec)
        }
        TypeInner::Matrix { columns, rows, .. } => {
            let n = columns as usize * rows as usize;
            Matrix::new(
                columns as usize,
                rows as usize,
                &cells[..n.min(cells.len())],
            )
            .map_or(Value::Void, Value::Mat)
        }
        TypeInner::Array {
            base,
            size: ArraySize::Constant(n),
            ..
        } => {
            let stride = types.cells(base) as usize;
            let b = &arena[base].inner;
            Value::Array(
                (0..n.get() as usize)
                    .map(|i| {
                        let s = (i * stride).min(cells.len());
                        let e = (s + stride).min(cells.len());
                        decode(arena, types, Some(base), b, &cells[s..e])
                    })
                    .collect(),
            )
        }
        TypeInner::Struct { ref members, .. } => Value::Struct(
            members
                .iter()
                .enumerate()
                .map(|(i, m)| {
                    let off = ty.and_then(|t| types.member_offset(t, i)).unwrap_or(0) as usize;
                    let s = off.min(cells.len());
                    let e = (s + types.cells(m.ty) as usize).min(cells.len());
                    decode(arena, types, Some(m.ty), &arena[m.ty].inner, &cells[s..e])
                })
                .collect(),
        ),
        _ => Value::Void,
    }
}

fn scalar_value(kind: Kind, x: f64) -> Value {
    match kind {
        Kind::F => Value::F(x),
        Kind::I32 => Value::I32(x as i32),
        Kind::U32 => Value::U32(x as u32),
        Kind::Bool => Value::Bool(x != 0.0),
    }
}
