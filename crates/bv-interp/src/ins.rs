//! The interpreter's instructions: one naga expression compiles to at most a
//! few of them, with operand cells resolved to frame offsets once, so running
//! one is a match and a short loop over `f64` cells.

use crate::math::{self, Bin, Tern, Un};

/// Where a pointer points.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Place {
    /// A cell offset in the current frame (a local variable or part of one).
    Local(u32),
    /// An absolute cell address (a module-scope variable or part of one).
    Abs(u32),
    /// The address is computed at run time and held in this frame cell.
    Dyn(u32),
}

impl Place {
    /// The absolute address this place denotes in the frame at `fb`.
    #[inline(always)]
    pub(crate) fn addr(self, mem: &[f64], fb: usize) -> usize {
        match self {
            Place::Local(o) => fb + o as usize,
            Place::Abs(a) => a as usize,
            Place::Dyn(s) => mem[fb + s as usize] as usize,
        }
    }
}

/// Clamps a run-time index to `0..len` (like naga's `Restrict` bounds-check
/// policy: an out-of-range index reads and writes the last element).
#[inline(always)]
fn clamp_index(i: f64, len: u32) -> usize {
    if i <= 0.0 {
        0
    } else if i >= f64::from(len) {
        len.saturating_sub(1) as usize
    } else {
        i as usize
    }
}

/// One instruction. Offsets (`dst`, `a`, `b`, …) are cells from the frame
/// base; `n` is the number of components.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Ins {
    /// Copies `n` cells within the frame.
    Copy { dst: u32, src: u32, n: u32 },
    /// Loads `n` cells from a place.
    Load { dst: u32, src: Place, n: u32 },
    /// Stores `n` cells to a place (naga's `Store` statement, run as an
    /// instruction so that straight-line code is one run).
    Store { dst: Place, src: u32, n: u32 },
    /// A pointer `off` cells past `base`.
    PtrAdd { dst: u32, base: Place, off: u32 },
    /// A pointer to element `index` (clamped to `len`) of stride `stride`.
    PtrIndex {
        dst: u32,
        base: Place,
        index: u32,
        stride: u32,
        len: u32,
    },
    /// Copies element `index` (clamped) of a composite value.
    IndexVal {
        dst: u32,
        base: u32,
        index: u32,
        stride: u32,
        len: u32,
    },
    /// One scalar into `n` components.
    Splat { dst: u32, src: u32, n: u8 },
    /// Components of a vector in the order `pat`.
    Swizzle {
        dst: u32,
        src: u32,
        n: u8,
        pat: [u8; 4],
    },
    /// A one-operand componentwise operation.
    Un { op: Un, dst: u32, a: u32, n: u8 },
    /// [`Ins::Un`] on scalars (the common case, without the loop).
    Un1 { op: Un, dst: u32, a: u32 },
    /// [`Ins::Bin`] on scalars.
    Bin1 { op: Bin, dst: u32, a: u32, b: u32 },
    /// A two-operand componentwise operation; `sa`/`sb` broadcast a scalar.
    Bin {
        op: Bin,
        dst: u32,
        a: u32,
        b: u32,
        n: u8,
        sa: bool,
        sb: bool,
    },
    /// A componentwise operation of three operands; `s` broadcasts scalars.
    Tern {
        op: Tern,
        dst: u32,
        a: u32,
        b: u32,
        c: u32,
        n: u8,
        s: [bool; 3],
    },
    /// WGSL `insertBits(e, newbits, offset, count)`.
    InsertBits {
        dst: u32,
        e: u32,
        new: u32,
        off: u32,
        count: u32,
        n: u8,
        signed: bool,
    },
    /// Matrix (`cols`×`rows`, or float: a Multiply by a broadcast scalar is a
    /// `Bin`) times a column vector.
    MatVec {
        dst: u32,
        m: u32,
        v: u32,
        cols: u8,
        rows: u8,
    },
    /// A row vector times a matrix.
    VecMat {
        dst: u32,
        v: u32,
        m: u32,
        cols: u8,
        rows: u8,
    },
    /// `a` (`k` columns, `rows` rows) times `b` (`cols` columns, `k` rows).
    MatMat {
        dst: u32,
        a: u32,
        b: u32,
        rows: u8,
        k: u8,
        cols: u8,
    },
    /// `condition ? accept : reject` over `n` cells (per component when the
    /// condition is a vector).
    Select {
        dst: u32,
        cond: u32,
        a: u32,
        b: u32,
        n: u32,
        per_component: bool,
    },
    /// `all` (`any` when `any`) of a boolean vector.
    AllAny { dst: u32, a: u32, n: u8, any: bool },
    /// Dot product; `int` wraps like `i32`/`u32` (`Some(signed)`).
    Dot {
        dst: u32,
        a: u32,
        b: u32,
        n: u8,
        int: Option<bool>,
    },
    /// Euclidean length.
    Length { dst: u32, a: u32, n: u8 },
    /// Euclidean distance.
    Distance { dst: u32, a: u32, b: u32, n: u8 },
    /// `a / length(a)`.
    Normalize { dst: u32, a: u32, n: u8 },
    /// 3-component cross product.
    Cross { dst: u32, a: u32, b: u32 },
    /// `dot(nref, i) < 0 ? n : -n`.
    FaceForward {
        dst: u32,
        n_: u32,
        i: u32,
        nref: u32,
        n: u8,
    },
    /// `i - 2 dot(n, i) n`.
    Reflect { dst: u32, i: u32, nn: u32, n: u8 },
    /// GLSL/WGSL `refract(i, n, eta)`.
    Refract {
        dst: u32,
        i: u32,
        nn: u32,
        eta: u32,
        n: u8,
    },
    /// Outer product: `rows` × `cols` from a column and a row vector.
    Outer {
        dst: u32,
        a: u32,
        b: u32,
        rows: u8,
        cols: u8,
    },
    /// Transpose of a `cols`×`rows` matrix.
    Transpose {
        dst: u32,
        a: u32,
        cols: u8,
        rows: u8,
    },
    /// Determinant of an `n`×`n` matrix.
    Determinant { dst: u32, a: u32, n: u8 },
    /// Inverse of an `n`×`n` matrix.
    Inverse { dst: u32, a: u32, n: u8 },
    /// `modf`: `{fract, whole}`, `n` components each.
    Modf { dst: u32, a: u32, n: u8 },
    /// `frexp`: `{fract, exp}`, `n` components each.
    Frexp { dst: u32, a: u32, n: u8 },
}

