//! Values passed into and out of the interpreter.
//!
//! Floats are `f64` whatever width the shader declares (the interpreter's
//! point is f64 reference math); integers keep their 32-bit semantics.

use std::fmt;

/// The scalar kind of a vector's components.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kind {
    /// `bool`.
    Bool,
    /// `i32` (GLSL `int`).
    I32,
    /// `u32` (GLSL `uint`).
    U32,
    /// A float of any declared width, evaluated in f64.
    F,
}

impl Kind {
    /// The WGSL-style name used in messages (`f32` for every float width:
    /// that is what BRDF shaders declare).
    pub fn name(self) -> &'static str {
        match self {
            Kind::Bool => "bool",
            Kind::I32 => "i32",
            Kind::U32 => "u32",
            Kind::F => "f32",
        }
    }

    /// Whether `x` is a value of this kind (integral and in range for the
    /// integers, 0 or 1 for booleans).
    fn holds(self, x: f64) -> bool {
        match self {
            Kind::F => true,
            Kind::Bool => x == 0.0 || x == 1.0,
            Kind::I32 => x.fract() == 0.0 && (-2_147_483_648.0..=2_147_483_647.0).contains(&x),
            Kind::U32 => x.fract() == 0.0 && (0.0..=4_294_967_295.0).contains(&x),
        }
    }
}

/// A vector of 2 to 4 components of one kind. Integers and booleans are stored
/// exactly in the `f64` components (booleans as 0 and 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vector {
    kind: Kind,
    size: u8,
    c: [f64; 4],
}

impl Vector {
    /// A vector of `kind` with the components `c` (2 to 4 of them, each a
    /// valid value of the kind); `None` otherwise.
    pub fn new(kind: Kind, c: &[f64]) -> Option<Vector> {
        if !(2..=4).contains(&c.len()) || !c.iter().all(|&x| kind.holds(x)) {
            return None;
        }
        let mut v = [0.0; 4];
        v[..c.len()].copy_from_slice(c);
        Some(Vector {
            kind,
            size: c.len() as u8,
            c: v,
        })
    }

    /// A float vector (2 to 4 components); `None` for another length.
    pub fn float(c: &[f64]) -> Option<Vector> {
        Vector::new(Kind::F, c)
    }

    /// The components' kind.
    pub fn kind(&self) -> Kind {
        self.kind
    }

    /// The number of components (2 to 4).
    pub fn size(&self) -> usize {
        self.size as usize
    }

    /// The components (booleans as 0 and 1).
    pub fn as_slice(&self) -> &[f64] {
        &self.c[..self.size as usize]
    }
}

/// A float matrix, `columns` × `rows` (each 2 to 4), stored column-major like
/// WGSL and GLSL.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Matrix {
    columns: u8,
    rows: u8,
    c: [f64; 16],
}

impl Matrix {
    /// A matrix from its components in column-major order; `None` unless both
    /// dimensions are 2 to 4 and `column_major` has `columns * rows` entries.
    pub fn new(columns: usize, rows: usize, column_major: &[f64]) -> Option<Matrix> {
        if !(2..=4).contains(&columns)
            || !(2..=4).contains(&rows)
            || column_major.len() != columns * rows
        {
            return None;
        }
        let mut c = [0.0; 16];
        c[..column_major.len()].copy_from_slice(column_major);
        Some(Matrix {
            columns: columns as u8,
            rows: rows as u8,
            c,
        })
    }

    /// The number of columns.
    pub fn columns(&self) -> usize {
        self.columns as usize
    }

    /// The number of rows.
    pub fn rows(&self) -> usize {
        self.rows as usize
    }

    /// The entry in `column`, `row` (`None` out of range).
    pub fn get(&self, column: usize, row: usize) -> Option<f64> {
        (column < self.columns() && row < self.rows()).then(|| self.c[column * self.rows() + row])
    }

    /// The entries, column-major.
    pub fn as_slice(&self) -> &[f64] {
        &self.c[..self.columns() * self.rows()]
    }
}

/// A value of a shader type.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// What a function without a result returns.
    Void,
    /// `bool`.
    Bool(bool),
    /// `i32`.
    I32(i32),
    /// `u32`.
    U32(u32),
    /// A float of any declared width, in f64.
    F(f64),
    /// A vector.
    Vec(Vector),
    /// A float matrix.
    Mat(Matrix),
    /// A fixed-size array, element by element.
    Array(Vec<Value>),
    /// A structure, member by member in declaration order.
    Struct(Vec<Value>),
}

impl Value {
    /// A float.
    pub fn f(x: f64) -> Value {
        Value::F(x)
    }

    /// A float `vec2`.
    pub fn vec2(x: f64, y: f64) -> Value {
        Value::Vec(Vector {
            kind: Kind::F,
            size: 2,
            c: [x, y, 0.0, 0.0],
        })
    }

    /// A float `vec3`.
    pub fn vec3(x: f64, y: f64, z: f64) -> Value {
        Value::Vec(Vector {
            kind: Kind::F,
            size: 3,
            c: [x, y, z, 0.0],
        })
    }

    /// A float `vec4`.
    pub fn vec4(x: f64, y: f64, z: f64, w: f64) -> Value {
        Value::Vec(Vector {
            kind: Kind::F,
            size: 4,
            c: [x, y, z, w],
        })
    }

    /// The float, if this is one.
    pub fn as_f(&self) -> Option<f64> {
        match *self {
            Value::F(x) => Some(x),
            _ => None,
        }
    }

    /// The components of a float `vec3`, if this is one.
    pub fn as_vec3(&self) -> Option<[f64; 3]> {
        match self {
            Value::Vec(v) if v.kind == Kind::F && v.size == 3 => Some([v.c[0], v.c[1], v.c[2]]),
            _ => None,
        }
    }

    /// The components of a vector of any kind and size (booleans as 0 and 1).
    pub fn as_vec(&self) -> Option<&[f64]> {
        match self {
            Value::Vec(v) => Some(v.as_slice()),
            _ => None,
        }
    }
}

/// Writes the shape of a value like a WGSL type, for messages.
impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Void => write!(f, "no value"),
            Value::Bool(_) => write!(f, "bool"),
            Value::I32(_) => write!(f, "i32"),
            Value::U32(_) => write!(f, "u32"),
            Value::F(_) => write!(f, "f32"),
            Value::Vec(v) => write!(f, "vec{}<{}>", v.size, v.kind.name()),
            Value::Mat(m) => write!(f, "mat{}x{}<f32>", m.columns, m.rows),
            Value::Array(a) => match a.first() {
                Some(e) => write!(f, "array<{e}, {}>", a.len()),
                None => write!(f, "array of 0"),
            },
            Value::Struct(m) => write!(f, "struct of {} members", m.len()),
        }
    }
}