/// Copies `n` cells from `s` to `d` (ranges may overlap only if equal):
/// short runs, the common case, without a call to `memmove`.
#[inline(always)]
pub(crate) fn copy(mem: &mut [f64], s: usize, d: usize, n: usize) {
    match n {
        1 => mem[d] = mem[s],
        3 => {
            let v = [mem[s], mem[s + 1], mem[s + 2]];
            mem[d..d + 3].copy_from_slice(&v);
        }
        0..=4 => {
            for k in 0..n {
                mem[d + k] = mem[s + k];
            }
        }
        _ => mem.copy_within(s..s + n, d),
    }
}

/// The steps an instruction costs: one, plus one per 8 cells it copies, so
/// that a loop copying a large array exhausts the step budget as promptly
/// as any other loop.
pub(crate) fn cost(i: &Ins) -> u64 {
    let n = match *i {
        Ins::Copy { n, .. } | Ins::Load { n, .. } | Ins::Store { n, .. } => n,
        Ins::IndexVal { stride, .. } => stride,
        Ins::Select { n, .. } => n,
        _ => 0,
    };
    1 + u64::from(n / 8)
}

/// Runs `ins` on the frame at `fb` of `mem`.
pub(crate) fn run(ins: &[Ins], mem: &mut [f64], fb: usize) {
    for i in ins {
        step(i, mem, fb);
    }
}

#[inline(always)]
fn at(o: u32, fb: usize) -> usize {
    fb + o as usize
}

/// Runs one instruction.
#[inline(always)]
pub(crate) fn step(i: &Ins, mem: &mut [f64], fb: usize) {
    match *i {
        Ins::Copy { dst, src, n } => copy(mem, at(src, fb), at(dst, fb), n as usize),
        Ins::Load { dst, src, n } => {
            let s = src.addr(mem, fb);
            copy(mem, s, at(dst, fb), n as usize);
        }
        Ins::Store { dst, src, n } => {
            let d = dst.addr(mem, fb);
            copy(mem, at(src, fb), d, n as usize);
        }
        Ins::Un1 { op, dst, a } => mem[at(dst, fb)] = math::un(op, mem[at(a, fb)]),
        Ins::Bin1 { op, dst, a, b } => {
            mem[at(dst, fb)] = math::bin(op, mem[at(a, fb)], mem[at(b, fb)]);
        }
        Ins::PtrAdd { dst, base, off } => {
            mem[at(dst, fb)] = (base.addr(mem, fb) + off as usize) as f64;
        }
        Ins::PtrIndex {
            dst,
            base,
            index,
            stride,
            len,
        } => {
            let k = clamp_index(mem[at(index, fb)], len);
            mem[at(dst, fb)] = (base.addr(mem, fb) + k * stride as usize) as f64;
        }
        Ins::IndexVal {
            dst,
            base,
            index,
            stride,
            len,
        } => {
            let k = clamp_index(mem[at(index, fb)], len);
            let s = at(base, fb) + k * stride as usize;
            mem.copy_within(s..s + stride as usize, at(dst, fb));
        }
        Ins::Splat { dst, src, n } => {
            let x = mem[at(src, fb)];
            let d = at(dst, fb);
            mem[d..d + n as usize].fill(x);
        }
        Ins::Swizzle { dst, src, n, pat } => {
            let s = at(src, fb);
            let mut v = [0.0; 4];
            for (x, &p) in v.iter_mut().zip(&pat).take(n as usize) {
                *x = mem[s + p as usize];
            }
            let d = at(dst, fb);
            mem[d..d + n as usize].copy_from_slice(&v[..n as usize]);
        }
        Ins::Un { op, dst, a, n } => {
            let (d, a) = (at(dst, fb), at(a, fb));
            for k in 0..n as usize {
                mem[d + k] = math::un(op, mem[a + k]);
            }
        }
        Ins::Bin {
            op,
            dst,
            a,
            b,
            n,
            sa,
            sb,
        } => {
            let (d, a, b) = (at(dst, fb), at(a, fb), at(b, fb));
            for k in 0..n as usize {
                let x = mem[if sa { a } else { a + k }];
                let y = mem[if sb { b } else { b + k }];
                mem[d + k] = math::bin(op, x, y);
            }
        }
        Ins::Tern {
            op,
            dst,
            a,
            b,
            c,
            n,
            s,
        } => {
            let (d, a, b, c) = (at(dst, fb), at(a, fb), at(b, fb), at(c, fb));
            for k in 0..n as usize {
                let x = mem[if s[0] { a } else { a + k }];
                let y = mem[if s[1] { b } else { b + k }];
                let z = mem[if s[2] { c } else { c + k }];
                mem[d + k] = math::tern(op, x, y, z);
            }
        }
        Ins::InsertBits {
            dst,
            e,
            new,
            off,
            count,
            n,
            signed,
        } => {
            let (o, c) = (mem[at(off, fb)], mem[at(count, fb)]);
            let (d, e, nw) = (at(dst, fb), at(e, fb), at(new, fb));
            for k in 0..n as usize {
                mem[d + k] = math::insert_bits(mem[e + k], mem[nw + k], o, c, signed);
            }
        }
        Ins::MatVec {
            dst,
            m,
            v,
            cols,
            rows,
        } => {
            let (d, m, v) = (at(dst, fb), at(m, fb), at(v, fb));
            let (cols, rows) = (cols as usize, rows as usize);
            let mut out = [0.0; 4];
            for (r, o) in out.iter_mut().enumerate().take(rows) {
                let mut s = 0.0;
                for c in 0..cols {
                    s += mem[m + c * rows + r] * mem[v + c];
                }
                *o = s;
            }
            mem[d..d + rows].copy_from_slice(&out[..rows]);
        }
        Ins::VecMat {
            dst,
            v,
            m,
            cols,
            rows,
        } => {
            let (d, m, v) = (at(dst, fb), at(m, fb), at(v, fb));
            let (cols, rows) = (cols as usize, rows as usize);
            let mut out = [0.0; 4];
            for (c, o) in out.iter_mut().enumerate().take(cols) {
                let mut s = 0.0;
                for r in 0..rows {
                    s += mem[v + r] * mem[m + c * rows + r];
                }
                *o = s;
            }
            mem[d..d + cols].copy_from_slice(&out[..cols]);
        }
        Ins::MatMat {
            dst,
            a,
            b,
            rows,
            k,
            cols,
        } => {
            let (d, a, b) = (at(dst, fb), at(a, fb), at(b, fb));
            let (rows, k, cols) = (rows as usize, k as usize, cols as usize);
            let mut out = [0.0; 16];
            for c in 0..cols {
                for r in 0..rows {
                    let mut s = 0.0;
                    for l in 0..k {
                        s += mem[a + l * rows + r] * mem[b + c * k + l];
                    }
                    out[c * rows + r] = s;
                }
            }
            mem[d..d + rows * cols].copy_from_slice(&out[..rows * cols]);
        }
        Ins::Select {
            dst,
            cond,
            a,
            b,
            n,
            per_component,
        } => {
            let (d, cnd, a, b) = (at(dst, fb), at(cond, fb), at(a, fb), at(b, fb));
            if per_component {
                for k in 0..n as usize {
                    mem[d + k] = if mem[cnd + k] != 0.0 {
                        mem[a + k]
                    } else {
                        mem[b + k]
                    };
                }
            } else {
                let s = if mem[cnd] != 0.0 { a } else { b };
                mem.copy_within(s..s + n as usize, d);
            }
        }
        Ins::AllAny { dst, a, n, any } => {
            let a = at(a, fb);
            let v = &mem[a..a + n as usize];
            let r = if any {
                v.iter().any(|&x| x != 0.0)
            } else {
                v.iter().all(|&x| x != 0.0)
            };
            mem[at(dst, fb)] = if r { 1.0 } else { 0.0 };
        }
        Ins::Dot { dst, a, b, n, int } => {
            let (a, b) = (at(a, fb), at(b, fb));
            let r = match int {
                None => (0..n as usize).map(|k| mem[a + k] * mem[b + k]).sum(),
                Some(signed) => {
                    let mut s = 0u32;
                    for k in 0..n as usize {
                        s = s.wrapping_add(
                            math::bits(mem[a + k]).wrapping_mul(math::bits(mem[b + k])),
                        );
                    }
                    if signed {
                        f64::from(s as i32)
                    } else {
                        f64::from(s)
                    }
                }
            };
            mem[at(dst, fb)] = r;
        }
        Ins::Length { dst, a, n } => {
            let a = at(a, fb);
            mem[at(dst, fb)] = len(&mem[a..a + n as usize]);
        }
        Ins::Distance { dst, a, b, n } => {
            let (a, b) = (at(a, fb), at(b, fb));
            let mut v = [0.0; 4];
            for (k, x) in v.iter_mut().enumerate().take(n as usize) {
                *x = mem[a + k] - mem[b + k];
            }
            mem[at(dst, fb)] = len(&v[..n as usize]);
        }
        Ins::Normalize { dst, a, n } => {
            let (d, a) = (at(dst, fb), at(a, fb));
            let l = len(&mem[a..a + n as usize]);
            for k in 0..n as usize {
                mem[d + k] = mem[a + k] / l;
            }
        }
        Ins::Cross { dst, a, b } => {
            let (d, a, b) = (at(dst, fb), at(a, fb), at(b, fb));
            let (x, y) = (
                [mem[a], mem[a + 1], mem[a + 2]],
                [mem[b], mem[b + 1], mem[b + 2]],
            );
            mem[d] = x[1] * y[2] - x[2] * y[1];
            mem[d + 1] = x[2] * y[0] - x[0] * y[2];
            mem[d + 2] = x[0] * y[1] - x[1] * y[0];
        }
        Ins::FaceForward {
            dst,
            n_,
            i,
            nref,
            n,
        } => {
            let (d, nv, iv, r) = (at(dst, fb), at(n_, fb), at(i, fb), at(nref, fb));
            let dt: f64 = (0..n as usize).map(|k| mem[r + k] * mem[iv + k]).sum();
            let s = if dt < 0.0 { 1.0 } else { -1.0 };
            for k in 0..n as usize {
                mem[d + k] = s * mem[nv + k];
            }
        }
        Ins::Reflect { dst, i, nn, n } => {
            let (d, iv, nv) = (at(dst, fb), at(i, fb), at(nn, fb));
            let dt: f64 = (0..n as usize).map(|k| mem[nv + k] * mem[iv + k]).sum();
            for k in 0..n as usize {
                mem[d + k] = mem[iv + k] - 2.0 * dt * mem[nv + k];
            }
        }
        Ins::Refract { dst, i, nn, eta, n } => {
            let (d, iv, nv) = (at(dst, fb), at(i, fb), at(nn, fb));
            let eta = mem[at(eta, fb)];
            let dt: f64 = (0..n as usize).map(|k| mem[nv + k] * mem[iv + k]).sum();
            let k2 = 1.0 - eta * eta * (1.0 - dt * dt);
            for k in 0..n as usize {
                mem[d + k] = if k2 < 0.0 {
                    0.0
                } else {
                    eta * mem[iv + k] - (eta * dt + k2.sqrt()) * mem[nv + k]
                };
            }
        }
        Ins::Outer {
            dst,
            a,
            b,
            rows,
            cols,
        } => {
            let (d, a, b) = (at(dst, fb), at(a, fb), at(b, fb));
            let (rows, cols) = (rows as usize, cols as usize);
            let mut out = [0.0; 16];
            for c in 0..cols {
                for r in 0..rows {
                    out[c * rows + r] = mem[a + r] * mem[b + c];
                }
            }
            mem[d..d + rows * cols].copy_from_slice(&out[..rows * cols]);
        }
        Ins::Transpose { dst, a, cols, rows } => {
            let (d, a) = (at(dst, fb), at(a, fb));
            let (cols, rows) = (cols as usize, rows as usize);
            for c in 0..cols {
                for r in 0..rows {
                    // The result has `rows` columns of `cols` rows.
                    mem[d + r * cols + c] = mem[a + c * rows + r];
                }
            }
        }
        Ins::Determinant { dst, a, n } => {
            let a = at(a, fb);
            let n = n as usize;
            mem[at(dst, fb)] = math::determinant(&mem[a..a + n * n], n);
        }
        Ins::Inverse { dst, a, n } => {
            let (d, a) = (at(dst, fb), at(a, fb));
            let n = n as usize;
            let mut out = [0.0; 16];
            math::inverse(&mem[a..a + n * n], n, &mut out);
            mem[d..d + n * n].copy_from_slice(&out[..n * n]);
        }
        Ins::Modf { dst, a, n } => {
            let (d, a) = (at(dst, fb), at(a, fb));
            let n = n as usize;
            for k in 0..n {
                let x = mem[a + k];
                // WGSL `modf`: the whole part truncates; the fraction keeps
                // the sign of `x`.
                mem[d + k] = x - x.trunc();
                mem[d + n + k] = x.trunc();
            }
        }
        Ins::Frexp { dst, a, n } => {
            let (d, a) = (at(dst, fb), at(a, fb));
            let n = n as usize;
            for k in 0..n {
                let (f, e) = math::frexp(mem[a + k]);
                mem[d + k] = f;
                mem[d + n + k] = e;
            }
        }
    }
}

fn len(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}
